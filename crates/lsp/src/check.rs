//! `ncc check`: find partprograms, check them in parallel, report.

use std::{
    io::{self, IsTerminal, Write},
    ops::Range,
    path::{Path, PathBuf},
    process::ExitCode,
};

use std::{collections::BTreeMap, sync::Arc};

use ariadne::{Color, IndexType, Label, Report, ReportKind, Source};
use line_index::{LineIndex, WideEncoding};
use ncc_analysis::{AnalysisHost, Config, Diagnostic, Severity, TextSize};
use ncc_syntax::encoding;
use rayon::prelude::*;
use serde::Serialize;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Format {
    /// Reports with source snippets, for people.
    Human,
    /// One JSON array of diagnostics, for tools (a stable contract).
    Json,
}

/// Reads a program file; bytes that are not UTF-8 are read as Kamenický, so
/// every file can be read (see `ncc_syntax::encoding`).
pub(crate) fn read_program(path: &Path) -> io::Result<String> {
    Ok(encoding::decode(std::fs::read(path)?).0)
}

struct CheckedFile {
    path: PathBuf,
    text: Arc<str>,
    diagnostics: Vec<Diagnostic>,
}

pub(crate) fn run(paths: &[PathBuf], format: Format) -> ExitCode {
    let (files, mut failures) = collect_files(paths);
    let read: Vec<Result<(PathBuf, String), String>> = files
        .par_iter()
        .map(|path| read_program(path).map(|text| (path.clone(), text)).map_err(|e| format!("{}: {e}", path.display())))
        .collect();

    // Files under the same `ncc.toml` form one workspace.
    let mut workspaces: BTreeMap<Option<PathBuf>, Vec<(PathBuf, String)>> = BTreeMap::new();
    for result in read {
        match result {
            Ok((path, text)) => workspaces.entry(Config::find_for(&path)).or_default().push((path, text)),
            Err(message) => failures.push(message),
        }
    }
    let mut checked = Vec::new();
    for (config_path, programs) in workspaces {
        let config = match &config_path {
            Some(path) => match std::fs::read_to_string(path)
                .map_err(|e| format!("{}: {e}", path.display()))
                .and_then(|text| Config::from_toml(&text, &path.display().to_string()))
            {
                Ok(config) => config,
                Err(message) => {
                    failures.push(message);
                    continue;
                }
            },
            None => Config::default(),
        };
        let mut host = AnalysisHost::new(config);
        let ids: Vec<_> =
            programs.into_iter().map(|(path, text)| (host.add_file(path.display().to_string(), text), path)).collect();
        let analysis = host.analysis();
        checked.par_extend(ids.into_par_iter().map_with(analysis, |analysis, (file, path)| CheckedFile {
            path,
            text: analysis.text(file),
            diagnostics: analysis.diagnostics(file),
        }));
    }
    checked.sort_by(|a, b| a.path.cmp(&b.path));

    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    let written = match format {
        Format::Human => write_human(&mut out, &checked),
        Format::Json => write_json(&mut out, &checked),
    };
    if let Err(error) = written.and_then(|()| out.flush()) {
        if error.kind() != io::ErrorKind::BrokenPipe {
            eprintln!("error: writing the report: {error}");
        }
        return ExitCode::from(2);
    }
    for failure in &failures {
        eprintln!("error: {failure}");
    }
    if !failures.is_empty() {
        ExitCode::from(2)
    } else if checked.iter().flat_map(|f| &f.diagnostics).any(|d| d.severity == Severity::Error) {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// The files to check: explicit files as given, partprograms found in
/// directories. Returns them sorted, and the paths that do not exist.
fn collect_files(paths: &[PathBuf]) -> (Vec<PathBuf>, Vec<String>) {
    let mut files = Vec::new();
    let mut failures = Vec::new();
    for path in paths {
        if path.is_file() {
            files.push(path.clone());
        } else if path.is_dir() {
            for entry in ignore::WalkBuilder::new(path).build() {
                match entry {
                    Ok(entry) if entry.file_type().is_some_and(|t| t.is_file()) && is_partprogram(entry.path()) => {
                        files.push(entry.into_path());
                    }
                    Ok(_) => {}
                    Err(error) => failures.push(error.to_string()),
                }
            }
        } else {
            failures.push(format!("{}: no such file or directory", path.display()));
        }
    }
    files.sort();
    files.dedup();
    (files, failures)
}

/// Partprograms (`*.NCP`, any case) and macrocycle files (`L<number>`, with
/// or without an extension).
fn is_partprogram(path: &Path) -> bool {
    let extension_is_ncp = path.extension().is_some_and(|ext| ext.eq_ignore_ascii_case("ncp"));
    let is_macrocycle = path.file_stem().and_then(|stem| stem.to_str()).is_some_and(|stem| {
        stem.len() > 1 && stem.starts_with(['L', 'l']) && stem[1..].bytes().all(|b| b.is_ascii_digit())
    });
    extension_is_ncp || is_macrocycle
}

fn write_human(out: &mut impl Write, files: &[CheckedFile]) -> io::Result<()> {
    let color = io::stdout().is_terminal();
    let config = ariadne::Config::default().with_index_type(IndexType::Byte).with_color(color);
    let mut counts = [0usize; 4];
    for file in files {
        if file.diagnostics.is_empty() {
            continue;
        }
        let name = file.path.display().to_string();
        let source = Source::from(&*file.text);
        for diagnostic in &file.diagnostics {
            counts[diagnostic.severity as usize] += 1;
            let range: Range<usize> = diagnostic.range.into();
            let (kind, label_color) = match diagnostic.severity {
                Severity::Error => (ReportKind::Error, Color::Red),
                Severity::Warning => (ReportKind::Warning, Color::Yellow),
                Severity::Info => (ReportKind::Custom("info", Color::Blue), Color::Blue),
                Severity::Hint => (ReportKind::Custom("hint", Color::Cyan), Color::Cyan),
            };
            let mut report = Report::build(kind, (name.clone(), range.clone()))
                .with_config(config)
                .with_code(format!("{} {}", diagnostic.code, diagnostic.name))
                .with_message(&diagnostic.message)
                .with_label(
                    Label::new((name.clone(), range))
                        .with_message(diagnostic.name.replace('-', " "))
                        .with_color(label_color)
                        .with_order(0),
                );
            for related in &diagnostic.related {
                match &related.file {
                    None => report.add_label(
                        Label::new((name.clone(), related.range.into()))
                            .with_message(&related.message)
                            .with_color(Color::Cyan)
                            .with_order(1),
                    ),
                    Some(other) => report.add_note(format!("{}: {}", other, related.message)),
                }
            }
            for fix in &diagnostic.fixes {
                report.add_help(&fix.title);
            }
            report.finish().write((name.clone(), &source), &mut *out)?;
        }
    }
    let [hints, infos, warnings, errors] = counts;
    let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
    let checked = plural(files.len(), "file");
    if errors + warnings + infos + hints == 0 {
        writeln!(out, "All checks passed ({checked} checked).")
    } else {
        writeln!(
            out,
            "Found {}, {}, {} and {} in {checked}.",
            plural(errors, "error"),
            plural(warnings, "warning"),
            plural(infos, "info"),
            plural(hints, "hint"),
        )
    }
}

/// One diagnostic in `--format json`. Lines and columns are 1-based, columns
/// count characters (Unicode scalar values), and the end is exclusive.
#[derive(Serialize)]
struct JsonDiagnostic<'a> {
    file: String,
    line: u32,
    column: u32,
    end_line: u32,
    end_column: u32,
    severity: &'static str,
    code: &'static str,
    name: &'static str,
    message: &'a str,
}

fn write_json(out: &mut impl Write, files: &[CheckedFile]) -> io::Result<()> {
    let mut all = Vec::new();
    for file in files {
        let index = LineIndex::new(&file.text);
        let position = |offset: TextSize| {
            let line_col = index.line_col(offset);
            let wide = index.to_wide(WideEncoding::Utf32, line_col).expect("offset inside the text");
            (wide.line + 1, wide.col + 1)
        };
        for diagnostic in &file.diagnostics {
            let (line, column) = position(diagnostic.range.start());
            let (end_line, end_column) = position(diagnostic.range.end());
            all.push(JsonDiagnostic {
                file: file.path.display().to_string(),
                line,
                column,
                end_line,
                end_column,
                severity: diagnostic.severity.as_str(),
                code: diagnostic.code,
                name: diagnostic.name,
                message: &diagnostic.message,
            });
        }
    }
    serde_json::to_writer_pretty(&mut *out, &all)?;
    writeln!(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recognises_partprogram_file_names() {
        for name in ["a.NCP", "b.ncp", "L9001", "L12.NCP", "dir/L7"] {
            assert!(is_partprogram(Path::new(name)), "{name}");
        }
        for name in ["README.md", "L", "Lx1", "a.txt", "NCP"] {
            assert!(!is_partprogram(Path::new(name)), "{name}");
        }
    }
}
