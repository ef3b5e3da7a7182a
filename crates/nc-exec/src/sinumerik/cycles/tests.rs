use super::{
    CycleError,
    CycleMove::{self, *},
    Hole,
    SpindleAction::*,
    drilling, swivel,
};
use crate::sinumerik::frames::{FrameCommand, Plane, ProgrammableFrame};

/// At X10 Y20, 50 mm above the part, F300 and S1000 M3.
const HOLE: Hole = Hole { position: [10.0, 20.0, 50.0], plane: Plane::XY, feed: 300.0, spindle: 1000.0 };

/// The arguments as a call writes them: numbers, and `None` for an empty slot.
fn call(name: &str, arguments: &[Option<f64>]) -> Vec<CycleMove> {
    drilling(name, arguments, &HOLE).unwrap()
}

fn refused(name: &str, arguments: &[Option<f64>]) -> CycleError {
    drilling(name, arguments, &HOLE).unwrap_err()
}

fn at(z: f64) -> [f64; 3] {
    [10.0, 20.0, z]
}

/// The length run at feed (or tapping), in mm, from the hole's position.
fn feed_length(moves: &[CycleMove]) -> f64 {
    let mut from = HOLE.position;
    let mut length = 0.0;
    for action in moves {
        let (to, cuts) = match *action {
            Rapid(to) => (to, false),
            Feed { to, .. } | Tap { to, .. } => (to, true),
            _ => continue,
        };
        if cuts {
            length += (0..3).map(|axis| (to[axis] - from[axis]).powi(2)).sum::<f64>().sqrt();
        }
        from = to;
    }
    length
}

/// The depths a cycle's feed moves end at.
fn bottoms(moves: &[CycleMove]) -> Vec<f64> {
    moves.iter().filter_map(|action| if let Feed { to, .. } = action { Some(to[2]) } else { None }).collect()
}

fn close(actual: f64, expected: f64) {
    assert!((actual - expected).abs() < 1e-9, "{actual} != {expected}");
}

#[test]
fn cycle81_drills_at_the_feed_and_retracts_at_rapid() {
    // The catalogue's example: RTP 10, RFP 0, SDIS 2, DP -20.
    let moves = call("CYCLE81", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0)]);
    assert_eq!(moves, [Rapid(at(2.0)), Feed { to: at(-20.0), feed: 300.0 }, Rapid(at(10.0))]);
    close(feed_length(&moves), 22.0);
    // DPR below RFP where DP is left out; DP where both are written.
    assert_eq!(call("CYCLE81", &[Some(10.0), Some(0.0), Some(2.0), None, Some(20.0)]), moves);
    assert_eq!(call("cycle81", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0), Some(5.0)]), moves);
    // Under G18 the tool axis is Y.
    let side = Hole { plane: Plane::ZX, ..HOLE };
    let moves = drilling("CYCLE81", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0)], &side).unwrap();
    assert_eq!(moves[1], Feed { to: [10.0, -20.0, 50.0], feed: 300.0 });
}

#[test]
fn cycle82_dwells_at_the_depth() {
    let moves = call("CYCLE82", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0), None, Some(1.5)]);
    assert_eq!(moves, [Rapid(at(2.0)), Feed { to: at(-20.0), feed: 300.0 }, Dwell(1.5), Rapid(at(10.0))]);
}

/// CYCLE83 with RTP 10, RFP 0, SDIS 2, DP -30, FDEP -10, DAM 5, DTB 1,
/// DTS 0.5, FRF 0.5 and `vari`.
fn deep(vari: f64) -> Vec<CycleMove> {
    let arguments = [10.0, 0.0, 2.0, -30.0].map(Some).into_iter().chain([None]);
    let arguments = arguments.chain([-10.0].map(Some)).chain([None]).chain([5.0, 1.0, 0.5, 0.5, vari].map(Some));
    call("CYCLE83", &arguments.collect::<Vec<_>>())
}

#[test]
fn cycle83_removes_the_chip_at_the_reference_plane() {
    let moves = deep(1.0);
    // Steps of 10, 5, then DAM's 5: the anticipation is 0.6 mm up to 30 mm.
    let back = |reached: f64| [Rapid(at(2.0)), Dwell(0.5), Rapid(at(reached + 0.6))];
    let mut expected = vec![Rapid(at(2.0)), Feed { to: at(-10.0), feed: 150.0 }];
    for (reached, next) in [(-10.0, -15.0), (-15.0, -20.0), (-20.0, -25.0), (-25.0, -30.0)] {
        expected.extend(back(reached));
        expected.push(Feed { to: at(next), feed: 300.0 });
    }
    expected.extend([Dwell(1.0), Rapid(at(10.0))]);
    assert_eq!(moves, expected);
    assert_eq!(bottoms(&moves), [-10.0, -15.0, -20.0, -25.0, -30.0]);
    close(feed_length(&moves), 12.0 + 4.0 * 5.6);
}

#[test]
fn cycle83_breaks_the_chip_one_millimetre_back() {
    let moves = deep(0.0);
    assert_eq!(bottoms(&moves), [-10.0, -9.0, -15.0, -14.0, -20.0, -19.0, -25.0, -24.0, -30.0]);
    assert_eq!(moves[1], Feed { to: at(-10.0), feed: 150.0 });
    close(feed_length(&moves), 12.0 + 4.0 * (1.0 + 6.0));
    // Without a first depth one step drills to the bottom; without DAM
    // the steps stay as long as the first.
    let one = call("CYCLE83", &[Some(10.0), Some(0.0), Some(2.0), Some(-30.0)]);
    assert_eq!(one, [Rapid(at(2.0)), Feed { to: at(-30.0), feed: 300.0 }, Rapid(at(10.0))]);
    let even = call("CYCLE83", &[Some(10.0), Some(0.0), Some(2.0), Some(-25.0), None, None, Some(10.0)]);
    assert_eq!(bottoms(&even), [-10.0, -9.0, -20.0, -19.0, -25.0]);
    // Deeper than 30 mm the anticipation is 1/50 of the depth.
    let long =
        [Some(10.0), Some(0.0), Some(0.0), Some(-100.0), None, Some(-50.0), None, None, None, None, None, Some(1.0)];
    assert!(call("CYCLE83", &long).contains(&Rapid(at(-48.0))));
}

#[test]
fn cycle84_taps_in_at_the_pitch_and_out_reversed() {
    // The catalogue's example: M8 (1.25 mm) at 300 rpm in and 500 out,
    // M3 after.
    let example = [10.0, 0.0, 2.0, -20.0].map(Some).into_iter().chain([None, Some(0.0), Some(3.0), Some(8.0), None]);
    let example: Vec<_> = example.chain([0.0, 300.0, 500.0].map(Some)).collect();
    let moves = call("CYCLE84", &example);
    assert_eq!(
        moves,
        [
            Rapid(at(2.0)),
            Spindle(Orient(0.0)),
            Tap { to: at(-20.0), lead: 1.25, rpm: 300.0 },
            Tap { to: at(2.0), lead: 1.25, rpm: -500.0 },
            Rapid(at(10.0)),
            Spindle(Turn(1000.0)),
        ]
    );
    close(feed_length(&moves), 44.0);
    // A left-hand M8 turns the other way; PIT, SST and SST1 left out take
    // the speed in force; SDAC 5 stops the spindle after.
    let mut left = example.clone();
    left[7] = Some(-8.0);
    assert_eq!(call("CYCLE84", &left)[2], Tap { to: at(-20.0), lead: 1.25, rpm: -300.0 });
    let plain = [10.0, 0.0, 2.0, -20.0, 0.0, 0.0, 5.0, 0.0, 1.5].map(Some);
    let moves = call("CYCLE84", &plain);
    assert_eq!(
        moves[2..4],
        [Tap { to: at(-20.0), lead: 1.5, rpm: 1000.0 }, Tap { to: at(2.0), lead: 1.5, rpm: -1000.0 }]
    );
    assert_eq!(moves.last(), Some(&Spindle(Stop)));
}

#[test]
fn cycle840_taps_at_the_pitch_with_an_encoder_and_at_the_feed_without() {
    // The catalogue's example: M8 with an encoder, the spindle reversed for
    // the return, M3 after.
    let example = [10.0, 0.0, 2.0, -20.0].map(Some).into_iter().chain([None]);
    let example: Vec<_> = example.chain([0.0, 0.0, 3.0, 0.0, 8.0].map(Some)).collect();
    assert_eq!(
        call("CYCLE840", &example),
        [
            Rapid(at(2.0)),
            Tap { to: at(-20.0), lead: 1.25, rpm: 1000.0 },
            Tap { to: at(2.0), lead: 1.25, rpm: -1000.0 },
            Rapid(at(10.0)),
            Spindle(Turn(1000.0)),
        ]
    );
    // Without an encoder at F, out in M4 as SDR says, M5 after.
    let floating = [10.0, 0.0, 2.0, -20.0, 0.0, 0.0, 4.0, 5.0, 1.0].map(Some);
    let moves = call("CYCLE840", &floating);
    assert_eq!(
        moves,
        [
            Rapid(at(2.0)),
            Feed { to: at(-20.0), feed: 300.0 },
            Spindle(Turn(-1000.0)),
            Feed { to: at(2.0), feed: 300.0 },
            Rapid(at(10.0)),
            Spindle(Stop),
        ]
    );
    close(feed_length(&moves), 44.0);
    // AXN 1 taps along X, whatever the plane.
    let mut along_x = floating.to_vec();
    along_x.extend([None, None, Some(1.0)]);
    assert_eq!(call("CYCLE840", &along_x)[1], Feed { to: [-20.0, 20.0, 50.0], feed: 300.0 });
    for (at, value, name) in [(8, 2.0, "ENC"), (6, 5.0, "SDR"), (11, 4.0, "AXN")] {
        let mut wrong = along_x.clone();
        wrong[at] = Some(value);
        assert_eq!(refused("CYCLE840", &wrong).argument, Some((at, name)));
    }
    let still = Hole { spindle: 0.0, ..HOLE };
    assert_eq!(drilling("CYCLE840", &floating, &still).unwrap_err().to_string(), "CYCLE840: needs the spindle turning");
}

#[test]
fn boring_cycles_feed_in_and_out_as_each_says() {
    let bore = [10.0, 0.0, 2.0, -20.0].map(Some);
    let with =
        |rest: &[Option<f64>]| bore.iter().copied().chain([None]).chain(rest.iter().copied()).collect::<Vec<_>>();
    let moves = call("CYCLE85", &with(&[Some(0.0), Some(300.0), Some(500.0)]));
    assert_eq!(
        moves,
        [Rapid(at(2.0)), Feed { to: at(-20.0), feed: 300.0 }, Feed { to: at(2.0), feed: 500.0 }, Rapid(at(10.0))]
    );
    close(feed_length(&moves), 44.0);
    let moves = call("CYCLE86", &with(&[Some(1.0), Some(3.0), Some(-1.0), Some(-1.0), Some(1.0), Some(45.0)]));
    assert_eq!(
        moves,
        [
            Spindle(Turn(1000.0)),
            Rapid(at(2.0)),
            Feed { to: at(-20.0), feed: 300.0 },
            Dwell(1.0),
            Spindle(Orient(45.0)),
            Rapid([9.0, 19.0, -19.0]),
            Rapid([9.0, 19.0, 10.0]),
            Rapid(at(10.0)),
            Spindle(Turn(1000.0)),
        ]
    );
    close(feed_length(&moves), 22.0);
    let moves = call("CYCLE88", &with(&[Some(1.0), Some(4.0)]));
    assert_eq!(
        moves,
        [
            Spindle(Turn(-1000.0)),
            Rapid(at(2.0)),
            Feed { to: at(-20.0), feed: 300.0 },
            Dwell(1.0),
            Spindle(Stop),
            ProgramStop,
            Rapid(at(10.0)),
            Spindle(Turn(-1000.0)),
        ]
    );
    assert_eq!(call("CYCLE87", &with(&[Some(4.0)])), [&moves[..3], &moves[4..]].concat());
    let moves = call("CYCLE89", &with(&[Some(2.0)]));
    assert_eq!(
        moves,
        [
            Rapid(at(2.0)),
            Feed { to: at(-20.0), feed: 300.0 },
            Dwell(2.0),
            Feed { to: at(2.0), feed: 300.0 },
            Rapid(at(10.0))
        ]
    );
    close(feed_length(&moves), 44.0);
}

#[test]
fn refused_calls_name_the_argument() {
    let at_fault = |name: &str, arguments: &[Option<f64>]| refused(name, arguments).argument;
    let hole = |dp: f64| vec![Some(10.0), Some(0.0), Some(2.0), Some(dp)];
    let error = refused("CYCLE81", &hole(5.0));
    assert_eq!(error.argument, Some((3, "DP")));
    assert_eq!(error.to_string(), "CYCLE81 DP: the final depth 5 is not below the reference plane RFP 0");
    assert_eq!(at_fault("CYCLE81", &[Some(10.0), Some(0.0), Some(2.0), None, Some(-3.0)]), Some((4, "DPR")));
    assert_eq!(at_fault("CYCLE81", &[Some(10.0), Some(0.0), Some(2.0)]), Some((3, "DP")));
    assert_eq!(at_fault("CYCLE81", &[Some(-5.0), Some(0.0), Some(2.0), Some(-20.0)]), Some((0, "RTP")));
    assert_eq!(at_fault("CYCLE81", &[Some(10.0), Some(0.0), Some(-2.0), Some(-20.0)]), Some((2, "SDIS")));
    assert_eq!(at_fault("CYCLE81", &[Some(10.0), Some(f64::NAN), Some(2.0), Some(-20.0)]), Some((1, "RFP")));
    assert_eq!(
        at_fault("CYCLE82", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0), None, Some(-1.0)]),
        Some((5, "DTB"))
    );
    let deep = |at: usize, value: f64| {
        let mut arguments = hole(-30.0);
        arguments.resize(12, None);
        arguments[at] = Some(value);
        refused("CYCLE83", &arguments).argument
    };
    assert_eq!(deep(5, 4.0), Some((5, "FDEP")));
    assert_eq!(deep(7, -1.0), Some((7, "DAM")));
    assert_eq!(deep(10, 2.0), Some((10, "FRF")));
    assert_eq!(deep(11, 2.0), Some((11, "VARI")));
    assert_eq!(deep(5, -1e-6).map(|(_, name)| name), Some("FDEP"), "too many steps");
    let mut tap = hole(-20.0);
    tap.resize(12, None);
    assert_eq!(refused("CYCLE84", &tap).argument, Some((8, "PIT")));
    tap[7] = Some(7.0);
    assert_eq!(refused("CYCLE84", &tap).argument, Some((7, "MPIT")));
    tap[7] = Some(8.0);
    tap[6] = Some(6.0);
    assert_eq!(refused("CYCLE84", &tap).argument, Some((6, "SDAC")));
    let mut tap_still = tap.clone();
    tap_still[6] = Some(3.0);
    let still = Hole { spindle: 0.0, ..HOLE };
    assert_eq!(drilling("CYCLE84", &tap_still, &still).unwrap_err().argument, Some((10, "SST")));
    assert_eq!(
        at_fault("CYCLE85", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0), None, None, Some(300.0)]),
        Some((7, "RFF"))
    );
    assert_eq!(
        at_fault("CYCLE87", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0), None, Some(5.0)]),
        Some((5, "SDIR"))
    );
    let unfed = drilling("CYCLE81", &hole(-20.0), &Hole { feed: 0.0, ..HOLE }).unwrap_err();
    assert_eq!(unfed.to_string(), "CYCLE81: needs a feed F above 0");
    assert_eq!(refused("CYCLE99", &[]).to_string(), "CYCLE99: is not a cycle of the catalogue");
    assert_eq!(refused("CYCLE832", &[Some(0.05)]).to_string(), "CYCLE832: is not a drilling cycle");
}

/// CYCLE800 with `st`, `mode`, the reference point, the angles and the
/// zero point after the turn; the data record left out.
fn swivelled(st: f64, mode: f64, reference: [f64; 3], angles: [f64; 3], zero: [f64; 3]) -> Vec<Option<f64>> {
    let mut arguments = vec![Some(1.0), None, Some(st), Some(mode)];
    arguments.extend(reference.iter().chain(&angles).chain(&zero).map(|&value| Some(value)));
    arguments.extend([Some(-1.0), Some(100.0), Some(1.0)]);
    arguments
}

fn near(actual: [f64; 3], expected: [f64; 3]) {
    let apart = actual.iter().zip(expected).map(|(a, e)| (a - e).abs()).fold(0.0, f64::max);
    assert!(apart < 1e-9, "{actual:?} != {expected:?}");
}

#[test]
fn cycle800_turns_the_frame_about_its_axes_in_order() {
    let mut frame = ProgrammableFrame::default();
    swivel(&swivelled(0.0, 57.0, [0.0; 3], [0.0, 0.0, 45.0], [0.0; 3])).unwrap().apply_to(&mut frame);
    let half = std::f64::consts::FRAC_1_SQRT_2;
    near(frame.direction_to_base([1.0, 0.0, 0.0]), [half, half, 0.0]);
    // About X, then the turned Y: Z goes into −Y and then about Y' into
    // the base's X.
    let mut frame = ProgrammableFrame::default();
    swivel(&swivelled(0.0, 57.0, [0.0; 3], [90.0, 90.0, 0.0], [0.0; 3])).unwrap().apply_to(&mut frame);
    near(frame.direction_to_base([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
    // Order Z, Y, X (0b01_10_11 = 27): _A turns about Z.
    let mut frame = ProgrammableFrame::default();
    swivel(&swivelled(0.0, 27.0, [0.0; 3], [90.0, 0.0, 0.0], [0.0; 3])).unwrap().apply_to(&mut frame);
    near(frame.direction_to_base([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    // Solid angles: about Z by _A, then about the turned Y by _B.
    let solid = swivel(&swivelled(0.0, 64.0, [0.0; 3], [90.0, 90.0, 0.0], [0.0; 3])).unwrap();
    assert_eq!(solid.turns, [(2, 90.0), (1, 90.0)]);
}

#[test]
fn cycle800_moves_the_zero_before_and_after_the_turn() {
    // The reference point in the base, the zero after the turn along the
    // turned axes: X5 after a quarter turn about Z runs along Y.
    let mut frame = ProgrammableFrame::default();
    swivel(&swivelled(0.0, 57.0, [10.0, 0.0, 0.0], [0.0, 0.0, 90.0], [5.0, 0.0, 0.0])).unwrap().apply_to(&mut frame);
    near(frame.to_base([0.0; 3]), [10.0, 5.0, 0.0]);
    near(frame.to_program([10.0, 5.0, 0.0]), [0.0; 3]);
}

#[test]
fn a_new_swivel_of_zeros_resets_and_an_additive_one_composes() {
    let mut frame = ProgrammableFrame::default();
    frame.apply(FrameCommand::from_name("TRANS").unwrap(), &[("Z", 10.0)], Plane::XY).unwrap();
    let turned = swivelled(1.0, 57.0, [0.0; 3], [0.0, 0.0, 90.0], [0.0; 3]);
    swivel(&turned).unwrap().apply_to(&mut frame);
    near(frame.to_base([1.0, 0.0, 0.0]), [0.0, 1.0, 10.0]);
    // The thesis's call: _ST 100000 (new), all angles 0 (004:3841).
    let reset = [Some(1.0), None, Some(100000.0), Some(57.0)].into_iter().chain([Some(0.0); 9]);
    let reset: Vec<_> = reset.chain([Some(-1.0), Some(100.0), Some(1.0)]).collect();
    swivel(&reset).unwrap().apply_to(&mut frame);
    assert!(frame.is_identity());
    // Left out, _MODE is 57 and the call resets too.
    swivel(&[]).unwrap().apply_to(&mut frame);
    assert!(frame.is_identity());
}

#[test]
fn cycle800_refuses_what_it_cannot_turn() {
    let at_fault = |arguments: &[Option<f64>]| swivel(arguments).unwrap_err().argument;
    assert_eq!(at_fault(&swivelled(2.0, 57.0, [0.0; 3], [0.0; 3], [0.0; 3])), Some((2, "_ST")));
    // X three times; projection angles; direct positions; not a number.
    for mode in [21.0, 128.0, 192.0, 57.5, 300.0] {
        assert_eq!(at_fault(&swivelled(0.0, mode, [0.0; 3], [0.0; 3], [0.0; 3])), Some((3, "_MODE")), "{mode}");
    }
    assert_eq!(at_fault(&swivelled(0.0, 57.0, [0.0; 3], [f64::INFINITY, 0.0, 0.0], [0.0; 3])), Some((7, "_A")));
}
