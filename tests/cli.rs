//! End-to-end tests of the `ncc` binary.

use std::{
    path::{Path, PathBuf},
    process::{Command, Output},
};

use expect_test::expect;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn ncc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ncc")).args(args).current_dir(workspace()).output().unwrap()
}

fn stdout(output: &Output) -> String {
    String::from_utf8(output.stdout.clone()).unwrap()
}

#[test]
fn bundled_examples_pass() {
    let output = ncc(&["check", "examples"]);
    assert_eq!(output.status.code(), Some(0), "{}", stdout(&output));
    assert_eq!(stdout(&output), "All checks passed (4 files checked).\n");
}

#[test]
fn json_positions_count_characters_in_czech_comments() {
    let output = ncc(&["check", "--format", "json", "tests/fixtures/czech_columns.NCP"]);
    assert_eq!(output.status.code(), Some(1));
    expect![[r#"
        [
          {
            "file": "tests/fixtures/czech_columns.NCP",
            "line": 2,
            "column": 35,
            "end_line": 2,
            "end_column": 42,
            "severity": "error",
            "code": "S002",
            "name": "space-in-number",
            "message": "space inside a number: the control rejects a value interrupted by spaces; join the digits"
          },
          {
            "file": "tests/fixtures/czech_columns.NCP",
            "line": 3,
            "column": 34,
            "end_line": 3,
            "end_column": 37,
            "severity": "error",
            "code": "S003",
            "name": "space-after-sign",
            "message": "space between the sign and the digits: the control rejects it; write the sign next to the number"
          }
        ]
    "#]]
    .assert_eq(&stdout(&output));
}

#[test]
fn human_report_shows_code_message_and_line() {
    let output = ncc(&["check", "tests/fixtures/czech_columns.NCP"]);
    assert_eq!(output.status.code(), Some(1));
    let report = stdout(&output);
    assert!(report.contains("[S002 space-in-number] Error: space inside a number"), "{report}");
    // ariadne prints `file:line:column` with character columns.
    assert!(report.contains("tests/fixtures/czech_columns.NCP:2:35"), "{report}");
    assert!(report.contains("tests/fixtures/czech_columns.NCP:3:34"), "{report}");
    assert!(report.ends_with("Found 2 errors, 0 warnings, 0 infos and 0 hints in 1 file.\n"), "{report}");
}

#[test]
fn files_in_the_controls_code_page_are_read_losslessly() {
    let output = ncc(&["check", "--format", "json", "tests/fixtures/kamenicky.NCP"]);
    assert_eq!(output.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let first = &json[0];
    // `N10 G00 X1 "ŘÁ" Y 2 Z`: Z is the 21st character of line 2.
    assert_eq!((first["line"].as_u64(), first["column"].as_u64()), (Some(2), Some(21)));
    assert_eq!(first["code"], "S004");

    let tree = stdout(&ncc(&["parse", "tests/fixtures/kamenicky.NCP"]));
    assert!(tree.contains(r#"COMMENT@3..14 "\"ŘEZÁNÍ\"""#), "{tree}");
}

#[test]
fn warnings_alone_do_not_fail() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("typo.NCP");
    std::fs::write(&path, "%1\nN10 G00 X1 \u{201C}TYPOGRAPHIC QUOTE\nN20 M30\n*\n").unwrap();
    let output = ncc(&["check", "--format", "json", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(0));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json[0]["severity"], "warning");
    assert_eq!(json[0]["code"], "S010");
}

#[test]
fn directories_are_searched_for_partprograms() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("macros")).unwrap();
    std::fs::write(dir.path().join("main.ncp"), "%1\nN10 X\n").unwrap();
    std::fs::write(dir.path().join("macros/L9001"), "N10 G79 L9001\nN20 G70\n").unwrap();
    std::fs::write(dir.path().join("notes.txt"), "N10 X\n").unwrap();
    let output = ncc(&["check", "--format", "json", dir.path().to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let files: Vec<_> = json.as_array().unwrap().iter().map(|d| d["file"].as_str().unwrap().to_owned()).collect();
    assert!(!files.is_empty());
    assert!(files.iter().all(|f| f.ends_with("main.ncp")), "{files:?}");

    let human = stdout(&ncc(&["check", dir.path().to_str().unwrap()]));
    assert!(human.ends_with("in 2 files.\n"), "{human}");
}

#[test]
fn clean_file_gives_an_empty_json_array() {
    let output = ncc(&["check", "--format", "json", "tests/fixtures/clean.NCP"]);
    assert_eq!(output.status.code(), Some(0));
    assert_eq!(stdout(&output), "[]\n");
}

#[test]
fn missing_path_is_a_usage_error() {
    let output = ncc(&["check", "no/such/program.NCP"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("no/such/program.NCP: no such file or directory"));
}

#[test]
fn parse_prints_the_lossless_tree() {
    let output = ncc(&["parse", "tests/fixtures/clean.NCP"]);
    assert_eq!(output.status.code(), Some(0));
    let tree = stdout(&output);
    assert!(tree.starts_with("SOURCE_FILE@0..89\n  HEADER@0..10\n    PERCENT@0..1 \"%\"\n"), "{tree}");
    assert!(tree.contains("    WORD@51..54\n      LETTER@51..52 \"G\"\n      NUMBER@52..54 \"01\"\n"), "{tree}");
}

/// A CAM program of a million blocks (about 35 MB) is checked completely.
#[test]
fn checks_a_35_megabyte_program() {
    use ncc_bench::progen::{self, Syntax};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("surface.NCP");
    let text = progen::write(&progen::surfacing(1_000_000), Syntax::Cnc8x6);
    assert!(text.len() > 33_000_000);
    let broken = text.replacen("N999990 G1 X", "N999990 G1 X- ", 1);
    std::fs::write(&path, broken).unwrap();
    let output = ncc(&["check", "--format", "json", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json.as_array().unwrap().len(), 1, "{json}");
    let last_lines = text.lines().position(|l| l.starts_with("N999990 ")).unwrap() + 1;
    assert_eq!(json[0]["line"].as_u64(), Some(last_lines as u64));
    assert_eq!(json[0]["code"], "S003");
}

#[test]
fn explain_prints_the_catalogue_text() {
    let output = ncc(&["explain", "G40"]);
    assert_eq!(output.status.code(), Some(0));
    let text = stdout(&output);
    assert!(text.starts_with("### G40 — "), "{text}");
    assert!(text.contains("Group: G3"), "{text}");

    let text = stdout(&ncc(&["explain", "R39"]));
    assert!(text.starts_with("### R39 — machine constant"), "{text}");
    assert!(text.contains("### R39 — program parameter"), "{text}");
    assert!(stdout(&ncc(&["explain", "op:48"])).starts_with("### Operation 48 — "));
    assert!(stdout(&ncc(&["explain", "x"])).starts_with("### X — "));
}

#[test]
fn explain_suggests_for_unknown_input() {
    let output = ncc(&["explain", "G99"]);
    assert_eq!(output.status.code(), Some(1));
    let error = String::from_utf8_lossy(&output.stderr);
    assert!(error.contains("`G99` is not a code"), "{error}");
    assert!(error.contains("did you mean G09"), "{error}");
}

#[test]
fn explain_list_prints_the_counts() {
    let text = stdout(&ncc(&["explain", "--list"]));
    for heading in
        ["groups (26)", "G codes (70)", "M codes (29)", "addresses (29)", "program parameters (96)", "operations (52)"]
    {
        assert!(text.contains(heading), "{heading} missing from\n{text}");
    }
}
