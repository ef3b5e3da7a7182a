//! Document symbols, folding, semantic highlighting and find references.
//! `$0` in a program marks the cursor.

#[path = "../../syntax/tests/strategies/mod.rs"]
mod strategies;

use expect_test::{Expect, expect};
use ncc_analysis::{
    Analysis, AnalysisHost, Config, Dialect, DocumentSymbol, FileId, HighlightKind, RootDatabase, TextEdit, TextRange,
    TextSize,
};
use proptest::prelude::*;
use strategies::{block_program, crowded_lines, overlong_lines, program_text};

/// A partprogram with subprograms, jumps, parameters and Czech comments.
const PROGRAM: &str = "%100 \"DÍL – ČEP Ø20\"
\" NULOVÝ BOD: STŘED ČELA
\" NÁSTROJ T1 VRTÁK Ø8
N10 G90 G17 G54 R12=5. R13=-2.5 \"začátek\"
N20 G00 X0 Y0 ZR12 S1200 M03
N30 G01 X-R13 F100
N40 G71 L100 Q2
N50 G91 X1.
N60 G73 L50 Q3
N70 G71 L100
N80 M30
\" podprogram drážky
N100 G79 L100 \"DRÁŽKA\"
N110 G01 ZR13 R12=R13
N120 G73 L110 Q1
N130 G70
\" NÁVRAT DO VÝCHOZÍ POLOHY
N200 G79 L200
N210 G70
*
";

const MACROCYCLE: &str = "N1 G79 L9001 \"VRTÁNÍ ŘADY\"
\" R20 = ROZTEČ
\" R21 = POČET
N2 G01 ZR20
N3 G73 L2 Q3
N4 G70
*
";

const CYCLE_FILE: &str = "\"  $PC - PEVNÉ CYKLY
N1 G79 L81 \"VRTÁNÍ\"
N2 G01 ZR31 FR26
N3 G00 ZR32 G70
N1 G79 L82
N2 G04 QR28
N3 G70
*
";

/// The host with `files` added, the ids, and the cursor (file, offset) if
/// one of them has `$0`.
/// A host in the dialect the first file's name gives, with the files.
fn setup(files: &[(&str, &str)]) -> (AnalysisHost, Vec<FileId>, Option<(FileId, TextSize)>) {
    let dialect =
        files.first().and_then(|(path, _)| Dialect::by_default_for(std::path::Path::new(path))).unwrap_or_default();
    let mut host = AnalysisHost::in_dialect(dialect, Config::default());
    let mut cursor = None;
    let mut ids = Vec::new();
    for (path, text) in files {
        let offset = text.find("$0");
        let id = host.add_file(*path, text.replace("$0", ""));
        if let Some(offset) = offset {
            cursor = Some((id, TextSize::try_from(offset).unwrap()));
        }
        ids.push(id);
    }
    (host, ids, cursor)
}

/// A range's text; its first and last line if it spans several.
fn show(text: &str, range: TextRange) -> String {
    let shown = &text[range];
    match (shown.lines().next(), shown.lines().last()) {
        (Some(first), Some(last)) if shown.contains('\n') => format!("`{first}` … `{last}`"),
        _ => format!("`{shown}`"),
    }
}

fn check_symbols(path: &str, text: &str, expect: Expect) {
    fn render(analysis: &Analysis, file: FileId, symbols: &[DocumentSymbol], depth: usize, out: &mut String) {
        let text = analysis.text(file);
        for symbol in symbols {
            assert!(symbol.range.contains_range(symbol.selection_range), "{symbol:?}");
            let detail = symbol.detail.as_deref().map(|d| format!(" ({d})")).unwrap_or_default();
            out.push_str(&format!(
                "{}{:?} {}{detail}: {} select {}\n",
                "  ".repeat(depth),
                symbol.kind,
                symbol.name,
                show(&text, symbol.range),
                show(&text, symbol.selection_range),
            ));
            for child in &symbol.children {
                assert!(symbol.range.contains_range(child.range), "{child:?} outside {symbol:?}");
            }
            render(analysis, file, &symbol.children, depth + 1, out);
        }
    }
    let (host, ids, _) = setup(&[(path, text)]);
    let analysis = host.analysis();
    let mut out = String::new();
    render(&analysis, ids[0], &analysis.document_symbols(ids[0]), 0, &mut out);
    expect.assert_eq(&out);
}

fn check_folds(path: &str, text: &str, expect: Expect) {
    let (host, ids, _) = setup(&[(path, text)]);
    let analysis = host.analysis();
    let folds: Vec<String> = analysis
        .folding_ranges(ids[0])
        .iter()
        .map(|fold| format!("{:?} {}", fold.kind, show(text, fold.range)))
        .collect();
    expect.assert_eq(&folds.join("\n"));
}

/// Each line with its highlighted pieces, `text:kind`.
fn check_highlight(path: &str, text: &str, expect: Expect) {
    let (host, ids, _) = setup(&[(path, text)]);
    let dialect = host.analysis().dialect();
    let ranges = host.analysis().highlight(ids[0]);
    let mut out = String::new();
    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        let line_end = line_start + line.len();
        let pieces: Vec<String> = ranges
            .iter()
            .filter(|h| (line_start..line_end).contains(&usize::from(h.range.start())))
            .map(|h| format!("{}:{}", &text[h.range], short(h.kind, dialect)))
            .collect();
        out.push_str(&format!("{}\n", pieces.join(" ")));
        line_start = line_end;
    }
    expect.assert_eq(&out);
}

fn short(kind: HighlightKind, dialect: Dialect) -> String {
    match kind {
        HighlightKind::Code { letter, group } => {
            let groups = &dialect.catalogue().groups;
            format!("{}{}", char::from(letter), group.map_or("?", |g| groups[usize::from(g)].id.as_str()))
        }
        HighlightKind::Address(role) => format!("{role:?}"),
        HighlightKind::Parameter { write: true } => "write".to_owned(),
        HighlightKind::Parameter { write: false } => "read".to_owned(),
        other => format!("{other:?}"),
    }
}

fn check_references(files: &[(&str, &str)], include_declaration: bool, expect: Expect) {
    expect.assert_eq(&references(files, include_declaration));
}

/// References as `path:line:column: text kind`, one per line.
fn references(files: &[(&str, &str)], include_declaration: bool) -> String {
    let (host, _, cursor) = setup(files);
    let (file, offset) = cursor.expect("a `$0` cursor");
    let analysis = host.analysis();
    let found: Vec<String> = analysis
        .references(file, offset, include_declaration)
        .iter()
        .map(|r| {
            let text = analysis.text(r.file);
            let before = &text[..usize::from(r.range.start())];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().unwrap_or_default().chars().count() + 1;
            format!("{}:{line}:{column}: {} {:?}", analysis.path(r.file), &text[r.range], r.kind)
        })
        .collect();
    found.join("\n")
}

fn at(text: &str, needle: &str) -> String {
    let at = text.find(needle).unwrap_or_else(|| panic!("`{needle}` in the program"));
    format!("{}$0{}", &text[..at], &text[at..])
}

#[test]
fn symbols_of_a_program_with_subprograms_and_jumps() {
    check_symbols(
        "PART.NCP",
        PROGRAM,
        expect![[r#"
            Program %100 (DÍL – ČEP Ø20): `%100 "DÍL – ČEP Ø20"` … `N80 M30` select `%100`
              JumpTarget N50 (jumped to from N60): `N50 G91 X1.` select `N50`
            Subprogram L100 (DRÁŽKA · called 2×): `N100 G79 L100 "DRÁŽKA"` … `N130 G70` select `L100`
              JumpTarget N110 (jumped to from N120): `N110 G01 ZR13 R12=R13` select `N110`
            Subprogram L200 (NÁVRAT DO VÝCHOZÍ POLOHY · not called): `N200 G79 L200` … `N210 G70` select `L200`
        "#]],
    );
}

#[test]
fn symbols_of_a_program_without_header() {
    check_symbols(
        "dir/PART.NCP",
        "N10 G00 X0\nN20 M30\n",
        expect![[r#"
        Program PART: `N10 G00 X0` … `N20 M30` select `N10`
    "#]],
    );
}

#[test]
fn symbols_of_a_macrocycle_file() {
    check_symbols(
        "macros/L9001",
        MACROCYCLE,
        expect![[r#"
        Macrocycle L9001 (VRTÁNÍ ŘADY): `N1 G79 L9001 "VRTÁNÍ ŘADY"` … `N4 G70` select `L9001`
          JumpTarget N2 (jumped to from N3): `N2 G01 ZR20` select `N2`
    "#]],
    );
}

#[test]
fn symbols_of_a_cycle_file() {
    check_symbols(
        "PCYKLY.NCP",
        CYCLE_FILE,
        expect![[r#"
        CycleBody L81 (VRTÁNÍ): `N1 G79 L81 "VRTÁNÍ"` … `N3 G00 ZR32 G70` select `L81`
        CycleBody L82: `N1 G79 L82` … `N3 G70` select `L82`
    "#]],
    );
}

#[test]
fn folds_units_and_comment_runs() {
    check_folds(
        "PART.NCP",
        PROGRAM,
        expect![[r#"
        Region `%100 "DÍL – ČEP Ø20"` … `N80 M30`
        Comment `" NULOVÝ BOD: STŘED ČELA` … `" NÁSTROJ T1 VRTÁK Ø8`
        Region `N100 G79 L100 "DRÁŽKA"` … `N130 G70`
        Region `N200 G79 L200` … `N210 G70`"#]],
    );
    check_folds(
        "macros/L9001",
        MACROCYCLE,
        expect![[r#"
        Region `N1 G79 L9001 "VRTÁNÍ ŘADY"` … `N4 G70`
        Comment `" R20 = ROZTEČ` … `" R21 = POČET`"#]],
    );
}

#[test]
fn a_single_comment_line_or_a_one_line_unit_does_not_fold() {
    check_folds(
        "PART.NCP",
        "%1 \"A\"\n\" one\nN10 M30 \"x\"\n\" two\n\n\" three\n",
        expect![[r#"Region `%1 "A"` … `N10 M30 "x"`"#]],
    );
}

#[test]
fn highlight_a_program() {
    check_highlight(
        "PART.NCP",
        PROGRAM,
        expect![[r#"
            %:Keyword 100:Number "DÍL – ČEP Ø20":Comment
            " NULOVÝ BOD: STŘED ČELA:Comment
            " NÁSTROJ T1 VRTÁK Ø8:Comment
            N10:BlockNumber G90:GG9 G17:GG1 G54:GG5 R12:write =:Operator 5.:Number R13:write =:Operator -2.5:Number "začátek":Comment
            N20:BlockNumber G00:GG0 X:Axis 0:Number Y:Axis 0:Number Z:Axis R12:read S:Speed 1200:Number M03:MM2
            N30:BlockNumber G01:GG0 X:Axis -:Operator R13:read F:Feed 100:Number
            N40:BlockNumber G71:GG7 L:Label 100:Number Q:Count 2:Number
            N50:BlockNumber G91:GG9 X:Axis 1.:Number
            N60:BlockNumber G73:GG7 L:Label 50:Number Q:Count 3:Number
            N70:BlockNumber G71:GG7 L:Label 100:Number
            N80:BlockNumber M30:MM1
            " podprogram drážky:Comment
            N100:BlockNumber G79:GG7 L:Label 100:Number "DRÁŽKA":Comment
            N110:BlockNumber G01:GG0 Z:Axis R13:read R12:write =:Operator R13:read
            N120:BlockNumber G73:GG7 L:Label 110:Number Q:Count 1:Number
            N130:BlockNumber G70:GG7
            " NÁVRAT DO VÝCHOZÍ POLOHY:Comment
            N200:BlockNumber G79:GG7 L:Label 200:Number
            N210:BlockNumber G70:GG7
            *:Keyword
        "#]],
    );
}

#[test]
fn highlight_a_cycle_file() {
    check_highlight(
        "PCYKLY.NCP",
        CYCLE_FILE,
        expect![[r#"
        ":Comment $PC:Keyword - PEVNÉ CYKLY:Comment
        N1:BlockNumber G79:GG7 L:Label 81:Number "VRTÁNÍ":Comment
        N2:BlockNumber G01:GG0 Z:Axis R31:read F:Feed R26:read
        N3:BlockNumber G00:GG0 Z:Axis R32:read G70:GG7
        N1:BlockNumber G79:GG7 L:Label 82:Number
        N2:BlockNumber G04:GG10 Q:Count R28:read
        N3:BlockNumber G70:GG7
        *:Keyword
    "#]],
    );
}

#[test]
fn highlight_errors_and_unusual_words() {
    let text = "leader\n%1\nN10 G01 X10 # Y5 g1.5 M99 O5 G 01\n/1 N20 R1 = 5 MSG R2=R3 GR4 =\nN30 X - 5 ,5\n* \"end\" never read\n";
    check_highlight(
        "ODD.NCP",
        text,
        expect![[r#"
        leader:Comment
        %:Keyword 1:Number
        N10:BlockNumber G01:GG0 X:Axis 10:Number #:Error Y:Axis 5:Number g1.5:G? M99:MM14 O:UnknownAddress 5:Number G:GG0 01:GG0
        /:Keyword 1:Number N20:BlockNumber R1:write =:Operator 5:Number MSG:Error R2:write =:Operator R3:read G:G? R4:write =:Operator
        N30:BlockNumber X:Axis -:Number 5:Number ,:Error 5:Error
        *:Keyword "end":Comment never read:Comment
    "#]],
    );
}

#[test]
fn highlight_range_takes_the_blocks_that_touch_it() {
    let (host, ids, _) = setup(&[("PART.NCP", PROGRAM)]);
    let analysis = host.analysis();
    let all = analysis.highlight(ids[0]);
    let start = PROGRAM.find("N30").unwrap();
    let end = PROGRAM.find("N50").unwrap() - 3;
    let range = TextRange::new(TextSize::try_from(start).unwrap(), TextSize::try_from(end).unwrap());
    let visible = analysis.highlight_range(ids[0], range);
    let shown: Vec<&str> = visible.iter().map(|h| &PROGRAM[h.range]).collect();
    assert_eq!(shown, ["N30", "G01", "X", "-", "R13", "F", "100", "N40", "G71", "L", "100", "Q", "2"]);
    assert!(visible.iter().all(|h| all.contains(h)));
}

#[test]
fn references_of_a_subprogram() {
    let from_call = references(&[("PART.NCP", &at(PROGRAM, "L100 Q2"))], true);
    expect![[r#"
        PART.NCP:13:10: L100 Definition
        PART.NCP:7:9: L100 Call
        PART.NCP:10:9: L100 Call"#]]
    .assert_eq(&from_call);
    assert_eq!(references(&[("PART.NCP", &at(PROGRAM, "G79 L100"))], true), from_call);
    assert_eq!(references(&[("PART.NCP", &at(PROGRAM, "71 L100 Q2"))], true), from_call);
    check_references(
        &[("PART.NCP", &at(PROGRAM, "L100 Q2"))],
        false,
        expect![[r#"
        PART.NCP:7:9: L100 Call
        PART.NCP:10:9: L100 Call"#]],
    );
}

#[test]
fn references_of_a_macrocycle_across_files() {
    let caller = "%2\nN10 G72 L9001\nN20 G72 L9001 Q2\nN30 M30\n*\n";
    let other = "%3\nN10 G72 L9001\nN20 M30\n*\n";
    let from_call =
        references(&[("A.NCP", &at(caller, "L9001 Q2")), ("B.NCP", other), ("macros/L9001", MACROCYCLE)], true);
    expect![[r#"
        macros/L9001:1:8: L9001 Definition
        A.NCP:2:9: L9001 Call
        A.NCP:3:9: L9001 Call
        B.NCP:2:9: L9001 Call"#]]
    .assert_eq(&from_call);
    let from_definition =
        references(&[("A.NCP", caller), ("B.NCP", other), ("macros/L9001", &at(MACROCYCLE, "L9001"))], true);
    assert_eq!(from_definition, from_call);
}

#[test]
fn references_of_a_jump_target() {
    let from_target = references(&[("PART.NCP", &at(PROGRAM, "N110"))], true);
    expect![[r#"
        PART.NCP:14:1: N110 Definition
        PART.NCP:15:10: L110 Jump"#]]
    .assert_eq(&from_target);
    assert_eq!(references(&[("PART.NCP", &at(PROGRAM, "L110"))], true), from_target);
    // The subprogram's `G73 L50` cannot reach N50 of the main body.
    let text = PROGRAM.replace("L110 Q1", "L50 Q1");
    check_references(
        &[("PART.NCP", &at(&text, "N50"))],
        true,
        expect![[r#"
        PART.NCP:8:1: N50 Definition
        PART.NCP:9:9: L50 Jump"#]],
    );
}

#[test]
fn references_of_a_parameter() {
    let from_read = references(&[("PART.NCP", &at(PROGRAM, "R13 F100"))], true);
    expect![[r#"
        PART.NCP:4:24: R13 Write
        PART.NCP:6:11: R13 Read
        PART.NCP:14:11: R13 Read
        PART.NCP:14:19: R13 Read"#]]
    .assert_eq(&from_read);
    assert_eq!(references(&[("PART.NCP", &at(PROGRAM, "R13=-2.5"))], true), from_read);
}

#[test]
fn references_of_a_control_word_include_the_arithmetic_that_runs_it() {
    let text = "%1\nN10 R20=5. R21=5\nN20 G29 R5=-42210226 R6=-42210127\n R7=-03272027 R8=08270027\nN30 G26 $0R5=48110095\nN40 M30\n*\n";
    check_references(
        &[("PART.NCP", text)],
        true,
        expect![[r#"
        PART.NCP:3:5: G29 Read
        PART.NCP:3:9: R5 Write
        PART.NCP:5:5: G26 Read
        PART.NCP:5:9: R5 Write"#]],
    );
}

#[test]
fn no_references_on_other_words() {
    check_references(&[("PART.NCP", &at(PROGRAM, "G90"))], true, expect![""]);
    check_references(&[("PART.NCP", &at(PROGRAM, "DÍL"))], true, expect![""]);
}

#[test]
fn highlighting_computes_nothing_and_references_relower_one_chunk_after_an_edit() {
    let mut text = String::from("%1\nN1 R12=5.\n");
    for n in 2..5000 {
        text.push_str(&format!("N{n} G01 X{n}. ZR12\n"));
    }
    text.push_str("N5000 M30\n*\n");
    let mut host = AnalysisHost::with_database(RootDatabase::with_execution_log(), Dialect::Cnc8x6, Config::default());
    let file = host.add_file("main.NCP", text.as_str());
    host.analysis().highlight(file);
    assert_eq!(host.db().take_executions(), Vec::<String>::new(), "highlighting reads the tree only");

    let cursor = TextSize::try_from(text.find("R12=").unwrap()).unwrap();
    assert_eq!(host.analysis().references(file, cursor, true).len(), 4999);
    let chunks = host.db().take_executions().iter().filter(|e| e.starts_with("chunk_parameter_uses")).count();
    assert!(chunks > 5, "a program of 5000 blocks has several chunks: {chunks}");

    let at = TextSize::try_from(text.find("N2500 G01 X2500.").unwrap() + "N2500 G01 X2".len()).unwrap();
    host.apply_edit(file, &TextEdit::replace(TextRange::at(at, TextSize::from(1)), "6"));
    assert_eq!(host.analysis().references(file, cursor, true).len(), 4999);
    let executions = host.db().take_executions();
    let chunks = executions.iter().filter(|e| e.starts_with("chunk_parameter_uses")).count();
    assert_eq!(chunks, 1, "only the edited chunk is lowered again: {executions:#?}");
}

/// Checks that the highlighting of `text` is well formed, and that of the
/// blocks around `start..end` is part of it.
fn check_highlight_ranges(path: &str, text: &str, start: usize, end: usize) {
    let mut host = AnalysisHost::default();
    let file = host.add_file(path, text);
    let analysis = host.analysis();
    let ranges = analysis.highlight(file);
    let kinds = HighlightKind::all(Dialect::Cnc8x6);
    let mut previous_end = 0;
    for highlight in &ranges {
        let range = std::ops::Range::<usize>::from(highlight.range);
        assert!(range.start >= previous_end && range.start < range.end && range.end <= text.len(), "{highlight:?}");
        assert!(text.is_char_boundary(range.start) && text.is_char_boundary(range.end), "{highlight:?}");
        let piece = &text[range.clone()];
        assert!(!piece.contains(['\n', '\r']), "{piece:?}");
        assert!(!piece.starts_with([' ', '\t']) && !piece.ends_with([' ', '\t']), "{piece:?}");
        assert!(kinds.contains(&highlight.kind), "{:?} is not listed", highlight.kind);
        previous_end = range.end;
    }
    let boundary = |at: usize| (0..=at.min(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
    let (start, end) = (boundary(start), boundary(end));
    let within = TextRange::new(TextSize::try_from(start).unwrap(), TextSize::try_from(end.max(start)).unwrap());
    for highlight in analysis.highlight_range(file, within) {
        assert!(ranges.contains(&highlight), "{highlight:?}");
    }
}

#[test]
fn odd_input_gives_well_formed_answers() {
    for text in ["", "%", "\u{b}", "\"NN\r\n\"$PC N", "$PC\"\"\"  ", "\u{201E}  ", "\"  $PC\nN1 X1\n\"  \n"] {
        check_highlight_ranges("P.NCP", text, 0, 0);
        let (host, ids, _) = setup(&[("P.NCP", text)]);
        let analysis = host.analysis();
        assert!(analysis.document_symbols(ids[0]).iter().all(|s| s.range.contains_range(s.selection_range)));
        assert!(analysis.folding_ranges(ids[0]).iter().all(|f| usize::from(f.range.end()) <= text.len()));
    }
}

/// Program text, sometimes a fixed-cycle file's (`$PC` before the blocks).
fn any_program() -> impl Strategy<Value = String> {
    let text = prop_oneof![program_text(), block_program(), crowded_lines(), overlong_lines()];
    (text, prop::bool::ANY).prop_map(|(text, cycles)| if cycles { format!("\"  $PC \"\n{text}") } else { text })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn highlight_ranges_are_sorted_disjoint_and_on_char_boundaries(
        text in any_program(),
        path in prop_oneof![Just("P.NCP"), Just("L9001")],
        start in 0usize..400,
        len in 0usize..100,
    ) {
        check_highlight_ranges(path, &text, start, start + len);
    }

    /// Diagnostics after an edit equal a fresh analysis's, on lines with
    /// more findings than a report shows too.
    #[test]
    fn edited_diagnostics_equal_a_fresh_analysis(
        text in any_program(),
        start in 0usize..400,
        len in 0usize..12,
        insert in prop_oneof![Just(""), Just("X "), Just("\n"), Just("N7 "), Just("1 2 3"), Just("\"")],
    ) {
        let boundary = |at: usize| (0..=at.min(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
        let (start, end) = (boundary(start), boundary(start + len));
        let edit = TextEdit::replace(TextRange::new(TextSize::try_from(start).unwrap(), TextSize::try_from(end).unwrap()), insert);
        let mut host = AnalysisHost::default();
        let file = host.add_file("P.NCP", text.as_str());
        host.analysis().diagnostics(file);
        host.apply_edit(file, &edit);
        let mut edited = text.clone();
        edit.apply(&mut edited);
        let mut fresh = AnalysisHost::default();
        let fresh_file = fresh.add_file("P.NCP", edited.as_str());
        prop_assert_eq!(host.analysis().diagnostics(file), fresh.analysis().diagnostics(fresh_file));
    }

    #[test]
    fn other_answers_never_panic(text in any_program(), at in 0usize..400) {
        let mut host = AnalysisHost::default();
        let file = host.add_file("P.NCP", text.as_str());
        let analysis = host.analysis();
        let at = (0..=at.min(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap();
        analysis.document_symbols(file);
        for fold in analysis.folding_ranges(file) {
            prop_assert!(usize::from(fold.range.end()) <= text.len());
        }
        for reference in analysis.references(file, TextSize::try_from(at).unwrap(), true) {
            prop_assert!(text.is_char_boundary(usize::from(reference.range.start())));
        }
    }
}

/// A Haas lathe program with a contour, a local subprogram, a loop, a call
/// of another program and a jump.
const LATHE: &str = "%
O1000 (SHAFT)
(ROUGHING)
(OD TOOL)
T0101 (ROUGH OD)
G50 S3000
G96 S200 M03
G00 X60. Z2.
G71 P10 Q20 U0.4 W0.1 D2. F0.25
N10 G00 X20.
G01 Z-20. ,C1.
N20 X60.
G70 P10 Q20
T0202 (GROOVE)
#1 = 0
WHILE [#1 LT 3] DO1
G01 U-[#1 * 2.] F0.1
#1 = #1 + 1
END1
M97 P100
M98 P2000
GOTO 30
N30 M30
N100 G04 P500
M99
%
";

#[test]
fn symbols_of_a_lathe_program() {
    check_symbols(
        "O1000.nc",
        LATHE,
        expect![[r#"
            Program O1000 (SHAFT): `O1000 (SHAFT)` … `M99` select `O1000`
              Tool T0101 (ROUGH OD): `T0101 (ROUGH OD)` select `T0101`
              JumpTarget N10: `N10 G00 X20.` select `N10`
              JumpTarget N20: `N20 X60.` select `N20`
              Tool T0202 (GROOVE): `T0202 (GROOVE)` select `T0202`
              JumpTarget N30: `N30 M30` select `N30`
              JumpTarget N100: `N100 G04 P500` select `N100`
        "#]],
    );
}

#[test]
fn folds_lathe_programs_contours_loops_and_comments() {
    check_folds(
        "O1000.nc",
        LATHE,
        expect![[r#"
            Region `O1000 (SHAFT)` … `M99`
            Comment `(ROUGHING)` … `(OD TOOL)`
            Region `N10 G00 X20.` … `N20 X60.`
            Region `WHILE [#1 LT 3] DO1` … `END1`"#]],
    );
}

#[test]
fn highlight_a_lathe_program() {
    let text =
        "%\nO1000 (SHAFT)\n#1 = #[#2 + 1] * SIN[30.]\nIF [#1 GT 2.] GOTO 20\nN20 G01 X-#1 Z[#1 / 2.] ,C1. F0.1\n%\n";
    check_highlight(
        "O1000.nc",
        text,
        expect![[r#"
            %:Keyword
            O:Keyword 1000:Number (SHAFT):Comment
            #1:write =:Operator #:read [:Operator #2:read +:Operator 1:Number ]:Operator *:Operator SIN:Keyword [:Operator 30.:Number ]:Operator
            IF:Keyword [:Operator #1:read GT:Operator 2.:Number ]:Operator GOTO:Keyword 20:Number
            N20:BlockNumber G01:GG1 X:Axis -:Operator #1:read Z:Axis [:Operator #1:read /:Operator 2.:Number ]:Operator ,:Operator C:Axis 1.:Number F:Feed 0.1:Number
            %:Keyword
        "#]],
    );
}

#[test]
fn lathe_references_and_definitions_follow_p_q_m97_m98_and_goto() {
    let files =
        |cursor: &str| vec![("O1000.nc", at(LATHE, cursor)), ("O2000.nc", "O2000 (SUB)\nG00 U2.\nM99\n".to_owned())];
    let refs = |cursor: &str| {
        let files = files(cursor);
        let borrowed: Vec<(&str, &str)> = files.iter().map(|(p, t)| (*p, t.as_str())).collect();
        references(&borrowed, true)
    };
    expect![[r#"
        O1000.nc:10:1: N10 Definition
        O1000.nc:9:5: P10 Jump
        O1000.nc:13:5: P10 Jump"#]]
    .assert_eq(&refs("N10"));
    assert_eq!(refs("P10 Q20 U"), refs("N10"));
    expect!["O1000.nc:24:1: N100 Definition\nO1000.nc:20:5: P100 Call"].assert_eq(&refs("N100"));
    let definition = |cursor: &str| {
        let files = files(cursor);
        let borrowed: Vec<(&str, &str)> = files.iter().map(|(p, t)| (*p, t.as_str())).collect();
        let (host, _, cursor) = setup(&borrowed);
        let (file, offset) = cursor.unwrap();
        let analysis = host.analysis();
        let targets = analysis.goto_definition(file, offset);
        targets
            .iter()
            .map(|t| format!("{} {}", analysis.path(t.file), show(&analysis.text(t.file), t.focus)))
            .collect::<Vec<_>>()
    };
    assert_eq!(definition("Q20 U"), ["O1000.nc `N20`"]);
    assert_eq!(definition("P100"), ["O1000.nc `N100`"]);
    assert_eq!(definition("P2000"), ["O2000.nc `O2000`"]);
    assert_eq!(definition("GOTO 30"), ["O1000.nc `N30`"]);
}

#[test]
fn lathe_hover_names_the_contour_block_and_the_variable() {
    let (host, ids, cursor) = setup(&[("O1000.nc", &at(LATHE, "P10 Q20 U"))]);
    let analysis = host.analysis();
    let hover = analysis.hover(ids[0], cursor.unwrap().1).unwrap().markdown;
    assert!(hover.starts_with("The contour's first block: line 10, `N10 G00 X20.`."), "{hover}");
    let (host, ids, cursor) = setup(&[("O1000.nc", &at(LATHE, "#1 LT"))]);
    let hover = host.analysis().hover(ids[0], cursor.unwrap().1 + TextSize::from(1)).unwrap().markdown;
    assert!(hover.contains("macro variable") || hover.contains("Macro variable"), "{hover}");
    let (host, ids, cursor) = setup(&[("O1000.nc", &at(LATHE, "G71"))]);
    let hover = host.analysis().hover(ids[0], cursor.unwrap().1).unwrap().markdown;
    assert!(hover.starts_with("### G71"), "{hover}");
}

/// Every editor question at every offset of the manual's examples answers
/// without a panic.
#[test]
fn every_lathe_example_answers_everywhere() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../syntax/test_data/haas-lathe");
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|ext| ext != "nc") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let (host, ids, _) = setup(&[("O1.nc", &text)]);
        let analysis = host.analysis();
        let file = ids[0];
        let _ = (analysis.document_symbols(file), analysis.folding_ranges(file), analysis.highlight(file));
        let _ = (analysis.diagnostics(file), analysis.inlay_hints(file, None), analysis.format(file, None));
        for offset in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
            let offset = TextSize::try_from(offset).unwrap();
            let _ = analysis.hover(file, offset);
            let _ = analysis.goto_definition(file, offset);
            let _ = analysis.references(file, offset, true);
        }
    }
}

#[test]
fn lathe_hover_shows_the_modal_state_before_the_block() {
    let (host, ids, cursor) = setup(&[("O1000.nc", &at(LATHE, "G70 P10"))]);
    let hover = host.analysis().hover(ids[0], cursor.unwrap().1).unwrap().markdown;
    let state = hover.split("**Modal state before this block:** ").nth(1).unwrap_or_else(|| panic!("{hover}"));
    // G96 from the program, G99 and G18 from reset.
    assert!(state.contains("G96") && state.contains("G18") && state.contains("G99"), "{state}");
}

/// A Sinumerik subprogram with the language's statements.
const SINUMERIK: &str = "%_N_PART_SPF
PROC PART(REAL DEPTH, VAR INT COUNT) SAVE
; two comment lines
; fold together
DEF REAL B=5, C[2]
N10 G17 G642 SOFT X=R1+5 CR=2
START: $P_UIFR[1,X,TR]=5
IF DEPTH>=2 GOTOF START
IF B<>C[1]
  WHILE R1<10
    R[R1]=R1 B=B*2
  ENDWHILE
ELSE
  REPEAT
    MSG(\"N=\"<<B)
  UNTIL B==5
ENDIF
ENDLOOP
CYCLE81(10,0,2,-5) L140(1)
M17
";

#[test]
fn highlight_a_sinumerik_program() {
    check_highlight(
        "PART.SPF",
        SINUMERIK,
        expect![[r#"
            %_N_PART_SPF:Keyword
            PROC:Keyword PART:Function (:Operator REAL:Keyword DEPTH:write ,:Operator VAR:Keyword INT:Keyword COUNT:write ):Operator SAVE:Keyword
            ; two comment lines:Comment
            ; fold together:Comment
            DEF:Keyword REAL:Keyword B:write =:Operator 5:Number ,:Operator C:write [:Operator 2:Number ]:Operator
            N10:BlockNumber G17:GG6 G642:GG10 SOFT:GG21 X:Axis =:Operator R1:read +:Operator 5:Number CR:Interpolation =:Operator 2:Number
            START::Label { write: true } $P_UIFR:SystemVariable [:Operator 1:Number ,:Operator X:Axis ,:Operator TR:Keyword ]:Operator =:Operator 5:Number
            IF:Keyword DEPTH:read >=:Operator 2:Number GOTOF:Keyword START:Label { write: false }
            IF:Keyword B:Axis <>:Operator C:Axis [:Operator 1:Number ]:Operator
            WHILE:Keyword R1:read <:Operator 10:Number
            R[:write R1:read ]:write =:Operator R1:read B:Axis =:Operator B:Axis *:Operator 2:Number
            ENDWHILE:Keyword
            ELSE:Keyword
            REPEAT:Keyword
            MSG:Function (:Operator "N=":String <<:Operator B:Axis ):Operator
            UNTIL:Keyword B:Axis ==:Operator 5:Number
            ENDIF:Keyword
            ENDLOOP:Keyword
            CYCLE81:Function (:Operator 10:Number ,:Operator 0:Number ,:Operator 2:Number ,:Operator -:Operator 5:Number ):Operator L140:Function (:Operator 1:Number ):Operator
            M17:MM1
        "#]],
    );
}

/// The `PROC` holds the labels after it; the structures fold, an end
/// without its start (`ENDLOOP`) folds nothing.
#[test]
fn symbols_and_folds_of_a_sinumerik_program() {
    check_symbols(
        "PART.SPF",
        SINUMERIK,
        expect![[r#"
            Subprogram PART ((REAL DEPTH, VAR INT COUNT) SAVE): `PROC PART(REAL DEPTH, VAR INT COUNT) SAVE` … `M17` select `PART`
              Variable B (REAL): `B=5` select `B`
              Variable C (REAL): `C[2]` select `C`
              JumpTarget START: `START: $P_UIFR[1,X,TR]=5` select `START`
              Structure IF B<>C[1]: `IF B<>C[1]` … `ENDIF` select `IF`
                Structure WHILE R1<10: `  WHILE R1<10` … `  ENDWHILE` select `WHILE`
                Structure REPEAT: `  REPEAT` … `  UNTIL B==5` select `REPEAT`
        "#]],
    );
    check_folds(
        "PART.SPF",
        SINUMERIK,
        expect![[r#"
        Comment `; two comment lines` … `; fold together`
        Region `IF B<>C[1]` … `ENDIF`
        Region `  WHILE R1<10` … `  ENDWHILE`
        Region `  REPEAT` … `  UNTIL B==5`"#]],
    );
}

/// Every token of the Sinumerik listings the parser reads without an error
/// is classified as something other than an error.
#[test]
fn sinumerik_listings_highlight_without_errors() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../syntax/test_data/sinumerik");
    let listings = std::fs::read_dir(&dir).unwrap().chain(std::fs::read_dir(dir.join("constructs")).unwrap());
    let mut read = 0;
    for path in listings.map(|entry| entry.unwrap().path()) {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if !(name.ends_with(".mpf") || name.ends_with(".spf")) || name.starts_with("error_") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let (host, ids, _) = setup(&[(&name.to_uppercase(), &text)]);
        let errors: Vec<&str> = host
            .analysis()
            .highlight(ids[0])
            .iter()
            .filter(|h| h.kind == HighlightKind::Error)
            .map(|h| &text[h.range])
            .collect();
        assert!(errors.is_empty(), "{name}: {errors:?}");
        read += 1;
    }
    assert!(read >= 15, "{read} listings");
}

/// The seed listings: L19's main program and subprogram, L29 with its
/// computed jumps, L30 and the cycle L31 it calls.
const L19_MAIN: &str = include_str!("../../syntax/test_data/sinumerik/l19_profil_main.mpf");
const L19_SUB: &str = include_str!("../../syntax/test_data/sinumerik/l19_profil_sub.spf");
const L25: &str = include_str!("../../syntax/test_data/sinumerik/l25_podpis_janskacel.mpf");
const L29: &str = include_str!("../../syntax/test_data/sinumerik/l29_blob_souradnice_dole.mpf");
const L30: &str = include_str!("../../syntax/test_data/sinumerik/l30_run_vacka.mpf");
const L31: &str = include_str!("../../syntax/test_data/sinumerik/l31_vacka_cyklus.spf");

/// A workspace of `files` with the cursor before `needle` in the first.
fn with_cursor(files: &[(&str, &str)], needle: &str) -> Vec<(String, String)> {
    let mut files: Vec<(String, String)> = files.iter().map(|(p, t)| (p.to_string(), t.to_string())).collect();
    files[0].1 = at(&files[0].1, needle);
    files
}

fn borrowed(files: &[(String, String)]) -> Vec<(&str, &str)> {
    files.iter().map(|(p, t)| (p.as_str(), t.as_str())).collect()
}

/// Where go to definition leads from before `needle` in the first file, as
/// `path:line: focus`.
fn definitions(files: &[(&str, &str)], needle: &str) -> Vec<String> {
    let files = with_cursor(files, needle);
    let (host, _, cursor) = setup(&borrowed(&files));
    let (file, offset) = cursor.unwrap();
    let analysis = host.analysis();
    analysis
        .goto_definition(file, offset)
        .iter()
        .map(|target| {
            let text = analysis.text(target.file);
            assert!(target.range.contains_range(target.focus), "{target:?}");
            let line = text[..usize::from(target.focus.start())].matches('\n').count() + 1;
            format!("{}:{line}: {}", analysis.path(target.file), show(&text, target.focus))
        })
        .collect()
}

fn references_at(files: &[(&str, &str)], needle: &str) -> String {
    references(&borrowed(&with_cursor(files, needle)), true)
}

#[test]
fn sinumerik_definitions_of_calls_variables_and_parameters_across_files() {
    let files = [("MAIN.MPF", L19_MAIN), ("PROFIL.SPF", L19_SUB)];
    assert_eq!(definitions(&files, "PROFIL ("), ["PROFIL.SPF:4: `PROFIL`"]);
    assert_eq!(definitions(&files, "DELKA) ;"), ["MAIN.MPF:4: `DELKA`"]);
    assert_eq!(definitions(&files, "DELKA=5.0"), ["MAIN.MPF:4: `DELKA`"]);
    // In the subprogram: the formal parameters, not the axes X1 and Y1.
    let files = [("PROFIL.SPF", L19_SUB), ("MAIN.MPF", L19_MAIN)];
    assert_eq!(definitions(&files, "X Y1"), ["PROFIL.SPF:4: `X`"]);
    assert_eq!(definitions(&files, "X1="), Vec::<String>::new());
    check_references(
        &borrowed(&with_cursor(&files, "PROFIL (")),
        true,
        expect![[r#"
            PROFIL.SPF:4:7: PROFIL Definition
            MAIN.MPF:6:6: PROFIL Call"#]],
    );
    // L30 declares the cycle L31 is and calls it; the program it writes is
    // called by its control name `_N_…_SPF`.
    let files = [
        ("RUN_VACKA.MPF", L30),
        ("VACKA_CYKLUS.SPF", L31),
        ("_N_GEOMETRIE_VACKA_SPF", "; written by VACKA_CYKLUS\nG0 X0\nM17\n"),
    ];
    assert_eq!(definitions(&files, "VACKA_CYKLUS("), ["VACKA_CYKLUS.SPF:3: `VACKA_CYKLUS`"]);
    assert_eq!(definitions(&files, "VACKA_CYKLUS(POC"), ["VACKA_CYKLUS.SPF:3: `VACKA_CYKLUS`"]);
    assert_eq!(definitions(&files, "_N_GEOMETRIE_VACKA_SPF\n"), ["_N_GEOMETRIE_VACKA_SPF:1: ``"]);
    check_references(
        &borrowed(&with_cursor(&files, "VACKA_CYKLUS(POC")),
        true,
        expect![[r#"
            VACKA_CYKLUS.SPF:3:6: VACKA_CYKLUS Definition
            RUN_VACKA.MPF:4:8: VACKA_CYKLUS Declaration
            RUN_VACKA.MPF:36:5: VACKA_CYKLUS Call"#]],
    );
}

/// The hover text before `needle` in the first file.
fn hover_at(files: &[(&str, &str)], needle: &str) -> String {
    let files = with_cursor(files, needle);
    let (host, _, cursor) = setup(&borrowed(&files));
    let (file, offset) = cursor.unwrap();
    host.analysis().hover(file, offset).map(|hover| hover.markdown).unwrap_or_default()
}

/// A name the program gives shows where it is defined and how often it is
/// used; what the control knows shows the catalogue's text.
#[test]
fn sinumerik_hover_on_a_name_shows_its_definition() {
    let files = [("MAIN.MPF", L19_MAIN), ("PROFIL.SPF", L19_SUB)];
    expect![[r#"
        **variable `DELKA`**

        ```sinumerik
         N60 DEF INT DELKA; Definice proměnné
        ```
        line 4

        2 uses"#]]
    .assert_eq(&hover_at(&files, "DELKA) ;"));
    expect![[r#"
        **program `PROFIL`**

        ```sinumerik
         PROC PROFIL (REAL C, BOOL H, REAL X, INT Y, REAL Z) ; Formální parametry by nabyly hodnotu: C=0, protože nebyl předán, H=TRUE, X=2.14, Y=DELKA=5.0 , Z=0, protože také nebyl zadán
        ```
        PROFIL.SPF line 4

        1 use"#]]
    .assert_eq(&hover_at(&files, "PROFIL ("));
    let text = "DEF INT N\nBACK: N=N+1\nIF N<3 GOTOB BACK\nGOTOF MISSING\nM30\n";
    expect![[r#"
        **label `BACK`**

        ```sinumerik
        BACK: N=N+1
        ```
        line 2

        1 use"#]]
    .assert_eq(&hover_at(&[("LOOP.MPF", text)], "BACK\nGOTOF"));
    expect![[r#"
        **label `MISSING`**

        no block of the program has it: a jump to it fails

        1 use"#]]
    .assert_eq(&hover_at(&[("LOOP.MPF", text)], "MISSING"));
    assert!(
        hover_at(&[("LOOP.MPF", text)], "GOTOB").starts_with("### GOTOB"),
        "{}",
        hover_at(&[("LOOP.MPF", text)], "GOTOB")
    );
    assert!(hover_at(&[("LOOP.MPF", text)], "M30").starts_with("### M30"));
    // Blank lines, comment lines and CR LF line ends are lines too.
    let text = "\r\n; a comment\r\n\r\nDEF INT COUNT\r\nCOUNT=1\r\n";
    let hover = hover_at(&[("LINES.MPF", text)], "COUNT=1");
    assert!(hover.contains("\nline 4\n"), "{hover}");
}

/// CR names the radius; its hover also says which of the two arcs of that
/// radius the block cuts, where the ends are known (digest §6 rule 21).
#[test]
fn sinumerik_hover_on_cr_shows_the_arc_it_chooses() {
    let text = "G17 G90 G0 X0 Y0\nG2 X20 Y0 CR=10 F100\nG3 X0 Y0 CR=-10\nG2 X100 CR=5\nR1=2\nG2 X=R1 CR=6\n";
    let first_line =
        |needle: &str| hover_at(&[("ARCS.MPF", text)], needle).lines().next().unwrap_or_default().to_owned();
    expect!["**This arc** (G2, a positive CR the shorter of the two arcs of radius 10): from X0.000 Y0.000 to X20.000 Y0.000 about X10.000 Y0.000, sweeping 180.0°"]
        .assert_eq(&first_line("CR=10"));
    expect!["**This arc** (G3, a negative CR the longer of the two arcs of radius 10): from X20.000 Y0.000 to X0.000 Y0.000 about X10.000 Y0.000, sweeping 180.0°"]
        .assert_eq(&first_line("CR=-10"));
    expect!["**This arc** (G2): no arc of radius 5 joins X0.000 Y0.000 and X100.000 Y0.000"]
        .assert_eq(&first_line("CR=5\nR1"));
    // An end the walk does not know: the catalogue's text alone.
    assert!(first_line("CR=6").starts_with("### CR"), "{}", first_line("CR=6"));
}

/// Over a frame command, the frame it leaves in force: L25's scales compose
/// as the digest says, 0.18·0.75 (rule 74), after CYCLE800 swivelled to
/// nothing and with R1 set to 0.18.
#[test]
fn sinumerik_hover_on_a_frame_shows_the_composed_frame() {
    let first_line = |needle: &str| hover_at(&[("L25.MPF", L25)], needle).lines().next().unwrap_or_default().to_owned();
    expect!["**The frame after this block:** translation X55 Y4, scale X0.18 Y0.18 Z0.18"]
        .assert_eq(&first_line("ASCALE X=R1"));
    expect!["**The frame after this block:** translation X14.5 Y4, scale X0.18·0.75 Y0.18·0.75 Z0.18"]
        .assert_eq(&first_line("ATRANS X-300"));
    // A value the walk does not know: the run's.
    let text = "G17 G71 R2=R1*2\nTRANS X=R2\nATRANS Y5\nTRANS X10\n";
    let first_line =
        |needle: &str| hover_at(&[("FRAMES.MPF", text)], needle).lines().next().unwrap_or_default().to_owned();
    assert!(first_line("ATRANS").contains("is the run's"), "{}", first_line("ATRANS"));
    expect!["**The frame after this block:** translation X10"].assert_eq(&first_line("TRANS X10"));
}

/// L29 jumps to block numbers and labels and computes the target of some:
/// those have no definition before a run.
#[test]
fn sinumerik_jumps_of_l29_lead_to_their_blocks() {
    let files = [("BLOB.MPF", L29)];
    assert_eq!(definitions(&files, "N5\nN3"), ["BLOB.MPF:87: `N5`"]);
    assert_eq!(definitions(&files, "N2\nELSE"), ["BLOB.MPF:66: `N2`"]);
    assert_eq!(definitions(&files, "PREDBEZNE\nENDIF"), ["BLOB.MPF:23: `PREDBEZNE`"]);
    assert_eq!(definitions(&files, "END\nR10="), ["BLOB.MPF:104: `END`"]);
    assert_eq!(definitions(&files, "\"N\"<<R3"), Vec::<String>::new());
    // An R parameter's definitions are its assignments.
    expect![[r#"
        BLOB.MPF:68: `R3`
        BLOB.MPF:83: `R3`"#]]
    .assert_eq(&definitions(&files, "R3\nENDIF").join("\n"));
    expect![[r#"
        BLOB.MPF:68:3: R3 Write
        BLOB.MPF:70:14: R3 Read
        BLOB.MPF:83:3: R3 Write
        BLOB.MPF:85:14: R3 Read"#]]
    .assert_eq(&references_at(&files, "R3=100"));
    expect![[r#"
        BLOB.MPF:66:1: N2 Definition
        BLOB.MPF:61:8: N2 Jump"#]]
    .assert_eq(&references_at(&files, "N2 "));
}

/// L31: labels reached forward and backward, CASE jumps to block numbers,
/// and a FOR variable written in three cases.
#[test]
fn sinumerik_labels_case_targets_and_variables_of_l31() {
    let files = [("VACKA_CYKLUS.SPF", L31)];
    assert_eq!(definitions(&files, "KRUH\n  WRITE"), ["VACKA_CYKLUS.SPF:87: `KRUH`"]);
    assert_eq!(definitions(&files, "COUNTER\n;"), ["VACKA_CYKLUS.SPF:83: `COUNTER`"]);
    assert_eq!(definitions(&files, "N24 10"), ["VACKA_CYKLUS.SPF:27: `N24`"]);
    assert_eq!(definitions(&files, "INKREMENT_UHLU\n"), ["VACKA_CYKLUS.SPF:3: `INKREMENT_UHLU`"]);
    expect![[r#"
        VACKA_CYKLUS.SPF:4:64: VAR_i Definition
        VACKA_CYKLUS.SPF:60:5: var_i Write
        VACKA_CYKLUS.SPF:63:35: VAR_I Read
        VACKA_CYKLUS.SPF:65:15: var_i Read
        VACKA_CYKLUS.SPF:66:34: var_i Read
        VACKA_CYKLUS.SPF:67:21: var_i Read
        VACKA_CYKLUS.SPF:67:39: var_i Read
        VACKA_CYKLUS.SPF:67:60: var_i Read
        VACKA_CYKLUS.SPF:69:15: var_i Read
        VACKA_CYKLUS.SPF:69:34: var_i Read
        VACKA_CYKLUS.SPF:71:58: var_i Read
        VACKA_CYKLUS.SPF:84:18: var_i Read"#]]
    .assert_eq(&references_at(&files, "var_i = 0"));
    expect![[r#"
        VACKA_CYKLUS.SPF:98:1: END Definition
        VACKA_CYKLUS.SPF:65:35: END Jump"#]]
    .assert_eq(&references_at(&files, "END:"));
}

/// The text after renaming what is before `needle` to `new_name`, or why not.
fn renamed(path: &str, text: &str, needle: &str, new_name: &str) -> Result<String, String> {
    let files = with_cursor(&[(path, text)], needle);
    let (host, ids, cursor) = setup(&borrowed(&files));
    let analysis = host.analysis();
    let offset = cursor.unwrap().1;
    let prepared = analysis.prepare_rename(ids[0], offset)?;
    assert!(prepared.contains_inclusive(offset), "{prepared:?} at {offset:?}");
    let mut edits = analysis.rename(ids[0], offset, new_name)?.in_file(ids[0]).to_vec();
    edits.sort_by_key(|edit| std::cmp::Reverse(edit.delete.start()));
    let mut text = analysis.text(ids[0]).to_string();
    for edit in edits {
        edit.apply(&mut text);
    }
    Ok(text)
}

/// The lines a rename changed, as they read after it (without indent).
fn changed_lines(before: &str, after: &str) -> String {
    before
        .lines()
        .zip(after.lines())
        .filter(|(b, a)| b != a)
        .map(|(_, a)| a.trim_start())
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn sinumerik_rename_changes_the_name_and_nothing_else() {
    let after = renamed("VACKA_CYKLUS.SPF", L31, "VAR_I<<", "IDX_I").unwrap();
    expect![[r#"
        DEF REAL AKT_R, AKT_UHEL, AKT_X, AKT_Y, KONECNY_UHEL, DELTA_R, IDX_I
        FOR IDX_I = 0 TO 20
        WRITE(ERROR,DEBURGER,"VAR_I= "<<IDX_I<<"")
        IF VAC_POLE[IDX_I+2,0]==0 GOTOF END
        KONECNY_UHEL=AKT_UHEL+VAC_POLE[IDX_I+1,0]
        DELTA_R=(VAC_POLE[IDX_I,1]-VAC_POLE[IDX_I+1,1])/VAC_POLE[IDX_I+1,0]*INKREMENT_UHLU
        IF VAC_POLE[IDX_I,1]==VAC_POLE[IDX_I+1,1] GOTOF KRUH
        WRITE(ERROR,DEBURGER,"VAC_POLE[var_i+1,0]= "<<VAC_POLE[IDX_I+1,0]<<"")
        AKT_R=VAC_POLE[IDX_I+1,1]"#]]
    .assert_eq(&changed_lines(L31, &after));
    let after = renamed("VACKA_CYKLUS.SPF", L31, "END\n  KONECNY", "KONEC").unwrap();
    expect![[r#"
        IF VAC_POLE[var_i+2,0]==0 GOTOF KONEC
        KONEC:"#]]
    .assert_eq(&changed_lines(L31, &after));
    // A PROC's formal parameter, in the subprogram.
    let after = renamed("PROFIL.SPF", L19_SUB, "X Y1", "XPOS").unwrap();
    expect![[r#"
         PROC PROFIL (REAL C, BOOL H, REAL XPOS, INT Y, REAL Z) ; Formální parametry by nabyly hodnotu: C=0, protože nebyl předán, H=TRUE, X=2.14, Y=DELKA=5.0 , Z=0, protože také nebyl zadán
         N30 X1=XPOS Y1=Y ; Najetí osou X1 na pozici 2.14 a osou Y1 na 5.0"#]]
    .assert_eq(&changed_lines(L19_SUB, &after));
}

#[test]
fn sinumerik_rename_refuses_names_the_control_would_not_take() {
    let refusal = |needle: &str, new_name: &str| renamed("VACKA_CYKLUS.SPF", L31, needle, new_name).unwrap_err();
    let refusals: Vec<String> = [
        ("AKT_X=", "1X"),
        ("AKT_X=", "X"),
        ("AKT_X=", "A1"),
        ("AKT_X=", "NAME-2"),
        ("AKT_X=", "ABCDEFGHIJKLMNOPQRSTUVWXYZ_ABCDE"),
        ("AKT_X=", "SIN"),
        ("AKT_X=", "cr"),
        ("AKT_X=", "GOTOF"),
        ("AKT_X=", "CYCLE800"),
        ("AKT_X=", "AKT_Y"),
        ("AKT_X=", "kruh"),
        ("KRUH:", "VACKA_CYKLUS"),
        ("R=AKT_R", "VAC_POLE"),
        ("VAC_POLE[0,1]", "TABLE"),
        ("BSPLINE", "TABLE"),
        ("$A_DAY", "TABLE"),
        ("N21 M", "TABLE"),
        ("VACKA_CYKLUS (", "AKT_X"),
        ("VACKA_CYKLUS (", "CYCLE81"),
        (";pohyb", "TABLE"),
    ]
    .into_iter()
    .map(|(needle, new_name)| format!("{needle:?} → {new_name}: {}", refusal(needle, new_name)))
    .collect();
    expect![[r#"
        "AKT_X=" → 1X: `1X` is not a valid name: two letters first, then letters, digits or `_`, at most 31 characters
        "AKT_X=" → X: `X` is not a valid name: two letters first, then letters, digits or `_`, at most 31 characters
        "AKT_X=" → A1: `A1` is not a valid name: two letters first, then letters, digits or `_`, at most 31 characters
        "AKT_X=" → NAME-2: `NAME-2` is not a valid name: two letters first, then letters, digits or `_`, at most 31 characters
        "AKT_X=" → ABCDEFGHIJKLMNOPQRSTUVWXYZ_ABCDE: `ABCDEFGHIJKLMNOPQRSTUVWXYZ_ABCDE` is not a valid name: two letters first, then letters, digits or `_`, at most 31 characters
        "AKT_X=" → SIN: `SIN` is a predefined function of the control
        "AKT_X=" → cr: `cr` is an address of the control
        "AKT_X=" → GOTOF: `GOTOF` is a keyword of the control
        "AKT_X=" → CYCLE800: `CYCLE800` is a cycle of the control
        "AKT_X=" → AKT_Y: `AKT_Y` is already a name in this file (`AKT_Y` on line 4)
        "AKT_X=" → kruh: `kruh` is already a name in this file (`KRUH` on line 69)
        "KRUH:" → VACKA_CYKLUS: `VACKA_CYKLUS` is already a name in this file (`VACKA_CYKLUS` on line 3)
        "R=AKT_R" → VAC_POLE: `VAC_POLE` is already a name in this file (`VAC_POLE` on line 11)
        "VAC_POLE[0,1]" → TABLE: `VAC_POLE` is not declared in this file (no DEF or PROC parameter): it cannot be renamed here
        "BSPLINE" → TABLE: Nothing to rename here: user variables, PROC parameters, labels and programs can be renamed
        "$A_DAY" → TABLE: Nothing to rename here: user variables, PROC parameters, labels and programs can be renamed
        "N21 M" → TABLE: `N21` is a block number: renumber the block instead
        "VACKA_CYKLUS (" → AKT_X: `AKT_X` is already a name in this file (`AKT_X` on line 4)
        "VACKA_CYKLUS (" → CYCLE81: `CYCLE81` is a cycle of the control
        ";pohyb" → TABLE: Nothing to rename here: user variables, PROC parameters, labels and programs can be renamed"#]].assert_eq(&refusals.join("\n"));
    // The same name in another case is the same name.
    assert!(renamed("VACKA_CYKLUS.SPF", L31, "AKT_X=", "Akt_X").is_ok());
    assert_eq!(
        renamed("BLOB.MPF", L29, "R3=100", "TABLE"),
        Err("`R3` is an R parameter: its number cannot be renamed".to_owned())
    );
}

/// Renaming a program renames its PROC, every call and EXTERN of it in the
/// workspace (bare or as `_N_NAME_SPF`), and its file.
#[test]
fn sinumerik_rename_of_a_program_changes_every_file_and_moves_its_file() {
    let main = format!("{L19_MAIN}_N_PROFIL_SPF\n");
    let files = with_cursor(&[("dir/MAIN.MPF", main.as_str()), ("dir/PROFIL.SPF", L19_SUB)], "PROFIL (,TRUE");
    let (host, ids, cursor) = setup(&borrowed(&files));
    let analysis = host.analysis();
    let renaming = analysis.rename(ids[0], cursor.unwrap().1, "Kontura").unwrap();
    let changed = |index: usize| {
        let mut text = analysis.text(ids[index]).to_string();
        for edit in renaming.in_file(ids[index]).iter().rev() {
            edit.apply(&mut text);
        }
        changed_lines(&analysis.text(ids[index]), &text)
    };
    expect![[r#"
        N70 Kontura (,TRUE,2.14,DELKA) ; Volání podprogramu se skutečnými parametry: 2.14 a DELKA
        _N_Kontura_SPF"#]]
    .assert_eq(&changed(0));
    expect!["PROC Kontura (REAL C, BOOL H, REAL X, INT Y, REAL Z) ; Formální parametry by nabyly hodnotu: C=0, protože nebyl předán, H=TRUE, X=2.14, Y=DELKA=5.0 , Z=0, protože také nebyl zadán"]
        .assert_eq(&changed(1));
    assert_eq!(renaming.moved, vec![(ids[1], "dir/KONTURA.SPF".to_owned())]);
    assert_eq!(
        analysis.rename(ids[0], cursor.unwrap().1, "MAIN"),
        Err("`MAIN` is already a program of the workspace (dir/MAIN.MPF)".to_owned())
    );
}

/// A Sinumerik subprogram with seven names the rename test picks from (two
/// PROC parameters, three variables, two labels), each also in a comment
/// and a string, which rename leaves alone.
fn naming_program(names: &[String]) -> String {
    let [a, b, c, d, e, l1, l2] = names else { panic!("seven names") };
    format!(
        "PROC WORK(REAL {a}, INT {b})
DEF REAL {c}={a}*2, {d}[3]
DEF INT {e}
{l1}: {c}={c}+{b} R1={d}[0]
IF {c}>10 GOTOF {l2}
FOR {e} = 0 TO {b}
  {d}[{e}]={a}+{e}
ENDFOR
REPEAT {l1} P=2
GOTOB {l1}
{l2}: WRITE(R2,\"LOG\",\"C=\"<<{c})
MSG(\"{a} {b} {c} {d} {e} {l1} {l2}\")
; {a} {b} {c} {d} {e} {l1} {l2}
M17
"
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Renaming a name and renaming it back gives the original text, and
    /// comments and strings keep the old name.
    #[test]
    fn sinumerik_rename_and_back_gives_the_original(
        bases in prop::collection::vec(("[A-Z]{2}[A-Z_]{0,5}", prop::bool::ANY), 7),
        picked in 0usize..7,
        new_base in "[A-Z]{2}[A-Z_]{0,5}",
    ) {
        // Distinct names, none a prefix of another: a digit only at the end.
        let names: Vec<String> = bases
            .iter()
            .enumerate()
            .map(|(i, (base, lower))| {
                let name = format!("{base}Z{i}");
                if *lower { name.to_lowercase() } else { name }
            })
            .collect();
        let text = naming_program(&names);
        let old = &names[picked];
        let new = format!("{new_base}Z9");
        let mut host = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
        let file = host.add_file("WORK.SPF", text.as_str());
        let offset = TextSize::try_from(text.find(old.as_str()).unwrap()).unwrap();
        let rename = |host: &AnalysisHost, to: &str| {
            let analysis = host.analysis();
            let mut edits = analysis.rename(file, offset, to).unwrap_or_else(|why| panic!("{why}\n{}", analysis.text(file))).in_file(file).to_vec();
            edits.sort_by_key(|edit| std::cmp::Reverse(edit.delete.start()));
            let mut renamed = analysis.text(file).to_string();
            for edit in &edits {
                edit.apply(&mut renamed);
            }
            renamed
        };
        let renamed = rename(&host, &new);
        let untouched = |line: &&str| line.starts_with(';') || line.starts_with("MSG(");
        prop_assert_eq!(text.lines().filter(untouched).collect::<Vec<_>>(), renamed.lines().filter(untouched).collect::<Vec<_>>());
        prop_assert!(!renamed.lines().filter(|line| !untouched(line)).any(|line| line.contains(old.as_str())), "{}", renamed);
        host.set_text(file, renamed);
        prop_assert_eq!(rename(&host, old), text);
    }
}

/// L31's outline: the PROC holds its variables, labels and structures,
/// the structures what lies inside them.
#[test]
fn sinumerik_outline_nests_structures_labels_and_variables() {
    check_symbols(
        "VACKA_CYKLUS.SPF",
        L31,
        expect![[r#"
        Subprogram VACKA_CYKLUS ((REAL POCATECNI_R, REAL TLOUSTKA, REAL INKREMENT_UHLU) SAVE): `PROC VACKA_CYKLUS (REAL POCATECNI_R, REAL TLOUSTKA, REAL INKREMENT_UHLU) SAVE` … `M17` select `VACKA_CYKLUS`
          Variable AKT_R (REAL): `AKT_R` select `AKT_R`
          Variable AKT_UHEL (REAL): `AKT_UHEL` select `AKT_UHEL`
          Variable AKT_X (REAL): `AKT_X` select `AKT_X`
          Variable AKT_Y (REAL): `AKT_Y` select `AKT_Y`
          Variable KONECNY_UHEL (REAL): `KONECNY_UHEL` select `KONECNY_UHEL`
          Variable DELTA_R (REAL): `DELTA_R` select `DELTA_R`
          Variable VAR_i (REAL): `VAR_i` select `VAR_i`
          Variable DEBURGER (STRING[50]): `DEBURGER="/_N_MPF_DIR/_N_VACKA_DIR/_N_DEBURGER_SPF"` select `DEBURGER`
          Variable PROGRAM (STRING[50]): `PROGRAM="/_N_MPF_DIR/_N_VACKA_DIR/_N_GEOMETRIE_VACKA_SPF"` select `PROGRAM`
          Variable ERROR (INT): `ERROR` select `ERROR`
          Structure IF(ISFILE(PROGRAM)): `IF(ISFILE(PROGRAM))` … `ENDIF` select `IF`
          Structure IF ERROR: `IF ERROR` … `ENDIF` select `IF`
            Structure CASE ERROR OF: `    CASE ERROR OF 1 GOTOF N21 2 GOTOF N22 3 GOTOF N23 4 GOTOF N24 10 GOTOF N25 11 GOTOF N26 12 GOTOF N27 13 GOTOF N28 20 GOTOF N29` select `CASE ERROR OF`
          Structure FOR var_i = 0 TO 20: `FOR var_i = 0 TO 20` … `ENDFOR` select `FOR`
            JumpTarget TEST_POKRACOVANI: `  TEST_POKRACOVANI:` select `TEST_POKRACOVANI`
            Structure WHILE AKT_UHEL < KONECNY_UHEL: `  WHILE AKT_UHEL < KONECNY_UHEL` … `  ENDWHILE` select `WHILE`
            JumpTarget COUNTER: `  COUNTER:` select `COUNTER`
          JumpTarget KRUH: `KRUH:` select `KRUH`
          JumpTarget END: `END:` select `END`
    "#]],
    );
}

/// The signature help before `needle` in the first file, the active
/// parameter in `⟨…⟩`.
fn signature(files: &[(&str, &str)], needle: &str) -> String {
    let files = with_cursor(files, needle);
    let (host, _, cursor) = setup(&borrowed(&files));
    let (file, offset) = cursor.unwrap();
    let Some(help) = host.analysis().signature_help(file, offset) else { return "none".to_owned() };
    let mut label = help.label.clone();
    if let Some(active) = help.active_parameter.map(|index| help.parameters[index].range) {
        label = format!("{}⟨{}⟩{}", &label[..active.start().into()], &label[active], &label[active.end().into()..]);
    }
    let documentation = help.active_parameter.and_then(|index| help.parameters[index].documentation.clone());
    format!("{label}{}", documentation.map(|d| format!(" — {d}")).unwrap_or_default())
}

/// Inside a call's parentheses: a PROC of the workspace, the EXTERN
/// declaration when the PROC's file is not there, a cycle's and a
/// function's catalogue signature.
#[test]
fn sinumerik_signature_help_of_procs_cycles_and_functions() {
    let l19 = [("MAIN.MPF", L19_MAIN), ("PROFIL.SPF", L19_SUB)];
    let l30 = [("RUN_VACKA.MPF", L30), ("VACKA_CYKLUS.SPF", L31)];
    let found: Vec<String> = [
        (&l19[..], ",TRUE"),
        (&l19[..], "2.14,"),
        (&l19[..], "DELKA)"),
        (&l19[..], ") ; V"),
        (&l19[..1], "DELKA)"),
        (&l30[..], "TLOUSTKA, INKREMENT_UHLU)\n"),
        (&l30[..1], "TLOUSTKA, INKREMENT_UHLU)\n"),
        (&l30[..], "\"0\",100000"),
        (&l30[..], "0,-30,0"),
        (&l30[..], "RADIUS_5)"),
        (&l30[..], "\"_N_GEOMETRIE"),
    ]
    .into_iter()
    .map(|(files, needle)| format!("{needle:?}: {}", signature(files, needle)))
    .collect();
    expect![[r#"
        ",TRUE": PROFIL(⟨REAL C⟩, BOOL H, REAL X, INT Y, REAL Z)
        "2.14,": PROFIL(REAL C, BOOL H, ⟨REAL X⟩, INT Y, REAL Z)
        "DELKA)": PROFIL(REAL C, BOOL H, REAL X, ⟨INT Y⟩, REAL Z)
        ") ; V": PROFIL(REAL C, BOOL H, REAL X, ⟨INT Y⟩, REAL Z)
        "DELKA)": none
        "TLOUSTKA, INKREMENT_UHLU)\n": VACKA_CYKLUS(REAL POCATECNI_R, ⟨REAL TLOUSTKA⟩, REAL INKREMENT_UHLU)
        "TLOUSTKA, INKREMENT_UHLU)\n": VACKA_CYKLUS(REAL, ⟨REAL⟩, REAL)
        "\"0\",100000": CYCLE800(INT _FR, ⟨STRING[32] _TC⟩, INT _ST, INT _MODE, REAL _X0, REAL _Y0, REAL _Z0, REAL _A, REAL _B, REAL _C, REAL _X1, REAL _Y1, REAL _Z1, INT _DIR, REAL _FR_I, INT _DMODE) — Name of the swivel data record (`"0"`, `"TC1"` in the thesis's calls); the thesis's reading: a string naming the record (inferred).
        "0,-30,0": WORKPIECE([STRING _1], STRING _2[, INT _3], STRING form, ⟨REAL… values⟩) — Reference and dimensions of the blank; `0,0,-60,0,0,0,140,30` for the thesis's box.
        "RADIUS_5)": SET(⟨REAL… values⟩) → array values — The values, in order.
        "\"_N_GEOMETRIE": ISFILE(⟨STRING file⟩) → BOOL — Path or name of the file."#]].assert_eq(&found.join("\n"));
}

/// Every editor question at every offset of the Sinumerik listings and
/// syntax fixtures answers without a panic, with ranges in the text.
#[test]
fn every_sinumerik_listing_answers_everywhere() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../syntax/test_data/sinumerik");
    let listings = std::fs::read_dir(&dir).unwrap().chain(std::fs::read_dir(dir.join("constructs")).unwrap());
    for path in listings.map(|entry| entry.unwrap().path()) {
        let name = path.file_name().unwrap().to_string_lossy().to_uppercase();
        if !(name.ends_with(".MPF") || name.ends_with(".SPF")) {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let (host, ids, _) = setup(&[(&name, &text), ("PROFIL.SPF", L19_SUB)]);
        let analysis = host.analysis();
        let file = ids[0];
        let within = |range: TextRange| usize::from(range.end()) <= text.len();
        assert!(analysis.document_symbols(file).iter().all(|s| within(s.range)), "{name}");
        for offset in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
            let offset = TextSize::try_from(offset).unwrap();
            for target in analysis.goto_definition(file, offset).iter().filter(|t| t.file == file) {
                assert!(within(target.range) && target.range.contains_range(target.focus), "{name}: {target:?}");
            }
            assert!(analysis.references(file, offset, true).iter().all(|r| r.file != file || within(r.range)));
            if let Ok(range) = analysis.prepare_rename(file, offset) {
                assert!(range.contains_inclusive(offset), "{name} at {offset:?}");
                let renaming = analysis.rename(file, offset, "RENAMED").unwrap();
                assert!(renaming.in_file(file).iter().all(|edit| within(edit.delete)), "{name}");
            }
            if let Some(help) = analysis.signature_help(file, offset) {
                assert!(help.parameters.iter().all(|p| usize::from(p.range.end()) <= help.label.len()), "{help:?}");
            }
        }
    }
}
