//! The modal state of a Haas lathe program: the code in force of every
//! modal group of the catalogue, which the interpreter and the checker's
//! walk both follow.

use ncc_catalog::{Catalogue, split_code};

/// The code in force of every modal group of the catalogue.
#[derive(Debug, Clone)]
pub struct Modes {
    catalogue: &'static Catalogue,
    /// By group index: the code's number.
    in_force: Vec<Option<u32>>,
}

impl Modes {
    pub fn at_reset(catalogue: &'static Catalogue) -> Modes {
        let default = |id: Option<&str>| id.and_then(split_code).map(|(_, number)| number);
        Modes { catalogue, in_force: catalogue.groups.iter().map(|group| default(group.default.as_deref())).collect() }
    }

    /// Puts a code in force if it is modal in a group, and sets the codes
    /// it cancels back to their groups' defaults (G00/G01 end a drilling
    /// cycle, lathe manual §5.7 (001:1075-1076)).
    pub fn set(&mut self, letter: char, number: u32) {
        if let Some(group) = self.catalogue.modal_group_index(letter, number) {
            self.in_force[group] = Some(number);
        }
        let cancels = self.catalogue.code(letter, number).map_or(&[][..], |code| &code.cancels[..]);
        for (letter, cancelled) in cancels.iter().filter_map(|code| split_code(code)) {
            let Some(group) = self.catalogue.modal_group_index(letter, cancelled) else { continue };
            if self.in_force[group] == Some(cancelled) {
                let default = self.catalogue.groups[group].default.as_deref().and_then(split_code);
                self.in_force[group] = default.map(|(_, number)| number);
            }
        }
    }

    /// The code in force in the group with id `group` (`"G1"`).
    pub fn get(&self, group: &str) -> Option<u32> {
        let index = self.catalogue.groups.iter().position(|g| g.id == group)?;
        self.in_force[index]
    }
}
