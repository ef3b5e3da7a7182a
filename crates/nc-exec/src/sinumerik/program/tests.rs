use std::fmt::Write;

use expect_test::{Expect, expect};

use super::*;
use crate::sinumerik::lower::{JumpTarget, tests::lower_text};

fn listing(name: &str) -> String {
    let path = format!("{}/../syntax/test_data/sinumerik/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|error| panic!("{path}: {error}"))
}

fn model_of(text: &str) -> SinumerikModel {
    SinumerikModel::new(&lower_text(text))
}

/// Block indices are shown as lines, from 1.
fn show_model(model: &SinumerikModel) -> String {
    let mut out = String::new();
    let line = |block: usize| block + 1;
    if let Some(header) = model.header() {
        let proc = &header.declaration;
        let parameters: Vec<String> = proc
            .parameters
            .iter()
            .map(|p| {
                format!(
                    "{}{:?} {}",
                    if p.by_reference { "VAR " } else { "" },
                    p.ty.base,
                    p.name.as_deref().unwrap_or("-")
                )
            })
            .collect();
        writeln!(out, "proc {} ({}) {:?} at {}", proc.name, parameters.join(", "), proc.attributes, line(header.block))
            .unwrap();
    }
    for declaration in &model.externs {
        let extern_ = &declaration.declaration;
        let types: Vec<String> = extern_.parameters.iter().map(|p| format!("{:?}", p.ty.base)).collect();
        writeln!(out, "extern {}({}) at {}", extern_.name, types.join(", "), line(declaration.block)).unwrap();
    }
    for definition in &model.definitions {
        writeln!(
            out,
            "def {:?} {} dims {} at {}",
            definition.ty.base,
            definition.declared.name,
            definition.declared.dimensions.len(),
            line(definition.block)
        )
        .unwrap();
    }
    for (label, blocks) in &model.labels {
        writeln!(out, "label {label} at {:?}", blocks.iter().copied().map(line).collect::<Vec<_>>()).unwrap();
    }
    for (number, blocks) in model.block_numbers.iter() {
        writeln!(out, "N{number} at {:?}", blocks.iter().copied().map(line).collect::<Vec<_>>()).unwrap();
    }
    for structure in &model.structures {
        let middle = structure.middle.map_or(String::new(), |m| format!(" else {}", line(m)));
        writeln!(
            out,
            "{:?} {}..{}{middle} depth {}",
            structure.kind,
            line(structure.start),
            line(structure.end),
            structure.depth
        )
        .unwrap();
    }
    for unmatched in &model.unmatched {
        writeln!(out, "unmatched {:?} {:?} at {}", unmatched.kind, unmatched.problem, line(unmatched.block)).unwrap();
    }
    for site in &model.jumps {
        let resolved = match site.resolved {
            Resolved::Block(block) => format!("line {}", line(block)),
            other => format!("{other:?}"),
        };
        writeln!(out, "{:?} at {} -> {resolved}", site.jump.kind, line(site.block)).unwrap();
    }
    for call in &model.calls {
        let modal = if call.modal { " modal" } else { "" };
        let callee = call.callee.program_name().map_or_else(|| format!("{:?}", call.callee), str::to_owned);
        writeln!(out, "call {callee} with {} at {}{modal}", call.arguments, line(call.block)).unwrap();
    }
    out
}

fn check(text: &str, expect: Expect) {
    expect.assert_eq(&show_model(&model_of(text)));
}

/// Every seed listing's structures close and its jumps reach a block
/// (or are computed).
#[test]
fn seed_listings_are_balanced_and_resolved() {
    let names = [
        "l19_profil_main.mpf",
        "l19_profil_sub.spf",
        "l24_igs_splines_output.spf",
        "l25_podpis_janskacel.mpf",
        "l26_krivky_y_const.spf",
        "l27_krivky_x_const_a_rot.spf",
        "l28_krivky_y_const_hrub.spf",
        "l29_blob_souradnice_dole.mpf",
        "l30_run_vacka.mpf",
        "l31_vacka_cyklus.spf",
    ];
    for name in names {
        let model = model_of(&listing(name));
        assert_eq!(model.unmatched, [], "{name}");
        // L28's block N30 is in the part the seed elides.
        let elided =
            |site: &&JumpSite| name.starts_with("l28") && site.jump.target == Some(JumpTarget::BlockNumber(Some(30)));
        for site in model.jumps.iter().filter(|site| !elided(site)) {
            assert!(
                matches!(site.resolved, Resolved::Block(_) | Resolved::Computed),
                "{name}: the jump at block {} is {:?}",
                site.block,
                site.resolved
            );
        }
    }
}

#[test]
fn l19_main_calls_profil_which_declares_five_parameters() {
    check(
        &listing("l19_profil_main.mpf"),
        expect![[r#"
            def Int DELKA dims 0 at 4
            N60 at [4]
            N65 at [5]
            N70 at [6]
            N100 at [8]
            call PROFIL with 4 at 6
        "#]],
    );
    check(
        &listing("l19_profil_sub.spf"),
        expect![[r#"
            proc PROFIL (Real C, Bool H, Real X, Int Y, Real Z) [] at 4
            N30 at [6]
            N100 at [8]
        "#]],
    );
}

#[test]
fn l29_jumps_by_label_block_number_and_computed_target() {
    check(
        &listing("l29_blob_souradnice_dole.mpf"),
        expect![[r#"
            label END at [104]
            label FINIS at [43]
            label HRUBOVANI at [32]
            label PREDBEZNE at [23]
            N1 at [58]
            N2 at [66]
            N3 at [73]
            N4 at [81]
            N5 at [87]
            N101 at [118]
            N102 at [120]
            N103 at [122]
            N1652 at [126]
            N1653 at [128]
            N1654 at [130]
            N1701 at [132]
            N1702 at [134]
            N6552 at [138]
            N6553 at [140]
            N6554 at [142]
            If 24..28 else 26 depth 1
            If 33..42 depth 1
            If 59..65 else 62 depth 1
            If 67..71 depth 1
            If 74..80 else 77 depth 1
            If 82..86 depth 1
            If 90..92 depth 1
            If 95..99 else 97 depth 1
            If 107..113 depth 1
            GotoF at 41 -> line 58
            Goto at 61 -> line 66
            GotoF at 70 -> Computed
            GotoF at 72 -> line 87
            Goto at 76 -> line 81
            GotoF at 85 -> Computed
            GotoF at 88 -> line 104
            GotoF at 102 -> Computed
            GotoB at 112 -> line 23
            GotoB at 119 -> Computed
            GotoB at 121 -> Computed
            GotoB at 123 -> Computed
            GotoB at 127 -> Computed
            GotoB at 129 -> Computed
            GotoB at 131 -> Computed
            GotoB at 133 -> Computed
            GotoB at 135 -> Computed
            GotoB at 139 -> Computed
            GotoB at 141 -> Computed
            GotoB at 143 -> Computed
            call CYCLE800 with 15 at 21
            call CYCLE832 with 3 at 48
        "#]],
    );
}

#[test]
fn l30_l31_cam_program_and_its_cycle() {
    check(
        &listing("l30_run_vacka.mpf"),
        expect![[r#"
            proc RUN_VACKA () [] at 3
            extern VACKA_CYKLUS(Real, Real, Real) at 4
            def Real POCATECNI_R dims 0 at 5
            def Real TLOUSTKA dims 0 at 5
            def Real INKREMENT_UHLU dims 0 at 5
            def Real UHEL_1 dims 0 at 6
            def Real RADIUS_1 dims 0 at 6
            def Real UHEL_2 dims 0 at 6
            def Real RADIUS_2 dims 0 at 6
            def Real UHEL_3 dims 0 at 6
            def Real RADIUS_3 dims 0 at 6
            def Real UHEL_4 dims 0 at 6
            def Real RADIUS_4 dims 0 at 6
            def Real UHEL_5 dims 0 at 6
            def Real RADIUS_5 dims 0 at 6
            If 29..32 depth 1
            If 34..38 depth 1
            call CYCLE800 with 16 at 18
            call VACKA_CYKLUS with 3 at 36
            call _N_GEOMETRIE_VACKA_SPF with 0 at 39
        "#]],
    );
    check(
        &listing("l31_vacka_cyklus.spf"),
        expect![[r#"
        proc VACKA_CYKLUS (Real POCATECNI_R, Real TLOUSTKA, Real INKREMENT_UHLU) ["SAVE"] at 3
        def Real AKT_R dims 0 at 4
        def Real AKT_UHEL dims 0 at 4
        def Real AKT_X dims 0 at 4
        def Real AKT_Y dims 0 at 4
        def Real KONECNY_UHEL dims 0 at 4
        def Real DELTA_R dims 0 at 4
        def Real VAR_I dims 0 at 4
        def String DEBURGER dims 0 at 5
        def String PROGRAM dims 0 at 6
        def Int ERROR dims 0 at 7
        label COUNTER at [83]
        label END at [98]
        label KRUH at [87]
        label TEST_POKRACOVANI at [64]
        N21 at [21]
        N22 at [23]
        N23 at [25]
        N24 at [27]
        N25 at [29]
        N26 at [31]
        N27 at [33]
        N28 at [35]
        N29 at [37]
        If 13..15 depth 1
        If 19..39 depth 1
        While 74..82 depth 2
        For 60..86 depth 1
        GotoF at 20 -> line 21
        GotoF at 20 -> line 23
        GotoF at 20 -> line 25
        GotoF at 20 -> line 27
        GotoF at 20 -> line 29
        GotoF at 20 -> line 31
        GotoF at 20 -> line 33
        GotoF at 20 -> line 35
        GotoF at 20 -> line 37
        GotoF at 65 -> line 98
        GotoF at 69 -> line 87
        GotoB at 96 -> line 83
    "#]],
    );
}

#[test]
fn unbalanced_structures_are_listed() {
    check(
        "IF R1==1\n\
         WHILE R2<3\n\
         ENDIF\n\
         ELSE\n\
         ENDWHILE\n\
         FOR R3=1 TO 2\n\
         IF R1\n\
         ELSE\n\
         ELSE\n\
         ENDIF\n\
         UNTIL R1>2\n\
         LOOP\n",
        expect![[r#"
            If 1..3 depth 1
            If 7..10 else 8 depth 2
            unmatched While NotClosed at 2
            unmatched If StrayElse at 4
            unmatched While NotOpened at 5
            unmatched If StrayElse at 9
            unmatched Repeat NotOpened at 11
            unmatched For NotClosed at 6
            unmatched Loop NotClosed at 12
        "#]],
    );
}

/// Siemens's own cycles close a one-line conditional jump with ENDIF,
/// words and comments between them, where no block IF is open; the
/// documented form without ENDIF stays a jump of its own, and an open
/// block IF takes the ENDIF after one.
#[test]
fn an_endif_after_a_one_line_jump_closes_it() {
    check(
        "IF R1==1 GOTOF END\n\
         ENDIF\n\
         IF R1==2 GOTOF END\n\
         H41=5 ; a comment\n\
         ENDIF\n\
         IF R2\n\
         IF R1==3 GOTOF END\n\
         WHILE R3<2\n\
         ENDWHILE\n\
         ENDIF\n\
         IF R4\n\
         IF R1==4 GOTOF END\n\
         ENDIF\n\
         END:\n",
        expect![[r#"
            label END at [14]
            If 1..2 depth 1
            If 3..5 depth 1
            While 8..9 depth 2
            If 6..10 depth 1
            If 11..13 depth 1
            GotoF at 1 -> line 14
            GotoF at 3 -> line 14
            GotoF at 7 -> line 14
            GotoF at 12 -> line 14
        "#]],
    );
}

#[test]
fn jumps_search_in_their_direction() {
    check(
        "N10 LBL: G1 X1\n\
         GOTOF LBL\n\
         GOTOB LBL\n\
         GOTO N10\n\
         N10 LBL: G1 X2\n\
         GOTOF N20\n\
         GOTOC MISSING\n\
         GOTO MISSING\n\
         GOTOS\n\
         GOTOF \"N\"<<R3\n\
         AGAIN: GOTOB AGAIN\n\
         CASE R1 OF 1 GOTOB LBL DEFAULT GOTOF END\n\
         END: M30\n",
        expect![[r#"
            label AGAIN at [11]
            label END at [13]
            label LBL at [1, 5]
            N10 at [1, 5]
            GotoF at 2 -> line 5
            GotoB at 3 -> line 1
            Goto at 4 -> line 5
            GotoF at 6 -> NotFound { alarm: true }
            GotoC at 7 -> NotFound { alarm: false }
            Goto at 8 -> NotFound { alarm: true }
            GotoS at 9 -> Start
            GotoF at 10 -> Computed
            GotoB at 11 -> line 11
            GotoB at 12 -> line 5
            GotoF at 12 -> line 13
        "#]],
    );
}

#[test]
fn resolve_is_what_the_model_lists() {
    let model = model_of("GOTOF AB\nAB: GOTOB AB\n");
    for site in &model.jumps {
        assert_eq!(model.resolve(site.block, &site.jump), site.resolved);
    }
    assert_eq!(model.jumps_from(1).map(|site| site.resolved).collect::<Vec<_>>(), [Resolved::Block(1)]);
    assert_eq!(model.structures_at(0).count(), 0);
}

proptest::proptest! {
    /// Any bytes lower and make a model; every jump the model lists is
    /// resolved as `resolve` says.
    #[test]
    fn any_bytes_make_a_model(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..200)) {
        let model = model_of(&String::from_utf8_lossy(&bytes));
        for site in &model.jumps {
            proptest::prop_assert_eq!(model.resolve(site.block, &site.jump), site.resolved);
        }
    }

    #[test]
    fn any_structure_soup_makes_a_model(lines in proptest::collection::vec(proptest::sample::select(vec![
        "IF R1", "ELSE", "ENDIF", "WHILE R1", "ENDWHILE", "FOR R1=1 TO 2", "ENDFOR", "REPEAT", "UNTIL R1",
        "LOOP", "ENDLOOP", "AB:", "N10", "GOTOF AB", "GOTOB N10", "GOTO AB", "GOTOC N10", "IF R1 GOTOB AB",
        "CASE R1 OF 1 GOTOF AB DEFAULT GOTOB N10", "PROC P(REAL X)", "DEF INT I[2]", "PROFIL(1,,2)",
    ]), 0..40)) {
        let model = model_of(&(lines.join("\n") + "\n"));
        // Every start and every end is in a structure or listed unmatched.
        let count = |of: &[&str]| lines.iter().filter(|line| of.contains(line)).count();
        let problems = |problem| model.unmatched.iter().filter(|u| u.problem == problem).count();
        // A one-line jump starts a structure where an ENDIF closes it.
        let closed_jumps = model.structures.iter().filter(|s| lines[s.start] == "IF R1 GOTOB AB").count();
        let starts = count(&["IF R1", "WHILE R1", "FOR R1=1 TO 2", "REPEAT", "LOOP"]) + closed_jumps;
        let ends = count(&["ENDIF", "ENDWHILE", "ENDFOR", "UNTIL R1", "ENDLOOP"]);
        proptest::prop_assert_eq!(starts, model.structures.len() + problems(Unbalanced::NotClosed));
        proptest::prop_assert_eq!(ends, model.structures.len() + problems(Unbalanced::NotOpened));
        for structure in &model.structures {
            let middle = structure.middle.unwrap_or(structure.start + 1);
            proptest::prop_assert!(structure.start < middle && middle <= structure.end);
        }
        // The index finds at each block what a search of all finds.
        for block in 0..=lines.len() {
            let all = model.structures.iter().filter(|s| s.start == block || s.middle == Some(block) || s.end == block);
            proptest::prop_assert_eq!(model.structures_at(block).collect::<Vec<_>>(), all.collect::<Vec<_>>());
            let jumps = model.jumps.iter().filter(|site| site.block == block);
            proptest::prop_assert_eq!(model.jumps_from(block).collect::<Vec<_>>(), jumps.collect::<Vec<_>>());
        }
    }
}
