//! The modal state of a Haas lathe program: the code in force of every
//! modal group of the catalogue, which the interpreter and the checker's
//! walk both follow. The interpreter knows every code; the walk may not
//! ([`Known`]).

use ncc_catalog::{Catalogue, split_code};

use crate::known::Known;

/// The code in force of every modal group of the catalogue.
#[derive(Debug, Clone)]
pub struct Modes {
    catalogue: &'static Catalogue,
    /// By group index: the code's number, `None` for no code of the group.
    in_force: Vec<Known<Option<u32>>>,
}

impl Modes {
    pub fn at_reset(catalogue: &'static Catalogue) -> Modes {
        let in_force = catalogue.groups.iter().map(|group| Known::Is(default(group.default.as_deref()))).collect();
        Modes { catalogue, in_force }
    }

    /// Every group unknown: where a static reading cannot follow the
    /// program.
    pub fn unknown(catalogue: &'static Catalogue) -> Modes {
        Modes { catalogue, in_force: vec![Known::Unknown; catalogue.groups.len()] }
    }

    /// Puts a code in force if it is modal in a group, and sets the codes
    /// it cancels back to their groups' defaults (G00/G01 end a drilling
    /// cycle, lathe manual §5.7 (001:1075-1076)).
    pub fn set(&mut self, letter: char, number: u32) {
        if let Some(group) = self.catalogue.modal_group_index(letter, number) {
            self.in_force[group] = Known::Is(Some(number));
        }
        let cancels = self.catalogue.code(letter, number).map_or(&[][..], |code| &code.cancels[..]);
        for (letter, cancelled) in cancels.iter().filter_map(|code| split_code(code)) {
            let Some(group) = self.catalogue.modal_group_index(letter, cancelled) else { continue };
            let reset = match self.in_force[group] {
                Known::Is(code) => code == Some(cancelled),
                // Unknown before, known after when every other code of the
                // group is cancelled.
                Known::Unknown => self.cancels_group(cancels, group),
            };
            if reset {
                self.in_force[group] = Known::Is(default(self.catalogue.groups[group].default.as_deref()));
            }
        }
    }

    fn cancels_group(&self, cancels: &[String], group: usize) -> bool {
        let group = &self.catalogue.groups[group];
        let mut others = self.catalogue.codes_in(&group.id).filter(|code| Some(&code.code) != group.default.as_ref());
        others.all(|code| cancels.contains(&code.code))
    }

    /// The code in force in the group with id `group` (`"G1"`), when known.
    pub fn get(&self, group: &str) -> Option<u32> {
        self.known(group).known().flatten()
    }

    /// The code in force in the group with id `group`, `None` for no code.
    pub fn known(&self, group: &str) -> Known<Option<u32>> {
        let index = self.catalogue.groups.iter().position(|g| g.id == group);
        index.map_or(Known::Unknown, |index| self.in_force[index])
    }

    /// What holds whichever of two ways the program took: the codes both
    /// have, unknown where they differ.
    pub fn join(&self, other: &Modes) -> Modes {
        let in_force =
            self.in_force.iter().zip(&other.in_force).map(|(a, b)| if a == b { *a } else { Known::Unknown }).collect();
        Modes { catalogue: self.catalogue, in_force }
    }
}

impl PartialEq for Modes {
    /// The same codes in force of the same catalogue's groups.
    fn eq(&self, other: &Modes) -> bool {
        std::ptr::eq(self.catalogue, other.catalogue) && self.in_force == other.in_force
    }
}

/// A group's default code as its number.
fn default(id: Option<&str>) -> Option<u32> {
    id.and_then(split_code).map(|(_, number)| number)
}

#[cfg(test)]
mod tests {
    use ncc_catalog::Dialect;

    use super::*;

    #[test]
    fn codes_replace_their_group_and_cancel_others() {
        let mut modes = Modes::at_reset(Dialect::HaasLathe.catalogue());
        assert_eq!((modes.get("G1"), modes.get("G9"), modes.get("G11")), (Some(1), Some(80), None));
        modes.set('G', 83);
        modes.set('G', 0);
        assert_eq!((modes.get("G1"), modes.get("G9")), (Some(0), Some(80)));
    }

    #[test]
    fn unknown_groups_become_known_when_set_or_wholly_cancelled() {
        let catalogue = Dialect::HaasLathe.catalogue();
        let mut modes = Modes::unknown(catalogue);
        assert_eq!(modes.known("G7"), Known::Unknown);
        modes.set('G', 42);
        modes.set('G', 1);
        assert_eq!(modes.known("G7"), Known::Is(Some(42)));
        // G01 cancels every drilling cycle: G80 is in force whatever was.
        assert_eq!(modes.known("G9"), Known::Is(Some(80)));
        let joined = modes.join(&Modes::at_reset(catalogue));
        assert_eq!((joined.known("G9"), joined.known("G7")), (Known::Is(Some(80)), Known::Unknown));
    }
}
