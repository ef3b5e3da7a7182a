//! The Sinumerik velocity policy: the parameters of the velocity model for
//! this control ([`dynamics`]), how it tells the reasons of its breaks,
//! and the continuous-path modes a run keeps ([`PathControl`]), which give
//! each step how it joins the one before and how its ramps run.
//!
//! ```text
//! let mut control = PathControl::default();      // G60 BRISK
//! control.code("G642");
//! control.code("SOFT");
//! let first = control.step(false, false);        // into the first move
//! let second = control.step(false, false);       // joined, within 0.1 mm
//! control.subprogram_end();                      // M17: the next junction stops
//! ```
//!
//! The thesis names the modes and gives one rule: M17 and M30 end
//! continuous-path mode G641–G645, RET keeps it (004:1561-1563); so the
//! junction after a subprogram's last block is an exact stop. The rest is
//! Siemens documentation (digest §3.4, §6.6 items 17–18) and these
//! readings:
//! - G60 (the reset default, read from the catalogue as BRISK is) stops
//!   at the end of every block, G9 at the end of its own; a junction
//!   takes the mode in force when the block before it ran. G601–G603 (the
//!   exact-stop windows) are not told apart: the stop waits the machine's
//!   settle time;
//! - G64 rounds no corner, but lets the axes' speeds jump a little at a
//!   block change (machine data MAX_ACCEL_OVL_FACTOR); the model takes that
//!   as a corner tolerance of 0.01 mm (assumed), so a square corner at
//!   1000 mm/s² runs at about 4.9 mm/s. G644 (the axes' full dynamics) is
//!   taken as G64;
//! - G641 rounds within the distance ADIS (ADISPOS for G0) from the corner:
//!   the blend of a turn θ leaves the corner by ADIS·tan(θ/4), which the
//!   model takes at a square corner, ADIS·tan(22.5°), and never tighter
//!   than G64 (ADIS 0 is G64, as Siemens says). The shortening of the
//!   distance on short blocks is not modelled;
//! - G642, G643 and G645 round within the contour tolerance: machine data
//!   COMPRESS_POS_TOL, assumed 0.1 mm, or CTOL where the program writes it
//!   (a negative CTOL restores the machine's);
//! - the ramps are the machine description's (`feed-acceleration`,
//!   `rapid-acceleration`, `spindle-acceleration`), 1000 mm/s² and
//!   1000 rpm/s where it gives none, as for the project's other controls;
//!   SOFT limits the jerk to 50 000 mm/s³ (assumed: machines are
//!   commissioned with their own, and the seed gives none), BRISK and DRIVE
//!   ramp linearly;
//! - a 4 ms interpolator tick (assumed) and 1 µm chord error bound the
//!   speed on arcs;
//! - the pause between unjoined blocks and the in-position wait are the
//!   machine description's, as for every control.

use std::{f64::consts::FRAC_PI_8, fmt};

use ncc_catalog::Dialect;

use crate::{
    machine::MachineConfig,
    trace::PathMode,
    velocity::{Assumed, Dynamics, Reason, Terms},
};

const ASSUMED_ACCELERATION: f64 = 1000.0;
const ASSUMED_SPINDLE_ACCELERATION: f64 = 1000.0;
const ASSUMED_JERK: f64 = 50_000.0;
const ASSUMED_TICK: f64 = 0.004;
const ASSUMED_CHORD_ERROR: f64 = 0.001;
/// The corner tolerance G64's speed jumps amount to, mm.
const ASSUMED_G64_TOLERANCE: f64 = 0.01;
/// COMPRESS_POS_TOL, mm.
const ASSUMED_CONTOUR_TOLERANCE: f64 = 0.1;

/// The velocity model's parameters for a Sinumerik `machine`.
pub fn dynamics(machine: &MachineConfig) -> Dynamics {
    let assumed = Assumed {
        acceleration: ASSUMED_ACCELERATION,
        spindle_acceleration: ASSUMED_SPINDLE_ACCELERATION,
        tick: ASSUMED_TICK,
        chord_error: ASSUMED_CHORD_ERROR,
        jerk: Some(ASSUMED_JERK),
    };
    Dynamics::joined_within_tolerance(machine, assumed, &TERMS)
}

/// The continuous-path mode of group 10.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// G60.
    ExactStop,
    /// G64, G644.
    Continuous,
    /// G641.
    Distance,
    /// G642, G643, G645.
    Tolerance,
}

/// How the path passes into a step from the one before it, and how the
/// step ramps: the fields of [`crate::trace::Step`] of the same names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPath {
    pub path_mode: PathMode,
    pub corner_tolerance: f32,
    pub jerk_limited: bool,
}

/// An address of the modes with a value the control refuses.
#[derive(Debug, Clone, PartialEq)]
pub struct PathError {
    pub address: String,
    pub value: f64,
}

impl fmt::Display for PathError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}: a rounding distance is a length of at least 0 mm", self.address, self.value)
    }
}

impl std::error::Error for PathError {}

/// The continuous-path and acceleration modes in force, as a run keeps
/// them block by block.
#[derive(Debug, Clone, PartialEq)]
pub struct PathControl {
    mode: Mode,
    soft: bool,
    /// ADIS and ADISPOS, mm.
    distance: f64,
    rapid_distance: f64,
    /// CTOL where programmed, mm.
    contour_tolerance: Option<f64>,
    /// How the block that ran last passes into the next: `None` before the
    /// first.
    ending: Option<(PathMode, f32)>,
}

impl Default for PathControl {
    /// The modes after reset: the catalogue's defaults of groups 10 and 21.
    fn default() -> Self {
        let mut control = PathControl {
            mode: Mode::ExactStop,
            soft: false,
            distance: 0.0,
            rapid_distance: 0.0,
            contour_tolerance: None,
            ending: None,
        };
        let catalogue = Dialect::Sinumerik.catalogue();
        for group in ["G10", "G21"] {
            for code in catalogue.codes_in(group).filter(|code| code.reset_default) {
                control.code(&code.code);
            }
        }
        control
    }
}

impl PathControl {
    /// A code of the modes: G60, G64, G641–G645, SOFT, BRISK, DRIVE. Whether
    /// it is one of them.
    pub fn code(&mut self, name: &str) -> bool {
        match name.to_ascii_uppercase().as_str() {
            "G60" => self.mode = Mode::ExactStop,
            "G64" | "G644" => self.mode = Mode::Continuous,
            "G641" => self.mode = Mode::Distance,
            "G642" | "G643" | "G645" => self.mode = Mode::Tolerance,
            "SOFT" => self.soft = true,
            "BRISK" | "DRIVE" => self.soft = false,
            _ => return false,
        }
        true
    }

    /// An address of the modes written with its value: ADIS, ADISPOS,
    /// CTOL. Whether it is one of them, or why its value is refused.
    pub fn address(&mut self, name: &str, value: f64) -> Result<bool, PathError> {
        let name = name.to_ascii_uppercase();
        let refused = || Err(PathError { address: name.clone(), value });
        match name.as_str() {
            "ADIS" | "ADISPOS" if !(value >= 0.0 && value.is_finite()) => return refused(),
            "ADIS" => self.distance = value,
            "ADISPOS" => self.rapid_distance = value,
            "CTOL" if !value.is_finite() => return refused(),
            "CTOL" => self.contour_tolerance = (value >= 0.0).then_some(value),
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// M17 or M30 ends the subprogram: the path stops after its last block.
    /// RET does not call this.
    pub fn subprogram_end(&mut self) {
        if let Some((path_mode, _)) = &mut self.ending {
            *path_mode = PathMode::ExactStop;
        }
    }

    /// The next step's fields: how the path passes into it from the block
    /// that ran before (by the modes in force then), and its ramps. `G9` in
    /// the block (`exact_stop_here`) stops the path at its end; `rapid`
    /// says it is a G0 move, which G641 rounds by ADISPOS.
    pub fn step(&mut self, exact_stop_here: bool, rapid: bool) -> StepPath {
        let (path_mode, corner_tolerance) = self.ending.unwrap_or((PathMode::ExactStop, f32::INFINITY));
        let tolerance = match self.mode {
            Mode::ExactStop => f64::INFINITY,
            Mode::Continuous => ASSUMED_G64_TOLERANCE,
            Mode::Distance => {
                let distance = if rapid { self.rapid_distance } else { self.distance };
                (distance * FRAC_PI_8.tan()).max(ASSUMED_G64_TOLERANCE)
            }
            Mode::Tolerance => self.contour_tolerance.unwrap_or(ASSUMED_CONTOUR_TOLERANCE),
        };
        let ending = match exact_stop_here || self.mode == Mode::ExactStop {
            true => PathMode::ExactStop,
            false => PathMode::Continuous,
        };
        self.ending = Some((ending, tolerance as f32));
        StepPath { path_mode, corner_tolerance, jerk_limited: self.soft }
    }
}

/// The reasons of breaks in Siemens's terms.
static TERMS: Terms = Terms { code: Reason::neutral_code, describe };

/// The reason in the control's terms.
fn describe(reason: &Reason, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    match reason {
        Reason::Unjoined => f.write_str("the control pauses for the next block"),
        Reason::ExactStop => f.write_str(
            "exact stop (G60 in force or G9 in the block before, or the end of a subprogram by M17 or M30): the axes stop and wait in position",
        ),
        Reason::JoiningOff => f.write_str("the control joins no blocks"),
        Reason::Corner { angle, limit } => write!(f, "a corner of {angle:.1}°, not below {limit:.0}°"),
        Reason::Rapid => f.write_str("a rapid move (G0) starts and ends at a stop"),
        Reason::Thread => f.write_str("a thread or a tap runs synchronised with the spindle, from a stop"),
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
        Reason::Accuracy { angle } => write!(
            f,
            "a corner of {angle:.1}°: the rounding of G64, G641 (ADIS) or G642–G645 (the contour tolerance) limits the speed through it"
        ),
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
mod tests;
