//! `ncc fmt`: format partprograms in place, or say what formatting would
//! change.

use std::{
    collections::BTreeMap,
    io::{self, Write},
    path::PathBuf,
    process::ExitCode,
};

use ncc_analysis::{Dialect, TextEdit};
use ncc_syntax::encoding;

use crate::{
    check::{Found, Projects, collect_files, read_file, shown_path, workspace_host},
    report::Positions,
};

/// What `ncc fmt` does with the files it formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Write the formatted text back.
    Write,
    /// Change nothing; name the files that would change.
    Check,
    /// Change nothing; print what would change as a unified diff.
    Diff,
}

/// A file as read: its text and how it was encoded, to write it back the
/// same way.
struct Program {
    path: PathBuf,
    text: String,
    encoding: encoding::Encoding,
}

/// `--renumber START,STEP`: the first block number and the step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Renumber {
    pub start: u64,
    pub step: u64,
}

impl std::str::FromStr for Renumber {
    type Err = String;

    fn from_str(text: &str) -> Result<Renumber, String> {
        let parsed = text
            .split_once(',')
            .and_then(|(start, step)| Some((start.trim().parse().ok()?, step.trim().parse().ok()?)));
        match parsed {
            Some((start, step)) if step > 0 => Ok(Renumber { start, step }),
            _ => Err(format!("`{text}` is not START,STEP with whole numbers and a step above 0 (`10,10`)")),
        }
    }
}

pub(crate) fn run(paths: &[PathBuf], mode: Mode, renumber: Option<Renumber>, forced: Option<Dialect>) -> ExitCode {
    let mut projects = Projects::default();
    let Found { files, mut failures } = collect_files(paths, &mut projects, forced);
    // The files of one dialect under the same `ncc.toml` share its style.
    let mut workspaces: BTreeMap<(Option<PathBuf>, Dialect), Vec<Program>> = BTreeMap::new();
    for (path, dialect) in files {
        match read_file(&path) {
            Ok(bytes) => {
                let (text, encoding) = encoding::decode(bytes);
                let workspace = (projects.config_path(Some(&path)), dialect);
                workspaces.entry(workspace).or_default().push(Program { path, text, encoding });
            }
            Err(error) => failures.push(format!("{}: {error}", shown_path(&path))),
        }
    }
    // What each changed file prints, by path.
    let mut reports: Vec<(PathBuf, String)> = Vec::new();
    let (mut changed, mut unchanged) = (0, 0);
    for ((config_path, dialect), programs) in workspaces {
        let Some(mut host) = workspace_host(&mut projects, config_path.as_deref(), dialect, &mut failures) else {
            continue;
        };
        for program in programs {
            let shown = shown_path(&program.path);
            let file = host.add_file(program.path.display().to_string(), program.text.as_str());
            let renumbered = match renumber {
                Some(Renumber { start, step }) => host.analysis().renumber(file, start, step),
                None => Ok(Vec::new()),
            };
            let formatted = renumbered.map(|edits| {
                if !edits.is_empty() {
                    host.set_text(file, applied(&program.text, &edits));
                }
                let text = host.analysis().text(file);
                applied(&text, &host.analysis().format(file, None))
            });
            host.remove_file(file);
            let formatted = match formatted {
                Ok(formatted) => formatted,
                Err(error) => {
                    let (line, column) = Positions::new(&program.text).at(error.range.start());
                    failures.push(format!("{shown}:{line}:{column}: not renumbered: {}", error.message));
                    continue;
                }
            };
            if formatted == program.text {
                unchanged += 1;
                continue;
            }
            changed += 1;
            match mode {
                Mode::Write => {
                    if let Err(error) = std::fs::write(&program.path, encoding::encode(&formatted, program.encoding)) {
                        failures.push(format!("{shown}: {error}"));
                    }
                }
                Mode::Check => reports.push((program.path, format!("Would reformat: {shown}\n"))),
                Mode::Diff => reports.push((program.path, unified_diff(&shown, &program.text, &formatted))),
            }
        }
    }
    let files = |n: usize| if n == 1 { "1 file".to_owned() } else { format!("{n} files") };
    let summary = match mode {
        Mode::Write => format!("{} reformatted, {} left unchanged", files(changed), files(unchanged)),
        Mode::Check | Mode::Diff => {
            format!("{} would be reformatted, {} already formatted", files(changed), files(unchanged))
        }
    };
    reports.sort();
    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    let written = reports
        .iter()
        .try_for_each(|(_, report)| out.write_all(report.as_bytes()))
        .and_then(|()| writeln!(out, "{summary}"))
        .and_then(|()| out.flush());
    for failure in &failures {
        eprintln!("error: {failure}");
    }
    if !failures.is_empty() || written.is_err() {
        ExitCode::from(2)
    } else if changed > 0 && mode != Mode::Write {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// `text` with `edits` (sorted, not overlapping) made.
fn applied(text: &str, edits: &[TextEdit]) -> String {
    let mut text = text.to_owned();
    for edit in edits.iter().rev() {
        edit.apply(&mut text);
    }
    text
}

/// A unified diff from `old` to `new` of the file shown as `path`.
fn unified_diff(path: &str, old: &str, new: &str) -> String {
    similar::TextDiff::from_lines(old, new).unified_diff().context_radius(2).header(path, path).to_string()
}
