//! The catalogue against the manual's tables, its internal consistency, and
//! the text `ncc explain` and hover show.

use std::collections::{BTreeMap, BTreeSet, HashSet};

use ncc_catalog::{AddressRole, Catalogue, Dialect, Doc, Documented, Flavour, Item, Modality, split_code};
use serde::Deserialize;

/// The manual's tables as transcribed in `spec_index.toml`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecIndex {
    groups: BTreeMap<String, Vec<String>>,
    outside_groups: Vec<String>,
    addresses: Vec<String>,
    parameters: u32,
    operations: u32,
    undefined_operations: Vec<u32>,
    milling_cycles: Vec<String>,
    lathe_cycles: Vec<String>,
    machine_constants: Vec<u32>,
}

fn spec_index() -> SpecIndex {
    toml::from_str(include_str!("spec_index.toml")).unwrap()
}

fn catalogue() -> &'static Catalogue {
    Dialect::Cnc8x6.catalogue()
}

fn assert_documented(what: &str, doc: Doc<'_>) {
    assert!(!doc.title.trim().is_empty(), "{what}: empty title");
    assert!(doc.summary.trim().len() > 10, "{what}: summary missing or too short");
    assert!(!doc.source.trim().is_empty(), "{what}: no source");
}

#[test]
fn every_item_of_the_manuals_tables_has_an_entry() {
    let spec = spec_index();
    let catalogue = catalogue();
    let mut counts = BTreeMap::new();

    for (id, codes) in &spec.groups {
        let group = catalogue.group(id).unwrap_or_else(|| panic!("group {id} missing"));
        assert_documented(id, group.doc());
        for name in codes {
            let (letter, number) = split_code(name).unwrap();
            let code = catalogue.code(letter, number).unwrap_or_else(|| panic!("{name} missing"));
            assert_eq!(code.group.as_deref(), Some(id.as_str()), "{name} is in group {id}");
            assert!(code.in_dictionary, "{name} is in the dictionary");
            assert_documented(name, code.doc());
            assert!(code.example.is_some(), "{name}: no example");
            *counts.entry(if letter == 'G' { "G codes" } else { "M codes" }).or_insert(0) += 1;
        }
        *counts.entry("groups").or_insert(0) += 1;
    }
    for name in &spec.outside_groups {
        let (letter, number) = split_code(name).unwrap();
        let code = catalogue.code(letter, number).unwrap_or_else(|| panic!("{name} missing"));
        assert!(!code.in_dictionary, "{name} is marked as absent from the dictionary");
        assert_documented(name, code.doc());
        *counts.entry("G codes").or_insert(0) += 1;
    }
    for letter in &spec.addresses {
        let address = catalogue.address(letter).unwrap_or_else(|| panic!("address {letter} missing"));
        assert_documented(letter, address.doc());
        assert!(address.example.is_some(), "address {letter}: no example");
        *counts.entry("addresses").or_insert(0) += 1;
    }
    assert_eq!(catalogue.parameters.count, spec.parameters);
    assert_documented("parameters", catalogue.parameters.doc());
    for number in 0..spec.parameters {
        let items = catalogue.explain(&format!("param:{number}")).unwrap();
        assert_eq!(items, [Item::Parameter(number)]);
        *counts.entry("parameters").or_insert(0) += 1;
    }
    for number in &spec.machine_constants {
        let constant =
            catalogue.machine_constant(*number).unwrap_or_else(|| panic!("machine constant {number} missing"));
        assert_documented(&format!("machine constant {number}"), constant.doc());
        *counts.entry("machine constants").or_insert(0) += 1;
    }
    for code in 0..spec.operations {
        let op = catalogue.operation(code).unwrap_or_else(|| panic!("operation {code} missing"));
        assert_eq!(op.defined, !spec.undefined_operations.contains(&code), "operation {code}");
        assert_documented(&format!("operation {code}"), op.doc());
        *counts.entry("operations").or_insert(0) += 1;
    }
    for (flavour, codes) in [(Flavour::Milling, &spec.milling_cycles), (Flavour::Lathe, &spec.lathe_cycles)] {
        for code in codes {
            let cycle = catalogue
                .cycles_for(code)
                .find(|c| c.flavour == flavour)
                .unwrap_or_else(|| panic!("{flavour:?} cycle {code} missing"));
            assert_documented(code, cycle.doc());
            *counts.entry("fixed cycles").or_insert(0) += 1;
            *counts.entry("cycle parameters").or_insert(0) += cycle.parameters.len();
        }
    }
    println!("catalogue entries checked against the manual's tables: {counts:?}");
}

#[test]
fn every_entry_is_documented() {
    let catalogue = catalogue();
    let docs = catalogue
        .groups
        .iter()
        .map(|g| (g.id.clone(), g.doc()))
        .chain(catalogue.codes.iter().map(|c| (c.code.clone(), c.doc())))
        .chain(catalogue.addresses.iter().map(|a| (a.letter.clone(), a.doc())))
        .chain(catalogue.parameter_ranges.iter().map(|r| (format!("R{}-R{}", r.first, r.last), r.doc())))
        .chain(catalogue.machine_constants.iter().map(|c| (format!("MC{}", c.number), c.doc())))
        .chain(catalogue.operations.iter().map(|o| (format!("op {}", o.code), o.doc())))
        .chain(catalogue.cycles.iter().map(|c| (format!("{} {:?}", c.code, c.flavour), c.doc())));
    for (name, doc) in docs {
        assert_documented(&name, doc);
    }
}

#[test]
fn function_letters_say_what_their_codes_do() {
    let catalogue = catalogue();
    for address in &catalogue.addresses {
        let is_function = address.role == AddressRole::Function;
        assert_eq!(address.function.is_some(), is_function, "{}: `function` goes with role function", address.letter);
    }
    assert_eq!(catalogue.preparatory_letter(), Some(b'G'));
}

#[test]
fn groups_are_consistent() {
    let catalogue = catalogue();
    let mut seen = HashSet::new();
    for code in &catalogue.codes {
        assert!(seen.insert(code.code.as_str()), "{} is listed twice (so in two groups)", code.code);
        assert!(split_code(&code.code).is_some_and(|(l, _)| l == 'G' || l == 'M'), "{} is no G/M code", code.code);
        assert_eq!(code.code.len(), 3, "{} is not written with two digits", code.code);
        if let Some(group) = &code.group {
            let group = catalogue.group(group).unwrap_or_else(|| panic!("{}: unknown group {group}", code.code));
            assert_eq!(group.id.as_bytes()[0], code.code.as_bytes()[0], "{} in group {}", code.code, group.id);
        }
    }
    let mut ids = HashSet::new();
    for group in &catalogue.groups {
        assert!(ids.insert(group.id.as_str()), "group {} twice", group.id);
        let members: Vec<_> = catalogue.codes_in(&group.id).collect();
        let resets: Vec<_> = members.iter().filter(|c| c.reset_default).map(|c| c.code.as_str()).collect();
        match &group.default {
            Some(default) => {
                assert_eq!(resets, [default.as_str()], "group {}: the default is its one reset code", group.id);
            }
            None => {
                assert!(resets.is_empty(), "group {}: reset codes {resets:?} but no default", group.id);
                assert!(group.default_note.is_some(), "group {} has neither a default nor a note why", group.id);
            }
        }
        if group.open {
            assert!(members.is_empty(), "open group {} lists codes", group.id);
        } else {
            assert!(!members.is_empty(), "group {} has no codes", group.id);
        }
        if members.iter().any(|c| c.modality == Modality::Modal) && group.default.is_none() {
            assert!(group.default_note.is_some(), "group {}: modal codes without a default need a note", group.id);
        }
    }
}

#[test]
fn modal_codes_put_themselves_in_force_in_their_group() {
    let catalogue = catalogue();
    let index_of = |id: &str| catalogue.groups.iter().position(|group| group.id == id);
    for code in &catalogue.codes {
        let (letter, number) = split_code(&code.code).expect("checked above");
        let expected = match code.modality {
            Modality::Modal => code.group.as_deref().and_then(index_of),
            Modality::Block => None,
        };
        assert_eq!(catalogue.modal_group_index(letter, number), expected, "{}", code.code);
    }
    // Unlisted M codes of the open range belong to the open group (M14),
    // above the dense table too; G codes outside the groups to none.
    let open = catalogue.groups.iter().rposition(|group| group.open && group.id.starts_with('M'));
    assert_eq!(catalogue.modal_group_index('M', 77), open);
    assert_eq!(catalogue.modal_group_index('m', 77), open);
    assert_eq!(catalogue.modal_group_index('G', 99), None);
    assert_eq!(catalogue.modal_group_index('G', 1000), None);
}

#[test]
fn references_between_entries_resolve() {
    let catalogue = catalogue();
    let known_addresses: BTreeSet<String> = catalogue.addresses.iter().map(|a| a.letter.to_ascii_uppercase()).collect();
    let is_word = |name: &str| {
        known_addresses.contains(name)
            || split_code(name).is_some_and(|(letter, number)| letter == 'R' && catalogue.is_parameter(number))
    };
    for code in &catalogue.codes {
        for name in code.requires.iter().chain(&code.allows) {
            assert!(is_word(name), "{}: `{name}` is neither an address nor a parameter", code.code);
        }
        for name in &code.cancels {
            let (letter, number) = split_code(name).unwrap_or_else(|| panic!("{}: cancels `{name}`", code.code));
            assert!(catalogue.code(letter, number).is_some(), "{}: cancels unknown {name}", code.code);
        }
    }
    for cycle in &catalogue.cycles {
        assert!(catalogue.code('G', split_code(&cycle.code).unwrap().1).is_some(), "cycle {}", cycle.code);
        for parameter in &cycle.parameters {
            assert!(catalogue.is_parameter(parameter.r), "{}: R{}", cycle.code, parameter.r);
        }
    }
    for range in &catalogue.parameter_ranges {
        assert!(range.first <= range.last && catalogue.is_parameter(range.last), "R{}-R{}", range.first, range.last);
    }
    let mut numbers = HashSet::new();
    for constant in &catalogue.machine_constants {
        for number in constant.number..=constant.last.unwrap_or(constant.number) {
            assert!(numbers.insert(number), "machine constant {number} described twice");
        }
    }
    let codes: Vec<u32> = catalogue.operations.iter().map(|op| op.code).collect();
    assert_eq!(codes, (0..52).collect::<Vec<_>>(), "operations in order 0-51");
}

#[test]
fn the_parsers_grammar_letters_come_from_the_address_table() {
    use ncc_catalog::AddressRole;
    let catalogue = catalogue();
    assert_eq!(catalogue.letter_with_role(AddressRole::BlockNumber), Some(b'N'));
    assert_eq!(catalogue.letter_with_role(AddressRole::Parameter), Some(b'R'));
    assert_eq!(catalogue.role_of(b'x'), Some(AddressRole::Axis));
}

fn explain(query: &str) -> String {
    let catalogue = catalogue();
    match catalogue.explain(query) {
        Ok(items) => items.iter().map(|item| item.markdown(catalogue)).collect::<Vec<_>>().join("\n"),
        Err(not_found) => format!("not found: {not_found:?}\n"),
    }
}

#[test]
fn explain_names_what_the_programmer_typed() {
    let headings = |query: &str| -> Vec<String> {
        let catalogue = catalogue();
        catalogue.explain(query).unwrap().iter().map(|item| item.heading(catalogue)).collect()
    };
    assert!(headings("g40")[0].starts_with("G40 — "));
    assert!(headings("G4")[0].starts_with("G04 — "));
    let r39 = headings("R39");
    assert!(r39[0].starts_with("R39 — machine constant"), "{r39:?}");
    assert!(r39[1].starts_with("R39 — program parameter"), "{r39:?}");
    let r5 = headings("R5");
    assert!(r5[0].starts_with("R5 — program parameter"), "{r5:?}");
    assert!(r5[1].starts_with("R5 — machine constant"), "{r5:?}");
    assert!(headings("op:48")[0].starts_with("Operation 48 — "));
    assert!(headings("mc:39")[0].starts_with("R39 — machine constant"));
    assert!(headings("M55")[0].contains("machine-defined"));
    let g81 = headings("G81");
    assert_eq!(g81.len(), 3, "the code and both cycle flavours: {g81:?}");
    assert!(headings("X")[0].starts_with("X — "));
    assert!(headings("&")[0].starts_with("& — "));

    let not_found = catalogue().explain("G99").unwrap_err();
    assert!(!not_found.suggestions.is_empty(), "{not_found:?}");
    assert!(catalogue().explain("hello").is_err());
}

#[test]
fn explain_snapshots() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/explain");
    for (query, file) in [
        ("G40", "G40.md"),
        ("M30", "M30.md"),
        ("R39", "R39.md"),
        ("R5", "R5.md"),
        ("op:48", "op48.md"),
        ("X", "X.md"),
        ("G83", "G83.md"),
        ("group:G3", "group_G3.md"),
    ] {
        expect_test::expect_file![dir.join(file)].assert_eq(&explain(query));
    }
}
