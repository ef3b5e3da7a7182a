//! The codes in force of Sinumerik's groups: G codes and the words that
//! stand in a group like one (`BSPLINE`, `SOFT`), by the catalogue, each
//! group starting at its default; `$P_GG[n]` reads them and `G[n]=k` sets
//! them by their index in the group (004:3335-3341).
//!
//! The run and the checker's walk share them: for the walk a group with no
//! code in force is one whose code it does not know.

use ncc_catalog::{Catalogue, Code, Dialect, Modality};

/// The catalogue's groups the run and the checker read, by their id.
pub mod groups {
    pub const MOTION: &str = "G1";
    pub const FRAMES: &str = "G3";
    pub const PLANE: &str = "G6";
    pub const TOOL_RADIUS: &str = "G7";
    pub const WORK_OFFSETS: &str = "G8";
    pub const MACHINE_COORDINATES: &str = "G9";
    pub const PATH_MODE: &str = "G10";
    pub const UNITS: &str = "G13";
    pub const DIMENSIONS: &str = "G14";
    pub const FEED_MODE: &str = "G15";
    pub const ACCELERATION: &str = "G21";
    pub const ORIENTATION_ANGLES: &str = "G50";
    pub const SPINDLE: &str = "M2";
    pub const COOLANT: &str = "M3";
}

/// The code in force of every group of the catalogue.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// By group index; `None` for a group without a default, or whose code
    /// a static reading does not know.
    in_force: Vec<Option<&'static Code>>,
}

fn catalogue() -> &'static Catalogue {
    Dialect::Sinumerik.catalogue()
}

/// Millimetres in an inch.
pub const INCH: f64 = 25.4;

impl Modes {
    /// Millimetres per unit of the lengths a program writes: an inch
    /// under G70 and G700; `None` where the units are not known.
    pub fn mm_per_unit(&self) -> Option<f64> {
        Some(match self.get(groups::UNITS)? {
            "G70" | "G700" => INCH,
            _ => 1.0,
        })
    }

    pub fn at_reset() -> Modes {
        let catalogue = catalogue();
        let in_force = catalogue
            .groups
            .iter()
            .map(|group| group.default.as_deref().and_then(|d| catalogue.code_named(d)))
            .collect();
        Modes { in_force }
    }

    /// No group's code known: where a subprogram starts, or after a call.
    pub fn unknown() -> Modes {
        Modes { in_force: vec![None; catalogue().groups.len()] }
    }

    /// What holds whichever of two ways the program took: each group's code
    /// where both agree.
    pub fn join(&self, other: &Modes) -> Modes {
        let same = |(a, b): (&Option<&'static Code>, &Option<&'static Code>)| match (a, b) {
            (Some(a), Some(b)) if std::ptr::eq(*a, *b) => Some(*a),
            _ => None,
        };
        Modes { in_force: self.in_force.iter().zip(&other.in_force).map(same).collect() }
    }

    /// Forgets the code of `group` (`G[1]=R1`, a code a loop may change).
    pub fn forget(&mut self, group: &str) {
        if let Some(index) = catalogue().groups.iter().position(|g| g.id == group) {
            self.in_force[index] = None;
        }
    }

    /// Puts `code` in force when it is modal in a group; whether it is.
    pub fn set(&mut self, code: &'static Code) -> bool {
        let Some(group) = code.group.as_deref().filter(|_| code.modality == Modality::Modal) else { return false };
        match catalogue().groups.iter().position(|g| g.id == group) {
            Some(index) => {
                self.in_force[index] = Some(code);
                true
            }
            None => false,
        }
    }

    /// The code in force in group `group` (`"G1"`), as the catalogue
    /// writes it (`G1`, `BSPLINE`).
    pub fn get(&self, group: &str) -> Option<&'static str> {
        self.code(group).map(|code| code.code.as_str())
    }

    pub fn code(&self, group: &str) -> Option<&'static Code> {
        let index = catalogue().groups.iter().position(|g| g.id == group)?;
        self.in_force[index]
    }

    /// Puts the G codes in force that were in `saved` (SAVE), the M
    /// groups staying as they are.
    pub(crate) fn restore_g(&mut self, saved: &Modes) {
        for (index, group) in catalogue().groups.iter().enumerate() {
            if group.id.starts_with('G') {
                self.in_force[index] = saved.in_force[index];
            }
        }
    }

    /// Whether `code` is in force in its group.
    pub fn is(&self, group: &str, code: &str) -> bool {
        self.get(group) == Some(code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_start_at_their_defaults_and_take_modal_codes() {
        let mut modes = Modes::at_reset();
        assert_eq!((modes.get("G1"), modes.get("G10"), modes.get("G21")), (Some("G1"), Some("G60"), Some("BRISK")));
        let catalogue = catalogue();
        assert!(modes.set(catalogue.code_named("BSPLINE").unwrap()));
        assert!(modes.set(catalogue.code_named("SOFT").unwrap()));
        assert!(!modes.set(catalogue.code_named("G9").unwrap()), "block-only");
        assert!(modes.is("G1", "BSPLINE") && modes.is("G21", "SOFT"));
        assert_eq!(modes.code("G1").and_then(|code| code.index), catalogue.code_named("BSPLINE").unwrap().index);
    }
}
