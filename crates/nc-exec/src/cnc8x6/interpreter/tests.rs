use std::f64::consts::PI;

use crate::run::{
    Axes, Called, Checkpoint, Checkpoints, Closing, DELIVERY_BATCH, Environment, Motion, NoFiles, Path, Stop, Trace,
    resume_into, round3, run, run_into,
};
use crate::{
    machine::OffsetTable,
    machine::{MachineConfig, TravelLimits},
};

#[test]
fn a_streamed_run_ends_soon_after_its_sink_closes() {
    // Two nested loops: a million moves.
    let text = "%1\nN1 G91 G01 X1 F1000\nN2 X-1 G73 L1 Q999\nN3 Y.001 G73 L1 Q999\nN4 M30\n";
    let mut sink = Closing { taken: 0, room: 1 };
    let trace = run_into(text, &NoFiles, &MachineConfig::default(), 1_000_000, &mut sink);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert!(sink.taken <= 2 * DELIVERY_BATCH, "{} steps after the sink closed", sink.taken);
    assert!(trace.blocks_run <= 4 * DELIVERY_BATCH, "{} blocks run", trace.blocks_run);
}

#[test]
fn a_streamed_run_hands_on_the_steps_a_kept_run_keeps() {
    // A compensated contour longer than a delivery batch, whose steps
    // compensation fixes a block late, then a loop of a subprogram.
    let mut text = String::from("%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\n");
    for i in 0..2200 {
        text.push_str(&format!("N{} X{} Y{}\n", 4 + i, (i + 1) * 2, (i % 2) * 3));
    }
    text.push_str("N3000 G40 X5000 Y-30\nN3001 G71 L5 Q40\nN3002 M30\nN3003 G79 L5\nN3004 G91 X1\nN3005 G90 G70\n");
    let kept = run(&text, &NoFiles, &MachineConfig::default(), 10_000);
    assert!(kept.findings.is_empty(), "{:?}", kept.findings);
    assert!(kept.steps.len() > 2 * DELIVERY_BATCH);
    let mut streamed = Vec::new();
    let trace = run_into(&text, &NoFiles, &MachineConfig::default(), 10_000, &mut streamed);
    assert!(trace.steps.is_empty());
    assert_eq!(streamed, kept.steps);
    assert_eq!(Trace { steps: streamed, ..trace }, kept);
}

/// Modal state, a parameter and a zero offset set early, then blocks
/// in order, then a jump back and a subprogram call.
fn resumable_program(first_x: &str) -> String {
    let mut text = format!("%1\nN1 G54 G90 G00 X{first_x} Y0 Z5 M03 S1000\nN2 R10=5.\nN3 G01 Z-1 F300\n");
    for i in 0..40 {
        text.push_str(&format!("N{} X{} YR10\n", 4 + i, i * 3));
    }
    text.push_str("N60 G91 X2\nN61 G90 G73 L30 Q2\nN62 G71 L7 Q2\nN63 M30\n");
    text.push_str("N70 G79 L7\nN71 G91 X1\nN72 G90 G70\n");
    text
}

#[test]
fn a_run_resumed_from_a_checkpoint_goes_on_as_the_whole_run() {
    let machine = MachineConfig::default();
    let text = resumable_program("0");
    let mut whole = Checkpoints { every: 7, ..Checkpoints::default() };
    let trace = resume_into(None, &text, &NoFiles, &machine, 10_000, &mut whole);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // Blocks 0, 7, …, 42: none once the jump has run.
    assert_eq!(whole.taken.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 7, 14, 21, 28, 35, 42]);
    for checkpoint in &whole.taken {
        let mut resumed = Checkpoints { before: checkpoint.steps(), every: 7, ..Checkpoints::default() };
        let trace = resume_into(Some(checkpoint), &text, &NoFiles, &machine, 10_000, &mut resumed);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert_eq!(resumed.steps, whole.steps[checkpoint.steps()..], "from block {}", checkpoint.block());
        let later: Vec<_> = whole.taken.iter().filter(|c| c.block() >= checkpoint.block()).collect();
        assert_eq!(resumed.taken.len(), later.len());
        for (again, first) in resumed.taken.iter().zip(later) {
            assert!(again.same_course(first) && again.offset() == first.offset());
        }
    }
}

#[test]
fn checkpoints_after_an_edit_take_the_same_course_once_the_edit_no_longer_matters() {
    let machine = MachineConfig::default();
    let checkpoints = |text: &str| {
        let mut sink = Checkpoints { every: 7, ..Checkpoints::default() };
        resume_into(None, text, &NoFiles, &machine, 10_000, &mut sink);
        sink.taken
    };
    let before = checkpoints(&resumable_program("0"));
    // An absolute move written longer: the course is the same from the
    // next move on, three bytes later.
    let after = checkpoints(&resumable_program("1234"));
    for (after, before) in after.iter().zip(&before).skip(1) {
        let shifted = before.shifted(3, 0, 0);
        assert_eq!(after.offset(), shifted.offset());
        assert!(after.same_course(&shifted));
    }
    // Incremental coordinates carry the difference to the end.
    let incremental = checkpoints(&resumable_program("0").replace("N3 G01", "N3 G91 G01"));
    assert!(incremental.iter().zip(&before).skip(1).all(|(after, before)| !after.same_course(before)));
}

fn run_text(text: &str) -> Trace {
    run(text, &NoFiles, &MachineConfig::default(), 1000)
}

/// The macrocycle file L9001, and a cycle file, with the same text.
struct Library(&'static str);

impl Environment for Library {
    fn file(&self, called: &Called) -> Option<String> {
        matches!(called, Called::Number(9001) | Called::Name(_)).then(|| self.0.to_owned())
    }
}

/// Durations (s) and lengths (mm) of the blocks, rounded to a
/// microsecond and a micrometre.
fn timing(trace: &Trace) -> Vec<(f64, f64)> {
    let round = |v: f64| (v * 1e6).round() / 1e6;
    trace.steps.iter().map(|step| (round(step.duration), round(step.length))).collect()
}

fn close(actual: f64, expected: f64) {
    assert!((actual - expected).abs() < 1e-9, "{actual} != {expected}");
}

#[test]
fn rapid_and_linear_moves_take_length_over_rate() {
    let trace = run_text("%1\nN1 G00 X100 Y0\nN2 G01 X100 Y100 F600\nN3 X0 Y100 F1.2\nN4 M30\n");
    // Rapid: the longest axis travel over 10,000 mm/min; F600 is mm/min;
    // F1.2 (with a point) is m/min.
    assert_eq!(timing(&trace), [(0.6, 100.0), (10.0, 100.0), (5.0, 100.0), (0.0, 0.0)]);
    assert_eq!(trace.steps[1].feed, Some(600.0));
    assert_eq!(trace.steps[2].feed, Some(1200.0));
    close(trace.totals().total_time, 15.6);
    close(trace.totals().time(Motion::Rapid), 0.6);
    close(trace.totals().length(Motion::Feed), 200.0);
    let end = trace.end_position();
    assert_eq!([b'X', b'Y', b'Z'].map(|axis| end[usize::from(axis - b'A')]), [0.0, 100.0, 0.0]);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

#[test]
fn feed_per_revolution_follows_the_spindle() {
    // F200 under G95 is 200 µm/rev, F0.5 is 0.5 mm/rev; at S500 that is
    // 100 and 250 mm/min.
    let trace = run_text("%1\nN1 G95 S500 G01 X10 F200\nN2 X20 F0.5\nN3 M30\n");
    assert_eq!(timing(&trace)[..2], [(6.0, 10.0), (2.4, 10.0)]);
    assert_eq!(trace.steps[1].feed, Some(250.0));
}

#[test]
fn constant_cutting_speed_turns_the_spindle_by_the_radius() {
    use std::f64::consts::TAU;
    // G97: CSS with feed per revolution; S1000 is 100 m/min. Facing
    // from X50 to X10 at 0.2 mm/rev: the time is the integral of
    // 2πr / (f·v) over the path, 40 mm × 2π × 30 mm / (0.2 × 100,000).
    let text = "%1\nN1 G00 X50 Z0\nN2 G97 S1000 G01 X10 F0.2\nN3 G95 X20 F0.1\nN4 M30\n";
    let trace = run_text(text);
    close6(trace.steps[1].duration, 40.0 * TAU * 30.0 / (0.2 * 100_000.0) * 60.0);
    // When CSS ends without a new S, S keeps the speed reached at X10.
    let reached = 100_000.0 / (TAU * 10.0);
    close6(trace.steps[2].duration, 10.0 / (0.1 * reached) * 60.0);
    // With `G76 S1000` the spindle stops speeding up at the radius
    // where 100 m/min needs 1000 rpm.
    let text = "%1\nN1 G00 X50 Z0\nN2 G76 S1000\nN3 G97 S1000 G01 X10 F0.2\nN4 M30\n";
    let limit_radius = 100_000.0 / (TAU * 1000.0);
    let expected = TAU * (50.0f64.powi(2) - limit_radius.powi(2)) / 2.0 / (0.2 * 100_000.0)
        + (limit_radius - 10.0) / (0.2 * 1000.0);
    close6(run_text(text).steps[2].duration, expected * 60.0);
    // G96 is CSS with feed per minute: the spindle does not change the time.
    let trace = run_text("%1\nN1 G00 X50\nN2 G96 S1000 G01 X10 F200\nN3 M30\n");
    close6(trace.steps[1].duration, 12.0);
    // Machine constant 329 decade 3 = 3 swaps G96/G97 and reads S in
    // m/min: the manual's `G96 G1 F200 S90 X50` is 90 m/min, 0.2 mm/rev.
    let mut machine = MachineConfig::default();
    machine.constants.insert(329, 300);
    let text = "%1\nN1 G00 X100\nN2 G96 G1 F200 S90 X50\nN3 M30\n";
    let trace = run(text, &NoFiles, &machine, 100);
    close6(trace.steps[1].duration, 50.0 * TAU * 75.0 / (0.2 * 90_000.0) * 60.0);
}

#[test]
fn arcs_and_compensation_run_in_the_machine_s_planes() {
    // Axes X, Z: the default G17 plane 12 is X-Z, so I runs along X and J
    // along Z, as the checker reads them.
    let lathe = MachineConfig { axes: b"XZ".to_vec(), diameter_axis: Some(b'X'), ..MachineConfig::default() };
    let text = "%1\nN1 G75 G00 X20 Z0\nN2 G02 X20 Z-20 I0 J-10 F100\nN3 M30\n";
    let trace = run(text, &NoFiles, &lathe, 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.steps[1].path, Path::Arc { plane: (b'X', b'Z'), centre: [20.0, -10.0], clockwise: true });
    // R340 = 21 swaps them: I along Z.
    let swapped = MachineConfig { constants: [(340, 21)].into(), ..lathe.clone() };
    let text = "%1\nN1 G75 G00 X20 Z0\nN2 G02 X20 Z-20 I-10 F100\nN3 M30\n";
    let trace = run(text, &NoFiles, &swapped, 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.steps[1].path, Path::Arc { plane: (b'Z', b'X'), centre: [-10.0, 20.0], clockwise: true });
    // The refinement E takes 1 µm off J: the end is then on the circle, and
    // without it 2 µm off, beyond the 1 µm tolerance.
    let text = |e: &str| format!("%1\nN1 G75 G00 X20 Z0\nN2 G02 X20 Z-20.004 I0 J-10.001 {e} F100\nN3 M30\n");
    assert!(run(&text("E-10001.000"), &NoFiles, &lathe, 100).findings.is_empty());
    assert!(run(&text(""), &NoFiles, &lathe, 100).findings[0].message.contains("does not lie on the circle"));
    // G18's plane names axis 3, which the lathe does not have.
    let text = "%1\nN1 G18 G00 X20 Z0 D1\nN2 G42 G01 Z-20 F100\nN3 G40 X30\nN4 M30\n";
    let trace = run(text, &NoFiles, &lathe, 100);
    let messages: Vec<&str> = trace.findings.iter().map(|finding| finding.message.as_str()).collect();
    assert_eq!(messages.len(), 1, "{messages:?}");
    assert!(messages[0].starts_with("radius compensation in the plane of G18, which this machine does not have"));
    assert!(trace.compensated.is_empty());
}

#[test]
fn diameter_programming_halves_the_diameter_axis() {
    use std::f64::consts::TAU;
    let lathe = MachineConfig {
        axes: b"XZ".to_vec(),
        diameter_axis: Some(b'X'),
        cycle_file: Some("PEVNECY5.NCP".to_owned()),
        ..MachineConfig::default()
    };
    let run_lathe = |text: &str| run(text, &NoFiles, &lathe, 1000);
    let text =
        "%1\nN1 G00 X40 Z0\nN2 G01 X50 F600\nN3 G91 X10\nN4 G90 G75 X20\nN5 G74 X20.001\nN6 G04 Q1\nN7 X30\nN8 M30\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
    // G74 is the lathe's start; G04 in group G10 does not end it.
    assert_eq!(x[..7], [20.0, 25.0, 30.0, 20.0, 10.0005, 10.0005, 15.0]);
    assert_eq!(timing(&trace)[1], (0.5, 5.0));
    // Constant cutting speed turns by the radius: facing from Ø100 to
    // Ø20 takes what it takes from radius 50 to 10.
    let trace = run_lathe("%1\nN1 G00 X100 Z0\nN2 G97 S1000 G01 X20 F0.2\nN3 M30\n");
    close6(trace.steps[1].duration, 40.0 * TAU * 30.0 / (0.2 * 100_000.0) * 60.0);
    // A built-in lathe cycle computes in diameters and runs in radii:
    // G82's first chip ends at Ø62 (see the cycles' own test).
    let text =
        "%1\nN1 G00 X104 Z2\nN2 R24=-4. R25=-2. R26=200 R27=0.001 R28=3. R29=2. R30=-40. R31=-10. G82\nN3 G80 M30\n";
    let trace = run_lathe(text);
    let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
    assert_eq!(x[2..6], [52.0, 31.0, 31.0, 52.0]);
}

fn close6(actual: f64, expected: f64) {
    assert!((actual - expected).abs() < 1e-6 * expected.abs().max(1.0), "{actual} != {expected}");
}

#[test]
fn program_stops_are_marked_on_their_block() {
    let trace = run_text("%1\nN1 G00 X1 M00\nN2 M01\nN3 M30\n");
    let stops: Vec<Option<Stop>> = trace.steps.iter().map(|step| step.stop).collect();
    assert_eq!(stops, [Some(Stop::Program), Some(Stop::Optional), None]);
}

#[test]
fn a_thread_turns_at_its_lead_after_the_zero_pulse() {
    // 15 mm at 1.5 mm/rev and S500: 0.02 min, plus half a revolution's
    // wait for the zero pulse, 0.001 min.
    let trace = run_text("%1\nN1 S500 M03 G00 X10 Z0\nN2 G33 Z-15. F1.5\nN3 M30\n");
    close6(trace.steps[1].duration, (0.02 + 0.001) * 60.0);
    assert_eq!(trace.steps[1].motion, Motion::Feed);
}

/// Drilling at X20 and X30 with G81 (RA Z2, RB Z-10, RC Z5, R26 F100),
/// cancelled by G80 at X40.
const DRILLING: &str =
    "%1\nN1 R26=100 R27=1000 R30=2. R31=-10. R32=5. M03\nN2 G00 X10 Y10 Z5\nN3 G81 X20\nN4 X30\nN5 G80 X40\nN6 M30\n";

/// What each step did: the block's line, the motion and Z at its end.
fn drilled(trace: &Trace) -> Vec<(String, Motion, f64)> {
    let z = usize::from(b'Z' - b'A');
    trace
        .steps
        .iter()
        .map(|s| (DRILLING[s.range].split(' ').next().unwrap().to_owned(), s.motion, trace.position(&s.end)[z]))
        .collect()
}

#[test]
fn a_built_in_cycle_runs_after_each_block_until_g80() {
    let trace = run_text(DRILLING);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let n = |s: &str| s.to_owned();
    let drill =
        |block: &str| [(n(block), Motion::Rapid, 2.0), (n(block), Motion::Feed, -10.0), (n(block), Motion::Rapid, 5.0)];
    let mut expected = vec![(n("N1"), Motion::None, 0.0), (n("N2"), Motion::Rapid, 5.0), (n("N3"), Motion::Rapid, 5.0)];
    expected.extend(drill("N3"));
    expected.push((n("N4"), Motion::Rapid, 5.0));
    expected.extend(drill("N4"));
    expected.extend([(n("N5"), Motion::Rapid, 5.0), (n("N6"), Motion::None, 5.0)]);
    assert_eq!(drilled(&trace), expected);
    // 12 mm at F100, twice.
    close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 100.0 * 60.0);
}

#[test]
fn a_cycle_file_body_runs_and_the_state_before_it_returns() {
    // The body feeds with G01 and R26; back in the program, G00 and no
    // F are in force again, so N4 and N5 are rapids.
    let body = "\"$PC\nN1 G79 L81\nN2 G00 G90 ZR30\nN3 G01 ZR31 FR26\nN4 G00 G70 ZR32\n*\n";
    let machine = MachineConfig { cycle_file: Some("PC.NCP".to_owned()), ..MachineConfig::default() };
    let trace = run(DRILLING, &Library(body), &machine, 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.files, [Called::Name("PC.NCP".to_owned())]);
    let lines: Vec<(usize, Motion)> = trace.steps.iter().map(|s| (s.source, s.motion)).collect();
    let body_steps = [(1, Motion::Rapid), (1, Motion::Feed), (1, Motion::Rapid)];
    let mut expected = vec![(0, Motion::None), (0, Motion::Rapid), (0, Motion::Rapid)];
    expected.extend(body_steps);
    expected.push((0, Motion::Rapid));
    expected.extend(body_steps);
    expected.extend([(0, Motion::Rapid), (0, Motion::None)]);
    assert_eq!(lines, expected);
    close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 100.0 * 60.0);
    // The block's own flow goes on after the body: a jump that repeats
    // the drilling block once, then M30 in a drilling block.
    let text = "%1\nN1 R26=100 R27=1000 R30=2. R31=-10. R32=5. M03\nN2 G00 G81 X20\nN3 G91 X10 G73 L3 Q1\nN4 X10 M30\nN5 X500\n";
    let trace = run(text, &Library(body), &machine, 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let drilled_at: Vec<f64> =
        trace.steps.iter().filter(|step| step.motion == Motion::Feed).map(|step| trace.axis(&step.end, b'X')).collect();
    assert_eq!(drilled_at, [20.0, 30.0, 40.0, 50.0]);
    // Without the file, the built-in cycle runs and says why.
    let trace = run(DRILLING, &NoFiles, &machine, 1000);
    let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
    assert_eq!(
        messages,
        ["the cycle file PC.NCP the machine names is not in the project: the built-in cycle runs instead"]
    );
    close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 100.0 * 60.0);
}

/// Lengths of the steps, to the micrometre.
fn lengths(trace: &Trace) -> Vec<f64> {
    trace.steps.iter().map(|step| (step.length * 1000.0).round() / 1000.0).collect()
}

#[test]
fn zero_offsets_move_the_program_zero() {
    // G54 is X+100: the same programmed X10 is 100 mm further.
    let mut machine = MachineConfig::default();
    (machine.offsets, _) = OffsetTable::parse("$POS\nG54: X=100.0\n", &machine.axes);
    let trace = run("%1\nN1 G00 X10\nN2 G54 X10\nN3 M30\n", &NoFiles, &machine, 100);
    assert_eq!(lengths(&trace)[..2], [10.0, 100.0]);
    assert_eq!([trace.axis(&trace.steps[1].end, b'X'), trace.axis(&trace.machine_end(1), b'X')], [10.0, 110.0]);
    assert_eq!(trace.axis(&trace.start_of(1), b'X'), -90.0);

    // G92 writes the G55 row and moves nothing; the offset holds from
    // the next block.
    let trace = run_text("%1\nN1 G55 G92 X100.5 Y200.\nN2 G00 X0 Y0\nN3 M30\n");
    assert_eq!(lengths(&trace)[..2], [0.0, 223.831]); // √(100.5² + 200²)

    // G93 X10. at X30 puts the program zero 10 mm behind the tool: the
    // row becomes 0 + 30 − 10 = 20 (01 §5.7, case 2).
    let trace = run_text("%1\nN1 G00 X30\nN2 G55 G93 X10.\nN3 G00 X10\nN4 X0\nN5 M30\n");
    assert_eq!(lengths(&trace)[..4], [30.0, 0.0, 0.0, 10.0]);
    assert_eq!(trace.axis(&trace.machine_end(3), b'X'), 20.0);
}

#[test]
fn length_corrections_shift_the_path_from_their_first_linear_block() {
    // D1 has Z length 50: `&0010` adds it to Z (axis 3) in the next G00
    // block; `&0` takes it off again.
    let text = "%1\nN1 G92 D1 R3=50.\nN2 D1 &0010 G00 Z0\nN3 Z10\nN4 &0\nN5 Z10\nN6 M30\n";
    let trace = run_text(text);
    assert_eq!(lengths(&trace)[..5], [0.0, 50.0, 10.0, 0.0, 50.0]);
    assert_eq!(trace.axis(&trace.machine_end(2), b'Z'), 60.0);
}

#[test]
fn radius_compensation_runs_the_tool_centre_path() {
    // Radius 5 on the left (G41) of a corner turning left: the start
    // move ends on the first line's normal at (0, 5), the inside corner
    // is the intersection (45, 5), the last line ends on its normal at
    // (45, 50), and G40 leaves from there for (70, 70).
    let text =
        "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 Y50\nN6 G40 X70 Y70\nN7 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(lengths(&trace)[..6], [0.0, 20.0, 25.0, 45.0, 45.0, 32.016]);
    close6(trace.steps[5].duration, 25.0f64.hypot(20.0) / 10.0);
    close6(trace.totals().total_time, 20.0 / 10_000.0 * 60.0 + (25.0 + 45.0 + 45.0 + 25.0f64.hypot(20.0)) / 10.0);
    // An arc too small for the tool on its inside stops the run there.
    let text = "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 G03 X0 Y6 I0 J3\nN5 G40 G01 X0 Y20\nN6 M30\n";
    let trace = run_text(text);
    let fatal: Vec<&str> = trace.findings.iter().filter(|f| f.stops()).map(|f| text[f.range].trim_end()).collect();
    assert_eq!(fatal, ["N4 G03 X0 Y6 I0 J3"]);
}

#[test]
fn mirroring_reverses_axes_arcs_and_the_compensation_side() {
    let trace = run_text("%1\nN1 G35 X0\nN2 G01 X10 Y5 F600\nN3 G02 X20 Y5 I5 J0\nN4 G34\nN5 G01 X0 Y0\nN6 M30\n");
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let ends: Vec<(f64, f64)> =
        trace.steps.iter().map(|step| (trace.axis(&step.end, b'X'), trace.axis(&step.end, b'Y'))).collect();
    assert_eq!(ends[..5], [(0.0, 0.0), (-10.0, 5.0), (-20.0, 5.0), (-20.0, 5.0), (0.0, 0.0)]);
    // The clockwise half circle over the top turns counter-clockwise
    // about the mirrored centre, still over the top.
    assert_eq!(trace.steps[2].path, Path::Arc { plane: (b'X', b'Y'), centre: [-15.0, 5.0], clockwise: false });
    close6(trace.steps[2].length, PI * 5.0);
    // Compensation G41 on the mirrored contour runs on the right: the
    // tool-centre path is the mirror image, with the same lengths.
    let text = "%1\nN10 G35 X0\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 Y50\nN6 G40 X70 Y70\nN7 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(lengths(&trace)[1..7], [0.0, 20.0, 25.0, 45.0, 45.0, 32.016]);
}

#[test]
fn scale_multiplies_the_programmed_lengths() {
    let trace = run_text("%1\nN1 G36 X2\nN2 G01 X10 F600\nN3 G36 X1 Y4\nN4 G91 X8\nN5 G36\nN6 X1\nN7 M30\n");
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
    assert_eq!(x[..6], [0.0, 20.0, 20.0, 22.0, 22.0, 23.0]);
    assert_eq!(timing(&trace)[1], (2.0, 20.0));
    // A scale of 0 stops the run at its G36.
    let text = "%1\nN1 G36 X1 Y0\nN2 G01 X10 F600\nN3 M30\n";
    let trace = run_text(text);
    let fatal: Vec<&str> = trace.findings.iter().filter(|f| f.stops()).map(|f| &text[f.range]).collect();
    assert_eq!(fatal, ["G36"]);
    assert_eq!(trace.steps.len(), 0);
}

#[test]
fn the_independent_offset_adds_to_the_zero_offset() {
    let trace = run_text("%1\nN1 G37 X10 Y-5\nN2 G00 X1 Y1\nN3 G37\nN4 G00 X1 Y1\nN5 M30\n");
    let machine = |index: usize| {
        let end = trace.machine_end(index);
        (trace.axis(&end, b'X'), trace.axis(&end, b'Y'))
    };
    // The tool stays at the machine zero when G37 comes: its program
    // position moves the other way.
    assert_eq!([machine(0), machine(1), machine(2), machine(3)], [(0.0, 0.0), (11.0, -4.0), (11.0, -4.0), (1.0, 1.0)]);
    assert_eq!(trace.axis(&trace.start_of(1), b'X'), -10.0);
    assert_eq!(lengths(&trace)[..4], [0.0, 137f64.sqrt(), 0.0, 125f64.sqrt()].map(round3));
}

#[test]
fn a_planar_transformation_turns_the_real_axes() {
    // The real system turned 90° and shifted by (10, 0): the program
    // runs in fictive coordinates, the axes move in real ones.
    let machine = MachineConfig { rapid_rates: [(b'X', 5_000)].into(), ..MachineConfig::default() };
    let text =
        "%1\nN1 G38 X10 Y0 I90\nN2 G38\nN3\nN4 G00 X10 Y10\nN5 G01 X20 F600\nN6 G38 I0\nN7\nN8 G01 X0 Y0\nN9 M30\n";
    let trace = run(text, &NoFiles, &machine, 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let at = |values: Axes| (round3(trace.axis(&values, b'X')), round3(trace.axis(&values, b'Y')));
    // Activated at the machine zero, the tool is at fictive (10, 0).
    assert_eq!(at(trace.steps[2].end), (10.0, 0.0));
    assert_eq!(at(trace.machine_end(2)), (0.0, 0.0));
    // Fictive Y is real X, which rapids at half the rate.
    assert_eq!(at(trace.machine_end(3)), (10.0, 0.0));
    assert_eq!(timing(&trace)[3], (0.12, 10.0));
    assert_eq!(at(trace.machine_end(4)), (10.0, -10.0));
    // Cancelled, the program takes the real position again.
    assert_eq!(at(trace.steps[6].end), (10.0, -10.0));
    assert_eq!(lengths(&trace)[..8], [0.0, 0.0, 0.0, 10.0, 10.0, 0.0, 0.0, 200f64.sqrt()].map(round3));
}

#[test]
fn the_spatial_transformation_and_what_the_control_refuses() {
    let text = "%1\nN1 G31 X0 Y0 Z0 I0 J0 K9000 E100\nN2 G31\nN3\nN4 G01 X10 F600\nN5 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let end = trace.machine_end(3);
    let real = [b'X', b'Y', b'Z'].map(|axis| round3(trace.axis(&end, axis)));
    assert_eq!(real, [0.0, -10.0, 0.0]);
    // Activating without parameters goes on without it; setting them
    // while active stops the run.
    let text = "%1\nN1 G39\nN2 G39 X0 Y0 I30\nN3 G39\nN4 G39 X1 Y1 I30\nN5 M30\n";
    let trace = run_text(text);
    let findings: Vec<(&str, bool)> = trace.findings.iter().map(|f| (text[f.range].trim_end(), f.stops())).collect();
    assert_eq!(findings, [("G39", false), ("G39", true)]);
    assert_eq!(&text[trace.findings[1].range.start().into()..][..2], "G3");
    assert!(trace.findings[1].message.contains("cannot change while it is active"));
}

#[test]
fn operation_51_messages_are_kept_with_their_block() {
    use crate::run::{Message, MessageDisplay};
    let trace = run_text("%1\nN1 G00 X10\nN2 R30=12.5 R5=51073053 G26\nN3 R5=51073050 G26\nN4 M30\n");
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let shown: Vec<(usize, Message)> = trace.messages.iter().map(|m| (m.step, m.message)).collect();
    let message = |value, display| Message { code: 7, parameter: 30, value, display };
    assert_eq!(
        shown,
        [(1, message(Some(12_500), MessageDisplay::Seconds(5))), (2, message(Some(12_500), MessageDisplay::Cancel))]
    );
}

#[test]
fn operation_49_reads_the_block_registers() {
    // S into R26 (F800), the motion code into R20 (G01), the spindle's
    // M code into R21 (M04), T into R22 and D into R23; dwells show them.
    let text = "%1\nN1 S800 M04 T3 D2\nN2 R5=49550026 G26\nN3 G01 X10 FR26\nN4 R5=49520020 R6=49510221 R7=49560022 R8=49580023 G29\nN5 G00 X0\nN6 GR20 X10\nN7 G04 QR21\nN8 G04 QR22\nN9 G04 QR23\nN10 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let times: Vec<f64> = timing(&trace).iter().map(|&(duration, _)| duration).collect();
    assert_eq!(times[2], 0.75);
    assert_eq!((trace.steps[5].motion, times[5]), (Motion::Feed, 0.75));
    assert_eq!(times[6..9], [0.04, 0.03, 0.02]);
}

#[test]
fn g23_i_selects_the_dynamic_set_and_steps_tell_which_lines_may_merge() {
    let trace = run_text(
        "%1\nN1 G23 I2 G01 X10 F600\nN2 X20\nN3 G23 I1 X30\nN4 G23 I7 X40\nN5 X40.003\nN6 X41 S500\nN7 G91 X1\nN8 G90 G00 X0\nN9 M30\n",
    );
    let sets: Vec<u8> = trace.steps.iter().map(|step| step.dynamic_set).collect();
    assert_eq!(sets, [2, 2, 1, 1, 1, 1, 1, 1, 1]);
    let mergeable: Vec<bool> = trace.steps.iter().map(|step| step.mergeable).collect();
    assert_eq!(mergeable, [false, true, true, true, true, false, false, false, false]);
    let messages: Vec<&str> = trace.findings.iter().map(|finding| finding.message.as_str()).collect();
    assert_eq!(messages, ["G23 I7: the dynamic sets are I1 to I4: the set in force stays"]);
}

#[test]
fn incremental_moves_add_to_the_position() {
    let trace = run_text("%1\nN1 G91 G01 X10 Y10 F600\nN2 X10\nN3 G90 X0\nN4 M30\n");
    let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
    assert_eq!(x, [10.0, 20.0, 0.0, 0.0]);
}

#[test]
fn arcs_run_the_way_their_code_turns() {
    let r = 10.0;
    // From (10,0) about the origin to (0,10): a quarter counter-clockwise,
    // three quarters clockwise; back to the start is a full circle.
    let trace = run_text(
        "%1\nN1 G00 X10 Y0\nN2 G03 X0 Y10 I-10 F600\nN3 G00 X10 Y0\nN4 G02 X0 Y10 I-10\nN5 G00 X10 Y0\nN6 G02 X10 Y0 I-10\nN7 M30\n",
    );
    let lengths: Vec<f64> = trace.steps.iter().map(|step| step.length).collect();
    close(lengths[1], PI * r / 2.0);
    close(lengths[3], 3.0 * PI * r / 2.0);
    close(lengths[5], 2.0 * PI * r);
    close(trace.steps[5].duration, 2.0 * PI * r / 600.0 * 60.0);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

#[test]
fn in_the_zx_plane_i_measures_along_z() {
    // The manual's example 7b: from Z500 to Z100 about Z300, radius 200.
    let trace = run_text("%1\nN1 G00 X100 Z500\nN2 G03 G90 X100.0 Z100.0 I-200.0 F1000\nN3 M30\n");
    close(trace.steps[1].length, PI * 200.0);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

#[test]
fn a_helix_adds_its_lead() {
    let trace = run_text("%1\nN1 G00 X10 Y0 Z0\nN2 G03 X10 Y0 Z5 I-10 F600\nN3 M30\n");
    close(trace.steps[1].length, ((2.0 * PI * 10.0f64).powi(2) + 25.0).sqrt());
}

#[test]
fn bad_arcs_and_missing_feed_are_reported_where_they_are() {
    let text = "%1\nN1 G01 X10\nN2 G02 X5\nN3 G02 X20 Y0 I3 F100\nN4 M30\n";
    let trace = run_text(text);
    let found: Vec<(&str, &str, bool)> =
        trace.findings.iter().map(|f| (&text[f.range], f.message.split(':').next().unwrap_or(""), f.stops())).collect();
    assert_eq!(
        found,
        [
            ("N1 G01 X10\n", "no feed F programmed before this motion", false),
            (
                "N2 G02 X5\n",
                "an arc needs both coordinates of its plane, even when the end point equals the start",
                false
            ),
            ("N3 G02 X20 Y0 I3 F100\n", "the end point does not lie on the circle", true),
        ]
    );
    // The control stops with error 7.56 before the arc runs.
    assert_eq!(lines_run(text, &trace), ["N1 G01 X10", "N2 G02 X5"]);
    assert!(trace.steps.iter().all(|step| step.duration == 0.0));
}

#[test]
fn machine_constant_55_widens_the_arc_end_tolerance() {
    // The end point lies 3 µm outside the circle of radius 10.
    let text = "%1\nN1 G00 X10 Y0\nN2 G02 X-10.003 Y0 I-10 F100\nN3 M30\n";
    let stopped = run_text(text);
    assert_eq!(stopped.findings.iter().filter(|f| f.stops()).count(), 1, "{:?}", stopped.findings);
    assert_eq!(stopped.steps.len(), 1);
    let machine = MachineConfig { constants: [(55, 5)].into(), ..MachineConfig::default() };
    let trace = run(text, &NoFiles, &machine, 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.steps.len(), 3);
}

#[test]
fn a_block_with_motion_and_g04_moves_then_dwells() {
    // 15 mm at F100 take 9 s, then 300 × 10 ms.
    let text = "%1\nN1 G00 X0 Y0 Z5\nN2 G01 Z-10 F100 G04 Q300\nN3 G00 Z5\nN4 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let motions: Vec<(String, Motion)> =
        trace.steps.iter().map(|step| (text[step.range].trim_end().to_owned(), step.motion)).collect();
    let n2 = "N2 G01 Z-10 F100 G04 Q300".to_owned();
    assert_eq!(motions[1..3], [(n2.clone(), Motion::Feed), (n2, Motion::Dwell)]);
    assert_eq!(timing(&trace)[1..4], [(9.0, 15.0), (3.0, 0.0), (0.09, 15.0)]);
    assert_eq!(trace.axis(&trace.steps[2].end, b'Z'), -10.0);
    // The manual's G82 of the cycle file drills, then dwells at the
    // bottom (R29 = 250: 2.5 s).
    let body = "\"$PC\nN1 G79 L82\nN2 G00 G90 ZR30 FR26 SR27\nN3 G01 ZR31 G04 QR29\nN4 G00 ZR32\nN5 G70\n*\n";
    let machine = MachineConfig { cycle_file: Some("PC.NCP".to_owned()), ..MachineConfig::default() };
    let text =
        "%1\nN1 R26=100 R27=1000 R29=250 R30=2. R31=-10. R32=5. M03\nN2 G00 X10 Y10 Z5\nN3 G82 X20\nN4 G80 M30\n";
    let trace = run(text, &Library(body), &machine, 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let body_steps: Vec<(Motion, f64, f64)> = trace
        .steps
        .iter()
        .filter(|step| step.source == 1)
        .map(|step| (step.motion, round3(step.duration), trace.axis(&step.end, b'Z')))
        .collect();
    assert_eq!(
        body_steps,
        [
            (Motion::Rapid, 0.018, 2.0),
            (Motion::Feed, 7.2, -10.0),
            (Motion::Dwell, 2.5, -10.0),
            (Motion::Rapid, 0.09, 5.0),
            (Motion::None, 0.0, 5.0),
        ]
    );
    // The manual's G86 pecks R28 deeper each time and dwells there.
    let body = "\"$PC\nN1 G79 L86\nN3 FR26 SR27\n   G27 R5=07280028\n       R6=16313034\nN4 GR34 L100\nN10 G00 G90 ZR30\n    G26 R5=00300024\nN20 G27 R5=02242824\n        R6=15312423\nN30 GR23 L60\nN40 G01  ZR24 G04 QR29\nN50 G73 L20 Q9998\nN60 ZR31\nN70 G70 G00 ZR32\n*\n";
    let text =
        "%1\nN1 R26=100 R27=1000 R28=3. R29=50 R30=2. R31=-10. R32=5. M03\nN2 G00 X10 Y10 Z5\nN3 G86 X20\nN4 G80 M30\n";
    let trace = run(text, &Library(body), &machine, 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let pecks: Vec<(Motion, f64)> = trace
        .steps
        .iter()
        .filter(|step| matches!(step.motion, Motion::Feed | Motion::Dwell))
        .map(|step| (step.motion, trace.axis(&step.end, b'Z')))
        .collect();
    let (feed, dwell) = (Motion::Feed, Motion::Dwell);
    let expected = [(feed, -1.0), (dwell, -1.0), (feed, -4.0), (dwell, -4.0), (feed, -7.0), (dwell, -7.0)];
    // The last peck reaches R31, where N60's feed ends too.
    assert_eq!(pecks[..6], expected);
    assert_eq!(pecks[6..], [(feed, -10.0), (dwell, -10.0), (feed, -10.0)]);
}

#[test]
fn g58_and_g59_hold_in_their_own_block_and_g92_writes_their_row() {
    let text = "%1\nN1 G55 G92 X10.\nN2 G58 G92 X100.\nN3 G59 G92 X200.\nN4 G00 X0\nN5 G58 X0\nN6 X0\nN7 G59 X0\nN8 X0\nN9 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let machine_x: Vec<f64> = (3..8).map(|step| trace.axis(&trace.machine_end(step), b'X')).collect();
    assert_eq!(machine_x, [10.0, 100.0, 10.0, 200.0, 10.0]);
}

#[test]
fn a_helix_drives_its_lead_axis_by_the_turns_of_the_arc() {
    use std::f64::consts::TAU;
    // The manual's helix: lead 1.05 mm on Z, a full circle of radius
    // 100 run 21 times (Q20), then a half circle; after G98 an arc
    // leaves Z alone.
    let text = "%1\nN5 X0 Y0 Z0 G00\nN10 Z1.05 G10\nN50 G09 G02 X0 Y0 I100 G73 L50 Q20 F1000\nN60 X200. Y0 I100\nN70 G98\nN75 G02 X200 Y0 I-100\nN80 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let z: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'Z')).collect();
    // The lead block does not move.
    assert_eq!(z[..3], [0.0, 0.0, 1.05]);
    assert_eq!(z[21..], [21.0, 22.05, 22.575, 22.575, 22.575, 22.575]);
    let turn = (TAU * 100.0).hypot(1.05);
    let half = (TAU / 2.0 * 100.0).hypot(0.525);
    close6(trace.steps[2].length, turn);
    close6(trace.steps[23].length, half);
    close6(trace.steps[25].length, TAU * 100.0);
    let length = 21.0 * turn + half + TAU * 100.0;
    close6(trace.totals().length(Motion::Feed), length);
    close6(trace.totals().time(Motion::Feed), length / 1000.0 * 60.0);
    assert_eq!(trace.axis(&trace.steps[23].end, b'X'), 200.0);
}

#[test]
fn m37_runs_the_feed_at_a_hundredth_until_m36() {
    let text = "%1\nN1 G01 X100 F1000\nN2 M37\nN3 X200\nN4 G00 X0\nN5 G95 S500 G01 X10 F200\nN6 M36\nN7 G94 X110 F1000\nN8 M37 S500 G33 Z-15. F1.5\nN9 M30\n";
    let trace = run_text(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // 100 mm at 10 mm/min; the rapid is not a feed; 200 µm/rev at S500
    // is 100 mm/min, 1 mm/min under M37; after M36 the feed is F again.
    let feeds: Vec<Option<f64>> = trace.steps.iter().map(|step| step.feed).collect();
    assert_eq!(feeds[..7], [Some(1000.0), None, Some(10.0), None, Some(1.0), None, Some(1000.0)]);
    let times: Vec<f64> = timing(&trace).iter().map(|&(duration, _)| duration).collect();
    assert_eq!(times[..7], [6.0, 0.0, 600.0, 1.2, 600.0, 0.0, 6.0]);
    // A thread's F is its lead: 15 mm at 1.5 mm/rev and S500.
    close6(trace.steps[7].duration, (0.02 + 0.001) * 60.0);
    // The built-in cycles feed under it too: 12 mm at F100 / 100.
    let trace = run_text(&DRILLING.replace("M03", "M03 M37"));
    close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 1.0 * 60.0);
}

/// The fatal findings of a run: where (the text) and what.
fn stops<'t>(text: &'t str, trace: &'t Trace) -> Vec<(&'t str, &'t str)> {
    trace.findings.iter().filter(|f| f.stops()).map(|f| (&text[f.range], f.message.as_str())).collect()
}

#[test]
fn a_value_the_control_refuses_stops_the_run_in_the_checkers_words() {
    let overflow = "the parameter holds 0.123 (123 as digits, 3 decades) but `{}` takes at most 2: the control stops with \"an R of more than 2 decades cannot be substituted\"";
    // The manual's example: three decades into G's two.
    let text = "%1\nN10 R10=123\nN20 GR10\nN30 G00 X10\nN40 M30\n";
    let trace = run_text(text);
    assert_eq!(stops(text, &trace), [("R10", overflow.replace("{}", "G").as_str())]);
    assert_eq!(trace.findings.len(), 1, "{:?}", trace.findings);
    assert_eq!(lines_run(text, &trace), ["N10 R10=123"]);
    // In a subprogram.
    let text = "%1\nN10 R10=123\nN20 G71 L5\nN30 M30\nN40 G79 L5\nN50 MR10\nN60 G70\n";
    let trace = run_text(text);
    assert_eq!(stops(text, &trace), [("R10", overflow.replace("{}", "M").as_str())]);
    for (text, at, message) in [
        ("%1\nN1 G01 X10 F-100\nN2 M30\n", "-100", "`F` takes only unsigned values; remove the sign"),
        (
            "%1\nN1 G26 R5=99010203\nN2 M30\n",
            "99010203",
            "`99010203` is outside the parameter range -69999.999 to 69999.999",
        ),
        (
            "%1\nN1 R10=-100\nN2 G01 X10 FR10\nN3 M30\n",
            "R10",
            "the parameter holds -0.100, but `F` takes only unsigned values",
        ),
        (
            "%1\nN10 G1 X99999999999999999999 F100\nN20 M30\n",
            "99999999999999999999",
            "`X99999999999999999999` has 20 digits before the point; the format of `X` allows 5",
        ),
        ("%1\nN1 R96=5\nN2 M30\n", "96", "R96: the control has parameters R0 to R95"),
        ("%1\nN1 G01 XR100 F100\nN2 M30\n", "100", "R100: the control has parameters R0 to R95"),
        (
            "%1\nN1 G92 D1 R0=5.\nN2 &0031 D1\nN3 M30\n",
            "0031",
            "`&0031`: each digit assigns one axis's length correction and must be 0 (off), 1 (add) or 2 (subtract)",
        ),
        (
            "%1\nN1 G92 D1 R0=5.\nN2 R10=13\nN3 &R10 D1\nN4 M30\n",
            "R10",
            "the parameter holds 0.013 (read as `&13`): each `&` digit must be 0, 1 or 2",
        ),
    ] {
        let trace = run_text(text);
        assert_eq!(stops(text, &trace), [(at, message)], "{text}");
        assert!(trace.steps.iter().all(|step| step.motion == Motion::None), "{text}");
    }
}

#[test]
fn a_move_beyond_the_axis_range_or_the_travel_limits_stops_the_run() {
    // G91 X1000 repeated: the 70th would reach X70000.
    let text = "%1\nN1 G91 G00 X1000\nN2 G73 L1 Q999\nN3 M30\n";
    let trace = run(text, &NoFiles, &MachineConfig::default(), 10_000);
    let message = "X would reach 70000.000, outside the range of `X`: -69999.999 to 69999.999: the control stops";
    assert_eq!(stops(text, &trace), [("N1 G91 G00 X1000\n", message)]);
    assert_eq!(trace.steps.len(), 2 * 69);
    assert_eq!(trace.axis(&trace.end(), b'X'), 69_000.0);
    // Under diameter programming the range holds the diameter.
    let lathe = MachineConfig { diameter_axis: Some(b'X'), ..MachineConfig::default() };
    let text = "%1\nN1 G74 G91 G00 X1000\nN2 G73 L1 Q999\nN3 M30\n";
    let trace = run(text, &NoFiles, &lathe, 10_000);
    assert_eq!(stops(text, &trace), [("N1 G74 G91 G00 X1000\n", message)]);
    assert_eq!(trace.axis(&trace.end(), b'X'), 34_500.0);
    // Travel limits are machine coordinates: G54 puts X250 at 450.
    let mut machine = MachineConfig {
        limits: [
            (b'X', TravelLimits { min: None, max: Some(500_000) }),
            (b'Z', TravelLimits { min: Some(-5_000), max: None }),
        ]
        .into(),
        ..MachineConfig::default()
    };
    (machine.offsets, _) = OffsetTable::parse("$POS\nG54: X=200.0\n", &machine.axes);
    let text = "%1\nN1 G54 G00 X250\nN2 X300\nN3 X350\nN4 M30\n";
    let trace = run(text, &NoFiles, &machine, 100);
    let message = "X would reach 550.000 in machine coordinates, beyond its travel limit 500.000 (`limits` of the machine): the control stops at the software limit switch";
    assert_eq!(stops(text, &trace), [("N3 X350\n", message)]);
    assert_eq!(trace.steps.len(), 2);
    // An arc's side: G03 from X290 (490 on the machine) about I0 J10
    // reaches 500; G02 between the same ends reaches 480.
    machine.limits.insert(b'X', TravelLimits { min: None, max: Some(495_000) });
    let text = "%1\nN1 G54 G00 X290 Y0\nN2 G03 X290 Y20 I0 J10 F100\nN3 M30\n";
    let trace = run(text, &NoFiles, &machine, 100);
    let message = "the arc's side: X would reach 500.000 in machine coordinates, beyond its travel limit 495.000 (`limits` of the machine): the control stops at the software limit switch";
    assert_eq!(stops(text, &trace), [("N2 G03 X290 Y20 I0 J10 F100\n", message)]);
    let trace = run(&text.replace("G03", "G02"), &NoFiles, &machine, 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // A built-in cycle's moves too: G81 drills to Z-10.
    let trace = run(DRILLING, &NoFiles, &machine, 100);
    let message = "the fixed cycle G81: Z would reach -10.000 in machine coordinates, beyond its travel limit -5.000 (`limits` of the machine): the control stops at the software limit switch";
    assert_eq!(stops(DRILLING, &trace), [("N3 G81 X20\n", message)]);
}

#[test]
fn dwell_is_q_times_ten_milliseconds() {
    let trace = run_text("%1\nN1 G04 Q150\nN2 M30\n");
    assert_eq!(trace.steps[0].motion, Motion::Dwell);
    close(trace.totals().time(Motion::Dwell), 1.5);
}

#[test]
fn a_block_moves_with_the_parameters_from_before_its_assignments() {
    // R1=20000 is 20 mm (thousandths); the block that assigns 50 mm
    // still moves with 20.
    let trace = run_text("%1\nN1 R1=20000\nN2 G01 XR1 F1200\nN3 R1=50000 G01 X-R1\nN4 XR1\nN5 M30\n");
    let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
    assert_eq!(x, [0.0, 20.0, -20.0, 50.0, 50.0]);
    close(trace.steps[1].duration, 1.0);
}

/// The block lines each step ran, in order.
fn lines_run(text: &str, trace: &Trace) -> Vec<String> {
    trace.steps.iter().map(|step| text[step.range].trim_end().to_owned()).collect()
}

#[test]
fn a_subprogram_runs_q_times_and_returns_after_the_call() {
    let text = "%1\nN1 G71 L7 Q2 F600\nN2 G00 X0\nN3 M30\nN10 G79 L7\nN11 G91 G01 X10\nN12 G90 G70\n*\n";
    let trace = run_text(text);
    assert_eq!(
        lines_run(text, &trace),
        [
            "N1 G71 L7 Q2 F600",
            "N11 G91 G01 X10",
            "N12 G90 G70",
            "N11 G91 G01 X10",
            "N12 G90 G70",
            "N2 G00 X0",
            "N3 M30"
        ]
    );
    // The subprogram's modal G01 and F carry on after it.
    close(trace.totals().time(Motion::Feed), 2.0);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

#[test]
fn a_macrocycle_file_runs_q_times_with_its_own_jumps() {
    // The macro drills R21 holes R20 apart: its jump back to N20 is
    // found in its own file, though the program has an N20 too.
    let program = "%1\nN10 R20=10. R21=3. G91 F600\nN20 G72 L9001 Q2\nN30 M30\n";
    let macro_text =
        "N1 G79 L9001\nN2 R22=0 R24=1.\nN20 G01 XR20\nN30 R5=1222422 R6=17222123 G27\nN40 GR23 L20 Q9999\nN50 G70\n";
    let trace = run(program, &Library(macro_text), &MachineConfig::default(), 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.files, [Called::Number(9001)]);
    // Two calls, three holes each.
    let moves: Vec<usize> = trace.steps.iter().filter(|s| s.motion == Motion::Feed).map(|s| s.source).collect();
    assert_eq!(moves, [1; 6]);
    assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 60.0);

    let trace = run(program, &NoFiles, &MachineConfig::default(), 1000);
    let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
    assert_eq!(messages, ["there is no macrocycle file L9001 to call"]);
    let unended = Library("N1 G79 L9001\nN2 G00 X1\n");
    let trace = run(program, &unended, &MachineConfig::default(), 1000);
    let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
    assert_eq!(messages, ["the macrocycle file ends without G70"]);
}

#[test]
fn a_jump_with_q_runs_the_section_q_plus_one_times() {
    // The manual's example: N26…N54 with `G73 L26 Q3` runs four times.
    let text = "%1\nN25 G91 F600\nN26 G01 X1\nN54 G73 L26 Q3\nN55 M30\n";
    let trace = run_text(text);
    assert_eq!(trace.steps.iter().filter(|step| &text[step.range] == "N26 G01 X1\n").count(), 4);
    assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 4.0);
    // Nested in a subprogram called twice, the count starts again.
    let text = "%1\nN1 G71 L1 Q2 G91 F600\nN2 M30\nN3 G79 L1\nN4 G01 X1\nN5 G73 L4 Q1\nN6 G70\n";
    assert_eq!(run_text(text).end_position()[usize::from(b'X' - b'A')], 4.0);
}

#[test]
fn a_long_program_runs_alike_taken_from_the_index_pass_or_lowered_again() {
    // Several batches from the index pass, then a jump back (which waits
    // for the whole index), a call into a subprogram after the end, and
    // comments, which the plain reading keeps.
    let mut text = String::from("%1\nN1 G91 G01 F600\n");
    for n in 2..3000 {
        text.push_str(&format!("N{n} X1 \"STEP\"\n"));
    }
    text.push_str("N3000 G73 L2 Q1\nN3001 G71 L7 Q2\nN3002 M30\nN3003 G79 L7\nN3004 Y1\nN3005 G70\n");
    let trace = run(&text, &NoFiles, &MachineConfig::default(), 100_000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.steps.len(), 1 + 2 * 2999 + 1 + 2 * 2 + 1);
    let end = trace.end_position();
    assert_eq!((end[usize::from(b'X' - b'A')], end[usize::from(b'Y' - b'A')]), (2.0 * 2998.0, 2.0));
}

#[test]
fn dwell_takes_q_and_the_call_runs_once() {
    let text = "%1\nN1 G04 G71 L5 Q200\nN2 M30\nN3 G79 L5\nN4 G01 X1 F60\nN5 G70\n";
    let trace = run_text(text);
    close(trace.totals().time(Motion::Dwell), 2.0);
    close(trace.totals().time(Motion::Feed), 1.0);
}

#[test]
fn endless_loops_and_missing_targets_stop_the_run_where_they_are() {
    let text = "%1\nN1 G71 L1\nN2 M30\nN3 G79 L1\nN4 G71 L1\nN5 G70\n";
    let trace = run_text(text);
    let fatal: Vec<(&str, &str)> =
        trace.findings.iter().filter(|f| f.stops()).map(|f| (text[f.range].trim_end(), f.message.as_str())).collect();
    assert_eq!(fatal, [("N4 G71 L1", "calls nest deeper than 64: runaway recursion?")]);

    let text = "%1\nN1 G73 L1 Q9999\nN2 M30\n";
    let trace = run(text, &NoFiles, &MachineConfig::default(), 500);
    assert_eq!(trace.steps.len(), 500);
    assert!(trace.findings[0].message.starts_with("stopped after 500 blocks"), "{:?}", trace.findings);

    for (text, message) in [
        ("%1\nN1 G71 L9\nN2 M30\n", "there is no subprogram L9 (G79 L9) in this file"),
        ("%1\nN1 G73 L5\nN2 M30\nN3 G79 L1\nN5 G70\n", "no block N5 in this program unit to jump to"),
        ("%1\nN1 X1\nN3 G79 L1\nN5 G70\n", "the main body runs into a subprogram: it has no M02 or M30 before it"),
    ] {
        let trace = run_text(text);
        assert_eq!(trace.findings.last().map(|f| f.message.as_str()), Some(message), "{text}");
    }
}

#[test]
fn arithmetic_runs_after_the_motion_and_conditional_codes_jump_on_73() {
    // R10 counts the passes: op 01 adds R11 (1.000) to it, op 17 writes
    // 73 into R20 while R10 < R12 (3.000), so `GR20` jumps back twice
    // and is G78 (no jump) the third time.
    let text =
        "%1\nN1 R10=0 R11=1. R12=3. G91 F600\nN2 G01 X1\nN3 G27 R5=1101110 R6=17101220\nN4 GR20 L2 Q9999\nN5 M30\n";
    let trace = run_text(text);
    assert_eq!(trace.steps.iter().filter(|step| &text[step.range] == "N2 G01 X1\n").count(), 3);
    assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 3.0);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // Op 26 reads the programmed position of axis 1 (X) after the
    // block's motion: 12.5 mm, raw 12500.
    let trace = run_text("%1\nN1 G00 X12.5 R5=26010010 G26\nN2 G01 YR10 F600\nN3 M30\n");
    assert_eq!(trace.end_position()[usize::from(b'Y' - b'A')], 12.5);
    // Op 49 reads a block register (table 4), which the run does not
    // model: the word that uses the value is named and left out.
    let text = "%1\nN1 R5=49410110 G26\nN2 G01 XR10 F100\nN3 M30\n";
    let trace = run_text(text);
    let found: Vec<(&str, bool)> = trace.findings.iter().map(|f| (&text[f.range], f.stops())).collect();
    assert_eq!(found, [("XR10", false)]);
    assert!(trace.findings[0].message.starts_with("R10 holds a value the executor does not know"));
}

#[test]
fn an_arithmetic_error_stops_the_run_at_its_function() {
    // Op 04 divides R1 by R2, which is zero.
    let text = "%1\nN1 R1=1. R2=0 R5=4010203 G26\nN2 G00 X1\nN3 M30\n";
    let trace = run_text(text);
    let found: Vec<(&str, &str, bool)> =
        trace.findings.iter().map(|f| (&text[f.range], f.message.as_str(), f.stops())).collect();
    assert_eq!(found, [("G26", "parameter arithmetic failed: division by zero", true)]);
    assert_eq!(trace.steps.len(), 1);
}

#[test]
fn speed_and_dwell_read_a_parameter_as_its_digits() {
    // R27=300 is S300 and R29=250 a dwell of 250 × 10 ms (03 §1.6);
    // G95 F1. is 1 mm/rev, 300 mm/min at S300.
    let trace = run_text("%1\nN1 R27=300 R29=250\nN2 SR27 G95 G01 X1 F1.\nN3 G04 QR29\nN4 M30\n");
    assert_eq!(trace.steps[1].feed, Some(300.0));
    close(trace.steps[1].duration, 0.2);
    close(trace.totals().time(Motion::Dwell), 2.5);
}

#[test]
fn the_program_ends_at_m30_and_unmodelled_work_is_named_once() {
    let trace = run_text("%1\nN1 G08 X1 F100\nN2 G08 X2\nN3 M30\nN4 G00 X500\n");
    assert_eq!(trace.steps.len(), 3);
    let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
    assert_eq!(messages, ["the executor does not run G08 yet: the time leaves them out"]);
}

#[test]
fn a_rapid_move_lasts_as_long_as_its_slowest_axis() {
    let machine = MachineConfig { rapid_rates: [(b'Z', 5_000)].into(), ..MachineConfig::default() };
    let trace = run("%1\nN1 G00 X100 Z40\nN2 X0 Z0 Y200\nN3 M30\n", &NoFiles, &machine, 100);
    // N1: X 100 mm at 10000 mm/min is 0.6 s, Z 40 mm at 5000 mm/min 0.48 s;
    // N2: Y 200 mm at 10000 mm/min is 1.2 s.
    close(trace.steps[0].duration, 0.6);
    close(trace.steps[1].duration, 1.2);
    let trace = run("%1\nN1 G00 X50 Z40\nN2 M30\n", &NoFiles, &machine, 100);
    close(trace.steps[0].duration, 0.48);
}
