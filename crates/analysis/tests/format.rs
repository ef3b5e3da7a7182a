//! Document formatting: the style on hand-written programs, and on
//! generated ones that formatting is idempotent, changes only spacing and
//! keeps the tree and its diagnostics.

#[path = "../../syntax/tests/strategies/mod.rs"]
mod strategies;
mod support;

use expect_test::{Expect, expect};
use ncc_analysis::{
    AnalysisHost, Config, Dialect, FormatConfig, LetterCase, NumberStyle, TextEdit, WordOrder, WordSpacing,
};
use ncc_syntax::{Parse, SyntaxErrorKind, SyntaxKind, SyntaxNode, TextRange, TextSize};
use proptest::prelude::*;
use rowan::NodeOrToken;
use strategies::{block_program, crowded_lines, overlong_lines, program_text};

/// The edits that format the CNC8x6 program `text` in the default style.
fn format_edits(text: &str) -> Vec<TextEdit> {
    format_in(Dialect::Cnc8x6, FormatConfig::default(), text, None)
}

/// The edits that format the lines `range` touches (all without it) of
/// `text`, a program of `dialect`, in `style`.
fn format_in(dialect: Dialect, style: FormatConfig, text: &str, range: Option<TextRange>) -> Vec<TextEdit> {
    let config = Config { format: style, ..Config::default() };
    let mut host = AnalysisHost::in_dialect(dialect, config);
    let file = host.add_file("main", text);
    host.analysis().format(file, range)
}

fn apply(text: &str, edits: &[TextEdit]) -> String {
    let mut text = text.to_owned();
    for edit in edits.iter().rev() {
        edit.apply(&mut text);
    }
    text
}

/// The formatted text, with `|` marking where each line ends.
fn check(text: &str, expect: Expect) {
    check_in(Dialect::Cnc8x6, FormatConfig::default(), text, expect);
}

/// `text`, a program of `dialect`, formatted in `style`, with `|` marking
/// where each line ends.
fn check_in(dialect: Dialect, style: FormatConfig, text: &str, expect: Expect) {
    let formatted = apply(text, &format_in(dialect, style, text, None));
    let shown: String =
        formatted.split_inclusive('\n').map(|line| line.replace('\r', "␍").replace('\n', "|\n")).collect();
    expect.assert_eq(&shown);
}

/// Every choice of `[format]` that changes something.
const EVERYTHING: FormatConfig = FormatConfig {
    spacing: WordSpacing::None,
    case: LetterCase::Upper,
    numbers: NumberStyle::Trim,
    word_order: WordOrder::Standard,
    indent: Some(2),
};

/// The choices of `[format]` but `spacing`.
const SPACED: FormatConfig = FormatConfig { spacing: WordSpacing::One, ..EVERYTHING };

#[test]
fn one_space_between_items_none_inside_them() {
    check(
        "%100 \"HŘÍDEL – zkouška\"  \nN10   G90  G17 G0X0 Y0\nN20 G01 X  36.12 F300\t \n  N30 R1 = 864  R2=5.  \nN40/ M30\n",
        expect![[r#"
            %100 "HŘÍDEL – zkouška"  |
            N10 G90 G17 G0 X0 Y0|
            N20 G01 X36.12 F300|
            N30 R1=864 R2=5.|
            N40 / M30|
        "#]],
    );
}

#[test]
fn continuation_lines_are_indented_by_one_space_and_comments_keep_their_column() {
    check(
        "%7\nN10  G29 R5=-42210226   \"R26 = R21 - 2 (počet skoků)\"\n      R6=-42210127     \"R27 = R21 - 1\"\nR7=1\n   \"  komentář – jen řádek\"\n\n\t\nN20 G1 X10  Y20    \"zarovnáno\"\nN30 G1 X1           \"zarovnáno\"\nN40 X1\"hned\" Y2 \"a\"\"b\"\n",
        expect![[r#"
            %7|
            N10 G29 R5=-42210226    "R26 = R21 - 2 (počet skoků)"|
             R6=-42210127          "R27 = R21 - 1"|
             R7=1|
               "  komentář – jen řádek"|
            |
            |
            N20 G1 X10 Y20     "zarovnáno"|
            N30 G1 X1           "zarovnáno"|
            N40 X1 "hned" Y2 "a" "b"|
        "#]],
    );
}

#[test]
fn syntax_errors_the_header_and_the_end_are_kept_as_written() {
    check(
        "ÚVOD  \r\n%12   \"hlavička\"   \r\nN10 X-  5   Y 1 2   Z  3\r\nN20 G1    X1  #€  Y2\r\n  n30  X1\r\n*   \"konec\"   \r\nN99   X1  \r\n",
        expect![[r#"
            ÚVOD  ␍|
            %12   "hlavička"   ␍|
            N10 X-  5 Y 1 2   Z3␍|
            N20 G1 X1  #€  Y2␍|
              n30 X1␍|
            *   "konec"   ␍|
            N99   X1  ␍|
        "#]],
    );
}

#[test]
fn a_line_is_not_made_longer_than_the_control_reads() {
    let long = format!("N10 G1X1 \"{}\"\nN20 G1X1\n", "A".repeat(69));
    assert_eq!(long.lines().next().map(str::len), Some(80));
    check(
        &long,
        expect![[r#"
            N10 G1X1 "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"|
            N20 G1 X1|
        "#]],
    );
}

#[test]
fn spaces_between_a_lone_carriage_return_and_a_line_feed_stay() {
    // Without them, `\r` and `\n` would become one line break.
    check(
        "N10 X1\r \nN20 X2 \r\n",
        expect![[r#"
            N10 X1␍ |
            N20 X2␍|
        "#]],
    );
}

#[test]
fn an_edit_replaces_a_line_from_its_first_change_to_its_last() {
    let text = "N10  G0X1 Y2   \nN20 X1\nN30 G1  X2\n";
    let edits: Vec<String> =
        format_edits(text).iter().map(|edit| format!("{:?} {:?}", edit.delete, edit.insert)).collect();
    expect![[r#"
        4..15 "G0 X1 Y2"
        30..31 """#]]
    .assert_eq(&edits.join("\n"));
}

#[test]
fn range_formatting_changes_the_lines_the_range_touches() {
    let text = "N10  G0X1\nN20  G0X1\nN30  G0X1\nN40  G0X1\n";
    // From inside the second line to the start of the third.
    let range = TextRange::new(TextSize::from(14), TextSize::from(20));
    let formatted = apply(text, &format_in(Dialect::Cnc8x6, FormatConfig::default(), text, Some(range)));
    assert_eq!(formatted, "N10  G0X1\nN20 G0 X1\nN30 G0 X1\nN40  G0X1\n");
}

#[test]
fn cnc8x6_in_every_style() {
    let text = "%1\nN10  g0 X010.500 S1200 y-2.000 M3 G90 \"x\"\nN20 G1 X1.0 R1=5.50 Y2\nN30 X.50 G54.1\n*\n";
    check_in(
        Dialect::Cnc8x6,
        EVERYTHING,
        text,
        expect![[r#"
            %1|
            N10G0G90X10.5Y-2.0S1200M3             "x"|
            N20G1X1.0 R1=5.5 Y2|
            N30G54.1X.5|
            *|
        "#]],
    );
}

#[test]
fn haas_lathe_keeps_or_sets_indentation_and_keeps_statements_and_tape_marks() {
    let text = "%  \nO1000 (SHAFT)\n  g0  x10.0 z-2.500 (c)\nG71 P10 Q20 U0.4 W0.1 D2. F0.25\n#1 = #2 + 3.50\nIF [#1 GT 2.0] GOTO10\nWHILE [#1 LT 3] DO1\n#1 = #1 + 1\n  WHILE [#2 LT 3] DO2\n#2 = #2 + 1\n    END2\nEND1\nG4 P30\nG1 X20. ,C1. F0.2\nM30\n% \n";
    check_in(
        Dialect::HaasLathe,
        FormatConfig::default(),
        text,
        expect![[r#"
            %  |
            O1000 (SHAFT)|
              g0  x10.0 z-2.500 (c)|
            G71 P10 Q20 U0.4 W0.1 D2. F0.25|
            #1 = #2 + 3.50|
            IF [#1 GT 2.0] GOTO10|
            WHILE [#1 LT 3] DO1|
            #1 = #1 + 1|
              WHILE [#2 LT 3] DO2|
            #2 = #2 + 1|
                END2|
            END1|
            G4 P30|
            G1 X20. ,C1. F0.2|
            M30|
            % |
        "#]],
    );
    check_in(
        Dialect::HaasLathe,
        EVERYTHING,
        text,
        expect![[r#"
            %  |
            O1000 (SHAFT)|
            G0X10.0Z-2.5        (c)|
            G71U0.4W0.1F0.25P10Q20D2.|
            #1 = #2 + 3.5|
            IF [#1 GT 2.0] GOTO10|
            WHILE [#1 LT 3] DO1|
              #1 = #1 + 1|
              WHILE [#2 LT 3] DO2|
                #2 = #2 + 1|
              END2|
            END1|
            G4P30|
            G1X20.,C1.F0.2|
            M30|
            % |
        "#]],
    );
}

#[test]
fn sinumerik_indents_structures_and_keeps_one_space_strings_and_comments() {
    let text = "PROC part(real depth) SAVE\n  def real a=1.50 ; Depth  \n  while a>0.0\n    g1   x=ic(5.0) f1000   Y10\n    a=a-0.50\n  endwhile\nLAB1:  msg(\"hello  World\")\nN10 Y10 G1 X20\nM17\n";
    check_in(
        Dialect::Sinumerik,
        EVERYTHING,
        text,
        expect![[r#"
            PROC PART(REAL DEPTH) SAVE|
            DEF REAL A=1.5    ; Depth  |
            WHILE A>0.0|
              G1 X=IC(5.0) F1000 Y10|
              A=A-0.5|
            ENDWHILE|
            LAB1: MSG("hello  World")|
            N10 G1 Y10 X20|
            M17|
        "#]],
    );
}

#[test]
fn trailing_spaces_go_in_every_dialect() {
    let text = "G1 X1  \t\nG1 X2\n";
    for dialect in [Dialect::HaasLathe, Dialect::Sinumerik] {
        let formatted = apply(text, &format_in(dialect, FormatConfig::default(), text, None));
        assert_eq!(formatted, "G1 X1\nG1 X2\n", "{dialect:?}");
    }
}

/// The tree's node and token kinds without spaces (and nodes of spaces
/// only): what case and number style leave as they are.
fn kinds(node: &SyntaxNode, out: &mut Vec<SyntaxKind>) {
    if node.text().to_string().trim_matches([' ', '\t']).is_empty() {
        return;
    }
    out.push(node.kind());
    for child in node.children_with_tokens() {
        match child {
            NodeOrToken::Node(node) => kinds(&node, out),
            NodeOrToken::Token(token) if token.kind() != SyntaxKind::WHITESPACE => out.push(token.kind()),
            NodeOrToken::Token(_) => {}
        }
    }
}

#[test]
fn the_run_tells_programs_apart() {
    let run = |text| support::run_of(Dialect::Sinumerik, text);
    assert_eq!(run("G1 X10 F100\nM30\n"), run("G1   X10 F100\nM30\n"));
    assert_ne!(run("G1 X10 F100\nM30\n"), run("G1 X10.5 F100\nM30\n"));
    assert_ne!(run("G1 X10 F100\nM30\n"), run("\nG1 X10 F100\nM30\n"));
}

/// Formatting `text` in `style` is idempotent, keeps the kinds of the
/// tree (reordered within blocks) and its errors, and the executor runs
/// the same steps before and after.
fn check_style_keeps_the_run(dialect: Dialect, style: FormatConfig, text: &str) -> Result<(), String> {
    let formatted = apply(text, &format_in(dialect, style, text, None));
    let again = format_in(dialect, style, &formatted, None);
    if !again.is_empty() {
        return Err(format!("not idempotent: {formatted:?} → {again:?}"));
    }
    let (before, after) = (Parse::new(text, dialect), Parse::new(&formatted, dialect));
    let (mut old_kinds, mut new_kinds) = (Vec::new(), Vec::new());
    kinds(&before.syntax_node(), &mut old_kinds);
    kinds(&after.syntax_node(), &mut new_kinds);
    if style.word_order == WordOrder::Keep && old_kinds != new_kinds {
        return Err(format!("the tree changed: {formatted:?}"));
    }
    let codes = |parse: &Parse| {
        let mut codes: Vec<_> = parse
            .errors()
            .iter()
            .filter(|e| !matches!(e.kind, SyntaxErrorKind::LineTooLong | SyntaxErrorKind::LowercaseAddress))
            .map(|e| e.kind)
            .collect();
        codes.sort();
        codes
    };
    if codes(&before) != codes(&after) {
        return Err(format!("the errors changed: {formatted:?}"));
    }
    if support::run_of(dialect, text) != support::run_of(dialect, &formatted) {
        return Err(format!("the run changed: {formatted:?}"));
    }
    Ok(())
}

#[test]
fn every_style_keeps_the_run_of_every_program_of_the_repository() {
    let programs = support::repository_programs();
    for dialect in [Dialect::Cnc8x6, Dialect::HaasLathe, Dialect::Sinumerik] {
        assert!(programs.iter().filter(|(_, d)| *d == dialect).count() >= 10, "{dialect:?}: too few programs");
    }
    let mut failures = Vec::new();
    for (path, dialect) in &programs {
        let Ok(text) = std::fs::read_to_string(path) else { continue };
        for style in [FormatConfig::default(), SPACED, EVERYTHING] {
            if let Err(error) = check_style_keeps_the_run(*dialect, style, &text) {
                failures.push(format!("{} in {style:?}: {error}", path.display()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Pieces of Haas lathe programs, glued at random by the property test.
const HAAS_PIECES: &[&str] = &[
    "G00 ",
    "G01",
    " g1 ",
    "X20.",
    "x-1.500",
    "Z-2.000",
    "Z 30",
    "U0.4 ",
    "W0.1",
    "F0.2",
    "f.250",
    "S1200 ",
    "M03",
    "T0101",
    "G71 P10 Q20 U0.4 W0.1 D2. F0.25",
    "N10 ",
    "N20",
    "G70 P10 Q20",
    "G96 S200 M3",
    "G50 S3000",
    "G02 X36. Z-43. R3.",
    ",C1.",
    "#1=2.500",
    " #1 = #1 + 1.0",
    "X#1",
    "IF [#1 GT 2.0] GOTO10",
    "(C) ",
    "  ",
    "\t",
    "\n",
    "\n",
    "\n",
    "M30\n",
    "%\n",
    "G04 P30",
    "G4 P1.50",
    "G76 X18.16 Z-20. K0.92 D0.3 A60 P1 F1.5",
    "WHILE [#1 LT 3] DO1\n",
    "END1\n",
    "  WHILE [#2 LT 3] DO2\n",
    "END2\n",
];

/// Pieces of Sinumerik programs, glued at random by the property test.
const SINUMERIK_PIECES: &[&str] = &[
    "G0 ",
    "g1",
    " X10.500",
    "Y=20.0 ",
    "z-2.000",
    "F1000.0",
    " S2000 ",
    "M3 ",
    "T1 D1",
    "N10 ",
    ":20 ",
    "R1=5.50",
    "X=R1",
    "DEF REAL A=1.50\n",
    "a=a+1.0\n",
    "IF A>2.0 GOTOF ende\n",
    "ENDE:",
    "WHILE A<3.0\n",
    "ENDWHILE\n",
    "CR=5.0",
    "G2 X20 Y10 CR=10.0",
    "; comment  ",
    "  ",
    "\t",
    "\n",
    "\n",
    "\n",
    "M30\n",
    "MSG(\"x  y\")",
    "TRANS X10 Y5.0",
    "ROT Z30.0",
    "CYCLE81(10,0,2,-5.0)",
    "G91 ",
    "G90 ",
    "IF A>1\n",
    "ELSE\n",
    "ENDIF\n",
    "  FOR R2=1 TO 3\n",
    "ENDFOR\n",
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn every_style_keeps_the_run_of_generated_programs(
        (dialect, text) in prop_oneof![
            block_program().prop_map(|text| (Dialect::Cnc8x6, text)),
            prop::collection::vec(prop::sample::select(HAAS_PIECES), 0..60)
                .prop_map(|pieces| (Dialect::HaasLathe, pieces.concat())),
            prop::collection::vec(prop::sample::select(SINUMERIK_PIECES), 0..60)
                .prop_map(|pieces| (Dialect::Sinumerik, pieces.concat())),
        ],
        style in prop::sample::select(vec![FormatConfig::default(), SPACED, EVERYTHING]),
    ) {
        check_style_keeps_the_run(dialect, style, &text).map_err(TestCaseError::fail)?;
    }
}

#[test]
fn a_formatted_program_has_nothing_to_format() {
    let examples = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let mut files = vec![format!("{examples}/macros/L9001")];
    for dir in ["milling", "lathe"] {
        for entry in std::fs::read_dir(format!("{examples}/{dir}")).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "NCP") {
                files.push(path.display().to_string());
            }
        }
    }
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(format_edits(&text), Vec::new(), "{path}");
    }
}

/// The tree without its spaces: node kinds, and every other token's kind
/// and text.
fn skeleton(node: &SyntaxNode, out: &mut Vec<String>) {
    out.push(format!("{:?}", node.kind()));
    for child in node.children_with_tokens() {
        match child {
            NodeOrToken::Node(node) => skeleton(&node, out),
            NodeOrToken::Token(token) if token.kind() != SyntaxKind::WHITESPACE => {
                out.push(format!("{:?} {:?}", token.kind(), token.text()));
            }
            NodeOrToken::Token(_) => {}
        }
    }
    out.push("end".to_owned());
}

/// The syntax errors other than long lines, which spacing may shorten,
/// and the number of long lines.
fn errors(parse: &Parse) -> (Vec<(SyntaxErrorKind, String)>, usize) {
    let (long, other): (Vec<_>, Vec<_>) = parse.errors().iter().partition(|e| e.kind == SyntaxErrorKind::LineTooLong);
    (other.into_iter().map(|e| (e.kind, e.message.clone())).collect(), long.len())
}

/// Text with runs of spaces and tabs put between random characters.
fn spaced_program() -> impl Strategy<Value = String> {
    let gaps =
        prop::collection::vec((0usize..400, prop_oneof![Just(" "), Just("  "), Just("\t"), Just(" \t ")]), 0..20);
    (block_program(), gaps).prop_map(|(mut text, gaps)| {
        for (at, gap) in gaps {
            let at = at % (text.len() + 1);
            if text.is_char_boundary(at) {
                text.insert_str(at, gap);
            }
        }
        text
    })
}

fn check_format_properties(text: &str) -> Result<(), TestCaseError> {
    let edits = format_edits(text);
    for pair in edits.windows(2) {
        prop_assert!(pair[0].delete.end() < pair[1].delete.start(), "edits sorted, apart: {pair:?}");
    }
    let formatted = apply(text, &edits);
    let unspaced = |text: &str| text.replace([' ', '\t'], "");
    prop_assert_eq!(unspaced(&formatted), unspaced(text), "changes spacing only");
    prop_assert_eq!(format_edits(&formatted), Vec::new(), "idempotent: {:?}", formatted);

    let (before, after) = (Parse::new(text, Dialect::Cnc8x6), Parse::new(&formatted, Dialect::Cnc8x6));
    let (mut old_tree, mut new_tree) = (Vec::new(), Vec::new());
    skeleton(&before.syntax_node(), &mut old_tree);
    skeleton(&after.syntax_node(), &mut new_tree);
    prop_assert_eq!(old_tree, new_tree, "same tree: {:?}", formatted);
    let ((old_errors, old_long), (new_errors, new_long)) = (errors(&before), errors(&after));
    prop_assert_eq!(old_errors, new_errors);
    prop_assert!(new_long <= old_long, "no new long line: {:?}", formatted);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn formatting_keeps_the_tree_and_is_idempotent(
        text in prop_oneof![program_text(), block_program(), spaced_program(), crowded_lines(), overlong_lines(), any::<String>()],
    ) {
        check_format_properties(&text)?;
    }
}
