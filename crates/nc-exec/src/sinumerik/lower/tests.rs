use expect_test::{Expect, expect};
use ncc_syntax::Parse;
use proptest::prelude::*;

use super::*;

pub(crate) fn lower_text(text: &str) -> Vec<SinumerikBlock> {
    let parse = Parse::new(text, Dialect::Sinumerik);
    block_nodes(parse.green()).map(|(_, block)| SinumerikBlock::lower(block)).collect()
}

#[test]
fn programs_are_looked_up_in_their_control_files() {
    assert_eq!(control_files("profil"), ["_N_PROFIL_MPF", "_N_PROFIL_SPF"]);
    assert_eq!(control_files("_N_GEOMETRIE_VACKA_SPF"), ["_N_GEOMETRIE_VACKA_SPF"]);
    assert_eq!(control_files("/_N_SPF_DIR/_N_SUB_MPF"), ["_N_SUB_MPF"]);
    let numbered = Callee::Numbered { letter: b'L', number: Some(140) };
    assert_eq!(numbered.control_files(), Some(vec!["_N_L140_MPF".to_owned(), "_N_L140_SPF".to_owned()]));
    assert_eq!(Callee::Cycle("CYCLE81".to_owned()).control_files(), None);
}

fn check(text: &str, expect: Expect) {
    let shown: Vec<String> =
        lower_text(text).iter().map(SinumerikBlock::to_string).filter(|line| !line.is_empty()).collect();
    expect.assert_eq(&(shown.join("\n") + "\n"));
}

#[test]
fn words_addresses_and_assignments() {
    check(
        "N10 G1 X-12.5 Y=R1+5 A3=1 X1=X CR=10 SD=3 TURN=2\n\
         :20 X=AC(10) Z=IC(-2) T=\"DRILL\" CHF=2 RND=1 M6\n\
         R1=5 R[R1+2]=0 VAC_POLE[0,1]=SET(AKT_R) $TC_DP1[1,1]=120 G[8]=2\n\
         / N30 X1.2. Y\n\
         /1 START: G0X10Y20\n\
         %_N_PART_MPF\n",
        expect![[r#"
            N10 | G1 | X-12.5 | Y=(R[1] Add 5) | A3=1 | X1=X | CR=10 | SD=3 | TURN=2
            :20 | X=Absolute(10) | Z=Incremental((Minus 2)) | T="DRILL" | CHF=2 | RND=1 | M6
            R[1] := 5 | R[(R[1] Add 2)] := 0 | VAC_POLE[0, 1] := SET(AKT_R) | sys:$TC_DP1[1, 1] := 120 | group:G[8] := 2
            /None | N30 | X? | Y?
            /Some(1) | START: | G0 | X10 | Y20
            %_N_PART_MPF
        "#]],
    );
}

#[test]
fn catalogue_tells_commands_from_calls() {
    check(
        "TRAORI TOROT FFWON BSPLINE SOFT G642 STOPRE\n\
         TRANS X10 Y20 Z5 G1 X3\n\
         ATRANS Z=R1 F100\n\
         CYCLE800(1,\"TC1\",,57)\n\
         PROFIL (,TRUE,2.14,DELKA)\n\
         PROFIL P3\n\
         _N_GEOMETRIE_VACKA_SPF\n\
         MSG(\"Position:\"<<$AA_IM[X]) WRITE(ERROR,PROGRAM,\"G0\") DELETE(ERROR,PROGRAM)\n\
         L140 L10(1,2)\n\
         MCALL CYCLE81(10,0,2)\n\
         MCALL\n\
         CALL \"/_N_SPF_DIR/_N_SUB_SPF\" BLOCK START TO FINISH\n\
         PCALL /_N_CST_DIR/_N_SUB_SPF(1)\n\
         REPEAT LABEL1 LABEL2 P=2\n\
         RET\n\
         M17\n",
        expect![[r#"
            cmd TRAORI() [] | cmd TOROT() [] | cmd FFWON() [] | cmd BSPLINE() [] | cmd SOFT() [] | G642 | cmd STOPRE() []
            cmd TRANS() [X10 Y20 Z5] | G1 | X3
            cmd ATRANS() [Z=R[1]] | F100
            call Cycle("CYCLE800")(1, "TC1", _, 57)
            call Program("PROFIL")(_, true, 2.14, DELKA)
            call Program("PROFIL")() P3
            call Program("_N_GEOMETRIE_VACKA_SPF")()
            call Predefined("MSG")(("Position:" Concat sys:$AA_IM[X])) | call Predefined("WRITE")(ERROR, PROGRAM, "G0") | call Predefined("DELETE")(ERROR, PROGRAM)
            call Numbered { letter: 76, number: Some(140) }() | call Numbered { letter: 76, number: Some(10) }(1, 2)
            mcall call Cycle("CYCLE81")(10, 0, 2)
            mcall off
            call Indirect "/_N_SPF_DIR/_N_SUB_SPF" block START to FINISH()
            call Path("/_N_CST_DIR/_N_SUB_SPF")(1)
            repeat LABEL1..Some("LABEL2") times 2
            ret()
            M17
        "#]],
    );
}

#[test]
fn declarations() {
    check(
        "PROC CONTOUR(REAL DEPTH, VAR INT COUNT, VAR REAL TABLE[3,4], STRING[20] NAME, AXIS AX) SAVE DISPLOF\n\
         PROC L10\n\
         EXTERN CYCLE_A(REAL, VAR INT, STRING[10])\n\
         DEF INT A[2,3]\n\
         DEF REAL B=5, C=B*2, D\n\
         DEF STRING[50] S=\"x\"\n\
         DEF NCK BOOL FLAG=TRUE\n\
         DEF REAL VALUES[3]=(1,,3)\n\
         DEFINE COOLANT_ON AS M8 M3\n",
        expect![[r#"
            proc CONTOUR(Real DEPTH, var Int COUNT, var Real TABLE[3, 4], String[20] NAME, Axis AX) ["SAVE", "DISPLOF"]
            proc L10() []
            extern CYCLE_A(Real -, var Int -, String[10] -)
            def None Int A[2, 3]
            def None Real B[] = 5; C[] = (B Mul 2); D[]
            def None String[50] S[] = "x"
            def Some("NCK") Bool FLAG[] = true
            def None Real VALUES[3] = list(1, _, 3)
            define COOLANT_ON as "M8 M3"
        "#]],
    );
}

#[test]
fn control_statements_and_jumps() {
    check(
        include_str!("../../../../syntax/test_data/sinumerik/constructs/control.mpf"),
        expect![[r#"
            if (R[1] Eq 1)
            G1 | X10
            Else
            G0 | X0
            EndIf
            if (R[1] Gt 5) GotoF label LABEL1
            if (Not ISFILE("_N_TEST_SPF")) GotoB N10
            while (R[1] Lt 10)
            R[1] := (R[1] Add 1)
            EndWhile
            for R[2] = 0 to 20
            EndFor
            for VAR_I = (R[1] Add 1) to (2 Mul R[2])
            EndFor
            Repeat
            R[3] := (R[3] Add 1)
            until (R[3] Ge 5)
            Loop
            GotoF label END_LOOP
            EndLoop
            case R[1] of 1 => GotoF label L1; 2 => GotoB N20; default => GotoF label LABEL2
            Goto label LABEL1
            GotoC N100
            GotoF computed ("N" Concat R[3])
            GotoS -
            LABEL1: | M0
            repeat LABEL1..Some("LABEL2") times 2
            sync ID=1 (sys:$AA_IM[X] Gt 10) do sys:$AC_PARAM[0] := 1 M7
        "#]],
    );
}

#[test]
fn expressions_keep_the_parsers_precedence() {
    check(
        "R1=-SIN(30)*COS(R2)+2 R2=7 MOD 3 + 7 DIV 2\n\
         OK=(R1>5) AND NOT (R2<=3) OR R3==1 XOR R4<>2 AND R5>=6\n\
         STR=\"G0 X0 Y\"<<POCATECNI_R+5<<\"\"\n\
         R3=1 B_OR 6 B_AND 3 B_XOR 1\n\
         VALUE=1.5EX-3+'H1F'+'B101' WB=FALSE FR=CTRANS(X,10):CROT(Z,45)\n\
         MSG(<<R1) R4=R[R1+1]*$P_GG[6]\n\
         R5=(1+ R6=SIN(\n",
        expect![[r#"
            R[1] := (((Minus SIN(30)) Mul COS(R[2])) Add 2) | R[2] := ((7 Mod 3) Add (7 IntDiv 2))
            OK := ((((((R[1] Gt 5) And (Not (R[2] Le 3))) Or R[3]) Eq (1 Xor R[4])) Ne (2 And R[5])) Ge 6)
            STR := (("G0 X0 Y" Concat (POCATECNI_R Add 5)) Concat "")
            R[3] := (1 BitOr ((6 BitAnd 3) BitXor 1))
            VALUE := ((1.5EX-3 Add int 31) Add int 5) | WB := false | FR := (CTRANS(X, 10) Chain CROT(Z, 45))
            call Predefined("MSG")((ToString R[1])) | R[4] := (R[(R[1] Add 1)] Mul sys:$P_GG[6])
            R[5] := (1 Add R[6]) | call Predefined("SIN")()
        "#]],
    );
}

#[test]
fn ranges_are_relative_to_the_block() {
    let blocks = lower_text("G0 X1\nN10 CR=2.5 TRANS X10\n");
    let block = &blocks[1];
    let StatementKind::Word(word) = &block.statements[0].kind else { panic!("a word: {block:?}") };
    assert_eq!(
        (word.range, word.value_range),
        (TextRange::new(4.into(), 10.into()), Some(TextRange::new(7.into(), 10.into())))
    );
    // The frame covers its words.
    assert_eq!(block.statements[1].range, TextRange::new(11.into(), 20.into()));
    assert_eq!(block.len, TextSize::from(21));
    // A literal's value starts at its sign.
    let StatementKind::Word(signed) = &lower_text("X-1.5\n")[0].statements[0].kind else { panic!("a word") };
    assert_eq!(signed.value_range, Some(TextRange::new(1.into(), 5.into())));
    assert_eq!(block.words().map(|w| w.address.as_str()).collect::<Vec<_>>(), ["CR", "X"]);
}

#[test]
fn program_ends() {
    let ends: Vec<Option<ProgramEnd>> =
        lower_text("RET\nM17\nM30\nM2\nM3\nG1 X1\n").iter().map(SinumerikBlock::program_end).collect();
    assert_eq!(
        ends,
        [
            Some(ProgramEnd::Return),
            Some(ProgramEnd::Subprogram),
            Some(ProgramEnd::Program),
            Some(ProgramEnd::Program),
            None,
            None
        ]
    );
}

#[test]
fn numbers_with_exponents() {
    let number = |text| Number::parse(None, text);
    assert_eq!(number("1EX3").and_then(|n| n.whole()), Some(1000));
    assert_eq!(number("1.5EX-3").map(|n| n.value()), Some(0.0015));
    assert_eq!(number("25EX-1").and_then(|n| n.whole()), None);
    assert_eq!(number("1EX"), None);
}

proptest! {
    #[test]
    fn any_text_lowers(text in "[ -~\n]{0,160}") {
        lower_text(&text);
    }

    #[test]
    fn any_statement_soup_lowers(parts in prop::collection::vec(prop::sample::select(vec![
        "IF", "ELSE", "ENDIF", "WHILE", "FOR", "TO", "CASE", "OF", "DEFAULT", "GOTOF", "GOTOB", "GOTOS", "DEF",
        "PROC", "EXTERN", "VAR", "REAL", "STRING", "MCALL", "CALL", "PCALL", "BLOCK", "REPEAT", "UNTIL", "DO",
        "WHEN", "DEFINE", "AS", "RET", "TRANS", "NOT", "AND", "<<", "==", ":", "=", "(", ")", "[", "]", ",",
        "\"", "'H", "R", "X", "L", "N", "P", "1", "2.", ".", "EX", "-", "+", "/", "$P_GG", "LBL", " ", "\n",
        ";", "%",
    ]), 0..60)) {
        lower_text(&parts.concat());
    }
}
