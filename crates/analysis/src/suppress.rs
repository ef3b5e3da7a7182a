//! Suppression comments.
//!
//! A comment that contains `ncc:ignore` silences the diagnostics that start
//! on its line; `ncc:ignore missing-feed, S009` silences only those rules
//! (by name or code). A comment alone on its line silences the next line
//! instead, for lines that have no room left:
//!
//! ```text
//! N10 G01 X10 "ncc:ignore missing-feed
//! "ncc:ignore line-too-long
//! N20 X1 Y2 …a line longer than 80 characters…
//! ```

use std::ops::Range;

use ncc_syntax::{Dialect, Parse, SyntaxKind, TextSize, ast::Comment};

const MARKER: &str = "ncc:ignore";

#[derive(Debug)]
pub struct Suppressions {
    /// Byte ranges of silenced lines, with the rules silenced (empty = all).
    lines: Vec<(Range<usize>, Vec<String>)>,
}

impl Suppressions {
    /// The suppressions of a text outside the database (a file the
    /// executor runs); it is parsed only when it holds a marker.
    pub fn of_text(text: &str, dialect: Dialect) -> Suppressions {
        if !text.contains(MARKER) {
            return Suppressions { lines: Vec::new() };
        }
        Suppressions::of(text, &Parse::new(text, dialect))
    }

    pub(crate) fn of(text: &str, parse: &Parse) -> Suppressions {
        let mut lines = Vec::new();
        // Most files have none; finding that out needs no tree walk.
        if !text.contains(MARKER) {
            return Suppressions { lines };
        }
        let comments = parse
            .syntax_node()
            .descendants_with_tokens()
            .filter_map(|e| e.into_token())
            .filter(|t| t.kind() == SyntaxKind::COMMENT)
            .filter_map(Comment::cast);
        for comment in comments {
            let Some(at) = comment.body().find(MARKER) else { continue };
            let rules: Vec<String> = comment.body()[at + MARKER.len()..]
                .split([',', ' '])
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect();
            let start = usize::from(comment.syntax().text_range().start());
            let line = line_around(text, start);
            let alone = text[line.start..start].trim().is_empty();
            let target = if alone { line_around(text, (line.end + 1).min(text.len())) } else { line };
            lines.push((target, rules));
        }
        lines.sort_by_key(|(line, _)| line.start);
        Suppressions { lines }
    }

    /// Whether findings of rule `code` (`name`) starting at `at` are
    /// silenced. A binary search: a file can have a comment on every line.
    pub fn silences(&self, at: TextSize, code: &str, name: &str) -> bool {
        let at = usize::from(at);
        let candidates = &self.lines[..self.lines.partition_point(|(line, _)| line.start <= at)];
        let on_line = candidates.iter().rev().take_while(|(line, _)| line.contains(&at) || line.start == at);
        on_line.into_iter().any(|(_, rules)| rules.is_empty() || rules.iter().any(|r| r == code || r == name))
    }
}

/// The line holding `at`, without its terminator.
fn line_around(text: &str, at: usize) -> Range<usize> {
    let bytes = text.as_bytes();
    let start = bytes[..at].iter().rposition(|&b| b == b'\n' || b == b'\r').map_or(0, |i| i + 1);
    let end = bytes[at..].iter().position(|&b| b == b'\n' || b == b'\r').map_or(text.len(), |i| at + i);
    start..end
}
