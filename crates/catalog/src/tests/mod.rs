//! Checks that hold for the data of every dialect, run over each data set;
//! and the facts of the Haas lathe's and Sinumerik's catalogues.

mod haas_lathe;
mod sinumerik;

use std::collections::{BTreeSet, HashSet};

use crate::*;

fn haas_lathe() -> &'static Catalogue {
    Dialect::HaasLathe.catalogue()
}

fn sinumerik() -> &'static Catalogue {
    Dialect::Sinumerik.catalogue()
}

/// Every data set by name.
fn data_sets() -> impl Iterator<Item = (&'static str, &'static Catalogue)> {
    Dialect::ALL.into_iter().map(|dialect| (dialect.name(), dialect.catalogue()))
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
            .chain(catalogue.cycles.iter().map(|c| (format!("{} {:?}", c.code, c.flavour), c.doc())))
            .chain(catalogue.keywords.iter().map(|k| (format!("keyword {}", k.word), k.doc())))
            .chain(catalogue.functions.iter().map(|f| (format!("function {}", f.name), f.doc())))
            .chain(catalogue.system_variables.iter().map(|v| (v.name.clone(), v.doc())))
            .chain(catalogue.variable_prefixes.iter().map(|p| (format!("prefix {}", p.prefix), p.doc())));
        for (name, doc) in docs {
            assert_documented(&format!("{set} {name}"), doc);
        }
        assert_documented(&format!("{set} parameters"), catalogue.parameters.doc());
        // Every code, address, operation, cycle, keyword, function and
        // system variable has an example (data/README.md).
        let examples = catalogue
            .codes
            .iter()
            .map(|c| (c.code.clone(), c.doc()))
            .chain(catalogue.addresses.iter().map(|a| (a.letter.clone(), a.doc())))
            .chain(catalogue.operations.iter().map(|o| (format!("op {}", o.code), o.doc())))
            .chain(catalogue.cycles.iter().map(|c| (format!("cycle {}", c.code), c.doc())))
            .chain(catalogue.keywords.iter().map(|k| (format!("keyword {}", k.word), k.doc())))
            .chain(catalogue.functions.iter().map(|f| (format!("function {}", f.name), f.doc())))
            .chain(catalogue.system_variables.iter().map(|v| (v.name.clone(), v.doc())));
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

/// A word of the language: upper-case letters, digits and `_`, starting
/// with a letter or `_` (`BSPLINE`, `CUT3DC`, `_FINISH`).
fn is_word(name: &str) -> bool {
    name.starts_with(|c: char| c.is_ascii_uppercase() || c == '_')
        && name.bytes().all(|b| b.is_ascii_uppercase() || b.is_ascii_digit() || b == b'_')
}

#[test]
fn groups_are_consistent() {
    for (set, catalogue) in data_sets() {
        let mut seen = HashSet::new();
        // Whether the codes below 10 are written with two digits (`G01`) or
        // one (Sinumerik's `G1`): one spelling per data set.
        let mut padding = HashSet::new();
        for code in &catalogue.codes {
            let name = &code.code;
            assert!(seen.insert(name.as_str()), "{set}: {name} is listed twice (so in two groups)");
            match split_code(name) {
                Some((letter, number)) => {
                    assert!(letter == 'G' || letter == 'M', "{set}: {name} is no G/M code");
                    let padded = format!("{letter}{number:02}");
                    assert!(*name == padded || *name == format!("{letter}{number}"), "{set}: {name} is misspelt");
                    if number < 10 {
                        padding.insert(*name == padded);
                    }
                }
                None => {
                    assert!(is_word(name), "{set}: {name} is neither a code nor a word");
                    assert!(code.group.as_deref().is_some_and(|g| g.starts_with('G')), "{set}: {name} in no G group");
                }
            }
            if let Some(group) = &code.group {
                let group = catalogue.group(group).unwrap_or_else(|| panic!("{set} {name}: unknown group {group}"));
                if !code.is_word() {
                    assert_eq!(group.id.as_bytes()[0], name.as_bytes()[0], "{set}: {name} in group {}", group.id);
                }
                if let Some(index) = code.index {
                    assert!(index >= 1, "{set}: {name}'s number in its group counts from 1");
                    let at = catalogue.code_at(&group.id, index).map(|c| c.code.as_str());
                    assert_eq!(at, Some(name.as_str()), "{set}: number {index} of group {} twice", group.id);
                }
            }
        }
        assert!(padding.len() <= 1, "{set}: codes below 10 written both with and without a leading zero");
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
            let expected = match code.modality {
                Modality::Modal => code.group.as_deref().and_then(index_of),
                Modality::Block => None,
            };
            let found = match split_code(&code.code) {
                Some((letter, number)) => catalogue.modal_group_index(letter, number),
                None => catalogue.word_modal_group_index(&code.code),
            };
            assert_eq!(found, expected, "{set} {}", code.code);
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
                assert!(catalogue.code_named(name).is_some(), "{set} {}: cancels unknown {name}", code.code);
            }
        }
        for group in &catalogue.groups {
            if let Some(default) = &group.default {
                assert!(catalogue.code_named(default).is_some(), "{set} group {}: unknown default", group.id);
            }
        }
        for cycle in &catalogue.cycles {
            // A cycle is a code (`G81`), or called by its name with arguments
            // (`CYCLE81(…)`).
            let called = !cycle.arguments.is_empty() && is_word(&cycle.code);
            assert!(called || catalogue.code_named(&cycle.code).is_some(), "{set}: cycle {} is no code", cycle.code);
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
        let ranked = catalogue.operations.iter().filter(|op| op.precedence.is_some()).count();
        assert!(ranked == 0 || ranked == catalogue.operations.len(), "{set}: precedence for some operators only");
    }
}

#[test]
fn language_entries_are_consistent() {
    for (set, catalogue) in data_sets() {
        // Each name means one thing: `explain` finds exactly it.
        let mut names = HashSet::new();
        let words = catalogue
            .keywords
            .iter()
            .map(|k| &k.word)
            .chain(catalogue.functions.iter().map(|f| &f.name))
            .chain(catalogue.codes.iter().filter(|c| c.is_word()).map(|c| &c.code))
            .chain(catalogue.addresses.iter().filter(|a| a.letter.len() > 1).map(|a| &a.letter));
        for word in words {
            assert!(is_word(word), "{set}: `{word}` is no upper-case word");
            assert!(names.insert(word.as_str()), "{set}: `{word}` has two entries");
            let found = catalogue.explain(word).unwrap_or_else(|e| panic!("{set}: {e:?}"));
            assert_eq!(found.len(), 1, "{set}: `{word}` explains as {found:?}");
        }
        for keyword in &catalogue.keywords {
            assert!(!keyword.syntax.is_empty(), "{set} {}: no syntax", keyword.word);
            for related in &keyword.related {
                assert!(catalogue.explain(related).is_ok(), "{set} {}: goes with unknown {related}", keyword.word);
            }
        }
        for function in &catalogue.functions {
            let mut parameters = HashSet::new();
            for parameter in &function.parameters {
                assert!(parameters.insert(&parameter.name), "{set} {}: {} twice", function.name, parameter.name);
                assert!(!parameter.ty.is_empty() && !parameter.meaning.is_empty(), "{set} {}", function.name);
            }
        }
        for cycle in catalogue.cycles.iter().filter(|c| !c.arguments.is_empty()) {
            let mut arguments = HashSet::new();
            for argument in &cycle.arguments {
                assert!(arguments.insert(&argument.name), "{set} {}: {} twice", cycle.code, argument.name);
            }
        }
        for variable in &catalogue.system_variables {
            let name = &variable.name;
            assert!(!name.contains('['), "{set} {name}: the index is no part of the name");
            let prefix = catalogue.variable_prefixes.iter().any(|p| name.starts_with(&p.prefix));
            assert!(prefix, "{set} {name}: no prefix describes it");
            assert_eq!(catalogue.system_variable(name), Some(SystemVariableInfo::Documented(variable)), "{set} {name}");
        }
        for prefix in &catalogue.variable_prefixes {
            let p = &prefix.prefix;
            assert!(p.starts_with('$') && p.ends_with('_'), "{set}: prefix {p}");
        }
        // Machine data with a name is read through a machine-data prefix.
        let machine_data = catalogue.variable_prefixes.iter().find(|p| p.machine_data);
        for constant in &catalogue.machine_constants {
            if let (Some(name), Some(prefix)) = (&constant.name, machine_data) {
                let found = catalogue.system_variable(&format!("{}{name}", prefix.prefix));
                assert!(matches!(found, Some(SystemVariableInfo::MachineData { .. })), "{set}: {name} as a variable");
            }
        }
    }
}
