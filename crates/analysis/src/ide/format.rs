//! Document formatting: the style of `[format]` in `ncc.toml`, never the
//! program's meaning.
//!
//! Always, in every dialect:
//!
//! * one space between the items of a block (`N10 G0X0` → `N10 G0 X0`),
//!   or none between words where `spacing = "none"` asks for it (not in
//!   Sinumerik, whose names run on until a space);
//! * a comment stays in its column: one after words keeps it as far as
//!   the words before it leave room (aligned comments stay aligned), and
//!   one that begins a line keeps its indentation;
//! * trailing spaces and tabs are removed.
//!
//! CNC8x6, as the manual's examples write it: a block's `N` starts its
//! line, a line that continues a block is indented by one space
//! (`N10 R1=100.` / ` R2=200.`), and nothing separates the parts of a word
//! or an assignment (`X  36.12` → `X36.12`, `R1 = 5` → `R1=5`). The Haas
//! lathe and Sinumerik, whose block is a line, keep a line's indentation
//! (Sinumerik's loops and branches are often indented) and the spacing
//! inside a statement (`IF [#1 GT 2]`, `DEF REAL A`).
//!
//! On request, letters to upper case, redundant zeros of decimal numbers
//! removed, the words of plain blocks put in the standard order and lines
//! indented by their nesting (see [`FormatConfig`]).
//!
//! Everything else is kept as written: comments, strings, line endings
//! (`\r\n` stays), blank lines, the CNC8x6 `%` header line and everything
//! from its `*` end on, the Haas `%` tape marks, and the text around any
//! syntax error, whose text may mean something else once changed. Lines
//! are never joined or split, and a line is left alone if formatting would
//! make it longer than the control reads.

use ncc_catalog::{AddressRole, Catalogue, Dialect, FunctionKind};
use ncc_syntax::{MAX_LINE_CHARS, NcLanguage, Parse, SyntaxErrorKind, SyntaxKind, TextEdit, TextRange, TextSize};
use rowan::{GreenNodeData, NodeOrToken};

use super::common_ends::{common_prefix, common_suffix};
use crate::config::{FormatConfig, LetterCase, NumberStyle, WordOrder, WordSpacing};

/// The edits that format `text`, whose parse is `parse`, in `style`: one
/// per changed line, sorted. With `range`, only the lines it touches
/// change. `levels` are the nesting levels of the blocks that start at
/// each offset, sorted, when `style` indents.
pub(crate) fn format(
    text: &str,
    parse: &Parse,
    style: FormatConfig,
    range: Option<TextRange>,
    levels: &[(TextSize, u32)],
) -> Vec<TextEdit> {
    let dialect = parse.dialect();
    let catalogue = dialect.catalogue();
    // A long line is the line's, not its text's; a lower-case letter is
    // what `case` changes.
    let folds = style.case == LetterCase::Upper;
    let errors = Errors::new(parse, |kind| {
        kind != SyntaxErrorKind::LineTooLong && !(folds && kind == SyntaxErrorKind::LowercaseAddress)
    });
    let mut formatter = Formatter {
        text,
        layout: Layout::of(dialect),
        catalogue,
        style,
        errors,
        block_letter: catalogue.letter_with_role(AddressRole::BlockNumber),
        items: 0,
        block_head: false,
        after_end: false,
        word_role: None,
        slot: None,
        levels,
        level: None,
        out: String::with_capacity(text.len()),
        line: Line { start: 0, out_start: 0 },
        prev: None,
    };
    formatter.node(parse.green(), 0, Place::Free);
    formatter.end_line(text.len());
    line_edits(text, &formatter.out, range)
}

/// What formatting must know of a dialect's layout.
#[derive(Debug, Clone, Copy)]
struct Layout {
    /// A block is a line: a line's indentation is the programmer's.
    block_is_line: bool,
    /// Nothing separates the parts of an item (CNC8x6 `X36.12`, `R1=5`);
    /// otherwise the spacing inside an item is kept.
    tight_items: bool,
    /// Words may be written together (`N10G0X0`).
    joins_words: bool,
    /// Names and keywords are read in any case, so `case` changes them too.
    folds_names: bool,
    /// The most characters a line may have after formatting: what the
    /// control reads of a block.
    line_limit: usize,
}

impl Layout {
    fn of(dialect: Dialect) -> Layout {
        match dialect {
            Dialect::Cnc8x6 => Layout {
                block_is_line: false,
                tight_items: true,
                joins_words: true,
                folds_names: false,
                line_limit: MAX_LINE_CHARS,
            },
            Dialect::HaasLathe => Layout {
                block_is_line: true,
                tight_items: false,
                joins_words: true,
                folds_names: false,
                // The manual gives no limit.
                line_limit: usize::MAX,
            },
            // Sinumerik reads a name until a space, so words stay apart.
            Dialect::Sinumerik => Layout {
                block_is_line: true,
                tight_items: false,
                joins_words: false,
                folds_names: true,
                line_limit: crate::sinumerik::MAX_BLOCK_CHARS,
            },
        }
    }

    /// Whether a node of `kind` directly in a block is one of its items.
    fn is_item(self, kind: SyntaxKind) -> bool {
        !self.tight_items || matches!(kind, SyntaxKind::WORD | SyntaxKind::PARAM_ASSIGN | SyntaxKind::BLOCK_SKIP)
    }
}

/// Where a token sits, as far as spacing goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    /// Between the items of a block, or between blocks.
    Free,
    /// Inside one item (a word, an assignment, a statement), by number,
    /// and whether the item is a word.
    Item(u32, bool),
    /// Kept as written: the header line, text the parser could not place.
    Verbatim,
}

/// A token other than spaces and line breaks.
#[derive(Debug, Clone, Copy)]
struct Token {
    kind: SyntaxKind,
    /// Where the gap after it starts.
    end: usize,
    place: Place,
    /// The block number that starts a block.
    starts_block: bool,
}

/// The line being formatted: where it starts in the text and in the
/// output.
struct Line {
    start: usize,
    out_start: usize,
}

struct Formatter<'a> {
    text: &'a str,
    layout: Layout,
    catalogue: &'static Catalogue,
    style: FormatConfig,
    /// The syntax errors that keep the text around them as written.
    errors: Errors,
    block_letter: Option<u8>,
    /// Items numbered so far.
    items: u32,
    /// The next token is a block's first.
    block_head: bool,
    /// The `*` end has been passed: nothing after it changes.
    after_end: bool,
    /// The role of the address of the word being read, once its letter
    /// has been.
    word_role: Option<AddressRole>,
    /// Where the slot of a reordered item starts, until its first token
    /// is written.
    slot: Option<usize>,
    /// The nesting level of each block by its start, when lines are
    /// indented by it.
    levels: &'a [(TextSize, u32)],
    /// The level of the block being written.
    level: Option<u32>,
    out: String,
    line: Line,
    /// The previous token on the current line.
    prev: Option<Token>,
}

impl Formatter<'_> {
    /// Visits the children of `node`, which starts at `offset`.
    fn node(&mut self, node: &GreenNodeData, mut offset: usize, place: Place) {
        let reordered = self.reordered_items(node, offset, place);
        let mut items = reordered.iter().flatten();
        for child in node.children() {
            let len = usize::from(child.text_len());
            match child {
                NodeOrToken::Token(token) => self.token(kind(token.kind()), offset, token.text(), place),
                NodeOrToken::Node(inner) => {
                    let inner_kind = kind(inner.kind());
                    let inner_place = match (place, inner_kind) {
                        (Place::Verbatim, _) | (_, SyntaxKind::HEADER | SyntaxKind::ERROR | SyntaxKind::TAPE_MARK) => {
                            Place::Verbatim
                        }
                        (Place::Free, SyntaxKind::BLOCK) => {
                            self.block_head = true;
                            self.level = self
                                .levels
                                .binary_search_by_key(&self::offset(offset), |&(start, _)| start)
                                .ok()
                                .map(|found| self.levels[found].1);
                            Place::Free
                        }
                        (Place::Free, SyntaxKind::BLOCK_RUN) => Place::Free,
                        (Place::Free, _) if self.layout.is_item(inner_kind) => {
                            self.items += 1;
                            Place::Item(self.items, inner_kind == SyntaxKind::WORD)
                        }
                        // A parameter reference inside its word, the end.
                        (place, _) => place,
                    };
                    if matches!(inner_place, Place::Item(..)) && inner_place != place {
                        self.word_role = None;
                    }
                    match items.next() {
                        // A reordered item takes the slot of the one it
                        // replaces: the gaps around it are the slot's.
                        Some(&(moved_from, moved)) => {
                            self.slot = Some(offset);
                            self.node(moved, moved_from, inner_place);
                            if let Some(prev) = self.prev.as_mut() {
                                prev.end = offset + len;
                            }
                        }
                        None => self.node(inner, offset, inner_place),
                    }
                }
            }
            offset += len;
        }
    }

    fn token(&mut self, kind: SyntaxKind, start: usize, text: &str, place: Place) {
        match kind {
            SyntaxKind::WHITESPACE => {}
            SyntaxKind::NEWLINE => {
                self.end_line(start);
                self.out.push_str(text);
                self.line = Line { start: start + text.len(), out_start: self.out.len() };
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
                let gap_end = self.slot.take().unwrap_or(start);
                self.gap(gap_end, Some(token));
                self.write_token(kind, start, text, place);
                self.prev = Some(token);
                if kind == SyntaxKind::STAR {
                    self.after_end = true;
                }
            }
        }
    }

    /// Writes a token, in the style's case and number form where it may
    /// change.
    fn write_token(&mut self, kind: SyntaxKind, start: usize, text: &str, place: Place) {
        if kind == SyntaxKind::LETTER && self.word_role.is_none() {
            self.word_role = Some(self.catalogue.address(text).map_or(AddressRole::Parameter, |a| a.role));
        }
        let free = matches!(place, Place::Item(..)) && !self.after_end;
        let end = start + text.len();
        match kind {
            SyntaxKind::LETTER | SyntaxKind::IDENT => {
                let folds = kind == SyntaxKind::LETTER || self.layout.folds_names;
                if self.style.case == LetterCase::Upper
                    && folds
                    && free
                    && text.bytes().any(|b| b.is_ascii_lowercase())
                    && !self.errors.touch(start, end)
                {
                    self.out.push_str(&text.to_ascii_uppercase());
                    return;
                }
            }
            SyntaxKind::NUMBER => {
                let code = matches!(
                    self.word_role,
                    Some(AddressRole::Function | AddressRole::BlockNumber | AddressRole::ProgramNumber)
                );
                if self.style.numbers == NumberStyle::Trim
                    && !code
                    && free
                    && let Some(trimmed) = trimmed_number(text)
                    && !self.errors.touch(start, end)
                {
                    self.out.push_str(&trimmed);
                    return;
                }
            }
            _ => {}
        }
        self.out.push_str(text);
    }

    /// Ends the line at `end`: its trailing spaces go, and it is written
    /// as it was if formatting made it too long for the control.
    fn end_line(&mut self, end: usize) {
        self.gap(end, None);
        self.prev = None;
        let old = &self.text[self.line.start..end];
        let new = &self.out[self.line.out_start..];
        if new.len() > old.len() && new.chars().count() > self.layout.line_limit {
            self.out.truncate(self.line.out_start);
            self.out.push_str(old);
        }
    }

    /// Writes the gap before `next` (`None`: the end of the line), which
    /// ends at `end`.
    fn gap(&mut self, end: usize, next: Option<Token>) {
        let start = self.prev.map_or(self.line.start, |prev| prev.end);
        match self.spacing(start, end, next) {
            Some(spaces) => self.out.extend(std::iter::repeat_n(' ', spaces)),
            None => self.out.push_str(&self.text[start..end]),
        }
    }

    /// How many spaces the gap `start..end` before `next` becomes; `None`
    /// to keep it as it is.
    fn spacing(&mut self, start: usize, end: usize, next: Option<Token>) -> Option<usize> {
        let prev = self.prev;
        let verbatim = |token: Option<Token>| token.is_some_and(|t| t.place == Place::Verbatim);
        if self.after_end || verbatim(prev) || verbatim(next) || self.errors.touch(start, end) {
            return None;
        }
        let Some(next) = next else {
            // Spaces between a lone `\r` and a `\n` keep them two line breaks.
            let bytes = self.text.as_bytes();
            let joins = start > 0 && bytes[start - 1] == b'\r' && bytes.get(end) == Some(&b'\n');
            return (!joins).then_some(0);
        };
        match prev {
            // A line's indentation: by its nesting when asked, else as
            // written.
            None if self.layout.block_is_line => match (self.style.indent, self.level) {
                (Some(width), Some(level)) => Some(usize::from(width) * level as usize),
                _ => None,
            },
            None if next.starts_block || next.kind == SyntaxKind::STAR => Some(0),
            None if next.kind == SyntaxKind::COMMENT => None,
            // A line that continues its block.
            None => Some(1),
            // The comment keeps its column if there is room.
            Some(_) if next.kind == SyntaxKind::COMMENT => {
                let written = (self.out.len() - self.line.out_start) as i64;
                let growth = written - (start - self.line.start) as i64;
                let old = (end - start) as i64;
                Some(usize::try_from(old - growth).unwrap_or(0).max(1))
            }
            Some(Token { place: Place::Item(item, _), .. }) if matches!(next.place, Place::Item(i, _) if i == item) => {
                self.layout.tight_items.then_some(0)
            }
            Some(Token { place: Place::Item(_, true), .. })
                if matches!(next.place, Place::Item(_, true))
                    && self.style.spacing == WordSpacing::None
                    && self.layout.joins_words =>
            {
                Some(0)
            }
            Some(_) => Some(1),
        }
    }

    /// The items of `node` in the standard order, when it is a block the
    /// style reorders and the order changes.
    fn reordered_items<'n>(
        &self,
        node: &'n GreenNodeData,
        offset: usize,
        place: Place,
    ) -> Option<Vec<(usize, &'n GreenNodeData)>> {
        if self.style.word_order != WordOrder::Standard
            || place != Place::Free
            || kind(node.kind()) != SyntaxKind::BLOCK
        {
            return None;
        }
        let mut items = Vec::new();
        let mut ended = false;
        let (mut start, mut end, mut at) = (None, offset, offset);
        for child in node.children() {
            let child_start = at;
            at += usize::from(child.text_len());
            if child.as_node().is_some() {
                start.get_or_insert(child_start);
                end = at;
            }
            match child {
                NodeOrToken::Token(token) => match kind(token.kind()) {
                    SyntaxKind::WHITESPACE => {}
                    // A comment or a line break ends the words: the block
                    // is one line of words and a comment after them.
                    SyntaxKind::COMMENT | SyntaxKind::NEWLINE => ended = true,
                    _ => return None,
                },
                NodeOrToken::Node(_) if ended => return None,
                NodeOrToken::Node(word) => items.push((self.rank(word)?, (child_start, word))),
            }
        }
        let repeated = |(i, (rank, (_, word))): (usize, &(Rank, (usize, &GreenNodeData)))| {
            !rank.is_code() && items[..i].iter().any(|(_, (_, other))| letter(other).eq_ignore_ascii_case(letter(word)))
        };
        // A block number elsewhere than first is not one to move there.
        let misplaced_number = items.iter().skip(1).any(|(rank, _)| *rank == Rank::BlockNumber);
        if misplaced_number
            || items.iter().enumerate().any(repeated)
            || items.is_sorted_by_key(|(rank, _)| *rank)
            || self.errors.touch(start?, end)
        {
            return None;
        }
        items.sort_by_key(|(rank, _)| *rank);
        Some(items.into_iter().map(|(_, word)| word).collect())
    }

    /// Where a plain word (a letter, a sign and a number) goes in the
    /// standard order; `None` for anything else. Words of one rank keep
    /// the order they are written in: of two codes of one group the last
    /// holds, and two letters may move one axis (Haas `X` and `U`).
    fn rank(&self, word: &GreenNodeData) -> Option<Rank> {
        match kind(word.kind()) {
            SyntaxKind::BLOCK_NUMBER => return Some(Rank::BlockNumber),
            SyntaxKind::WORD => {}
            _ => return None,
        }
        let mut kinds = word.children().map(|child| kind(child.kind()));
        let plain = matches!(
            (kinds.next(), kinds.next(), kinds.next(), kinds.next()),
            (Some(SyntaxKind::LETTER), Some(SyntaxKind::NUMBER), None, None)
                | (
                    Some(SyntaxKind::LETTER),
                    Some(SyntaxKind::MINUS | SyntaxKind::PLUS),
                    Some(SyntaxKind::NUMBER),
                    None
                )
        );
        if !plain {
            return None;
        }
        let address = self.catalogue.address(letter(word))?;
        Rank::of(address.role, address.function)
    }
}

/// Syntax errors of some kinds, to ask whether a range touches one.
struct Errors {
    /// By start.
    ranges: Vec<TextRange>,
    /// The furthest end of the errors up to each.
    reach: Vec<TextSize>,
}

impl Errors {
    fn new(parse: &Parse, counts: impl Fn(SyntaxErrorKind) -> bool) -> Errors {
        let mut ranges: Vec<TextRange> = parse.errors().iter().filter(|e| counts(e.kind)).map(|e| e.range).collect();
        ranges.sort_by_key(|e| e.start());
        let reach = ranges
            .iter()
            .scan(TextSize::from(0), |reach, error| {
                *reach = (*reach).max(error.end());
                Some(*reach)
            })
            .collect();
        Errors { ranges, reach }
    }

    /// Whether `start..end` touches one of the errors.
    fn touch(&self, start: usize, end: usize) -> bool {
        let before = self.ranges.partition_point(|e| e.start() <= offset(end));
        before > 0 && self.reach[before - 1] >= offset(start)
    }
}

/// The standard order of a block's words (Sinumerik's recommended
/// `N G X Y Z F S T D M H`, the ISO controls' alike), by address role.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Rank {
    BlockNumber,
    Preparatory,
    Axis,
    Interpolation,
    Corner,
    Feed,
    Speed,
    Tool,
    Offset,
    Miscellaneous,
    /// `P`, `Q`, `L`, `H`: what the block's function takes.
    Arguments,
}

impl Rank {
    fn of(role: AddressRole, function: Option<FunctionKind>) -> Option<Rank> {
        Some(match role {
            AddressRole::BlockNumber => Rank::BlockNumber,
            AddressRole::Function => match function? {
                FunctionKind::Preparatory => Rank::Preparatory,
                FunctionKind::Miscellaneous => Rank::Miscellaneous,
            },
            AddressRole::Axis => Rank::Axis,
            AddressRole::Interpolation => Rank::Interpolation,
            AddressRole::Corner => Rank::Corner,
            AddressRole::Feed => Rank::Feed,
            AddressRole::Speed => Rank::Speed,
            AddressRole::Tool => Rank::Tool,
            AddressRole::Offset | AddressRole::LengthCompensation => Rank::Offset,
            AddressRole::Count | AddressRole::Label | AddressRole::Auxiliary => Rank::Arguments,
            _ => return None,
        })
    }

    /// Codes may be written more than once in a block (codes of different
    /// groups); a letter of any other address only once.
    fn is_code(self) -> bool {
        matches!(self, Rank::Preparatory | Rank::Miscellaneous)
    }
}

/// The address letter of a word.
fn letter(word: &GreenNodeData) -> &str {
    word.children().next().and_then(NodeOrToken::into_token).map_or("", |token| token.text())
}

/// `number` (digits with a decimal point) without the zeros that say
/// nothing, if it has any: `010.500` → `10.5`, `00.5` → `0.5`. A digit
/// after the point stays (`2.000` → `2.0`): every control reads `2.0`.
fn trimmed_number(number: &str) -> Option<String> {
    let (int, frac) = number.split_once('.')?;
    if !int.bytes().chain(frac.bytes()).all(|b| b.is_ascii_digit()) {
        return None;
    }
    let int = match int.trim_start_matches('0') {
        "" if !int.is_empty() => "0",
        rest => rest,
    };
    let frac = match frac.trim_end_matches('0') {
        "" if !frac.is_empty() => "0",
        rest => rest,
    };
    let trimmed = format!("{int}.{frac}");
    (trimmed != number).then_some(trimmed)
}

/// One edit per line of `old` that `new` (with the same lines) changes,
/// from the first changed character to the last; with `range`, only of
/// the lines it touches.
fn line_edits(old: &str, new: &str, range: Option<TextRange>) -> Vec<TextEdit> {
    // Formatting never adds or removes a line feed.
    debug_assert_eq!(old.matches('\n').count(), new.matches('\n').count(), "formatting changed the lines");
    let mut edits = Vec::new();
    let mut start = 0;
    for (old_line, new_line) in old.split('\n').zip(new.split('\n')) {
        let line = TextRange::new(offset(start), offset(start + old_line.len()));
        let touched = range.is_none_or(|range| range.intersect(line).is_some());
        if old_line != new_line && touched {
            // The common bytes, backed off to a character's start: where
            // the bytes before are alike, both lines have one there.
            let mut prefix = common_prefix(old_line.as_bytes(), new_line.as_bytes());
            while !old_line.is_char_boundary(prefix) {
                prefix -= 1;
            }
            let (old_rest, new_rest) = (&old_line[prefix..], &new_line[prefix..]);
            let mut suffix = common_suffix(old_rest.as_bytes(), new_rest.as_bytes());
            while !old_rest.is_char_boundary(old_rest.len() - suffix) {
                suffix -= 1;
            }
            let delete = TextRange::new(offset(start + prefix), offset(start + old_line.len() - suffix));
            edits.push(TextEdit::replace(delete, &new_rest[..new_rest.len() - suffix]));
        }
        start += old_line.len() + 1;
    }
    edits
}

fn kind(raw: rowan::SyntaxKind) -> SyntaxKind {
    <NcLanguage as rowan::Language>::kind_from_raw(raw)
}

fn offset(at: usize) -> TextSize {
    TextSize::try_from(at).expect("texts are smaller than 4 GiB")
}
