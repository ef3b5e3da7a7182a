//! Quick fixes resolve what they are offered for, without losing text.

use ncc_analysis::{AnalysisHost, Diagnostic};

fn apply_fix(text: &str, diagnostic: &Diagnostic) -> String {
    let mut result = text.to_owned();
    let mut edits = diagnostic.fixes[0].edits.clone();
    edits.sort_by_key(|e| std::cmp::Reverse(e.delete.start()));
    for edit in edits {
        edit.apply(&mut result);
    }
    result
}

fn diagnostics(text: &str) -> Vec<Diagnostic> {
    let mut host = AnalysisHost::default();
    let file = host.add_file("main.NCP", text);
    host.analysis().diagnostics(file)
}

#[test]
fn missing_g70_fix_closes_the_subprogram() {
    let text = "%1\nN10 G71 L100\nN20 M30\nN100 G79 L100\nN110 G00 X5. \"keep me\"\nN200 G79 L200\nN210 G70\n*\n";
    let found = diagnostics(text);
    let missing = found.iter().find(|d| d.name == "missing-g70").expect("missing-g70");
    let fixed = apply_fix(text, missing);
    assert_eq!(
        fixed,
        "%1\nN10 G71 L100\nN20 M30\nN100 G79 L100\nN110 G00 X5. \"keep me\"\nN120 G70\nN200 G79 L200\nN210 G70\n*\n"
    );
    assert!(diagnostics(&fixed).is_empty(), "{:#?}", diagnostics(&fixed));
}

#[test]
fn missing_g70_fix_at_the_end_of_a_file_without_newline() {
    let text = "%1\nN10 M30\nN100 G79 L100\nN101 G00 X5.";
    let found = diagnostics(text);
    let missing = found.iter().find(|d| d.name == "missing-g70").expect("missing-g70");
    let fixed = apply_fix(text, missing);
    assert_eq!(fixed, "%1\nN10 M30\nN100 G79 L100\nN101 G00 X5.\nN102 G70\n");
}

#[test]
fn empty_block_fix_removes_the_block() {
    let text = "%1\nN10 G00 X5.\nN20\nN30 M30\n*\n";
    let found = diagnostics(text);
    let empty = found.iter().find(|d| d.name == "empty-block").expect("empty-block");
    let fixed = apply_fix(text, empty);
    assert_eq!(fixed, "%1\nN10 G00 X5.\nN30 M30\n*\n");
    assert!(diagnostics(&fixed).is_empty(), "{:#?}", diagnostics(&fixed));
}

#[test]
fn arc_missing_end_coordinate_fix_repeats_the_unchanged_coordinate() {
    let text = "%1\nN10 G90 G17 G00 X0 Y5. F100\nN20 G02 X10. I5.\nN30 G91 G02 X0 I5.\nN40 M30\n*\n";
    let found = diagnostics(text);
    let missing: Vec<_> = found.iter().filter(|d| d.name == "arc-missing-end-coordinate").collect();
    assert_eq!(missing.len(), 2, "{found:#?}");
    let fixed = apply_fix(&apply_fix(text, missing[1]), missing[0]);
    assert_eq!(fixed, "%1\nN10 G90 G17 G00 X0 Y5. F100\nN20 G02 X10. Y5. I5.\nN30 G91 G02 X0 Y0 I5.\nN40 M30\n*\n");
    assert!(diagnostics(&fixed).is_empty(), "{:#?}", diagnostics(&fixed));
}

#[test]
fn haas_thread_angle_fix_drops_the_point_of_a_whole_angle() {
    let text = "O1\nG54 G00 X30. Z3.\nG97 S800 M03\nG76 X27. Z-20. K1.2 D0.3 A60. P1 F2.\nG76 X27. Z-20. K1.2 D0.3 A29.5 P1 F2.\nM30\n";
    let mut host = AnalysisHost::in_dialect(ncc_analysis::Dialect::HaasLathe, ncc_analysis::Config::default());
    let file = host.add_file("O1.nc", text);
    let found = host.analysis().diagnostics(file);
    let angles: Vec<&Diagnostic> = found.iter().filter(|d| d.name == "thread-angle-with-point").collect();
    assert_eq!(angles.len(), 2, "{found:#?}");
    // A29.5 has no whole value to keep: no fix.
    assert!(angles[1].fixes.is_empty());
    let fixed = apply_fix(text, angles[0]);
    assert_eq!(fixed, text.replace("A60.", "A60"));
    host.apply_edit(file, &angles[0].fixes[0].edits[0]);
    let left: Vec<&str> = host.analysis().diagnostics(file).iter().map(|d| d.name).collect();
    assert_eq!(left, ["thread-angle-with-point"]);
}
