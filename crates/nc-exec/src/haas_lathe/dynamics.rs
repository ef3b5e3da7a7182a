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
//! - G64 joins every feed block to the next (programmed joining): the
//!   manual describes no corner recognition, so no tolerance angle stops
//!   the path at a corner, and no move is too short to join, since the
//!   control looks ahead (G103 limits it) rather than one block;
//! - a 1 ms interpolator tick and 1 µm chord error bound the speed on arcs;
//! - the pause between unjoined blocks and the in-position wait are the
//!   machine description's, as for every control.

use std::fmt;

use crate::{
    machine::MachineConfig,
    velocity::{Dynamics, Joining, Reason, Terms},
};

const ASSUMED_ACCELERATION: f64 = 1000.0;
const ASSUMED_TICK: f64 = 0.001;
const ASSUMED_CHORD_ERROR: f64 = 0.001;

/// The velocity model's parameters for a Haas lathe `machine`.
pub fn dynamics(machine: &MachineConfig) -> Dynamics {
    Dynamics {
        joining: Joining::Programmed,
        // With programmed joining no corner is compared with the angle.
        tolerance_angle: 180.0,
        tolerance_cosine: -1.0,
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
        Reason::JoiningOff => "continuity-off",
        Reason::Corner { .. } => "corner",
        Reason::Rapid => "rapid",
        Reason::Thread => "thread",
        Reason::NonMotion => "non-motion",
        Reason::ShortBlock { .. } => "short-block",
        Reason::BeyondThreeAxes => "beyond-three-axes",
        Reason::LookAhead => "look-ahead",
        Reason::ArcLimit { .. } => "arc-limit",
        Reason::Accuracy { .. } => "accuracy",
        Reason::Overload { .. } => "overload",
        Reason::Centrifugal { .. } => "centrifugal",
        Reason::WindowEnd { .. } => "window-end",
        Reason::ContinuityLength { .. } => "continuity-length",
    }
}

/// The reason in the control's terms.
fn describe(reason: &Reason, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    match reason {
        Reason::Unjoined | Reason::ExactStop => {
            f.write_str("exact stop (G09 in the block, or G61 in force): the axes stop and wait in position")
        }
        Reason::JoiningOff => f.write_str("the control joins no blocks"),
        Reason::Corner { angle, limit } => write!(f, "a corner of {angle:.1}°, not below {limit:.1}°"),
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
