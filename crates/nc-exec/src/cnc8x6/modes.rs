//! The modal machine: the active code of every G and M group, as the
//! catalogue defines the groups, their codes and their reset codes.

use ncc_catalog::{Catalogue, Dialect};

/// The active code of each group (by its index in the catalogue's groups);
/// `None` for a group without a code in force (G74/G75 before either is
/// written).
#[derive(Debug, Clone)]
pub struct Modes {
    catalogue: &'static Catalogue,
    active: Vec<Option<u32>>,
}

impl PartialEq for Modes {
    /// The same codes in force (of the same catalogue).
    fn eq(&self, other: &Modes) -> bool {
        std::ptr::eq(self.catalogue, other.catalogue) && self.active == other.active
    }
}

/// A group, resolved once by its id (`G0`, `M2`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Group(usize);

impl Modes {
    /// The state after reset and at program start: every group's reset
    /// code (the priority block, 01 README decision 2).
    pub fn reset() -> Modes {
        let catalogue = Dialect::Cnc8x6.catalogue();
        let active = catalogue.groups.iter().map(|group| default_code(group.default.as_deref())).collect();
        Modes { catalogue, active }
    }

    /// The group with id `id`.
    ///
    /// # Panics
    /// If the catalogue has no such group: the ids are fixed by the code
    /// that asks, so this is a programming error.
    pub fn group(&self, id: &str) -> Group {
        self.find(id).unwrap_or_else(|| panic!("the catalogue has no group {id}"))
    }

    /// The group with id `id`, if the catalogue has one.
    pub fn find(&self, id: &str) -> Option<Group> {
        self.catalogue.groups.iter().position(|group| group.id == id).map(Group)
    }

    /// The code in force in `group`.
    pub fn active(&self, group: Group) -> Option<u32> {
        self.active[group.0]
    }

    /// The group a modal code puts itself in force in; `None` for
    /// block-only codes and codes outside the groups.
    pub fn modal_group_of(&self, letter: u8, number: u32) -> Option<Group> {
        self.catalogue.modal_group_index(char::from(letter), number).map(Group)
    }

    /// The group of a code, modal or block-only.
    pub fn group_of(&self, letter: u8, number: u32) -> Option<Group> {
        let group = self.catalogue.group_of(char::from(letter), number)?;
        self.catalogue.groups.iter().position(|g| std::ptr::eq(g, group)).map(Group)
    }

    /// Puts a modal code in force in its group; block-only codes and codes
    /// outside the groups change nothing.
    pub fn set(&mut self, letter: u8, number: u32) {
        if let Some(index) = self.catalogue.modal_group_index(char::from(letter), number) {
            self.active[index] = Some(number);
        }
    }
}

fn default_code(default: Option<&str>) -> Option<u32> {
    default.and_then(ncc_catalog::split_code).map(|(_, number)| number)
}

#[cfg(test)]
mod tests {
    use super::Modes;

    #[test]
    fn codes_replace_their_group_and_block_only_codes_hold_nothing() {
        let mut modes = Modes::reset();
        let (motion, units, spindle, flow) =
            (modes.group("G0"), modes.group("G6"), modes.group("M2"), modes.group("M1"));
        assert_eq!([modes.active(motion), modes.active(units), modes.active(spindle)], [Some(1), Some(94), Some(5)]);
        modes.set(b'G', 0);
        modes.set(b'G', 97);
        modes.set(b'M', 3);
        modes.set(b'M', 0);
        assert_eq!([modes.active(motion), modes.active(units), modes.active(spindle)], [Some(0), Some(97), Some(3)]);
        assert_eq!(modes.active(flow), None);
    }
}
