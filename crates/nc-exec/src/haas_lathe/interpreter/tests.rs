use std::{
    f64::consts::{FRAC_PI_2, PI},
    ops::ControlFlow,
};

use ncc_catalog::Dialect;
use ncc_syntax::TextSize;
use proptest::prelude::*;

use crate::{
    compensation::{Piece, ToolElement},
    machine::{MachineConfig, OffsetTable, ToolEntry, ToolTable},
    run::{NoFiles, resume_into, run, run_into},
    trace::{
        Called, Checkpoint, Checkpoints, Closing, Compensated, DELIVERY_BATCH, Environment, Motion, Path, PathMode,
        RunRule, Step, StepSink, Stop, Tool, Trace,
    },
    transform::Frame,
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
    assert_eq!(trace.tools, [Tool::Number(101)]);
    assert_eq!(steps[1].m_functions, 1);
    assert_eq!((steps[2].stop, steps[3].stop), (Some(Stop::Program), Some(Stop::Optional)));
}

#[test]
fn what_does_not_run_yet_is_reported_once_per_kind() {
    let text = "O1\nG20\nG98 G01 X30. K-1. F100.\nZ-5. ,C1.\nG20\nG101 X0\nM30\n";
    let trace = run_lathe(text);
    let not_run: Vec<(RunRule, &str)> =
        trace.findings.iter().map(|finding| (finding.rule, text[finding.range].trim())).collect();
    assert_eq!(
        not_run,
        [(RunRule::NotRunYet, "G20"), (RunRule::NotRunYet, "G98 G01 X30. K-1. F100."), (RunRule::NotRunYet, "G101 X0"),]
    );
}

#[test]
fn the_manual_s_g71_program_runs_to_its_end() {
    let text = include_str!("../../../../syntax/test_data/haas-lathe/e14_g71_type1_program.nc");
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // The contour after G71 is not run as moves: from G71 the run goes on
    // after N20, and ends at M30.
    let lines: Vec<&str> = trace.steps.iter().map(|step| text[step.range].trim()).collect();
    assert!(!lines.iter().any(|line| line.starts_with("N10")), "{lines:?}");
    assert_eq!(lines.last(), Some(&"M30"));
    // From the machine zero, where the run starts, G53 goes to X-100.
    // Z-250. in machine coordinates (radius -50): Z's 250 mm at 10 m/min.
    // The offsets are zero, so G54's X70. Z3. is 253 mm of Z away.
    let step = |line: &str| trace.steps.iter().find(|step| text[step.range].trim() == line).expect(line);
    let g53 = step("G00 G53 X-100. Z-250.");
    close(g53.duration, 250.0 / 10_000.0 * 60.0);
    assert_eq!(g53.end[..2], [-50.0, -250.0]);
    close(step("G54 G00 X70. Z3.   ( P0 )").duration, 253.0 / 10_000.0 * 60.0);
}

#[test]
fn words_take_variables_and_failed_arithmetic_stops_the_run() {
    let trace = run_lathe("O1\n#1 = 30.\nG00 X#1 Z-[#1 / 3]\nU-#1\n#2 = 1 / 0\nG00 X100.\nM30\n");
    let ends: Vec<(f64, f64)> = trace.steps[1..3].iter().map(|step| (step.end[0], step.end[1])).collect();
    assert_eq!(ends, [(15.0, -10.0), (0.0, -10.0)]);
    assert_eq!(rules(&trace), [RunRule::ArithmeticFailed]);
    assert_eq!(trace.steps.len(), 3);
}

/// (Z, X radius) of a step's end; the lathe's axes are X then Z.
fn zx(step: &Step) -> (f64, f64) {
    (step.end[1], step.end[0])
}

fn close_zx(actual: (f64, f64), expected: (f64, f64)) {
    close(actual.0, expected.0);
    close(actual.1, expected.1);
}

#[test]
fn g28_returns_through_its_intermediate_point_and_g29_comes_back_through_it() {
    let text = "O1\nG00 X40. Z10.\nG28 U10. W5.\nG29 X30. Z-5.\nG28 U0\nM30\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let ends: Vec<(f64, f64)> = trace.steps.iter().map(zx).collect();
    // From (Z10, r20): U10. W5. is the intermediate point (15, 25), then
    // the reference point, the machine zero (0, 0). G29 goes back through
    // (15, 25) to X30. Z-5. (-5, 15); G28 U0 sends X alone home.
    assert_eq!(ends, [(10.0, 20.0), (15.0, 25.0), (0.0, 0.0), (15.0, 25.0), (-5.0, 15.0), (-5.0, 0.0), (-5.0, 0.0)]);
    let times: Vec<f64> = trace.steps.iter().map(|step| step.duration).collect();
    // Rapid, the longest axis at 10 m/min: 5 mm, 25 mm, 25 mm, 20 mm, 15 mm.
    for (time, travel) in times[1..6].iter().zip([5.0, 25.0, 25.0, 20.0, 15.0]) {
        close(*time, travel / 10_000.0 * 60.0);
    }
    assert!(trace.steps[1..6].iter().all(|step| step.motion == Motion::Rapid));
}

/// A lathe whose G54 lies at X-100. (a diameter) Z-200. and G55 at Z-250.
/// from the machine zero.
fn lathe_with_offsets() -> MachineConfig {
    let rows = [(54, [-100_000, -200_000, 0, 0, 0, 0]), (55, [0, -250_000, 0, 0, 0, 0])].into();
    MachineConfig { offsets: OffsetTable { rows }, ..lathe() }
}

#[test]
fn work_offsets_move_the_machine_positions_and_g53_moves_in_machine_coordinates() {
    let text = "O1\nG00 X20. Z5.\nG55 G00 X20. Z5.\nG52 Z-10.\nG00 Z0\nG53 X-60. Z-100.\nG54 U0\nM30\n";
    let trace = run(text, &NoFiles, &lathe_with_offsets(), 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let machine: Vec<[f64; 2]> =
        (0..trace.steps.len()).map(|i| [trace.machine_end(i)[1], trace.machine_end(i)[0]]).collect();
    // G54: program Z5. r10 is machine Z-195 r-40; from the machine zero the
    // rapid takes Z's 195 mm.
    assert_eq!(zx(&trace.steps[0]), (5.0, 10.0));
    assert_eq!(machine[0], [-195.0, -40.0]);
    close(trace.steps[0].duration, 195.0 / 10_000.0 * 60.0);
    assert_eq!(trace.reset_frame, trace.frames[trace.steps[0].frame]);
    // G55: the same program point is machine Z-245 r10, 50 mm away on both.
    assert_eq!(machine[1], [-245.0, 10.0]);
    close(trace.steps[1].duration, 50.0 / 10_000.0 * 60.0);
    // G52 Z-10. moves nothing and shifts the zero: Z0 is machine Z-260.
    assert_eq!((trace.steps[2].motion, machine[2]), (Motion::None, [-245.0, 10.0]));
    assert_eq!(machine[3], [-260.0, 10.0]);
    // G53 X-60. Z-100. is machine r-30 Z-100 at rapid, in its own frame.
    assert_eq!(zx(&trace.steps[4]), (-100.0, -30.0));
    assert_eq!(machine[4], [-100.0, -30.0]);
    assert_eq!(trace.steps[4].motion, Motion::Rapid);
    close(trace.steps[4].duration, 160.0 / 10_000.0 * 60.0);
    // Back in G54 (with G52's Z-10.), the tool stays where it is: program
    // Z-100 - (-200 - 10) = 110, r-30 - (-50) = 20.
    assert_eq!(zx(&trace.steps[5]), (110.0, 20.0));
    assert_eq!(machine[5], [-100.0, -30.0]);
    for index in 1..trace.steps.len() {
        assert_eq!(trace.machine_start(index), trace.machine_end(index - 1));
    }
}

/// A lathe whose offsets 1 and 3 have a nose radius of 0.8 mm and tip 3.
fn lathe_with_nose() -> MachineConfig {
    let nose = ToolEntry { radius: 800, lengths: [0; 6], tip: Some(3) };
    let entries = [(1, nose), (3, nose)].into();
    MachineConfig { tools: ToolTable { entries }, ..lathe() }
}

/// A piece of the tool path: its step, kind, start and end (Z, X radius).
type Shown = (usize, Piece, (f64, f64), (f64, f64));

/// The tool path's pieces, to a nanometre.
fn pieces(trace: &Trace) -> Vec<Shown> {
    let round = |v: f64| (v * 1e6).round() / 1e6 + 0.0;
    let at = |point: nalgebra::Point2<f64>| (round(point.x), round(point.y));
    trace
        .tool_centre
        .iter()
        .map(|piece| (piece.block, piece.kind, at(piece.path.start()), at(piece.path.end())))
        .collect()
}

#[test]
fn nose_radius_compensation_offsets_a_profile_by_the_radius_and_shifts_it_to_the_tip() {
    // OD: up the face at Z0 to Ø20, along Z to Z-10, a 45° taper to Ø30 at
    // Z-15, along Z to Z-25, G42 (the tool above the contour).
    let text = "O1\nT101\nG98 F100.\nG00 X10. Z2.\nG42 G01 Z0\nX20.\nZ-10.\nX30. Z-15.\nZ-25.\nG40 G00 X40.\nM30\n";
    let trace = run(text, &NoFiles, &lathe_with_nose(), 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // By hand, (Z, r): the nose centre runs 0.8 from the contour: Z0.8
    // before the face, r10.8 above the first straight, on z + r = 0.8·√2 =
    // 1.131371 beside the taper z + r = 0, and r15.8 above the second
    // straight. The corners are the intersections: (0.8, 10.8) (a right
    // angle outside), (1.131371 - 10.8, 10.8) = (-9.668629, 10.8) (inside),
    // (1.131371 - 15.8, 15.8) = (-14.668629, 15.8) (outside, 45°). The
    // start ends on the face's normal at its start, (0.8, 5); the last
    // element on its normal at its end, (-25, 15.8). Tip 3 puts the
    // imaginary tip 0.8 toward -X and -Z of the centre: the tool path is
    // the centre's shifted by (-0.8, -0.8), the tip on the programmed line
    // along the axes and r·(2 - √2) = 0.468629 behind it along the taper.
    assert_eq!(
        pieces(&trace),
        [
            (3, Piece::Start, (2.0, 5.0), (0.0, 4.2)),
            (4, Piece::Contour, (0.0, 4.2), (0.0, 10.0)),
            (5, Piece::Contour, (0.0, 10.0), (-10.468629, 10.0)),
            (6, Piece::Contour, (-10.468629, 10.0), (-15.468629, 15.0)),
            (7, Piece::Contour, (-15.468629, 15.0), (-25.8, 15.0)),
            (8, Piece::Cancel, (-25.8, 15.0), (-25.0, 20.0)),
        ]
    );
    assert_eq!(trace.compensated.len(), 1);
    assert_eq!((trace.compensated[0].steps.clone(), trace.compensated[0].plane), (3..9, (b'Z', b'X')));
    // The steps keep the programmed points and take the tool path's length
    // and time: the straight 10.468629 mm and the taper 5·√2 mm at
    // 100 mm/min, the cancel at rapid (5 mm of X).
    assert_eq!(zx(&trace.steps[6]), (-15.0, 15.0));
    close(trace.steps[5].length, 10.0 + 0.8 * (2.0 - 2f64.sqrt()));
    close(trace.steps[6].length, 50f64.sqrt());
    close(trace.steps[6].duration, 50f64.sqrt() / 100.0 * 60.0);
    close(trace.steps[3].length, 4.64f64.sqrt());
    close(trace.steps[8].length, 25.64f64.sqrt());
    close(trace.steps[8].duration, 5.0 / 10_000.0 * 60.0);
    // Where the tool is at the taper's end: the tip, behind the programmed
    // point along Z.
    let tip = trace.tool_end(6, &trace.steps[6].end);
    close_zx((tip[1], tip[0]), (-15.0 - 0.8 * (2.0 - 2f64.sqrt()), 15.0));
    // Without a radius (the default) the path is the programmed one.
    let plain = run_lathe(text);
    assert!(plain.findings.is_empty() && plain.tool_centre.is_empty() && plain.compensated.is_empty());
    close(plain.steps[5].length, 10.0);
}

#[test]
fn g10_writes_work_offsets_and_the_one_in_force_moves_the_program_zero_at_once() {
    // G10 L2 P2 sets G55 at X-40. (a diameter) Z-300.; W-5. then adds to
    // G54's Z, which is in force: the program zero moves under the tool.
    let text = "O1\nG10 L2 P2 X-40. Z-300.\nG55 G00 X0 Z0\nG54 G00 X0 Z0\nG10 L2 P1 W-5.\nG00 X0 Z0\nG10 L20 P3 X10.\nG10 L1 P1 X1.\nM30\n";
    let trace = run(text, &NoFiles, &lathe_with_offsets(), 100);
    let machine: Vec<[f64; 2]> = (0..trace.steps.len())
        .filter(|&i| trace.steps[i].motion == Motion::Rapid)
        .map(|i| [trace.machine_end(i)[1], trace.machine_end(i)[0]])
        .collect();
    assert_eq!(machine, [[-300.0, -20.0], [-200.0, -50.0], [-205.0, -50.0]]);
    // Only G10's work offsets are written; its tool offsets are not run.
    let rules: Vec<(RunRule, String)> =
        trace.findings.iter().map(|f| (f.rule, text[f.range].trim_end().to_owned())).collect();
    assert_eq!(rules, [(RunRule::NotRunYet, "G10 L1 P1 X1.".to_owned())]);
}

#[test]
fn g31_feeds_to_its_end_point() {
    let text = "O1\nG98 F100.\nG00 X20. Z5.\nG31 W-10.\nM30\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let skip = trace.steps.iter().rfind(|step| step.motion != Motion::None).unwrap();
    assert_eq!((skip.motion, zx(skip)), (Motion::Feed, (-5.0, 10.0)));
    assert!((skip.duration - 6.0).abs() < 1e-9, "10 mm at 100 mm/min: {}", skip.duration);
}

#[test]
fn a_new_work_offset_ends_compensation_and_the_next_start_is_in_its_frame() {
    let machine = MachineConfig { offsets: lathe_with_offsets().offsets, ..lathe_with_nose() };
    let text = "O1\nT101\nG98 F100.\nG00 X20. Z2.\nG42 G01 Z0\nZ-10.\nG55 Z-20.\nM30\n";
    let trace = run(text, &NoFiles, &machine, 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // G54 ends with Z-10.'s normal at its end, the tip 0.8 behind it. In
    // G55 the tool stands at machine Z-210 r-40, program Z40 r-40, and
    // G42 starts anew from there, in force to the end; no element follows.
    assert_eq!(
        pieces(&trace),
        [
            (3, Piece::Start, (2.0, 10.0), (-0.8, 10.0)),
            (4, Piece::Contour, (-0.8, 10.0), (-10.8, 10.0)),
            (5, Piece::Start, (40.0, -40.0), (-20.0, -40.0)),
        ]
    );
    assert_eq!(trace.compensated.iter().map(|span| span.steps.clone()).collect::<Vec<_>>(), [3..5, 5..7]);
}

#[test]
fn nose_radius_compensation_starts_and_ends_on_lines_only() {
    let starts_on_arc = "O1\nT101\nG98 F100.\nG00 X20. Z0\nG42 G02 X40. Z-10. R10.\nG40 G01 X50.\nM30\n";
    let trace = run(starts_on_arc, &NoFiles, &lathe_with_nose(), 100);
    assert_eq!(rules(&trace), [RunRule::CompensationFailed]);
    let ends_on_arc = "O1\nT101\nG98 F100.\nG00 X20. Z2.\nG42 G01 Z0\nZ-10.\nG40 G02 X40. Z-20. R10.\nM30\n";
    let trace = run(ends_on_arc, &NoFiles, &lathe_with_nose(), 100);
    assert_eq!(rules(&trace), [RunRule::CompensationFailed]);
    assert_eq!(&text_of(ends_on_arc, &trace), "G40 G02 X40. Z-20. R10.");
}

/// The line of the run's first finding.
fn text_of(text: &str, trace: &Trace) -> String {
    text[trace.findings[0].range].trim().to_owned()
}

/// The manual's start and cancel examples (lathe manual §7.1, E5–E7
/// (001:975-995, 1021-1031, 1049-1064)), each in a program around it. The
/// placeholders `X.. Z..` are filled, and the cancels after an arc take
/// the G01 that the table's format `G1/0 G40` (001:101) asks for.
#[test]
fn the_manual_s_compensation_examples_run_without_findings() {
    let od = ["G42 X40.", "G42 Z0", "G42 X30. Z0", "G42 X40. Z0"]
        .map(|start| format!("G00 X50. Z5.\nG01 {start}\nX50. Z-10.\nZ-20.\nG40 G00 X60."));
    let id = ["G41 Z0", "G41 X90.", "G41 X90. Z0", "G41 X95. Z0"]
        .map(|start| format!("G00 X100. Z5.\nG01 {start}\nX80. Z-10.\nZ-20.\nG40 G00 X70."));
    let cancels = [
        "G00 X20. Z5.\nG01 G42 X20. Z0\nG2 X40. Z-10. R10.\nG01 G40 X60. Z-10.",
        "G00 X20. Z5.\nG01 G42 X20. Z0\nG1 X40. Z-60.\nG40 X60. Z-60.",
        "G00 X20. Z5.\nG01 G42 X20. Z0\nG1 X0 Z0\nG40 X10. Z5.",
        "G00 X20. Z5.\nG01 G42 X20. Z0\nG1 Z-40.\nG40 I50.K-30. X80. Z-50.",
    ];
    for example in od.iter().chain(&id).map(String::as_str).chain(cancels) {
        let text = format!("O1\nT101\nG98 F100.\n{example}\nM30\n");
        let trace = run(&text, &NoFiles, &lathe_with_nose(), 100);
        assert!(trace.findings.is_empty(), "{example}: {:?}", trace.findings);
        assert_eq!(trace.compensated.len(), 1, "{example}");
        // After the cancel the tip is on the programmed point.
        let last = trace.steps.len() - 2;
        assert_eq!(trace.tool_end(last, &trace.steps[last].end), trace.steps[last].end, "{example}");
    }
}

#[test]
fn g70_follows_the_compensated_contour_and_g71_compensates_its_pass_along_it() {
    let text = "O1\nT101\nG98\nG00 X30. Z5.\nG70 P10 Q20 F100.\nM30\nN10 G00 X10.\nG01 G42 Z0\nX20.\nZ-10.\nN20 G00 G40 X30.\n";
    let trace = run(text, &NoFiles, &lathe_with_nose(), 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    // G70's moves: the P block to (5, 5), the start to Z0, up the face, along
    // Z, the cancel to r15 and back to the start (5, 15). The tip: as in
    // the profile above, the face at Z0 up to r10, along r10 to the normal
    // at Z-10 (the centre at -10, the tip at -10.8), then onto X30.
    let ends: Vec<(f64, f64)> = pieces(&trace).iter().map(|&(_, _, _, end)| end).collect();
    assert_eq!(ends, [(0.0, 4.2), (0.0, 10.0), (-10.8, 10.0), (-10.0, 15.0)]);
    assert_eq!(trace.compensated.len(), 1);
    // The manual's G71 program on the same tool: the roughing levels run
    // as they are, the pass along the contour and G70 compensated.
    let e14 = include_str!("../../../../syntax/test_data/haas-lathe/e14_g71_type1_program.nc");
    let trace = run(e14, &NoFiles, &lathe_with_nose(), 10_000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let lines: Vec<&str> =
        trace.compensated.iter().map(|span| e14[trace.steps[span.steps.start].range].trim()).collect();
    assert_eq!(lines, ["G71 P10 Q20 U0.3 W0.1 D8. F0.3", "G70 P10 Q20 F0.1"]);
    // G71's 25 moves: to the shifted start, three levels of four moves,
    // the pass (the P block's move, the start on the G42 block, seven
    // moves, the cancel on the Q block) and two back. The start, the seven
    // and the cancel are compensated; the P block's move is not.
    let g71_steps = trace.steps.iter().filter(|step| e14[step.range].starts_with("G71")).count();
    assert_eq!((trace.compensated[0].steps.len(), g71_steps), (9, 25));
}

/// The programs beside the one that runs: O1000 only.
struct Library(&'static str);

impl Environment for Library {
    fn file(&self, called: &Called) -> Option<String> {
        (*called == Called::Program(1000)).then(|| self.0.to_owned())
    }
}

#[test]
fn m97_runs_a_local_subprogram_l_times_and_m99_p_returns_to_a_block() {
    let text = "O1\nG98 G01 F600.\nM97 P100 L3\nM97 P200\nG00 X100.\nN300 G00 X50.\nM30\nN100 G01 W-1.\nM99\nN200 G01 U2.\nM99 P300\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let lines: Vec<&str> = trace.steps.iter().map(|step| text[step.range].trim()).collect();
    assert_eq!(
        lines,
        [
            "G98 G01 F600.",
            "M97 P100 L3",
            "N100 G01 W-1.",
            "M99",
            "N100 G01 W-1.",
            "M99",
            "N100 G01 W-1.",
            "M99",
            "M97 P200",
            "N200 G01 U2.",
            "M99 P300",
            "N300 G00 X50.",
            "M30"
        ]
    );
    // Three times W-1. at 600 mm/min: 0.1 s each; U2. is 1 mm of radius.
    close_zx(zx(&trace.steps[10]), (-3.0, 1.0));
    close(trace.totals().time(Motion::Feed), 0.3 + 0.1);
}

#[test]
fn m98_calls_a_program_of_the_file_and_one_beside_it() {
    let text = "O1\nM98 P2\nM98 P1000 L2\nM30\nO2\nG98 G01 W-1. F600.\nM99\n";
    let beside = "O1000\nG98 G01 U2. F600.\nM99\n";
    let trace = run(text, &Library(beside), &lathe(), 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.files, [Called::Program(1000)]);
    let sources: Vec<(usize, &str)> = trace
        .steps
        .iter()
        .map(|step| (step.source, if step.source == 0 { &text[step.range] } else { &beside[step.range] }.trim()))
        .collect();
    assert_eq!(
        sources,
        [
            (0, "M98 P2"),
            (0, "G98 G01 W-1. F600."),
            (0, "M99"),
            (0, "M98 P1000 L2"),
            (1, "G98 G01 U2. F600."),
            (1, "M99"),
            (1, "G98 G01 U2. F600."),
            (1, "M99"),
            (0, "M30"),
        ]
    );
    // Twice U2.: 2 mm of radius.
    close_zx(zx(trace.steps.last().unwrap()), (-1.0, 2.0));
    // A file without the program's O line runs from its start, read once.
    let trace = run("O1\nM98 P1000\nM98 P1000\nM30\n", &Library("G98 G01 U2. F600.\nM99\n"), &lathe(), 100);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert_eq!(trace.files, [Called::Program(1000)]);
    close_zx(zx(trace.steps.last().unwrap()), (0.0, 2.0));
    // A program neither in the file nor beside it stops the run there.
    let missing = run("O1\nM98 P5000\nG00 X10.\nM30\n", &Library(beside), &lathe(), 100);
    assert_eq!(rules(&missing), [RunRule::CallTargetMissing]);
    assert!(missing.steps.is_empty());
}

#[test]
fn g65_passes_its_arguments_as_locals_and_gives_the_caller_its_own_back() {
    // A → #1, B → #2, C → #3: each run moves W-[1 + 2·10 + 3·100] = -321.
    // Each of the two runs starts from the arguments, whatever the last
    // left in #1; back in the caller, #1 is its own 7. again.
    let text = "O1\n#1 = 7.\nG65 P9010 A1. B2. C3. L2\nG00 X#1\nM30\nO9010\nG00 W-[#1 + #2 * 10. + #3 * 100.]\n#1 = 50.\nM99\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    close_zx(zx(trace.steps.last().unwrap()), (-642.0, 3.5));
}

#[test]
fn g65_reads_argument_assignment_ii_for_repeated_i_j_k() {
    // I2. J3. fill the first set (#4, #5); I4. starts no new set after J,
    // so a second one: #7, and K5. is its K, #9; D6. gives #7 too and,
    // later in the block, holds; I1. after K starts the third set, #10.
    let text = "O1\nG65 P9020 I2. J3. I4. K5. D6. I1.\nM30\nO9020\nG00 X0 W-[#4 + #5 * 10. + #7 * 100. + #9 * 1000. + #10 * 10000.]\nM99\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    close_zx(zx(trace.steps.last().unwrap()), (-15632.0, 0.0));
}

#[test]
fn runaway_recursion_stops_at_the_depth_limit() {
    for text in ["O1\nM98 P1\nM30\n", "O1\nG65 P1 A1.\nM30\n", "O1\nN1 M97 P1\nM30\n"] {
        let trace = run_lathe(text);
        assert_eq!(rules(&trace), [RunRule::CallDepth], "{text}");
        assert!(trace.blocks_run < 200, "{text}: {}", trace.blocks_run);
    }
    // A subprogram without M99 stops where it ends.
    let trace = run_lathe("O1\nM98 P2\nM30\nO2\nG00 X10.\n");
    assert_eq!(rules(&trace), [RunRule::MacrocycleWithoutReturn]);
}

mod properties {
    use proptest::prelude::*;

    use super::{Library, lathe_with_nose, lathe_with_offsets};
    use crate::{machine::MachineConfig, run::run};

    proptest! {
        #[test]
        fn any_calls_coordinates_and_compensation_run_to_an_end(lines in prop::collection::vec(prop::sample::select(vec![
            "O1", "O2", "O1000", "N10 G00 X20. Z2.", "N20 G01 X30. Z-5. F0.2", "G02 X40. Z-10. R5.", "G03 W-3. U-4. R2.",
            "G42 G01 Z0", "G41 X10.", "G40 G00 X50.", "G01 X0", "M97 P10", "M97 P20 L2", "M98 P2", "M98 P1000",
            "M98 P7 L0", "G65 P2 A1. B#1", "M99", "M99 P10", "M30", "G28 U0 W0", "G28", "G29 X10. Z5.",
            "G53 X-10. Z-20.", "G52 Z-5.", "G55", "G54", "G70 P10 Q20", "G71 P10 Q20 D1. U0.2", "#1 = #1 + 1",
            "IF [#1 GT 3] GOTO 20", "T101", "T303", "M98 P#2", "G65 P1", "G97 S500 M03", "G90 X10. Z-3.",
        ]), 0..25)) {
            let text = lines.join("\n");
            let machine = MachineConfig { offsets: lathe_with_offsets().offsets, ..lathe_with_nose() };
            let trace = run(&text, &Library("O1000\nG01 U1. F0.1\nM99\n"), &machine, 2000);
            prop_assert!(trace.blocks_run <= 2000);
            for step in &trace.steps {
                prop_assert!(step.duration.is_finite() && step.length.is_finite(), "{text}\n{step:?}");
                prop_assert!(step.end.iter().all(|value| value.is_finite()), "{text}\n{step:?}");
            }
            for piece in &trace.tool_centre {
                prop_assert!(piece.path.length().is_finite(), "{text}\n{piece:?}");
            }
        }
    }
}

#[test]
fn steps_record_the_spindle_speed_and_the_path_modes_in_force() {
    // Under G96 a rapid commands the rpm at its end, a cut follows the
    // diameter from its start to its end up to the G50 limit; M04 turns
    // the other way, M05 stops.
    let text = "O1\nG50 S2000\nG96 S100 M04\nG00 X40. Z0\nG99 F0.1 G01 X10.\nG97 S500 M03 G187 P3\nG103 P1 G01 Z-5.\nM05\nM30\n";
    let trace = run_lathe(text);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let rpm = |diameter: f64| (1000.0 * 100.0 / (PI * diameter)) as f32;
    let spindles: Vec<[f32; 2]> = trace.steps.iter().map(|step| step.spindle).collect();
    assert_eq!(spindles[..4], [[0.0; 2], [-2000.0; 2], [-rpm(40.0); 2], [-rpm(40.0), -2000.0]]);
    assert_eq!(spindles[4..7], [[500.0; 2], [500.0; 2], [0.0; 2]]);
    let modes: Vec<(PathMode, f32)> = trace.steps[3..6].iter().map(|s| (s.path_mode, s.corner_tolerance)).collect();
    assert_eq!(modes, [(PathMode::Continuous, 0.05), (PathMode::Continuous, 0.01), (PathMode::Stop, 0.01)]);
}

// Streaming runs and checkpoints: a run hands on its steps as they are
// final, and a run resumed from a checkpoint goes on as the whole run.

/// Keeps the steps, checking that what they refer to comes before them,
/// and counts the steps of each delivery.
#[derive(Default)]
struct Deliveries {
    steps: Vec<Step>,
    frames: Vec<Frame>,
    pieces: Vec<ToolElement>,
    sizes: Vec<usize>,
}

impl StepSink for Deliveries {
    fn step(&mut self, step: Step) {
        assert!(step.frame < self.frames.len(), "the frame of step {} comes before it", self.steps.len());
        self.steps.push(step);
        if let Some(size) = self.sizes.last_mut() {
            *size += 1;
        }
    }

    fn references(&mut self, frames: &[Frame], _compensated: &[Compensated], pieces: &[ToolElement]) {
        assert!(pieces.iter().all(|piece| piece.block >= self.steps.len()), "pieces come before their steps");
        self.frames = frames.to_vec();
        self.pieces.extend_from_slice(pieces);
        self.sizes.push(0);
    }
}

/// A compensated contour longer than a delivery batch, then a local
/// subprogram called in a loop.
fn long_compensated_program() -> String {
    let mut text = String::from("O1\nT101\nG98 G00 X30. Z5.\nG42 G01 X20. Z0 F100.\n");
    for i in 0..2500 {
        text.push_str(&format!("X{}. Z-{}.\n", 20 + (i % 2) * 2, i + 1));
    }
    text.push_str(
        "G40 G00 X40.\n#1 = 0\nWHILE [#1 LT 3] DO1\nM97 P100 L2\n#1 = #1 + 1\nEND1\nM30\nN100 G01 W-1.\nM99\n",
    );
    text
}

#[test]
fn a_streamed_run_hands_on_the_steps_a_kept_run_keeps_a_batch_at_a_time() {
    let text = long_compensated_program();
    let machine = lathe_with_nose();
    let kept = run(&text, &NoFiles, &machine, 100_000);
    assert!(kept.findings.is_empty(), "{:?}", kept.findings);
    assert!(kept.tool_centre.len() > 2500);
    let mut delivered = Deliveries::default();
    let trace = run_into(&text, &NoFiles, &machine, 100_000, &mut delivered);
    assert!(trace.steps.is_empty());
    assert_eq!(delivered.steps, kept.steps);
    assert_eq!(delivered.frames, kept.frames);
    assert_eq!(delivered.pieces, kept.tool_centre);
    assert_eq!(Trace { steps: delivered.steps, ..trace }, kept);
    // The run held no more than a batch at a time, compensation or not.
    assert!(delivered.sizes.len() > 2, "{:?}", delivered.sizes);
    assert!(delivered.sizes.iter().all(|&size| size <= DELIVERY_BATCH), "{:?}", delivered.sizes);
}

#[test]
fn a_streamed_run_ends_soon_after_its_sink_closes() {
    let text = "O1\nG98 G01 F1000.\nN1 U0.002\nGOTO 1\n";
    let mut sink = Closing { taken: 0, room: 1 };
    let trace = run_into(text, &NoFiles, &lathe(), 1_000_000, &mut sink);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert!(sink.taken <= 2 * DELIVERY_BATCH, "{} steps after the sink closed", sink.taken);
    assert!(trace.blocks_run <= 4 * DELIVERY_BATCH, "{} blocks run", trace.blocks_run);
}

/// Wants one checkpoint, at block `at`, and ends the run there.
struct StopAt {
    at: usize,
}

impl StepSink for StopAt {
    fn step(&mut self, _step: Step) {}

    fn checkpoint_wanted(&mut self, block: usize, _offset: TextSize) -> bool {
        block == self.at
    }

    fn checkpoint(&mut self, _checkpoint: Checkpoint) -> ControlFlow<()> {
        ControlFlow::Break(())
    }
}

/// Checks that a run of `text` resumed from each of its checkpoints (one
/// every `every` blocks) goes on as the whole run: the same steps, and
/// after what the run reported up to the checkpoint, the same findings and
/// tool-centre path; it takes the same checkpoints after it.
fn assert_resumes_as_the_whole_run(text: &str, machine: &MachineConfig, every: usize) -> Vec<usize> {
    let budget = 20_000;
    let mut whole = Checkpoints { every, ..Checkpoints::default() };
    let trace = resume_into(None, text, &NoFiles, machine, budget, &mut whole);
    for checkpoint in &whole.taken {
        let at = checkpoint.block();
        let before = run_into(text, &NoFiles, machine, budget, &mut StopAt { at });
        let mut resumed = Checkpoints { before: checkpoint.steps(), every, ..Checkpoints::default() };
        let after = resume_into(Some(checkpoint), text, &NoFiles, machine, budget, &mut resumed);
        assert_eq!(resumed.steps, whole.steps[checkpoint.steps()..], "from block {at}");
        assert_eq!([&before.findings[..], &after.findings[..]].concat(), trace.findings, "from block {at}");
        assert_eq!([&before.tool_centre[..], &after.tool_centre[..]].concat(), trace.tool_centre, "from block {at}");
        assert_eq!([&before.compensated[..], &after.compensated[..]].concat(), trace.compensated, "from block {at}");
        assert_eq!((&after.frames, after.blocks_run), (&trace.frames, trace.blocks_run), "from block {at}");
        let later: Vec<&Checkpoint> = whole.taken.iter().filter(|c| c.block() >= at).collect();
        assert_eq!(resumed.taken.len(), later.len(), "from block {at}");
        for (again, first) in resumed.taken.iter().zip(later) {
            assert!(again.same_course(first) && again.offset() == first.offset(), "from block {at}");
        }
    }
    whole.taken.iter().map(Checkpoint::block).collect()
}

#[test]
fn a_run_resumed_from_a_checkpoint_goes_on_as_the_whole_run() {
    let text = long_compensated_program();
    let blocks = assert_resumes_as_the_whole_run(&text, &lathe_with_nose(), 1);
    // Up to G42's block, then none until G40's has run; the loop's blocks
    // up to the first call of the subprogram after M30, and none after it.
    assert_eq!(blocks, [0, 1, 2, 3, 2505, 2506, 2507]);
}

#[test]
fn checkpoints_skip_calls_compensation_later_loop_passes_and_spans_a_later_cycle_reads_back() {
    let text = "O1\nT101\nG98 G00 X30. Z5. F100.\nG71 P10 Q20 U0.3 W0.1 D1.\nN10 G00 X10.\nG01 Z0\nX20.\nZ-10.\nN20 G00 X30.\nG00 Z5.\nG70 P10 Q20\n#1 = 0\nWHILE [#1 LT 2] DO1\n#1 = #1 + 1\nEND1\nG42 G01 W-1.\nW-1.\nG40 G00 U2.\nM97 P100\nM30\nN100 G01 W-1.\nM99\n";
    let mut sink = Checkpoints { every: 1, ..Checkpoints::default() };
    let trace = resume_into(None, text, &NoFiles, &lathe_with_nose(), 1000, &mut sink);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let lines: Vec<&str> = sink.taken.iter().map(|c| text[usize::from(c.offset())..].lines().next().unwrap()).collect();
    // Not between the contour's start and G70, which reads it (G71 goes
    // on after the contour); each loop block once; not under G42 before
    // the cancel has run; none after the call of the subprogram after M30.
    assert_eq!(
        lines,
        [
            "O1",
            "T101",
            "G98 G00 X30. Z5. F100.",
            "G71 P10 Q20 U0.3 W0.1 D1.",
            "#1 = 0",
            "WHILE [#1 LT 2] DO1",
            "#1 = #1 + 1",
            "END1",
            "G42 G01 W-1.",
            "M97 P100"
        ]
    );
    assert_resumes_as_the_whole_run(text, &lathe_with_nose(), 1);
}

/// The checkpoints of a run of `text`, one every `every` blocks.
fn checkpoints(text: &str, every: usize) -> Vec<Checkpoint> {
    let mut sink = Checkpoints { every, ..Checkpoints::default() };
    resume_into(None, text, &NoFiles, &lathe(), 10_000, &mut sink);
    sink.taken
}

/// Modal state and a variable set early, then moves, then a jump back.
fn resumable_program(first_x: &str) -> String {
    let mut text = format!("O1\nG00 X{first_x} Z5. M03 S1000\n#100 = 5.\nG98 G01 Z-1. F300.\n");
    for i in 0..40 {
        text.push_str(&format!("X{}. Z#100\n", i * 3));
    }
    text.push_str("N60 U2.\nIF [#100 LT 8] GOTO 70\n#100 = #100 + 1\nGOTO 60\nN70 M30\n");
    text
}

#[test]
fn checkpoints_after_an_edit_take_the_same_course_once_the_edit_no_longer_matters() {
    let before = checkpoints(&resumable_program("0"), 7);
    assert_eq!(before.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 7, 14, 21, 28, 35, 42]);
    // An absolute move written longer: the course is the same from the
    // next move on, three bytes later.
    let after = checkpoints(&resumable_program("1234"), 7);
    assert_eq!(after.len(), before.len());
    for (after, before) in after.iter().zip(&before).skip(1) {
        let shifted = before.shifted(3, 0, 0);
        assert_eq!(after.offset(), shifted.offset());
        assert!(after.same_course(&shifted));
    }
    // A variable the moves read carries the difference to the end.
    let deeper = checkpoints(&resumable_program("0").replace("#100 = 5.", "#100 = 6."), 7);
    assert!(deeper.iter().zip(&before).skip(1).all(|(after, before)| !after.same_course(before)));
    // A block numbered 70 before them: the GOTO after them goes there.
    let renumbered = checkpoints(&resumable_program("0").replace("#100 = 5.", "N70 #100 = 5."), 7);
    assert!(renumbered.iter().zip(&before).skip(1).all(|(after, before)| !after.same_course(&before.shifted(4, 0, 0))));
}

#[test]
fn a_block_jumped_over_before_a_checkpoint_is_part_of_its_course() {
    // N20 runs only after the checkpoints: its text decides the run.
    let program =
        |x: &str| format!("O1\nG98 G01 F100.\nGOTO 30\nN20 G01 U{x}\nM99 P40\nN30 U1.\nW-1.\nM97 P20\nN40 M30\n");
    let (short, long) = (checkpoints(&program("1."), 1), checkpoints(&program("10."), 1));
    assert_eq!(short.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 1, 2, 5, 6, 7, 8]);
    assert!(!short[4].same_course(&long[4].shifted(-1, 0, 0)));
    assert!(short[2].same_course(&long[2]));
}

/// Pieces of programs to put together: moves, variables, a WHILE loop, a
/// local subprogram and a program of the file called, a jump over a
/// block, a roughing cycle over the contour after it and the finishing
/// cycle after that, a compensated stretch, a box cycle, work offsets, a
/// dwell. `{n}` is a number of its own for each piece.
const PIECES: [&str; 13] = [
    "G01 U-1. W-1.\n",
    "G00 U1.5 W0.5\n",
    "#100 = #100 + 1\nIF [#100 GT 3] THEN #101 = #100\n",
    "#5 = 0\nWHILE [#5 LT 2] DO1\nG01 U0.5 W-0.5\n#5 = #5 + 1\nEND1\n",
    "M97 P9000 L2\n",
    "M98 P2000\n",
    "GOTO {n}\nG01 U7.\nN{n} G01 W-1.\n",
    "G00 X30. Z5.\nG71 P{n}1 Q{n}2 U0.3 W0.1 D1.\nN{n}1 G00 X10.\nG01 Z0\nX20.\nZ-10.\nN{n}2 G00 X30.\nG00 Z5.\nG70 P{n}1 Q{n}2\n",
    "G42 G01 U1. W-1.\nW-2.\nU2. W-1.\nG40 G00 U4.\n",
    "G90 U-2. W-3.\nW-1.\nG00 U3.\n",
    "G55\nG00 U1.\n",
    "G54 G52 W-1.\nG00 U-1.\n",
    "G04 P100\n",
];

/// A program of `pieces` between a start and the subprograms.
fn generated(pieces: &[usize]) -> String {
    let mut text = String::from("O1000\nT101\nG18 G98 F300.\nG00 X40. Z5.\n");
    for (n, &piece) in pieces.iter().enumerate() {
        text.push_str(&PIECES[piece].replace("{n}", &(100 + n).to_string()));
    }
    text.push_str("M30\nN9000 G01 U0.2 W-0.2\nM99\nO2000\nG01 U-0.2 W-0.1\nM99\n");
    text
}

#[test]
fn the_pieces_of_generated_programs_run_without_findings() {
    let machine = MachineConfig { offsets: lathe_with_offsets().offsets, ..lathe_with_nose() };
    let trace = run(&generated(&(0..PIECES.len()).collect::<Vec<_>>()), &NoFiles, &machine, 10_000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Over generated programs with calls, loops, jumps, cycles and
    /// compensation, a run resumed from any checkpoint goes on as the
    /// whole run.
    #[test]
    fn runs_resumed_from_any_checkpoint_go_on_as_whole_runs(
        pieces in proptest::collection::vec(0..PIECES.len(), 1..24),
        every in 1usize..4,
    ) {
        let machine = MachineConfig { offsets: lathe_with_offsets().offsets, ..lathe_with_nose() };
        assert_resumes_as_the_whole_run(&generated(&pieces), &machine, every);
    }
}
