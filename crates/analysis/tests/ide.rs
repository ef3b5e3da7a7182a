//! Hover and go to definition. `$0` in a program marks the cursor.

use expect_test::{Expect, expect};
use ncc_analysis::{AnalysisHost, FileId, TextSize};

/// The host with `files` added (the first one holds the cursor), the file
/// and the cursor offset.
fn setup(files: &[(&str, &str)]) -> (AnalysisHost, FileId, TextSize, Vec<FileId>) {
    let mut host = AnalysisHost::default();
    let mut cursor = None;
    let mut ids = Vec::new();
    for (path, text) in files {
        let offset = text.find("$0");
        let text = text.replace("$0", "");
        let id = host.add_file(*path, text.as_str());
        if let Some(offset) = offset {
            cursor = Some((id, TextSize::try_from(offset).unwrap()));
        }
        ids.push(id);
    }
    let (file, offset) = cursor.expect("a `$0` cursor");
    (host, file, offset, ids)
}

fn check_hover(files: &[(&str, &str)], expect: Expect) {
    let (host, file, offset, _) = setup(files);
    let analysis = host.analysis();
    let hover = analysis.hover(file, offset).expect("a hover");
    let text = analysis.text(file);
    let shown = format!("[{}]\n{}", &text[hover.range], hover.markdown);
    expect.assert_eq(&shown);
}

/// Go to definition, as `path: the target's text | the focus's text`.
fn check_goto(files: &[(&str, &str)], expect: Expect) {
    let (host, file, offset, _) = setup(files);
    let analysis = host.analysis();
    let targets: Vec<String> = analysis
        .goto_definition(file, offset)
        .iter()
        .map(|target| {
            let text = analysis.text(target.file);
            format!("{}: {} | {}", analysis.path(target.file), text[target.range].trim_end(), &text[target.focus])
        })
        .collect();
    expect.assert_eq(&targets.join("\n"));
}

const PROGRAM: &str = "%1\nN10 G90 R12=864 R13=5.\nN20 G01 XR12 F100\nN30 G71 L100 Q2\nN40 M30\nN100 G79 L100\nN110 G91 YR13\nN120 G70\n*\n";

fn at(text: &str, needle: &str) -> String {
    let at = text.find(needle).unwrap_or_else(|| panic!("`{needle}` in the program"));
    format!("{}$0{}", &text[..at], &text[at..])
}

/// The hovered text and the hover's first line, with the cursor on `needle`.
fn hover_heading(needle: &str) -> (String, String) {
    let (host, file, offset, _) = setup(&[("main.NCP", &at(PROGRAM, needle))]);
    let hover = host.analysis().hover(file, offset).expect("a hover");
    let heading = hover.markdown.lines().next().unwrap_or_default().to_owned();
    (host.analysis().text(file)[hover.range].to_owned(), heading)
}

#[test]
fn hover_on_a_code_or_an_address_shows_its_documentation() {
    let (hovered, heading) = hover_heading("01 XR12");
    assert_eq!(hovered, "G01");
    assert!(heading.starts_with("### G01"), "{heading}");
    let (hovered, heading) = hover_heading("F100");
    assert_eq!(hovered, "F100");
    assert!(heading.starts_with("### F"), "{heading}");
    let (hovered, heading) = hover_heading("M30");
    assert_eq!(hovered, "M30");
    assert!(heading.starts_with("### M30"), "{heading}");
}

#[test]
fn hover_on_a_parameter_shows_its_value_there() {
    check_hover(
        &[("main.NCP", &at(PROGRAM, "R12 F100"))],
        expect![[r#"
            [R12]
            ### R12 — program parameter (General-purpose parameters)

            Program parameter 12 of R0–R95.

            **General-purpose parameters** (ordinary): Parameters without a fixed role, free for declarations, substitution and parameter arithmetic.

            These parameters have no role of their own. Keep in mind:
            - The supplied fixed cycles take their inputs in parameters of this range (for example `R26`–`R32` in the milling drilling cycles) and use others as working storage; see the cycles catalogue.
            - When double precision is enabled, the control words of parameter arithmetic can name only `R0`–`R49` individually; fields 50–99 then mean 64-bit pairs, so `R50`–`R89` cannot be reached by the arithmetic in that mode.
            - `R80` (like `R0`) must not be chosen as the thread-angle parameter named by machine constant 8; the manual's thread examples use `R15` (run-out) and `R16` (lead-in).

            Ninety-six numeric registers that a program fills with `Rn=value` and substitutes for the value of almost any address with `<address>Rn`.

            **Numbering.** The control has 96 parameters, `R0` to `R95` (since panel software 30.08 of 10.9.1999). A leading zero is allowed in the number (`R05`). Some have roles: `R0`–`R4` in `G92 D…` blocks, `R5`–`R8` as control words of `G26`–`G29`; `R90`–`R94` are reserved for future control parameters and `R95` must not be used. The manual also writes machine constants as `R39`, `R283`, `R329`; those are configuration of the control (TAB0.REK), not program parameters.

            **Declaration.** `Rn=value` stores a value, for example `N10 R1=864 R2=-0.864 R3=100000`. A block may hold several declarations, also together with other words (`N4 R3=15 M03 M42 M08`). `R` is the only address that may occur more than once in a block, at most 95 times. The manual's examples put spaces around `=` (`R04= -00120.000`, `R2 =200.`); they are accepted (inferred). The value must be a literal number, optionally signed: `R` cannot itself take a parameter, so `R1=R2` is not a declaration (inferred); parameter arithmetic copies values.

            **Thousandths rule.** Parameter values are dimensionless numbers with three decimals. A value **without a decimal point counts thousandths**: `R1=864` stores 0.864, `R3=100000` stores 100.000, `R20=250` stores 0.250, `R31=1` stores 0.001. A value with a point is taken as written: `R11=100.` stores 100.000, `R2=-0.864` stores −0.864. `R20=120` and `R20=0.120` therefore store the same value.

            **Range.** −69999.999 to +69999.999. The value must also be admissible for the address where the parameter will be used. Digit limits of a declaration (inferred from the range and the `+5.3` format): without a point at most eight digits (at most 69999999 thousandths), with a point at most five integer and three fractional digits.

            **Use.** Write `R` and the parameter number straight after an address letter instead of a value: `XR1`, `GR31`, `SR20`, `TR3`, `FR10`, `QR12`. Every address may be given a value this way **except four: `N`, `/`, `R` and the function `G79`**. When the address is processed, the value last declared in a preceding block is substituted. Whether a declaration in the same block is already visible is not stated. The manual never writes a blank between the letter and `R`, nor a sign in front of `R`, so neither form is documented.

            **How an address reads the stored value.**
            - *Dimensional addresses* (X, Y, Z, U, V, W, I, J, K; A, B, C in degrees, inferred) read the stored value in millimetres. A parameter declared without a point is therefore in micrometres: after `R10=100 R11=100. R12=0.100`, the block `N50 XR10 YR11 ZR12` moves X to 0.1 mm, Y to 100 mm and Z to 0.1 mm, whereas a literal `X100` is 100 mm. The manual recommends declaring lengths with a decimal point.
            - *Dimensionless addresses* (G, M, S, T, D, H, P and the like) take the raw digits: after `R20=120 R21=40 R22=12345678`, the block `SR20 GR21 TR22` sends `S120`, cancels compensation with `G40` and sends `T12345678`. Declaring `R20=0.120 R21=0.040 R22=12345.678` means the same, but the manual recommends writing such values without a point.
            - *Feed `F`* reads the raw thousandths as mm/min: `R10=100` and `R10=0.100` both give 100 mm/min (0.1 m/min) with `FR10`, while `R10=100.` means 100 m/min, more than the system allows. A parameter also carries thread leads above the 99.99 mm/rev a literal F allows: `R10=250.0` and `G33 … FR10` cut a 250 mm lead (under feed per revolution the raw value counts µm/rev, inferred).

            **Digit overflow.** A parameter whose raw value has more decades than the address takes cannot be substituted. After `N10 R10=123`, the block `N20 GR10` stops at execution with "Do dvoudekádové adresy nelze dosadit R o více než 2 dekádách" (an R of more than two decades cannot be substituted into a two-decade address), because G takes two decades and 0.123 has three. The manual shows only this case; the project applies the rule to every address by its digit count: two for G, M, D, H, P; four for S, L, Q, &; eight for T (inferred generalisation). A dimensionless value declared with a point is a typical cause: `R21=40.` holds 40000 thousandths and overflows `GR21` (inferred).

            **No check at load time.** Loading a program does not validate parameter values; they are the programmer's responsibility, and the control detects a bad value only while executing the block that uses it. A static checker can report them early where the value is known before the run.

            **Double precision.** In parameter arithmetic (`G26`–`G29`) some operations can read a 64-bit operand from two consecutive parameters n and n+1; the control word then names the parameter number increased by 50. The program therefore chooses between two modes:

            | Mode | Parameter fields in control words | Precision |
            |---|---|---|
            | double precision disabled | 0–95 | 32 bit |
            | double precision enabled | 0–49 single; 50–99 = pairs of 0–49 | 32 / 64 bit |

            Decade 4 of machine constant 283 selects: 0 = parameters 0–49 with double precision, 1 = parameters 0–95 without, 2 = decided at run time by **decade 1 of `R95`** (0 = 0–49 with double precision, 1 = 0–95 without). The recommended instructions are `R5=48110095 G26` (set decade 1 of R95 to 1) and `R5=48210095 G26` (clear it to 0). The layout of a 64-bit pair is not documented, nor whether `R50`–`R95` stay usable for ordinary declarations while double precision is on.

            **Typical uses.** Values declared in the calling program and read inside fixed cycles, macrocycles and subprograms; parameter arithmetic; declarations and uses in ordinary blocks are allowed too.

            Example:

            ```
            N620 G54 G00 X0 Y0 R1=864 R2=-0.864 R3=100000 R20=250 R31=1
            ```

            Manual: Chapter 9, Parametric programming - function R (Declaration of parameters; Invocation of parameters; Decimal point in parameter declarations); Chapter 11, Common rules; Double-precision control; Chapter 2, Address dictionary


            **Value before this block:** `0.864` (864 thousandths)

            ---

            **Modal state before this block:** `G01 G17 G98 G40 G53 G94 G70 G80 G90 G34` · F`0` · S`0` · T unknown · D unknown"#]],
    );
}

#[test]
fn hover_in_a_subprogram_shows_the_value_of_each_call() {
    let text =
        "%1\nN10 R2=5.\nN20 G71 L100\nN30 R2=7.\nN40 G71 L100\nN50 M30\nN100 G79 L100\nN110 G91 YR$02\nN120 G70\n*\n";
    let (host, file, offset, _) = setup(&[("main.NCP", text)]);
    let hover = host.analysis().hover(file, offset).unwrap();
    assert!(
        hover.markdown.contains(
            "**Values before this block** (one per call): `5` (5000 thousandths), `7` (7000 thousandths)\n\n---"
        ),
        "{}",
        hover.markdown
    );
}

#[test]
fn hover_after_a_loop_shows_the_value_the_loop_left() {
    // N20 runs 123 times, counting R10 up by one each time.
    let text = "%1\nN10 R10=0\nN20 G26 R5=-41100010\nN30 G73 L20 Q122\nN40 GR$010\nN50 M30\n*\n";
    let (host, file, offset, _) = setup(&[("main.NCP", text)]);
    let hover = host.analysis().hover(file, offset).unwrap();
    assert!(hover.markdown.contains("**Value before this block:** `0.123` (123 thousandths)"), "{}", hover.markdown);
}

#[test]
fn hover_on_a_call_says_where_it_goes() {
    let (host, file, offset, _) = setup(&[("main.NCP", &at(PROGRAM, "L100 Q2"))]);
    let hover = host.analysis().hover(file, offset).unwrap();
    assert!(hover.markdown.starts_with("Calls subprogram L100.\n\n### L"), "{}", hover.markdown);
    let missing = PROGRAM.replace("G71 L100", "G71 L$0300");
    let (host, file, offset, _) = setup(&[("main.NCP", &missing)]);
    let hover = host.analysis().hover(file, offset).unwrap();
    assert!(hover.markdown.starts_with("Calls subprogram L300, which does not exist."), "{}", hover.markdown);
}

#[test]
fn no_hover_between_blocks_or_on_comments() {
    let text = "%1 \"NAME\"\nN10 G00 X0 \"a com$0ment\"\nN20 M30\n";
    let (host, file, offset, _) = setup(&[("main.NCP", text)]);
    assert_eq!(host.analysis().hover(file, offset), None);
    let (host, file, offset, _) = setup(&[("main.NCP", "%1 \"NA$0ME\"\nN10 M30\n")]);
    assert_eq!(host.analysis().hover(file, offset), None);
}

#[test]
fn goto_a_subprogram() {
    check_goto(&[("main.NCP", &at(PROGRAM, "L100 Q2"))], expect!["main.NCP: N100 G79 L100 | N100"]);
    check_goto(&[("main.NCP", &at(PROGRAM, "G71"))], expect!["main.NCP: N100 G79 L100 | N100"]);
}

#[test]
fn goto_a_macrocycle_file() {
    check_goto(
        &[("main.NCP", "%1\nN10 G72 L$09001\nN20 M30\n"), ("macros/L9001", "\"DRILL\"\nN1 G79 L9001\nN2 G70\n")],
        expect!["macros/L9001: N1 G79 L9001 | N1"],
    );
}

#[test]
fn goto_a_jump_target_in_the_same_unit() {
    let text = "%1\nN10 G00 X0\nN20 G73 L$010 Q3\nN30 M30\nN100 G79 L100\nN10 G70\n*\n";
    check_goto(&[("main.NCP", text)], expect!["main.NCP: N10 G00 X0 | N10"]);
}

#[test]
fn goto_the_assignments_a_parameter_comes_from() {
    check_goto(&[("main.NCP", &at(PROGRAM, "R12 F100"))], expect!["main.NCP: 864 | 864"]);
    let text =
        "%1\nN10 R2=5.\nN20 G71 L100\nN30 R2=7.\nN40 G71 L100\nN50 M30\nN100 G79 L100\nN110 G91 YR$02\nN120 G70\n*\n";
    check_goto(
        &[("main.NCP", text)],
        expect![[r#"
        main.NCP: 5. | 5.
        main.NCP: 7. | 7."#]],
    );
}

#[test]
fn goto_on_an_unknown_parameter_finds_nothing() {
    check_goto(&[("main.NCP", "%1\nN10 G01 XR$07 F100\nN20 M30\n")], expect![""]);
}

#[test]
fn the_state_at_a_block_follows_each_call() {
    let text = "%1\nN10 G90 G00 X0 R2=5.\nN20 G01 X5. F100\nN30 G71 L100\nN40 F250 R2=7.\nN50 G71 L100\nN60 M30\nN100 G79 L100\nN110 G91 YR2\nN120 G70\n*\n";
    let (host, file, offset, _) = setup(&[("main.NCP", &text.replace("N110", "$0N110"))]);
    let states = host.analysis().states_at(file, offset);
    let seen: Vec<(String, Option<i64>, Option<i64>)> = states
        .iter()
        .map(|(modal, params)| {
            let feed = match &modal.feed {
                ncc_analysis::Known::Is(Some(setting)) => setting.value.to_string(),
                other => format!("{other:?}"),
            };
            (feed, params.get(2).map(|(raw, _)| raw), modal.position(b'X'))
        })
        .collect();
    assert_eq!(
        seen,
        [("100".to_owned(), Some(5000), Some(5000)), ("250".to_owned(), Some(7000), Some(5000))],
        "one state per call, each with the caller's feed, parameters and position"
    );
}
