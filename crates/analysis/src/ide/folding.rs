//! Folding: program units, and runs of comment lines.

use ncc_syntax::{SyntaxKind, TextRange, TextSize};
use rowan::{GreenNodeData, NodeOrToken};

use super::{
    highlight::{children, kind},
    symbols::Outline,
};
use crate::db::{Db, SourceFile};

/// A range an editor can fold. It starts on the line that stays visible and
/// ends where the last folded line's text ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Fold {
    pub range: TextRange,
    pub kind: FoldKind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FoldKind {
    /// A program unit: the main body, a subprogram, a macrocycle or a
    /// fixed-cycle body.
    Region,
    /// Two or more consecutive lines that hold nothing but comments.
    Comment,
}

/// The folds of a file, sorted by start (an enclosing fold first).
pub(crate) fn folding_ranges(db: &dyn Db, file: SourceFile) -> Vec<Fold> {
    let outline = Outline::new(db, file);
    let units = (0..outline.program.units.len()).filter_map(|unit| outline.unit_range(unit));
    with_comment_runs(db, file, units.map(|range| Fold { range, kind: FoldKind::Region }).collect())
}

/// `regions` that span lines and the runs of comment lines of `file`,
/// sorted by start (an enclosing fold first).
pub(crate) fn with_comment_runs(db: &dyn Db, file: SourceFile, regions: Vec<Fold>) -> Vec<Fold> {
    let text = file.text(db);
    let mut folds: Vec<Fold> = regions.into_iter().filter(|fold| text[fold.range].contains(['\n', '\r'])).collect();
    let mut lines = CommentLines::default();
    lines.node(file.parse(db).green(), TextSize::from(0));
    lines.end_line();
    lines.end_run();
    folds.append(&mut lines.folds);
    folds.sort_by_key(|fold| (fold.range.start(), std::cmp::Reverse(fold.range.end())));
    folds
}

/// Finds the runs of comment-only lines, token by token.
#[derive(Default)]
struct CommentLines {
    /// The first and last comment of the current run, and its length in lines.
    run: Option<(TextRange, TextRange, usize)>,
    /// The comments of the current line.
    comments: Option<TextRange>,
    /// The current line holds something other than comments and blanks.
    text: bool,
    folds: Vec<Fold>,
}

impl CommentLines {
    fn node(&mut self, node: &GreenNodeData, start: TextSize) {
        for (range, child) in children(node, start) {
            match child {
                NodeOrToken::Node(node) => match kind(node.kind()) {
                    SyntaxKind::BLOCK_RUN | SyntaxKind::BLOCK | SyntaxKind::HEADER | SyntaxKind::END => {
                        self.node(node, range.start())
                    }
                    // Words, assignments and the like never hold a line
                    // break or a comment.
                    _ => self.text = true,
                },
                NodeOrToken::Token(token) => match kind(token.kind()) {
                    SyntaxKind::NEWLINE => self.end_line(),
                    SyntaxKind::WHITESPACE => {}
                    SyntaxKind::COMMENT => self.comments = Some(self.comments.map_or(range, |c| c.cover(range))),
                    // Text before `%` may span lines; the header continues
                    // its last one.
                    SyntaxKind::PREAMBLE => {
                        self.text = true;
                        self.end_line();
                        self.text = !token.text().ends_with(['\n', '\r']);
                    }
                    _ => self.text = true,
                },
            }
        }
    }

    fn end_line(&mut self) {
        match (self.comments.take(), self.text) {
            (Some(comments), false) => {
                self.run = Some(match self.run {
                    Some((first, _, lines)) => (first, comments, lines + 1),
                    None => (comments, comments, 1),
                });
            }
            _ => self.end_run(),
        }
        self.text = false;
    }

    fn end_run(&mut self) {
        if let Some((first, last, lines)) = self.run.take()
            && lines >= 2
        {
            self.folds.push(Fold { range: first.cover(last), kind: FoldKind::Comment });
        }
    }
}
