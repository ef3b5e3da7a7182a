use super::*;
use crate::{
    run::run_into,
    trace::{DEFAULT_STEP_BUDGET, NoFiles, PathMode},
};
use ncc_catalog::Dialect;

fn expand(text: &str) -> String {
    let machine = MachineConfig::of_control(Dialect::Sinumerik);
    let mut out = Vec::new();
    let mut expansion = Box::new(Expansion::new(&mut out, &machine, "EXPANDED FROM T.MPF"));
    let trace = run_into(text, &NoFiles, &machine, DEFAULT_STEP_BUDGET, &mut *expansion);
    assert_eq!(trace.findings, []);
    expansion.finish().expect("written");
    String::from_utf8(out).expect("text")
}

#[test]
fn loops_and_arcs_become_plain_blocks() {
    let text = "DEF INT PASS\nG0 X10 Y0\nFOR PASS=1 TO 2\nG1 Z=-PASS F100\nENDFOR\nG64 SOFT G3 X0 Y10 CR=10\nG18 G2 Z0 X2 K2 I0\nG4 F1.5\nM0\nM30\n";
    let written = expand(text);
    let expected = "; EXPANDED FROM T.MPF\nG17 G71 G90 G94 G60 BRISK\nG0 X10 Y0 Z0\nG1 Z-1 F100\nG1 Z-2\nG642 CTOL=0.01 SOFT G3 X0 Y10 I-10 J0\nG18 G2 X2 Z0 K2 I0\nG4 F1.5\nM0\nM30\n";
    assert_eq!(written, expected);
    assert_eq!((decimal(-3000), decimal(12_500), decimal(1)), ("-3".to_owned(), "12.5".to_owned(), "0.001".to_owned()));
}

#[test]
fn the_expansion_runs_the_same_moves() {
    let text = "G0 X5 Y5\nF500 G642\nG2 X15 Y5 CR=5\nSOFT BSPLINE X20 Y10\nX25 Y5\nG1 X0 Y0 G9\nG641 ADIS=0.2 X3\nG60 Y3\nM30\n";
    let machine = MachineConfig::of_control(Dialect::Sinumerik);
    let original = crate::run::run(text, &NoFiles, &machine, DEFAULT_STEP_BUDGET);
    let expanded = expand(text);
    let again = crate::run::run(&expanded, &NoFiles, &machine, DEFAULT_STEP_BUDGET);
    assert_eq!(again.findings, []);
    let length = |trace: &crate::trace::Trace| trace.steps.iter().map(|step| step.length).sum::<f64>();
    assert!((length(&original) - length(&again)).abs() < 1e-3, "{expanded}");
    // The path passes from move to move as it did.
    let joins = |trace: &crate::trace::Trace| -> Vec<_> {
        let moves = trace.steps.iter().filter(|step| matches!(step.motion, Motion::Rapid | Motion::Feed));
        // An exact stop bounds its corner by no tolerance.
        let corner =
            |step: &Step| (step.path_mode == PathMode::Continuous).then(|| (step.corner_tolerance * 1000.0).round());
        moves.map(|step| (step.path_mode, step.jerk_limited, corner(step))).collect()
    };
    assert_eq!(joins(&original), joins(&again), "{expanded}");
    assert_eq!(original.end_position(), again.end_position());
}

#[test]
fn under_radius_compensation_the_tool_centre_is_written() {
    // G41 radius 2 outside a right turn: the corner's arc is a block of
    // its own, before the next side; the cancel goes back to (30, -10).
    let text = "$TC_DP6[1,1]=2\nT1 D1\nG0 X0 Y-10\nG41 G1 X0 Y0 F500\nX20\nY-10\nG40 X30\nM30\n";
    let expected = "; EXPANDED FROM T.MPF\nG17 G71 G90 G94 G60 BRISK\nG0 X0 Y-10 Z0\nG1 Y2 F500\nG1 X20\nG2 X22 Y0 I0 J-2\nG1 Y-10\nG1 X30\nM30\n";
    assert_eq!(expand(text), expected);
    // G42 is inside both corners: the sides meet at their intersection.
    let expected =
        "; EXPANDED FROM T.MPF\nG17 G71 G90 G94 G60 BRISK\nG0 X0 Y-10 Z0\nG1 Y-2 F500\nG1 X18\nG1 Y-10\nG1 X30\nM30\n";
    assert_eq!(expand(&text.replace("G41", "G42")), expected);
}
