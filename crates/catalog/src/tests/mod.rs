//! Checks that hold for the data of every dialect, run over each data set;
//! and the facts of the Haas lathe's catalogue.

mod haas_lathe;

use std::collections::{BTreeSet, HashSet};

use crate::*;

fn haas_lathe() -> &'static Catalogue {
    Dialect::HaasLathe.catalogue()
}

/// Every data set by name.
fn data_sets() -> impl Iterator<Item = (&'static str, &'static Catalogue)> {
    Dialect::all().map(|dialect| (DialectId::from(dialect).name(), dialect.catalogue()))
}

fn assert_documented(what: &str, doc: Doc<'_>) {
    assert!(!doc.title.trim().is_empty(), "{what}: empty title");
    assert!(doc.summary.trim().len() > 10, "{what}: summary missing or too short");
    assert!(!doc.source.trim().is_empty(), "{what}: no source");
}

#[test]
fn every_entry_is_documented() {
    for (set, catalogue) in data_sets() {
        let docs = catalogue
            .groups
            .iter()
            .map(|g| (g.id.clone(), g.doc()))
            .chain(catalogue.codes.iter().map(|c| (c.code.clone(), c.doc())))
            .chain(catalogue.addresses.iter().map(|a| (a.letter.clone(), a.doc())))
            .chain(catalogue.parameter_ranges.iter().map(|r| (format!("range {}-{}", r.first, r.last), r.doc())))
            .chain(catalogue.machine_constants.iter().map(|c| (format!("constant {}", c.number), c.doc())))
            .chain(catalogue.operations.iter().map(|o| (format!("op {}", o.code), o.doc())))
            .chain(catalogue.cycles.iter().map(|c| (format!("{} {:?}", c.code, c.flavour), c.doc())));
        for (name, doc) in docs {
            assert_documented(&format!("{set} {name}"), doc);
        }
        assert_documented(&format!("{set} parameters"), catalogue.parameters.doc());
        // Every code, address, operation and cycle has an example (data/README.md).
        let examples = catalogue
            .codes
            .iter()
            .map(|c| (c.code.clone(), c.doc()))
            .chain(catalogue.addresses.iter().map(|a| (a.letter.clone(), a.doc())))
            .chain(catalogue.operations.iter().map(|o| (format!("op {}", o.code), o.doc())))
            .chain(catalogue.cycles.iter().map(|c| (format!("cycle {}", c.code), c.doc())));
        for (name, doc) in examples {
            assert!(doc.example.is_some_and(|e| !e.trim().is_empty()), "{set} {name}: no example");
        }
    }
}

#[test]
fn function_letters_say_what_their_codes_do() {
    for (set, catalogue) in data_sets() {
        for address in &catalogue.addresses {
            let is_function = address.role == AddressRole::Function;
            assert_eq!(address.function.is_some(), is_function, "{set} {}: `function` goes with role", address.letter);
        }
        assert_eq!(catalogue.preparatory_letter(), Some(b'G'), "{set}");
    }
}

#[test]
fn groups_are_consistent() {
    for (set, catalogue) in data_sets() {
        let mut seen = HashSet::new();
        for code in &catalogue.codes {
            let name = &code.code;
            assert!(seen.insert(name.as_str()), "{set}: {name} is listed twice (so in two groups)");
            assert!(split_code(name).is_some_and(|(l, _)| l == 'G' || l == 'M'), "{set}: {name} is no G/M code");
            // Two digits at least (`G01`), and no leading zero beyond them.
            let digits = &name[1..];
            assert!(digits.len() == 2 || (digits.len() > 2 && !digits.starts_with('0')), "{set}: {name} is misspelt");
            if let Some(group) = &code.group {
                let group = catalogue.group(group).unwrap_or_else(|| panic!("{set} {name}: unknown group {group}"));
                assert_eq!(group.id.as_bytes()[0], name.as_bytes()[0], "{set}: {name} in group {}", group.id);
            }
        }
        let mut ids = HashSet::new();
        for group in &catalogue.groups {
            let id = &group.id;
            assert!(ids.insert(id.as_str()), "{set}: group {id} twice");
            let members: Vec<_> = catalogue.codes_in(id).collect();
            let resets: Vec<_> = members.iter().filter(|c| c.reset_default).map(|c| c.code.as_str()).collect();
            match &group.default {
                Some(default) => {
                    assert_eq!(resets, [default.as_str()], "{set} group {id}: the default is its one reset code");
                }
                None => {
                    assert!(resets.is_empty(), "{set} group {id}: reset codes {resets:?} but no default");
                    assert!(group.default_note.is_some(), "{set} group {id} has neither a default nor a note why");
                }
            }
            if group.open {
                assert!(members.is_empty(), "{set}: open group {id} lists codes");
            } else {
                assert!(!members.is_empty(), "{set}: group {id} has no codes");
            }
        }
    }
}

#[test]
fn modal_codes_put_themselves_in_force_in_their_group() {
    for (set, catalogue) in data_sets() {
        let index_of = |id: &str| catalogue.groups.iter().position(|group| group.id == id);
        for code in &catalogue.codes {
            let (letter, number) = split_code(&code.code).expect("checked above");
            let expected = match code.modality {
                Modality::Modal => code.group.as_deref().and_then(index_of),
                Modality::Block => None,
            };
            assert_eq!(catalogue.modal_group_index(letter, number), expected, "{set} {}", code.code);
        }
    }
}

#[test]
fn references_between_entries_resolve() {
    for (set, catalogue) in data_sets() {
        let known: BTreeSet<String> = catalogue.addresses.iter().map(|a| a.letter.to_ascii_uppercase()).collect();
        let parameter_letter = catalogue.letter_with_role(AddressRole::Parameter).map(char::from);
        let is_parameter = |name: &str| {
            let mut chars = name.chars();
            chars.next() == parameter_letter
                && chars.as_str().parse().is_ok_and(|number: u32| catalogue.is_parameter(number))
        };
        for code in &catalogue.codes {
            for name in code.requires.iter().chain(&code.allows) {
                assert!(known.contains(name) || is_parameter(name), "{set} {}: `{name}` is no address", code.code);
            }
            for name in &code.cancels {
                let (letter, number) =
                    split_code(name).unwrap_or_else(|| panic!("{set} {}: cancels `{name}`", code.code));
                assert!(catalogue.code(letter, number).is_some(), "{set} {}: cancels unknown {name}", code.code);
            }
        }
        for group in &catalogue.groups {
            if let Some(default) = &group.default {
                let (letter, number) = split_code(default).unwrap_or_else(|| panic!("{set} {}: default", group.id));
                assert!(catalogue.code(letter, number).is_some(), "{set} group {}: unknown default", group.id);
            }
        }
        for cycle in &catalogue.cycles {
            let (letter, number) = split_code(&cycle.code).unwrap_or_else(|| panic!("{set} cycle {}", cycle.code));
            assert!(catalogue.code(letter, number).is_some(), "{set}: cycle {} is no code", cycle.code);
            for parameter in &cycle.parameters {
                assert!(catalogue.is_parameter(parameter.r), "{set} {}: R{}", cycle.code, parameter.r);
            }
            for address in &cycle.addresses {
                assert!(known.contains(&address.letter), "{set} {}: address {}", cycle.code, address.letter);
            }
            for &number in &cycle.machine_constants {
                assert!(catalogue.machine_constant(number).is_some(), "{set} {}: constant {number}", cycle.code);
            }
        }
        for range in &catalogue.parameter_ranges {
            let (first, last) = (range.first, range.last);
            assert!(first <= last && catalogue.is_parameter(last), "{set}: range {first}-{last}");
        }
        let mut numbers = HashSet::new();
        for constant in &catalogue.machine_constants {
            for number in constant.number..=constant.last.unwrap_or(constant.number) {
                assert!(numbers.insert(number), "{set}: machine constant {number} described twice");
            }
        }
        let codes: Vec<u32> = catalogue.operations.iter().map(|op| op.code).collect();
        assert!(codes.windows(2).all(|pair| pair[0] < pair[1]), "{set}: operations in ascending order");
        let mut symbols = HashSet::new();
        for symbol in catalogue.operations.iter().filter_map(|op| op.symbol.as_deref()) {
            assert!(symbols.insert(symbol), "{set}: operator {symbol} described twice");
        }
    }
}
