//! How the control reads an arc, one rule for the interpreter and the
//! checker: the planes of arcs and of radius compensation, and the centre
//! refinement E.
//!
//! Planes (02 §1.16): machine constants R340 and R341
//! each hold four pairs of axis ordinals, first axis first. Their first
//! three pairs are the compensation planes of G17–G19 and G14–G16; all
//! eight are the interpolation planes, and an arc runs in the one of the
//! two axes it writes, I along the first axis and J along the second. A
//! constant of zeros reads as its default (`00233.112`, `00412.434`), so
//! the default G17 plane 12 is X–Y on a mill and X–Z on a lathe with axes
//! X, Z.

use crate::machine::MachineConfig;

/// The compensation plane of the plane code `code` (G17–G19 from R340,
/// G14–G16 from R341), first axis first; `None` for another code or a pair
/// that names an axis the machine does not have.
pub fn compensation_plane(machine: &MachineConfig, code: u32) -> Option<[u8; 2]> {
    match code {
        17..=19 => machine_plane(machine, 340, code - 17),
        14..=16 => machine_plane(machine, 341, code - 14),
        _ => None,
    }
}

/// The machine's interpolation planes, first axis first.
pub fn interpolation_planes(machine: &MachineConfig) -> impl Iterator<Item = [u8; 2]> + '_ {
    [340, 341]
        .into_iter()
        .flat_map(move |constant| (0..4).filter_map(move |pair| machine_plane(machine, constant, pair)))
}

/// The interpolation plane of an arc that writes the axes `one` and
/// `other`, first axis first; `None` when the machine has no such plane.
pub fn arc_plane(machine: &MachineConfig, one: u8, other: u8) -> Option<[u8; 2]> {
    arc_plane_of(interpolation_planes(machine), one, other)
}

fn arc_plane_of(mut planes: impl Iterator<Item = [u8; 2]>, one: u8, other: u8) -> Option<[u8; 2]> {
    let written = [one, other];
    planes.find(|plane| plane[0] != plane[1] && written.contains(&plane[0]) && written.contains(&plane[1]))
}

/// The machine's planes, read once: every arc and every block under radius
/// compensation asks.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Planes {
    /// The compensation planes of G14–G19, by code − 14.
    compensation: [Option<[u8; 2]>; 6],
    interpolation: Vec<[u8; 2]>,
}

impl Planes {
    pub fn of(machine: &MachineConfig) -> Planes {
        Planes {
            compensation: std::array::from_fn(|i| compensation_plane(machine, 14 + i as u32)),
            interpolation: interpolation_planes(machine).collect(),
        }
    }

    /// See [`compensation_plane`].
    pub fn compensation(&self, code: u32) -> Option<[u8; 2]> {
        *self.compensation.get(usize::try_from(code.checked_sub(14)?).ok()?)?
    }

    /// See [`arc_plane`].
    pub fn arc(&self, one: u8, other: u8) -> Option<[u8; 2]> {
        arc_plane_of(self.interpolation.iter().copied(), one, other)
    }
}

/// The centre refinement of an arc, `E` (02 §1.15): the preprocessor's
/// correction of I or J in thousandths of a µm, `Iz = I + E/1000`; decade 8
/// picks the word (0: I, 1: J). `raw` is E's raw value, in thousandths of
/// a µm as written (`E2.054` adds 2.054 µm to I).
pub fn refinement(raw: i64) -> Result<Refinement, InvalidRefinement> {
    let selector = raw.unsigned_abs() / REFINEMENT_SELECTOR;
    let amount = i64::try_from(raw.unsigned_abs() % REFINEMENT_SELECTOR).unwrap_or_default() * raw.signum();
    match selector {
        0 => Ok(Refinement { word: 0, amount }),
        1 => Ok(Refinement { word: 1, amount }),
        _ => Err(InvalidRefinement { selector }),
    }
}

/// Decade 8 of a refinement E picks I or J.
const REFINEMENT_SELECTOR: u64 = 10_000_000;

/// A correction of an arc's centre.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Refinement {
    /// The centre word corrected: 0 for I, 1 for J.
    pub word: usize,
    /// In thousandths of a µm.
    pub amount: i64,
}

/// A refinement whose decade 8 picks neither I nor J.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InvalidRefinement {
    /// Decade 8 and above, as written.
    pub selector: u64,
}

/// Pair `pair` (0 = decades 2–1) of a plane constant, as letters of the
/// configured axes.
fn machine_plane(machine: &MachineConfig, constant: u32, pair: u32) -> Option<[u8; 2]> {
    let planes = match machine.constant(constant) {
        0 => machine.default_constant(constant)?,
        planes => planes,
    };
    let ordinals = planes.unsigned_abs() / 100u64.pow(pair) % 100;
    let axis = |ordinal: u64| machine.axes.get(usize::try_from(ordinal).ok()?.checked_sub(1)?).copied();
    Some([axis(ordinals / 10)?, axis(ordinals % 10)?])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_planes_follow_the_machine_s_axes() {
        let mill = MachineConfig::default();
        let planes: Vec<String> =
            interpolation_planes(&mill).map(|plane| String::from_utf8(plane.to_vec()).unwrap()).collect();
        assert_eq!(planes, ["XY", "ZX", "YZ", "ZU", "YU", "UX"]);
        assert_eq!(compensation_plane(&mill, 18), Some(*b"ZX"));
        assert_eq!(arc_plane(&mill, b'X', b'Z'), Some(*b"ZX"));
        assert_eq!(arc_plane(&mill, b'X', b'C'), None);
        let lathe = MachineConfig { axes: b"XZ".to_vec(), ..MachineConfig::default() };
        assert_eq!(arc_plane(&lathe, b'Z', b'X'), Some(*b"XZ"));
        assert_eq!(compensation_plane(&lathe, 18), None);
        let swapped = MachineConfig { constants: [(340, 21)].into(), ..lathe.clone() };
        assert_eq!(arc_plane(&swapped, b'X', b'Z'), Some(*b"ZX"));
        for machine in [mill, lathe, swapped] {
            let planes = Planes::of(&machine);
            for code in 13..=20 {
                assert_eq!(planes.compensation(code), compensation_plane(&machine, code));
            }
            for (one, other) in [(b'X', b'Y'), (b'Z', b'X'), (b'X', b'Z'), (b'C', b'X')] {
                assert_eq!(planes.arc(one, other), arc_plane(&machine, one, other));
            }
        }
    }

    #[test]
    fn a_refinement_corrects_i_or_j() {
        assert_eq!(refinement(2_054), Ok(Refinement { word: 0, amount: 2_054 }));
        assert_eq!(refinement(-10_006_992), Ok(Refinement { word: 1, amount: -6_992 }));
        assert_eq!(refinement(20_000_001), Err(InvalidRefinement { selector: 2 }));
    }
}
