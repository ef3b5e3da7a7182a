//! The modal machine: the code in force in every G and M group, as the
//! catalogue defines the groups, their codes and their reset codes. One
//! type for the executor, which knows every code, and the checker's flow
//! walk, which may not ([`Known`]).

use std::sync::OnceLock;

use ncc_catalog::{Dialect, Modality};

use crate::known::Known;

/// The G groups `G0`…`G11` and the M groups `M1`…`M14` (chapter 2's
/// address dictionary).
const G_GROUPS: usize = 12;
const M_GROUPS: usize = 14;
const GROUPS: usize = G_GROUPS + M_GROUPS;

/// A group, by the number the manual gives it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Group(u8);

impl Group {
    pub const MOTION: Group = Group::g(0);
    pub const PLANE: Group = Group::g(1);
    pub const JOINING: Group = Group::g(2);
    pub const COMPENSATION: Group = Group::g(3);
    pub const ZERO_OFFSET: Group = Group::g(5);
    pub const FEED_UNITS: Group = Group::g(6);
    pub const CYCLE: Group = Group::g(8);
    pub const DIMENSIONS: Group = Group::g(9);
    pub const X_PROGRAMMING: Group = Group::g(10);
    pub const TRANSFORMATION: Group = Group::g(11);
    pub const SPINDLE: Group = Group::m(2);
    pub const FEED_REDUCTION: Group = Group::m(4);

    /// G group `number`.
    ///
    /// # Panics
    /// Beyond `G11`: the numbers are fixed by the code that asks.
    pub const fn g(number: usize) -> Group {
        assert!(number < G_GROUPS, "no such G group");
        Group(number as u8)
    }

    /// M group `number`.
    ///
    /// # Panics
    /// Outside `M1`…`M14`.
    pub const fn m(number: usize) -> Group {
        assert!(number >= 1 && number <= M_GROUPS, "no such M group");
        Group((G_GROUPS + number - 1) as u8)
    }

    /// The group with the catalogue's id (`G3`, `M14`).
    pub fn of_id(id: &str) -> Option<Group> {
        let (letter, number) = ncc_catalog::split_code(id)?;
        Group::numbered(letter, usize::try_from(number).ok()?)
    }

    /// G or M group `number`, if there is one.
    pub fn numbered(letter: char, number: usize) -> Option<Group> {
        match letter {
            'G' if number < G_GROUPS => Some(Group::g(number)),
            'M' if (1..=M_GROUPS).contains(&number) => Some(Group::m(number)),
            _ => None,
        }
    }

    /// The group a modal code puts itself in force in; `None` for
    /// block-only codes and codes outside the groups.
    pub fn modal_of(letter: u8, number: u32) -> Option<Group> {
        match layout().codes(letter, number) {
            Some(code) => code.modal,
            None => {
                let index = Dialect::Cnc8x6.catalogue().modal_group_index(char::from(letter), number)?;
                layout().by_catalogue_index[index]
            }
        }
    }

    /// The group of a code, modal or block-only.
    pub fn of(letter: u8, number: u32) -> Option<Group> {
        match layout().codes(letter, number) {
            Some(code) => code.group,
            None => Group::of_id(&Dialect::Cnc8x6.catalogue().group_of(char::from(letter), number)?.id),
        }
    }
}

/// What a group may hold: the code in force, known or not.
pub trait Mode: Copy + PartialEq {
    /// `code` in force (`None`: no code of the group).
    fn code(code: Option<u32>) -> Self;
    /// A group of modal codes without a reset code (G74/G75), at the start
    /// of the program: the manual gives no default.
    const NO_RESET_CODE: Self;
}

/// The executor knows every code.
impl Mode for Option<u32> {
    fn code(code: Option<u32>) -> Self {
        code
    }
    const NO_RESET_CODE: Self = None;
}

/// The checker may not.
impl Mode for Known<Option<u32>> {
    fn code(code: Option<u32>) -> Self {
        Known::Is(code)
    }
    const NO_RESET_CODE: Self = Known::Unknown;
}

/// The code in force in every group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Modes<V = Option<u32>> {
    active: [V; GROUPS],
}

impl<V: Mode> Modes<V> {
    /// The state after reset and at program start: every group's reset
    /// code (the priority block, 01 README decision 2).
    pub fn reset() -> Modes<V> {
        Modes {
            active: layout().reset.map(|reset| match reset {
                Reset::Code(code) => V::code(code),
                Reset::None => V::NO_RESET_CODE,
            }),
        }
    }

    /// Every group holding `value`.
    pub fn all(value: V) -> Modes<V> {
        Modes { active: [value; GROUPS] }
    }

    /// The code in force in `group`.
    pub fn get(&self, group: Group) -> V {
        self.active[usize::from(group.0)]
    }

    /// What the G groups hold, from `G0` to `G11`.
    pub fn g_groups(&self) -> impl Iterator<Item = V> + '_ {
        self.active[..G_GROUPS].iter().copied()
    }

    /// Puts a modal code in force in its group; block-only codes and codes
    /// outside the groups change nothing.
    pub fn set(&mut self, letter: u8, number: u32) {
        if let Some(group) = Group::modal_of(letter, number) {
            self.active[usize::from(group.0)] = V::code(Some(number));
        }
    }
}

/// What reset puts in a group.
#[derive(Clone, Copy)]
enum Reset {
    Code(Option<u32>),
    None,
}

/// The catalogue's groups, read once.
struct Layout {
    by_catalogue_index: Vec<Option<Group>>,
    reset: [Reset; GROUPS],
    /// The groups of G00…G99 and M00…M99: a run asks for every code.
    g_codes: [CodeGroups; DENSE_CODES],
    m_codes: [CodeGroups; DENSE_CODES],
}

const DENSE_CODES: usize = 100;

#[derive(Clone, Copy, Default)]
struct CodeGroups {
    group: Option<Group>,
    modal: Option<Group>,
}

impl Layout {
    fn codes(&self, letter: u8, number: u32) -> Option<CodeGroups> {
        let table = match letter.to_ascii_uppercase() {
            b'G' => &self.g_codes,
            b'M' => &self.m_codes,
            _ => return None,
        };
        table.get(usize::try_from(number).ok()?).copied()
    }
}

fn layout() -> &'static Layout {
    static LAYOUT: OnceLock<Layout> = OnceLock::new();
    LAYOUT.get_or_init(|| {
        let catalogue = Dialect::Cnc8x6.catalogue();
        let by_catalogue_index: Vec<Option<Group>> =
            catalogue.groups.iter().map(|group| Group::of_id(&group.id)).collect();
        let mut reset = [Reset::Code(None); GROUPS];
        for (group, slot) in catalogue.groups.iter().filter_map(|group| Some((group, Group::of_id(&group.id)?))) {
            let default = group.default.as_deref().and_then(ncc_catalog::split_code).map(|(_, number)| number);
            let holds_modal_codes = catalogue.codes_in(&group.id).any(|code| code.modality == Modality::Modal);
            reset[usize::from(slot.0)] = match default {
                None if group.id.starts_with('G') && holds_modal_codes => Reset::None,
                default => Reset::Code(default),
            };
        }
        let codes = |letter: char| {
            std::array::from_fn(|number| {
                let number = number as u32;
                CodeGroups {
                    group: catalogue.group_of(letter, number).and_then(|group| Group::of_id(&group.id)),
                    modal: catalogue
                        .modal_group_index(letter, number)
                        .and_then(|index| by_catalogue_index.get(index).copied().flatten()),
                }
            })
        };
        let (g_codes, m_codes) = (codes('G'), codes('M'));
        Layout { by_catalogue_index, reset, g_codes, m_codes }
    })
}

#[cfg(test)]
mod tests {
    use super::{Group, Modes};
    use crate::known::Known;

    #[test]
    fn codes_replace_their_group_and_block_only_codes_hold_nothing() {
        let mut modes = Modes::<Option<u32>>::reset();
        let groups = [Group::MOTION, Group::FEED_UNITS, Group::SPINDLE];
        assert_eq!(groups.map(|group| modes.get(group)), [Some(1), Some(94), Some(5)]);
        modes.set(b'G', 0);
        modes.set(b'G', 97);
        modes.set(b'M', 3);
        modes.set(b'M', 0);
        assert_eq!(groups.map(|group| modes.get(group)), [Some(0), Some(97), Some(3)]);
        assert_eq!(modes.get(Group::m(1)), None);
    }

    #[test]
    fn every_catalogue_group_has_a_place_and_g74_g75_start_unknown_to_the_checker() {
        let catalogue = ncc_catalog::Dialect::Cnc8x6.catalogue();
        assert!(catalogue.groups.iter().all(|group| Group::of_id(&group.id).is_some()));
        assert_eq!(Group::modal_of(b'G', 41), Some(Group::COMPENSATION));
        assert_eq!(Group::modal_of(b'G', 4), None);
        assert_eq!(Group::of(b'G', 4), Some(Group::X_PROGRAMMING));
        let checker = Modes::<Known<Option<u32>>>::reset();
        assert_eq!(checker.get(Group::X_PROGRAMMING), Known::Unknown);
        assert_eq!(checker.get(Group::MOTION), Known::Is(Some(1)));
        assert_eq!(Modes::<Option<u32>>::reset().get(Group::X_PROGRAMMING), None);
    }
}
