//! Findings as the analysis keeps them, and the limit every report applies.
//!
//! A line keeps the first [`PER_LINE`] findings of each rule; the others
//! are counted (see `ncc_syntax::limit`), so a hostile file costs memory
//! in proportion to its lines, not to its findings. [`limit`] then shows
//! at most [`PER_LINE`] findings a line and the configured number a file,
//! and says how many it left out, where the first of them is.

use ncc_syntax::{
    Severity, TextEdit, TextRange, TextSize,
    limit::{LineCursor, Omitted, PER_LINE, keep_per_line},
};

use crate::{Diagnostic, diagnostic::declare_rules};

declare_rules! {
    MORE_ON_LINE = "Z001", "more-findings-on-line", Info, "Findings of a line beyond the first 10, counted in one finding as severe as the most severe of them.";
    MORE_IN_FILE = "Z002", "more-findings-in-file", Info, "Findings of a file beyond the most a report shows (`[report] max-findings`), counted in one finding as severe as the most severe of them.";
}

/// Findings of one rule, at one severity, left out of a line.
pub type OmittedFindings = Omitted<(&'static str, Severity)>;

/// A file's findings: the ones kept, and counts of those left out.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Findings {
    pub diagnostics: Vec<Diagnostic>,
    pub omitted: Vec<OmittedFindings>,
}

impl Findings {
    /// `diagnostics` of `text` limited per line: the first [`PER_LINE`] of
    /// each rule on each line are kept, in order of position.
    pub(crate) fn of(text: &str, mut diagnostics: Vec<Diagnostic>, mut omitted: Vec<OmittedFindings>) -> Findings {
        sort_diagnostics(&mut diagnostics);
        let diagnostics = keep_per_line(text, diagnostics, &mut omitted, |d| d.range.start(), key);
        Findings { diagnostics, omitted }
    }

    pub fn append(&mut self, mut other: Findings) {
        self.diagnostics.append(&mut other.diagnostics);
        self.omitted.append(&mut other.omitted);
    }

    /// Moved by `offset` (chunk-relative positions become file positions).
    pub(crate) fn shifted(self, offset: TextSize) -> Findings {
        Findings {
            diagnostics: self.diagnostics.into_iter().map(|d| d.shifted(offset)).collect(),
            omitted: self.omitted.into_iter().map(|o| o.shifted(offset)).collect(),
        }
    }

    /// The findings where they stand after `edit`, without those it
    /// touches (see [`Diagnostic::moved_through`]).
    pub fn moved_through(self, edit: &TextEdit) -> Findings {
        let inserted = TextSize::of(edit.insert.as_str());
        let omitted = self.omitted.into_iter().filter_map(|o| {
            if o.at < edit.delete.start() {
                Some(o)
            } else if o.line >= edit.delete.end() {
                let moved = |at: TextSize| at - edit.delete.len() + inserted;
                Some(Omitted { line: moved(o.line), at: moved(o.at), ..o })
            } else {
                None
            }
        });
        Findings {
            diagnostics: self.diagnostics.into_iter().filter_map(|d| d.moved_through(edit)).collect(),
            omitted: omitted.collect(),
        }
    }
}

/// What a line keeps a number of: a rule at a severity (a configuration
/// and `ncc:ignore` act on whole rules).
pub(crate) fn key(diagnostic: &Diagnostic) -> (&'static str, Severity) {
    (diagnostic.code, diagnostic.severity)
}

pub(crate) fn sort_diagnostics(diagnostics: &mut [Diagnostic]) {
    diagnostics.sort_by(|a, b| (a.range.start(), a.range.end(), a.code).cmp(&(b.range.start(), b.range.end(), b.code)));
}

/// Findings left out of a report: how many, where the first starts, and
/// the most severe.
struct LeftOut {
    at: TextSize,
    count: u64,
    severity: Severity,
}

impl LeftOut {
    fn add(this: &mut Option<LeftOut>, at: TextSize, count: u64, severity: Severity) {
        match this {
            Some(left) => {
                left.count += count;
                left.severity = left.severity.max(severity);
            }
            None => *this = Some(LeftOut { at, count, severity }),
        }
    }

    /// "1 more finding", "12 more findings".
    fn more(&self) -> String {
        format!("{} more finding{}", self.count, if self.count == 1 { "" } else { "s" })
    }

    fn finding(self, rule: &'static crate::Rule, message: String) -> Diagnostic {
        let mut finding = Diagnostic::new(rule, TextRange::empty(self.at), message);
        finding.severity = self.severity;
        finding
    }
}

/// The findings a report shows: at most [`PER_LINE`] a line and
/// `max_per_file` a file, in order of position, each line's and the file's
/// rest counted in one finding at the first finding left out.
pub(crate) fn limit(text: &str, findings: Findings, max_per_file: usize) -> Vec<Diagnostic> {
    let Findings { mut diagnostics, mut omitted } = findings;
    sort_diagnostics(&mut diagnostics);
    omitted.sort_by_key(|o| o.at);
    let (mut diagnostics, mut omitted) = (diagnostics.into_iter().peekable(), omitted.into_iter().peekable());
    let mut shown = Vec::new();
    let mut shown_in_file = 0;
    let mut lines = LineCursor::new(text);
    let (mut line, mut shown_on_line) = (None, 0);
    let (mut line_rest, mut file_rest) = (None, None);
    let line_finding = |rest: LeftOut| {
        let message = format!("{} on this line not shown (a report shows at most {PER_LINE} a line)", rest.more());
        rest.finding(&MORE_ON_LINE, message)
    };
    loop {
        // The next finding or count, in order of position.
        let next = match (diagnostics.peek(), omitted.peek()) {
            (None, None) => break,
            (Some(d), Some(o)) if o.at < d.range.start() => Err(omitted.next()),
            (Some(_), _) => Ok(diagnostics.next()),
            (None, Some(_)) => Err(omitted.next()),
        };
        let (at, count, severity) = match &next {
            Ok(Some(d)) => (d.range.start(), 1, d.severity),
            Err(Some(o)) => (o.at, u64::from(o.count), o.kind.1),
            _ => break,
        };
        if shown_in_file >= max_per_file {
            LeftOut::add(&mut file_rest, at, count, severity);
            continue;
        }
        let here = lines.line_start(usize::from(at));
        if here != line {
            shown.extend(line_rest.take().map(line_finding));
            (line, shown_on_line) = (here, 0);
        }
        match next {
            Ok(Some(diagnostic)) if shown_on_line < PER_LINE => {
                shown_on_line += 1;
                shown_in_file += 1;
                shown.push(diagnostic);
            }
            _ => LeftOut::add(&mut line_rest, at, count, severity),
        }
    }
    shown.extend(line_rest.map(line_finding));
    if let Some(rest) = file_rest {
        let message = format!(
            "{} in this file not shown (a report shows at most {max_per_file} a file; `max-findings` in the `[report]` section of ncc.toml sets it)",
            rest.more()
        );
        shown.push(rest.finding(&MORE_IN_FILE, message));
    }
    sort_diagnostics(&mut shown);
    shown
}
