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
    assert_eq!(stdout(&output), "All checks passed (9 files checked).\n");
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
            "message": "space inside a number: the control rejects a value interrupted by spaces; join the digits",
            "related": [],
            "fixes": []
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
            "message": "space between the sign and the digits: the control rejects it; write the sign next to the number",
            "related": [],
            "fixes": []
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

/// Lines end at a lone `\r` too, as the parser reads them: old files from
/// the control's editor end their lines so.
#[test]
fn positions_count_lines_ended_by_a_carriage_return() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("CR.NCP");
    std::fs::write(&path, "%1\rN10 G00 X1\rN20 Y\rN30 M30\r*\r").unwrap();
    let path = path.to_str().unwrap();
    let json: serde_json::Value = serde_json::from_slice(&ncc(&["check", "--format", "json", path]).stdout).unwrap();
    assert_eq!(
        (json[0]["code"].as_str(), json[0]["line"].as_u64(), json[0]["column"].as_u64()),
        (Some("S004"), Some(3), Some(5))
    );
    let human = stdout(&ncc(&["check", path]));
    assert!(human.contains(&format!("{path}:3:5")), "{human}");
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

/// A program saved as UTF-16 or UTF-32 text (with the byte-order mark
/// editors write) is checked as written; the encoding is one finding.
#[test]
fn unicode_files_are_checked_as_written_with_one_finding_for_the_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let program = "\u{FEFF}%1 \"ŘEZ\"\r\nN10 G00 X0 Y0\r\nN20 M30\r\n*\r\n";
    let utf16: Vec<u8> = program.encode_utf16().flat_map(u16::to_le_bytes).collect();
    let utf32: Vec<u8> = program.chars().flat_map(|c| u32::from(c).to_be_bytes()).collect();
    for (name, bytes) in [("UTF16.NCP", utf16), ("UTF32.NCP", utf32)] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let path = path.to_str().unwrap();
        let output = ncc(&["check", "--format", "json", path]);
        let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let codes: Vec<&str> = json.as_array().unwrap().iter().map(|d| d["code"].as_str().unwrap()).collect();
        assert_eq!(codes, ["S020"], "{name}: {json}");
        assert_eq!((json[0]["line"].as_u64(), json[0]["column"].as_u64()), (Some(1), Some(1)));
        let human = stdout(&ncc(&["check", path]));
        assert!(human.contains("[S020 byte-order-mark] Warning: the file starts with a byte-order mark"), "{human}");
        assert!(!human.contains('\0'), "{human}");
    }
}

#[test]
fn warnings_fail_and_infos_do_not() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("typo.NCP");
    std::fs::write(&path, "%1\nN10 G00 X1 \u{201C}TYPOGRAPHIC QUOTE\nN20 M30\n*\n").unwrap();
    let output = ncc(&["check", "--format", "json", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json[0]["severity"], "warning");
    assert_eq!(json[0]["code"], "S010");

    // Without the physical end `*` there is only an info.
    std::fs::write(&path, "%1\nN10 G00 X1\nN20 M30\n").unwrap();
    let output = ncc(&["check", "--format", "json", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(0));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json[0]["severity"], "info", "{json}");
}

#[test]
fn short_format_is_one_line_per_finding() {
    let output = ncc(&["check", "--format", "short", "tests/fixtures/findings.NCP"]);
    assert_eq!(output.status.code(), Some(1));
    expect![[r#"
        tests/fixtures/findings.NCP:4:6: error[R301]: the parameter holds 0.123 (123 as digits, 3 decades) but `G` takes at most 2: the control stops with "an R of more than 2 decades cannot be substituted"
        tests/fixtures/findings.NCP:7:1: error[P109]: subprogram L100 has no closing G70 block: the file ends before it is closed
    "#]]
    .assert_eq(&stdout(&output));
}

#[test]
fn json_has_related_locations_and_fixes() {
    let output = ncc(&["check", "--format", "json", "tests/fixtures/findings.NCP"]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let overflow = &json[0];
    assert_eq!(overflow["code"], "R301");
    assert_eq!(overflow["related"][0]["line"], 3);
    assert_eq!(overflow["related"][0]["column"], 9);
    assert_eq!(overflow["related"][0]["message"], "the value was assigned here");
    let missing_g70 = &json[1];
    assert_eq!(missing_g70["fixes"][0]["edits"][0]["new_text"], "N80 G70\n");
    assert_eq!(missing_g70["fixes"][0]["edits"][0]["line"], 9);
}

#[test]
fn sarif_is_valid_against_the_schema() {
    // The published schema's `language` pattern has a stray `]`, which makes
    // the schema itself invalid; it is corrected to what it means.
    let text = include_str!("schemas/sarif-2.1.0.json")
        .replace(r#""^[a-zA-Z]{2}|^[a-zA-Z]{2}-[a-zA-Z]{2}]?$""#, r#""^[a-zA-Z]{2}(-[a-zA-Z]{2})?$""#);
    let schema: serde_json::Value = serde_json::from_str(&text).expect("the schema is JSON");
    let validator = jsonschema::validator_for(&schema).expect("the schema compiles");
    let output = ncc(&["check", "--format", "sarif", "tests/fixtures/findings.NCP", "tests/fixtures/clean.NCP"]);
    assert_eq!(output.status.code(), Some(1));
    let log: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let errors: Vec<String> = validator.iter_errors(&log).map(|e| format!("{e} at {}", e.instance_path())).collect();
    assert!(errors.is_empty(), "{errors:#?}");
    // The validator does reject what the schema forbids.
    let mut broken = log.clone();
    broken["runs"][0]["results"][0]["level"] = "fatal".into();
    assert!(!validator.is_valid(&broken));

    let run = &log["runs"][0];
    assert_eq!(log["version"], "2.1.0");
    assert_eq!(run["columnKind"], "unicodeCodePoints");
    let results = run["results"].as_array().unwrap();
    assert_eq!(results.len(), 2);
    let rules = run["tool"]["driver"]["rules"].as_array().unwrap();
    for result in results {
        let index = result["ruleIndex"].as_u64().unwrap() as usize;
        assert_eq!(rules[index]["id"], result["ruleId"]);
    }
    let overflow = &results[0];
    assert_eq!(overflow["ruleId"], "R301");
    assert_eq!(overflow["level"], "error");
    let location = &overflow["locations"][0]["physicalLocation"];
    assert_eq!(location["artifactLocation"]["uri"], "tests/fixtures/findings.NCP");
    assert_eq!(location["artifactLocation"]["uriBaseId"], "SRCROOT");
    assert_eq!(
        (location["region"]["startLine"].as_u64(), location["region"]["startColumn"].as_u64()),
        (Some(4), Some(6))
    );
    assert_eq!(overflow["relatedLocations"][0]["physicalLocation"]["region"]["startLine"], 3);
    let fix = &results[1]["fixes"][0]["artifactChanges"][0]["replacements"][0];
    assert_eq!(fix["insertedContent"]["text"], "N80 G70\n");
}

#[test]
fn macrocycles_beside_a_checked_program_are_resolved_not_reported() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("main.NCP");
    std::fs::write(&program, "%1\nN10 G72 L9001\nN20 M30\n*\n").unwrap();
    // The macrocycle has a finding of its own (a repeated address).
    std::fs::write(dir.path().join("L9001"), "N10 G79 L9001\nN20 X1 X2\nN30 G70\n").unwrap();
    let output = ncc(&["check", "--format", "json", program.to_str().unwrap()]);
    assert_eq!(stdout(&output), "[]\n");
    assert_eq!(output.status.code(), Some(0));

    std::fs::remove_file(dir.path().join("L9001")).unwrap();
    let output = ncc(&["check", "--format", "json", program.to_str().unwrap()]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json[0]["name"], "undefined-macrocycle", "{json}");
}

#[test]
fn rules_lists_every_rule_and_finds_one() {
    let output = ncc(&["rules"]);
    assert_eq!(output.status.code(), Some(0));
    let text = stdout(&output);
    assert!(text.contains("S002  error    space-in-number"), "{text}");
    assert!(text.contains("missing-g70"), "{text}");

    let text = stdout(&ncc(&["rules", "missing-g70"]));
    assert!(text.starts_with("P109  error    missing-g70  "), "{text}");
    assert!(text.ends_with("1 rules\n"), "{text}");
    assert_eq!(ncc(&["rules", "no-such-rule"]).status.code(), Some(1));
}

#[test]
fn the_rules_reference_is_current() {
    let output = ncc(&["rules", "--markdown"]);
    assert_eq!(output.status.code(), Some(0));
    let text = stdout(&output);
    let listed = text.lines().filter(|line| line.starts_with("| ") && !line.starts_with("| code")).count();
    assert_eq!(listed, ncc_analysis::Rule::all().count(), "every rule has a section");
    expect_test::expect_file!["../docs/rules.md"].assert_eq(&text);
}

#[test]
fn usage_errors_exit_with_2() {
    assert_eq!(ncc(&["check", "--format", "xml", "examples"]).status.code(), Some(2));
    assert_eq!(ncc(&["frobnicate"]).status.code(), Some(2));
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

/// The pre-commit hook's `files` pattern picks the files `ncc check` finds
/// in a directory.
#[test]
fn the_pre_commit_hook_matches_the_partprograms() {
    let hooks = std::fs::read_to_string(workspace().join(".pre-commit-hooks.yaml")).unwrap();
    let pattern = hooks
        .lines()
        .find_map(|line| line.trim().strip_prefix("files: '")?.strip_suffix('\''))
        .expect("a single-quoted `files:` pattern");
    let pattern = regex::Regex::new(pattern).unwrap();
    let names = [
        "a.NCP",
        "b.ncp",
        "L9001",
        "l12",
        "macros/L9001",
        "macros/L12.NCP",
        "notes.txt",
        "L12a",
        "LX.NCP",
        "NCP",
        "L",
        "sub/L7.txt",
        "PL12",
    ];
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("macros")).unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    for name in names {
        std::fs::write(dir.path().join(name), "%1\nN10 X\n").unwrap();
    }
    let output = ncc(&["check", "--format", "json", dir.path().to_str().unwrap()]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let prefix = format!("{}/", dir.path().display());
    let mut found: Vec<String> = json
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["file"].as_str().unwrap().strip_prefix(&prefix).unwrap().to_owned())
        .collect();
    found.sort();
    found.dedup();
    let mut matched: Vec<String> = names.iter().filter(|name| pattern.is_match(name)).map(|n| n.to_string()).collect();
    matched.sort();
    assert_eq!(found, matched);
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
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("no/such/program.NCP: No such file or directory (os error 2)"), "{stderr}");
}

/// `ncc` with a timeout: a command that waits forever fails the test
/// instead of hanging it.
fn ncc_within(args: &[&str], limit: std::time::Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ncc"))
        .args(args)
        .current_dir(workspace())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            child.kill().unwrap();
            panic!("`ncc {}` still runs after {limit:?}", args.join(" "));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// A path that is no regular file is reported with what it is, by `check`
/// and `run` alike; a named pipe without a writer is not waited for.
#[cfg(unix)]
#[test]
fn paths_that_are_no_regular_files_are_reported_as_what_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("PIPE.NCP");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let (loop_a, loop_b) = (dir.path().join("A.NCP"), dir.path().join("B.NCP"));
    std::os::unix::fs::symlink(&loop_b, &loop_a).unwrap();
    std::os::unix::fs::symlink(&loop_a, &loop_b).unwrap();
    let cases = [
        ("/dev/null".into(), "a character device, not a regular file"),
        (fifo.display().to_string(), "a named pipe (FIFO), not a regular file"),
        (loop_a.display().to_string(), "Too many levels of symbolic links"),
    ];
    for (path, cause) in &cases {
        for command in ["check", "run"] {
            let output = ncc_within(&[command, path], std::time::Duration::from_secs(20));
            assert_eq!(output.status.code(), Some(2), "{command} {path}");
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(stderr.contains(&format!("{path}: {cause}")), "{command} {path}: {stderr}");
        }
    }
}

#[test]
fn parse_prints_the_lossless_tree() {
    let output = ncc(&["parse", "tests/fixtures/clean.NCP"]);
    assert_eq!(output.status.code(), Some(0));
    let tree = stdout(&output);
    assert!(tree.starts_with("SOURCE_FILE@0..89\n  HEADER@0..10\n    PERCENT@0..1 \"%\"\n"), "{tree}");
    assert!(tree.contains("      WORD@51..54\n        LETTER@51..52 \"G\"\n        NUMBER@52..54 \"01\"\n"), "{tree}");
}

/// The first `lines` lines `ncc lower` prints for `path`.
fn lowered(path: &str, lines: usize) -> Vec<String> {
    let output = ncc(&["lower", path]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    stdout(&output).lines().take(lines).map(str::to_owned).collect()
}

/// `ncc lower` prints each block as the executor reads it, after its line.
#[test]
fn lower_prints_the_blocks_as_the_executor_reads_them() {
    expect![[r#"
        [
            "     5  N10 G90 G17 G80 G94 G54",
            "     6  N20 T5 M06",
            "     7  N30 G00 X20. Y20. S1200 M03",
            "     8  N40 Z50. &0010 D5 M08",
            "     9  N50 R20=30. R21=5 R22=2. R23=-2.5 R24=100 R25=30",
        ]
    "#]]
    .assert_debug_eq(&lowered("examples/milling/holes.NCP", 5));
    assert_eq!(ncc(&["lower", "no/such/program.NCP"]).status.code(), Some(2));
    expect![[r#"
        [
            "     4  def None Real DEPTH[]; STEP[] = 2",
            "     5  def None Int PASS[]; PASSES[] = 3; HOLES[]",
            "     6  G17 | G54 | G71 | G90 | G94",
            "     7  T=\"END MILL 10\"",
        ]
    "#]]
    .assert_debug_eq(&lowered("examples/sinumerik/POCKET.MPF", 4));
}

/// A CAM program of a million blocks (about 35 MB) is checked completely.
#[test]
fn checks_a_35_megabyte_program() {
    use ncc_bench::cnc8x6::progen::{self, Syntax};
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

#[test]
fn explain_reads_the_sinumerik_catalogue() {
    let output = ncc(&["explain", "--dialect", "sinumerik", "bspline"]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(text.starts_with("### BSPLINE — B-spline"), "{text}");
    assert!(text.contains("`G[1]=7` selects it"), "{text}");
    let text = stdout(&ncc(&["explain", "--dialect", "sinumerik", "$P_XYZ"]));
    assert!(text.starts_with("### $P_… — a system variable ncc does not document"), "{text}");
    let text = stdout(&ncc(&["explain", "--dialect", "sinumerik", "--list"]));
    for heading in ["G group words (", "keywords (", "functions (", "system variables (", "fixed cycles (12)"] {
        assert!(text.contains(heading), "{heading} missing from\n{text}");
    }
    let output = ncc(&["explain", "--dialect", "sinumerik", "GOTOX"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("of Siemens Sinumerik"), "{}", stderr(&output));
}

/// A diagnostic's code explains its rule, before what the catalogue reads
/// in the same letters.
#[test]
fn explain_names_the_rule_of_a_diagnostic_code() {
    let output = ncc(&["explain", "--dialect", "sinumerik", "k105"]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(text.starts_with("### K105 — jump-wrong-direction\n"), "{text}");
    assert!(text.contains("GOTOF to a target only behind the jump"), "{text}");
    let text = stdout(&ncc(&["explain", "K047"]));
    assert!(text.contains("warning, opt-in"), "{text}");
}

/// `ncc plot` draws the moves with their lines, rapids dashed, an arc as
/// chords, the breaks marked and the total time in the legend.
#[test]
fn plot_draws_the_toolpath_as_svg() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("PLOT.NCP");
    let text = "%1\nN1 G00 X10 Y0\nN2 G01 X20 F600\nN3 G03 X30 Y0 I5 J0\nN4 M30\n";
    std::fs::write(&program, text).unwrap();
    let svg = dir.path().join("plot.svg");
    let output = ncc(&["plot", program.to_str().unwrap(), "-o", svg.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let svg = std::fs::read_to_string(svg).unwrap();
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""), "{svg}");
    assert!(svg.trim_end().ends_with("</svg>"));
    let paths: Vec<&str> = svg.lines().filter(|line| line.starts_with("<path")).collect();
    assert_eq!(paths.len(), 3, "{svg}");
    assert!(paths[0].contains("data-line=\"2\"") && paths[0].contains("stroke-dasharray"), "the rapid: {}", paths[0]);
    assert!(paths[1].contains("data-line=\"3\"") && paths[1].contains("line 3: 600 mm/min"), "{}", paths[1]);
    // A half circle in chords of 5°: 36 chords, 37 points.
    assert_eq!(paths[2].matches(" L").count(), 36, "{}", paths[2]);
    // Stops after the rapid, between the G98 moves and before M30.
    assert_eq!(svg.lines().filter(|line| line.starts_with("<circle data-line")).count(), 3, "{svg}");
    // The part's extent is the cutting moves': the half circle dips to Y-5.
    assert!(svg.contains("XY plane · part X 10…30, Y -5…0, Z 0…0 mm · total time"), "{svg}");
}

/// `ncc plot -o NAME.png` draws the same picture as a PNG image at twice
/// the SVG's size, on white, with the moves in colour.
#[test]
fn plot_writes_a_png_image() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("PLOT.NCP");
    std::fs::write(&program, "%1\nN1 G00 X10 Y0\nN2 G01 X20 F600\nN3 G03 X30 Y0 I5 J0\nN4 M30\n").unwrap();
    let (svg, png) = (dir.path().join("plot.svg"), dir.path().join("plot.PNG"));
    for output in [&svg, &png] {
        let run = ncc(&["plot", program.to_str().unwrap(), "-o", output.to_str().unwrap()]);
        assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
    }
    let svg = std::fs::read_to_string(svg).unwrap();
    let size = |attribute: &str| -> u32 {
        let start = svg.find(&format!(" {attribute}=\"")).unwrap() + attribute.len() + 3;
        svg[start..].split('"').next().unwrap().parse().unwrap()
    };
    let image = resvg::tiny_skia::Pixmap::decode_png(&std::fs::read(png).unwrap()).unwrap();
    assert_eq!((image.width(), image.height()), (2 * size("width"), 2 * size("height")));
    let pixels = image.pixels();
    assert!(pixels[0].red() == 255 && pixels[0].green() == 255 && pixels[0].blue() == 255, "a white background");
    let coloured =
        pixels.iter().filter(|p| p.red().abs_diff(p.green()) > 64 || p.red().abs_diff(p.blue()) > 64).count();
    assert!(coloured > 100, "the moves in the speed's colours: {coloured} pixels");
}

/// A lathe's picture in either view: the cut at X50. (a diameter) runs at
/// the scale's mark 25 in the radius view and at the marks 50 on both
/// sides of the spindle axis in the diameter view, the default, which
/// mirrors the path there; a mill's picture has a scale in mm without a
/// mirror image.
#[test]
fn plot_draws_a_lathe_in_the_radius_or_the_diameter_view() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("O0001.nc");
    let text = "%\nO00001\nG18 G21 G99 G54\nT101\nG97 S1000 M03\nG00 X50. Z10.\nG01 Z-20. F0.2\nG00 X60.\nM30\n%\n";
    std::fs::write(&program, text).unwrap();
    let draw = |view: Option<&str>| {
        let svg = dir.path().join("lathe.svg");
        let mut args = vec!["plot", program.to_str().unwrap(), "-o", svg.to_str().unwrap()];
        args.extend(view.map(|view| ["--view", view]).into_iter().flatten());
        let output = ncc(&args);
        assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
        std::fs::read_to_string(svg).unwrap()
    };
    // The height of the cut (line 7), and of the scale's marks labelled `label`.
    let cut_height = |svg: &str| -> f64 {
        let cut = svg.lines().find(|line| line.starts_with("<path data-line=\"7\"")).unwrap();
        let d = cut.split(" d=\"").nth(1).unwrap().split('"').next().unwrap();
        d.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let marks = |svg: &str, label: &str| -> Vec<f64> {
        let scale = &svg[svg.find("<g id=\"scale\"").unwrap_or_else(|| panic!("no scale: {svg}"))..];
        let scale = &scale[..scale.find("</g>").unwrap()];
        let text = format!(">{label}</text>");
        // Each label sits 2 pixels above its grid line.
        scale
            .lines()
            .filter(|line| line.ends_with(&text))
            .map(|line| line.split(" y=\"").nth(1).unwrap().split('"').next().unwrap().parse::<f64>().unwrap() + 2.0)
            .collect()
    };

    let radius = draw(Some("radius"));
    assert_eq!(marks(&radius, "25"), [cut_height(&radius)], "{radius}");
    assert!(marks(&radius, "50").is_empty(), "{radius}");
    assert!(!radius.contains("mirror-image") && radius.contains("ZX plane, X as a radius"), "{radius}");

    let diameter = draw(Some("diameter"));
    assert_eq!(draw(None), diameter, "the diameter view is the default");
    let (cut, axis) = (cut_height(&diameter), spindle_axis_height(&diameter));
    assert_eq!(marks(&diameter, "50"), [cut, 2.0 * axis - cut], "{diameter}");
    assert!(diameter.contains(&format!("<g id=\"mirror-image\" transform=\"matrix(1 0 0 -1 0 {:.2})\"", 2.0 * axis)));
    assert!(diameter.contains("ZX plane, X as a diameter"), "{diameter}");

    let mill = dir.path().join("MILL.NCP");
    std::fs::write(&mill, "%1\nN1 G00 X10 Y0\nN2 G01 X20 F600\nN3 M30\n").unwrap();
    let svg = dir.path().join("mill.svg");
    let output = ncc(&["plot", mill.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--view", "radius"]);
    assert_eq!(output.status.code(), Some(0));
    let svg = std::fs::read_to_string(svg).unwrap();
    assert!(svg.contains("id=\"scale\"") && !svg.contains("mirror-image") && svg.contains("XY plane ·"), "{svg}");
    assert!(svg.contains(">X mm</text>") && svg.contains(">Y mm</text>"), "a mill's scale names its axes: {svg}");
}

/// The height in pixels of a lathe picture's spindle axis.
fn spindle_axis_height(svg: &str) -> f64 {
    let axis = svg.lines().find(|line| line.starts_with("<line id=\"spindle-axis\"")).unwrap();
    axis.split(" y1=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap()
}

/// On a lathe the summary gives the end on the diameter axis as the
/// diameter the program wrote (`N640 G00 X100. Z100.`), the JSON as a radius.
#[test]
fn run_shows_the_lathe_end_as_a_diameter() {
    let output = ncc(&["run", "examples/lathe/shaft.NCP"]);
    assert_eq!(output.status.code(), Some(0));
    assert!(stdout(&output).contains("end position X100.000 Z100.000 (X as a diameter)\n"), "{}", stdout(&output));
    let output = ncc(&["run", "examples/lathe/shaft.NCP", "--format", "json"]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json["end_position"]["X"], 50.0);
}

/// A block that runs many times is one place in the summary's list of
/// breaks, with its runs and their cost added up; blocks that come back
/// out of order need every break kept.
#[test]
fn run_lists_a_subprograms_breaks_once_with_their_runs() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("LOOP.NCP");
    let text = "%1 \"LOOP\"\nN1 G01 G98 X10 F600\nN2 G71 L5 Q3\nN3 G01 X0\nN4 M30\nN5 G79 L5\nN6 G91 G01 X5 F600\nN7 X-5\nN8 G90 G70\n";
    std::fs::write(&program, text).unwrap();
    let program = program.to_str().unwrap();
    let output = ncc(&["run", program]);
    assert_eq!(output.status.code(), Some(0));
    let summary = stdout(&output).replace(program, "LOOP.NCP");
    let breaks = &summary[summary.find("breaks ").unwrap()..];
    expect![[r#"
        breaks       8 where the path speed drops (5 non-motion, 3 g98), costing 0:00:00.215
            LOOP.NCP:7  G98 joins no blocks: a stop and a pause before the next: 600 → 0 mm/min, 0.090 s (3 runs)
            LOOP.NCP:8  a block without motion between moves: 600 → 0 mm/min, 0.075 s (3 runs)
            LOOP.NCP:2  a block without motion between moves: 600 → 0 mm/min, 0.025 s
            LOOP.NCP:4  a block without motion between moves: 600 → 0 mm/min, 0.025 s
    "#]]
    .assert_eq(breaks);
}

/// `ncc run` prints the time split and the end; JSON has the total and a
/// record per block with its source line.
#[test]
fn run_prints_the_time_and_a_record_per_block() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("DEMO.NCP");
    let text = "%1 \"DEMO\"\nN1 G00 X100 Y0 T1\nN2 G01 X100 Y100 F600\nN3 G02 X0 Y100 I-50\nN4 G04 Q150 R5=51073051 G26\nN5 G01 G08 X0\nN6 M30\n";
    std::fs::write(&program, text).unwrap();
    let program = program.to_str().unwrap();

    let output = ncc(&["run", program]);
    assert_eq!(output.status.code(), Some(0));
    let summary = stdout(&output).replace(program, "DEMO.NCP");
    expect![[r#"
        DEMO.NCP
          total time   0:00:28.055  (0:00:27.808 at the programmed feeds)
            cutting    0:00:25.768       257.080 mm
            rapid      0:00:00.787       100.000 mm
            dwell      0:00:01.500
          messages     1 by operation 51 (codes 7)
          tools        T1
          end position X0.000 Y100.000 Z0.000 U0.000 V0.000 C0.000
          breaks       3 where the path speed drops (1 g98, 1 non-motion, 1 rapid), costing 0:00:00.090
            DEMO.NCP:3  G98 joins no blocks: a stop and a pause before the next: 600 → 0 mm/min, 0.030 s
            DEMO.NCP:4  a block without motion between moves: 600 → 0 mm/min, 0.025 s
    "#]]
    .assert_eq(&summary);
    let warnings = String::from_utf8(output.stderr).unwrap().replace(program, "DEMO.NCP");
    assert_eq!(warnings, "DEMO.NCP:6: info[E020]: the executor does not run G08 yet: the time leaves them out\n");

    let output = ncc(&["run", program, "--format", "json"]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let programmed = json["programmed_time_s"].as_f64().unwrap();
    assert!((programmed - (0.6 + 10.0 + 50.0 * std::f64::consts::PI / 600.0 * 60.0 + 1.5)).abs() < 1e-9);
    // The velocity model: 1000 mm/s² ramps and 20 ms pauses under G98.
    let rapid = 2.0 * (10_000.0 / 60.0) / 1000.0 + (100.0 - (10_000.0f64 / 60.0).powi(2) / 1000.0) / (10_000.0 / 60.0);
    let total = json["total_time_s"].as_f64().unwrap();
    // The rapid's ramps and pause, each line's two 10 ms ramp halves and pause.
    let extra = (rapid - 0.6 + 0.02) + (0.01 + 0.02) + (0.01 + 0.02);
    assert!((total - (programmed + extra)).abs() < 1e-9, "{total}");
    let blocks = json["blocks"].as_array().unwrap();
    let lines: Vec<u64> = blocks.iter().map(|b| b["line"].as_u64().unwrap()).collect();
    assert_eq!(lines, [2, 3, 4, 5, 6, 7]);
    assert_eq!(blocks[1]["feed_mm_min"], 600.0);
    assert!((blocks[1]["start_time_s"].as_f64().unwrap() - (rapid + 0.02)).abs() < 1e-12);
    assert!((blocks[1]["programmed_duration_s"].as_f64().unwrap() - 10.0).abs() < 1e-12);
    let speeds = ["entry_speed_mm_min", "peak_speed_mm_min", "exit_speed_mm_min"].map(|key| blocks[1][key].as_f64());
    assert_eq!(speeds, [Some(0.0), Some(600.0), Some(0.0)]);
    let breaks: Vec<(u64, &str)> = json["breaks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| (b["line"].as_u64().unwrap(), b["reason"].as_str().unwrap()))
        .collect();
    assert_eq!(breaks, [(2, "rapid"), (3, "g98"), (4, "non-motion")]);
    assert_eq!(blocks[1]["end"]["program"]["Y"], 100.0);
    assert_eq!(blocks[1]["end"]["machine"]["Y"], 100.0);
    // R30 is 0: the message shows it as it was when the block ran.
    let message = &json["messages"][0];
    assert_eq!((&message["line"], &message["code"], &message["value"]), (&5.into(), &7.into(), &0.0.into()));
    assert_eq!(message["display"], "permanent");
}

/// A run that stops on an error says where, and exits with 1.
#[test]
fn run_stops_on_a_call_to_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("CALL.NCP");
    std::fs::write(&program, "%1\nN1 G00 X10\nN2 G71 L9\nN3 M30\n").unwrap();
    let output = ncc(&["run", program.to_str().unwrap(), "--step-budget", "100"]);
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(stderr.ends_with("CALL.NCP:3: error[E007]: there is no subprogram L9 (G79 L9) in this file\n"), "{stderr}");
}

/// Where the control stops, `ncc run`, `ncc expand` and `ncc plot` stop:
/// the located message, exit status 1, and no infinity or NaN in what
/// they write.
#[test]
fn run_expand_and_plot_stop_where_the_control_stops() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "OVERFLOW.NCP",
            "%1\nN10 R10=123\nN20 GR10\nN30 G00 X10\nN40 M30\n",
            3,
            "the parameter holds 0.123 (123 as digits, 3 decades) but `G` takes at most 2: the control stops with \"an R of more than 2 decades cannot be substituted\"",
        ),
        ("SIGN.NCP", "%1\nN1 G01 X10 F-100\nN2 M30\n", 2, "`F` takes only unsigned values; remove the sign"),
        (
            "HUGE.NCP",
            "%1\nN10 G1 X99999999999999999999 F100\nN20 M30\n",
            2,
            "`X99999999999999999999` has 20 digits before the point; the format of `X` allows 5",
        ),
        (
            "REPEAT.NCP",
            "%1\nN1 G91 G00 X1000\nN2 G73 L1 Q999\nN3 M30\n",
            2,
            "X would reach 70000.000, outside the range of `X`: -69999.999 to 69999.999: the control stops",
        ),
        (
            "ARC.NCP",
            "%1\nN1 G00 X10 Y0\nN2 G02 X20 Y0 I3 F100\nN3 M30\n",
            3,
            "the end point does not lie on the circle: 7 mm from the centre, the start 3 mm, more than the tolerance 0.001 mm apart: the control stops with error 7.56",
        ),
    ];
    let svg = dir.path().join("PLOT.svg");
    for (name, text, line, message) in cases {
        let program = dir.path().join(name);
        std::fs::write(&program, text).unwrap();
        let program = program.to_str().unwrap();
        for args in [
            vec!["run", program],
            vec!["run", program, "--format", "json"],
            vec!["expand", program],
            vec!["plot", program, "-o", svg.to_str().unwrap()],
        ] {
            let _ = std::fs::remove_file(&svg);
            let output = ncc(&args);
            assert_eq!(output.status.code(), Some(1), "{args:?}");
            let stderr = String::from_utf8(output.stderr.clone()).unwrap();
            let (place, said) = stderr.trim_end().split_once(": error[E").unwrap_or_default();
            assert!(place.ends_with(&format!("{name}:{line}")), "{args:?}: {stderr}");
            assert!(said.split_once("]: ").is_some_and(|(_, said)| said == message), "{args:?}: {stderr}");
            let written = stdout(&output) + &std::fs::read_to_string(&svg).unwrap_or_default();
            let words = written.split(|c: char| !c.is_ascii_alphanumeric()).map(str::to_ascii_lowercase);
            assert!(
                words.clone().all(|word| word != "inf" && word != "nan" && word != "infinity"),
                "{args:?}: {written}"
            );
        }
    }
}

/// `G72 L9001` runs the macrocycle file `L9001` of the program's project
/// (the directory of its ncc.toml); its blocks and findings name that file.
#[test]
fn run_finds_macrocycle_files_in_the_project() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ncc.toml"), "").unwrap();
    std::fs::create_dir(dir.path().join("macros")).unwrap();
    std::fs::write(dir.path().join("macros/L9001"), "N1 G79 L9001\nN2 G91 G01 X10 F600\nN3 G90 G70\n").unwrap();
    std::fs::create_dir(dir.path().join("parts")).unwrap();
    let program = dir.path().join("parts/MAIN.NCP");
    std::fs::write(&program, "%1\nN1 G72 L9001 Q3\nN2 G72 L9002\nN3 M30\n").unwrap();

    let (json, places) = run_places(&program);
    // The failed call runs as a block too: the run stops after it.
    let expected = [
        ("MAIN.NCP", 2),
        ("L9001", 2),
        ("L9001", 3),
        ("L9001", 2),
        ("L9001", 3),
        ("L9001", 2),
        ("L9001", 3),
        ("MAIN.NCP", 3),
    ];
    let expected: Vec<(String, u64)> = expected.into_iter().map(|(f, l)| (f.to_owned(), l)).collect();
    assert_eq!(places, expected);
    assert_eq!(json["end_position"]["X"], 30.0);
    assert_eq!(json["findings"][0]["message"], "there is no macrocycle file L9002 to call");
    assert_eq!(json["findings"][0]["line"], 3);
}

/// A Haas program's `M98 P1000` runs the program file `O01000.nc` beside
/// it; its blocks name that file, and a program with no file stops the run.
#[test]
fn run_finds_haas_program_files_beside_the_program() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("O01000.nc"), "O1000\nG98 G01 W-10. F600.\nM99\n").unwrap();
    let program = dir.path().join("main.nc");
    std::fs::write(&program, "O1\nM98 P1000 L2\nM98 P2000\nM30\n").unwrap();

    let (json, places) = run_places(&program);
    let expected = [("main.nc", 2), ("O01000.nc", 2), ("O01000.nc", 3), ("O01000.nc", 2), ("O01000.nc", 3)];
    let expected: Vec<(String, u64)> = expected.into_iter().map(|(f, l)| (f.to_owned(), l)).collect();
    assert_eq!(places, expected);
    assert_eq!(json["end_position"]["Z"], -20.0);
    let message = json["findings"][0]["message"].as_str().unwrap();
    assert!(message.contains("no program O2000"), "{message}");
    assert_eq!(json["findings"][0]["line"], 3);
}

/// `ncc expand` writes a program that runs the same moves in the same time
/// (to F's whole mm/min), here with a macrocycle file and its dwells
/// resolved; the expanded program passes `ncc check` without errors.
#[test]
fn expand_writes_a_program_with_the_same_moves() {
    let dir = tempfile::tempdir().unwrap();
    let expanded = dir.path().join("HOLES.NCP");
    let expanded = expanded.to_str().unwrap();
    let output = ncc(&["expand", "examples/milling/holes.NCP", "-o", expanded]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let moves = |program: &str| {
        let output = ncc(&["run", program, "--format", "json"]);
        let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let ends: Vec<String> = json["blocks"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|b| b["motion"] != "none" && b["length_mm"].as_f64() != Some(0.0))
            .map(|b| format!("{} {}", b["motion"], b["end"]["program"]))
            .collect();
        (ends, json["total_time_s"].as_f64().unwrap())
    };
    let (original, original_time) = moves("examples/milling/holes.NCP");
    let (again, again_time) = moves(expanded);
    assert_eq!(again, original);
    assert!((again_time - original_time).abs() < 1e-3 * original_time, "{original_time} s, expanded {again_time} s");
    let check = ncc(&["check", "--format", "short", expanded]);
    let report = String::from_utf8(check.stdout).unwrap();
    assert!(!report.contains(": error"), "{report}");
}

/// A Haas turning program whose passes a WHILE loop makes, under constant
/// cutting speed.
const HAAS_ROUGHING: &str = "%
O1 (ROUGHING)
G50 S3000
G96 S180 M03
G00 X64. Z2.
G99 F0.25
#1 = 60.
WHILE [#1 GT 48.] DO1
G00 X#1 Z2.
G01 Z-30.
G02 U6. W-3. R3.
G00 U2. Z2.
#1 = #1 - 4.
END1
G04 P250
M30
%
";

/// `ncc expand` writes a Haas program as plain lathe blocks: the loop
/// unrolled, X as a diameter, the feed per minute each pass ran at; it
/// passes `ncc check` and runs the same moves in the same time.
#[test]
fn expand_writes_a_haas_program_as_plain_lathe_blocks() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("O1.nc");
    std::fs::write(&program, HAAS_ROUGHING).unwrap();
    let (program, expanded) = (program.to_str().unwrap(), dir.path().join("out.nc"));
    let expanded = expanded.to_str().unwrap();
    let output = ncc(&["expand", program, "-o", expanded]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let text = std::fs::read_to_string(expanded).unwrap();
    // 180 m/min at Ø60 is 954.93 rpm, at 0.25 mm/rev 238.732 mm/min.
    assert!(
        text.starts_with("%\nO1 (EXPANDED FROM O1.nc)\nG18 G21 G40 G54 G97 G98\nG00 X64. Z2.\nG00 X60.\n"),
        "{text}"
    );
    assert!(text.contains("\nG01 Z-30. F238.732\nG02 X66. Z-33. I3. K0. F227.364\nG00 X68. Z2.\n"), "{text}");
    assert_eq!(text.matches("G01 Z-30.").count(), 3, "{text}");
    assert!(text.ends_with("G00 X60. Z2.\nG04 P250\nM30\n%\n"), "{text}");
    let check = ncc(&["check", expanded]);
    assert_eq!(check.status.code(), Some(0), "{}", stdout(&check));
    // The source's hints carry over: an arc without tool-nose
    // compensation, a dwell in milliseconds (the expansion selects G54).
    let summary = "Found 0 errors, 0 warnings, 2 infos and 0 hints in 1 file.\n";
    assert!(stdout(&check).ends_with(summary), "{}", stdout(&check));
    let ((original, original_time), (again, again_time)) = (run_moves(program), run_moves(expanded));
    assert_eq!(original.len(), 13);
    assert!(same_moves(&again, &original), "{again:?}\n{original:?}");
    assert!((again_time - original_time).abs() < 1e-3 * original_time, "{original_time} s, expanded {again_time} s");
}

/// The moves of `ncc run` (kind and end: X as a radius, Z) and the total
/// time without the waits for the spindle, which an expansion does not
/// write.
fn run_moves(program: &str) -> (Vec<(String, [f64; 2])>, f64) {
    let output = ncc(&["run", program, "--format", "json"]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let ends = json["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["motion"] != "none" && b["length_mm"].as_f64() != Some(0.0))
        .map(|b| {
            let axis = |letter: &str| b["end"]["program"][letter].as_f64().unwrap();
            (b["motion"].to_string(), [axis("X"), axis("Z")])
        })
        .collect();
    let spindle = json["breaks"].as_array().unwrap().iter().filter(|b| b["reason"] == "spindle");
    let waits: f64 = spindle.map(|b| b["lost_s"].as_f64().unwrap()).sum();
    (ends, json["total_time_s"].as_f64().unwrap() - waits)
}

/// Whether two runs make the same moves, to the µm the expansion writes.
fn same_moves(a: &[(String, [f64; 2])], b: &[(String, [f64; 2])]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|((kind_a, a), (kind_b, b))| {
            kind_a == kind_b && (a[0] - b[0]).abs() <= 0.001 && (a[1] - b[1]).abs() <= 0.001
        })
}

/// The bundled Haas example expands to a program of the same moves and
/// time: its cycles (G71/G70, the G75 groove, the G76 thread passes, the
/// G83 pecks) become plain blocks.
#[test]
fn the_haas_example_expands_to_the_same_moves_and_time() {
    let dir = tempfile::tempdir().unwrap();
    let expanded = dir.path().join("O1000.nc");
    let expanded = expanded.to_str().unwrap();
    let output = ncc(&["expand", "examples/haas-lathe/O1000.nc", "-o", expanded]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let text = std::fs::read_to_string(expanded).unwrap();
    assert!(text.contains("\nS600 M03\nG32 Z-20. F1.5\n"), "{text}");
    // D0.3·√n reaches 0.9 mm in 9 passes; the 10th cuts to K0.92.
    assert_eq!(text.matches("G32").count(), 10, "the thread's passes: {text}");
    let ((original, original_time), (again, again_time)) =
        (run_moves("examples/haas-lathe/O1000.nc"), run_moves(expanded));
    assert!(same_moves(&again, &original), "{again:?}\n{original:?}");
    assert!((again_time - original_time).abs() < 1e-3 * original_time, "{original_time} s, expanded {again_time} s");
}

/// A contour under radius compensation (D1 of radius 5 on the left, G41):
/// the control moves the tool centre on the equidistant and displays it.
const COMPENSATED: &str = "%1\nN1 G92 D1 R0=5.\nN2 G92 X-100 Y0\nN3 G00 X0 Y-20 D1\nN4 G41 G01 X0 Y0 F600\nN5 X50\nN6 Y50\nN7 G40 X70 Y70\nN8 M30\n";

/// `ncc run --format json` gives the tool centre's positions, in program
/// and machine coordinates, and under compensation the programmed point
/// beside them.
#[test]
fn run_reports_the_tool_centre_under_radius_compensation() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("CONTOUR.NCP");
    std::fs::write(&program, COMPENSATED).unwrap();
    let output = ncc(&["run", program.to_str().unwrap(), "--format", "json"]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    type Point = (f64, f64);
    let at = |place: &serde_json::Value| (place["X"].as_f64().unwrap(), place["Y"].as_f64().unwrap());
    let blocks = json["blocks"].as_array().unwrap();
    let ends: Vec<(u64, Point, Point)> = blocks
        .iter()
        .map(|block| (block["line"].as_u64().unwrap(), at(&block["end"]["program"]), at(&block["end"]["machine"])))
        .collect();
    // The start move ends on the first line's normal, the inside corner is
    // where the equidistants meet, and G40 leaves the last one's normal for
    // the programmed point; G92 X-100 at the machine zero puts the program's
    // X0 at the machine's X-100.
    let expected = [
        (4, (0.0, -20.0), (-100.0, -20.0)),
        (5, (0.0, 5.0), (-100.0, 5.0)),
        (6, (45.0, 5.0), (-55.0, 5.0)),
        (7, (45.0, 50.0), (-55.0, 50.0)),
        (8, (70.0, 70.0), (-30.0, 70.0)),
    ];
    assert_eq!(ends[2..7], expected);
    let corner = &blocks[4];
    assert_eq!(at(&corner["start"]["program"]), (0.0, 5.0));
    assert_eq!(at(&corner["end"]["programmed"]["program"]), (50.0, 0.0));
    assert_eq!(at(&corner["end"]["programmed"]["machine"]), (-50.0, 0.0));
    assert_eq!(at(&corner["start"]["programmed"]["program"]), (0.0, 0.0));
    assert_eq!(corner["length_mm"], 45.0);
    // Outside compensation the tool centre is the programmed point.
    assert!(blocks[2]["end"].get("programmed").is_none(), "{}", blocks[2]);
    assert_eq!(at(&json["end_position"]), (70.0, 70.0));
    assert!(json.get("programmed_end_position").is_none());
}

/// `ncc plot` draws the tool centre's moves, and under compensation the
/// programmed contour as a second layer, thin and dotted, with the same
/// lines to click.
#[test]
fn plot_draws_the_tool_centre_and_the_programmed_contour() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("CONTOUR.NCP");
    std::fs::write(&program, COMPENSATED).unwrap();
    let svg = dir.path().join("contour.svg");
    let output = ncc(&["plot", program.to_str().unwrap(), "-o", svg.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let svg = std::fs::read_to_string(svg).unwrap();
    let layer = |id: &str| -> Vec<String> {
        let start = svg.find(&format!("<g id=\"{id}\">")).unwrap_or_else(|| panic!("no layer {id}: {svg}"));
        let end = start + svg[start..].find("</g>").unwrap();
        svg[start..end].lines().filter(|line| line.starts_with("<path")).map(str::to_owned).collect()
    };
    let (tool, programmed) = (layer("tool-centre"), layer("programmed-contour"));
    let lines = |paths: &[String]| -> Vec<String> {
        paths.iter().map(|path| path.split('"').nth(1).unwrap().to_owned()).collect::<Vec<_>>()
    };
    assert_eq!(lines(&tool), ["4", "5", "6", "7", "8"], "{svg}");
    assert_eq!(lines(&programmed), ["5", "6", "7", "8"], "{svg}");
    assert!(programmed.iter().all(|path| path.contains("stroke-dasharray") && path.contains("programmed contour")));
    // The corner block runs from the start move's end (0, 5) to (45, 5),
    // its programmed line from (0, 0) to (50, 0).
    let pixel = pixel_of(&svg);
    let d = |path: &str| path.split(" d=\"").nth(1).unwrap().split('"').next().unwrap().to_owned();
    let expected = |from: (f64, f64), to: (f64, f64)| {
        let (from, to) = (pixel(from), pixel(to));
        format!("M{:.2} {:.2} L{:.2} {:.2}", from.0, from.1, to.0, to.1)
    };
    assert_eq!(d(&tool[2]), expected((0.0, 5.0), (45.0, 5.0)));
    assert_eq!(d(&programmed[1]), expected((0.0, 0.0), (50.0, 0.0)));
    assert!(
        svg.contains(">programmed contour (G41/G42); solid: the tool centre</text>"),
        "the legend names the layers: {svg}"
    );
}

/// A program that ends (M30) with compensation still in force: the control
/// leaves the tool centre on the normal at the last programmed point, as
/// before a G40 block, and every report says so alike: the run's end, the
/// last block's end and length, the expanded program and the picture.
#[test]
fn a_program_ending_under_compensation_ends_on_the_last_normal() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("OPEN.NCP");
    std::fs::write(&program, "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 Y50\nN6 M30\n")
        .unwrap();
    let program = program.to_str().unwrap();
    let at = |place: &serde_json::Value| (place["X"].as_f64().unwrap(), place["Y"].as_f64().unwrap());
    let output = ncc(&["run", program, "--format", "json"]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    // The last line Y50 runs on its equidistant X45 from the corner (45, 5).
    assert_eq!(at(&json["end_position"]), (45.0, 50.0));
    let last = json["blocks"].as_array().unwrap().iter().rfind(|block| block["motion"] == "feed").unwrap();
    assert_eq!((last["line"].as_u64(), at(&last["end"]["program"])), (Some(6), (45.0, 50.0)));
    assert_eq!(last["length_mm"], 45.0);
    // 25 onto the first normal, then 45 and 45 on the equidistants.
    assert_eq!(json["cutting_length_mm"], 115.0);
    let summary = String::from_utf8(ncc(&["run", program]).stdout).unwrap();
    assert!(summary.contains("end position X45.000 Y50.000 "), "{summary}");
    // The expanded program makes the same last move.
    let expanded = dir.path().join("EXPANDED.NCP");
    let output = ncc(&["expand", program, "-o", expanded.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let expanded = std::fs::read_to_string(expanded).unwrap();
    assert!(expanded.contains(" G01 Y50.000\n"), "{expanded}");
    // The picture's last tool-centre move runs from (45, 5) to (45, 50).
    let svg = dir.path().join("open.svg");
    let output = ncc(&["plot", program, "-o", svg.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
    let svg = std::fs::read_to_string(svg).unwrap();
    let pixel = pixel_of(&svg);
    let last_move = svg.lines().find(|line| line.starts_with("<path data-line=\"6\"")).unwrap();
    let ((x, y0), (_, y1)) = (pixel((45.0, 5.0)), pixel((45.0, 50.0)));
    assert!(last_move.contains(&format!(" d=\"M{x:.2} {y0:.2} L{x:.2} {y1:.2}\"")), "{svg}");
}

/// Where a plane picture puts program point (X, Y), by the frame its
/// drawing states.
fn pixel_of(svg: &str) -> impl Fn((f64, f64)) -> (f64, f64) {
    let drawing = svg.lines().find(|line| line.starts_with("<g id=\"drawing\"")).expect("a drawing");
    let attribute = |name: &str| -> f64 {
        drawing.split(&format!(" {name}=\"")).nth(1).unwrap().split('"').next().unwrap().parse().unwrap()
    };
    let (min_x, max_y, scale) = (attribute("data-min-x"), attribute("data-max-y"), attribute("data-scale"));
    let (left, top) = (attribute("data-left"), attribute("data-top"));
    move |(x, y)| (left + (x - min_x) * scale, top + (max_y - y) * scale)
}

/// Three jump loops nested, each of a thousand runs: a billion blocks,
/// which only the step budget ends.
const NESTED_LOOPS: &str =
    "%1\nN1 G23 G91 G01 X.002 F1\nN2 X.002 G73 L1 Q999\nN3 X.002 G73 L1 Q999\nN4 X.002 G73 L1 Q999\nN5 M30\n";

/// `ncc expand | head`: once the reader has gone, the run ends quietly
/// instead of running on to its step budget.
#[test]
fn expand_ends_when_its_reader_goes() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("NESTED.NCP");
    std::fs::write(&program, NESTED_LOOPS).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_ncc"))
        .args(["expand", program.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap()).read_line(&mut first).unwrap();
    assert_eq!(first, "%1 \"EXPANDED FROM NESTED.NCP\"\n");
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("stopped after"), "{stderr}");
}

/// `ncc plot` draws the first moves of a long run only, and says so in the
/// picture and on stderr; the legend's time is the whole run's.
#[test]
fn plot_draws_a_long_run_up_to_a_number_of_moves() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("NESTED.NCP");
    std::fs::write(&program, NESTED_LOOPS).unwrap();
    let svg = dir.path().join("nested.svg");
    let program = program.to_str().unwrap();
    let output = ncc(&["plot", program, "-o", svg.to_str().unwrap(), "--step-budget", "20000", "--max-moves", "500"]);
    // The budget stops the run: an error.
    assert_eq!(output.status.code(), Some(1));
    let note = "drawn: the first 500 of the run's 20000 moves; the total time and the breaks are the whole run's";
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(stderr.contains(&format!("note: {note} (--max-moves draws more)\n")), "{stderr}");
    let svg = std::fs::read_to_string(svg).unwrap();
    assert_eq!(svg.lines().filter(|line| line.starts_with("<path")).count(), 500);
    assert!(svg.contains(&format!(">{note}</text>")), "{svg}");
    // 20,000 moves of 2 µm at 1 mm/min, each 0.12 s.
    assert!(svg.contains("total time 0:40:00.000"), "{svg}");
    assert!(svg.len() < 100_000, "{} bytes", svg.len());
}

/// A move the written program cannot express stops `ncc expand` with the
/// block's place, and no program cut short is left behind.
#[test]
fn expand_stops_at_a_move_it_cannot_write() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("TURNED.NCP");
    // A planar transformation of X and Z turns an arc of XY out of its plane.
    std::fs::write(&program, "%1\nN1 G38 X0 Z0 I30\nN2 G38\nN3\nN4 G01 Z-1 F500\nN5 G02 X10 Y0 I5 J0\nN6 M30\n")
        .unwrap();
    let expanded = dir.path().join("EXPANDED.NCP");
    let output = ncc(&["expand", program.to_str().unwrap(), "-o", expanded.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(
        stderr.ends_with(
            "TURNED.NCP:6: an arc turned out of its plane by a transformation (G38/G39/G31) is no arc of any plane\n"
        ),
        "{stderr}"
    );
    assert!(!expanded.exists());
}

/// A megabyte of random text on one line: ncc reads its first kilobyte,
/// which has hundreds of findings; every format shows ten of the line and
/// counts the rest in one finding as severe as the worst of them.
#[test]
fn a_line_of_random_text_reports_ten_findings_and_counts_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("RANDOM.NCP");
    std::fs::write(&path, ncc_bench::cnc8x6::progen::random_line(1 << 20, 7)).unwrap();
    let path = path.to_str().unwrap();

    let output = ncc(&["check", "--format", "short", path]);
    assert_eq!(output.status.code(), Some(1));
    let report = stdout(&output);
    let lines: Vec<&str> = report.lines().collect();
    assert_eq!(lines.len(), 11, "{report}");
    let rest = lines.iter().find(|line| line.contains("[Z001]")).unwrap();
    let counted: u64 = rest.split("[Z001]: ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!(counted > 100, "{rest}");
    assert!(rest.contains(": error[Z001]: "), "as severe as the worst it counts: {rest}");

    let output = ncc(&["check", "--format", "json", path]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json.as_array().unwrap().len(), 11);

    // Each report shows the line cut to windows around its marks.
    let human = stdout(&ncc(&["check", path]));
    assert_eq!(human.matches("╭─[").count(), 11, "{human}");
    assert!(human.len() < 20_000, "{} bytes", human.len());
}

/// A mark far into a long line: the report shows a window of the line
/// around it, and the place above it counts the columns of the whole line.
#[test]
fn a_report_shows_a_long_line_around_its_mark_at_its_real_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("LONG.NCP");
    std::fs::write(&path, format!("%1\nN10 G01 X1 F100{}Y\nN20 M30\n*\n", " ".repeat(900))).unwrap();
    let path = path.to_str().unwrap();
    let human = stdout(&ncc(&["check", path]));
    assert!(human.contains("[S004 missing-value] Error: address `Y` has no value"), "{human}");
    assert!(human.contains(&format!("{path}:2:916 ]")), "{human}");
    assert!(human.contains(&format!("{path}:2:81 ]")), "line-too-long: {human}");
    let widest = human.lines().map(|line| line.chars().count()).max().unwrap();
    assert!(widest < 300, "a line of {widest} characters: {human}");
}

/// Control characters from a file are drawn or escaped in every report
/// for people, never written raw: a terminal would act on them.
#[test]
fn control_characters_of_a_file_are_never_printed_raw() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("CONTROL.NCP");
    std::fs::write(&path, "%1\nN10 G01 X1 F100 \u{0}\u{1b}[2J Y2 \"\u{1b}]0;title\u{7}\"\u{c}\nN20 M30\n*\n").unwrap();
    let path = path.to_str().unwrap();
    for format in ["human", "short"] {
        let output = ncc(&["check", "--format", format, path]);
        assert_eq!(output.status.code(), Some(1));
        let report = stdout(&output);
        assert!(report.contains("unexpected `\\u{0}\\u{1b}[`"), "{format}: {report}");
        let raw: Vec<char> = report.chars().filter(|&c| c.is_control() && c != '\n').collect();
        assert!(raw.is_empty(), "{format} prints {raw:?}: {report}");
    }
    assert!(stdout(&ncc(&["check", path])).contains("F100 ␀␛[2J Y2 \"␛]0;title␇\"␌"));
}

/// A file shows its first 1000 findings (or what `ncc.toml` says) and
/// counts the rest in one finding where the first one left out is.
#[test]
fn a_file_reports_its_first_findings_and_counts_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("MANY.NCP");
    let program: String = (0..300).map(|block| format!("N{block} X1 Y Y Y Y\n")).collect();
    std::fs::write(&path, format!("%1\n{program}")).unwrap();
    let path = path.to_str().unwrap();
    let findings = |max: usize| -> Vec<serde_json::Value> {
        std::fs::write(dir.path().join("ncc.toml"), format!("[report]\nmax-findings = {max}\n")).unwrap();
        let output = ncc(&["check", "--format", "json", path]);
        serde_json::from_slice::<serde_json::Value>(&output.stdout).unwrap().as_array().unwrap().clone()
    };
    let all = findings(100_000);
    assert!(all.len() > 2000 && all.iter().all(|d| d["code"] != "Z002"), "{}", all.len());
    let position = |d: &serde_json::Value| (d["line"].as_u64(), d["column"].as_u64());
    for max in [5, 1000] {
        let shown = findings(max);
        assert_eq!(shown.len(), max + 1);
        let rest = shown.iter().find(|d| d["code"] == "Z002").unwrap();
        let more = format!("{} more findings in this file not shown", all.len() - max);
        assert!(rest["message"].as_str().unwrap().starts_with(&more), "{rest}");
        assert_eq!(position(rest), position(&all[max]), "at the first one left out");
    }
    std::fs::remove_file(dir.path().join("ncc.toml")).unwrap();
    let output = ncc(&["check", "--format", "json", path]);
    let default: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(default.as_array().unwrap().len(), 1001, "1000 by default, and the rest");
}

/// `ncc run` names a program in what it prints: a control character in the
/// file's name is escaped there too.
#[test]
fn run_escapes_control_characters_in_what_it_prints() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("A\u{1b}[2J.NCP");
    std::fs::write(&path, "%1\nN10 G72 L9002\nN20 M30\n").unwrap();
    let output = ncc(&["run", path.to_str().unwrap()]);
    let (out, err) = (stdout(&output), String::from_utf8(output.stderr).unwrap());
    assert!(err.contains("A\\u{1b}[2J.NCP:2: error[E007]: there is no macrocycle file L9002 to call"), "{err}");
    for printed in [&out, &err] {
        assert!(!printed.contains('\u{1b}'), "{printed}");
    }
}

fn stderr(output: &Output) -> String {
    String::from_utf8(output.stderr.clone()).unwrap()
}

#[test]
fn an_unknown_dialect_is_a_usage_error_that_lists_the_known_ones() {
    for args in [&["check", "--dialect", "fanuc", "examples"][..], &["--dialect", "fanuc", "run", "x.NCP"]] {
        let output = ncc(args);
        assert_eq!(output.status.code(), Some(2));
        let message = stderr(&output);
        assert!(message.contains("unknown dialect `fanuc` (known: cnc8x6, haas-lathe, sinumerik)"), "{message}");
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ncc.toml"), "dialect = \"fanuc\"\n").unwrap();
    std::fs::write(dir.path().join("a.NCP"), "%1\nN10 M30\n").unwrap();
    let output = ncc(&["check", dir.path().to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("ncc.toml: TOML parse error at line 1, column 11"), "{message}");
    assert!(message.contains("unknown dialect `fanuc` (known: cnc8x6, haas-lathe, sinumerik)"), "{message}");
}

#[test]
fn a_named_dialect_reads_the_program_whatever_its_name_says() {
    let dir = tempfile::tempdir().unwrap();
    let lathe = dir.path().join("O1000.nc");
    std::fs::write(&lathe, "%\nO1000\nG28\nM30\n%\n").unwrap();
    assert_eq!(ncc(&["check", "--dialect", "cnc8x6", lathe.to_str().unwrap()]).status.code(), Some(1));
    let output = ncc(&["check", "--dialect", "sinumerik", "--format", "short", lathe.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stdout(&output).contains("O1000.nc:1:1: error[S015]"), "{}", stdout(&output));
    assert_eq!(ncc(&["explain", "--dialect", "cnc8x6", "G40"]).status.code(), Some(0));
}

/// A Sinumerik program is checked for its syntax and rules and runs: `run`
/// times it with the subprogram beside it, `expand` writes its moves as
/// plain blocks, `plot` draws it, and the files it writes go below
/// `--write-dir`.
#[test]
fn sinumerik_programs_are_checked_and_run() {
    let dir = tempfile::tempdir().unwrap();
    let clean = dir.path().join("PART.MPF");
    let text = "; a part
DEF REAL DEPTH=5
N10 G0 X0 Y0
IF DEPTH>2 GOTOF DONE
WHILE R1<10
  R1=R1+1
ENDWHILE
DONE: G642 SOFT
MSG(\"depth \"<<DEPTH)
SIDE(DEPTH)
WRITE(R2,\"/_N_MPF_DIR/_N_OUT_DIR/_N_LOG_SPF\",\"X\"<<DEPTH)
M30
";
    std::fs::write(&clean, text).unwrap();
    std::fs::write(dir.path().join("SIDE.SPF"), "PROC SIDE(REAL D)\nG1 X=D*2 Y=D F600\nM17\n").unwrap();
    let clean = clean.to_str().unwrap();
    let output = ncc(&["check", clean]);
    assert_eq!(output.status.code(), Some(0), "{}", stdout(&output));
    assert_eq!(stdout(&output), "All checks passed (1 file checked).\n");
    let broken = dir.path().join("SUB.SPF");
    std::fs::write(&broken, "PROC SUB\nR1=(5+2\nMSG(\"open)\nRET\n").unwrap();
    let output = ncc(&["check", "--format", "short", broken.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(1));
    let out = stdout(&output);
    assert!(out.contains("SUB.SPF:2:4: error[S029]: `(` is not closed by `)` on its line"), "{out}");
    assert!(out.contains("SUB.SPF:3:5: error[S028]"), "{out}");
    let written = dir.path().join("out");
    let output = ncc(&["run", "--write-dir", written.to_str().unwrap(), clean]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let out = stdout(&output);
    assert!(out.contains("(0:00:01.118 at the programmed feeds)") && out.contains("11.180 mm"), "{out}");
    assert!(out.contains("end position X10.000 Y5.000 Z0.000"), "{out}");
    let log = written.join("MPF").join("OUT").join("LOG.SPF");
    assert_eq!(std::fs::read_to_string(&log).unwrap(), "X5\n");
    assert!(stderr(&output).ends_with(&format!("wrote {}\n", log.display())), "{}", stderr(&output));
    let output = ncc(&["expand", clean]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert_eq!(
        stdout(&output),
        "; EXPANDED FROM PART.MPF\nG17 G71 G90 G94 G60 BRISK\nG642 CTOL=0.1 G0 X0 Y0 Z0\nSOFT G1 X10 Y5 F600\nM30\n"
    );
    let svg = dir.path().join("part.svg");
    let output = ncc(&["plot", clean, "-o", svg.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    // A written path that would leave the directory is refused.
    let leaving = dir.path().join("LEAVE.MPF");
    std::fs::write(&leaving, "WRITE(R1,\"/ETC/X\",\"x\")\nM30\n").unwrap();
    let output = ncc(&["run", "--write-dir", written.to_str().unwrap(), leaving.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("the program wrote /ETC/X, a path that would leave"), "{}", stderr(&output));
    let output = ncc(&["parse", clean]);
    assert_eq!(output.status.code(), Some(0));
    assert!(stdout(&output).contains("LABEL@"), "{}", stdout(&output));
    let output = ncc(&["lower", clean]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(!stdout(&output).lines().any(|line| line.trim().parse::<usize>().is_ok()), "{}", stdout(&output));
}

#[test]
fn directories_are_searched_by_extension_per_dialect_and_ncc_toml_maps_more() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
    write("a.NCP", "%1\nN10 M30\n*\n");
    write("b.PRG", "%2\nN10 M30\n*\n");
    write("MAIN.MPF", "G0 X0\nM30\n");
    write("SUB.SPF", "PROC SUB\nRET\n");
    write("O1000.nc", "%\nO1000\nM30\n%\n");
    write("notes.txt", "N10 X\n");
    let checked = |dir: &Path| {
        let output = ncc(&["check", dir.to_str().unwrap()]);
        (output.status.code(), stdout(&output), stderr(&output))
    };
    let (code, out, err) = checked(dir.path());
    assert_eq!(code, Some(0), "{out}{err}");
    assert_eq!((out.as_str(), err.as_str()), ("All checks passed (4 files checked).\n", ""));
    // The project maps an extension of its own, and takes `.nc` files for
    // CNC8x6 programs.
    write("ncc.toml", "[extensions]\nPRG = \"cnc8x6\"\n\".nc\" = \"cnc8x6\"\n");
    let (code, out, _) = checked(dir.path());
    assert_eq!(code, Some(1), "{out}");
    assert!(out.ends_with("in 5 files.\n") && out.contains("O1000.nc"), "{out}");
    assert!(!out.contains("b.PRG"), "a clean file has no findings: {out}");
    // A project of one dialect: every program is read as it.
    write("ncc.toml", "dialect = \"sinumerik\"\n");
    let (code, out, _) = checked(dir.path());
    assert_eq!(code, Some(1), "{out}");
    assert!(out.ends_with("in 4 files.\n") && out.contains("a.NCP") && out.contains("O1000.nc"), "{out}");
    write("ncc.toml", "[extensions]\n\"a/b\" = \"cnc8x6\"\n");
    let (code, _, err) = checked(dir.path());
    assert_eq!(code, Some(2));
    assert!(err.contains("ncc.toml: [extensions] key `a/b` is not a file extension like `NCP`"), "{err}");
}

/// The executor's findings are rules: `ncc.toml` turns them off or changes
/// their level, `ncc:ignore` comments silence them, and the JSON output
/// names them; a finding the run stops on is shown whatever its level.
#[test]
fn run_findings_are_rules_that_ncc_toml_configures() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("RULES.NCP");
    let text = "%1\nN10 G01 X1 F100\nN20 G30\nN30 G23 I7\nN35 G23 I9 \"ncc:ignore E015\nN40 G72 L9001\nN50 M30\n";
    std::fs::write(&program, text).unwrap();
    let program = program.to_str().unwrap();
    let findings = |config: &str| {
        std::fs::write(dir.path().join("ncc.toml"), config).unwrap();
        let output = ncc(&["run", program]);
        assert_eq!(output.status.code(), Some(1));
        String::from_utf8(output.stderr).unwrap().replace(program, "RULES.NCP")
    };
    assert_eq!(
        findings(""),
        "RULES.NCP:3: info[E020]: the executor does not run G30 yet: the time leaves them out\n\
         RULES.NCP:4: warning[E015]: G23 I7: the dynamic sets are I1 to I4: the set in force stays\n\
         RULES.NCP:6: error[E007]: there is no macrocycle file L9001 to call\n"
    );
    let configured = "[rules]\nnot-run-yet = \"off\"\nE015 = \"error\"\ncall-target-missing = \"off\"\n";
    assert_eq!(
        findings(configured),
        "RULES.NCP:4: error[E015]: G23 I7: the dynamic sets are I1 to I4: the set in force stays\n\
         RULES.NCP:6: error[E007]: there is no macrocycle file L9001 to call\n"
    );
    let output = ncc(&["run", program, "--format", "json"]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let records: Vec<String> = json["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| format!("{} {} {} {} {}", f["code"], f["name"], f["severity"], f["line"], f["stopped"]))
        .collect();
    assert_eq!(
        records,
        [r#""E015" "dynamic-set-out-of-range" "error" 4 false"#, r#""E007" "call-target-missing" "error" 6 true"#]
    );
}

/// `ncc run --format json` of a program whose run stops on an error: its
/// output, and each block's file name and line.
fn run_places(program: &Path) -> (serde_json::Value, Vec<(String, u64)>) {
    let output = ncc(&["run", program.to_str().unwrap(), "--format", "json"]);
    assert_eq!(output.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let places = json["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            let file = b["file"].as_str().unwrap().replace('\\', "/");
            (file.rsplit('/').next().unwrap().to_owned(), b["line"].as_u64().unwrap())
        })
        .collect();
    (json, places)
}

/// `ncc fmt --check` and `--diff` say what would change and exit with 1,
/// changing nothing; `ncc fmt` writes the files in the project's style,
/// in their own encoding, and leaves a formatted file alone.
#[test]
fn fmt_checks_diffs_and_writes_in_the_projects_style() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ncc.toml"), "[format]\ncase = \"upper\"\nnumbers = \"trim\"\n").unwrap();
    let (mill, lathe, done) = (dir.path().join("A.MPF"), dir.path().join("O0001.nc"), dir.path().join("B.SPF"));
    let mill_text = "g1  x10.500 F1000 ; feed  \nM30\n";
    std::fs::write(&mill, mill_text).unwrap();
    // The control's code page: `Č` is byte 0x80 in Kamenický.
    let lathe_bytes = b"G0  X1.0 (\x80)\nM30\n";
    std::fs::write(&lathe, lathe_bytes).unwrap();
    std::fs::write(&done, "G1 X1\nM17\n").unwrap();
    let root = dir.path().to_str().unwrap();

    let check = ncc(&["fmt", "--check", root]);
    assert_eq!(check.status.code(), Some(1));
    let out = stdout(&check).replace(root, "DIR");
    expect_test::expect![[r#"
        Would reformat: DIR/A.MPF
        Would reformat: DIR/O0001.nc
        2 files would be reformatted, 1 file already formatted
    "#]]
    .assert_eq(&out);

    let diff = ncc(&["fmt", "--diff", mill.to_str().unwrap()]);
    assert_eq!(diff.status.code(), Some(1));
    let out = stdout(&diff).replace(root, "DIR");
    expect_test::expect![[r#"
        --- DIR/A.MPF
        +++ DIR/A.MPF
        @@ -1,2 +1,2 @@
        -g1  x10.500 F1000 ; feed  
        +G1 X10.5 F1000    ; feed  
         M30
        1 file would be reformatted, 0 files already formatted
    "#]]
    .assert_eq(&out);
    assert_eq!(std::fs::read_to_string(&mill).unwrap(), mill_text, "--check and --diff change nothing");

    let write = ncc(&["fmt", root]);
    assert_eq!(write.status.code(), Some(0), "{}", String::from_utf8_lossy(&write.stderr));
    assert_eq!(stdout(&write), "2 files reformatted, 1 file left unchanged\n");
    assert_eq!(std::fs::read_to_string(&mill).unwrap(), "G1 X10.5 F1000    ; feed  \nM30\n");
    assert_eq!(std::fs::read(&lathe).unwrap(), b"G0 X1.0  (\x80)\nM30\n");
    let again = ncc(&["fmt", "--check", root]);
    assert_eq!(again.status.code(), Some(0), "{}", stdout(&again));
}

#[test]
fn fmt_fails_on_a_missing_path() {
    let run = ncc(&["fmt", "no-such-file.NCP"]);
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("no-such-file.NCP"));
}

/// `ncc fmt --renumber` renumbers blocks with their references and then
/// formats; a file it cannot renumber safely is left alone with the
/// reason and where, and the exit status is 2.
#[test]
fn fmt_renumbers_blocks_with_their_references_or_says_why_not() {
    let dir = tempfile::tempdir().unwrap();
    let (good, bad) = (dir.path().join("O0001.nc"), dir.path().join("O0002.nc"));
    std::fs::write(&good, "G71 P1 Q2 U0.4 W0.1 D2. F0.25\nN1  G00 X14.\nN2 X20.\nM30\n").unwrap();
    std::fs::write(&bad, "N1 G00 X14.\nGOTO #1\nM30\n").unwrap();
    let run = ncc(&["fmt", "--renumber", "100,5", dir.path().to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(&good).unwrap(),
        "G71 P100 Q105 U0.4 W0.1 D2. F0.25\nN100 G00 X14.\nN105 X20.\nM30\n"
    );
    assert_eq!(std::fs::read_to_string(&bad).unwrap(), "N1 G00 X14.\nGOTO #1\nM30\n");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("O0002.nc:2:1: not renumbered: the target is computed when the program runs"), "{stderr}");
    let usage = ncc(&["fmt", "--renumber", "10,0", "."]);
    assert_eq!(usage.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&usage.stderr).contains("a step above 0"));
}

/// The picture fits the part, the cutting moves, not the rapid from far
/// away that reaches it (cut at the frame's edge); `--view iso` draws a
/// mill's three axes in an isometric view.
#[test]
fn plot_fits_the_cutting_moves_and_draws_an_isometric_view() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("FAR.MPF");
    std::fs::write(&program, "G0 X500 Y500 Z50\nG0 X0 Y0 Z2\nG1 Z-5 F200\nG1 X10 Y10 F500\nG0 Z50\nM30\n").unwrap();
    let draw = |view: &str| {
        let svg = dir.path().join("far.svg");
        let output = ncc(&["plot", program.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--view", view]);
        assert_eq!(output.status.code(), Some(0), "{}", String::from_utf8_lossy(&output.stderr));
        std::fs::read_to_string(svg).unwrap()
    };
    let top = draw("diameter");
    let pixel = pixel_of(&top);
    // The part spans 10 mm, with 5% around it: 10 mm are 960 / 11 pixels.
    let (left, right) = (pixel((0.0, 0.0)).0, pixel((10.0, 0.0)).0);
    assert!(((right - left) - 960.0 / 11.0 * 10.0).abs() < 0.01, "{left} {right}: {top}");
    assert!(top.contains(r#"<g id="drawing" clip-path="url(#frame)" data-projection="plane""#), "{top}");
    assert!(top.contains("XY plane · part X 0…10, Y 0…10, Z -5…2 mm"), "{top}");

    let iso = draw("iso");
    assert!(iso.contains(r#"data-projection="isometric""#), "{iso}");
    assert!(iso.contains("isometric view · part X 0…10, Y 0…10, Z -5…2 mm"), "{iso}");
    for axis in ["X", "Y", "Z"] {
        assert!(iso.contains(&format!(r#"font-weight="bold">{axis}</text>"#)), "the axes' directions: {iso}");
    }
    // The part's extent is a box of 12 edges, its height labelled on one
    // edge from -5 to 2 mm, a label every millimetre.
    let extent = iso.split(r#"<g id="extent""#).nth(1).unwrap().split("</g>").next().unwrap();
    assert_eq!(extent.matches("<line ").count(), 12, "{extent}");
    // The labels of one scale share their x; -5 is only a height.
    let label_at = |text: &str| -> Vec<(f64, f64)> {
        let ends = format!(">{text}</text>");
        let coordinate = |line: &str, at: usize| line.split('"').nth(at).unwrap().parse::<f64>().unwrap();
        iso.lines()
            .filter(|line| line.ends_with(&ends))
            .map(|line| (coordinate(line, 1), coordinate(line, 3)))
            .collect()
    };
    let edge = label_at("-5")[0].0;
    let heights: Vec<f64> = (-5..=2)
        .map(|z| {
            label_at(&z.to_string()).into_iter().find(|&(x, _)| x == edge).unwrap_or_else(|| panic!("{z}: {iso}")).1
        })
        .collect();
    assert!(heights.windows(2).all(|pair| pair[0] > pair[1]), "upwards: {heights:?}");
    // At the front corner X's 0 starts right of where Y's 0 ends.
    let y_zero = iso.lines().find(|line| line.ends_with(r#" text-anchor="end">0</text>"#)).unwrap();
    let y_zero_end: f64 = y_zero.split('"').nth(1).unwrap().parse().unwrap();
    let x_zero = label_at("0").into_iter().find(|&(x, _)| x != edge && x != y_zero_end).unwrap();
    assert!(x_zero.0 > y_zero_end, "{x_zero:?} {y_zero}");
    // The plunge (line 3) goes straight down the picture.
    let plunge = iso.lines().find(|line| line.starts_with("<path data-line=\"3\"")).unwrap();
    let d = plunge.split(" d=\"").nth(1).unwrap().split('"').next().unwrap();
    let xs: Vec<&str> =
        d.split(['M', 'L']).filter(|p| !p.trim().is_empty()).map(|p| p.split_whitespace().next().unwrap()).collect();
    assert!(xs.windows(2).all(|pair| pair[0] == pair[1]), "{d}");
}
