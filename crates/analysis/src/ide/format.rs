//! Document formatting: spacing only, never the program's meaning.
//!
//! The style follows the manual's examples and common CNC8x6 practice:
//!
//! * a block's `N` starts its line; a line that continues a block is
//!   indented by one space (`N10 R1=100.` / ` R2=200.`);
//! * one space between the items of a block (`N10 G0X0` → `N10 G0 X0`),
//!   none inside a word or an assignment (`X  36.12` → `X36.12`,
//!   `R1 = 5` → `R1=5`);
//! * a comment stays in its column: one after words keeps it as far as
//!   the words before it leave room (aligned comments stay aligned), and
//!   one that begins a line keeps its indentation;
//! * trailing spaces and tabs are removed, tabs become spaces.
//!
//! Everything else is kept as written: comments, line endings (`\r\n`
//! stays), blank lines, the `%` header line, everything from the `*` end
//! on, and the spacing around any syntax error, whose text may mean
//! something else once respaced. Lines are never joined or split, and a
//! line is left alone if respacing would make it longer than the
//! control's 80 characters.

use ncc_catalog::AddressRole;
use ncc_syntax::{MAX_LINE_CHARS, NcLanguage, Parse, SyntaxErrorKind, SyntaxKind, TextEdit, TextRange, TextSize};
use rowan::{GreenNodeData, NodeOrToken};

/// The edits that format `text`, whose parse is `parse`: sorted, not
/// overlapping, each replacing one run of spaces (or the empty gap between
/// two items) that changes.
pub(crate) fn format(text: &str, parse: &Parse) -> Vec<TextEdit> {
    let block_letter = parse.dialect().catalogue().letter_with_role(AddressRole::BlockNumber);
    let mut formatter = Formatter {
        text,
        errors: parse.errors().iter().filter(|e| e.kind != SyntaxErrorKind::LineTooLong).map(|e| e.range).collect(),
        next_error: 0,
        error_reach: None,
        block_letter,
        items: 0,
        block_head: false,
        after_end: false,
        edits: Vec::new(),
        line: Line { start: 0, edits: 0, growth: 0 },
        prev: None,
    };
    formatter.node(parse.green(), 0, Place::Free);
    formatter.end_line(text.len());
    formatter.edits
}

/// Where a token sits, as far as spacing goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    /// Between the items of a block, or between blocks.
    Free,
    /// Inside one item (a word, an assignment, a block skip), by number.
    Item(u32),
    /// Kept as written: the header line, text the parser could not place.
    Verbatim,
}

/// A token other than spaces and line breaks.
#[derive(Debug, Clone, Copy)]
struct Token {
    kind: SyntaxKind,
    end: usize,
    place: Place,
    /// The block number that starts a block.
    starts_block: bool,
}

/// The line being formatted.
struct Line {
    start: usize,
    /// Index of the line's first edit.
    edits: usize,
    /// Bytes the line's edits so far add (negative: remove).
    growth: i64,
}

struct Formatter<'a> {
    text: &'a str,
    /// Ranges of the syntax errors, by start.
    errors: Vec<TextRange>,
    next_error: usize,
    /// The furthest end of the errors that start before the current gap.
    error_reach: Option<TextSize>,
    block_letter: Option<u8>,
    /// Items numbered so far.
    items: u32,
    /// The next token is a block's first.
    block_head: bool,
    /// The `*` end has been passed: nothing after it changes.
    after_end: bool,
    edits: Vec<TextEdit>,
    line: Line,
    /// The previous token on the current line.
    prev: Option<Token>,
}

impl Formatter<'_> {
    /// Visits the children of `node`, which starts at `offset`.
    fn node(&mut self, node: &GreenNodeData, mut offset: usize, place: Place) {
        for child in node.children() {
            match child {
                NodeOrToken::Token(token) => {
                    self.token(kind(token.kind()), offset, token.text(), place);
                }
                NodeOrToken::Node(inner) => {
                    let inner_place = match (place, kind(inner.kind())) {
                        (Place::Verbatim, _) | (_, SyntaxKind::HEADER | SyntaxKind::ERROR) => Place::Verbatim,
                        (Place::Free, SyntaxKind::WORD | SyntaxKind::PARAM_ASSIGN | SyntaxKind::BLOCK_SKIP) => {
                            self.items += 1;
                            Place::Item(self.items)
                        }
                        (Place::Free, SyntaxKind::BLOCK) => {
                            self.block_head = true;
                            Place::Free
                        }
                        // A parameter reference inside its word, the end.
                        (place, _) => place,
                    };
                    self.node(inner, offset, inner_place);
                }
            }
            offset += usize::from(child.text_len());
        }
    }

    fn token(&mut self, kind: SyntaxKind, start: usize, text: &str, place: Place) {
        match kind {
            SyntaxKind::WHITESPACE => {}
            SyntaxKind::NEWLINE => {
                self.end_line(start);
                self.line = Line { start: start + text.len(), edits: self.edits.len(), growth: 0 };
            }
            _ => {
                let place = match kind {
                    SyntaxKind::PREAMBLE | SyntaxKind::TRAILER | SyntaxKind::UNREAD | SyntaxKind::ERROR_TOKEN => {
                        Place::Verbatim
                    }
                    _ => place,
                };
                let head = std::mem::take(&mut self.block_head);
                let starts_block = head && text.bytes().next().map(|b| b.to_ascii_uppercase()) == self.block_letter;
                let token = Token { kind, end: start + text.len(), place, starts_block };
                self.gap(start, Some(token));
                self.prev = Some(token);
                if kind == SyntaxKind::STAR {
                    self.after_end = true;
                }
            }
        }
    }

    /// Ends the line at `end`: its trailing spaces go, and its edits are
    /// dropped if they would make it too long for the control.
    fn end_line(&mut self, end: usize) {
        self.gap(end, None);
        self.prev = None;
        if self.line.growth > 0 {
            let chars = self.text[self.line.start..end].chars().count() as i64;
            if chars + self.line.growth > MAX_LINE_CHARS as i64 {
                self.edits.truncate(self.line.edits);
            }
        }
    }

    /// Respaces the gap before `next` (`None`: the end of the line), which
    /// ends at `end`.
    fn gap(&mut self, end: usize, next: Option<Token>) {
        let start = self.prev.map_or(self.line.start, |prev| prev.end);
        let Some(spaces) = self.spacing(start, end, next) else { return };
        let old = &self.text.as_bytes()[start..end];
        self.line.growth += spaces as i64 - old.len() as i64;
        if old.len() != spaces || old.iter().any(|&b| b != b' ') {
            let range = TextRange::new(offset(start), offset(end));
            self.edits.push(TextEdit::replace(range, " ".repeat(spaces)));
        }
    }

    /// How many spaces the gap `start..end` before `next` becomes; `None`
    /// to keep it as it is.
    fn spacing(&mut self, start: usize, end: usize, next: Option<Token>) -> Option<usize> {
        let prev = self.prev;
        let verbatim = |token: Option<Token>| token.is_some_and(|t| t.place == Place::Verbatim);
        if self.after_end || verbatim(prev) || verbatim(next) || self.touches_error(start, end) {
            return None;
        }
        let Some(next) = next else {
            // Spaces between a lone `\r` and a `\n` keep them two line breaks.
            let bytes = self.text.as_bytes();
            let joins = start > 0 && bytes[start - 1] == b'\r' && bytes.get(end) == Some(&b'\n');
            return (!joins).then_some(0);
        };
        match prev {
            None if next.starts_block || next.kind == SyntaxKind::STAR => Some(0),
            None if next.kind == SyntaxKind::COMMENT => None,
            // A line that continues its block.
            None => Some(1),
            // The comment keeps its column if there is room.
            Some(_) if next.kind == SyntaxKind::COMMENT => {
                let old = (end - start) as i64;
                Some(usize::try_from(old - self.line.growth).unwrap_or(0).max(1))
            }
            Some(prev) if matches!(prev.place, Place::Item(_)) && prev.place == next.place => Some(0),
            Some(_) => Some(1),
        }
    }

    /// Whether the gap `start..end` touches a syntax error (other than a
    /// long line). Gaps come in order, so the errors are swept once.
    fn touches_error(&mut self, start: usize, end: usize) -> bool {
        while let Some(error) = self.errors.get(self.next_error).filter(|e| e.start() <= offset(end)) {
            self.error_reach = Some(self.error_reach.map_or(error.end(), |reach| reach.max(error.end())));
            self.next_error += 1;
        }
        self.error_reach.is_some_and(|reach| reach >= offset(start))
    }
}

fn kind(raw: rowan::SyntaxKind) -> SyntaxKind {
    <NcLanguage as rowan::Language>::kind_from_raw(raw)
}

fn offset(at: usize) -> TextSize {
    TextSize::try_from(at).expect("texts are smaller than 4 GiB")
}
