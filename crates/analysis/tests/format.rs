//! Document formatting: the style on hand-written programs, and on
//! generated ones that formatting is idempotent, changes only spacing and
//! keeps the tree and its diagnostics.

#[path = "../../syntax/tests/strategies/mod.rs"]
mod strategies;

use expect_test::{Expect, expect};
use ncc_analysis::{AnalysisHost, Dialect, TextEdit};
use ncc_syntax::{Parse, SyntaxErrorKind, SyntaxKind, SyntaxNode};
use proptest::prelude::*;
use rowan::NodeOrToken;
use strategies::{block_program, crowded_lines, overlong_lines, program_text};

/// The edits that format `text`.
fn format_edits(text: &str) -> Vec<TextEdit> {
    let mut host = AnalysisHost::default();
    let file = host.add_file("main.NCP", text);
    host.analysis().format(file)
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
    let formatted = apply(text, &format_edits(text));
    let shown: String =
        formatted.split_inclusive('\n').map(|line| line.replace('\r', "␍").replace('\n', "|\n")).collect();
    expect.assert_eq(&shown);
}

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
fn edits_replace_only_the_spacing_that_changes() {
    let text = "N10  G0X1 Y2   \nN20 X1\n";
    let edits: Vec<String> =
        format_edits(text).iter().map(|edit| format!("{:?} {:?}", edit.delete, edit.insert)).collect();
    expect![[r#"
        3..5 " "
        7..7 " "
        12..15 """#]]
    .assert_eq(&edits.join("\n"));
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
    for edit in &edits {
        let old = &text[edit.delete];
        prop_assert!(old.bytes().all(|b| b == b' ' || b == b'\t'), "replaces spacing only: {old:?}");
        prop_assert!(edit.insert.bytes().all(|b| b == b' ') && edit.insert != old, "{edit:?}");
    }
    let formatted = apply(text, &edits);
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
