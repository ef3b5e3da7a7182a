//! The Sinumerik grammar: snapshots of small programs for every construct
//! and of error cases, the seed's listings (which must parse without a
//! syntax error), and the properties every dialect keeps (lossless round
//! trip, no panic, reparse equals a full parse, valid programs parse
//! cleanly).
//!
//! `test_data/sinumerik/*` are the listings of the seed, each saying at its
//! top what was changed to make it the program its author meant;
//! `test_data/sinumerik/constructs/*` are small programs with their trees
//! in `.rast` files (run with `UPDATE_EXPECT=1` to accept new output).

mod line_dialects;

use std::{fs, path::PathBuf};

use line_dialects::{
    assert_every_edit_reparses_like_a_full_parse, assert_only_one_block_rebuilt, assert_well_formed, glued, insertion,
};
use ncc_syntax::{Dialect, Parse, SyntaxErrorKind, SyntaxKind, SyntaxNode};
use proptest::prelude::*;

fn parse(text: &str) -> Parse {
    Parse::new(text, Dialect::Sinumerik)
}

fn root(parse: &Parse) -> SyntaxNode {
    parse.syntax_node()
}

fn files(dir: &str) -> Vec<(PathBuf, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("test_data/sinumerik").join(dir);
    let mut files: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "mpf" || ext == "spf"))
        .collect();
    files.sort();
    files.into_iter().map(|path| (path.clone(), fs::read_to_string(&path).unwrap())).collect()
}

#[test]
fn listings_parse_without_errors() {
    let listings = files("");
    let names: Vec<String> =
        listings.iter().map(|(path, _)| path.file_name().unwrap().to_string_lossy().into()).collect();
    for listing in ["l19", "l24", "l25", "l26", "l27", "l28", "l29", "l30", "l31"] {
        assert!(names.iter().any(|name| name.starts_with(listing)), "{listing} missing");
    }
    for (path, text) in listings {
        let parts = parse(&text);
        assert_eq!(root(&parts).to_string(), text, "{} does not round-trip", path.display());
        assert!(parts.errors().is_empty(), "{}:\n{}", path.display(), parts.debug_dump());
    }
}

#[test]
fn construct_snapshots() {
    let fixtures = files("constructs");
    assert!(fixtures.len() >= 7);
    for (path, text) in fixtures {
        let parts = parse(&text);
        assert_eq!(root(&parts).to_string(), text, "{} does not round-trip", path.display());
        let is_error_fixture = path.file_name().unwrap().to_str().unwrap().starts_with("error_");
        assert_eq!(
            !parts.errors().is_empty(),
            is_error_fixture,
            "{}: error fixtures are named error_*\n{:?}",
            path.display(),
            parts.errors()
        );
        expect_test::expect_file![path.with_extension("rast")].assert_eq(&parts.debug_dump());
    }
}

/// Deleting each character, and inserting a few interesting ones at each
/// position, reparses to the same result as a full parse.
#[test]
fn fixture_edits_reparse_like_full_parses() {
    let inserts = ["N", "(", ")", "\n", "\r", " ", "\"", "[", "5", "%", ";", ":", "IF"];
    for (path, text) in files("constructs").into_iter().chain(files("").into_iter().take(2)) {
        assert_every_edit_reparses_like_a_full_parse(Dialect::Sinumerik, &path.display().to_string(), &text, &inserts);
    }
}

/// An edit inside a loop rebuilds its own block only: `WHILE` and
/// `ENDWHILE` are separate blocks, matched later.
#[test]
fn an_edit_inside_a_loop_reparses_one_block() {
    let text = "R1=0\nWHILE R1<10\nG1 X=R1*2 F100\nR1=R1+1\nENDWHILE\nM30\n";
    let at = text.find("R1*2").unwrap() + 3;
    assert_only_one_block_rebuilt(Dialect::Sinumerik, text, at, "3", 6, 2);
}

fn tokens(text: &str) -> Vec<(SyntaxKind, String)> {
    line_dialects::tokens(Dialect::Sinumerik, text)
}

#[test]
fn addresses_and_names_split_by_the_two_letter_rule() {
    use SyntaxKind::*;
    let t = |kind: SyntaxKind, text: &str| (kind, text.to_owned());
    assert_eq!(
        tokens("G641 X1=XA CR=2"),
        [
            t(LETTER, "G"),
            t(NUMBER, "641"),
            t(LETTER, "X"),
            t(NUMBER, "1"),
            t(EQ, "="),
            t(IDENT, "XA"),
            t(IDENT, "CR"),
            t(EQ, "="),
            t(NUMBER, "2")
        ]
    );
}

/// The top node of the first statement of `text`'s first block.
fn first_statement(text: &str) -> SyntaxNode {
    let parts = parse(text);
    assert!(parts.errors().is_empty(), "{:?}", parts.errors());
    let block = root(&parts).descendants().find(|n| n.kind() == SyntaxKind::BLOCK).unwrap();
    block.children().next().unwrap()
}

#[test]
fn precedence_follows_the_siemens_table() {
    // `+` binds tighter than `<<`, which binds tighter than `==` (digest §2.4).
    let assign = first_statement("S=\"Y\"<<R1+5==\"Y15\"\n");
    let top = assign.children().find(|n| n.kind() == SyntaxKind::BIN_EXPR).unwrap();
    let operator = top.children_with_tokens().find(|e| e.kind() == SyntaxKind::EQ_EQ);
    assert!(operator.is_some(), "{top:#?}");
    let concat = top.children().next().unwrap();
    assert_eq!(concat.to_string(), "\"Y\"<<R1+5");
    assert_eq!(concat.children().nth(1).unwrap().to_string(), "R1+5");
    // `AND` binds tighter than `OR`, `NOT` tightest.
    let assign = first_statement("B=NOT R1 OR R2 AND R3\n");
    let top = assign.children().find(|n| n.kind() == SyntaxKind::BIN_EXPR).unwrap();
    assert_eq!(top.children().next().unwrap().to_string(), "NOT R1");
    assert_eq!(top.children().nth(1).unwrap().to_string(), "R2 AND R3");
}

#[test]
fn one_line_jump_belongs_to_its_if() {
    let statement = first_statement("IF R1>5 GOTOF LABEL\n");
    assert_eq!(statement.kind(), SyntaxKind::IF_STMT);
    let jump = statement.children().find(|n| n.kind() == SyntaxKind::GOTO_STMT).unwrap();
    assert_eq!(jump.to_string(), "GOTOF LABEL");
}

#[test]
fn a_long_line_is_read_up_to_the_limit() {
    let line = "X1 ".repeat(400_000);
    let text = format!("{line}\nG0 X1\n");
    let parts = parse(&text);
    let root = root(&parts);
    assert_eq!(root.to_string(), text);
    assert!(root.descendants_with_tokens().count() < 3_000);
    assert!(parts.errors().iter().any(|e| e.kind == SyntaxErrorKind::LineTooLong));
}

#[test]
fn deep_nesting_is_bounded() {
    for text in [
        "R1=".to_owned() + &"(".repeat(5000),
        "R1=".to_owned() + &"-".repeat(5000) + "1",
        "R1=".to_owned() + &"A[".repeat(3000),
        "R1=".to_owned() + &"SIN(".repeat(3000),
        "R1=".to_owned() + &"NOT ".repeat(3000),
    ] {
        assert_eq!(root(&parse(&text)).to_string(), text);
    }
}

/// Fragments of Sinumerik programs, valid or not.
const FRAGMENTS: &[&str] = &[
    "G01 ",
    "X-12.5",
    "X=R1+5 ",
    "R1",
    "R[R2+1]",
    "=",
    " ",
    "\n",
    "\r\n",
    "\r",
    "(",
    ")",
    "[",
    "]",
    ",",
    ":",
    ";c",
    "\"",
    "\"TEXT\"",
    "%_N_A_MPF",
    "N10 ",
    ":20 ",
    "/",
    "/1",
    "LABEL:",
    "IF R1==2 GOTOF LABEL",
    "ELSE",
    "ENDIF",
    "WHILE ",
    "ENDWHILE",
    "FOR I=1 TO 3",
    "CASE R1 OF 1 GOTOF L1 DEFAULT GOTOB N10",
    "DEF STRING[20] S=\"x\"",
    "DEF INT A[2,3]",
    "PROC P(VAR REAL X[2]) SAVE",
    "EXTERN P(REAL)",
    "MSG(\"a\"<<R1)",
    "SIN(30)",
    "$AA_IM[X]",
    "CYCLE81(,1,2)",
    "<<",
    "<>",
    "AND",
    "NOT",
    "*",
    "-",
    "+",
    "7.75.",
    "..",
    "1EX3",
    "é",
    "\u{feff}",
    "#",
    "'",
    "WHEN R1>1 DO M7",
];

/// Statements that are valid wherever they stand in a block.
fn valid_statement() -> impl Strategy<Value = String> {
    let number = (-9999i32..9999, 0u32..1000).prop_map(|(int, frac)| format!("{int}.{frac}"));
    let name = "[A-Z][A-Z_][A-Z0-9_]{0,6}".prop_filter("not a keyword", |name| !is_keyword(name));
    let expr = expression();
    prop_oneof![
        ("[XYZABCUVW]", number.clone()).prop_map(|(a, n)| format!("{a}{n}")),
        ("[GMSFTD]", 0u32..1000).prop_map(|(a, n)| format!("{a}{n}")),
        ("[XYZ]", expr.clone()).prop_map(|(a, e)| format!("{a}={e}")),
        ("[ABC]", 1u32..6, expr.clone()).prop_map(|(a, n, e)| format!("{a}{n}={e}")),
        (0u32..100, expr.clone()).prop_map(|(n, e)| format!("R{n}={e}")),
        (expr.clone(), expr.clone()).prop_map(|(i, e)| format!("R[{i}]={e}")),
        (name.clone(), expr.clone(), expr.clone()).prop_map(|(n, i, e)| format!("{n}[{i},1]={e}")),
        (name.clone(), prop::collection::vec(prop::option::of(expr.clone()), 0..4)).prop_map(|(n, args)| format!(
            "{n}({})",
            args.into_iter().map(Option::unwrap_or_default).collect::<Vec<_>>().join(",")
        )),
        name.clone(),
        expr.clone().prop_map(|e| format!("MSG(\"v\"<<{e})")),
        expr.clone().prop_map(|e| format!("IF {e}")),
        (expr.clone(), name.clone()).prop_map(|(e, n)| format!("IF {e} GOTOF {n}")),
        expr.clone().prop_map(|e| format!("WHILE {e}")),
        (name.clone(), expr.clone(), expr.clone()).prop_map(|(n, a, b)| format!("FOR {n}={a} TO {b}")),
        (expr.clone(), 0u32..9, name.clone())
            .prop_map(|(e, k, n)| format!("CASE {e} OF {k} GOTOF {n} DEFAULT GOTOB N{k}")),
        Just("ELSE".to_owned()),
        Just("ENDIF".to_owned()),
        Just("ENDWHILE".to_owned()),
        Just("REPEAT".to_owned()),
        (name.clone(), 1u32..9).prop_map(|(n, k)| format!("DEF REAL {n}[{k},2]={k}")),
        (name.clone(), 1u32..40).prop_map(|(n, k)| format!("DEF STRING[{k}] {n}=\"x\"")),
        (name.clone(), 1u32..4).prop_map(|(n, k)| format!("DEF INT {n}[{k}]=(1,2,3)")),
        name.clone().prop_map(|n| format!("DEFINE {n} AS M8 $A_DBB[1]")),
        name.clone().prop_map(|n| format!("CALL \"_N_{n}_SPF\"")),
        (1u32..9, expr.clone()).prop_map(|(k, e)| format!("IDS={k} DO $$AC_PARAM[{k}]={e}")),
        name.prop_map(|n| format!("L10({n}) M6({n},1)")),
    ]
}

fn is_keyword(name: &str) -> bool {
    [
        "IF", "ELSE", "ENDIF", "WHILE", "ENDWHILE", "FOR", "ENDFOR", "REPEAT", "UNTIL", "LOOP", "ENDLOOP", "CASE",
        "OF", "DEFAULT", "TO", "DO", "BLOCK", "GOTO", "GOTOF", "GOTOB", "GOTOC", "GOTOS", "DEF", "PROC", "EXTERN",
        "WHEN", "WHENEVER", "EVERY", "FROM", "MCALL", "AND", "OR", "XOR", "NOT", "DIV", "MOD", "B_AND", "B_OR",
        "B_XOR", "B_NOT", "VAR", "INT", "REAL", "BOOL", "CHAR", "STRING", "AXIS", "FRAME", "AS", "DEFINE", "CALL",
        "PCALL",
    ]
    .contains(&name)
}

fn expression() -> BoxedStrategy<String> {
    let leaf = prop_oneof![
        (0u32..1000).prop_map(|n| n.to_string()),
        (0u32..100).prop_map(|n| format!("R{n}")),
        Just("$P_F".to_owned()),
        Just("$AA_IM[X]".to_owned()),
        Just("\"N\"".to_owned()),
        Just("TRUE".to_owned()),
        Just("X1".to_owned()),
    ];
    leaf.prop_recursive(4, 24, 3, |inner| {
        let op = prop::sample::select(vec!["+", "-", "*", "/", "<<", "==", "<>", "<=", ">", " AND ", " OR ", " MOD "]);
        prop_oneof![
            (inner.clone(), op, inner.clone()).prop_map(|(a, op, b)| format!("{a}{op}{b}")),
            inner.clone().prop_map(|a| format!("({a})")),
            inner.clone().prop_map(|a| format!("-{a}")),
            inner.clone().prop_map(|a| format!("NOT {a}")),
            inner.clone().prop_map(|a| format!("<<{a}")),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("CTRANS(X,{a}):CROT(Z,{b})")),
            inner.clone().prop_map(|a| format!("SIN({a})")),
            (inner.clone(), inner).prop_map(|(a, b)| format!("ATAN2({a},{b})")),
        ]
    })
    .boxed()
}

/// A valid program: a `PROC` line, and blocks of an optional skip,
/// number and label, then statements and a comment.
fn valid_program() -> impl Strategy<Value = String> {
    let name = || "[A-Z][A-Z_][A-Z0-9_]{0,6}".prop_filter("not a keyword", |name| !is_keyword(name));
    let proc_line =
        prop::option::of((name(), name()).prop_map(|(p, n)| format!("PROC {p}(REAL {n}, VAR INT B[2]) SAVE\n")));
    let block = (
        prop::option::of(prop::sample::select(vec!["/", "/1 "])),
        prop::option::of((0u32..10000).prop_map(|n| format!("N{n} "))),
        prop::option::of(name().prop_map(|n| format!("{n}: "))),
        prop::collection::vec(valid_statement(), 0..4),
        prop::option::of(".*".prop_map(|c: String| format!(" ;{}", c.replace(['\n', '\r'], "")))),
    )
        .prop_map(|(skip, number, label, statements, comment)| {
            format!(
                "{}{}{}{}{}\n",
                skip.unwrap_or_default(),
                number.unwrap_or_default(),
                label.unwrap_or_default(),
                statements.join(" "),
                comment.unwrap_or_default()
            )
        });
    (proc_line, prop::collection::vec(block, 0..20))
        .prop_map(|(proc_line, blocks)| proc_line.unwrap_or_default() + &blocks.concat())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn any_string_round_trips(text in any::<String>()) {
        assert_well_formed(&text, &parse(&text));
    }

    #[test]
    fn sinumerik_like_text_round_trips(text in glued(FRAGMENTS)) {
        assert_well_formed(&text, &parse(&text));
    }

    #[test]
    fn valid_programs_parse_without_errors(text in valid_program()) {
        let parts = parse(&text);
        assert_well_formed(&text, &parts);
        prop_assert!(parts.errors().is_empty(), "{}", parts.debug_dump());
    }

    #[test]
    fn reparse_equals_full_parse(
        text in prop_oneof![glued(FRAGMENTS), valid_program(), any::<String>()],
        start in 0usize..2000,
        len in 0usize..12,
        insert in insertion(FRAGMENTS),
    ) {
        line_dialects::reparse_equals_full_parse(Dialect::Sinumerik, &text, start, len, insert)?;
    }
}
