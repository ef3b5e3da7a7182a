//! The codes in force of Sinumerik's groups: G codes and the words that
//! stand in a group like one (`BSPLINE`, `SOFT`), by the catalogue, each
//! group starting at its default; `$P_GG[n]` reads them and `G[n]=k` sets
//! them by their index in the group (004:3335-3341).

use ncc_catalog::{Catalogue, Code, Dialect, Modality};

/// The code in force of every group of the catalogue.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Modes {
    /// By group index; `None` for a group without a default.
    in_force: Vec<Option<&'static Code>>,
}

fn catalogue() -> &'static Catalogue {
    Dialect::Sinumerik.catalogue()
}

impl Modes {
    pub(super) fn at_reset() -> Modes {
        let catalogue = catalogue();
        let in_force = catalogue
            .groups
            .iter()
            .map(|group| group.default.as_deref().and_then(|d| catalogue.code_named(d)))
            .collect();
        Modes { in_force }
    }

    /// Puts `code` in force when it is modal in a group; whether it is.
    pub(super) fn set(&mut self, code: &'static Code) -> bool {
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
    pub(super) fn get(&self, group: &str) -> Option<&'static str> {
        self.code(group).map(|code| code.code.as_str())
    }

    pub(super) fn code(&self, group: &str) -> Option<&'static Code> {
        let index = catalogue().groups.iter().position(|g| g.id == group)?;
        self.in_force[index]
    }

    /// Puts the G codes in force that were in `saved` (SAVE), the M
    /// groups staying as they are.
    pub(super) fn restore_g(&mut self, saved: &Modes) {
        for (index, group) in catalogue().groups.iter().enumerate() {
            if group.id.starts_with('G') {
                self.in_force[index] = saved.in_force[index];
            }
        }
    }

    /// Whether `code` is in force in its group.
    pub(super) fn is(&self, group: &str, code: &str) -> bool {
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
