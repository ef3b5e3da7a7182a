//! What the tests that prove a change of text keeps the program share: the
//! programs of the repository, and a run's account that must not change.

use nc_exec::run::Step;
use ncc_analysis::{Dialect, MachineConfig};
use ncc_syntax::{TextRange, TextSize};

/// What a run of `text` does, in terms a change of its layout must not
/// change: its steps with the line of their block, its findings' rules and
/// lines, its tools and the files it writes.
pub fn run_of(dialect: Dialect, text: &str) -> String {
    let machine = MachineConfig::of_control(dialect);
    let trace = nc_exec::run::run(text, &nc_exec::run::NoFiles, &machine, 20_000);
    let line = |range: TextRange| text[..usize::from(range.start())].matches('\n').count();
    let mut out = String::new();
    for step in &trace.steps {
        let at = line(step.range);
        let step = Step { range: TextRange::empty(TextSize::from(0)), ..step.clone() };
        out.push_str(&format!("line {at}: {step:?}\n"));
    }
    for finding in &trace.findings {
        out.push_str(&format!("{:?} {} {}\n", finding.rule, finding.source, line(finding.range)));
    }
    out.push_str(&format!("{:?} {:?}\n", trace.tools, trace.written));
    out
}

/// Every program of the repository: examples and fixtures, with their
/// dialects.
pub fn repository_programs() -> Vec<(std::path::PathBuf, Dialect)> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut programs = Vec::new();
    let mut dirs =
        vec![root.join("examples"), root.join("crates/analysis/test_data"), root.join("crates/syntax/test_data")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if let Some(dialect) = Dialect::by_default_for(&path) {
                programs.push((path, dialect));
            }
        }
    }
    programs.sort();
    programs
}
