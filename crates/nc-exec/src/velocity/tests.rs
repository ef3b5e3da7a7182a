use super::{Dynamics, Joining, Reason, Timing, corner_speed, time};
use crate::{
    cnc8x6::dynamics,
    machine::MachineConfig,
    run::{NoFiles, run},
};

/// The default machine: R97 = 2, R39 = 60°, R52 = 1000, R236 = 400 and
/// R237 = 1000 mm/s², a 20 ms pause under G98 and a 10 ms settle.
fn timed(text: &str) -> Timing {
    let machine = MachineConfig::default();
    let trace = run(text, &NoFiles, &machine, 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    time(&trace, &dynamics::dynamics(&machine))
}

/// Times `text` with ramps limited to `jerk` mm/s³ in the steps
/// `soft` picks, as a control's SOFT marks them.
fn soft(text: &str, jerk: f64, soft: impl Fn(usize) -> bool) -> Timing {
    let machine = MachineConfig::default();
    let mut trace = run(text, &NoFiles, &machine, 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    trace.steps.iter_mut().enumerate().for_each(|(i, step)| step.jerk_limited = soft(i));
    time(&trace, &Dynamics { jerk: Some(jerk), ..dynamics::dynamics(&machine) })
}

/// The speed (mm/s) from which ramps of `a` and `j` stop within `length`
/// mm where they reach `a` (length > a³/j²): length = v/2 · (v/a + a/j).
fn s_curve_stopping_speed(length: f64, a: f64, j: f64) -> f64 {
    ((a.powi(4) / (j * j) + 8.0 * a * length).sqrt() - a * a / j) / 2.0
}

fn close(actual: f64, expected: f64) {
    assert!((actual - expected).abs() <= expected.abs() * 1e-9 + 1e-12, "{actual} != {expected}");
}

/// A move of `length` mm from rest to rest at `speed` mm/s with `a` mm/s².
fn rest_to_rest(length: f64, speed: f64, a: f64) -> f64 {
    2.0 * speed / a + (length - speed * speed / a) / speed
}

#[test]
fn unset_constants_take_the_models_assumptions() {
    let dynamics = dynamics::dynamics(&MachineConfig::default());
    assert_eq!((dynamics.joining, dynamics.tolerance_angle), (Joining::Automatic, 60.0));
    let accelerations = (dynamics.feed_acceleration, dynamics.continuity_acceleration, dynamics.rapid_acceleration);
    assert_eq!(accelerations, (1000.0, 400.0, 1000.0));
}

#[test]
fn the_corner_speed_keeps_the_blend_within_the_tolerance() {
    let (x, y) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    // 90°: r = ε·cos 45° / (1 − cos 45°) = ε (1 + √2).
    close(corner_speed(x, y, 0.1, 1000.0), (1000.0 * 0.1 * (1.0 + 2.0f64.sqrt())).sqrt());
    assert_eq!(corner_speed(x, x, 0.1, 1000.0), f64::INFINITY);
    assert_eq!(corner_speed(x, [-1.0, 0.0, 0.0], 0.1, 1000.0), 0.0);
    assert_eq!(corner_speed(x, [-1.0, 0.0, 0.0], f64::INFINITY, 1000.0), f64::INFINITY);
}

#[test]
fn one_long_line_ramps_up_and_down() {
    // 100 mm at 100 mm/s: 5 mm of ramp at each end at 1000 mm/s².
    let timing = timed("%1\nN1 G01 X100 F6000\nN2 M30\n");
    let line = timing.profiles[0];
    assert_eq!((line.entry, line.peak, line.exit), (0.0, 6000.0, 0.0));
    close(line.duration, rest_to_rest(100.0, 100.0, 1000.0) + 0.020);
    close(timing.total_time(), 1.1 + 0.020);
    let reasons: Vec<Reason> = timing.breaks.iter().map(|b| b.reason.reason).collect();
    assert_eq!(reasons, [Reason::NonMotion]);
    // The stop costs the ramp down, against going on at 100 mm/s.
    close(timing.breaks[0].lost, 100.0 / 1000.0 / 2.0 + 0.020);
    // Too short to reach the feed: a triangle.
    let short = timed("%1\nN1 G01 X1 F6000\nN2 M30\n").profiles[0];
    close(short.peak, (1000.0f64 * 1.0).sqrt() * 60.0);
    close(short.duration, 2.0 * (1000.0f64).sqrt() / 1000.0 + 0.020);
}

#[test]
fn a_collinear_g23_chain_runs_through_at_the_feed() {
    let timing = timed("%1\nN1 G23 G01 X10 F600\nN2 X20\nN3 X30\nN4 M30\n");
    let speeds: Vec<(f64, f64)> = timing.profiles[..3].iter().map(|p| (p.entry, p.exit)).collect();
    assert_eq!(speeds, [(0.0, 600.0), (600.0, 600.0), (600.0, 0.0)]);
    // Under continuity the ramps take R236: 10 mm/s at 400 mm/s².
    close(timing.total_time(), 3.0 + 10.0 / 400.0 + 0.010);
    assert_eq!(timing.breaks.len(), 1);
}

#[test]
fn a_corner_below_r39_joins_and_one_above_stops() {
    // 53.13° (3-4-5) and 63.43° (1-2) turns from the X axis.
    let below = timed("%1\nN1 G23 G01 X10 F600\nN2 X13 Y4\nN3 M30\n");
    assert_eq!(below.breaks.len(), 1);
    close(below.total_time(), 15.0 / 10.0 + 10.0 / 400.0 + 0.010);
    let above = timed("%1\nN1 G23 G01 X10 F600\nN2 X11 Y2\nN3 M30\n");
    let Reason::Corner { angle, limit } = above.breaks[0].reason.reason else { panic!("{:?}", above.breaks) };
    close(angle, 2.0f64.atan().to_degrees());
    assert_eq!(limit, 60.0);
    let second = 5.0f64.sqrt();
    let expected = rest_to_rest(10.0, 10.0, 400.0) + 0.010 + rest_to_rest(second, 10.0, 400.0) + 0.010;
    close(above.total_time(), expected);
    // Against a smooth join at 10 mm/s the corner costs a ramp down and
    // up (10/400 s) and the settle.
    close(above.breaks[0].lost, 10.0 / 400.0 + 0.010);
}

#[test]
fn g98_g24_and_g23_on_the_same_path() {
    let path = |code: &str| timed(&format!("%1\nN1 {code} G01 X10 F600\nN2 X20\nN3 M30\n")).total_time();
    // G98: R52 ramps and a 20 ms pause after each line; G24: the same
    // ramps and a 10 ms settle; G23: one smooth run with R236 ramps.
    close(path("G98"), 2.0 * rest_to_rest(10.0, 10.0, 1000.0) + 2.0 * 0.020);
    close(path("G24"), 2.0 * rest_to_rest(10.0, 10.0, 1000.0) + 2.0 * 0.010);
    close(path("G23"), 2.0 + 10.0 / 400.0 + 0.010);
}

#[test]
fn an_arc_runs_at_its_chord_limit() {
    // Radius 1 mm: a 1 µm chord error per 10 ms allows sqrt(8 r e)/Ts.
    let timing = timed("%1\nN1 G02 X2 Y0 I1 J0 F1000\nN2 M30\n");
    let limit = (8.0f64 * 0.001).sqrt() / 0.01;
    close(timing.profiles[0].peak, limit * 60.0);
    let arc = timing.breaks.iter().find(|b| matches!(b.reason.reason, Reason::ArcLimit { .. })).unwrap();
    assert_eq!(arc.reason.reason, Reason::ArcLimit { radius: 1.0 });
    close(arc.at, limit * 60.0);
    close(arc.before, 1000.0);
    let length = std::f64::consts::PI;
    close(timing.profiles[0].duration, rest_to_rest(length, limit, 1000.0) + 0.020);
}

#[test]
fn dwell_keeps_its_time_and_breaks_the_path() {
    let timing = timed("%1\nN1 G23 G01 X10 F600\nN2 G04 Q150\nN3 X20\nN4 M30\n");
    close(timing.profiles[1].duration, 1.5);
    let reasons: Vec<(usize, Reason)> = timing.breaks.iter().map(|b| (b.step, b.reason.reason)).collect();
    assert_eq!(reasons, [(0, Reason::NonMotion), (2, Reason::NonMotion)]);
}

#[test]
fn a_short_block_after_a_fast_one_limits_the_junction() {
    // The control brakes one block ahead: the 0.5 mm block must be able
    // to stop within itself, sqrt(2 * 400 * 0.5) = 20 mm/s.
    let timing = timed("%1\nN1 G23 G01 X100 F3000\nN2 X100.5 F3000\nN3 X200\nN4 M30\n");
    let reasons: Vec<Reason> = timing.breaks.iter().map(|b| b.reason.reason).collect();
    assert_eq!(reasons[0], Reason::ShortBlock { duration: 0.5 / 50.0, limit: 0.060 });
    // 8 mm take 80 ms at 100 mm/s, but stop within themselves only
    // from sqrt(2 * 400 * 8) = 80 mm/s.
    let timing = timed("%1\nN1 G23 G01 X100 F6000\nN2 X108\nN3 X200\nN4 M30\n");
    assert_eq!((timing.breaks[0].step, timing.breaks[0].reason.reason), (0, Reason::LookAhead));
    close(timing.breaks[0].at, 4800.0);
    close(timing.profiles[1].entry, 4800.0);
    // Long enough blocks, one slow: the fast one ends at the slow speed.
    let timing = timed("%1\nN1 G23 G01 X100 F3000\nN2 X110 F600\nN3 M30\n");
    assert_eq!(timing.profiles[0].exit, 600.0);
    assert_eq!(timing.profiles[1].entry, 600.0);
}

/// A CNC8x9 with the envelope velocity and the linear profile (R338
/// decade 2 = 1).
fn enveloped(text: &str) -> Timing {
    let machine = MachineConfig { constants: [(338, 10)].into(), ..MachineConfig::default() };
    let dynamics = dynamics::dynamics(&machine);
    assert!(dynamics.envelope.is_some());
    let trace = run(text, &NoFiles, &machine, 1000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    time(&trace, &dynamics)
}

#[test]
fn the_envelope_runs_a_chain_of_short_blocks_at_the_feed() {
    // 100 blocks of 1 mm at 100 mm/s: 10 ms each, far below the CNC8x6's
    // 60 ms, but the envelope plans across them as one 100 mm line
    // ramping at R236 = 400 mm/s², with the 10 ms settle at the end.
    let mut text = String::from("%1\nN1 G23 G01 X1 F6000\n");
    for i in 2..=100 {
        text.push_str(&format!("N{i} X{i}\n"));
    }
    text.push_str("N101 M30\n");
    let timing = enveloped(&text);
    let expected = rest_to_rest(100.0, 100.0, 400.0) + 0.010;
    assert!((timing.total_time() - expected).abs() < expected * 1e-3, "{} != {expected}", timing.total_time());
    let reasons: Vec<(usize, Reason)> = timing.breaks.iter().map(|b| (b.step, b.reason.reason)).collect();
    assert_eq!(reasons, [(99, Reason::NonMotion)]);
    // The CNC8x6 stops after every block.
    assert!(timed(&text).total_time() > 3.0 * expected);
}

#[test]
fn the_envelope_merges_a_tiny_line_by_r383_unless_it_may_not() {
    // A 3 µm line inside a 100 mm one at 100 mm/s: merged, the path is
    // one line; on its own it would take the 4 ms minimum duration
    // (0.75 mm/s), braking from and ramping back to the feed.
    let program = |middle: &str| format!("%1\nN1 G23 G01 X50 F6000\nN2 {middle}\nN3 X100\nN4 M30\n");
    let merged = enveloped(&program("X50.003")).total_time();
    let expected = rest_to_rest(100.0, 100.0, 400.0) + 0.010;
    assert!((merged - expected).abs() < expected * 1e-3, "{merged} != {expected}");
    // Braking to a near stop and back costs about v/A against passing.
    let ramps = 100.0 / 400.0;
    // A technology function keeps it a block of its own.
    let with_speed = enveloped(&program("X50.003 S1000")).total_time();
    assert!(with_speed > merged + 0.9 * ramps, "{with_speed} vs {merged}");
    // A minus sign blocks R383.
    let machine = MachineConfig { constants: [(338, 10), (383, -5)].into(), ..MachineConfig::default() };
    let trace = run(&program("X50.003"), &NoFiles, &machine, 1000);
    let blocked = time(&trace, &dynamics::dynamics(&machine)).total_time();
    assert!(blocked > merged + 0.9 * ramps, "{blocked} vs {merged}");
}

#[test]
fn g23_i_selects_the_dynamic_set_of_the_parabolic_envelope() {
    // Sets on (R406, R412), parabolic profile: set 1 ramps at R408 =
    // 600 mm/s², set 2 at R414 = 100 mm/s², with the same P.
    let constants = [(338, 20), (406, 1), (407, 50_000), (408, 600), (412, 1), (413, 50_000), (414, 100)];
    let machine = MachineConfig { constants: constants.into(), ..MachineConfig::default() };
    let timed = |set: u8| {
        let text = format!("%1\nN1 G23 I{set} G01 X100 F6000\nN2 M30\n");
        let trace = run(&text, &NoFiles, &machine, 1000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        time(&trace, &dynamics::dynamics(&machine)).total_time()
    };
    let (first, second) = (timed(1), timed(2));
    // J = P / 32.768. Set 2 reaches A: v/A + A/J + L/v (04 §2.2); set 1
    // reaches 100 mm/s before A = 600 mm/s² (A²/J > v): 2·sqrt(v/J) + L/v.
    let jerk: f64 = 50_000.0 / 32.768;
    let (one, two) = (2.0 * (100.0 / jerk).sqrt() + 1.0 + 0.010, 100.0 / 100.0 + 100.0 / jerk + 1.0 + 0.010);
    assert!((first - one).abs() < one * 1e-3, "{first} != {one}");
    assert!((second - two).abs() < two * 1e-3, "{second} != {two}");
}

#[test]
fn the_envelope_slows_a_corner_by_the_accuracy_criterion() {
    // 45° below R39: R384 = 8 µm at Ts = 2 ms allows
    // 0.008 / (0.002 tan 22.5°) mm/s, below R385's 10000 · 0.002 /
    // (2 sin 22.5°).
    let timing = enveloped("%1\nN1 G23 G01 X100 F6000\nN2 X200 Y100\nN3 M30\n");
    let corner = timing.breaks[0];
    assert_eq!(corner.step, 0);
    let Reason::Accuracy { angle } = corner.reason.reason else { panic!("{:?}", corner.reason) };
    assert!((angle - 45.0).abs() < 1e-9);
    let limit = 0.008 / (0.002 * 22.5f64.to_radians().tan()) * 60.0;
    assert!((corner.at - limit).abs() < limit * 1e-3, "{} != {limit}", corner.at);
    assert!((timing.profiles[1].entry - corner.at).abs() < 1e-9);
    // The drop costs both moves' ramps against passing at 100 mm/s.
    let (v, a) = (limit / 60.0, 400.0);
    let ramps = 2.0 * ((100.0 - v) / a - (100.0 * 100.0 - v * v) / (2.0 * a) / 100.0);
    assert!((corner.lost - ramps).abs() < ramps * 1e-3, "{} != {ramps}", corner.lost);
}

#[test]
fn a_move_still_ramping_up_into_a_junction_is_no_break() {
    // 8 mm from rest under G23 reach sqrt(2 * 400 * 8) = 80 mm/s of the
    // 100 programmed, and the long next move takes that speed over.
    let timing = timed("%1\nN1 G23 G01 X8 F6000\nN2 X200\nN3 M30\n");
    close(timing.profiles[0].exit, 4800.0);
    close(timing.profiles[1].entry, 4800.0);
    let reasons: Vec<(usize, Reason)> = timing.breaks.iter().map(|b| (b.step, b.reason.reason)).collect();
    assert_eq!(reasons, [(1, Reason::NonMotion)]);
}

#[test]
fn a_thread_block_without_motion_is_a_non_motion_block() {
    // X10 again: a G33 block that does not move.
    let timing = timed("%1\nN1 M03 S500\nN2 G23 G01 X10 F600\nN3 G33 X10 K1\nN4 G01 X20\nN5 M30\n");
    let reasons: Vec<(usize, &str)> = timing.breaks.iter().map(|b| (b.step, b.reason.code())).collect();
    assert_eq!(reasons, [(1, "non-motion"), (3, "non-motion")]);
}

#[test]
fn a_g24_block_too_short_to_send_the_next_pauses_as_under_g98() {
    // 1 mm at 100 mm/s takes 10 ms, under the 30 ms G24 needs.
    let timing = timed("%1\nN1 G24 G01 X1 F6000\nN2 X101\nN3 M30\n");
    let first = 2.0 * (1000.0f64).sqrt() / 1000.0;
    close(timing.profiles[0].duration, first + 0.020);
    close(timing.profiles[1].duration, rest_to_rest(100.0, 100.0, 1000.0) + 0.010);
}

#[test]
fn m_functions_and_tool_changes_take_the_machines_times() {
    let machine = MachineConfig { m_function_ms: 200, tool_change_ms: 6000, ..MachineConfig::default() };
    // M06 is the tool change; M03 and M08 two M functions; M30 ends.
    let trace = run("%1\nN1 T1 M06\nN2 M03 M08 S1000\nN3 M30\n", &NoFiles, &machine, 100);
    let timing = time(&trace, &dynamics::dynamics(&machine));
    let durations: Vec<f64> = timing.profiles.iter().map(|profile| profile.duration).collect();
    assert_eq!(durations, [6.0, 0.4, 0.0]);
}

#[test]
fn a_subprogram_called_q_times_and_a_jump_loop() {
    // Each run of the 10 mm move ends at the non-motion G70 or G73
    // block: from rest to rest at R236, then the settle.
    let one_run = rest_to_rest(10.0, 10.0, 400.0) + 0.010;
    let called = timed("%1\nN1 G23 G01 F600 G71 L1 Q3\nN2 M30\nN3 G79 L1\nN4 G91 X10\nN5 G70\n");
    close(called.total_time(), 3.0 * one_run);
    let looped = timed("%1\nN1 G23 G91 G01 F600\nN2 X10\nN3 G73 L2 Q2\nN4 M30\n");
    close(looped.total_time(), 3.0 * one_run);
    assert_eq!(looped.breaks.len(), 3);
}

#[test]
fn rapid_moves_stop_at_both_ends() {
    let timing = timed("%1\nN1 G23 G01 X10 F600\nN2 G00 X100\nN3 G01 X110\nN4 M30\n");
    let reasons: Vec<(usize, Reason)> = timing.breaks.iter().map(|b| (b.step, b.reason.reason)).collect();
    assert_eq!(reasons[..2], [(0, Reason::Rapid), (1, Reason::Rapid)]);
    // 90 mm at the default 10 m/min rapid with R237 ramps.
    close(timing.profiles[1].duration, rest_to_rest(90.0, 10_000.0 / 60.0, 1000.0) + 0.010);
}

#[test]
fn a_jerk_limited_move_from_rest_to_rest_takes_the_s_curves_time() {
    let (a, f, j) = (1000.0, 100.0, 20_000.0);
    let line =
        |length: f64, jerk: f64| soft(&format!("%1\nN1 G01 X{length} F6000\nN2 M30\n"), jerk, |_| true).profiles[0];
    // 100 mm reach the feed, and the acceleration A on the way (A²/J =
    // 50 mm/s < F): F/A + A/J + L/F, with the 20 ms pause.
    let long = line(100.0, j);
    assert_eq!((long.entry, long.peak, long.exit), (0.0, 6000.0, 0.0));
    close(long.duration, f / a + a / j + 100.0 / f + 0.020);
    // J = 5000 mm/s³ never reaches A (A²/J = 200 mm/s > F): 2·sqrt(F/J) + L/F.
    close(line(100.0, 5000.0).duration, 2.0 * (f / 5000.0).sqrt() + 100.0 / f + 0.020);
    // 8 mm are too short for the feed: each half ramps through A to v.
    let short = line(8.0, j);
    let v = s_curve_stopping_speed(4.0, a, j);
    close(short.peak, v * 60.0);
    close(short.duration, 2.0 * (v / a + a / j) + 0.020);
    // 1 mm is too short for A (A³/J² = 2.5 mm per ramp):
    // v = ((L/2)²·J)^⅓ and t = 4·(L/(2J))^⅓.
    let tiny = line(1.0, j);
    close(tiny.peak, (0.25 * j).cbrt() * 60.0);
    close(tiny.duration, 4.0 * (1.0 / (2.0 * j)).cbrt() + 0.020);
}

#[test]
fn a_joined_move_can_stop_within_itself_under_the_jerk_limit() {
    // As without a jerk limit, the 8 mm block after a fast one limits
    // the junction; the S-curve stops within 8 mm at R236 = 400 mm/s²
    // and J = 4000 mm/s³ from 62.5 mm/s, not the linear 80 mm/s.
    let (a, j) = (400.0, 4000.0);
    let timing = soft("%1\nN1 G23 G01 X100 F6000\nN2 X108\nN3 X200\nN4 M30\n", j, |_| true);
    let v = s_curve_stopping_speed(8.0, a, j);
    assert!(v < 80.0 && v > 62.0, "{v}");
    assert_eq!((timing.breaks[0].step, timing.breaks[0].reason.reason), (0, Reason::LookAhead));
    close(timing.breaks[0].at, v * 60.0);
    close(timing.profiles[0].exit, v * 60.0);
    close(timing.profiles[1].entry, v * 60.0);
    // The first block, 100 mm from rest: up to the feed through A,
    // down to v below it (Δv < A²/J = 40 mm/s).
    let up = 100.0 / a + a / j;
    let down = 2.0 * ((100.0 - v) / j).sqrt();
    let cruise = 100.0 - 50.0 * up - (100.0 + v) / 2.0 * down;
    close(timing.profiles[0].duration, up + down + cruise / 100.0);
}

#[test]
fn soft_and_brisk_switch_block_by_block() {
    // Two lines with a stop between them (G98): the first limits its
    // jerk, the second ramps linearly.
    let text = "%1\nN1 G01 X100 F6000\nN2 X200\nN3 M30\n";
    let timing = soft(text, 20_000.0, |i| i == 0);
    close(timing.profiles[0].duration, 0.1 + 0.05 + 1.0 + 0.020);
    close(timing.profiles[1].duration, rest_to_rest(100.0, 100.0, 1000.0) + 0.020);
    // A jerk limit no step asks for changes nothing.
    assert_eq!(soft(text, 20_000.0, |_| false), timed(text));
}
