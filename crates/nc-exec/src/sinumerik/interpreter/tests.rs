use std::{collections::BTreeMap, ops::ControlFlow};

use proptest::prelude::*;

use super::*;
use crate::{
    run::{resume_into, run_into},
    trace::{Checkpoints, DEFAULT_STEP_BUDGET, NoFiles, PathMode, WrittenFile},
};

/// Files beside the program by the control's name (`_N_PROFIL_SPF`).
#[derive(Default)]
struct Beside(BTreeMap<String, String>);

impl Beside {
    fn with(files: &[(&str, &str)]) -> Beside {
        Beside(files.iter().map(|(name, text)| ((*name).to_owned(), (*text).to_owned())).collect())
    }
}

impl Environment for Beside {
    fn file(&self, called: &Called) -> Option<String> {
        match called {
            Called::ControlFile(name) => self.0.get(name).cloned(),
            _ => None,
        }
    }
}

fn machine() -> MachineConfig {
    MachineConfig::of_control(Dialect::Sinumerik)
}

fn run_with(text: &str, files: &dyn Environment) -> Trace {
    run_in(text, None, files, &machine(), DEFAULT_STEP_BUDGET, None, None)
}

fn run(text: &str) -> Trace {
    run_with(text, &NoFiles)
}

/// The findings as (rule, text of their range).
fn findings<'t>(trace: &Trace, text: &'t str) -> Vec<(RunRule, &'t str)> {
    trace.findings.iter().map(|finding| (finding.rule, &text[finding.range])).collect()
}

/// The end of the last step as (X, Y, Z).
fn end(trace: &Trace) -> [f64; 3] {
    let position = trace.end_position();
    [position[slot(b'X')], position[slot(b'Y')], position[slot(b'Z')]]
}

fn moves(trace: &Trace) -> Vec<&Step> {
    trace.steps.iter().filter(|step| matches!(step.motion, Motion::Rapid | Motion::Feed)).collect()
}

#[test]
fn a_for_loop_makes_one_move_a_pass_to_the_computed_end() {
    let text =
        "DEF INT COUNT, LAST=5\nG0 X0 Y0 Z0\nF1000\nFOR COUNT = 1 TO LAST\n  G1 X=COUNT*10 Y=COUNT\nENDFOR\nM30\n";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    let made = moves(&trace);
    assert_eq!(made.len(), 6, "the rapid and five passes");
    assert!(
        made[1..].iter().all(|step| step.motion == Motion::Feed && &text[step.range] == "  G1 X=COUNT*10 Y=COUNT\n")
    );
    assert_eq!(end(&trace), [50.0, 5.0, 0.0]);
    let length: f64 = made.iter().map(|step| step.length).sum();
    assert!((length - 5.0 * 101f64.sqrt()).abs() < 1e-9, "{length}");
    let time: f64 = made[1..].iter().map(|step| step.duration).sum();
    assert!((time - length / 1000.0 * 60.0).abs() < 1e-9);
    // A loop whose end is below its start runs no pass.
    let none = run("DEF INT COUNT\nF100\nFOR COUNT = 3 TO 2\nG1 X1\nENDFOR\n");
    assert!(moves(&none).is_empty() && none.findings.is_empty());
}

#[test]
fn structures_branch_and_loop() {
    let text = "\
R1=0 R2=0
WHILE R1<3
  R1=R1+1
ENDWHILE
REPEAT
  R2=R2+2
UNTIL R2>=6
IF R1==3
  R3=1
ELSE
  R3=2
ENDIF
IF R1<>3
  R4=1
ELSE
  R4=2
ENDIF
LOOP
  R5=R5+1
  IF R5==4 GOTOF OUT
ENDLOOP
OUT: CASE R4 OF 1 GOTOF ONE 2 GOTOF TWO DEFAULT GOTOF ONE
ONE: R6=1
TWO: G0 X=R1 Y=R2 Z=R3*10+R4+R5/10+R6
M30
";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    assert_eq!(end(&trace), [3.0, 6.0, 12.4]);
}

#[test]
fn computed_jumps_go_to_the_block_number_the_string_names() {
    // As L29: coordinates after M30, reached by GOTOF "N"<<R3 and left by
    // GOTOB "N"<<R9 (004:4629-4633, 4737-4791).
    let text = "\
R10=0
N1 R10=R10+1
R3=1000+R10 R9=2
GOTOF \"N\"<<R3
N2 IF R10<3 GOTOB N1
M30
N1001 G0 X1
GOTOB \"N\"<<R9
N1002 G0 X2 Y2
GOTOB \"N\"<<R9
N1003 G0 X3 Y3 Z3
GOTOB \"N\"<<R9
";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    let ends: Vec<[f64; 3]> = moves(&trace).iter().map(|step| [step.end[0], step.end[1], step.end[2]]).collect();
    assert_eq!(ends, [[1.0, 0.0, 0.0], [2.0, 2.0, 0.0], [3.0, 3.0, 3.0]]);
    let missing = "R3=7\nGOTOF \"L\"<<R3\nN7 M30\n";
    let trace = run(missing);
    assert_eq!(findings(&trace, missing), [(RunRule::CallTargetMissing, "GOTOF \"L\"<<R3")]);
}

#[test]
fn a_jump_into_a_for_body_runs_on_as_the_loop() {
    // The cam cycle's shape: out of the body to a label after ENDFOR and
    // back into the body (004:5091, 5133-5165).
    let text = "\
DEF INT I_1
DEF INT VISITS
FOR I_1 = 0 TO 3
  IF I_1==1 GOTOF OUTSIDE
  BACK:
  VISITS=VISITS+1
ENDFOR
GOTOF DONE
OUTSIDE:
  R1=R1+1
GOTOB BACK
DONE: G0 X=VISITS Y=R1 Z=I_1
";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    assert_eq!(end(&trace), [4.0, 1.0, 4.0]);
}

#[test]
fn a_loop_without_end_stops_at_the_budget() {
    let text = "LOOP\nG91 G1 X1 F1000\nENDLOOP\n";
    let trace = run_in(text, None, &NoFiles, &machine(), 1000, None, None);
    let [finding] = trace.findings.as_slice() else { panic!("{:?}", trace.findings) };
    assert_eq!(finding.rule, RunRule::StepBudget);
    assert_eq!(trace.blocks_run, 1000);
}

#[test]
fn calls_bind_parameters_by_value_and_by_reference() {
    let main = "\
DEF REAL TOTAL=1
DEF INT COUNT
DEF REAL TABLE[3]
ADD(5, TOTAL, COUNT, TABLE[2]) P2
G0 X=TOTAL Y=COUNT Z=TABLE[2]
M30
";
    let add = "\
PROC ADD(REAL STEP, VAR REAL SUM, VAR INT CALLS, VAR REAL CELL) SAVE
DEF REAL LOCAL=STEP*2
G91
SUM=SUM+STEP
CALLS=CALLS+1
CELL=CELL+LOCAL
INNER(CALLS)
M17
";
    let inner = "PROC INNER(VAR INT N)\nN=N*10\nRET\n";
    let files = Beside::with(&[("_N_ADD_SPF", add), ("_N_INNER_SPF", inner)]);
    let trace = run_with(main, &files);
    assert_eq!(trace.findings, []);
    // Twice: TOTAL 1+5+5, COUNT (0+1)*10 then (10+1)*10, TABLE[2] 10+10.
    assert_eq!(end(&trace), [11.0, 110.0, 20.0]);
    // SAVE brought G90 back: the move was absolute.
    assert_eq!(
        trace.files,
        [Called::ControlFile("_N_ADD_SPF".to_owned()), Called::ControlFile("_N_INNER_SPF".to_owned())]
    );
    let sources: Vec<usize> = trace.steps.iter().map(|step| step.source).collect();
    // Of ADD's blocks the machine sees G91 and M17, twice; the others
    // only compute.
    assert_eq!(sources.iter().filter(|&&source| source == 1).count(), 2 * 2);
}

#[test]
fn l19_passes_omitted_parameters_as_zero() {
    let main = include_str!("../../../../syntax/test_data/sinumerik/l19_profil_main.mpf");
    let sub = include_str!("../../../../syntax/test_data/sinumerik/l19_profil_sub.spf");
    // X1 and Y1 of the seed's machine are X and Y of this one.
    let sub = sub.replace("X1=X Y1=Y", "G0 X=X Y=Y Z=C+Z+$P_SUBPAR[1]+$P_SUBPAR[4]*10");
    let trace = run_with(main, &Beside::with(&[("_N_PROFIL_SPF", &sub)]));
    assert_eq!(trace.findings, []);
    assert_eq!(end(&trace), [2.14, 5.0, 10.0]);
}

#[test]
fn a_missing_program_and_runaway_recursion_stop_the_run() {
    let text = "NOWHERE\nM30\n";
    let trace = run(text);
    assert_eq!(findings(&trace, text), [(RunRule::CallTargetMissing, "NOWHERE")]);
    let selfish = "PROC AGAIN\nAGAIN\nM17\n";
    let trace = run_with("AGAIN\n", &Beside::with(&[("_N_AGAIN_SPF", selfish)]));
    let rules: Vec<RunRule> = trace.findings.iter().map(|finding| finding.rule).collect();
    assert_eq!(rules, [RunRule::CallDepth]);
    assert_eq!(trace.findings[0].source, 1);
    // An empty program called a trillion times takes no time to run.
    let trace = run_with("EMPTY P999999999999\nG0 X1\n", &Beside::with(&[("_N_EMPTY_SPF", "")]));
    assert_eq!((trace.findings.as_slice(), end(&trace)), (&[][..], [1.0, 0.0, 0.0]));
}

#[test]
fn motion_follows_the_modes() {
    let text = "\
G0 X10 Y0 Z0
G17 G3 X0 Y10 I-10 J0 F600
G2 X10 Y0 CR=-10
G91 G1 X=IC(5) Y=AC(0) Z-1
G90 G18 G2 Z-11 X0 CR=10
G70 G1 X1
G4 F2.5
M30
";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    let steps = &trace.steps;
    let quarter = 10.0 * std::f64::consts::FRAC_PI_2;
    assert!((steps[1].length - quarter).abs() < 1e-9);
    assert_eq!(steps[1].path, Path::Arc { plane: (b'X', b'Y'), centre: [0.0, 0.0], clockwise: false });
    assert!((steps[1].duration - quarter / 600.0 * 60.0).abs() < 1e-9);
    assert!((steps[2].length - 3.0 * quarter).abs() < 1e-9, "CR<0: the long way");
    assert_eq!([steps[3].end[0], steps[3].end[1], steps[3].end[2]], [15.0, 0.0, -1.0]);
    assert!(matches!(steps[4].path, Path::Arc { plane: (b'Z', b'X'), clockwise: true, .. }));
    assert_eq!(steps[5].end[0], 25.4);
    assert_eq!((steps[6].motion, steps[6].duration), (Motion::Dwell, 2.5));
    // The rapid move: the slowest axis decides.
    let rapid = run("G0 X100 Y50\n");
    let rate = f64::from(machine().axis_rapid_rate(b'X').min(machine().axis_rapid_rate(b'Y')));
    assert!(rapid.steps[0].duration >= 50.0 / rate * 60.0 - 1e-9);
}

/// Each step records how the path passes into it, by the modes in force
/// in the block before it (the velocity policy's `PathControl`): G60 and
/// G9 stop at the end of their block, G64 and G641 join within their
/// tolerances, SOFT limits the jerk of the block's own ramps.
#[test]
fn steps_record_the_path_modes() {
    let text = "F100\nG1 X1\nG64 SOFT X2\nG641 ADIS=0.5 X3\nG9 X4\nBRISK G60 X5\n";
    let trace = run(text);
    let modes: Vec<(PathMode, bool, f32)> =
        trace.steps[1..].iter().map(|step| (step.path_mode, step.jerk_limited, step.corner_tolerance)).collect();
    let (inf, g64, adis) = (f32::INFINITY, 0.01, (0.5 * std::f64::consts::FRAC_PI_8.tan()) as f32);
    assert_eq!(
        modes,
        [
            (PathMode::ExactStop, false, inf),
            (PathMode::ExactStop, true, inf),
            (PathMode::Continuous, true, g64),
            (PathMode::Continuous, true, adis),
            (PathMode::ExactStop, false, adis),
        ]
    );
}

#[test]
fn unmodelled_words_are_reported_once_and_the_run_goes_on() {
    let text = "CYCLE832(0.01,_FINISH,1)\nCYCLE832(0.1)\nG0 X1 A2=5 B3=1\nG0 X2 A2=6\nR1=$A_DAY+$A_DAY\nTRAORI\nM30\n";
    let trace = run(text);
    assert_eq!(
        findings(&trace, text),
        [
            (RunRule::NotRunYet, "CYCLE832(0.01,_FINISH,1)"),
            (RunRule::NotRunYet, "A2=5"),
            (RunRule::ParameterUnknown, "$A_DAY"),
            (RunRule::NotRunYet, "TRAORI"),
        ]
    );
    assert_eq!(end(&trace), [2.0, 0.0, 0.0]);
}

#[test]
fn arithmetic_errors_stop_with_their_place() {
    let text = "R1=0\nR2=5/R1\nG0 X1\n";
    let trace = run(text);
    assert_eq!(findings(&trace, text), [(RunRule::ArithmeticFailed, "5/R1")]);
    assert!(moves(&trace).is_empty());
}

#[test]
fn a_rational_bspline_is_the_quarter_circle() {
    // The quarter circle of radius 10 as a rational quadratic: the middle
    // point weighs cos 45°.
    let text = format!(
        "G0 X10 Y0\nF1000\nBSPLINE SD=2 X10 Y10 PW={}\nX0 Y10\nG1 X0 Y20\nM30\n",
        std::f64::consts::FRAC_1_SQRT_2
    );
    let trace = run(&text);
    assert_eq!(trace.findings, []);
    let curve: Vec<&Step> = trace
        .steps
        .iter()
        .filter(|step| text[step.range].starts_with("BSPLINE") || &text[step.range] == "X0 Y10\n")
        .collect();
    let length: f64 = curve.iter().map(|step| step.length).sum();
    let quarter = 5.0 * std::f64::consts::PI;
    assert!((length - quarter).abs() < quarter * 1e-3, "{length}");
    assert!(curve.len() > 20, "pieces within 1 µm: {}", curve.len());
    for step in &curve {
        let radius = step.end[0].hypot(step.end[1]);
        assert!((radius - 10.0).abs() < 1e-9, "on the circle: {radius}");
        assert!((step.duration - step.length / 1000.0 * 60.0).abs() < 1e-12);
    }
    // Both blocks have pieces, joined: each starts where the one before ends.
    assert!(curve.iter().any(|step| text[step.range].starts_with("BSPLINE")));
    assert_eq!(curve.last().map(|step| [step.end[0], step.end[1]]), Some([0.0, 10.0]));
    assert_eq!(end(&trace), [0.0, 20.0, 0.0]);
    let lines = trace.steps.iter().filter(|step| step.motion == Motion::Feed).count();
    assert_eq!(lines, curve.len() + 1);
    // Left by `G[1]=2` (G1): the line after the curve keeps its own end.
    let text = "F1000\nBSPLINE X10 Y10\nX20 Y0\nG[1]=2\nX0 Y20\n";
    let trace = run(text);
    assert_eq!(trace.findings, []);
    let last = trace.steps.last().unwrap();
    assert_eq!((&text[last.range], [last.end[0], last.end[1]]), ("X0 Y20\n", [0.0, 20.0]));
    assert!((last.length - 20.0 * 2f64.sqrt()).abs() < 1e-9);
}

#[test]
fn written_files_can_be_called_later_in_the_run() {
    let text = "\
DEF INT ERROR
DEF STRING[60] PROGRAM=\"/_N_MPF_DIR/_N_PARTS_DIR/_N_MADE_SPF\"
IF NOT ISFILE(\"_N_MADE_SPF\")
  WRITE(ERROR,PROGRAM,\"G0 X\"<<4*2.5<<\" Y\"<<1/4)
  WRITE(ERROR,PROGRAM,\"M17\")
ENDIF
MADE
DELETE(ERROR,\"_N_OTHER_SPF\")
G0 Z=ERROR
M30
";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    assert_eq!(end(&trace), [10.0, 0.25, 3.0]);
    assert_eq!(
        trace.written,
        [WrittenFile {
            path: "/_N_MPF_DIR/_N_PARTS_DIR/_N_MADE_SPF".to_owned(),
            text: "G0 X10 Y0.25\nM17\n".to_owned()
        }]
    );
    assert_eq!(trace.files, [Called::Written("/_N_MPF_DIR/_N_PARTS_DIR/_N_MADE_SPF".to_owned())]);
}

fn seed(name: &str) -> &'static str {
    match name {
        "l24" => include_str!("../../../../syntax/test_data/sinumerik/l24_igs_splines_output.spf"),
        "l25" => include_str!("../../../../syntax/test_data/sinumerik/l25_podpis_janskacel.mpf"),
        "l26" => include_str!("../../../../syntax/test_data/sinumerik/l26_krivky_y_const.spf"),
        "l27" => include_str!("../../../../syntax/test_data/sinumerik/l27_krivky_x_const_a_rot.spf"),
        "l28" => include_str!("../../../../syntax/test_data/sinumerik/l28_krivky_y_const_hrub.spf"),
        "l29" => include_str!("../../../../syntax/test_data/sinumerik/l29_blob_souradnice_dole.mpf"),
        "l30" => include_str!("../../../../syntax/test_data/sinumerik/l30_run_vacka.mpf"),
        "l31" => include_str!("../../../../syntax/test_data/sinumerik/l31_vacka_cyklus.spf"),
        _ => unreachable!("{name}"),
    }
}

/// L29 with the coordinate blocks the seed elides: block `N<100i+j>` for
/// every point of the 65 × 54 grid its R4 and R5 give.
fn l29_complete() -> String {
    let mut text = seed("l29").to_owned();
    for i in 1..=65 {
        for j in 1..=54 {
            let number = 100 * i + j;
            if !text.contains(&format!("\nN{number} ")) {
                let (x, y) = (-50.0 + f64::from(i - 1) * 100.0 / 64.0, 50.0 - f64::from(j - 1) * 100.0 / 53.0);
                text.push_str(&format!("N{number} X{x:.8} Y{y:.8} Z-30\n  GOTOB \"N\"<<R9\n"));
            }
        }
    }
    text
}

#[test]
fn the_seed_listings_run_to_their_end() {
    let l29 = l29_complete();
    for name in ["l24", "l25", "l26", "l27", "l28", "l29"] {
        let text = if name == "l29" { l29.as_str() } else { seed(name) };
        let trace = run(text);
        let stops: Vec<&Finding> = trace.findings.iter().filter(|finding| finding.stops()).collect();
        assert_eq!(stops, Vec::<&Finding>::new(), "{name}");
        assert!(trace.steps.iter().any(|step| step.motion == Motion::Feed), "{name}");
        // Only what the run leaves out, and L28's first move, which the
        // seed writes before any F.
        for finding in &trace.findings {
            let expected = matches!(finding.rule, RunRule::NotRunYet)
                || (name == "l28"
                    && finding.rule == RunRule::MotionWithoutFeed
                    && &text[finding.range] == "X-60 Y60\n");
            assert!(expected, "{name}: {finding:?}");
        }
    }
}

#[test]
fn the_cam_program_writes_its_geometry_and_runs_it() {
    // The GUD the seed leaves out (004:3112-3114): a row per angle and
    // radius.
    let gud = "DEF NCK REAL VAC_POLE[30,2]\n";
    let files = Beside::with(&[("_N_VACKA_CYKLUS_SPF", seed("l31")), ("_N_UGUD_DEF", gud)]);
    let trace = run_with(seed("l30"), &files);
    let rules: Vec<(RunRule, &str)> =
        trace.findings.iter().map(|finding| (finding.rule, finding.message.split(':').next().unwrap_or(""))).collect();
    assert_eq!(
        rules,
        [
            (RunRule::NotRunYet, "the executor does not run axis A (the machine has none) yet"),
            (RunRule::NotRunYet, "the executor does not run axis C (the machine has none) yet"),
            (RunRule::ParameterUnknown, "the run has no clock"),
        ]
    );
    let path = "/_N_MPF_DIR/_N_VACKA_DIR/_N_GEOMETRIE_VACKA_SPF";
    let [geometry, debug] = trace.written.as_slice() else { panic!("{:?}", trace.written) };
    assert_eq!(debug.path, "/_N_MPF_DIR/_N_VACKA_DIR/_N_DEBURGER_SPF");
    assert_eq!(geometry.path, path);
    let lines: Vec<&str> = geometry.text.lines().collect();
    assert_eq!(lines[0], ";Date: 0.0.2000  Time: 0:0:0");
    assert_eq!(lines[1..5], ["G[06]=1    ; G17/G18/G19", "G90 G94", ";NASTROJ a M6", "F2000"]);
    assert_eq!(lines[5], "S2000 M5", "the spindle never started");
    assert_eq!(lines[11..14], ["G0 X0 Y15", "G1 Z-3", "Y10"]);
    assert_eq!(lines[lines.len() - 5..], ["G0 Z200", "X200 Y200 A0 C0", "SUPA FFWOF", "M5 M9", "M17"]);
    // The first 12° at a constant radius are one arc, then a point a
    // degree over the 35°, 175° and 25° where the radius changes; the
    // cycle looks two rows ahead (`VAC_POLE[var_i+2,0]==0`), so the last
    // row's 113° is never written.
    let points = lines.iter().filter(|line| line.starts_with("X=") || line.starts_with("G2 ")).count();
    assert_eq!(points, 1 + 35 + 175 + 25);
    // The run called what it wrote: its moves are the file's blocks.
    assert_eq!(trace.files.last(), Some(&Called::Written(path.to_owned())));
    let source = trace.files.len();
    let mut blocks: Vec<TextRange> = trace
        .steps
        .iter()
        .filter(|step| step.source == source && step.motion == Motion::Feed)
        .map(|step| step.range)
        .collect();
    blocks.dedup();
    // G1 Z-3, Y10, the arc and the control points of the BSPLINE that
    // `G[01]=7` selects.
    assert_eq!(blocks.len(), 3 + 235);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn any_bytes_run_without_panic_within_the_budget(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        let trace = run_in(&text, None, &NoFiles, &machine(), 2000, None, None);
        prop_assert!(trace.blocks_run <= 2000);
    }

    #[test]
    fn statement_soup_runs_without_panic(parts in proptest::collection::vec(prop::sample::select(vec![
        "R1=R1+1", "GOTOB N1", "GOTOF N2", "N1", "N2", "IF R1>3", "ENDIF", "ELSE", "WHILE R1<5", "ENDWHILE",
        "FOR R2=1 TO 3", "ENDFOR", "LOOP", "ENDLOOP", "REPEAT", "UNTIL R1>2", "G2 X1 Y1 CR=0.1", "BSPLINE X1 PW=0",
        "G1 X=R1 F100", "SUB(1)", "EMPTY P999999999999", "M17", "RET", "DEF INT A[2]", "A[5]=1", "M30", "G0 X=1/R3", "\n", "\n", "\n",
    ]), 0..60)) {
        let text = parts.join(" ");
        let files = Beside::with(&[("_N_SUB_SPF", "PROC SUB(INT N)\nSUB(N+1)\n"), ("_N_EMPTY_SPF", "")]);
        let trace = run_in(&text, None, &files, &machine(), 3000, None, None);
        prop_assert!(trace.blocks_run <= 3000);
    }
}

#[test]
fn a_subprogram_run_by_itself_has_its_parameters_at_zero() {
    let text = "PROC SIDE(REAL D, VAR INT N) SAVE\nN=N+1\nG0 X=D+1 Y=N Z=$P_SUBPAR[1]\nM17\n";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    assert_eq!(end(&trace), [1.0, 1.0, 0.0]);
}

#[test]
fn modal_calls_and_repeated_sections_run_where_the_control_runs_them() {
    let main = "\
MCALL MARK(R1)
G0 X1
R1=R1+1
G0 X2
MCALL
G0 X3
START: R3=R3+1
R4=R4+10
FINISH: R5=R5+100
REPEAT START FINISH P=3
G0 Y=R2 Z=R3+R4+R5
M30
";
    let mark = "PROC MARK(REAL WHAT)\nR2=R2+WHAT+1\nM17\n";
    let trace = run_with(main, &Beside::with(&[("_N_MARK_SPF", mark)]));
    assert_eq!(findings(&trace, main), []);
    // MARK after the two moves under MCALL: (0+1) + (1+1); the section
    // once on the way and three times repeated.
    assert_eq!(end(&trace), [3.0, 3.0, 4.0 + 40.0 + 400.0]);
}

/// The end of every move, X, Y and Z, to the micrometre.
fn ends(trace: &Trace) -> Vec<[f64; 3]> {
    let moves = trace.steps.iter().filter(|step| matches!(step.motion, Motion::Rapid | Motion::Feed));
    moves.map(|step| [0, 1, 2].map(|axis| (step.end[axis] * 1000.0).round() / 1000.0)).collect()
}

/// Frames move the path as they compose: an ATRANS after an ASCALE is
/// scaled, a rotation turns the moves and their arcs, a mirror turns an
/// arc over; the tool stays where it is when a frame changes.
#[test]
fn frames_compose_as_the_control_composes_them() {
    let text = "G0 X0 Y0 Z0\nASCALE X2 Y2 Z2\nATRANS X5\nG0 X1 Y1\nTRANS X10\nAROT Z90\nG1 X5 Y0 F100\nTRANS\nMIRROR X0\nG0 X10 Y0\nG2 X0 Y10 CR=10\nTRANS\nG0 X0 Y0\nM30\n";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    // ASCALE 2 then ATRANS X5: (1, 1) is (2·(1+5), 2·1).
    // TRANS X10 AROT Z90: X5 is 5 along the turned X, so (10, 5).
    // MIRROR X: (10, 0) is (-10, 0); the short G2 from there to (0, 10)
    // turns about (10, 10), which is (-10, 10) mirrored, and over to G3.
    assert_eq!(
        ends(&trace),
        [[0.0, 0.0, 0.0], [12.0, 2.0, 0.0], [10.0, 5.0, 0.0], [-10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 0.0]]
    );
    let arc = trace.steps.iter().find(|step| matches!(step.path, Path::Arc { .. })).expect("the arc");
    assert!(
        matches!(arc.path, Path::Arc { clockwise: false, centre, .. } if centre == [-10.0, 10.0]),
        "{:?}",
        arc.path
    );
    assert!((arc.length - 10.0 * std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    // A scale lengthens the moves: 2 mm programmed is 4 mm run.
    let scaled = run("G0 X0 Y0 Z0\nSCALE X2 Y2\nG1 X2 F60\nM30\n");
    let cut = scaled.steps.iter().find(|step| step.motion == Motion::Feed).expect("the cut");
    assert_eq!((cut.length, cut.duration), (4.0, 4.0));
}

/// CYCLE800 turns the plane it drills in; a modal drilling cycle runs at
/// every position after MCALL until MCALL alone ends it.
#[test]
fn cycles_drill_at_each_position_and_swivel_the_plane() {
    let text = "G17 G0 X0 Y0 Z50\nF200 S1000 M3\nMCALL CYCLE81(10,0,2,-20)\nX10 Y10\nX20\nMCALL\nX30\nM30\n";
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    let holes: Vec<[f64; 3]> = ends(&trace).into_iter().filter(|end| end[2] == -20.0).collect();
    assert_eq!(holes, [[10.0, 10.0, -20.0], [20.0, 10.0, -20.0]]);
    // In at the feed from the safety distance 2 mm above RFP 0: 22 mm at
    // 200 mm/min for each hole.
    let drilled: f64 = trace.steps.iter().filter(|step| step.motion == Motion::Feed).map(|step| step.length).sum();
    assert!((drilled - 44.0).abs() < 1e-9, "{drilled}");
    assert_eq!(ends(&trace).last(), Some(&[30.0, 10.0, 10.0]));
    // Turned by 90° about Z, X10 runs along the base's Y.
    let swivelled = run("G0 X0 Y0 Z0\nCYCLE800(0,\"TC1\",0,57,0,0,0,0,0,90)\nG0 X10\nM30\n");
    assert_eq!(findings(&swivelled, ""), []);
    assert_eq!(ends(&swivelled).last(), Some(&[0.0, 10.0, 0.0]));
}

/// Tools by number and by name (tool management), each once, in the order
/// first selected; T0 selects none.
#[test]
fn the_trace_lists_numbered_and_named_tools() {
    let trace = run("T5 M6\nT=\"BALL_6\" M6\nT5\nT=\"BALL_6\"\nT0\n");
    assert_eq!(trace.tools, [Tool::Number(5), Tool::Name("BALL_6".to_owned())]);
    assert_eq!(trace.tools.iter().map(Tool::to_string).collect::<Vec<_>>(), ["T5", "T=\"BALL_6\""]);
}

/// G93: a block takes 1/F minutes whatever its length; G94 goes back to
/// mm/min.
#[test]
fn inverse_time_feed_gives_each_block_one_over_f_minutes() {
    let trace = run("G17 G90 G0 X0 Y0\nG93 G1 X10 F2\nY30 F4\nX20 Y40\nG94 X30 F100\n");
    let durations: Vec<f64> = moves(&trace).iter().skip(1).map(|step| step.duration).collect();
    assert_eq!(durations, [30.0, 15.0, 15.0, 6.0]);
    let feeds: Vec<Option<f64>> = moves(&trace).iter().skip(1).map(|step| step.feed).collect();
    assert_eq!(feeds[0], Some(20.0), "10 mm in half a minute");
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

/// A run that reports nothing.
fn run_clean(text: &str) -> Trace {
    let trace = run(text);
    assert_eq!(findings(&trace, text), []);
    trace
}

/// The tool-centre ends of the moves in the plane's axes `(a, b)`, to the
/// micrometre.
fn centre_ends(trace: &Trace, (a, b): (u8, u8)) -> Vec<(f64, f64)> {
    let round = |value: f64| (value * 1000.0).round() / 1000.0 + 0.0;
    (0..trace.steps.len())
        .filter(|&index| matches!(trace.steps[index].motion, Motion::Rapid | Motion::Feed))
        .map(|index| {
            let end = trace.tool_end(index, &trace.steps[index].end);
            (round(trace.axis(&end, a)), round(trace.axis(&end, b)))
        })
        .collect()
}

/// A pocket 20 × 10 counter-clockwise from (0, 0) in the plane of `plane`
/// (its axes `a`, `b`), under `side` with the tool data of `tool`.
fn pocket(plane: &str, [a, b]: [char; 2], side: &str, tool: &str) -> String {
    format!(
        "{tool}\n{plane} G0 {a}-10 {b}-10\n{side} G1 {a}0 {b}0 F1000\n{a}20\n{b}10\n{a}0\n{b}0\nG40 G0 {a}-10 {b}-10\nM30\n"
    )
}

/// Inside the pocket, radius 2: the start ends on the first side's normal,
/// the corners are the equidistants' intersections, the last side ends on
/// its normal, and G40 goes back to the programmed point.
const INSIDE: [(f64, f64); 7] =
    [(-10.0, -10.0), (0.0, 2.0), (18.0, 2.0), (18.0, 8.0), (2.0, 8.0), (2.0, 0.0), (-10.0, -10.0)];

#[test]
fn g41_runs_the_tool_centre_left_of_the_contour_in_g17() {
    let text = pocket("G17", ['X', 'Y'], "G41", "$TC_DP6[1,1]=2\nT1 D1");
    let trace = run_clean(&text);
    assert_eq!(centre_ends(&trace, (b'X', b'Y')), INSIDE);
    assert_eq!(trace.compensated.iter().map(|span| span.plane).collect::<Vec<_>>(), [(b'X', b'Y')]);
    // The steps' ends stay the programmed points; their lengths are the
    // tool centre's: the side along X from (0, 2) to (18, 2), the one
    // along Y from (18, 2) to (18, 8).
    let made = moves(&trace);
    assert_eq!(end(&trace), [-10.0, -10.0, 0.0]);
    assert_eq!([made[2].length, made[3].length], [18.0, 6.0]);
}

#[test]
fn g42_goes_round_outside_corners_on_arcs_under_g450_and_to_intersections_under_g451() {
    let text = pocket("G17", ['X', 'Y'], "G42", "$TC_DP6[1,1]=2\nT1 D1");
    let trace = run_clean(&text);
    // Outside, right of the motion: the corner (20, 0) is passed on an arc
    // from (20, -2) to (22, 0), which belongs to the block after it.
    assert_eq!(
        centre_ends(&trace, (b'X', b'Y')),
        [(-10.0, -10.0), (0.0, -2.0), (20.0, -2.0), (22.0, 10.0), (0.0, 12.0), (-2.0, 0.0), (-10.0, -10.0)]
    );
    assert!(trace.tool_centre.iter().any(|piece| matches!(piece.path, crate::compensation::Element::Arc { .. })));
    let text = text.replace("G42", "G451 G42");
    let trace = run(&text);
    assert_eq!(
        centre_ends(&trace, (b'X', b'Y')),
        [(-10.0, -10.0), (0.0, -2.0), (22.0, -2.0), (22.0, 12.0), (-2.0, 12.0), (-2.0, 0.0), (-10.0, -10.0)]
    );
}

#[test]
fn g41_in_g18_offsets_in_the_z_x_plane() {
    let text = pocket("G18", ['Z', 'X'], "G41", "$TC_DP6[1,1]=2\nT1 D1");
    let trace = run_clean(&text);
    assert_eq!(centre_ends(&trace, (b'Z', b'X')), INSIDE);
    assert_eq!(trace.compensated[0].plane, (b'Z', b'X'));
}

#[test]
fn a_mirror_of_one_axis_swaps_the_side_so_the_tool_stays_inside_the_mirrored_pocket() {
    let text = pocket("G17", ['X', 'Y'], "G41", "$TC_DP6[1,1]=2\nT1 D1\nMIRROR X0");
    let trace = run_clean(&text);
    let mirrored: Vec<(f64, f64)> = INSIDE.iter().map(|&(x, y)| (-x + 0.0, y)).collect();
    assert_eq!(centre_ends(&trace, (b'X', b'Y')), mirrored);
}

#[test]
fn without_a_known_radius_or_under_d0_the_path_is_the_programmed_one() {
    let programmed = [(-10.0, -10.0), (0.0, 0.0), (20.0, 0.0), (20.0, 10.0), (0.0, 10.0), (0.0, 0.0), (-10.0, -10.0)];
    for tool in ["T1 D1", "$TC_DP6[1,1]=2\nT1 D0", "$TC_DP6[1,1]=2\nT2"] {
        let text = pocket("G17", ['X', 'Y'], "G41", tool);
        let trace = run(&text);
        assert_eq!(findings(&trace, &text), [], "{tool}");
        assert_eq!(centre_ends(&trace, (b'X', b'Y')), programmed, "{tool}");
        assert!(trace.compensated.is_empty() && trace.tool_centre.is_empty(), "{tool}");
    }
}

#[test]
fn the_radius_comes_from_the_machine_s_cutting_edges_unless_the_program_writes_it() {
    let mut machine = machine();
    machine.cutting_edges.insert((1, 1), crate::machine::ToolEntry { radius: 2000, ..Default::default() });
    let text = pocket("G17", ['X', 'Y'], "G41", "T1 D1");
    let trace = run_in(&text, None, &NoFiles, &machine, DEFAULT_STEP_BUDGET, None, None);
    assert_eq!(centre_ends(&trace, (b'X', b'Y')), INSIDE);
    let text = pocket("G17", ['X', 'Y'], "G41", "$TC_DP6[1,1]=1\nT1 D1\nR1=$TC_DP6[1,1]");
    let trace = run_in(&text, None, &NoFiles, &machine, DEFAULT_STEP_BUDGET, None, None);
    assert_eq!(findings(&trace, &text), []);
    assert_eq!(centre_ends(&trace, (b'X', b'Y'))[1], (0.0, 1.0));
}

#[test]
fn compensation_starting_on_an_arc_stops_the_run() {
    let text = "$TC_DP6[1,1]=2\nT1 D1\nG0 X0 Y0\nG41 G2 X10 Y0 CR=5 F100\nG40 G1 X0\nM30\n";
    let trace = run(text);
    assert_eq!(findings(&trace, text), [(RunRule::CompensationFailed, "G41 G2 X10 Y0 CR=5 F100\n")]);
}

/// Wants one checkpoint, at block `at`, and ends the run there.
struct StopAt {
    at: usize,
}

impl StepSink for StopAt {
    fn step(&mut self, _step: Step) {}

    fn checkpoint_wanted(&mut self, block: usize, _offset: TextSize) -> bool {
        block == self.at
    }

    fn checkpoint(&mut self, _checkpoint: Checkpoint) -> ControlFlow<()> {
        ControlFlow::Break(())
    }
}

/// Checks that a run of `text` resumed from each of its checkpoints (one
/// every `every` blocks) goes on as the whole run: the same steps, and
/// after what the run reported up to the checkpoint, the same findings and
/// tool-centre path; it takes the same checkpoints after it. The blocks of
/// the checkpoints.
fn assert_resumes_as_the_whole_run(text: &str, files: &dyn Environment, every: usize) -> Vec<usize> {
    let (machine, budget) = (machine(), 20_000);
    let mut whole = Checkpoints { every, ..Checkpoints::default() };
    let trace = resume_into(None, text, files, &machine, budget, &mut whole);
    for checkpoint in &whole.taken {
        let at = checkpoint.block();
        let before = run_into(text, files, &machine, budget, &mut StopAt { at });
        let mut resumed = Checkpoints { before: checkpoint.steps(), every, ..Checkpoints::default() };
        let after = resume_into(Some(checkpoint), text, files, &machine, budget, &mut resumed);
        assert_eq!(resumed.steps, whole.steps[checkpoint.steps()..], "from block {at}");
        assert_eq!([&before.findings[..], &after.findings[..]].concat(), trace.findings, "from block {at}");
        assert_eq!([&before.tool_centre[..], &after.tool_centre[..]].concat(), trace.tool_centre, "from block {at}");
        assert_eq!([&before.compensated[..], &after.compensated[..]].concat(), trace.compensated, "from block {at}");
        assert_eq!((&after.files, after.blocks_run), (&trace.files, trace.blocks_run), "from block {at}");
        let later: Vec<&Checkpoint> = whole.taken.iter().filter(|c| c.block() >= at).collect();
        assert_eq!(resumed.taken.len(), later.len(), "from block {at}");
        for (again, first) in resumed.taken.iter().zip(later) {
            assert!(again.same_course(first) && again.offset() == first.offset(), "from block {at}");
        }
    }
    whole.taken.iter().map(Checkpoint::block).collect()
}

/// Variables, loops, a branch, a jump over a block, frames, a compensated
/// stretch, a spline, a jump back to a label and a call.
const RESUMABLE: &str = "\
DEF REAL DEPTH=2
DEF INT I
R1=0 R2=5
G17 G0 X0 Y0 Z5 S1000 M3
G1 Z=-DEPTH F500
TRANS X10
AROT Z30
WHILE R1<3
  R1=R1+1
  G1 X=R1*10 Y=R1
ENDWHILE
FOR I=1 TO 3
  G1 X=I Y=I*2
ENDFOR
IF R2>3
  G1 X20
ELSE
  G1 X30
ENDIF
GOTOF SKIP
G1 X99
SKIP:
TRANS
$TC_DP6[1,1]=5
T1 D1
G41 G1 X0 Y0
G1 X40
G1 Y40
G40 G1 X60 Y60
BSPLINE X61 Y61
X62 Y63
X64 Y64
G1 X65 Y65
BACK: G1 X70
R3=R3+1
IF R3<2 GOTOB BACK
G1 X80
PROFIL
G1 X90
M30
";

fn profil() -> Beside {
    Beside::with(&[("_N_PROFIL_SPF", "G1 X1 Y1\nM17\n")])
}

#[test]
fn a_run_resumed_from_a_checkpoint_goes_on_as_the_whole_run() {
    let files = profil();
    let trace = run_with(RESUMABLE, &files);
    assert_eq!(findings(&trace, RESUMABLE), []);
    assert!(!trace.tool_centre.is_empty() && trace.files.len() == 1);
    let blocks = assert_resumes_as_the_whole_run(RESUMABLE, &files, 1);
    let lines: Vec<&str> = RESUMABLE.lines().collect();
    let taken: Vec<&str> = blocks.iter().map(|&block| lines[block]).collect();
    // Before WHILE, FOR and IF, none inside them; the jump's target, not
    // the block it jumps over; up to G41's block and none until G40's has
    // run; BSPLINE's, none until the line after the curve has ended it;
    // each block of the jump back once; none after the call.
    assert_eq!(
        taken,
        [
            "DEF REAL DEPTH=2",
            "DEF INT I",
            "R1=0 R2=5",
            "G17 G0 X0 Y0 Z5 S1000 M3",
            "G1 Z=-DEPTH F500",
            "TRANS X10",
            "AROT Z30",
            "WHILE R1<3",
            "FOR I=1 TO 3",
            "IF R2>3",
            "GOTOF SKIP",
            "SKIP:",
            "TRANS",
            "$TC_DP6[1,1]=5",
            "T1 D1",
            "G41 G1 X0 Y0",
            "BSPLINE X61 Y61",
            "BACK: G1 X70",
            "R3=R3+1",
            "IF R3<2 GOTOB BACK",
            "G1 X80",
            "PROFIL",
        ]
    );
    // Every other block: the same steps from a checkpoint as from the start.
    assert_resumes_as_the_whole_run(RESUMABLE, &files, 2);
}

/// The checkpoints of a run of `text`, one every `every` blocks.
fn checkpoints(text: &str, files: &dyn Environment, every: usize) -> Vec<Checkpoint> {
    let mut sink = Checkpoints { every, ..Checkpoints::default() };
    resume_into(None, text, files, &machine(), 10_000, &mut sink);
    sink.taken
}

#[test]
fn no_checkpoint_after_a_start_never_closed_or_with_global_data() {
    let text = "G0 X0 F100\nG1 X1\nWHILE R1<2\nR1=R1+1\nG1 X2\nG1 X3\nM30\n";
    let blocks: Vec<usize> = checkpoints(text, &NoFiles, 1).iter().map(Checkpoint::block).collect();
    assert_eq!(blocks, [0, 1, 2]);
    // Global user data read at the start: the files can change under a
    // checkpoint.
    let globals = Beside::with(&[("_N_UGUD_DEF", "DEF NCK REAL DEPTH\n")]);
    let text = "DEPTH=2\nG0 X0 F100\nG1 X=DEPTH\nM30\n";
    assert!(checkpoints(text, &globals, 1).is_empty());
    let taken = checkpoints(text.replace("DEPTH", "R1").as_str(), &NoFiles, 1);
    assert_eq!(taken.len(), 4);
    // Resumed where global data is now there, the run starts at the top.
    let mut sink = Checkpoints { every: 1, ..Checkpoints::default() };
    let trace = resume_into(Some(&taken[2]), text, &globals, &machine(), 10_000, &mut sink);
    assert_eq!(findings(&trace, text), []);
    assert_eq!(sink.steps, run_with(text, &globals).steps);
    assert_eq!(sink.steps.iter().map(|step| step.end[0]).collect::<Vec<_>>(), [0.0, 2.0, 2.0], "G1 X=DEPTH is 2");
    assert_eq!(sink.steps.iter().map(|step| step.end[0]).collect::<Vec<_>>(), [0.0, 2.0, 2.0], "G1 X=DEPTH is 2");
}

/// Modal state and variables set early, then moves, then jumps back, one
/// to a label the program does not have.
fn resumable_program(first_x: &str) -> String {
    let mut text = format!("DEF REAL D=5\nR4=2\n; setup\nG0 X{first_x} Y0 Z5 S1000 M3\nR1=2 G1 Z=-D F300\n");
    for i in 0..40 {
        text.push_str(&format!("N{} X{} Y{}\n", 100 + i, i * 3, i % 7));
    }
    text.push_str("BACK: G1 Y=R1\nR1=R1+1\nIF R1<4 GOTOB BACK\nIF R1<5 GOTOC AGAIN\nM30\n");
    text
}

#[test]
fn checkpoints_after_an_edit_take_the_same_course_once_the_edit_no_longer_matters() {
    let text = resumable_program("0");
    let before = checkpoints(&text, &NoFiles, 7);
    assert_eq!(before.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 7, 14, 21, 28, 35, 42, 49]);
    let course = |edited: &str, shift: i64| {
        let after = checkpoints(edited, &NoFiles, 7);
        assert_eq!(after.len(), before.len(), "{edited}");
        let pairs = after.iter().zip(&before).skip(1);
        pairs.map(|(after, before)| after.same_course(&before.shifted(shift, 0, 0))).collect::<Vec<bool>>()
    };
    // An absolute move written longer, a comment, the same value written
    // otherwise in a block with a step: the course is the same from the
    // next block on.
    assert_eq!(course(&resumable_program("1234"), 3), [true; 7]);
    assert_eq!(course(&text.replace("; setup", "; set up"), 1), [true; 7]);
    assert_eq!(course(&text.replace("R1=2 ", "R1=1+1 "), 2), [true; 7]);
    // A variable read at the end carries the difference there, until the
    // loop has made it 4 either way.
    let mut differs = [false; 7];
    differs[6] = true;
    assert_eq!(course(&text.replace("R1=2 ", "R1=3 "), 0), differs);
    // So do the modes, the feed, the spindle, a frame, the tool and its
    // data.
    for (from, to) in [
        ("S1000 M3", "S1000 M4"),
        ("S1000 M3", "S1200 M3"),
        ("F300", "F301"),
        ("G0 X0", "G0 G91 X0"),
        ("G0 X0", "G0 X0 T2"),
        ("G0 X0", "G0 X0 D2"),
        ("R1=2 G1", "R1=2 TRANS Z1\nG1"),
        ("R1=2 G1", "R1=2 $TC_DP6[1,1]=2 G1"),
    ] {
        let edited = text.replace(from, to);
        let shift = edited.len() as i64 - text.len() as i64;
        let blocks = i64::from(to.contains('\n'));
        let after = checkpoints(&edited, &NoFiles, 7);
        let same =
            after.iter().skip(1).filter(|after| before.iter().any(|b| after.same_course(&b.shifted(shift, blocks, 0))));
        assert_eq!(same.count(), 0, "{to}");
    }
    // A frame moved otherwise, the text of the blocks without a step the
    // same.
    let moved =
        |z: &str| text.replace("G0 X0", &format!("R5={z} G0 X0")).replace("R1=2 G1", "TRANS Z=R5\nR5=0 R1=2 G1");
    let (one, two) = (checkpoints(&moved("1"), &NoFiles, 7), checkpoints(&moved("2"), &NoFiles, 7));
    assert!(one.iter().zip(&two).skip(1).all(|(one, two)| !one.same_course(two)));
    // The same value written otherwise in a block without a step: a jump
    // back could run it again unseen.
    assert_eq!(course(&text.replace("R4=2", "R4=1+1"), 2), [false; 7]);
    // A label or another block number before them: jumps back look them up.
    assert_eq!(course(&text.replace("N101 ", "N101 AGAIN: "), 7), [false; 7]);
    assert_eq!(course(&text.replace("N100 ", "N10 "), -1), [false; 7]);
}

#[test]
fn a_block_jumped_over_before_a_checkpoint_is_part_of_its_course() {
    // `AGAIN: G1 X{x}` runs only after the checkpoints: its text decides
    // the run.
    let program = |x: &str| {
        format!("G0 X0 F100\nGOTOF START\nAGAIN: G1 X{x}\nGOTOF END\nSTART: G1 Y1\nG1 Y2\nGOTOB AGAIN\nEND: M30\n")
    };
    let (short, long) = (checkpoints(&program("1"), &NoFiles, 1), checkpoints(&program("10"), &NoFiles, 1));
    assert_eq!(short.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 1, 4, 5, 6, 7]);
    assert!(!short[2].same_course(&long[2].shifted(-1, 0, 0)));
    assert!(short[1].same_course(&long[1]));
    assert_resumes_as_the_whole_run(&program("1"), &NoFiles, 1);
}

/// Pieces of programs to put together: moves, variables, IF … ELSE …
/// ENDIF, WHILE and FOR loops, a jump over a block and one back to a
/// label, frames, a compensated stretch, a spline, a modal drilling cycle,
/// a call, a dwell. `{n}` is a number of its own for each piece.
const PIECES: [&str; 13] = [
    "G1 X=R1+1 Y2\n",
    "G0 X5 Y5\n",
    "R1=R1+1\nIF R1>3\nR2=R1\nELSE\nG1 X1\nENDIF\n",
    "R5=0\nWHILE R5<2\nG1 X=R5 Y1\nR5=R5+1\nENDWHILE\n",
    "FOR I=1 TO 2\nG1 Y=I\nENDFOR\n",
    "GOTOF SKIP{n}\nG1 X77\nSKIP{n}: G1 Y-1\n",
    "R7=0\nBACK{n}: G1 X3\nR7=R7+1\nIF R7<2 GOTOB BACK{n}\n",
    "TRANS X{n}\nAROT Z10\nG1 X1\nTRANS\n",
    "$TC_DP6[1,1]=2\nT1 D1\nG41 G1 X0 Y0\nG1 X10\nG1 Y10\nG40 G1 X-10 Y-10\n",
    "BSPLINE X1 Y1\nX2 Y3\nX4 Y1\nG1 X5 Y5\n",
    "MCALL CYCLE81(10,0,2,-20)\nG0 X3 Y3\nMCALL\n",
    "PROFIL\n",
    "G4 F0.1\n",
];

/// A program of `pieces` after a start.
fn generated(pieces: &[usize]) -> String {
    let mut text = String::from("DEF INT I\nG17 G0 X0 Y0 Z5 S1000 M3\nF500\n");
    for (n, &piece) in pieces.iter().enumerate() {
        text.push_str(&PIECES[piece].replace("{n}", &(100 + n).to_string()));
    }
    text.push_str("M30\n");
    text
}

#[test]
fn the_pieces_of_generated_programs_run_without_findings() {
    let text = generated(&(0..PIECES.len()).collect::<Vec<_>>());
    let trace = run_with(&text, &profil());
    assert_eq!(findings(&trace, &text), []);
    assert!(!trace.tool_centre.is_empty() && trace.files.len() == 1);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Over generated programs with loops, jumps, frames, compensation,
    /// splines, cycles and calls, a run resumed from any checkpoint goes on
    /// as the whole run.
    #[test]
    fn runs_resumed_from_any_checkpoint_go_on_as_whole_runs(
        pieces in proptest::collection::vec(0..PIECES.len(), 1..24),
        every in 1usize..4,
    ) {
        assert_resumes_as_the_whole_run(&generated(&pieces), &profil(), every);
    }
}
