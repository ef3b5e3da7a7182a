use ncc_catalog::Dialect;
use ncc_syntax::TextRange;

use super::{ASSUMED_CONTOUR_TOLERANCE, ASSUMED_G64_TOLERANCE, ASSUMED_JERK, PathControl, PathError, dynamics};
use crate::{
    machine::MachineConfig,
    trace::{MAX_AXES, Motion, Path, PathMode, Step},
    velocity::{Timer, Timing},
};

fn machine() -> MachineConfig {
    MachineConfig::of_control(Dialect::Sinumerik)
}

/// Times feed moves at 100 mm/s in X/Y from the origin, as an interpreter
/// would give them with [`PathControl`]: each block's words (codes,
/// `ADDRESS=value`, G9, M17 after the move) and its end point.
fn timed_on(machine: &MachineConfig, blocks: &[(&str, [f64; 2])]) -> Timing {
    let dynamics = dynamics(machine);
    let axes = machine.step_axes().to_vec();
    let mut timer = Timer::new(&axes, &dynamics, Timing::default());
    let mut control = PathControl::default();
    let mut from = [0.0; 2];
    for &(words, to) in blocks {
        let (mut exact_stop_here, mut subprogram_end) = (false, false);
        for word in words.split_whitespace() {
            match word.split_once('=') {
                Some((address, value)) => assert_eq!(control.address(address, value.parse().unwrap()), Ok(true)),
                None if word == "G9" => exact_stop_here = true,
                None if word == "M17" => subprogram_end = true,
                None => assert!(control.code(word), "{word}"),
            }
        }
        let path = control.step(exact_stop_here, false);
        let length = (to[0] - from[0]).hypot(to[1] - from[1]);
        let mut end = [0.0; MAX_AXES];
        end[..2].copy_from_slice(&to);
        timer.push(Step {
            source: 0,
            range: TextRange::default(),
            motion: Motion::Feed,
            path: Path::Straight,
            duration: length / 100.0,
            length,
            feed: Some(6000.0),
            end,
            frame: 0,
            stop: None,
            path_mode: path.path_mode,
            m_functions: 0,
            tool_change: false,
            dynamic_set: 1,
            mergeable: false,
            jerk_limited: path.jerk_limited,
            spindle: [0.0; 2],
            corner_tolerance: path.corner_tolerance,
        });
        if subprogram_end {
            control.subprogram_end();
        }
        from = to;
    }
    timer.finish()
}

fn timed(blocks: &[(&str, [f64; 2])]) -> Timing {
    timed_on(&machine(), blocks)
}

/// Five 20 mm legs turning 90° four times; `modes` in the first block,
/// `second` in the second.
fn zigzag(modes: &'static str, second: &'static str) -> [(&'static str, [f64; 2]); 5] {
    [(modes, [20.0, 0.0]), (second, [20.0, 20.0]), ("", [40.0, 20.0]), ("", [40.0, 40.0]), ("", [60.0, 40.0])]
}

/// The breaks of a timing by step and code.
fn breaks(timing: &Timing) -> Vec<(usize, &'static str)> {
    timing.breaks.iter().map(|b| (b.step, b.reason.code())).collect()
}

fn close(actual: f64, expected: f64) {
    assert!((actual - expected).abs() <= expected.abs() * 1e-9 + 1e-12, "{actual} != {expected}");
}

/// Seconds of a move of `length` mm at up to `speed` mm/s from `entry`
/// to `exit` mm/s, ramping linearly at `a` mm/s² (long enough to reach
/// `speed`).
fn trapezoid(length: f64, speed: f64, (entry, exit): (f64, f64), a: f64) -> f64 {
    let ramps = (2.0 * speed * speed - entry * entry - exit * exit) / (2.0 * a);
    assert!(ramps <= length);
    (speed - entry) / a + (speed - exit) / a + (length - ramps) / speed
}

/// The zigzag's time with each corner at `corner` mm/s; nothing follows
/// its last move, which ends at rest.
fn joined_legs(corner: f64) -> f64 {
    trapezoid(20.0, 100.0, (0.0, corner), 1000.0)
        + 3.0 * trapezoid(20.0, 100.0, (corner, corner), 1000.0)
        + trapezoid(20.0, 100.0, (corner, 0.0), 1000.0)
}

/// The speed through a 90° corner blended within `tolerance` (in single
/// precision, as a step keeps it) at 1000 mm/s²: the arc's radius is
/// ε·cos 45° / (1 − cos 45°).
fn square_corner(tolerance: f64) -> f64 {
    let tolerance = f64::from(tolerance as f32);
    let half = std::f64::consts::FRAC_1_SQRT_2;
    (1000.0 * tolerance * half / (1.0 - half)).sqrt()
}

/// The in-position wait after an exact stop.
const SETTLE: f64 = 0.010;

#[test]
fn the_module_example_joins_after_the_first_move() {
    let mut control = PathControl::default();
    assert!(control.code("G642") && control.code("SOFT"));
    let first = control.step(false, false);
    assert_eq!((first.path_mode, first.jerk_limited), (PathMode::ExactStop, true));
    let second = control.step(false, false);
    assert_eq!((second.path_mode, second.corner_tolerance), (PathMode::Continuous, ASSUMED_CONTOUR_TOLERANCE as f32));
    control.subprogram_end();
    assert_eq!(control.step(false, false).path_mode, PathMode::ExactStop);
}

#[test]
fn g60_stops_at_every_corner() {
    // The reset default: every leg from rest to rest, the settle between.
    let timing = timed(&zigzag("", ""));
    assert_eq!(breaks(&timing), [(0, "exact-stop"), (1, "exact-stop"), (2, "exact-stop"), (3, "exact-stop")]);
    close(timing.total_time(), 5.0 * trapezoid(20.0, 100.0, (0.0, 0.0), 1000.0) + 4.0 * SETTLE);
    close(timed(&zigzag("G64 G60", "")).total_time(), timing.total_time());
}

#[test]
fn g64_and_g642_join_corners_within_their_tolerances() {
    let g64 = timed(&zigzag("G64", ""));
    assert_eq!(breaks(&g64), [(0, "accuracy"), (1, "accuracy"), (2, "accuracy"), (3, "accuracy")]);
    close(g64.breaks[0].at, square_corner(ASSUMED_G64_TOLERANCE) * 60.0);
    close(g64.total_time(), joined_legs(square_corner(ASSUMED_G64_TOLERANCE)));
    let g642 = timed(&zigzag("G642", ""));
    close(g642.total_time(), joined_legs(square_corner(ASSUMED_CONTOUR_TOLERANCE)));
    // CTOL widens the tolerance: a faster corner.
    let wide = timed(&zigzag("G642 CTOL=0.5", ""));
    close(wide.total_time(), joined_legs(square_corner(0.5)));
    let totals = [g64.total_time(), g642.total_time(), wide.total_time()];
    assert!(totals[0] > totals[1] && totals[1] > totals[2], "{totals:?}");
    // A negative CTOL restores the machine's; G643 and G645 round alike,
    // G644 as G64.
    close(timed(&zigzag("G642 CTOL=0.5 CTOL=-1", "")).total_time(), g642.total_time());
    close(timed(&zigzag("G645", "")).total_time(), g642.total_time());
    close(timed(&zigzag("G644", "")).total_time(), g64.total_time());
}

#[test]
fn g641_rounds_within_adis() {
    // At a square corner the blend leaves the corner by ADIS·tan 22.5°.
    let tolerance = 0.5 * std::f64::consts::FRAC_PI_8.tan();
    close(timed(&zigzag("G641 ADIS=0.5", "")).total_time(), joined_legs(square_corner(tolerance)));
    // Without ADIS G641 is G64.
    close(timed(&zigzag("G641", "")).total_time(), timed(&zigzag("G64", "")).total_time());
}

#[test]
fn soft_runs_slower_than_brisk_on_the_same_moves() {
    // One 20 mm move from rest to rest: F/A + A/J + L/F under SOFT.
    let soft = timed(&[("SOFT", [20.0, 0.0])]).total_time();
    close(soft, 100.0 / 1000.0 + 1000.0 / ASSUMED_JERK + 20.0 / 100.0);
    close(timed(&[("BRISK", [20.0, 0.0])]).total_time(), trapezoid(20.0, 100.0, (0.0, 0.0), 1000.0));
    let (soft, brisk) = (timed(&zigzag("G642 SOFT", "")), timed(&zigzag("G642 BRISK", "")));
    assert!(soft.total_time() > brisk.total_time(), "{} <= {}", soft.total_time(), brisk.total_time());
}

#[test]
fn g9_stops_at_the_end_of_its_block_only() {
    let timing = timed(&zigzag("G64", "G9"));
    assert_eq!(breaks(&timing), [(0, "accuracy"), (1, "exact-stop"), (2, "accuracy"), (3, "accuracy")]);
}

#[test]
fn m17_ends_continuous_path_mode_and_ret_does_not() {
    // The subprogram's last block is the second; the caller goes on.
    let ended = timed(&zigzag("G642", "M17"));
    assert_eq!(breaks(&ended), [(0, "accuracy"), (1, "exact-stop"), (2, "accuracy"), (3, "accuracy")]);
    let returned = timed(&zigzag("G642", ""));
    assert!(returned.total_time() < ended.total_time());
}

#[test]
fn the_machines_accelerations_set_the_ramps() {
    let configured = MachineConfig {
        feed_acceleration: Some(250),
        rapid_acceleration: Some(2000),
        spindle_acceleration: Some(600),
        ..machine()
    };
    let set = dynamics(&configured);
    let ramps = (set.feed_acceleration, set.continuity_acceleration, set.rapid_acceleration, set.spindle_acceleration);
    assert_eq!(ramps, (250.0, 250.0, 2000.0, 600.0));
    // 100 mm at 100 mm/s ramping at 250 mm/s²: 40 mm of ramps.
    let line = timed_on(&configured, &[("", [100.0, 0.0])]);
    close(line.total_time(), 2.0 * 100.0 / 250.0 + 60.0 / 100.0);
    let assumed = dynamics(&machine());
    assert_eq!(
        (assumed.feed_acceleration, assumed.rapid_acceleration, assumed.jerk),
        (1000.0, 1000.0, Some(ASSUMED_JERK))
    );
}

#[test]
fn the_reset_modes_come_from_the_catalogue_and_bad_distances_are_refused() {
    let mut control = PathControl::default();
    let first = control.step(false, false);
    assert!(!first.jerk_limited);
    // G60 in force: the next junction stops.
    assert_eq!(control.step(false, false).path_mode, PathMode::ExactStop);
    assert!(!control.code("G1") && !control.code("G9"));
    assert_eq!(control.address("X", 5.0), Ok(false));
    let refused = control.address("adis", -0.5).unwrap_err();
    assert_eq!(refused, PathError { address: "ADIS".into(), value: -0.5 });
    assert_eq!(refused.to_string(), "ADIS=-0.5: a rounding distance is a length of at least 0 mm");
    assert!(control.address("ADISPOS", f64::NAN).is_err() && control.address("CTOL", f64::INFINITY).is_err());
    // ADISPOS rounds G0 blocks under G641.
    control.code("G641");
    assert_eq!(control.address("ADISPOS", 2.0), Ok(true));
    control.step(false, true);
    let tolerance = (2.0 * std::f64::consts::FRAC_PI_8.tan()) as f32;
    assert_eq!(control.step(false, false).corner_tolerance, tolerance);
}
