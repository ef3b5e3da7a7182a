//! The text and JSON reports of `ncc check`.

use std::{
    collections::HashMap,
    io::{self, Write},
    path::PathBuf,
    sync::Arc,
};

use ariadne::{Color, IndexType, Label, Report, ReportKind};
use ncc_analysis::{Diagnostic, Severity, TextRange, TextSize};
use ncc_syntax::visible;
use serde::Serialize;

use crate::{
    excerpt::{MarkedFile, Shown},
    positions::{Columns, TextIndex},
};

/// Line and column of offsets in one file: 1-based, columns counting
/// characters (Unicode scalar values), as editors and people count them.
pub(crate) struct Positions(TextIndex);

impl Positions {
    pub fn new(text: &str) -> Positions {
        Positions(TextIndex::new(text))
    }

    pub fn at(&self, offset: TextSize) -> (u32, u32) {
        let (line, col) = self.0.line_col(offset, Columns::Characters);
        (line + 1, col + 1)
    }
}

/// A checked file and its diagnostics.
pub(crate) struct CheckedFile {
    pub path: PathBuf,
    pub text: Arc<String>,
    pub diagnostics: Vec<Diagnostic>,
}

/// What a report shows: the checked files, and the text of every file a
/// diagnostic points into (macrocycle files that were not checked too).
pub(crate) struct Checked {
    pub files: Vec<CheckedFile>,
    pub sources: HashMap<String, Arc<String>>,
}

impl Checked {
    /// The text of a file named in a related location.
    pub fn source(&self, name: &str) -> Option<&str> {
        self.sources.get(name).map(|text| text.as_str())
    }
}

pub(crate) fn write_human(out: &mut impl Write, checked: &Checked, color: bool) -> io::Result<()> {
    let config = ariadne::Config::default().with_index_type(IndexType::Char).with_color(color);
    let mut shown = Shown::new(marked_files(checked));
    let mut counts = [0usize; 4];
    let mut rendered = Vec::new();
    for file in &checked.files {
        let name = file.path.display().to_string();
        let Some(key) = shown.key(&name) else { continue };
        for diagnostic in &file.diagnostics {
            counts[diagnostic.severity as usize] += 1;
            let (kind, label_color) = match diagnostic.severity {
                Severity::Error => (ReportKind::Error, Color::Red),
                Severity::Warning => (ReportKind::Warning, Color::Yellow),
                Severity::Info => (ReportKind::Custom("info", Color::Blue), Color::Blue),
                Severity::Hint => (ReportKind::Custom("hint", Color::Cyan), Color::Cyan),
            };
            let span = shown.span(key, diagnostic.range);
            let mut report = Report::build(kind, span.clone())
                .with_config(config)
                .with_code(format!("{} {}", diagnostic.code, diagnostic.name))
                .with_message(visible::escaped(&diagnostic.message))
                .with_label(
                    Label::new(span)
                        .with_message(diagnostic.name.replace('-', " "))
                        .with_color(label_color)
                        .with_order(0),
                );
            for related in &diagnostic.related {
                let other = related.file.as_ref().unwrap_or(&name);
                match shown.key(other) {
                    Some(other) => report.add_label(
                        Label::new(shown.span(other, related.range))
                            .with_message(visible::escaped(&related.message))
                            .with_color(Color::Cyan)
                            .with_order(1),
                    ),
                    None => report.add_note(visible::escaped(&format!("{other}: {}", related.message))),
                }
            }
            for fix in &diagnostic.fixes {
                report.add_help(visible::escaped(&fix.title));
            }
            rendered.clear();
            report.finish().write(&mut shown, &mut rendered)?;
            out.write_all(shown.restore_places(&String::from_utf8_lossy(&rendered)).as_bytes())?;
        }
        shown.forget(key);
    }
    let [hints, infos, warnings, errors] = counts;
    let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
    let files = plural(checked.files.len(), "file");
    if errors + warnings + infos + hints == 0 {
        writeln!(out, "All checks passed ({files} checked).")
    } else {
        writeln!(
            out,
            "Found {}, {}, {} and {} in {files}.",
            plural(errors, "error"),
            plural(warnings, "warning"),
            plural(infos, "info"),
            plural(hints, "hint"),
        )
    }
}

/// The files the findings point into, with the places they mark.
fn marked_files(checked: &Checked) -> Vec<MarkedFile<'_>> {
    let mut marks: HashMap<&str, Vec<usize>> = HashMap::new();
    for file in &checked.files {
        for diagnostic in &file.diagnostics {
            let own =
                checked.sources.get_key_value(file.path.display().to_string().as_str()).map(|(name, _)| name.as_str());
            let places = own.map(|name| (name, diagnostic.range)).into_iter().chain(
                diagnostic.related.iter().filter_map(|related| {
                    let name = related.file.as_deref().or(own)?;
                    Some((checked.sources.get_key_value(name)?.0.as_str(), related.range))
                }),
            );
            for (name, range) in places {
                marks.entry(name).or_default().extend([usize::from(range.start()), usize::from(range.end())]);
            }
        }
    }
    marks
        .into_iter()
        .filter_map(|(name, marks)| Some(MarkedFile { name, text: checked.source(name)?, marks }))
        .collect()
}

/// `file:line:col: severity[code]: message`, one line each, like compilers
/// print for editors and grep.
pub(crate) fn write_short(out: &mut impl Write, checked: &Checked) -> io::Result<()> {
    for file in &checked.files {
        let positions = Positions::new(&file.text);
        let name = file.path.display().to_string();
        let name = visible::escaped(&name);
        for diagnostic in &file.diagnostics {
            let (line, column) = positions.at(diagnostic.range.start());
            // One line per finding, whatever a message or a file name holds.
            let message = visible::escaped(&diagnostic.message);
            writeln!(out, "{name}:{line}:{column}: {}[{}]: {message}", diagnostic.severity, diagnostic.code)?;
        }
    }
    Ok(())
}

/// A range in `--format json`: 1-based, columns count characters, the end
/// is exclusive.
#[derive(Serialize)]
struct JsonRange {
    line: u32,
    column: u32,
    end_line: u32,
    end_column: u32,
}

impl JsonRange {
    fn new(positions: &Positions, range: TextRange) -> JsonRange {
        let (line, column) = positions.at(range.start());
        let (end_line, end_column) = positions.at(range.end());
        JsonRange { line, column, end_line, end_column }
    }
}

/// One diagnostic in `--format json`.
#[derive(Serialize)]
struct JsonDiagnostic<'a> {
    file: String,
    #[serde(flatten)]
    range: JsonRange,
    severity: &'static str,
    code: &'static str,
    name: &'static str,
    message: &'a str,
    related: Vec<JsonRelated<'a>>,
    fixes: Vec<JsonFix<'a>>,
}

/// Another place that explains a diagnostic.
#[derive(Serialize)]
struct JsonRelated<'a> {
    file: String,
    /// Absent when the place is in a file that was not read.
    #[serde(flatten)]
    range: Option<JsonRange>,
    message: &'a str,
}

#[derive(Serialize)]
struct JsonFix<'a> {
    title: &'a str,
    edits: Vec<JsonEdit<'a>>,
}

/// Replace the text of `range` (in the diagnostic's file) with `new_text`.
#[derive(Serialize)]
struct JsonEdit<'a> {
    #[serde(flatten)]
    range: JsonRange,
    new_text: &'a str,
}

pub(crate) fn write_json(out: &mut impl Write, checked: &Checked) -> io::Result<()> {
    let mut all = Vec::new();
    for file in &checked.files {
        let positions = Positions::new(&file.text);
        let name = file.path.display().to_string();
        all.extend(file.diagnostics.iter().map(|diagnostic| json_diagnostic(checked, &name, &positions, diagnostic)));
    }
    serde_json::to_writer_pretty(&mut *out, &all)?;
    writeln!(out)
}

fn json_diagnostic<'a>(
    checked: &Checked,
    file: &str,
    positions: &Positions,
    diagnostic: &'a Diagnostic,
) -> JsonDiagnostic<'a> {
    JsonDiagnostic {
        file: file.to_owned(),
        range: JsonRange::new(positions, diagnostic.range),
        severity: diagnostic.severity.as_str(),
        code: diagnostic.code,
        name: diagnostic.name,
        message: &diagnostic.message,
        related: diagnostic
            .related
            .iter()
            .map(|related| {
                let range = match &related.file {
                    None => Some(JsonRange::new(positions, related.range)),
                    Some(other) => {
                        checked.source(other).map(|text| JsonRange::new(&Positions::new(text), related.range))
                    }
                };
                JsonRelated {
                    file: related.file.clone().unwrap_or_else(|| file.to_owned()),
                    range,
                    message: &related.message,
                }
            })
            .collect(),
        fixes: diagnostic
            .fixes
            .iter()
            .map(|fix| JsonFix {
                title: &fix.title,
                edits: fix
                    .edits
                    .iter()
                    .map(|edit| JsonEdit { range: JsonRange::new(positions, edit.delete), new_text: &edit.insert })
                    .collect(),
            })
            .collect(),
    }
}
