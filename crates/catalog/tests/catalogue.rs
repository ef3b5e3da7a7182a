//! The CNC8x6 catalogue against the manual's tables, and the text
//! `ncc explain` and hover show. The consistency checks that hold for every
//! dialect's data run in the crate's unit tests (`src/tests`).

use std::collections::BTreeMap;

use ncc_catalog::{Catalogue, Dialect, Doc, Documented, Flavour, Item, split_code};
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
fn unlisted_codes_belong_to_the_open_group() {
    // Unlisted M codes of the open range belong to the open group (M14),
    // above the dense table too; G codes outside the groups to none. The
    // checks that hold for every dialect run in the crate's unit tests.
    let catalogue = catalogue();
    let open = catalogue.groups.iter().rposition(|group| group.open && group.id.starts_with('M'));
    assert_eq!(catalogue.modal_group_index('M', 77), open);
    assert_eq!(catalogue.modal_group_index('m', 77), open);
    assert_eq!(catalogue.modal_group_index('G', 99), None);
    assert_eq!(catalogue.modal_group_index('G', 1000), None);
}

#[test]
fn operations_are_numbered_0_to_51() {
    let codes: Vec<u32> = catalogue().operations.iter().map(|op| op.code).collect();
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
