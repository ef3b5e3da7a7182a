//! The Haas lathe velocity policy: the parameters of the velocity model
//! for this control, and how it tells the reasons of its breaks.
//!
//! The manual gives the modes and no figures: G09 stops exactly in one
//! block, G61 in every block until G64, the default, which joins the
//! blocks (lathe manual §5.8 (001:73, 001:133-134)). Everything numeric is
//! an assumption until the machine's configuration says otherwise:
//! - the ramps: 1000 mm/s² for feed, continuous path and rapid, as for
//!   the project's other controls; the seed names no acceleration
//!   (lathe manual §5.6, the time model is inferred there);
//! - G64 joins feed blocks through corners under 45° and stops at sharper
//!   ones (a shoulder, a reversal): the manual gives no corner rule, and
//!   Haas's corner-rounding Setting 85 is not in it; no move is too short
//!   to join, since the control looks ahead (G103 limits it) rather than
//!   one block;
//! - a 1 ms interpolator tick and 1 µm chord error bound the speed on arcs;
//! - the pause between unjoined blocks and the in-position wait are the
//!   machine description's, as for every control.

use std::fmt;

use crate::{
    machine::MachineConfig,
    velocity::{Dynamics, Joining, Reason, Terms},
};

const ASSUMED_ACCELERATION: f64 = 1000.0;
const ASSUMED_CORNER: f64 = 45.0;
const ASSUMED_TICK: f64 = 0.001;
const ASSUMED_CHORD_ERROR: f64 = 0.001;

/// The velocity model's parameters for a Haas lathe `machine`.
pub fn dynamics(machine: &MachineConfig) -> Dynamics {
    Dynamics {
        joining: Joining::Automatic,
        tolerance_angle: ASSUMED_CORNER,
        tolerance_cosine: ASSUMED_CORNER.to_radians().cos(),
        feed_acceleration: ASSUMED_ACCELERATION,
        continuity_acceleration: ASSUMED_ACCELERATION,
        rapid_acceleration: ASSUMED_ACCELERATION,
        block_pause: f64::from(machine.block_pause_ms) / 1000.0,
        settle_time: f64::from(machine.settle_time_ms) / 1000.0,
        min_continuity: 0.0,
        min_tight_joining: 0.0,
        tick: ASSUMED_TICK,
        chord_error: ASSUMED_CHORD_ERROR,
        m_function_time: f64::from(machine.m_function_ms) / 1000.0,
        tool_change_time: f64::from(machine.tool_change_ms) / 1000.0,
        envelope: None,
        terms: &TERMS,
    }
}

/// The reasons of breaks in the Haas manual's terms.
static TERMS: Terms = Terms { code, describe };

/// A short name for scripts.
fn code(reason: &Reason) -> &'static str {
    match reason {
        Reason::Unjoined | Reason::ExactStop => "exact-stop",
        other => other.neutral_code(),
    }
}

/// The reason in the control's terms.
fn describe(reason: &Reason, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    match reason {
        Reason::Unjoined | Reason::ExactStop => {
            f.write_str("exact stop (G09 in the block, or G61 in force): the axes stop and wait in position")
        }
        Reason::JoiningOff => f.write_str("the control joins no blocks"),
        Reason::Corner { angle, limit } => {
            write!(f, "a corner of {angle:.1}°, not below the {limit:.0}° the path is joined through (assumed)")
        }
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
        Reason::Accuracy { angle } => write!(f, "a corner of {angle:.1}°: the accuracy (G187) limits the speed"),
        Reason::Overload { angle } => write!(f, "a corner of {angle:.1}°: the ramps limit the speed"),
        Reason::Centrifugal { radius } => write!(f, "an arc of radius {radius:.3} mm limits the speed"),
        Reason::WindowEnd { blocks } => write!(f, "the look-ahead of {blocks} blocks ends"),
        Reason::ContinuityLength { limit } => write!(f, "a block shorter than {limit:.3} mm breaks the path"),
    }
}

#[cfg(test)]
mod tests {
    use ncc_catalog::Dialect;

    use crate::{
        machine::MachineConfig,
        run::{NoFiles, Step, run_into},
        velocity::{Break, Profile, Reason, Timer, TimingSink},
    };

    /// The breaks of a run, by the program's line and reason.
    #[derive(Default)]
    struct Breaks(Vec<(usize, Reason)>);

    impl TimingSink for Breaks {
        fn speed_break(&mut self, _step: &Step, speed_break: Break) {
            self.0.push((speed_break.step, speed_break.reason.reason));
        }

        fn timed(&mut self, _step: &Step, _profile: Profile) {}
    }

    fn breaks(text: &str) -> Vec<(usize, &'static str)> {
        let machine = MachineConfig::of_control(Dialect::HaasLathe);
        let dynamics = super::dynamics(&machine);
        let mut timer = Timer::new(machine.step_axes(), &dynamics, Breaks::default());
        run_into(text, &NoFiles, &machine, 100, &mut timer);
        timer.finish().0.into_iter().map(|(step, reason)| (step, super::code(&reason))).collect()
    }

    #[test]
    fn g64_joins_tangent_blocks_and_stops_at_shoulders_and_reversals() {
        // Steps: 0 G98, 1 the rapid, 2 Z-10., 3 the arc tangent to it and
        // to 4, the shoulder X40., 5 back out X30., 6 M30; a break at step
        // n is at the junction after it.
        let text = "O1\nG98 F200.\nG00 X20. Z0\nG01 Z-10.\nG02 X30. Z-15. R5.\nG01 X40.\nX30.\nM30\n";
        let found = breaks(text);
        assert_eq!(found, [(1, "rapid"), (4, "corner"), (5, "non-motion")]);
        let exact = breaks(&text.replace("G01 Z-10.", "G61 G01 Z-10."));
        assert!(exact.contains(&(2, "exact-stop")) && exact.contains(&(3, "exact-stop")), "{exact:?}");
    }
}
