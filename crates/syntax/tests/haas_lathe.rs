//! The Haas lathe grammar: snapshots of the manual's example programs and of
//! error cases, lexing decisions, and the properties every dialect keeps
//! (lossless round trip, no panic, reparse equals a full parse).
//!
//! The fixtures in `test_data/haas-lathe` are the examples of the lathe
//! manual §10, cleaned as §10 and §5.3 describe; [`CLEANED`] records what
//! was stripped from each. Run with `UPDATE_EXPECT=1` to accept new output.

mod line_dialects;

use std::{fs, path::PathBuf};

use line_dialects::{
    assert_every_edit_reparses_like_a_full_parse, assert_only_one_block_rebuilt, assert_well_formed, glued, insertion,
};
use ncc_syntax::{Dialect, Parse, Severity, SyntaxKind};
use proptest::prelude::*;

/// What was removed from the manual's text to make each example a program
/// (the page-marker token is removed from all of them).
const CLEANED: &[(&str, &str)] = &[
    ("e01_block_anatomy", "E1 (001:370): the prose prefix `Napr.:` and the figure label `NC -veta`"),
    (
        "e12_g71_g70_skeleton",
        "E12 (001:1605-1621): the heading `Príklad:`, the elision lines `...`/`....` and the prose lines between them",
    ),
    ("e14_g71_type1_program", "E14 (001:1800-1824): nothing (one blank OCR line was already dropped by §10)"),
    (
        "e17_g71_type2_template",
        "E17 (001:2004-2029): the placeholders `X..`, `Z..`, `Z...` and the bare `X Z` replaced by values of E14's contour; the closing prose warning and its example line",
    ),
    ("e20_g92_thread", "E20 (001:2886-2903): the heading `Príklad: M30 x 3.5`; the doubled point of `X25.8.` (§5.3)"),
    ("e21_corner_chamfer", "E21 (001:2998-3000): the prose prefix `Napr.:`"),
    (
        "e22_corner_examples",
        "E22 (001:3023-3103): the OCR line splits `K- ⏎ 10.` and `R- ⏎ 10.` joined; the closing prose warning. `Z 30` is kept (a warning)",
    ),
    ("e23_angle_lines", "E23 (001:3150-3182): the prose lines `alebo` (\"or\")"),
    ("e25_uebung", "E25 (001:3712-3772): the cleaned order of §10, without the explanation column"),
];

fn fixtures() -> Vec<(PathBuf, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("test_data/haas-lathe");
    let mut files: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "nc"))
        .collect();
    files.sort();
    files.into_iter().map(|path| (path.clone(), fs::read_to_string(&path).unwrap())).collect()
}

fn parse(text: &str) -> Parse {
    Parse::new(text, Dialect::HaasLathe)
}

#[test]
fn every_cleaned_example_has_its_fixture() {
    let names: Vec<String> =
        fixtures().iter().map(|(path, _)| path.file_stem().unwrap().to_str().unwrap().to_owned()).collect();
    for (name, _) in CLEANED {
        assert!(names.iter().any(|n| n == name), "{name}");
    }
}

#[test]
fn snapshots() {
    for (path, text) in fixtures() {
        let parse = parse(&text);
        assert_eq!(parse.syntax_node().to_string(), text, "{} does not round-trip", path.display());
        let is_error_fixture = path.file_name().unwrap().to_str().unwrap().starts_with("error_");
        let has_errors = parse.errors().iter().any(|e| e.severity() == Severity::Error);
        assert_eq!(
            has_errors,
            is_error_fixture,
            "{}: error fixtures are named error_*\n{:?}",
            path.display(),
            parse.errors()
        );
        expect_test::expect_file![path.with_extension("rast")].assert_eq(&parse.debug_dump());
    }
}

/// Deleting each character, and inserting a few interesting ones at each
/// position, reparses to the same result as a full parse.
#[test]
fn fixture_edits_reparse_like_full_parses() {
    let inserts = ["N", "(", ")", "\n", "\r", " ", "#", "[", "5", "%", ";", "IF"];
    for (path, text) in fixtures() {
        assert_every_edit_reparses_like_a_full_parse(Dialect::HaasLathe, &path.display().to_string(), &text, &inserts);
    }
}

fn tokens(text: &str) -> Vec<(SyntaxKind, String)> {
    line_dialects::tokens(Dialect::HaasLathe, text)
}

#[test]
fn letters_lex_by_the_longest_keyword() {
    use SyntaxKind::*;
    let t = |kind: SyntaxKind, text: &str| (kind, text.to_owned());
    assert_eq!(tokens("G0 GOTO5"), [t(LETTER, "G"), t(NUMBER, "0"), t(IDENT, "GOTO"), t(NUMBER, "5")]);
    assert_eq!(tokens("D0 DO1"), [t(LETTER, "D"), t(NUMBER, "0"), t(IDENT, "DO"), t(NUMBER, "1")]);
    assert_eq!(tokens("END2 E1."), [t(IDENT, "END"), t(NUMBER, "2"), t(LETTER, "E"), t(NUMBER, "1.")]);
    assert_eq!(
        tokens("IF[#1EQ2]GOTO9"),
        [
            t(IDENT, "IF"),
            t(L_BRACK, "["),
            t(HASH, "#"),
            t(NUMBER, "1"),
            t(IDENT, "EQ"),
            t(NUMBER, "2"),
            t(R_BRACK, "]"),
            t(IDENT, "GOTO"),
            t(NUMBER, "9")
        ]
    );
}

#[test]
fn comment_contents_are_never_tokenised() {
    use SyntaxKind::*;
    let text = "G0 (X1 #1=2 [ IF GOTO5 ; %) X2. ; (P0 ] WHILE\n";
    let parse = parse(text);
    assert!(parse.errors().is_empty(), "{:?}", parse.errors());
    assert_eq!(
        tokens(text),
        [
            (LETTER, "G".to_owned()),
            (NUMBER, "0".to_owned()),
            (COMMENT, "(X1 #1=2 [ IF GOTO5 ; %)".to_owned()),
            (LETTER, "X".to_owned()),
            (NUMBER, "2.".to_owned()),
            (COMMENT, "; (P0 ] WHILE".to_owned()),
        ]
    );
}

#[test]
fn precedence_follows_fanuc() {
    let parse = parse("#1 = 1 + 2 * 3 EQ -4 OR 5 AND 6\n");
    assert!(parse.errors().is_empty(), "{:?}", parse.errors());
    let root = parse.syntax_node();
    let top = root.descendants().find(|n| n.kind() == SyntaxKind::BIN_EXPR).unwrap();
    // `EQ` is the loosest operator: the top expression splits at it.
    let operator = top.children_with_tokens().find(|e| e.kind() == SyntaxKind::IDENT).unwrap();
    assert_eq!(operator.to_string(), "EQ");
    let left = top.children().next().unwrap();
    assert_eq!(left.to_string(), "1 + 2 * 3");
    assert_eq!(left.children().nth(1).unwrap().to_string(), "2 * 3");
}

#[test]
fn a_long_line_is_read_up_to_the_limit() {
    let line = "X1.".repeat(400_000);
    let text = format!("O1\n{line}\nG0 X1.\n");
    let parse = parse(&text);
    let root = parse.syntax_node();
    assert_eq!(root.to_string(), text);
    assert!(root.descendants_with_tokens().count() < 3_000);
    assert!(parse.errors().iter().any(|e| e.kind == ncc_syntax::SyntaxErrorKind::LineTooLong));
}

#[test]
fn deep_nesting_is_bounded() {
    for text in [
        "#1=".to_owned() + &"[".repeat(5000),
        "X".to_owned() + &"-".repeat(5000) + "1",
        "#1=".to_owned() + &"-[".repeat(3000),
    ] {
        let parse = parse(&text);
        assert_eq!(parse.syntax_node().to_string(), text);
    }
}

/// Fragments of Haas programs, valid or not.
const FRAGMENTS: &[&str] = &[
    "G01 ",
    "X-12.5",
    "Z.5",
    "#1",
    "#[#2+1]",
    "=",
    " ",
    "\n",
    "\r\n",
    "\r",
    "(",
    ")",
    "(P1)",
    ";c",
    "%",
    "O1234",
    "N10 ",
    "/",
    "/1",
    "IF [#1 EQ 2] GOTO 10",
    "THEN",
    "GOTO",
    "WHILE [#1 LT 3] DO1",
    "END1",
    "DO",
    "SIN[30.]",
    "ATAN[1]/[2]",
    "[",
    "]",
    "*",
    "MOD",
    ",C1.",
    ",",
    "7.75.",
    "Z- 30.",
    "X 5",
    "é",
    "\u{feff}",
    "AND",
    "-",
    "+",
    "G65 P9010 A1. B2.",
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn any_string_round_trips(text in any::<String>()) {
        assert_well_formed(&text, &parse(&text));
    }

    #[test]
    fn haas_like_text_round_trips(text in glued(FRAGMENTS)) {
        assert_well_formed(&text, &parse(&text));
    }

    #[test]
    fn reparse_equals_full_parse(
        text in prop_oneof![glued(FRAGMENTS), any::<String>()],
        start in 0usize..2000,
        len in 0usize..12,
        insert in insertion(FRAGMENTS),
    ) {
        line_dialects::reparse_equals_full_parse(Dialect::HaasLathe, &text, start, len, insert)?;
    }
}

/// The cases the property tests once failed on.
#[test]
fn reparses_that_once_failed() {
    for (text, start, len, insert) in
        [("G01 O1234G01 GOTO", 0, 0, "G01 O123"), ("\u{113c2}🌀A0", 132, 0, "\u{feff}O1234O1")]
    {
        line_dialects::reparse_equals_full_parse(Dialect::HaasLathe, text, start, len, insert.to_owned()).unwrap();
    }
}

/// An edit inside a loop rebuilds its own block only: `WHILE … DO1` and
/// `END1` are separate blocks, matched later.
#[test]
fn an_edit_inside_a_loop_reparses_one_block() {
    let text = "O1\n#1 = 0\nWHILE [#1 LT 10] DO1\nG01 X[#1 * 2.] F0.1\n#1 = #1 + 1\nEND1\nM30\n";
    let at = text.find("X[#1 * 2.]").unwrap() + 8;
    assert_only_one_block_rebuilt(Dialect::HaasLathe, text, at, "3", 7, 3);
}
