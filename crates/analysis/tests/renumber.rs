//! Renumbering: the new numbers and references per dialect, the refusals,
//! and the executor as the oracle: every program of the repository and
//! generated ones run the same before and after.

// Only the numbered programs of the shared strategies are used here.
#[allow(dead_code)]
#[path = "../../syntax/tests/strategies/mod.rs"]
mod strategies;
mod support;

use expect_test::{Expect, expect};
use ncc_analysis::{AnalysisHost, Config, Dialect, RenumberError, TextEdit, TextRange};
use proptest::prelude::*;

fn renumbered(dialect: Dialect, text: &str, start: u64, step: u64) -> Result<String, RenumberError> {
    let mut host = AnalysisHost::in_dialect(dialect, Config::default());
    let file = host.add_file("main", text);
    let edits: Vec<TextEdit> = host.analysis().renumber(file, start, step)?;
    let mut text = text.to_owned();
    for edit in edits.iter().rev() {
        edit.apply(&mut text);
    }
    Ok(text)
}

fn check(dialect: Dialect, text: &str, expect: Expect) {
    let shown = match renumbered(dialect, text, 10, 10) {
        Ok(text) => text,
        Err(error) => format!("refused at {:?} `{}`: {}", error.range, &text[error.range], error.message),
    };
    expect.assert_eq(&shown);
}

#[test]
fn cnc8x6_jumps_follow_their_blocks_and_subprogram_labels_stay() {
    check(
        Dialect::Cnc8x6,
        "%1\nN5 G71 L100 Q1\nN7 R1=2\nN9 G73 L7 Q2\nN11 GR24 L5\nN0020 M30\nN100 G79 L100\nN3 X1 G70\n*\n",
        expect![[r#"
            %1
            N10 G71 L100 Q1
            N20 R1=2
            N30 G73 L20 Q2
            N40 GR24 L10
            N50 M30
            N60 G79 L100
            N70 X1 G70
            *
        "#]],
    );
}

#[test]
fn haas_contours_local_calls_and_gotos_follow_their_blocks() {
    check(
        Dialect::HaasLathe,
        "%\nO1000\nG71 P1 Q2 U0.4 W0.1 D2. F0.25\nN1 G00 X14.\nG01 Z-10.\nN2 X20.\nG70 P1 Q2\nM97 P50\nIF [#1 GT 2] GOTO 2\nM98 P2000\nM30\nN50 G00 X1.\nM99\n%\n",
        expect![[r#"
            %
            O1000
            G71 P10 Q20 U0.4 W0.1 D2. F0.25
            N10 G00 X14.
            G01 Z-10.
            N20 X20.
            G70 P10 Q20
            M97 P30
            IF [#1 GT 2] GOTO 20
            M98 P2000
            M30
            N30 G00 X1.
            M99
            %
        "#]],
    );
}

#[test]
fn sinumerik_jumps_follow_their_blocks_in_their_direction() {
    check(
        Dialect::Sinumerik,
        "N5 R1=0\nN5 R1=R1+1\nIF R1<3 GOTOB N5\nGOTOF N7\nN9 LAB1: G0 X1\n:12 G1 X2\nN7 M30\n",
        expect![[r#"
            N10 R1=0
            N20 R1=R1+1
            IF R1<3 GOTOB N20
            GOTOF N50
            N30 LAB1: G0 X1
            :40 G1 X2
            N50 M30
        "#]],
    );
}

#[test]
fn computed_missing_and_ambiguous_targets_are_refused() {
    check(
        Dialect::Cnc8x6,
        "%1\nN1 G73 LR5\nN2 M30\n",
        expect![
            "refused at 10..13 `LR5`: the jump's target is a parameter, known only when the program runs: renumbering could break it"
        ],
    );
    check(
        Dialect::Cnc8x6,
        "%1\nN1 G73 L9\nN2 M30\n",
        expect![
            "refused at 10..12 `L9`: no block of the jump's unit has this number: renumbering could make it lead somewhere"
        ],
    );
    check(
        Dialect::HaasLathe,
        "GOTO #1\nN1 M30\n",
        expect!["refused at 0..7 `GOTO #1`: the target is computed when the program runs: renumbering could break it"],
    );
    check(
        Dialect::HaasLathe,
        "M97 P5\nN1 M30\nN1 M99\n",
        expect![
            "refused at 4..6 `P5`: no block of the program has this number: renumbering could make it lead somewhere"
        ],
    );
    check(
        Dialect::HaasLathe,
        "M97 P1\nM30\nN1 G0 X1\nN1 M99\n",
        expect!["refused at 4..6 `P1`: several blocks of the program have this number: number them apart first"],
    );
    check(
        Dialect::HaasLathe,
        "N1 G0 X1\nM99 P1\n",
        expect![
            "refused at 13..15 `P1`: `M99 P` returns to a block of the calling program, which may be another file's: renumber by hand"
        ],
    );
    check(
        Dialect::Sinumerik,
        "GOTOF \"N\"<<R3\nN10 M30\n",
        expect![[
            r#"refused at 0..13 `GOTOF "N"<<R3`: the jump's target is computed when the program runs: renumbering could break it"#
        ]],
    );
    check(
        Dialect::Sinumerik,
        "N10 G0 X1\nGOTOF N10\nM30\n",
        expect![
            "refused at 16..19 `N10`: no block in the jump's direction has this number: renumbering could make it lead somewhere"
        ],
    );
}

#[test]
fn a_number_the_address_cannot_hold_is_refused() {
    let error = renumbered(Dialect::Cnc8x6, "%1\nN1 X1\nN2 M30\n", 99_999_999, 1).unwrap_err();
    assert_eq!(error.message, "2 blocks from 99999999 by 1 pass the largest number, 99999999");
    let error = renumbered(Dialect::Cnc8x6, "%1\nN1 X1\nN2 M30\n", 0, 1).unwrap_err();
    assert_eq!(error.message, "block numbers start at 1, so renumbering cannot start from 0");
    assert_eq!(error.range, TextRange::new(4.into(), 5.into()));
}

/// Renumbering `text` either is refused or leaves its run as it was, and
/// renumbering again with the same numbers changes nothing.
fn check_keeps_the_run(dialect: Dialect, text: &str, start: u64, step: u64) -> Result<bool, String> {
    let Ok(new) = renumbered(dialect, text, start, step) else { return Ok(false) };
    if support::run_of(dialect, text) != support::run_of(dialect, &new) {
        return Err(format!("the run changed: {new:?}"));
    }
    match renumbered(dialect, &new, start, step) {
        Ok(again) if again == new => Ok(new != text),
        again => Err(format!("not stable: {new:?} → {again:?}")),
    }
}

#[test]
fn renumbering_keeps_the_run_of_every_program_of_the_repository() {
    let mut failures = Vec::new();
    let mut renumbered = [0; 3];
    for (path, dialect) in support::repository_programs() {
        let Ok(text) = std::fs::read_to_string(&path) else { continue };
        for (start, step) in [(10, 10), (1, 1), (1000, 5)] {
            match check_keeps_the_run(dialect, &text, start, step) {
                Ok(changed) => renumbered[dialect as usize] += usize::from(changed && start == 1),
                Err(error) => failures.push(format!("{} from {start} by {step}: {error}", path.display())),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Enough programs of each dialect are renumbered to prove something.
    assert!(renumbered.iter().all(|&count| count >= 5), "renumbered per dialect: {renumbered:?}");
}

/// Pieces of numbered programs with jumps, glued at random.
const HAAS_PIECES: &[&str] = &[
    "N10 ",
    "N20 ",
    "N30 ",
    "G00 X20.\n",
    "G01 Z-2. F0.2\n",
    "#1=#1+1\n",
    "IF [#1 LT 3] GOTO10\n",
    "GOTO30\n",
    "G71 P10 Q20 U0.4 W0.1 D2. F0.25\n",
    "G70 P10 Q20\n",
    "M97 P30\n",
    "M99\n",
    "M30\n",
    "\n",
];
const SINUMERIK_PIECES: &[&str] = &[
    "N10 ",
    "N20 ",
    "N30 ",
    ":40 ",
    "G0 X10\n",
    "G1 Y5 F100\n",
    "R1=R1+1\n",
    "IF R1<3 GOTOB N10\n",
    "GOTOF N30\n",
    "GOTO N20\n",
    "GOTOC N40\n",
    "LAB: ",
    "GOTOF LAB\n",
    "M30\n",
    "\n",
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn renumbering_keeps_the_run_of_generated_programs(
        (dialect, text) in prop_oneof![
            strategies::block_program().prop_map(|text| (Dialect::Cnc8x6, text)),
            prop::collection::vec(prop::sample::select(HAAS_PIECES), 0..40)
                .prop_map(|pieces| (Dialect::HaasLathe, pieces.concat())),
            prop::collection::vec(prop::sample::select(SINUMERIK_PIECES), 0..40)
                .prop_map(|pieces| (Dialect::Sinumerik, pieces.concat())),
        ],
        (start, step) in (0u64..1000, 1u64..100),
    ) {
        check_keeps_the_run(dialect, &text, start, step).map_err(TestCaseError::fail)?;
    }
}
