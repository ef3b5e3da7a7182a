//! The Haas lathe's catalogue against the manual's tables: every G and M code,
//! address, Setting and cycle the manual names has an entry, and the groups,
//! defaults and modality are the ones the catalogue decided on.

use std::collections::BTreeMap;

use super::haas_lathe;
use crate::*;

/// The G-function table, code by catalogue group (printed group 00 → "G0",
/// 01 → "G1", …; the split groups "G10M" and "G12S"; "" for the codes kept
/// outside the groups).
const G_CODES: &[(&str, &[&str])] = &[
    (
        "G0",
        &[
            "G04", "G05", "G09", "G10", "G28", "G29", "G31", "G53", "G60", "G65", "G70", "G71", "G72", "G73", "G74",
            "G75", "G76",
        ],
    ),
    ("G1", &["G00", "G01", "G02", "G03", "G32", "G90", "G92", "G94"]),
    ("G2", &["G18"]),
    ("G6", &["G20", "G21"]),
    ("G7", &["G40", "G41", "G42"]),
    ("G9", &["G80", "G81", "G82", "G83", "G84", "G85", "G86", "G87", "G88", "G89", "G95", "G184"]),
    ("G10", &["G98", "G99"]),
    ("G10M", &["G100", "G101"]),
    ("G11", &["G50"]),
    (
        "G12",
        &[
            "G54", "G55", "G56", "G57", "G58", "G59", "G110", "G111", "G112", "G113", "G114", "G115", "G116", "G117",
            "G118", "G119", "G120", "G121", "G122", "G123", "G124", "G125", "G126", "G127", "G128", "G129",
        ],
    ),
    ("G12S", &["G96", "G97"]),
    ("G13", &["G61", "G64"]),
    ("", &["G52", "G103", "G187"]),
];

/// The M-function table.
const M_CODES: &[&str] = &[
    "M00", "M01", "M02", "M03", "M04", "M05", "M08", "M09", "M10", "M11", "M12", "M13", "M14", "M15", "M17", "M18",
    "M19", "M21", "M22", "M23", "M24", "M30", "M31", "M32", "M33", "M36", "M37", "M41", "M42", "M43", "M44", "M51",
    "M52", "M53", "M54", "M55", "M56", "M57", "M58", "M61", "M62", "M63", "M64", "M65", "M66", "M67", "M68", "M76",
    "M77", "M78", "M79", "M82", "M85", "M86", "M88", "M89", "M95", "M96", "M97", "M98", "M99", "M121", "M122", "M123",
    "M124", "M125", "M126", "M127", "M128", "M133", "M134", "M135", "M154", "M155",
];

/// Every address letter the manual uses, and those Haas documentation adds.
const ADDRESSES: &[&str] = &[
    "O", "N", "G", "M", "X", "Z", "U", "W", "C", "Y", "H", "B", "I", "K", "J", "R", "A", "F", "E", "S", "T", "P", "Q",
    "L", "D", "#", "/",
];

/// The Settings the manual names.
const SETTINGS: &[u32] = &[22, 36, 52, 73, 86, 95, 96, 99];

/// The canned cycles.
const CYCLES: &[&str] = &[
    "G70", "G71", "G72", "G73", "G74", "G75", "G76", "G90", "G92", "G94", "G81", "G82", "G83", "G84", "G85", "G86",
    "G87", "G88", "G89", "G184", "G95",
];

/// The operators and functions of macro expressions.
const OPERATORS: &[&str] = &[
    "+", "-", "*", "/", "MOD", "SIN", "COS", "TAN", "ATAN", "ASIN", "ACOS", "SQRT", "ABS", "ROUND", "FIX", "FUP", "EQ",
    "NE", "GT", "GE", "LT", "LE", "AND", "OR", "XOR",
];

fn code(name: &str) -> &'static Code {
    let (letter, number) = split_code(name).unwrap();
    haas_lathe().code(letter, number).unwrap_or_else(|| panic!("{name} missing"))
}

fn modal_group(name: &str) -> Option<&'static str> {
    let (letter, number) = split_code(name).unwrap();
    let catalogue = haas_lathe();
    catalogue.modal_group_index(letter, number).map(|index| catalogue.groups[index].id.as_str())
}

#[test]
fn every_item_of_the_manuals_tables_has_an_entry() {
    let catalogue = haas_lathe();
    let mut counts = BTreeMap::new();
    for (group, codes) in G_CODES {
        for name in *codes {
            assert_eq!(code(name).group.as_deref().unwrap_or(""), *group, "{name}");
            *counts.entry("G codes").or_insert(0) += 1;
        }
    }
    for name in M_CODES {
        assert!(code(name).code.starts_with('M'));
        *counts.entry("M codes").or_insert(0) += 1;
    }
    assert_eq!(catalogue.codes.len(), counts["G codes"] + counts["M codes"], "codes the tables do not list");
    for letter in ADDRESSES {
        assert!(catalogue.address(letter).is_some(), "address {letter} missing");
    }
    assert_eq!(catalogue.addresses.len(), ADDRESSES.len(), "addresses the manual does not use");
    for &number in SETTINGS {
        assert!(catalogue.machine_constant(number).is_some(), "Setting {number} missing");
    }
    assert_eq!(catalogue.machine_constants.len(), SETTINGS.len());
    for name in CYCLES {
        let cycle = catalogue.cycles_for(name).next().unwrap_or_else(|| panic!("cycle {name} missing"));
        assert_eq!(cycle.flavour, Flavour::Lathe);
        assert!(!cycle.addresses.is_empty(), "cycle {name} lists no addresses");
    }
    assert_eq!(catalogue.cycles.len(), CYCLES.len());
    let symbols: Vec<_> = catalogue.operations.iter().filter_map(|op| op.symbol.as_deref()).collect();
    assert_eq!(symbols, OPERATORS);
    counts.insert("groups", catalogue.groups.len());
    counts.insert("addresses", catalogue.addresses.len());
    counts.insert("settings", catalogue.machine_constants.len());
    counts.insert("operations", catalogue.operations.len());
    counts.insert("cycles", catalogue.cycles.len());
    counts.insert("variable ranges", catalogue.parameter_ranges.len());
    println!("Haas lathe catalogue: {counts:?}");
}

#[test]
fn codes_are_documented_with_the_manuals_line_numbers() {
    for code in &haas_lathe().codes {
        let doc = code.doc();
        assert!(!doc.title.is_empty() && !doc.summary.is_empty(), "{}", code.code);
        assert!(doc.example.is_some_and(|e| e.starts_with('N')), "{}: an example block", code.code);
        assert!(doc.source.contains("(001:"), "{}: the source cites the manual's lines", code.code);
    }
}

#[test]
fn one_shot_codes_never_hold() {
    assert_eq!(code("G04").modality, Modality::Block);
    assert_eq!(code("G04").requires, ["P"]);
    for name in G_CODES[0].1 {
        assert_eq!(code(name).modality, Modality::Block, "{name}");
        assert_eq!(modal_group(name), None, "{name}");
    }
    assert_eq!(code("G71").group.as_deref(), Some("G0"));
    for name in ["M00", "M01", "M02", "M30", "M97", "M98", "M99"] {
        assert_eq!(modal_group(name), None, "{name}");
    }
    assert_eq!(code("M98").requires, ["P"]);
}

#[test]
fn options_restrictions_and_undescribed_codes_follow_the_tables() {
    let catalogue = haas_lathe();
    let marked = |field: fn(&Code) -> bool| -> Vec<&str> {
        catalogue.codes.iter().filter(|code| field(code)).map(|code| code.code.as_str()).collect()
    };
    // `#` in the tables (001:264, 99, 135, 307, 322-323, 338-341, 349).
    let mut optional = vec!["G31", "G65", "M19"];
    let relays = (51..=58).chain(61..=68).map(|n| format!("M{n}"));
    let relays: Vec<String> = relays.chain((121..=128).map(|n| format!("M{n}"))).collect();
    optional.extend(relays.iter().map(String::as_str));
    optional.extend(["M85", "M86", "M88", "M89"]);
    let mut found = marked(|code| code.optional);
    found.sort();
    optional.sort();
    assert_eq!(found, optional);
    assert_eq!(marked(|code| !code.machines.is_empty()), ["M41", "M42"]);
    assert_eq!(code("M41").machines, ["SL-30", "SL-40"]);
    assert_eq!(marked(|code| code.service), ["M43", "M44", "M82"]);
    assert_eq!(marked(|code| !code.described), ["G05", "G60", "G103", "G187"]);
    assert_eq!(marked(|code| code.live_tool), ["G95", "M133", "M134", "M135"]);
}

#[test]
fn shared_printed_groups_are_split() {
    // Printed group 12 holds the work offsets and G96/G97; printed group 10
    // the feed mode and the mirror image.
    assert_eq!(modal_group("G54"), Some("G12"));
    assert_eq!(modal_group("G96"), Some("G12S"));
    assert_eq!(modal_group("G98"), Some("G10"));
    assert_eq!(modal_group("G101"), Some("G10M"));
    // Settings that hold without replacing anything in group 00 or 10.
    for name in ["G52", "G103", "G187"] {
        assert_eq!(code(name).modality, Modality::Modal, "{name}");
        assert_eq!(modal_group(name), None, "{name}");
    }
    // Modal G32 and the turning cycles are motions of group 01.
    for name in ["G32", "G90", "G92", "G94"] {
        assert_eq!(modal_group(name), Some("G1"), "{name}");
    }
    assert_eq!(modal_group("G95"), Some("G9"));
    assert!(!code("G95").in_dictionary);
}

#[test]
fn defaults_follow_the_table_and_the_inferences() {
    let catalogue = haas_lathe();
    let default = |group: &str| catalogue.group(group).and_then(|g| g.default.as_deref());
    let printed =
        [("G1", "G01"), ("G2", "G18"), ("G6", "G21"), ("G7", "G40"), ("G9", "G80"), ("G12", "G54"), ("G13", "G64")];
    for (group, code) in printed {
        assert_eq!(default(group), Some(code), "group {group}");
        assert!(catalogue.group(group).unwrap().default_note.is_none(), "{code} carries the table's `*`");
    }
    // Not marked in the table: inferred, and the note says so.
    for (group, code) in [("G10", "G99"), ("G12S", "G97"), ("G10M", "G100"), ("M2", "M05")] {
        assert_eq!(default(group), Some(code), "group {group}");
        assert!(catalogue.group(group).unwrap().default_note.as_deref().is_some_and(|n| n.contains("inferred")));
    }
    assert_eq!(default("G11"), None);
    assert_eq!(default("G0"), None);
}

#[test]
fn g50_is_the_spindle_speed_limit() {
    let g50 = code("G50");
    assert_eq!(g50.group.as_deref(), Some("G11"));
    assert_eq!(g50.requires, ["S"]);
    assert_eq!(g50.title, "Spindle speed limit");
}

#[test]
fn the_grammar_letters_come_from_the_address_table() {
    let catalogue = haas_lathe();
    assert_eq!(catalogue.letter_with_role(AddressRole::BlockNumber), Some(b'N'));
    assert_eq!(catalogue.letter_with_role(AddressRole::Parameter), Some(b'#'));
    assert_eq!(catalogue.letter_with_role(AddressRole::ProgramNumber), Some(b'O'));
    assert_eq!(catalogue.letter_with_role(AddressRole::Feed), Some(b'F'));
    assert_eq!(catalogue.role_of(b'u'), Some(AddressRole::Axis));
    assert_eq!(catalogue.role_of(b'R'), Some(AddressRole::Interpolation));
    assert!(catalogue.is_parameter(101) && catalogue.is_parameter(5021));
    let locals = catalogue.parameter_ranges_of(24).next().unwrap();
    assert_eq!((locals.first, locals.last), (1, 33));
}

#[test]
fn cycles_read_the_settings_the_manual_names() {
    let catalogue = haas_lathe();
    let settings = |name: &str| catalogue.cycles_for(name).next().unwrap().machine_constants.clone();
    assert_eq!(settings("G71"), [73]);
    assert_eq!(settings("G76"), [86, 95, 96, 99]);
    assert_eq!(settings("G83"), [22, 52]);
    let g22 = catalogue.machine_constant(22).unwrap();
    assert_eq!((g22.unit.as_deref(), g22.default.as_deref()), (Some("mm"), Some("0.25")));
}

#[test]
fn explain_finds_the_entries() {
    let catalogue = haas_lathe();
    let headings = |query: &str| -> Vec<String> {
        catalogue.explain(query).unwrap().iter().map(|item| item.heading(catalogue)).collect()
    };
    assert_eq!(
        headings("g71"),
        ["G71 — Longitudinal roughing cycle", "G71 (lathe cycle) — Longitudinal roughing cycle"]
    );
    assert_eq!(headings("G4")[0], "G04 — Dwell");
    assert_eq!(headings("M133")[0], "M133 — Live tool forward");
    assert_eq!(headings("group:G12S")[0], "Group G12S — Spindle speed mode");
    assert!(catalogue.explain("M16").is_err(), "unknown M codes are unknown");
}

#[test]
fn hover_speaks_of_settings_and_macro_variables() {
    let catalogue = haas_lathe();
    let constant = catalogue.machine_constant(73).unwrap();
    let setting = Item::MachineConstant { number: 73, constant };
    assert!(setting.heading(catalogue).starts_with("Setting 73 — setting: "), "{}", setting.heading(catalogue));
    let text = setting.markdown(catalogue);
    assert!(text.contains("SETNG") && !text.contains("TAB0") && !text.contains("R73"), "{text}");
    let variable = Item::Parameter(100).heading(catalogue);
    assert!(variable.starts_with("#100 — macro variable"), "{variable}");
    // X takes a variable as its value (`X#101`).
    let x = Item::Address(catalogue.address("X").unwrap()).markdown(catalogue);
    assert!(x.contains("allowed (e.g. `X#1`)") && !x.contains("`XR1`"), "{x}");
}
