use std::f64::consts::{FRAC_PI_2, PI};

use ncc_catalog::Dialect;

use crate::{
    machine::MachineConfig,
    run::{NoFiles, run},
    trace::{Motion, Path, PathMode, RunRule, Stop, Trace},
};

/// A lathe; the programs' `O` lines make no step.
fn lathe() -> MachineConfig {
    MachineConfig::of_control(Dialect::HaasLathe)
}

fn run_lathe(text: &str) -> Trace {
    run(text, &NoFiles, &lathe(), 10_000)
}

fn close(actual: f64, expected: f64) {
    assert!((actual - expected).abs() < 1e-9, "{actual} is not {expected}");
}

/// The rules of the findings, in order.
fn rules(trace: &Trace) -> Vec<RunRule> {
    trace.findings.iter().map(|finding| finding.rule).collect()
}

#[test]
fn x_is_a_diameter_and_steps_keep_the_radius() {
    let trace = run_lathe("O1\nG00 X40. Z0\nG98 G01 X50. Z0 F100.\nM30\n");
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.diameter_axis, Some(b'X'));
    assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 25.0);
    let line = &trace.steps[1];
    assert_eq!((line.motion, line.path, line.feed), (Motion::Feed, Path::Straight, Some(100.0)));
    close(line.length, 5.0);
    close(line.duration, 5.0 / 100.0 * 60.0);
}

#[test]
fn u_and_w_count_from_the_last_position_mixed_with_x_and_z() {
    let trace = run_lathe("O1\nG00 X20. Z10.\nU10. W-5.\nX40. W-5.\nU-4. Z0\nM30\n");
    let ends: Vec<(f64, f64)> = trace.steps[..4].iter().map(|step| (step.end[0], step.end[1])).collect();
    assert_eq!(ends, [(10.0, 10.0), (15.0, 5.0), (20.0, 0.0), (18.0, 0.0)]);
}

#[test]
fn rapid_moves_take_the_slowest_axis_at_its_rate() {
    let machine = MachineConfig { rapid_rates: [(b'Z', 5_000)].into(), ..lathe() };
    // X travels 30 mm of radius at 10 m/min, Z 20 mm at 5 m/min.
    let trace = run("O1\nG00 X60. Z-20.\nM30\n", &NoFiles, &machine, 100);
    assert_eq!(trace.steps[0].motion, Motion::Rapid);
    close(trace.steps[0].duration, 20.0 / 5_000.0 * 60.0);
}

#[test]
fn a_quarter_circle_by_radius_and_by_centre() {
    // From Ø20 Z0 to Ø40 Z-10 with radius 10: a quarter turn.
    for arc in ["G02 X40. Z-10. R10.", "G02 X40. Z-10. I10. K0"] {
        let trace = run_lathe(&format!("O1\nG00 X20. Z0\nG98 F100.\n{arc}\nM30\n"));
        assert!(trace.findings.is_empty(), "{arc}: {:?}", trace.findings);
        let step = &trace.steps[2];
        close(step.length, 10.0 * FRAC_PI_2);
        let Path::Arc { plane, centre, clockwise } = step.path else { panic!("{arc}: {:?}", step.path) };
        assert_eq!((plane, clockwise), ((b'Z', b'X'), true), "{arc}");
        close(centre[0], 0.0);
        close(centre[1], 20.0);
    }
    // G03 the other way round the same ends, and a negative radius takes
    // the three-quarter arc.
    let trace = run_lathe("O1\nG00 X20. Z0\nG98 F100.\nG03 X40. Z-10. R10.\nM30\n");
    assert_eq!(trace.steps[2].path, Path::Arc { plane: (b'Z', b'X'), centre: [-10.0, 10.0], clockwise: false });
    let trace = run_lathe("O1\nG00 X20. Z0\nG98 F100.\nG02 X40. Z-10. R-10.\nM30\n");
    close(trace.steps[2].length, 10.0 * 3.0 * FRAC_PI_2);
}

#[test]
fn an_arc_end_off_its_circle_stops_the_run() {
    let trace = run_lathe("O1\nG00 X20. Z0\nG98 F100.\nG02 X40. Z-10. I10. K-3.\nM30\n");
    assert_eq!(rules(&trace), [RunRule::ArcOffCircle]);
    assert_eq!(trace.steps.len(), 2);
}

#[test]
fn feed_per_revolution_at_constant_speed() {
    // 0.2 mm/rev at 500 rpm: 100 mm/min over 10 mm.
    let trace = run_lathe("O1\nG00 X40. Z0\nG97 S500 M03\nG99 G01 Z-10. F0.2\nM30\n");
    let step = &trace.steps[2];
    close(step.feed.unwrap(), 100.0);
    close(step.duration, 10.0 / (0.2 * 500.0) * 60.0);
}

#[test]
fn feed_per_revolution_with_the_spindle_stopped_is_reported() {
    let trace = run_lathe("O1\nG00 X40. Z0\nG97 S500\nG01 Z-10. F0.2\nM30\n");
    assert_eq!(rules(&trace), [RunRule::MotionWithoutFeed]);
    assert_eq!(trace.steps[2].duration, 0.0);
}

#[test]
fn constant_cutting_speed_follows_the_diameter_up_to_the_limit() {
    let time_at = |diameter: f64| {
        let text = format!("O1\nG50 S2000\nG00 X{diameter:.1} Z0\nG96 S100 M03\nG01 Z-10. F0.1\nM30\n");
        run_lathe(&text).steps[3].duration
    };
    // At Ø50: 1000·100/(π·50) ≈ 637 rpm; at Ø10 the G50 limit 2000 rpm.
    close(time_at(50.0), 10.0 / (0.1 * 100_000.0 / (PI * 50.0)) * 60.0);
    close(time_at(10.0), 10.0 / (0.1 * 2000.0) * 60.0);
    // Facing from Ø50 to Ø30 runs at the mean diameter, Ø40.
    let trace = run_lathe("O1\nG00 X50. Z0\nG96 S100 M03\nG01 X30. F0.1\nM30\n");
    close(trace.steps[2].duration, 10.0 / (0.1 * 100_000.0 / (PI * 40.0)) * 60.0);
}

#[test]
fn dwell_p_without_a_point_is_ms_with_one_seconds() {
    let trace = run_lathe("O1\nG04 P500\nG04 P0.5\nG4 P2.\nM30\n");
    let dwells: Vec<(Motion, f64)> = trace.steps[..3].iter().map(|step| (step.motion, step.duration)).collect();
    assert_eq!(dwells, [(Motion::Dwell, 0.5), (Motion::Dwell, 0.5), (Motion::Dwell, 2.0)]);
}

#[test]
fn exact_stop_one_shot_and_modal() {
    let trace = run_lathe("O1\nG98 F100.\nG09 G01 Z-1.\nZ-2.\nG61 Z-3.\nZ-4.\nG64 Z-5.\nM30\n");
    let modes: Vec<PathMode> = trace.steps[1..6].iter().map(|step| step.path_mode).collect();
    use PathMode::{Continuous, ExactStop};
    assert_eq!(modes, [ExactStop, Continuous, ExactStop, ExactStop, Continuous]);
}

#[test]
fn a_while_loop_runs_its_body_while_the_condition_holds() {
    let text = "O1\n#1 = 0\nWHILE [#1 LT 3] DO1\nG98 G01 W-1. F60.\n#1 = #1 + 1\nEND1\nM30\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    close(trace.end_position()[usize::from(b'Z' - b'A')], -3.0);
    close(trace.totals().time(Motion::Feed), 3.0);
}

#[test]
fn if_goto_and_goto_jump_to_numbered_blocks() {
    let text = "O1\n#1 = 2\nIF [#1 EQ 2] GOTO 20\nG00 X100.\nN20 G00 X10.\nIF [#1 EQ 3] GOTO 30\nIF [#1 GT 1] THEN #2 = 7\nG00 Z#2\nGOTO 40\nN30 G00 X200.\nN40 M30\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let position = trace.end_position();
    assert_eq!((position[usize::from(b'X' - b'A')], position[usize::from(b'Z' - b'A')]), (5.0, 7.0));
}

#[test]
fn an_endless_loop_stops_at_the_budget() {
    let trace = run("O1\nN1 G00 U1.\nGOTO 1\n", &NoFiles, &lathe(), 50);
    assert_eq!(rules(&trace), [RunRule::StepBudget]);
    assert_eq!(trace.blocks_run, 50);
}

#[test]
fn stops_ends_tools_and_m_functions() {
    let trace = run_lathe("O1\nT101\nM08\nM00\nM01\nM30\nG00 X100.\n");
    let steps = &trace.steps;
    assert_eq!(steps.len(), 5);
    assert!(steps[0].tool_change);
    assert_eq!(trace.tools, [101]);
    assert_eq!(steps[1].m_functions, 1);
    assert_eq!((steps[2].stop, steps[3].stop), (Some(Stop::Program), Some(Stop::Optional)));
}

#[test]
fn what_does_not_run_yet_is_reported_once_per_kind_and_moves_nothing() {
    let text = "O1\nG00 X50. Z0\nG28 U0 W0\nG28 U0\nG65 P9010 A1.\nM98 P100\nG41 G98 G01 X30. F100.\nM30\n";
    let trace = run_lathe(text);
    assert_eq!(rules(&trace), [RunRule::NotRunYet; 4]);
    assert_eq!(trace.steps[1].end, trace.steps[0].end);
    assert_eq!(trace.steps[3].motion, Motion::None);
}

#[test]
fn the_manual_s_g71_program_runs_to_its_end() {
    let text = include_str!("../../../../syntax/test_data/haas-lathe/e14_g71_type1_program.nc");
    let trace = run_lathe(text);
    // Once per kind, where first met; the compensation in the contour is
    // met when G71 reads it.
    let not_run: Vec<(RunRule, &str)> =
        trace.findings.iter().map(|finding| (finding.rule, text[finding.range].trim())).collect();
    assert_eq!(
        not_run,
        [
            (RunRule::NotRunYet, "G00 G53 X-100. Z-250."),
            (RunRule::NotRunYet, "G54 G00 X70. Z3.   ( P0 )"),
            (RunRule::NotRunYet, "G01 G42 X17. Z0 ( P2 )"),
        ]
    );
    // The contour after G71 is not run as moves: from G71 the run goes on
    // after N20, and ends at M30.
    let lines: Vec<&str> = trace.steps.iter().map(|step| text[step.range].trim()).collect();
    assert!(!lines.iter().any(|line| line.starts_with("N10")), "{lines:?}");
    assert_eq!(lines.last(), Some(&"M30"));
    // The positioning move to Ø70 Z3 is timed from the start; the second
    // one, before G70, finds the tool back there after G71.
    let rapid = |line: &str| trace.steps.iter().find(|step| text[step.range].trim() == line).map(|s| s.duration);
    close(rapid("G54 G00 X70. Z3.   ( P0 )").unwrap(), 35.0 / 10_000.0 * 60.0);
    assert_eq!(rapid("G54 G00 X70. Z3."), Some(0.0));
}

#[test]
fn words_take_variables_and_failed_arithmetic_stops_the_run() {
    let trace = run_lathe("O1\n#1 = 30.\nG00 X#1 Z-[#1 / 3]\nU-#1\n#2 = 1 / 0\nG00 X100.\nM30\n");
    let ends: Vec<(f64, f64)> = trace.steps[1..3].iter().map(|step| (step.end[0], step.end[1])).collect();
    assert_eq!(ends, [(15.0, -10.0), (0.0, -10.0)]);
    assert_eq!(rules(&trace), [RunRule::ArithmeticFailed]);
    assert_eq!(trace.steps.len(), 3);
}
