//! Fixture programs with the expected diagnostics written inline.
//!
//! Every program in `test_data/rules` is analysed in the dialect its file
//! name gives (`*.ncp`: CNC8x6, `*.nc`: Haas lathe, `*.mpf`: Sinumerik) and its diagnostics are compared with the
//! annotations in it. An annotation is a line of the dialect's comment
//! (CNC8x6: `"`, Haas lathe and Sinumerik: `;`) right after the line it describes:
//!
//! ```text
//! N20 G01 X10 Y10
//! "   ^^^ missing-feed
//! ```
//!
//! The carets stand under the diagnostic's range (same columns, counted in
//! characters), followed by the rule's name. `"@ name` instead says that a
//! diagnostic of that rule starts somewhere on the line above (for ranges
//! that start in the first column). A `name.toml` beside a fixture is used
//! as its `ncc.toml`. Files without annotations must have no diagnostics.
//!
//! The fixtures in `test_data/run_rules` are run on the executor instead,
//! and its findings are compared with their annotations the same way.

use std::{fmt::Write, fs, path::PathBuf};

use nc_exec::run::{Called, Environment};
use ncc_analysis::{AnalysisHost, Config, Diagnostic, Dialect, Rule, TextRange};

#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Expected {
    line: usize,
    /// Start and end column; `None` for `@` annotations.
    columns: Option<(usize, usize)>,
    name: String,
}

/// The dialect a fixture's program is in, by its file name; `None` for
/// files of no dialect this build reads.
fn dialect_of(path: &std::path::Path) -> Option<Dialect> {
    Dialect::by_default_for(path)
}

/// What starts a line comment in `dialect`, where annotations are written.
fn comment_start(dialect: Dialect) -> &'static str {
    match dialect {
        Dialect::Cnc8x6 => "\"",
        Dialect::HaasLathe | Dialect::Sinumerik => ";",
    }
}

fn annotations(text: &str, dialect: Dialect) -> Vec<Expected> {
    let mut expected = Vec::new();
    let mut target_line = 0;
    for (number, line) in text.lines().enumerate() {
        let Some(rest) = line.strip_prefix(comment_start(dialect)) else {
            target_line = number;
            continue;
        };
        let body = rest.trim_start();
        if let Some(name) = body.strip_prefix('@') {
            expected.push(Expected { line: target_line, columns: None, name: name.trim().to_owned() });
        } else if body.starts_with('^') {
            let chars: Vec<char> = line.chars().collect();
            let start = chars.iter().position(|&c| c == '^').expect("a caret");
            let end = start + chars[start..].iter().take_while(|&&c| c == '^').count();
            let name = chars[end..].iter().collect::<String>().trim().to_owned();
            expected.push(Expected { line: target_line, columns: Some((start, end)), name });
        } else {
            // An ordinary comment line belongs to nothing.
            continue;
        }
    }
    expected
}

fn actual(text: &str, diagnostic: &Diagnostic) -> Expected {
    actual_at(text, diagnostic.range, diagnostic.name)
}

fn actual_at(text: &str, range: TextRange, name: &str) -> Expected {
    let start = usize::from(range.start());
    let end = usize::from(range.end());
    let line = text[..start].matches('\n').count();
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let column = |at: usize| text[line_start..at].chars().count();
    let end_column = if text[start..end].contains('\n') { column(start) + 1 } else { column(end) };
    Expected { line, columns: Some((column(start), end_column)), name: name.to_owned() }
}

fn matches(expected: &Expected, actual: &Expected) -> bool {
    expected.line == actual.line
        && expected.name == actual.name
        && expected.columns.is_none_or(|columns| Some(columns) == actual.columns)
}

/// Single-file fixtures (`*.ncp`) and workspace fixtures (directories whose
/// files are analysed together, e.g. a program and its macrocycle files).
fn fixtures(directory: &str) -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("test_data").join(directory);
    let mut entries: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir() || dialect_of(p).is_some())
        .collect();
    entries.sort();
    entries
}

/// What a fixture gives the analysis.
struct Inputs {
    /// The files, with their text.
    files: Vec<(PathBuf, String)>,
    config: Config,
    /// The dialect its programs are in.
    dialect: Dialect,
}

fn inputs(fixture: &PathBuf) -> Result<Inputs, String> {
    let (files, config_path) = if fixture.is_dir() {
        let mut files: Vec<PathBuf> = fs::read_dir(fixture)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.file_name().is_some_and(|n| n != "ncc.toml"))
            .collect();
        files.sort();
        (files, fixture.join("ncc.toml"))
    } else {
        (vec![fixture.clone()], fixture.with_extension("toml"))
    };
    let config = if config_path.exists() {
        Config::from_toml(&fs::read_to_string(&config_path).unwrap(), &config_path, |path| fs::read_to_string(path))?
    } else {
        Config::default()
    };
    let dialect = files.iter().find_map(|path| dialect_of(path)).ok_or("a fixture without a program")?;
    let files = files.into_iter().map(|path| (path.clone(), fs::read_to_string(path).unwrap())).collect();
    Ok(Inputs { files, config, dialect })
}

fn check(fixture: &PathBuf) -> Result<Vec<Diagnostic>, String> {
    let Inputs { files, config, dialect } = inputs(fixture)?;
    let mut host = AnalysisHost::in_dialect(dialect, config);
    let ids: Vec<_> = files
        .into_iter()
        .map(|(path, text)| (host.add_file(path.display().to_string(), text.as_str()), path, text))
        .collect();
    let analysis = host.analysis();
    let mut all = Vec::new();
    let mut report = String::new();
    for (file, path, text) in ids {
        let diagnostics = analysis.diagnostics(file);
        let found = diagnostics.iter().map(|d| (actual(&text, d), d.message.clone())).collect();
        if let Err(mismatch) = compare(&path, &text, dialect, found) {
            report.push_str(&mismatch);
        }
        all.extend(diagnostics);
    }
    if report.is_empty() { Ok(all) } else { Err(report) }
}

/// The files of a run fixture besides its program: macrocycle files by
/// number, the cycle file by name.
struct FixtureFiles<'a>(&'a [(PathBuf, String)]);

impl FixtureFiles<'_> {
    fn named(&self, name: &str) -> Option<&(PathBuf, String)> {
        self.0.iter().find(|(path, _)| path.file_name().is_some_and(|file| file.eq_ignore_ascii_case(name)))
    }
}

impl Environment for FixtureFiles<'_> {
    fn file(&self, called: &Called) -> Option<String> {
        let found = match called {
            Called::Number(number) => self.named(&format!("L{number}")),
            Called::Name(name) => self.named(name),
            Called::Program(number) => self.named(&format!("O{number}")),
            Called::ControlFile(name) => self.0.iter().find(|(path, _)| ncc_catalog::is_control_file(path, name)),
            Called::Written(_) => None,
        };
        found.map(|(_, text)| text.clone())
    }
}

/// Blocks a run fixture may run: enough for each, few enough for a loop
/// that never ends.
const RUN_FIXTURE_BUDGET: usize = 1000;

/// Runs a fixture's program (its `.ncp` file) and compares the findings
/// in each of its files with their annotations; returns the rules found.
fn run_check(fixture: &PathBuf) -> Result<Vec<&'static str>, String> {
    let Inputs { files, config, dialect } = inputs(fixture)?;
    // The main program: its dialect's, of a main program's extension.
    let program =
        files.iter().position(|(path, _)| path.extension().is_some_and(|e| e == "ncp" || e == "mpf")).unwrap();
    let machine = config.for_dialect(dialect).machine;
    let trace = nc_exec::run::run(&files[program].1, &FixtureFiles(&files), &machine, RUN_FIXTURE_BUDGET);
    let file_of = |source: usize| match source.checked_sub(1).map(|called| &trace.files[called]) {
        None => program,
        Some(Called::Number(number)) => {
            files.iter().position(|(path, _)| path.ends_with(format!("L{number}"))).unwrap()
        }
        Some(Called::Name(name)) => files.iter().position(|(path, _)| path.ends_with(name)).unwrap(),
        Some(Called::Program(number)) => {
            files.iter().position(|(path, _)| path.ends_with(format!("O{number}"))).unwrap()
        }
        Some(Called::ControlFile(name)) => {
            files.iter().position(|(path, _)| ncc_catalog::is_control_file(path, name)).unwrap()
        }
        Some(Called::Written(path)) => panic!("a fixture wrote {path}, which has no annotations"),
    };
    let mut report = String::new();
    for (index, (path, text)) in
        files.iter().enumerate().filter(|(_, (path, _))| path.extension().is_none_or(|e| e != "KOR"))
    {
        let found = trace
            .findings
            .iter()
            .filter(|finding| file_of(finding.source) == index)
            .map(|finding| (actual_at(text, finding.range, finding.rule.name()), finding.message.clone()))
            .collect();
        if let Err(mismatch) = compare(path, text, dialect, found) {
            report.push_str(&mismatch);
        }
    }
    let rules = trace.findings.iter().map(|finding| finding.rule.name()).collect();
    if report.is_empty() { Ok(rules) } else { Err(report) }
}

/// Compares what was found in a file, each with its message, with the
/// file's annotations.
fn compare(path: &std::path::Path, text: &str, dialect: Dialect, found: Vec<(Expected, String)>) -> Result<(), String> {
    let mut expected = annotations(text, dialect);
    let mut unexpected = Vec::new();
    for (found, message) in found {
        match expected.iter().position(|e| matches(e, &found)) {
            Some(i) => {
                expected.remove(i);
            }
            None => unexpected.push((found, message)),
        }
    }
    if expected.is_empty() && unexpected.is_empty() {
        return Ok(());
    }
    let mut report = format!("{}:\n", path.display());
    for e in &expected {
        let at = e.columns.map_or(String::new(), |(s, end)| format!(":{}-{}", s + 1, end + 1));
        let _ = writeln!(report, "  missing    {}{at} {}", e.line + 1, e.name);
    }
    for (found, message) in &unexpected {
        let (s, end) = found.columns.unwrap();
        let _ = writeln!(report, "  unexpected {}:{}-{} {}: {message}", found.line + 1, s + 1, end + 1, found.name);
    }
    Err(report)
}

#[test]
fn fixtures_have_exactly_the_annotated_diagnostics() {
    let mut failures = String::new();
    let mut covered = std::collections::BTreeSet::new();
    for path in fixtures("rules") {
        match check(&path) {
            Ok(diagnostics) => covered.extend(diagnostics.iter().map(|d| d.name)),
            Err(report) => failures.push_str(&report),
        }
    }
    for path in fixtures("run_rules") {
        match run_check(&path) {
            Ok(rules) => covered.extend(rules),
            Err(report) => failures.push_str(&report),
        }
    }
    assert!(failures.is_empty(), "\n{failures}");
    // Syntax diagnostics have their own fixtures in crates/syntax.
    let syntax: std::collections::BTreeSet<_> = ncc_syntax::SyntaxErrorKind::ALL.iter().map(|k| k.name()).collect();
    let checks: Vec<_> = Rule::all().map(|r| r.name).filter(|name| !syntax.contains(name)).collect();
    let untested: Vec<_> = checks.iter().filter(|name| !covered.contains(*name)).collect();
    assert!(untested.is_empty(), "rules without a fixture that shows them: {untested:?}");
    println!("{} rules shown by fixtures", checks.len());
}

/// The bundled examples are realistic programs: they must be clean.
#[test]
fn examples_have_no_diagnostics() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    // Each example's workspace is the examples with the same ncc.toml, as
    // `ncc check examples` groups them.
    let mut workspaces: std::collections::BTreeMap<Option<PathBuf>, Vec<PathBuf>> = Default::default();
    for entry in ["milling/pocket.NCP", "milling/holes.NCP", "lathe/shaft.NCP", "macros/L9001"] {
        let path = dir.join(entry);
        workspaces.entry(Config::find_for(&path)).or_default().push(path);
    }
    for (config_path, paths) in workspaces {
        let config = config_path
            .map(|p| Config::from_toml(&fs::read_to_string(&p).unwrap(), &p, |path| fs::read_to_string(path)).unwrap())
            .unwrap_or_default();
        let mut host = AnalysisHost::new(config);
        let files: Vec<_> = paths
            .iter()
            .map(|path| host.add_file(path.display().to_string(), fs::read_to_string(path).unwrap().as_str()))
            .collect();
        let analysis = host.analysis();
        for file in files {
            let diagnostics = analysis.diagnostics(file);
            assert!(diagnostics.is_empty(), "{}: {diagnostics:#?}", analysis.path(file));
        }
    }
}
