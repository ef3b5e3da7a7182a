//! Completion and inlay hints. `$0` in a program marks the cursor.

#[path = "../../syntax/tests/strategies/mod.rs"]
mod strategies;

use expect_test::{Expect, expect};
use ncc_analysis::{AnalysisHost, CompletionItem, CompletionKind, Config, Dialect, TextRange, TextSize};
use proptest::prelude::*;
use strategies::{block_program, crowded_lines, overlong_lines, program_text};

const PROGRAM: &str = "%1 \"ZKOUŠKA – doplňování\"
N10 G90 G17 R12=12.5 R13=864 \"Čerpání\"
N20 G01 X0 Y0 F200
N30 G71 L100
N40 G73 L20 Q2
N50 M30
N100 G79 L100 \"PODPROGRAM – kapsa\"
N110 G91 X1
N120 G70
N200 G79 L200 \"DRUHÝ\"
 \"  R20 = hloubka\"
N210 G70
*
";

/// The completions with the cursor at `$0` in the first file, on a machine
/// configured by `config`.
fn completions_with(config: &str, files: &[(&str, &str)]) -> (String, Vec<CompletionItem>) {
    let config = Config::from_toml(config, "ncc.toml".as_ref(), |path| std::fs::read_to_string(path))
        .expect("a valid configuration");
    let mut host = AnalysisHost::new(config);
    let mut cursor = None;
    for (path, text) in files {
        let offset = text.find("$0");
        let id = host.add_file(*path, text.replace("$0", ""));
        cursor = cursor.or(offset.map(|at| (id, TextSize::try_from(at).unwrap())));
    }
    let (file, offset) = cursor.expect("a `$0` cursor");
    let analysis = host.analysis();
    (analysis.text(file).to_string(), analysis.completions(file, offset))
}

/// The program with `$0` after the first `needle`.
fn cursor_after(needle: &str) -> String {
    let at = PROGRAM.find(needle).unwrap_or_else(|| panic!("`{needle}` in the program")) + needle.len();
    format!("{}$0{}", &PROGRAM[..at], &PROGRAM[at..])
}

/// One line per item: label, kind, detail, what it replaces and, if it
/// differs from the label, what it inserts.
fn show(text: &str, items: &[CompletionItem]) -> String {
    items
        .iter()
        .map(|item| {
            let mut line = format!("{} ({:?}) {} [{}]", item.label, item.kind, item.detail, &text[item.replace]);
            if item.insert_text != item.label {
                line.push_str(&format!(" inserts {}", item.insert_text));
            }
            line
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn check(program: &str, expect: Expect) {
    let (text, items) = completions_with("", &[("main.NCP", program)]);
    expect.assert_eq(&show(&text, &items));
}

fn labels(items: &[CompletionItem]) -> String {
    items.iter().map(|item| item.label.as_str()).collect::<Vec<_>>().join(" ")
}

#[test]
fn codes_leave_out_the_groups_the_block_already_has() {
    let program = PROGRAM.replace("N20 G01 X0", "N20 G01 G$0 X0");
    let (text, items) = completions_with("", &[("main.NCP", &program)]);
    // G01 holds group G0 (motion) and G90 is in another block.
    expect![[r#"G04 G05 G06 G07 G08 G09 G10 G14 G15 G16 G17 G18 G19 G23 G24 G26 G27 G28 G29 G31 G34 G35 G36 G37 G38 G39 G40 G41 G42 G53 G54 G55 G56 G57 G58 G59 G70 G71 G72 G73 G74 G75 G76 G78 G79 G80 G81 G82 G83 G84 G85 G86 G87 G88 G89 G90 G91 G92 G93 G94 G95 G96 G97 G98"#]]
    .assert_eq(&labels(&items));
    let g04 = &items[0];
    assert_eq!((g04.kind, g04.detail.as_str(), &text[g04.replace]), (CompletionKind::Code, "Dwell", "G"));
    assert!(g04.documentation.as_deref().is_some_and(|doc| doc.starts_with("### G04 — Dwell")), "{g04:?}");
}

#[test]
fn codes_being_typed_replace_the_word_and_m_groups_count_too() {
    check(
        "%1\nN10 M03 M0$0 S500\n",
        expect![[r#"
            M00 (Code) Program stop [M0]
            M01 (Code) Optional stop [M0]
            M02 (Code) End of program [M0]
            M06 (Code) Tool change [M0]
            M07 (Code) Coolant 2 on [M0]
            M08 (Code) Coolant 1 on [M0]
            M09 (Code) Coolant 1 and 2 off [M0]
            M10 (Code) Clamp workpiece [M0]
            M11 (Code) Unclamp workpiece [M0]
            M17 (Code) Coolant 1 and 2 on [M0]
            M30 (Code) End of program (same as M02) [M0]
            M36 (Code) Feed as programmed [M0]
            M37 (Code) Feed reduced 1 : 100 [M0]
            M40 (Code) Automatic spindle range [M0]
            M41 (Code) Spindle range 1 [M0]
            M42 (Code) Spindle range 2 [M0]
            M43 (Code) Spindle range 3 [M0]
            M44 (Code) Spindle range 4 [M0]
            M48 (Code) Feed override active [M0]
            M49 (Code) Feed override bypassed [M0]
            M50 (Code) Coolant 3 on [M0]
            M51 (Code) Coolant 4 on [M0]
            M52 (Code) Coolant 3 and 4 on [M0]
            M53 (Code) Coolant 3 and 4 off [M0]
            M60 (Code) Workpiece change [M0]"#]],
    );
}

#[test]
fn planes_the_machine_lacks_are_left_out() {
    let program = "%1\nN10 G1$0\n";
    let (_, lathe) = completions_with("[machine]\naxes = [\"X\", \"Z\"]\n", &[("main.NCP", program)]);
    let (_, mill) = completions_with("", &[("main.NCP", program)]);
    let planes = |items: &[CompletionItem]| {
        let planes = ["G14", "G15", "G16", "G17", "G18", "G19"];
        items.iter().map(|i| i.label.as_str()).filter(|l| planes.contains(l)).collect::<Vec<_>>().join(" ")
    };
    assert_eq!(planes(&mill), "G14 G15 G16 G17 G18 G19");
    // On two axes only G17's pair (axes 1 and 2) exists.
    assert_eq!(planes(&lathe), "G17");
}

#[test]
fn addresses_the_block_needs_come_first() {
    let program = PROGRAM.replace("N30 G71 L100", "N30 G71 $0");
    let (text, items) = completions_with("", &[("main.NCP", &program)]);
    let first_code = items.iter().position(|item| item.kind == CompletionKind::Code).expect("codes");
    let (addresses, codes) = items.split_at(first_code);
    expect![[r#"
        L (Address) Subprogram, macrocycle or jump target number []
        Q (Address) Repetition count or dwell time []
        G (Address) Preparatory function []
        M (Address) Miscellaneous function []
        D (Address) Tool-offset entry []
        X (Address) X axis []
        Y (Address) Y axis []
        Z (Address) Z axis []
        U (Address) U axis (4th axis by default) []
        V (Address) V axis (5th axis by default) []
        C (Address) C axis (6th axis by default, spindle position) []
        I (Address) Arc centre, first axis (thread start angle) []
        J (Address) Arc centre, second axis (thread run-out) []
        K (Address) Third interpolation word []
        R (Address) Program parameter []
        F (Address) Feed rate []
        H (Address) Auxiliary function H []
        P (Address) Auxiliary function P []
        S (Address) Spindle speed []
        T (Address) Tool number []
        E (Address) Thread lead-in length []
        & (Address) Length-compensation control []"#]]
    .assert_eq(&show(&text, addresses));
    // The codes follow, for the word may become one; G71 holds group G7.
    assert!(codes.iter().all(|code| code.kind == CompletionKind::Code));
    assert_eq!((codes[0].label.as_str(), codes.last().map(|c| c.label.as_str())), ("G00", Some("M60")));
    assert!(!codes.iter().any(|code| ["G70", "G72", "G73", "G79"].contains(&code.label.as_str())));
}

#[test]
fn the_arc_centre_follows_the_axes_of_the_block() {
    let (text, items) = completions_with("", &[("main.NCP", "%1\nN10 G02 X10 Z5 F100 I$0 \"oblouk Z–X\"\n")]);
    let shown = show(&text, &items);
    let centre: Vec<&str> = shown.lines().filter(|l| l.contains("Arc centre")).collect();
    expect![[r#"
        I (Address) Arc centre along Z, the first axis of the Z–X plane [I]
        J (Address) Arc centre along X, the second axis of the Z–X plane [I]"#]]
    .assert_eq(&centre.join("\n"));
    assert!(shown.starts_with("I (Address)"), "read by G02 first:\n{shown}");
    assert!(!shown.contains("\nX ") && !shown.contains("\nF "), "written once:\n{shown}");
}

#[test]
fn call_targets_are_the_subprograms_the_macrocycles_and_the_blocks() {
    check(
        &cursor_after("N30 G71 L"),
        expect![[r#"
            L100 (Subprogram) PODPROGRAM – kapsa [L100]
            L200 (Subprogram) DRUHÝ [L100]"#]],
    );
    check(
        &cursor_after("N40 G73 L2"),
        expect![[r#"
            L10 (Block) N10 G90 G17 R12=12.5 R13=864 "Čerpání" [L20]
            L20 (Block) N20 G01 X0 Y0 F200 [L20]
            L30 (Block) N30 G71 L100 [L20]
            L40 (Block) N40 G73 L20 Q2 [L20]
            L50 (Block) N50 M30 [L20]"#]],
    );
    let macro_file = "N10 G79 L9001 \"VRTÁNÍ ŘADY\"\n\" R20 = rozteč\nN20 G70\n";
    let (text, items) = completions_with(
        "",
        &[("main.NCP", "%1\nN10 G72 L9$0\n"), ("lib/L9002", "N1 G79 L9002\nN2 G70\n"), ("lib/L9001", macro_file)],
    );
    expect![[r#"
        L9001 (Macrocycle) VRTÁNÍ ŘADY [L9]
        L9002 (Macrocycle) N1 G79 L9002 [L9]"#]]
    .assert_eq(&show(&text, &items));
    expect![[r#"
        `lib/L9001`

        ```text
        N10 G79 L9001 "VRTÁNÍ ŘADY"
        " R20 = rozteč
        ```"#]]
    .assert_eq(items[0].documentation.as_deref().unwrap_or_default());
}

#[test]
fn parameters_with_a_value_come_first() {
    let program = PROGRAM.replace("N20 G01 X0", "N20 G01 XR1$0");
    let (text, items) = completions_with("", &[("main.NCP", &program)]);
    let shown = show(&text, &items);
    expect![[r#"
        R12 (Parameter) = 12.5 [R1]
        R13 (Parameter) = 0.864 [R1]
        R0 (Parameter) Tool-offset values for G92 D [R1]"#]]
    .assert_eq(&shown.lines().take(3).collect::<Vec<_>>().join("\n"));
    assert!(items.iter().all(|item| item.label != "R95"), "R95 is reserved");
    assert_eq!(items.last().map(|item| item.label.as_str()), Some("R94"), "not recommended last");
    let documentation = items[0].documentation.as_deref().unwrap_or_default();
    assert!(documentation.ends_with("**Value before this block:** `12.5` (12500 thousandths)"), "{documentation}");
}

#[test]
fn an_assignment_completes_its_parameter_and_the_equals_sign() {
    let (text, items) = completions_with("", &[("main.NCP", "%1\nN10 R1$0=5 R\n")]);
    assert_eq!(show(&text, &items[..1]), "R0 (Parameter) Tool-offset values for G92 D [R1]");
    let (text, items) = completions_with("", &[("main.NCP", "%1\nN10 R1=5\nN20 X1 R$0\n")]);
    assert_eq!(show(&text, &items[..1]), "R1 (Parameter) = 0.005 [R] inserts R1=");
}

#[test]
fn nothing_inside_comments_values_or_the_block_number() {
    for program in
        ["%1\nN10 G01 \"G0$0\n", "%1\nN10 G01 X1$0\n", "%1\nN1$0 G01\n", "%1 \"$0\"\nN10\n", "%1\nN10 R1=5$0\n"]
    {
        let (text, items) = completions_with("", &[("main.NCP", program)]);
        assert!(items.is_empty(), "{program:?}: {}", show(&text, &items));
    }
}

/// The text with each inlay hint shown as `⟨label⟩` where it goes.
fn inlays(text: &str, range: Option<TextRange>) -> String {
    let mut host = AnalysisHost::default();
    let file = host.add_file("main.NCP", text);
    let mut shown = text.to_owned();
    for hint in host.analysis().inlay_hints(file, range).iter().rev() {
        shown.insert_str(usize::from(hint.offset), &format!("⟨{}⟩", hint.label));
    }
    shown
}

const PARAMETERS: &str = "%1 \"Parametry – ověření\"
N10 R1=864 R2=-5 R3=0.864 R4=864. R5=0 \"čísla bez tečky jsou tisíciny\"
 R6=100000 R7= +12
N20 XR1 R8=1
";

#[test]
fn inlay_hints_show_what_an_assignment_without_a_point_stores() {
    expect![[r#"
        %1 "Parametry – ověření"
        N10 R1=864⟨= 0.864⟩ R2=-5⟨= -0.005⟩ R3=0.864 R4=864. R5=0 "čísla bez tečky jsou tisíciny"
         R6=100000⟨= 100⟩ R7= +12⟨= 0.012⟩
        N20 XR1 R8=1⟨= 0.001⟩
    "#]]
    .assert_eq(&inlays(PARAMETERS, None));
    let mut host = AnalysisHost::default();
    let file = host.add_file("main.NCP", PARAMETERS);
    let hint = &host.analysis().inlay_hints(file, None)[0];
    assert!(hint.tooltip.as_deref().is_some_and(|t| t.contains("R1=864 stores 0.864")), "{hint:?}");
}

#[test]
fn inlay_hints_cover_the_blocks_the_range_touches() {
    let n20 = TextSize::try_from(PARAMETERS.find("N20").unwrap()).unwrap();
    expect![[r#"
        %1 "Parametry – ověření"
        N10 R1=864 R2=-5 R3=0.864 R4=864. R5=0 "čísla bez tečky jsou tisíciny"
         R6=100000 R7= +12
        N20 XR1 R8=1⟨= 0.001⟩
    "#]]
    .assert_eq(&inlays(PARAMETERS, Some(TextRange::at(n20 + TextSize::from(2), 0.into()))));
    assert_eq!(inlays(PARAMETERS, Some(TextRange::up_to(TextSize::from(3)))), PARAMETERS, "the header only");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Any text, any cursor: answers that stay inside the text, no panic.
    #[test]
    fn completions_and_hints_anywhere(text in prop_oneof![program_text(), block_program(), crowded_lines(), overlong_lines()], at in 0usize..2000) {
        let mut host = AnalysisHost::default();
        let file = host.add_file("main.NCP", text.as_str());
        let analysis = host.analysis();
        let offset = TextSize::try_from(at % (text.len() + 1)).unwrap();
        let end = TextSize::of(text.as_str());
        for item in analysis.completions(file, offset) {
            prop_assert!(item.replace.contains_inclusive(offset) && item.replace.end() <= end, "{item:?}");
        }
        for hint in analysis.inlay_hints(file, Some(TextRange::empty(offset))) {
            prop_assert!(hint.offset <= end);
        }
        let mut host = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
        let file = host.add_file("MAIN.MPF", text.as_str());
        for item in host.analysis().completions(file, offset) {
            prop_assert!(item.replace.contains_inclusive(offset) && item.replace.end() <= end, "{item:?}");
        }
    }
}

/// The completions of a Sinumerik program with `$0` as the cursor, as
/// `label (kind)`.
fn sinumerik_completions(program: &str) -> Vec<String> {
    let mut host = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
    let file = host.add_file("MAIN.MPF", program.replace("$0", ""));
    let offset = TextSize::try_from(program.find("$0").expect("a `$0` cursor")).unwrap();
    host.analysis().completions(file, offset).iter().map(|item| format!("{} ({:?})", item.label, item.kind)).collect()
}

/// Where a word starts: codes, addresses, keywords and functions; in an
/// expression the functions alone; nothing in a comment or a string.
#[test]
fn sinumerik_completion_offers_the_catalogues_words() {
    let items = sinumerik_completions("N10 G0 X0\nGOT$0\n");
    for expected in
        ["G642 (Code)", "X (Address)", "CR (Address)", "GOTOF (Keyword)", "WHILE (Keyword)", "SIN (Function)"]
    {
        assert!(items.iter().any(|item| item == expected), "{expected} in {items:?}");
    }
    let items = sinumerik_completions("G1 X=SI$0\n");
    assert!(items.iter().any(|item| item == "SIN (Function)"), "{items:?}");
    assert!(items.iter().all(|item| item.ends_with("(Function)")), "{items:?}");
    for program in ["G1 X0 ; a G$0\n", "MSG(\"G$0\")\n"] {
        assert_eq!(sinumerik_completions(program), Vec::<String>::new(), "{program}");
    }
}

/// The completions in a workspace of `files`, the cursor at `$0` in the
/// first, as `label (kind): detail`, and the inserted text when it is not
/// the label.
fn sinumerik_workspace_completions(files: &[(&str, &str)]) -> Vec<String> {
    let mut host = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
    let (path, program) = files[0];
    let file = host.add_file(path, program.replace("$0", ""));
    for (path, text) in &files[1..] {
        host.add_file(*path, *text);
    }
    let offset = TextSize::try_from(program.find("$0").expect("a `$0` cursor")).unwrap();
    let text = host.analysis().text(file);
    host.analysis()
        .completions(file, offset)
        .iter()
        .map(|item| {
            assert_eq!(&text[item.replace], &program[usize::from(item.replace.start())..offset.into()]);
            let inserted =
                if item.insert_text == item.label { String::new() } else { format!(" → {}", item.insert_text) };
            format!("{} ({:?}): {}{inserted}", item.label, item.kind, item.detail)
        })
        .collect()
}

const CAM: &str = "PROC CAM(REAL RADIUS, VAR INT COUNT) SAVE
DEF STRING[50] FILE_NAME=\"CAM\"
DEF REAL ANGLE, STEPS[3]
START: ANGLE=0
END_CAM: M17
";

/// After `$` the catalogue's system variables and prefixes; after a jump
/// the file's labels alone; the file's variables and parameters with
/// their types wherever a value goes; where a word starts the programs of
/// the workspace, with their parameters to fill.
#[test]
fn sinumerik_completion_offers_the_files_names() {
    let items = sinumerik_workspace_completions(&[("MAIN.MPF", "R1=$P_$0\n")]);
    assert!(items.iter().any(|item| item.starts_with("$P_F (Variable): ")), "{items:?}");
    assert!(items.iter().any(|item| item.starts_with("$AA_ (Variable): ")), "{items:?}");
    assert!(items.iter().all(|item| item.starts_with('$')), "{items:?}");

    let with_cam = |program: &str| {
        let program = CAM.replace("END_CAM: M17\n", &format!("{program}\nEND_CAM: M17\n"));
        sinumerik_workspace_completions(&[("CAM.SPF", &program)])
    };
    expect![[r#"
        START (Label): label, line 4
        END_CAM (Label): label, line 6"#]]
    .assert_eq(&with_cam("IF ANGLE>1 GOTOB S$0").join("\n"));
    let items = with_cam("ANGLE=RA$0");
    let names: Vec<&String> = items.iter().filter(|item| item.contains("(Variable)")).collect();
    expect![[r#"
        [
            "RADIUS (Variable): REAL",
            "COUNT (Variable): VAR INT",
            "FILE_NAME (Variable): STRING[50]",
            "ANGLE (Variable): REAL",
            "STEPS (Variable): REAL",
        ]
    "#]]
    .assert_debug_eq(&names);

    let files = [("MAIN.MPF", "G0 X0\nCA$0\n"), ("CAM.SPF", CAM), ("_N_PLAIN_SPF", "PROC PLAIN\nM17\n")];
    let items = sinumerik_workspace_completions(&files);
    let programs: Vec<&String> = items.iter().filter(|item| item.contains("(Program)")).collect();
    expect![[r#"
        [
            "CAM (Program): CAM(REAL RADIUS, VAR INT COUNT) → CAM(${1:RADIUS}, ${2:COUNT})",
            "PLAIN (Program): PLAIN()",
        ]
    "#]]
    .assert_debug_eq(&programs);
}

/// A Haas lathe program with contours, calls, a jump and macro variables;
/// `$0` goes in where a test puts it.
const HAAS: &str = "%
O01000 (MAIN)
#100=2.5
#101=#100*2
G00 X50. Z2. (START #7)
G71 P10 Q20 U0.4 W0.1 D2. F0.25
N10 G00 X20.
N15 G01 Z-20.
N20 X50.
G70 P10 Q20
M97 P100
M98 P2000
IF [#100 GT 1] GOTO 30
G01 X#101 Z0
N30 M30
N100 G01 X10.
M99
%
";

/// The completions in a Haas lathe workspace with `HAAS` as `O01000.nc`,
/// `before` replaced by `after` (with its `$0`), beside a program O02000
/// and a file named after program 3000.
fn haas_completions(before: &str, after: &str) -> (String, Vec<CompletionItem>) {
    assert!(HAAS.contains(before), "`{before}` in the program");
    let program = HAAS.replacen(before, after, 1);
    let mut host = AnalysisHost::in_dialect(Dialect::HaasLathe, Config::default());
    let main = host.add_file("O01000.nc", program.replace("$0", ""));
    host.add_file("O02000.nc", "%\nO02000 (SUB)\nG00 X1.\nM99\n%\n");
    host.add_file("O3000.nc", "G01 U-1.\nM99\n");
    let offset = TextSize::try_from(program.find("$0").expect("a `$0` cursor")).unwrap();
    let analysis = host.analysis();
    (analysis.text(main).to_string(), analysis.completions(main, offset))
}

/// P of a contour cycle: the numbered blocks after the cycle; Q: those
/// from the P block on; each with its block's line and what it replaces.
#[test]
fn haas_contour_words_complete_the_blocks_of_the_program() {
    let (text, items) = haas_completions("G71 P10 Q20", "G71 P1$0 Q20");
    expect![[r#"
        P10 (Block) N10 G00 X20. [P1]
        P15 (Block) N15 G01 Z-20. [P1]
        P20 (Block) N20 X50. [P1]
        P30 (Block) N30 M30 [P1]
        P100 (Block) N100 G01 X10. [P1]"#]]
    .assert_eq(&show(&text, &items));
    assert_eq!(items[0].documentation.as_deref(), Some("```text\nN10 G00 X20.\n```"));
    let (_, items) = haas_completions("G70 P10 Q20", "G70 P15 Q$0");
    assert_eq!(labels(&items), "Q15 Q20 Q30 Q100");
    // A P that names no block: Q from the cycle on.
    let (_, items) = haas_completions("G70 P10 Q20", "G70 P99 Q$0");
    assert_eq!(labels(&items), "Q30 Q100");
}

/// M97 P and GOTO name any numbered block of the program; M98 P and G65 P
/// the other programs of the workspace, by `O` line or by file name.
#[test]
fn haas_calls_and_jumps_complete_their_targets() {
    let (_, items) = haas_completions("M97 P100", "M97 P$0");
    assert_eq!(labels(&items), "P10 P15 P20 P30 P100");
    let (text, items) = haas_completions("GOTO 30", "GOTO 3$0");
    expect![[r#"
        10 (Block) N10 G00 X20. [3]
        15 (Block) N15 G01 Z-20. [3]
        20 (Block) N20 X50. [3]
        30 (Block) N30 M30 [3]
        100 (Block) N100 G01 X10. [3]"#]]
    .assert_eq(&show(&text, &items));
    for (call, typed) in [("M98 P$0", "P"), ("G65 P2$0 A1.", "P2")] {
        let (text, items) = haas_completions("M98 P2000", call);
        let expected = format!("P2000 (Program) SUB [{typed}]\nP3000 (Program) G01 U-1. [{typed}]");
        assert_eq!(show(&text, &items), expected, "{call}");
        assert_eq!(items[0].documentation.as_deref(), Some("`O02000.nc`\n\n```text\nO02000 (SUB)\n```"), "{call}");
    }
}

/// After `#`: the variables the program uses, with their values before the
/// block as far as the walk knows them, then those the catalogue
/// documents; a comment's `#7` is no variable.
#[test]
fn haas_variables_complete_with_their_values() {
    let (text, items) = haas_completions("G00 X50. Z2.", "G00 X#10$0 Z2.");
    let shown = show(&text, &items);
    let lines: Vec<&str> = shown.lines().collect();
    let values = ["#10 (Parameter) = vacant [#10]", "#100 (Parameter) = 2.5 [#10]", "#101 (Parameter) = 5 [#10]"];
    assert_eq!(lines[..3], values, "{shown}");
    assert!(items[1].documentation.as_ref().unwrap().ends_with("**Before this block:** 2.5"), "{:?}", items[1]);
    assert!(!labels(&items).split(' ').any(|label| label == "#7"), "{shown}");
    // The documented ranges: short ones in full, long ones by their first.
    assert!(lines.contains(&"#1 (Parameter) Local variables (macro arguments) (#1–#33) [#10]"), "{shown}");
    assert!(labels(&items).split(' ').any(|label| label == "#3001"), "{shown}");
    assert!(
        labels(&items).split(' ').any(|label| label == "#5201")
            && !labels(&items).split(' ').any(|label| label == "#5202"),
        "{shown}"
    );
    // Before the second assignment, the first one holds.
    let (_, items) = haas_completions("#101=#100*2", "#101=#$0100*2");
    assert_eq!(items[..2].iter().map(|item| item.detail.as_str()).collect::<Vec<_>>(), ["= 2.5", "= vacant"]);
    assert_eq!(items[0].replace.len(), TextSize::from(4), "`#100` whole");
}

/// The macro keywords where a statement starts, after a condition, and in
/// expressions: functions where an operand starts, named operators after
/// one.
#[test]
fn haas_keywords_complete_where_the_language_takes_them() {
    let (text, items) = haas_completions("IF [#100 GT 1] GOTO 30", "WH$0");
    expect![[r#"
        IF (Keyword) IF [condition] GOTO n, or IF [condition] THEN #v = e [WH]
        GOTO (Keyword) GOTO n: go on at block Nn [WH]
        WHILE (Keyword) WHILE [condition] DOn … ENDn [WH]
        DO (Keyword) DOn … ENDn: loop n, while the condition of a WHILE before it holds [WH]
        END (Keyword) ENDn: the end of loop n [WH]"#]]
    .assert_eq(&show(&text, &items));
    let (_, items) = haas_completions("GOTO 30", "$0");
    assert_eq!(labels(&items), "THEN GOTO");
    let (_, items) = haas_completions("IF [#100 GT 1] GOTO 30", "WHILE [#100 LT 3] $0");
    assert_eq!(labels(&items), "DO");
    let (_, items) = haas_completions("#101=#100*2", "#101=S$0");
    assert_eq!(labels(&items), "SIN COS TAN ATAN ASIN ACOS SQRT ABS ROUND FIX FUP");
    assert!(items[0].documentation.as_ref().unwrap().contains("SIN"), "{:?}", items[0]);
    let (_, items) = haas_completions("[#100 GT 1]", "[#100 $0GT 1]");
    assert_eq!(labels(&items), "MOD EQ NE GT GE LT LE AND OR XOR");
    // Where a word starts: the addresses, the codes and the statements.
    let (_, items) = haas_completions("N30 M30", "N30 $0M30");
    let found = labels(&items);
    let found: Vec<&str> = found.split(' ').collect();
    for label in ["X", "Z", "#", "G00", "G71", "M98", "IF", "WHILE", "END"] {
        assert!(found.contains(&label), "{label} in {found:?}");
    }
    assert!(!found.contains(&"THEN") && !found.contains(&"Y"), "{found:?}");
    // In a comment, nothing.
    assert!(haas_completions("(START #7)", "(START $0#7)").1.is_empty());
}

/// Completion at every position of Haas texts, whole and broken: no
/// panic, and every item replaces text around the cursor.
#[test]
fn haas_completions_anywhere() {
    let broken =
        "%\nO1 (ÚVOD 🙂\nIF [#1 EQ [SIN[#[#2] GOTO\n#3=#\nWHILE [ DO1\nM98 P-1.5 (x)\nG71 P Q\nN1 END1 #1=ROUND[\r\n";
    for text in [HAAS, broken] {
        let mut host = AnalysisHost::in_dialect(Dialect::HaasLathe, Config::default());
        let file = host.add_file("O00001.nc", text);
        let analysis = host.analysis();
        for offset in (0..=text.len()).filter(|&at| text.is_char_boundary(at)) {
            let offset = TextSize::try_from(offset).unwrap();
            for item in analysis.completions(file, offset) {
                assert!(
                    item.replace.contains_inclusive(offset) && item.replace.end() <= TextSize::of(text),
                    "{item:?}"
                );
            }
        }
    }
}
