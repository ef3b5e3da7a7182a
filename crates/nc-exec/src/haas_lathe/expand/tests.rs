use expect_test::expect;
use ncc_catalog::Dialect;
use ncc_syntax::{Parse, TextRange, TextSize};
use proptest::prelude::*;

use super::Expansion;
use crate::{
    expand::{Expand, ExpandError, Unwritable},
    machine::MachineConfig,
    run::{self, NoFiles, run, run_into},
    trace::{MAX_AXES, Motion, Path, PathMode, Step, StepSink, Stop, Trace},
    velocity::{self, Reason},
};

const BUDGET: usize = 100_000;

fn lathe() -> MachineConfig {
    MachineConfig::of_control(Dialect::HaasLathe)
}

/// `text` run on a lathe and written as program `O<number>`, through the
/// interface the command line drives.
fn expand(text: &str, number: u32, title: &str) -> String {
    expand_on(&lathe(), text, number, title)
}

/// [`expand`] on `machine`.
fn expand_on(machine: &MachineConfig, text: &str, number: u32, title: &str) -> String {
    let machine = machine.clone();
    let mut written = Vec::new();
    let mut expansion: Box<dyn Expand + '_> = Box::new(Expansion::new(&mut written, &machine, number, title));
    let trace = run_into(text, &NoFiles, &machine, BUDGET, &mut *expansion);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    expansion.finish().expect("an expansion into memory");
    String::from_utf8(written).expect("an ASCII program")
}

/// Lines both ways, arcs both ways by R and by I/K, a dwell in ms and one
/// in seconds, both stops, feeds per revolution at a constant speed and at
/// a constant cutting speed, and an exact stop; the tool, the spindle and
/// the speed limit are not written.
const PROGRAM: &str = "%
O1234 (DEMO)
T101
G50 S2500
G97 S1000 M03
G00 X40. Z2.
G99 G01 Z-20. F0.1
G02 X60. Z-30. R10.
G03 X80. Z-40. I0 K-10.
G04 P500
G04 P1.5
M01
G96 S100
G01 X100. F0.2
G09 Z-50.
G00 X120. Z5. M00
M30
%
";

#[test]
fn a_program_is_written_as_plain_lathe_blocks() {
    let expanded = expand(PROGRAM, 1234, "EXPANDED FROM O1234 (DEMO).nc");
    // 100 mm/min at 1000 rpm; under G96 S100 the rpm at the mean diameters
    // 90 and 100 make 70.736 and 63.662 mm/min.
    expect![[r#"
        %
        O1234 (EXPANDED FROM O1234 DEMO.nc)
        G18 G21 G40 G54 G97 G98
        G00 X40. Z2.
        G01 Z-20. F100.
        G02 X60. Z-30. I10. K0.
        G03 X80. Z-40. I0. K-10.
        G04 P500
        G04 P1500
        M01
        G01 X100. F70.736
        G61 G01 Z-50. F63.662
        G64 G00 X120. Z5. M00
        M30
        %
    "#]]
    .assert_eq(&expanded);
    round_trip(PROGRAM);
}

/// The first move writes both axes, the later ones those that change.
#[test]
fn the_first_move_writes_both_axes() {
    let expanded = expand("O1\nG00 X70.\nZ2.\nX70. Z-1.\nM30\n", 1, "");
    assert_eq!(expanded, "%\nO1\nG18 G21 G40 G54 G97 G98\nG00 X70. Z0.\nG00 Z2.\nG00 Z-1.\nM30\n%\n");
}

/// A step over the lathe's axes X (the radius) and Z, as the interpreter
/// makes them.
fn step(motion: Motion, path: Path, x: f64, z: f64, feed: Option<f64>) -> Step {
    let mut end = [0.0; MAX_AXES];
    (end[0], end[1]) = (x, z);
    Step {
        source: 0,
        range: TextRange::default(),
        motion,
        path,
        duration: 1.0,
        length: 1.0,
        feed,
        end,
        frame: 0,
        stop: None,
        path_mode: PathMode::Continuous,
        m_functions: 0,
        tool_change: false,
        dynamic_set: 1,
        mergeable: false,
        jerk_limited: false,
        spindle: [0.0; 2],
        corner_tolerance: super::super::dynamics::corner_rounding(&lathe()) as f32,
    }
}

/// The run does not make threads yet: hand-made steps show how they are
/// written. S comes before the thread when the speed changes, the lead is
/// F (to 0.0001 mm), and the feed after a thread writes F again.
#[test]
fn threads_are_g32_with_their_lead_after_their_speed() {
    let thread = |lead, speed| Path::Thread { lead, speed };
    let steps = [
        step(Motion::Rapid, Path::Straight, 15.0, 5.0, None),
        step(Motion::Feed, thread(1.5, 500.0), 15.0, -20.0, Some(750.0)),
        step(Motion::Rapid, Path::Straight, 20.0, -20.0, None),
        step(Motion::Rapid, Path::Straight, 20.0, 5.0, None),
        step(Motion::Rapid, Path::Straight, 14.5, 5.0, None),
        step(Motion::Feed, thread(1.5, 500.0), 14.5, -20.0, Some(750.0)),
        step(Motion::Feed, Path::Straight, 20.0, -20.0, Some(150.0)),
        step(Motion::Feed, thread(1.5875, 800.0), 20.0, -40.0, Some(1270.0)),
    ];
    let mut expansion = Expansion::new(Vec::new(), &lathe(), 9, "THREADS");
    for step in steps {
        expansion.step(step);
    }
    let expanded = String::from_utf8(expansion.finish().expect("written")).expect("ASCII");
    expect![[r#"
        %
        O9 (THREADS)
        G18 G21 G40 G54 G97 G98
        G00 X30. Z5.
        S500 M03
        G32 Z-20. F1.5
        G00 X40.
        G00 Z5.
        G00 X29.
        G32 Z-20.
        G01 X40. F150.
        S800 M03
        G32 Z-40. F1.5875
        M30
        %
    "#]]
    .assert_eq(&expanded);
    assert!(Parse::new(&expanded, Dialect::HaasLathe).errors().is_empty());
}

/// An arc in another plane than the lathe's stops the writing at its
/// block: nothing is written after it, and the run may end.
#[test]
fn an_arc_outside_the_plane_zx_is_unwritable() {
    let range = TextRange::new(TextSize::from(5), TextSize::from(9));
    let arc = Path::Arc { plane: (b'X', b'Y'), centre: [0.0, 0.0], clockwise: true };
    let mut expansion = Expansion::new(Vec::new(), &lathe(), 1, "");
    expansion.step(step(Motion::Rapid, Path::Straight, 10.0, 0.0, None));
    assert!(!expansion.closed());
    expansion.step(Step { range, ..step(Motion::Feed, arc, 0.0, 10.0, Some(100.0)) });
    assert!(expansion.closed());
    let Err(ExpandError::Unwritable(Unwritable { source: 0, range: at, reason })) = expansion.finish() else {
        panic!("the arc out of the plane ZX is written");
    };
    assert_eq!(at, range);
    assert!(reason.contains("plane ZX"), "{reason}");
}

/// Every move of a run: its kind, its end (Z and the radius X), its length
/// and its feed (mm/min) or, for a dwell, its duration.
fn moves(trace: &Trace) -> Vec<(Motion, [f64; 2], f64, f64)> {
    trace
        .steps
        .iter()
        .filter(|step| match step.motion {
            Motion::Rapid | Motion::Feed => step.length > 0.0,
            Motion::Dwell => true,
            Motion::None => false,
        })
        .map(|step| {
            let rate = if step.motion == Motion::Dwell { step.duration } else { step.feed.unwrap_or(0.0) };
            (step.motion, [step.end[1], step.end[0]], step.length, rate)
        })
        .collect()
}

fn within(after: f64, before: f64, relative: f64) -> bool {
    (after - before).abs() <= relative * before.abs() + 1e-9
}

/// Expands `text`, parses the expansion as a Haas program and runs both:
/// the same moves, each ending within 1 µm of its original, as long within
/// 10 µm (an arc's centre by R lies off the µm grid, and the written one on
/// it) at the same feed to 0.1 %, the same dwells, and the same total time
/// to 0.1 %; the expansion's lines fit in 80 characters.
fn round_trip(text: &str) -> String {
    let machine = lathe();
    let original = run(text, &NoFiles, &machine, BUDGET);
    assert!(original.findings.is_empty(), "{:?}", original.findings);
    let expanded = expand(text, 1, "ROUND TRIP");
    let parse = Parse::new(&expanded, Dialect::HaasLathe);
    assert!(parse.errors().is_empty(), "{:?}\n{expanded}", parse.errors());
    assert!(expanded.lines().all(|line| line.len() <= 80), "{expanded}");
    let again = run(&expanded, &NoFiles, &machine, BUDGET);
    assert!(again.findings.is_empty(), "{:?}\n{expanded}", again.findings);
    let (before, after) = (moves(&original), moves(&again));
    assert_eq!(before.len(), after.len(), "{expanded}");
    for (i, ((motion, end, length, rate), (motion_again, end_again, length_again, rate_again))) in
        before.iter().zip(&after).enumerate()
    {
        let context = || format!("move {i}: {:?} against {:?}\n{expanded}", before[i], after[i]);
        assert_eq!(motion, motion_again, "{}", context());
        assert!((0..2).all(|axis| (end[axis] - end_again[axis]).abs() <= 0.001 + 1e-9), "{}", context());
        assert!((length - length_again).abs() <= 0.01, "{}", context());
        assert!(within(*rate_again, *rate, 1e-3), "{}", context());
    }
    let total = |trace: &Trace| trace.totals().total_time;
    assert!(within(total(&again), total(&original), 1e-3), "{} s, expanded {} s", total(&original), total(&again));
    expanded
}

/// A turning program of macro statements: a WHILE loop of roughing passes
/// with arcs by R and by I/K and incremental words, an IF jump, a computed
/// word, a dwell, a stop and a constant cutting speed.
#[test]
fn a_program_of_loops_and_variables_runs_the_same_expanded() {
    let text = "%
O2001 (WHILE TURNING)
G50 S3000
G96 S180 M03
G00 X64. Z2.
G99 F0.25
#1 = 60.
#2 = 0
WHILE [#1 GT 40.] DO1
G00 X#1 Z2.
G01 Z-30.
G02 U6. W-3. R3.
G00 U2. Z2.
#1 = #1 - 4.
#2 = #2 + 1
END1
IF [#2 LT 5] GOTO 50
G01 X[#1 - 10.] Z-40.
N50 G04 P250
G00 X30. Z2.
G01 Z0 F[0.1 * 2]
G03 X40. Z-5. I0 K-5.
G02 X50. Z-10. R5.
M01
G97 S800
G98 G01 X70. W-10. F120.
G00 X100. Z50.
M30
%
";
    let expanded = round_trip(text);
    // Five passes of four moves, each pass at its own diameter.
    assert_eq!(expanded.matches("G01 Z-30.").count(), 5, "{expanded}");
    assert_eq!(expanded.matches("G02 ").count(), 6, "{expanded}");
    assert!(expanded.contains("G04 P250\n"), "{expanded}");
    assert!(!expanded.contains('#') && !expanded.contains("WHILE"), "{expanded}");
}

/// One block of a random lathe program: a move by U and W, a line that may
/// change the feed, an arc by R or by I and K; or a change of the path's
/// modes, G187 with smoothness level P (0: none) or G103 P, in the block
/// of the next move (a block without motion would stop the path).
#[derive(Debug, Clone)]
enum Move {
    Smoothness {
        level: u8,
    },
    LookAhead {
        blocks: u8,
    },
    Rapid {
        u: i32,
        w: i32,
    },
    /// `feed` in mm/min, or µm/rev less 50.
    Line {
        u: i32,
        w: i32,
        feed: Option<u32>,
    },
    /// G02/G03 by R, `stretch` times half the chord (a negative R for the
    /// long way round). Its centre is off the µm grid the expansion writes
    /// it on: an arc of a few mm stays within 0.1 % of its length.
    ByRadius {
        clockwise: bool,
        u: i32,
        w: i32,
        stretch: f64,
        long: bool,
    },
    /// G02/G03 about the centre at I, K (µm) through `quarters` quarter
    /// turns: the end is on the circle exactly.
    ByCentre {
        clockwise: bool,
        i: i32,
        k: i32,
        quarters: u8,
    },
}

fn a_move() -> impl Strategy<Value = Move> {
    let delta = -20_000..20_000i32;
    prop_oneof![
        (0..4u8).prop_map(|level| Move::Smoothness { level }),
        (0..3u8).prop_map(|blocks| Move::LookAhead { blocks }),
        (delta.clone(), delta.clone()).prop_map(|(u, w)| Move::Rapid { u, w }),
        (delta.clone(), delta.clone(), prop::option::of(1..5_000u32)).prop_map(|(u, w, feed)| Move::Line {
            u,
            w,
            feed
        }),
        (any::<bool>(), delta.clone(), delta.clone(), 1.0..3.0f64, any::<bool>())
            .prop_filter("a chord of 3 mm", |(_, u, w, _, _)| f64::from(*u).hypot(f64::from(*w)) >= 3000.0)
            .prop_map(|(clockwise, u, w, stretch, long)| Move::ByRadius { clockwise, u, w, stretch, long }),
        (any::<bool>(), -10_000..10_000i32, -10_000..10_000i32, 1..4u8)
            .prop_filter("a radius", |(_, i, k, _)| i.abs() + k.abs() > 100)
            .prop_map(|(clockwise, i, k, quarters)| Move::ByCentre { clockwise, i, k, quarters }),
    ]
}

/// µm as the program writes them.
fn mm(micrometres: i64) -> String {
    format!("{:.3}", micrometres as f64 / 1000.0)
}

/// A program of `moves` from Ø`start` at Z0, with the feed per minute, per
/// revolution at 1000 rpm, or per revolution at 150 m/min up to 2000 rpm.
fn lathe_program(start: u32, feed_mode: u8, moves: &[Move]) -> String {
    let mut text = String::from("O1\n");
    text.push_str(match feed_mode {
        0 => "G98 F500.\n",
        1 => "G97 S1000 M03\nG99 F0.2\n",
        _ => "G50 S2000\nG96 S150 M03\nG99 F0.2\n",
    });
    text.push_str(&format!("G00 X{start}. Z0\n"));
    // One mode in a block: G103 and G187 both write P.
    let mut mode = String::new();
    for one in moves {
        let block = match *one {
            Move::Smoothness { level: 0 } => {
                mode = "G187 ".to_owned();
                continue;
            }
            Move::Smoothness { level } => {
                mode = format!("G187 P{level} ");
                continue;
            }
            Move::LookAhead { blocks } => {
                mode = format!("G103 P{blocks} ");
                continue;
            }
            Move::Rapid { u, w } => format!("G00 U{} W{}", mm(2 * i64::from(u)), mm(i64::from(w))),
            Move::Line { u, w, feed } => {
                let feed = feed.map_or_else(String::new, |feed| match feed_mode {
                    0 => format!(" F{feed}."),
                    // 0.05 to 0.5 mm/rev: slow enough for F's 0.001 mm/min.
                    _ => format!(" F{}", mm(50 + i64::from(feed) % 450)),
                });
                format!("G01 U{} W{}{feed}", mm(2 * i64::from(u)), mm(i64::from(w)))
            }
            Move::ByRadius { clockwise, u, w, stretch, long } => {
                let half = f64::from(u).hypot(f64::from(w)) / 2.0;
                let radius = (half * stretch).round() as i64 * if long { -1 } else { 1 };
                let code = if clockwise { "G02" } else { "G03" };
                format!("{code} U{} W{} R{}", mm(2 * i64::from(u)), mm(i64::from(w)), mm(radius))
            }
            Move::ByCentre { clockwise, i, k, quarters } => {
                // From the centre the start is at (-k, -i) in (Z, X); a
                // quarter turn counter-clockwise takes (z, x) to (-x, z).
                let mut from_centre = (-i64::from(k), -i64::from(i));
                for _ in 0..quarters {
                    from_centre =
                        if clockwise { (from_centre.1, -from_centre.0) } else { (-from_centre.1, from_centre.0) };
                }
                let (w, u) = (i64::from(k) + from_centre.0, i64::from(i) + from_centre.1);
                let code = if clockwise { "G02" } else { "G03" };
                format!("{code} U{} W{} I{} K{}", mm(2 * u), mm(w), mm(i64::from(i)), mm(i64::from(k)))
            }
        };
        text.push_str(&std::mem::take(&mut mode));
        text.push_str(&block);
        text.push('\n');
    }
    text.push_str("M30\n");
    text
}

proptest! {
    /// Random lathe programs expand to programs that run the same moves in
    /// the same time, by the velocity model too: the expansion leaves out
    /// only blocks before the first feed move, and the spindle, whose waits
    /// the original's time loses here.
    #[test]
    fn random_lathe_programs_expand_to_the_same_run(
        start in 20..200u32,
        feed_mode in 0..3u8,
        moves in prop::collection::vec(a_move(), 1..25),
    ) {
        let text = lathe_program(start, feed_mode, &moves);
        round_trip(&text);
        let expanded = expand(&text, 1, "RANDOM");
        let machine = lathe();
        let dynamics = run::dynamics(&machine);
        let timed = |text: &str| {
            let timing = velocity::time(&run(text, &NoFiles, &machine, BUDGET), &dynamics);
            let spindle = timing.breaks.iter().filter(|b| matches!(b.reason.reason, Reason::Spindle { .. }));
            timing.total_time() - spindle.map(|b| b.lost).sum::<f64>()
        };
        let (before, after) = (timed(&text), timed(&expanded));
        prop_assert!(within(after, before, 1e-3), "{} s, expanded {} s\n{}\n{}", before, after, text, expanded);
    }
}

#[test]
fn numbers_are_written_with_a_point_and_no_trailing_zeros() {
    use super::decimal;
    assert_eq!(
        [decimal(20_000, 3), decimal(150, 3), decimal(-2_500, 3), decimal(0, 3), decimal(15_875, 4), decimal(-1, 3)],
        ["20.", "0.15", "-2.5", "0.", "1.5875", "-0.001"]
    );
}

/// Stops and a block's stop with its move: M00 on the move, M01 alone.
#[test]
fn stops_are_written_where_the_run_had_them() {
    let mut expansion = Expansion::new(Vec::new(), &lathe(), 3, "");
    expansion.step(Step { stop: Some(Stop::Program), ..step(Motion::Rapid, Path::Straight, 5.0, 1.0, None) });
    expansion.step(Step { stop: Some(Stop::Optional), ..step(Motion::None, Path::Straight, 5.0, 1.0, None) });
    let expanded = String::from_utf8(expansion.finish().expect("written")).expect("ASCII");
    assert_eq!(expanded, "%\nO3\nG18 G21 G40 G54 G97 G98\nG00 X10. Z1. M00\nM01\nM30\n%\n");
}

/// Moves under G55, G52 and G53 are written in G54's coordinates, which
/// the expansion selects: they reach the same machine positions, arcs
/// included.
#[test]
fn offsets_are_written_in_g54s_coordinates() {
    let rows = [(54, [-100_000, -200_000, 0, 0, 0, 0]), (55, [0, -250_000, 0, 0, 0, 0])].into();
    let machine = MachineConfig { offsets: crate::machine::OffsetTable { rows }, ..lathe() };
    let text = "O7\nG54 G98 G00 X20. Z5.\nG01 Z-10. F100.\nG55 G00 X30. Z2.\nG02 X40. Z-3. R5.\nG52 Z-10.\nG01 Z-5.\nG53 X-50. Z-100.\nM30\n";
    let original = run(text, &NoFiles, &machine, BUDGET);
    assert!(original.findings.is_empty(), "{:?}", original.findings);
    let expanded = expand_on(&machine, text, 7, "OFFSETS");
    assert!(expanded.contains("G18 G21 G40 G54 G97 G98\n"), "{expanded}");
    let again = run(&expanded, &NoFiles, &machine, BUDGET);
    assert!(again.findings.is_empty(), "{:?}\n{expanded}", again.findings);
    let machine_ends = |trace: &Trace| -> Vec<[f64; 2]> {
        let axis = |letter: u8| trace.axes.iter().position(|&a| a == letter).expect("X and Z");
        let (x, z) = (axis(b'X'), axis(b'Z'));
        (0..trace.steps.len())
            .filter(|&i| matches!(trace.steps[i].motion, Motion::Rapid | Motion::Feed) && trace.steps[i].length > 0.0)
            .map(|i| {
                let end = trace.machine_end(i);
                [end[x], end[z]]
            })
            .collect()
    };
    let (before, after) = (machine_ends(&original), machine_ends(&again));
    assert_eq!(before.len(), after.len(), "{expanded}");
    for (a, b) in before.iter().zip(&after) {
        assert!((a[0] - b[0]).abs() <= 0.001 && (a[1] - b[1]).abs() <= 0.001, "{before:?}\n{after:?}\n{expanded}");
    }
    // The G53 move's machine Z-100 is G54's Z100.
    assert!(expanded.contains("Z100."), "{expanded}");
}
