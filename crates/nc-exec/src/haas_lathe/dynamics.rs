//! The Haas lathe velocity policy: the parameters of the velocity model
//! for this control, and how it tells the reasons of its breaks.
//!
//! The manual gives the modes and no figures: G09 stops exactly in one
//! block, G61 in every block until G64, the default, which joins the
//! blocks (lathe manual §5.8 (001:73, 001:133-134)). It names G187
//! (accuracy control) and G103 (look-ahead limit) without a format or a
//! meaning beyond their titles (001:232, 001:279); their words and levels
//! are Haas's documentation, not the manual's. The ramps come from the
//! machine description (`feed-acceleration`, `rapid-acceleration`,
//! `spindle-acceleration`, `corner-rounding`) and everything else numeric
//! is an assumption:
//! - the ramps, where the machine gives none: 1000 mm/s² for feed (on a
//!   continuous path too) and for rapid, as for the project's other
//!   controls; the seed names no acceleration (lathe manual §5.6, the time
//!   model is inferred there);
//! - G64 joins every feed block to the next, and a corner is run at most
//!   at the speed that keeps the path within the corner tolerance in force
//!   ([`crate::velocity::corner_speed`] at the feed acceleration), so that a
//!   reversal comes to rest; no move is too short to join;
//! - the corner tolerance is Setting 85 (maximum corner rounding), assumed
//!   0.05 mm where the machine gives none, until G187 changes it: `G187 E`
//!   sets it, `G187 P1` (rough), `P2` (medium) and `P3` (finish) take
//!   0.2, 0.05 and 0.01 mm (assumed: Haas gives the levels no figures),
//!   and `G187` alone restores Setting 85; E wins over P;
//! - `G103 P1` reads no block ahead of the one running: every junction
//!   stops and pauses for the next block (the machine's block pause), as
//!   unjoined blocks do; `G103` alone, `P0` or a larger P leaves the model's
//!   one block of look-ahead, which is the least that joins blocks: the
//!   model plans no further ahead in any case;
//! - the spindle changes its speed at 1000 rpm/s where the machine gives
//!   none; a cut waits for the spindle's rpm (velocity model), and under
//!   G96 the control commands the rpm of a rapid move's end point as the
//!   move starts (Fanuc's convention; the manual is silent);
//! - a 1 ms interpolator tick and 1 µm chord error bound the speed on arcs;
//! - the pause between unjoined blocks and the in-position wait are the
//!   machine description's, as for every control.

use std::fmt;

use crate::{
    machine::MachineConfig,
    velocity::{Assumed, Dynamics, Reason, Terms},
};

const ASSUMED_ACCELERATION: f64 = 1000.0;
const ASSUMED_SPINDLE_ACCELERATION: f64 = 1000.0;
const ASSUMED_TICK: f64 = 0.001;
const ASSUMED_CHORD_ERROR: f64 = 0.001;
/// Setting 85 in mm, and the tolerances of G187's levels P1, P2 and P3.
const ASSUMED_CORNER_ROUNDING: f64 = 0.05;
const ASSUMED_LEVELS: [f64; 3] = [0.2, 0.05, 0.01];

/// The velocity model's parameters for a Haas lathe `machine`.
pub fn dynamics(machine: &MachineConfig) -> Dynamics {
    let assumed = Assumed {
        acceleration: ASSUMED_ACCELERATION,
        spindle_acceleration: ASSUMED_SPINDLE_ACCELERATION,
        tick: ASSUMED_TICK,
        chord_error: ASSUMED_CHORD_ERROR,
        // The manual names no jerk limit: linear ramps.
        jerk: None,
    };
    Dynamics::joined_within_tolerance(machine, assumed, &TERMS)
}

/// Setting 85, the corner tolerance in mm without G187 or after a G187
/// without P or E.
pub(crate) fn corner_rounding(machine: &MachineConfig) -> f64 {
    machine.corner_rounding_um.map_or(ASSUMED_CORNER_ROUNDING, |um| f64::from(um) / 1000.0)
}

/// The corner tolerance in mm of G187's smoothness level `P`: 1 rough, 2
/// medium, 3 finish; `None` for another number.
pub(crate) fn smoothness_level(level: f64) -> Option<f64> {
    let index = [1.0, 2.0, 3.0].iter().position(|&number| number == level)?;
    Some(ASSUMED_LEVELS[index])
}

/// The reasons of breaks in the Haas manual's terms.
static TERMS: Terms = Terms { code, describe };

/// A short name for scripts.
fn code(reason: &Reason) -> &'static str {
    match reason {
        Reason::Unjoined => "g103",
        Reason::ExactStop => "exact-stop",
        other => other.neutral_code(),
    }
}

/// The reason in the control's terms.
fn describe(reason: &Reason, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    match reason {
        Reason::Unjoined => {
            f.write_str("G103 P1 reads no block ahead: the axes stop and the control pauses for the next block")
        }
        Reason::ExactStop => {
            f.write_str("exact stop (G09 in the block, or G61 in force): the axes stop and wait in position")
        }
        Reason::JoiningOff => f.write_str("the control joins no blocks"),
        Reason::Corner { angle, limit } => write!(f, "a corner of {angle:.1}°, not below {limit:.0}°"),
        Reason::Rapid => f.write_str("a rapid move (G00) starts and ends at a stop"),
        Reason::Thread => f.write_str("a thread (G32, G76, G92) runs synchronised with the spindle, from a stop"),
        Reason::NonMotion => f.write_str("a block without motion between moves"),
        Reason::ShortBlock { duration, limit } => write!(
            f,
            "a block of {:.0} ms at its feed, shorter than the {:.0} ms joining needs",
            duration * 1000.0,
            limit * 1000.0
        ),
        Reason::BeyondThreeAxes => f.write_str("the path is joined on the first three axes only"),
        Reason::LookAhead => f.write_str("the next block must be able to stop within itself"),
        Reason::ArcLimit { radius } => write!(
            f,
            "an arc of radius {radius:.3} mm: at most {:.0} µm chord error per {:.0} ms (assumed)",
            ASSUMED_CHORD_ERROR * 1000.0,
            ASSUMED_TICK * 1000.0
        ),
        Reason::Accuracy { angle } => {
            write!(f, "a corner of {angle:.1}°: the corner tolerance (Setting 85, or G187) limits the speed through it")
        }
        Reason::Overload { angle } => write!(f, "a corner of {angle:.1}°: the ramps limit the speed"),
        Reason::Centrifugal { radius } => write!(f, "an arc of radius {radius:.3} mm limits the speed"),
        Reason::WindowEnd { blocks } => write!(f, "the look-ahead of {blocks} blocks ends"),
        Reason::ContinuityLength { limit } => write!(f, "a block shorter than {limit:.3} mm breaks the path"),
        Reason::Spindle { from, to } => {
            write!(f, "the cut waits for the spindle to get from {from:.0} to {to:.0} rpm (spindle-acceleration)")
        }
    }
}

#[cfg(test)]
mod tests {
    use ncc_catalog::Dialect;

    use crate::{
        machine::MachineConfig,
        run::{NoFiles, run},
        velocity::{Timing, time},
    };

    fn lathe() -> MachineConfig {
        MachineConfig::of_control(Dialect::HaasLathe)
    }

    fn timed_on(machine: &MachineConfig, text: &str) -> Timing {
        let trace = run(text, &NoFiles, machine, 1000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        time(&trace, &super::dynamics(machine))
    }

    /// The breaks of a timing by step and code.
    fn breaks(timing: &Timing) -> Vec<(usize, &'static str)> {
        timing.breaks.iter().map(|b| (b.step, b.reason.code())).collect()
    }

    fn close(actual: f64, expected: f64) {
        assert!((actual - expected).abs() <= expected.abs() * 1e-6 + 1e-9, "{actual} != {expected}");
    }

    /// Seconds of a move of `length` mm at up to `speed` mm/s from `entry`
    /// to `exit` mm/s, ramping at `a` mm/s² (long enough to reach `speed`).
    fn trapezoid(length: f64, speed: f64, (entry, exit): (f64, f64), a: f64) -> f64 {
        let ramps = (2.0 * speed * speed - entry * entry - exit * exit) / (2.0 * a);
        assert!(ramps <= length);
        (speed - entry) / a + (speed - exit) / a + (length - ramps) / speed
    }

    /// The speed through a 90° corner blended within `tolerance` at `a`:
    /// the arc's radius is ε·cos 45° / (1 − cos 45°).
    fn square_corner(tolerance: f64, a: f64) -> f64 {
        let half = std::f64::consts::FRAC_1_SQRT_2;
        (a * tolerance * half / (1.0 - half)).sqrt()
    }

    /// Five 20 mm legs at 100 mm/s turning 90° four times, under `modes`.
    fn zigzag(modes: &str) -> String {
        format!("O1\nG98 {modes} F6000.\nG01 Z-20.\nX40.\nZ-40.\nX0.\nZ-60.\nM30\n")
    }

    const SETTLE: f64 = 0.010;
    const PAUSE: f64 = 0.020;

    #[test]
    fn g64_joins_corners_within_the_tolerance_and_stops_at_reversals() {
        // Steps: 0 G98, 1 the rapid, 2 Z-10., 3 the arc tangent to it, 4
        // the shoulder X40., 5 back out X30., 6 M30; a break at step n is at
        // the junction after it. At 3.3 mm/s the shoulder's 90° keeps the
        // feed; the reversal comes to rest.
        let text = "O1\nG98 F200.\nG00 X20. Z0\nG01 Z-10.\nG02 X30. Z-15. R5.\nG01 X40.\nX30.\nM30\n";
        let found = timed_on(&lathe(), text);
        assert_eq!(breaks(&found), [(1, "rapid"), (4, "accuracy"), (5, "non-motion")]);
        assert_eq!(found.breaks[1].at, 0.0);
        let exact = breaks(&timed_on(&lathe(), &text.replace("G01 Z-10.", "G61 G01 Z-10.")));
        assert!(exact.contains(&(2, "exact-stop")) && exact.contains(&(3, "exact-stop")), "{exact:?}");
    }

    #[test]
    fn the_machines_accelerations_set_the_ramps() {
        // 100 mm at 100 mm/s, from rest to rest, then the in-position wait.
        let line = "O1\nG98 F6000.\nG01 Z-100.\nM30\n";
        close(timed_on(&lathe(), line).total_time(), trapezoid(100.0, 100.0, (0.0, 0.0), 1000.0) + SETTLE);
        let slow = MachineConfig { feed_acceleration: Some(250), ..lathe() };
        close(timed_on(&slow, line).total_time(), 2.0 * 100.0 / 250.0 + (100.0 - 40.0) / 100.0 + SETTLE);
        // G00 at the default 10 m/min, ramping at the rapid acceleration.
        let rapid = "O1\nG00 Z-100.\nM30\n";
        let speed = 10_000.0 / 60.0;
        let quick = MachineConfig { rapid_acceleration: Some(500), ..lathe() };
        close(timed_on(&quick, rapid).total_time(), trapezoid(100.0, speed, (0.0, 0.0), 500.0) + SETTLE);
        close(timed_on(&slow, rapid).total_time(), trapezoid(100.0, speed, (0.0, 0.0), 1000.0) + SETTLE);
    }

    #[test]
    fn g187_bounds_the_corner_speed_by_its_tolerance() {
        let legs = |corner: f64| {
            trapezoid(20.0, 100.0, (0.0, corner), 1000.0)
                + 3.0 * trapezoid(20.0, 100.0, (corner, corner), 1000.0)
                + trapezoid(20.0, 100.0, (corner, 0.0), 1000.0)
                + SETTLE
        };
        let mut totals = Vec::new();
        for tolerance in [0.2, 0.02] {
            let timing = timed_on(&lathe(), &zigzag(&format!("G187 E{tolerance}")));
            let corner = square_corner(tolerance, 1000.0);
            close(timing.total_time(), legs(corner));
            assert_eq!(
                breaks(&timing),
                [(1, "accuracy"), (2, "accuracy"), (3, "accuracy"), (4, "accuracy"), (5, "non-motion")]
            );
            close(timing.breaks[0].at, corner * 60.0);
            close(timing.profiles[2].entry, corner * 60.0);
            totals.push(timing.total_time());
        }
        assert!(totals[1] > totals[0], "{totals:?}");
        // Setting 85 without G187, and after G187 alone; the machine's own.
        let setting = legs(square_corner(super::ASSUMED_CORNER_ROUNDING, 1000.0));
        close(timed_on(&lathe(), &zigzag("")).total_time(), setting);
        // A corner takes the tolerance of the block after it: all four are
        // Setting 85's again from X40. on.
        let restored = zigzag("G187 E0.2").replace("X40.", "G187 X40.");
        close(timed_on(&lathe(), &restored).total_time(), setting);
        let machine = MachineConfig { corner_rounding_um: Some(20), ..lathe() };
        close(timed_on(&machine, &zigzag("")).total_time(), legs(square_corner(0.02, 1000.0)));
        // Finer levels run slower: P1 rough, P2 medium, P3 finish.
        let levels: Vec<f64> =
            (1..=3).map(|level| timed_on(&lathe(), &zigzag(&format!("G187 P{level}"))).total_time()).collect();
        assert!(levels[0] < levels[1] && levels[1] < levels[2], "{levels:?}");
        close(levels[2], legs(square_corner(super::ASSUMED_LEVELS[2], 1000.0)));
    }

    #[test]
    fn g187_refuses_a_level_or_tolerance_it_has_not() {
        for modes in ["G187 P4", "G187 E0", "G187 P1.5", "G187 P3 G103 P1"] {
            let trace = run(&zigzag(modes), &NoFiles, &lathe(), 1000);
            assert_eq!(trace.findings.len(), 1, "{modes}: {:?}", trace.findings);
            assert!(
                trace.findings[0].stops() && trace.findings[0].message.starts_with("G1"),
                "{modes}: {:?}",
                trace.findings
            );
        }
    }

    #[test]
    fn g103_p1_stops_every_block_and_g103_joins_them_again() {
        // One block read at a time: each leg from rest to rest, then the
        // pause for the next block.
        let timing = timed_on(&lathe(), &zigzag("G103 P1"));
        close(timing.total_time(), 5.0 * (trapezoid(20.0, 100.0, (0.0, 0.0), 1000.0) + PAUSE));
        assert_eq!(breaks(&timing), [(1, "g103"), (2, "g103"), (3, "g103"), (4, "g103"), (5, "non-motion")]);
        for modes in ["G103 P1\nG103", "G103 P1\nG103 P0", "G103 P2"] {
            let joined = timed_on(&lathe(), &zigzag("").replace("G01 Z-20.", &format!("{modes}\nG01 Z-20.")));
            close(joined.total_time(), timed_on(&lathe(), &zigzag("")).total_time());
        }
        let trace = run(&zigzag("G103 P-1"), &NoFiles, &lathe(), 1000);
        assert!(trace.findings[0].message.starts_with("G103 P"), "{:?}", trace.findings);
    }

    #[test]
    fn a_cut_waits_for_the_spindle_to_reach_its_speed() {
        let machine = MachineConfig { spindle_acceleration: Some(500), ..lathe() };
        // M03 S2000 from rest: 4 s at 500 rpm/s; the cut waits for all of it.
        let cut = trapezoid(10.0, 10.0, (0.0, 0.0), 1000.0) + SETTLE;
        let text = "O1\nG97 S2000 M03\nG98 F600.\nG01 Z-10.\nM30\n";
        let timing = timed_on(&machine, text);
        assert_eq!(breaks(&timing), [(2, "non-motion"), (2, "spindle")]);
        close(timing.breaks[1].lost, 4.0);
        close(timing.profiles[2].duration, 4.0 + cut);
        close(timing.total_time(), 4.0 + cut);
        // A rapid of 25 mm (radius) before it runs while the spindle turns
        // up: a triangle at 1000 mm/s² of 2·sqrt(25/1000) s, and its settle.
        let rapid = 2.0 * (25.0f64 / 1000.0).sqrt() + SETTLE;
        let text = "O1\nG97 S2000 M03\nG98 F600.\nG00 X50.\nG01 Z-10.\nM30\n";
        let timing = timed_on(&machine, text);
        close(timing.breaks.iter().find(|b| b.reason.code() == "spindle").unwrap().lost, 4.0 - rapid);
        close(timing.total_time(), 4.0 + cut);
        // An S change under G97 in a block between cuts: down 1000 rpm, 2 s.
        let text = "O1\nG97 S2000 M03\nG98 F600.\nG01 Z-10.\nS1000\nG01 Z-20.\nM30\n";
        let timing = timed_on(&machine, text);
        let waits: Vec<(usize, f64)> =
            timing.breaks.iter().filter(|b| b.reason.code() == "spindle").map(|b| (b.step, b.lost)).collect();
        assert_eq!(waits.len(), 2);
        assert_eq!((waits[0].0, waits[1].0), (2, 4));
        close(waits[1].1, 2.0);
        close(timing.total_time(), 4.0 + cut + 2.0 + cut);
        // A dwell hides the run-up too; a spindle that follows at once waits not at all.
        let dwell = timed_on(&machine, "O1\nG97 S2000 M03\nG04 P1.5\nG98 F600.\nG01 Z-10.\nM30\n");
        close(dwell.total_time(), 4.0 + cut);
        let instant = MachineConfig { spindle_acceleration: Some(u32::MAX), ..lathe() };
        close(timed_on(&instant, text).total_time(), 2.0 * cut + 3000.0 / f64::from(u32::MAX));
    }

    #[test]
    fn under_g96_a_rapid_commands_its_end_rpm_and_the_cut_waits_for_it() {
        // At the centre G96 asks for the G50 clamp, 2000 rpm; the rapid out
        // to Ø40 asks for 1000·100/(π·40) rpm, which the spindle reaches
        // from rest 0.2828 s (a triangle of 20 mm) plus the settle after the
        // rapid starts. The face cut back to the centre follows the
        // diameter (its time is the exact integral), up to the clamp; the
        // rapid out again brings the spindle down from 2000 rpm, and the
        // turning cut at Ø40 waits for it.
        let text = "O1\nG50 S2000\nG96 S100 M03\nG99 F0.1\nG00 X40. Z0\nG01 X0\nG00 X40. Z1.\nG01 Z-5.\nM30\n";
        let accelerating = timed_on(&lathe(), text);
        let following = timed_on(&MachineConfig { spindle_acceleration: Some(u32::MAX), ..lathe() }, text);
        let at_40 = 1000.0 * 100.0 / (std::f64::consts::PI * 40.0);
        let rapid = 2.0 * (20.0f64 / 1000.0).sqrt() + SETTLE;
        let waits: Vec<(usize, f64)> =
            accelerating.breaks.iter().filter(|b| b.reason.code() == "spindle").map(|b| (b.step, b.lost)).collect();
        assert_eq!(waits.len(), 2, "{waits:?}");
        assert_eq!((waits[0].0, waits[1].0), (4, 6));
        close(waits[0].1, at_40 / 1000.0 - rapid);
        // The second rapid: 20 mm in X and 1 mm in Z at the same rate.
        let back = 2.0 * (20.0f64.hypot(1.0) / 1000.0).sqrt() + SETTLE;
        close(waits[1].1, (2000.0 - at_40) / 1000.0 - back);
        close(accelerating.total_time() - following.total_time(), waits[0].1 + waits[1].1);
    }
}
