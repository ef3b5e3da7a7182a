use proptest::prelude::*;

use super::{FrameCommand, FrameError, FrameErrorKind, Plane, ProgrammableFrame};

/// The frame after `commands`, each a name and its words, under `plane`.
fn framed(plane: Plane, commands: &[(&str, &[(&str, f64)])]) -> ProgrammableFrame {
    let mut frame = ProgrammableFrame::default();
    for (name, words) in commands {
        frame.apply(FrameCommand::from_name(name).unwrap(), words, plane).unwrap();
    }
    frame
}

fn frame(commands: &[(&str, &[(&str, f64)])]) -> ProgrammableFrame {
    framed(Plane::XY, commands)
}

fn near(actual: [f64; 3], expected: [f64; 3]) {
    let apart = actual.iter().zip(expected).map(|(a, e)| (a - e).abs()).fold(0.0, f64::max);
    assert!(apart < 1e-9, "{actual:?} != {expected:?}");
}

#[test]
fn the_module_example_translates_then_scales() {
    let mut frame = ProgrammableFrame::default();
    frame.apply(FrameCommand::from_name("ATRANS").unwrap(), &[("X", 55.0), ("Y", 4.0)], Plane::XY).unwrap();
    frame.apply(FrameCommand::from_name("ASCALE").unwrap(), &[("X", 0.18), ("Y", 0.18)], Plane::XY).unwrap();
    near(frame.to_base([100.0, 0.0, 0.0]), [73.0, 4.0, 0.0]);
}

#[test]
fn each_command_alone() {
    near(frame(&[("TRANS", &[("X", 10.0), ("Z", -5.0)])]).to_base([1.0, 2.0, 3.0]), [11.0, 2.0, -2.0]);
    // A quarter turn about Z takes X into Y; RPL under G18 turns about Y,
    // from Z into X.
    near(frame(&[("ROT", &[("Z", 90.0)])]).to_base([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    near(frame(&[("ROT", &[("RPL", 90.0)])]).to_base([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    near(framed(Plane::ZX, &[("ROT", &[("RPL", 90.0)])]).to_base([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
    near(framed(Plane::YZ, &[("ROT", &[("RPL", 90.0)])]).to_base([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
    // A scale leaves the axes it does not name at 1.
    near(frame(&[("SCALE", &[("X", 2.0), ("Y", 0.5)])]).to_base([1.0, 4.0, 3.0]), [2.0, 2.0, 3.0]);
    // MIRROR's value only names the axis.
    near(frame(&[("MIRROR", &[("X", 0.0)])]).to_base([1.0, 2.0, 3.0]), [-1.0, 2.0, 3.0]);
    near(frame(&[("MIRROR", &[("Y", 7.0)])]).to_base([1.0, 2.0, 3.0]), [1.0, -2.0, 3.0]);
}

#[test]
fn several_axes_in_one_rotation_turn_about_z_then_y_then_x() {
    // Rz(90)·Rx(90): Z turns about X into −Y first, and that about Z into X.
    let turned = frame(&[("ROT", &[("X", 90.0), ("Z", 90.0)])]);
    near(turned.to_base([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
    near(turned.to_base([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    // As ROT Z90 then AROT X90; the other order leaves Z on −Y.
    let chained = frame(&[("ROT", &[("Z", 90.0)]), ("AROT", &[("X", 90.0)])]);
    near(chained.to_base([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
    let reversed = frame(&[("ROT", &[("X", 90.0)]), ("AROT", &[("Z", 90.0)])]);
    near(reversed.to_base([0.0, 0.0, 1.0]), [0.0, -1.0, 0.0]);
}

#[test]
fn absolute_commands_replace_the_frame_and_trans_alone_clears_it() {
    let replaced = frame(&[("ATRANS", &[("X", 10.0)]), ("AROT", &[("Z", 30.0)]), ("TRANS", &[("Y", 5.0)])]);
    near(replaced.to_base([1.0, 1.0, 1.0]), [1.0, 6.0, 1.0]);
    let scaled = frame(&[("TRANS", &[("X", 10.0)]), ("SCALE", &[("X", 2.0)])]);
    near(scaled.to_base([1.0, 1.0, 1.0]), [2.0, 1.0, 1.0]);
    let cleared = frame(&[("ROT", &[("Z", 30.0)]), ("ASCALE", &[("X", 3.0)]), ("TRANS", &[])]);
    assert!(cleared.is_identity());
    assert_eq!(cleared.to_string(), "no programmable frame");
    // Mirroring an axis twice restores it.
    assert!(frame(&[("MIRROR", &[("X", 0.0)]), ("AMIRROR", &[("X", 0.0)])]).to_base([1.0, 0.0, 0.0])[0] > 0.0);
}

#[test]
fn an_additive_translation_runs_along_the_turned_axes() {
    // ATRANS then AROT: the shift is in the base, the turn about the new
    // zero; AROT then ATRANS: the shift runs along the turned X, into Y.
    let shifted_first = frame(&[("ATRANS", &[("X", 10.0)]), ("AROT", &[("Z", 90.0)])]);
    near(shifted_first.to_base([1.0, 0.0, 0.0]), [10.0, 1.0, 0.0]);
    near(shifted_first.to_base([0.0; 3]), [10.0, 0.0, 0.0]);
    let turned_first = frame(&[("AROT", &[("Z", 90.0)]), ("ATRANS", &[("X", 10.0)])]);
    near(turned_first.to_base([1.0, 0.0, 0.0]), [0.0, 11.0, 0.0]);
    near(turned_first.to_base([0.0; 3]), [0.0, 10.0, 0.0]);
    // A translation after a scale is scaled; one before it is not.
    near(frame(&[("ASCALE", &[("X", 2.0)]), ("ATRANS", &[("X", 10.0)])]).to_base([0.0; 3]), [20.0, 0.0, 0.0]);
    near(frame(&[("ATRANS", &[("X", 10.0)]), ("ASCALE", &[("X", 2.0)])]).to_base([0.0; 3]), [10.0, 0.0, 0.0]);
}

#[test]
fn annex_2s_chain_scales_its_later_translation() {
    // L25: R1=0.18, ATRANS X=55 Y=4, ASCALE X=R1 Y=R1 Z=R1; later
    // ASCALE X0.75 Y0.75 and ATRANS X-300 (004:3847-3849, 3933-3935).
    let first: &[(&str, &[(&str, f64)])] =
        &[("ATRANS", &[("X", 55.0), ("Y", 4.0)]), ("ASCALE", &[("X", 0.18), ("Y", 0.18), ("Z", 0.18)])];
    let signature = frame(first);
    near(signature.to_base([100.0, 50.0, 5.0]), [55.0 + 18.0, 4.0 + 9.0, 0.9]);
    assert_eq!(signature.to_string(), "translation X55 Y4, scale X0.18 Y0.18 Z0.18");
    let mut later = first.to_vec();
    later.extend_from_slice(&[("ASCALE", &[("X", 0.75), ("Y", 0.75)]), ("ATRANS", &[("X", -300.0)])]);
    let later = frame(&later);
    // −300 at 0.18·0.75: the program zero moves 40.5 mm to X14.5.
    near(later.to_base([0.0; 3]), [14.5, 4.0, 0.0]);
    near(later.to_base([300.0, 100.0, 10.0]), [55.0, 4.0 + 13.5, 1.8]);
    assert_eq!(later.scale().map(|s| (s * 1e6).round() / 1e6), [0.135, 0.135, 0.18]);
    assert_eq!(later.to_string(), "translation X14.5 Y4, scale X0.18·0.75 Y0.18·0.75 Z0.18");
}

#[test]
fn display_names_rotation_and_mirror() {
    let shown = frame(&[("TRANS", &[("X", 1.5)]), ("AROT", &[("Z", 45.0)]), ("AMIRROR", &[("Y", 0.0)])]);
    assert_eq!(shown.to_string(), "translation X1.5, rotation Z45, mirror Y");
    assert_eq!(frame(&[("ROT", &[("Z", 30.0)]), ("AROT", &[("Z", -30.0)])]).to_string(), "no programmable frame");
}

#[test]
fn arcs_keep_their_plane_under_turns_about_the_tool_axis_and_uniform_scales() {
    let plain = |commands: &[(&str, &[(&str, f64)])], plane| {
        let frame = framed(plane, commands);
        (frame.keeps_plane(plane), frame.turns_arcs_over(plane))
    };
    assert_eq!(plain(&[], Plane::XY), (true, false));
    assert_eq!(
        plain(&[("ROT", &[("Z", 30.0)]), ("ASCALE", &[("X", 2.0), ("Y", 2.0), ("Z", 5.0)])], Plane::XY),
        (true, false)
    );
    assert_eq!(plain(&[("SCALE", &[("X", 2.0)])], Plane::XY), (false, false));
    assert_eq!(plain(&[("ROT", &[("X", 30.0)])], Plane::XY), (false, false));
    // A turn about X keeps the G19 plane (Y/Z), and the G18 one does not.
    assert_eq!(plain(&[("ROT", &[("X", 30.0)])], Plane::YZ), (true, false));
    assert_eq!(plain(&[("ROT", &[("X", 30.0)])], Plane::ZX), (false, false));
    // One mirrored plane axis turns arcs over, two do not; the tool axis
    // does not count. A half turn about X turns the G17 plane over.
    assert_eq!(plain(&[("MIRROR", &[("X", 0.0)])], Plane::XY), (true, true));
    assert_eq!(plain(&[("MIRROR", &[("X", 0.0), ("Y", 0.0)])], Plane::XY), (true, false));
    assert_eq!(plain(&[("MIRROR", &[("Y", 0.0)])], Plane::ZX), (true, false));
    assert_eq!(plain(&[("MIRROR", &[("Z", 0.0)])], Plane::ZX), (true, true));
    assert_eq!(plain(&[("ROT", &[("X", 180.0)])], Plane::XY), (true, true));
}

#[test]
fn refused_words_name_their_place_and_leave_the_frame() {
    let mut frame = frame(&[("ATRANS", &[("X", 5.0)])]);
    let before = frame.clone();
    let refused = |frame: &mut ProgrammableFrame, name: &str, words: &[(&str, f64)]| {
        frame.apply(FrameCommand::from_name(name).unwrap(), words, Plane::XY).unwrap_err()
    };
    let error = refused(&mut frame, "TRANS", &[("X", 1.0), ("A", 10.0)]);
    assert_eq!(error, FrameError { word: 1, kind: FrameErrorKind::NotAFrameAxis("A".into()) });
    assert_eq!(error.to_string(), "A is not an axis of the programmable frame: X, Y and Z (RPL for a rotation)");
    assert_eq!(refused(&mut frame, "ASCALE", &[("Y", 0.0)]).kind, FrameErrorKind::ScaleZero("Y".into()));
    assert_eq!(refused(&mut frame, "ATRANS", &[("RPL", 10.0)]).kind, FrameErrorKind::PlaneRotation);
    assert_eq!(refused(&mut frame, "AROT", &[("RPL", 10.0), ("Z", 1.0)]).word, 1);
    assert_eq!(refused(&mut frame, "AROT", &[("Z", 10.0), ("z", 1.0)]).kind, FrameErrorKind::Repeated("Z".into()));
    assert_eq!(refused(&mut frame, "TRANS", &[("X", f64::NAN)]).kind, FrameErrorKind::NotFinite("X".into()));
    assert_eq!(frame, before);
    assert_eq!(FrameCommand::from_name("ATRANSX"), None);
    assert_eq!(FrameCommand::from_name("rot").map(|c| c.additive), Some(false));
}

fn words() -> impl Strategy<Value = Vec<(&'static str, f64)>> {
    let axis = prop::sample::select(vec!["X", "Y", "Z"]);
    prop::collection::vec((axis, -500.0..500.0f64), 0..3)
}

fn commands() -> impl Strategy<Value = Vec<(&'static str, Vec<(&'static str, f64)>)>> {
    let names = prop::sample::select(vec!["TRANS", "ATRANS", "ROT", "AROT", "SCALE", "ASCALE", "MIRROR", "AMIRROR"]);
    prop::collection::vec((names, words()), 1..8)
}

proptest! {
    /// Random frames of non-zero scales map back exactly what they map.
    #[test]
    fn to_program_undoes_to_base(commands in commands(), point in prop::array::uniform3(-1000.0..1000.0f64)) {
        let mut frame = ProgrammableFrame::default();
        for (name, words) in &commands {
            let command = FrameCommand::from_name(name).unwrap();
            // Scales between 0.01 and 5 in size keep the round trip well conditioned.
            let words: Vec<(&str, f64)> = words
                .iter()
                .map(|&(axis, value)| match name.ends_with("SCALE") {
                    true => (axis, (value / 100.0).clamp(-5.0, 5.0).abs().max(0.01) * value.signum()),
                    false => (axis, value),
                })
                .collect();
            // A repeated axis is refused and changes nothing.
            let _ = frame.apply(command, &words, Plane::XY);
        }
        let back = frame.to_program(frame.to_base(point));
        let apart = back.iter().zip(point).map(|(a, e)| (a - e).abs()).fold(0.0, f64::max);
        prop_assert!(apart < 1e-6, "{:?} came back as {:?} through {}", point, back, frame);
    }
}
