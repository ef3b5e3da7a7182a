//! Sinumerik's catalogue against the digest of the thesis: every word and
//! system variable its inventory names has an entry, the G groups carry the
//! thesis's numbers, and unknown system variables are known by their prefix.

use std::collections::BTreeMap;

use super::sinumerik;
use crate::*;

/// The keyword inventory of the thesis (digest §2.10), word by word; `G` for
/// the indirect `G[n]=k`, `G64` for the "G64n" series.
const INVENTORY: &[&str] = &[
    "G0",
    "G1",
    "G2",
    "G3",
    "G00",
    "G01",
    "G02",
    "G03",
    "CR",
    "ASPLINE",
    "CSPLINE",
    "BSPLINE",
    "SD",
    "PW",
    "PL",
    "POLY",
    "SPLINEPATH",
    "COMPCAD",
    "G64",
    "G641",
    "G642",
    "G643",
    "G644",
    "G645",
    "SOFT",
    "BRISK",
    "DYNFINISH",
    "FIFOCTRL",
    "FFWON",
    "FFWOF",
    "CYCLE832",
    "CYCLE800",
    "TRAORI",
    "TRAFOOF",
    "TOROT",
    "TOROTOF",
    "ORIWKS",
    "ORIAXES",
    "ORISON",
    "UPATH",
    "OTOL",
    "A3",
    "B3",
    "C3",
    "A4",
    "B4",
    "C4",
    "A5",
    "B5",
    "C5",
    "LEAD",
    "TILT",
    "A2",
    "B2",
    "A",
    "C",
    "CUT3DF",
    "CUT3DC",
    "CUT3DCC",
    "CUT2DF",
    "KONT",
    "TCARR",
    "PAROTOF",
    "SUPA",
    "TRANS",
    "ATRANS",
    "ROT",
    "AROT",
    "SCALE",
    "ASCALE",
    "MIRROR",
    "AMIRROR",
    "G500",
    "G54",
    "G70",
    "G71",
    "G710",
    "G17",
    "G90",
    "G91",
    "G94",
    "G",
    "WORKPIECE",
    "T",
    "M6",
    "M06",
    "M0",
    "M3",
    "M5",
    "M8",
    "M9",
    "M17",
    "M30",
    "PROC",
    "SAVE",
    "VAR",
    "RET",
    "EXTERN",
    "DEF",
    "MCALL",
    "CALL",
    "REAL",
    "INT",
    "BOOL",
    "STRING",
    "CHAR",
    "AXIS",
    "TRUE",
    "FALSE",
    "IF",
    "ELSE",
    "ENDIF",
    "WHILE",
    "ENDWHILE",
    "FOR",
    "TO",
    "ENDFOR",
    "CASE",
    "OF",
    "GOTO",
    "GOTOF",
    "GOTOB",
    "NOT",
    "MSG",
    "WRITE",
    "DELETE",
    "ISFILE",
    "READ",
    "SET",
    "REP",
    "SIN",
    "COS",
    "ABS",
    "AXSTRING",
    "NUMBER",
    "ISNUMBER",
    "AXNAME",
    "TOLOWER",
    "TOUPPER",
    "STRLEN",
    "GROUP_BEGIN",
    "GROUP_END",
    "CONTPRON",
    "ID",
    "DO",
    "GETEXET",
    "GETSELT",
    "_FINISH",
];

/// The system variables of the thesis (digest §2.11), as the programs write
/// them.
const SYSTEM_VARIABLES: &[&str] = &[
    "$P_F",
    "$P_GG[6]",
    "$MN_MM_NUM_R_PARAM",
    "$P_SUBPAR[4]",
    "$AA_IM[X]",
    "$P_ISTEST",
    "$P_TOOLNO",
    "$P_TOOLP",
    "$A_DAY",
    "$A_MONTH",
    "$A_YEAR",
    "$A_HOUR",
    "$A_MINUTE",
    "$A_SECOND",
    "$P_S[$AC_MSNUM]",
    "$P_SDIR[$AC_MSNUM]",
    "$AC_MSNUM",
];

/// Words the digest names outside the inventory (operators §2.4, control
/// structures §2.5, splines, compressor and path modes §3.2–§3.4, five-axis
/// words §3.6), and the language's usual functions.
const FURTHER_WORDS: &[&str] = &[
    "+",
    "-",
    "*",
    "/",
    "DIV",
    "MOD",
    "==",
    "<>",
    ">",
    "<",
    ">=",
    "<=",
    "AND",
    "OR",
    "XOR",
    "B_NOT",
    "B_AND",
    "B_OR",
    "B_XOR",
    "<<",
    "LOOP",
    "ENDLOOP",
    "REPEAT",
    "UNTIL",
    "GOTOC",
    "DEFAULT",
    "STOPRE",
    "DISPLOF",
    "BAUTO",
    "BNAT",
    "BTAN",
    "EAUTO",
    "ENAT",
    "ETAN",
    "COMPON",
    "COMPCURV",
    "COMPOF",
    "G60",
    "G9",
    "G601",
    "G602",
    "G603",
    "DYNNORM",
    "DYNPOS",
    "DYNROUGH",
    "DYNSEMIFIN",
    "ADIS",
    "ADISPOS",
    "CTOL",
    "XH",
    "YH",
    "ZH",
    "ORICURVE",
    "ORIEULER",
    "ORIRPY",
    "WHEN",
    "WHENEVER",
    "EVERY",
    "FROM",
    "IDS",
    "TAN",
    "ASIN",
    "ACOS",
    "ATAN2",
    "SQRT",
    "POT",
    "TRUNC",
    "ROUND",
    "LN",
    "EXP",
    "MINVAL",
    "MAXVAL",
    "BOUND",
    "INDEX",
    "SUBSTR",
    "AC",
    "IC",
    "CYCLE81",
    "CYCLE82",
    "CYCLE83",
    "CYCLE84",
    "CYCLE85",
    "CYCLE86",
    "CYCLE87",
    "CYCLE88",
    "CYCLE89",
    "CYCLE840",
    "CIP",
    "CT",
    "G4",
    "G53",
    "G18",
    "G19",
    "G40",
    "G41",
    "G42",
    "G55",
    "G56",
    "G57",
    "G93",
    "G95",
    "G96",
    "G97",
    "G700",
    "M1",
    "M2",
    "M4",
    "M7",
    "X",
    "Y",
    "Z",
    "B",
    "I",
    "J",
    "K",
    "F",
    "S",
    "D",
    "N",
    "R",
    "AP",
    "RP",
    "CHF",
    "CHR",
    "RND",
    "RNDM",
    "TURN",
    "AR",
    "L",
    "P",
    "H",
];

fn kind(item: &Item<'_>) -> &'static str {
    match item {
        Item::Group(_) => "groups",
        Item::Code(_) | Item::UnlistedCode { .. } => "codes",
        Item::Address(_) => "addresses",
        Item::Parameter(_) => "parameters",
        Item::MachineConstant { .. } => "machine data",
        Item::Operation(_) => "operators",
        Item::Cycle(_) => "cycles",
        Item::Keyword(_) => "keywords",
        Item::Function(_) => "functions",
        Item::SystemVariable(_) => "system variables",
        Item::UndocumentedVariable(_) => "undocumented variables",
    }
}

#[test]
fn every_word_and_variable_the_thesis_names_has_an_entry() {
    let catalogue = sinumerik();
    let mut found = BTreeMap::new();
    for name in INVENTORY.iter().chain(SYSTEM_VARIABLES).chain(FURTHER_WORDS) {
        let items = catalogue.explain(name).unwrap_or_else(|not_found| panic!("{name} missing: {not_found:?}"));
        for item in &items {
            assert!(!matches!(item, Item::UndocumentedVariable(_)), "{name} is not documented");
            *found.entry(kind(item)).or_insert(0) += 1;
        }
    }
    let counts = BTreeMap::from([
        ("groups", catalogue.groups.len()),
        ("codes", catalogue.codes.len()),
        ("word codes", catalogue.codes.iter().filter(|c| c.is_word()).count()),
        ("addresses", catalogue.addresses.len()),
        ("operators", catalogue.operations.len()),
        ("keywords", catalogue.keywords.len()),
        ("functions", catalogue.functions.len()),
        ("system variables", catalogue.system_variables.len()),
        ("prefixes", catalogue.variable_prefixes.len()),
        ("machine data", catalogue.machine_constants.len()),
        ("cycles", catalogue.cycles.len()),
    ]);
    println!("Sinumerik catalogue: {counts:?}; the names checked found {found:?}");
}

#[test]
fn the_g_groups_carry_the_numbers_the_thesis_gives() {
    let catalogue = sinumerik();
    // Tab. 1.3 of the thesis (004:741-757) and the BSPLINE of group 1.
    let groups: [(&str, &[&str]); 6] = [
        ("G1", &["G0", "G1", "G2", "G3", "ASPLINE", "BSPLINE", "POLY"]),
        ("G6", &["G17", "G18", "G19"]),
        ("G7", &["G40", "G41", "G42"]),
        ("G8", &["G500", "G54", "G55", "G56"]),
        ("G13", &["G70", "G71", "G710"]),
        ("G14", &["G90", "G91"]),
    ];
    for (group, members) in groups {
        for name in members {
            let code = catalogue.code_named(name).unwrap_or_else(|| panic!("{name}"));
            assert_eq!(code.group.as_deref(), Some(group), "{name}");
        }
    }
    // `G[1]=1` is G0, and G1 is `G[1]=2` (004:3335-3341).
    assert_eq!(catalogue.code_at("G1", 1).map(|c| c.code.as_str()), Some("G0"));
    assert_eq!(catalogue.code_at("G1", 2).map(|c| c.code.as_str()), Some("G1"));
    assert_eq!(catalogue.code_at("G6", 1).map(|c| c.code.as_str()), Some("G17"));
    assert_eq!(catalogue.code_at("G13", 2).map(|c| c.code.as_str()), Some("G71"));
    assert_eq!(catalogue.code_named("G00"), catalogue.code_named("g0"));
    // The settable frames G505–G599 belong to group 8 without entries.
    let g8 = catalogue.groups.iter().position(|g| g.id == "G8");
    assert_eq!(catalogue.modal_group_index('G', 550), g8);
    assert!(matches!(catalogue.explain("G550").unwrap()[0], Item::UnlistedCode { .. }));
}

#[test]
fn words_of_a_group_replace_each_other_and_frames_hold_one_block() {
    let catalogue = sinumerik();
    let group_of = |word: &str| catalogue.word_modal_group_index(word).map(|i| catalogue.groups[i].id.as_str());
    assert_eq!(group_of("BSPLINE"), Some("G1"));
    assert_eq!(group_of("soft"), group_of("BRISK"));
    assert_eq!(group_of("FFWON"), Some("G24"));
    assert_eq!(group_of("COMPCAD"), Some("G30"));
    // Frame instructions share group 3 and act once: no modal slot.
    for frame in ["TRANS", "ATRANS", "ROT", "AROT", "SCALE", "ASCALE", "MIRROR", "AMIRROR"] {
        let code = catalogue.word_code(frame).unwrap();
        assert_eq!((code.group.as_deref(), code.modality), (Some("G3"), Modality::Block), "{frame}");
        assert!(!code.syntax.is_empty(), "{frame}: its form");
        assert_eq!(group_of(frame), None, "{frame}");
    }
    let defaults: Vec<_> = ["G1", "G6", "G7", "G8", "G10", "G13", "G14", "G21", "G24", "M2"]
        .iter()
        .map(|id| catalogue.group(id).and_then(|g| g.default.as_deref()).unwrap_or("-"))
        .collect();
    assert_eq!(defaults, ["G1", "G17", "G40", "G500", "G60", "G71", "G90", "BRISK", "FFWOF", "M5"]);
}

#[test]
fn system_variables_are_known_by_name_or_by_prefix() {
    let catalogue = sinumerik();
    let info = |name: &str| catalogue.system_variable(name);
    assert!(matches!(info("$P_GG[ 6 ]"), Some(SystemVariableInfo::Documented(v)) if v.name == "$P_GG"));
    assert!(matches!(info("$p_f"), Some(SystemVariableInfo::Documented(v)) if v.name == "$P_F"));
    // Unknown names with a known prefix are undocumented, never unknown.
    assert!(matches!(info("$P_XYZ"), Some(SystemVariableInfo::Undocumented { prefix }) if prefix.prefix == "$P_"));
    assert!(matches!(info("$AA_FOO[X]"), Some(SystemVariableInfo::Undocumented { prefix }) if prefix.prefix == "$AA_"));
    assert!(
        matches!(info("$TC_DP6[1,1]"), Some(SystemVariableInfo::Undocumented { prefix }) if prefix.prefix == "$TC_")
    );
    assert_eq!(info("$XYZ"), None);
    assert!(catalogue.explain("$XYZ").is_err());
    // Machine data by either prefix the thesis and Siemens write.
    for name in ["$MN_MM_NUM_R_PARAM", "$MC_MM_NUM_R_PARAM"] {
        assert!(
            matches!(info(name), Some(SystemVariableInfo::MachineData { constant, .. }) if constant.number == 28050)
        );
    }
    let undocumented = catalogue.explain("$P_XYZ").unwrap()[0].markdown(catalogue);
    assert!(undocumented.starts_with("### $P_… — a system variable ncc does not document"), "{undocumented}");
    let gg = catalogue.system_variables.iter().find(|v| v.name == "$P_GG").unwrap();
    assert_eq!((gg.ty.as_str(), gg.access, gg.main_run), ("INT", Access::Read, false));
    assert!(catalogue.system_variables.iter().find(|v| v.name == "$AA_IM").unwrap().main_run);
}

#[test]
fn operators_bind_as_the_priority_table_says() {
    let catalogue = sinumerik();
    let level = |symbol: &str| {
        let op = catalogue.operations.iter().find(|op| op.symbol.as_deref() == Some(symbol));
        op.and_then(|op| op.precedence).unwrap_or_else(|| panic!("{symbol}"))
    };
    // Digest §2.4, tightest first.
    let table: [&[&str]; 11] = [
        &["NOT", "B_NOT"],
        &["*", "/", "DIV", "MOD"],
        &["+", "-"],
        &["B_AND"],
        &["B_XOR"],
        &["B_OR"],
        &["AND"],
        &["XOR"],
        &["OR"],
        &["<<"],
        &["==", "<>", ">", "<", ">=", "<="],
    ];
    for (rank, symbols) in (1u8..).zip(table) {
        for symbol in symbols {
            assert_eq!(level(symbol), rank, "{symbol}");
        }
    }
    assert_eq!(catalogue.operations.len(), table.iter().map(|symbols| symbols.len()).sum::<usize>());
}

#[test]
fn functions_and_cycles_have_their_signatures() {
    let catalogue = sinumerik();
    let signature = |name: &str| catalogue.function(name).unwrap().signature();
    assert_eq!(signature("SIN"), "SIN(REAL angle) → REAL");
    assert_eq!(signature("ATAN2"), "ATAN2(REAL y, REAL x) → REAL");
    assert_eq!(signature("SUBSTR"), "SUBSTR(STRING text, INT start[, INT length]) → STRING");
    assert_eq!(signature("WRITE"), "WRITE(VAR INT error, STRING file, STRING line)");
    assert_eq!(signature("STRLEN"), "STRLEN(STRING text) → INT");
    let arguments = |name: &str| -> Vec<&str> {
        let cycle = catalogue.cycles_for(name).next().unwrap_or_else(|| panic!("{name}"));
        cycle.arguments.iter().map(|a| a.name.as_str()).collect()
    };
    assert_eq!(arguments("CYCLE81"), ["RTP", "RFP", "SDIS", "DP", "DPR"]);
    assert_eq!(arguments("CYCLE832"), ["S_TOL", "S_TOLM", "S_OTOL"]);
    // The thesis's calls pass 16 arguments (004:3841).
    assert_eq!(arguments("CYCLE800").len(), 16);
    for cycle in &catalogue.cycles {
        assert!(cycle.code.starts_with("CYCLE") && !cycle.arguments.is_empty(), "{}", cycle.code);
    }
}

#[test]
fn addresses_of_several_letters_take_no_letter_of_their_own() {
    let catalogue = sinumerik();
    assert_eq!(catalogue.role_of(b'C'), Some(AddressRole::Axis));
    assert_eq!(catalogue.role_of(b'r'), Some(AddressRole::Parameter));
    assert_eq!(catalogue.address("cr").map(|a| a.role), Some(AddressRole::Interpolation));
    assert_eq!(catalogue.address("OTOL").map(|a| a.role), Some(AddressRole::Tolerance));
    assert_eq!(catalogue.letter_with_role(AddressRole::Parameter), Some(b'R'));
    assert!(catalogue.is_parameter(99) && !catalogue.is_parameter(100));
    // A parameter is an address's value after `=`.
    let x = Item::Address(catalogue.address("X").unwrap()).markdown(catalogue);
    assert!(x.contains("allowed (e.g. `X=R1`)"), "{x}");
}
