//! The CNC8x6 parser.
//!
//! File layout, as the control reads it:
//!
//! ```text
//! [preamble] [%number ["comment"]] {trivia} {block} [* {anything}]
//! ```
//!
//! * Everything before the first `%` that is not inside a comment is the
//!   preamble: the control skips it while loading.
//! * A block starts at its `N` and runs until the next `N` outside a comment
//!   (or `*`, or the end), across as many lines as it takes. Comment-only lines
//!   and `/` therefore belong to the block that is open.
//! * The first `*` outside a comment is the physical end; the control reads
//!   nothing after it.
//!
//! Every `N` letter outside a comment starts a block: no value position of
//! any word can hold a letter other than `R`. That makes block boundaries
//! findable from any line start (comments never span lines), which the
//! parallel parse and the incremental reparse both rely on.

use std::ops::Range;

use rowan::{GreenNode, NodeOrToken, TextRange};

use super::{
    GrammarLetters, grammar_letters, is_block_letter,
    lexer::{self, Token},
};
pub(crate) use crate::lexing::{line_end, line_start};
use crate::{
    SyntaxError, SyntaxErrorKind as E,
    SyntaxKind::{self, *},
    encoding::BYTE_ORDER_MARK,
    error::Errors,
    green::{self, GreenElement, GreenFactory},
    lexing::{MAX_READ_LINE, range, read_end},
    limit::{LineLimiter, Omitted},
    runs::RunBuilder,
    visible,
};

/// The control's limit on characters per line.
pub const MAX_LINE_CHARS: usize = 80;

/// Bodies larger than this are split at block boundaries and parsed in parallel.
const PARALLEL_THRESHOLD: usize = 1 << 20;

pub(crate) fn parse_source_file(text: &str) -> (GreenNode, Vec<SyntaxError>, Vec<Omitted<E>>) {
    parse_source_file_with(text, PARALLEL_THRESHOLD)
}

fn parse_source_file_with(text: &str, parallel_threshold: usize) -> (GreenNode, Vec<SyntaxError>, Vec<Omitted<E>>) {
    let Outline { mut front, mut errors, header, body } = outline(text);
    let (body_start, end) = (body.start, body.end);

    // File-level trivia and words without a block number, up to the first block.
    let mut parser = Parser::new(text, body_start, end);
    while let Some(token) = parser.peek() {
        match token.kind {
            WHITESPACE | NEWLINE | COMMENT | UNREAD => front.push(parser.bump_trivia(token)),
            LETTER if parser.at_block_start() => break,
            _ => front.push(NodeOrToken::Node(parser.block())),
        }
    }
    let blocks_start = parser.pos;
    errors.append(parser.into_errors());

    // The blocks, in parts that start at block boundaries. Each part also
    // checks the length of the lines that start inside it.
    let lines_from = header.unwrap_or(0);
    let bounds = if end - blocks_start < parallel_threshold {
        vec![blocks_start, end]
    } else {
        split_at_blocks(text, blocks_start..end, rayon::current_num_threads() * 4)
    };
    let line_starts: Vec<usize> = bounds.iter().map(|&at| line_start_at_or_after(text, at, lines_from, end)).collect();
    errors.kept.extend(long_lines(text, lines_from..line_starts[0]));
    let parse_part = |i: usize| {
        let (blocks, mut part_errors) = parse_blocks(text, bounds[i]..bounds[i + 1]);
        part_errors.kept.extend(long_lines(text, line_starts[i]..line_starts[i + 1]));
        (blocks, part_errors)
    };
    let parts: Vec<_> = if bounds.len() > 2 {
        use rayon::prelude::*;
        (0..bounds.len() - 1).into_par_iter().map(parse_part).collect()
    } else {
        vec![parse_part(0)]
    };

    let mut back = None;
    if end < text.len() {
        let mut parser = Parser::new(text, end, text.len());
        back = Some(NodeOrToken::Node(parser.end()));
        errors.append(parser.into_errors());
    }
    // Runs are formed in one pass over all parts: where a run ends must not
    // depend on how the text was split for parallel parsing.
    let mut runs = RunBuilder::new(text, blocks_start);
    for (blocks, part_errors) in parts {
        for block in blocks {
            runs.push(block);
        }
        errors.append(part_errors);
    }
    let (errors, omitted) = errors.finish(text);

    let children: Vec<GreenElement> = front.into_iter().chain(runs.finish()).chain(back).collect();
    (green::node(SOURCE_FILE, children), errors, omitted)
}

/// What surrounds a program's blocks: the preamble and the header, and the
/// body, which runs from the header to the physical end `*`.
struct Outline {
    front: Vec<GreenElement>,
    errors: Errors,
    /// Where the header's `%` is.
    header: Option<usize>,
    body: Range<usize>,
}

fn outline(text: &str) -> Outline {
    let mut front: Vec<GreenElement> = Vec::new();
    let mut errors = Errors::default();
    // An editor's mark of Unicode text is not part of the program (01 §1.2:
    // the control reads plain text).
    let mark = if text.starts_with(BYTE_ORDER_MARK) {
        let mark = BYTE_ORDER_MARK.len_utf8();
        // A token, not a node: the header stays the file's first node.
        front.push(NodeOrToken::Token(rowan::GreenToken::new(ERROR_TOKEN.into(), &text[..mark])));
        errors.kept.push(SyntaxError::new(
            E::ByteOrderMark,
            range(0..mark),
            "the file starts with a byte-order mark: it was saved as Unicode text (UTF-8, UTF-16 or UTF-32 with a mark), but the control reads plain text, one byte a character (ASCII, Kamenický in comments); save it as plain text",
        ));
        mark
    } else {
        0
    };
    let header = find_outside_comments(text, mark, b'%');
    let body_start = match header {
        Some(at) => {
            if at > mark {
                let preamble = &text[mark..at];
                front.push(NodeOrToken::Token(rowan::GreenToken::new(PREAMBLE.into(), preamble)));
                if !preamble.trim().is_empty() {
                    errors.kept.push(SyntaxError::new(
                        E::IgnoredPreamble,
                        range(mark..at),
                        "text before the program header `%` is skipped by the control",
                    ));
                }
            }
            let mut parser = Parser::new(text, at, text.len());
            front.push(NodeOrToken::Node(parser.header()));
            let pos = parser.pos;
            errors.append(parser.into_errors());
            pos
        }
        None => mark,
    };
    let end = find_outside_comments(text, body_start, b'*').unwrap_or(text.len());
    Outline { front, errors, header, body: body_start..end }
}

/// A program's blocks one at a time, each parsed only when asked for: for
/// a reader that takes most blocks some faster way and needs the tree of
/// only a few. The blocks and their ranges are those of the whole tree.
pub struct BlockParser<'a> {
    parser: Parser<'a>,
    header: Option<GreenNode>,
    body: Range<usize>,
}

impl std::fmt::Debug for BlockParser<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockParser").field("body", &self.body).finish_non_exhaustive()
    }
}

impl<'a> BlockParser<'a> {
    pub fn new(text: &'a str) -> BlockParser<'a> {
        let Outline { front, header, body, .. } = outline(text);
        let header = header.and_then(|_| front.into_iter().find_map(NodeOrToken::into_node));
        let mut parser = Parser::new(text, body.start, body.end);
        // File-level trivia before the first block belongs to no block.
        while let Some(token @ Token { kind: WHITESPACE | NEWLINE | COMMENT | UNREAD, .. }) = parser.peek() {
            parser.advance(token);
        }
        let body = parser.pos..body.end;
        BlockParser { parser, header, body }
    }

    /// The program header `%…`.
    pub fn header(&self) -> Option<crate::ast::Header> {
        let root = crate::SyntaxNode::new_root(self.header.clone()?);
        <crate::ast::Header as crate::ast::AstNode>::cast(root)
    }

    /// Where the blocks are: from the first one to the physical end `*`.
    /// Blocks start at a block number `N` (only the words before the first
    /// one lack it) and run up to the next one.
    pub fn body(&self) -> Range<usize> {
        self.body.clone()
    }

    /// The block that starts at `at` with its range; `None` at the end of
    /// the body.
    pub fn block_at(&mut self, at: usize) -> Option<(TextRange, GreenNode)> {
        self.parser.move_to(at);
        self.parser.peek()?;
        let block = self.parser.block();
        self.parser.errors.clear();
        Some((range(at..self.parser.pos), block))
    }
}

/// Boundaries that split `region` (which starts at a block) into about
/// `pieces` parts, each starting at a block.
fn split_at_blocks(text: &str, region: Range<usize>, pieces: usize) -> Vec<usize> {
    let mut bounds = vec![region.start];
    for i in 1..pieces {
        let target = region.start + (region.end - region.start) * i / pieces;
        let at = next_block_start(text, target, region.end);
        if at > *bounds.last().unwrap() && at < region.end {
            bounds.push(at);
        }
    }
    bounds.push(region.end);
    bounds
}

/// The first position at or after `at` where a line starts (`lines_from`
/// counts as one), or `limit`.
fn line_start_at_or_after(text: &str, at: usize, lines_from: usize, limit: usize) -> usize {
    let bytes = text.as_bytes();
    if at == lines_from || at >= limit || matches!(bytes[at - 1], b'\n' | b'\r') {
        return at.min(limit);
    }
    match memchr::memchr2(b'\n', b'\r', &bytes[at..limit]) {
        Some(i) if bytes[at + i] == b'\r' && bytes.get(at + i + 1) == Some(&b'\n') => (at + i + 2).min(limit),
        Some(i) => at + i + 1,
        None => limit,
    }
}

/// Parses the blocks in `region`, which starts at a block's `N` and ends at
/// a block start, at `*` or at the end of the text.
pub(crate) fn parse_blocks(text: &str, region: Range<usize>) -> (Vec<GreenElement>, Errors) {
    let (blocks, errors, _) = parse_blocks_until(text, region, |_| false, &[]);
    (blocks, errors)
}

/// Like [`parse_blocks`], but stops early at the first block start for which
/// `stop_at` holds. Returns where parsing stopped.
pub(crate) fn parse_blocks_until(
    text: &str,
    region: Range<usize>,
    stop_at: impl Fn(usize) -> bool,
    replaced: &[&rowan::GreenNodeData],
) -> (Vec<GreenElement>, Errors, usize) {
    let mut parser = Parser::new(text, region.start, region.end);
    for block in replaced {
        parser.green.share_words_of(block);
    }
    let mut blocks = Vec::new();
    while parser.pos < region.end {
        let before = parser.pos;
        blocks.push(NodeOrToken::Node(parser.block()));
        if parser.pos == before || stop_at(parser.pos) {
            break;
        }
    }
    let pos = parser.pos;
    (blocks, parser.into_errors(), pos)
}

/// The first block start at or after the line holding `from`.
fn next_block_start(text: &str, from: usize, limit: usize) -> usize {
    let bytes = text.as_bytes();
    let mut pos = match memchr::memchr2(b'\n', b'\r', &bytes[from..limit]) {
        Some(i) => from + i,
        None => return limit,
    };
    // Past the read part of a line no block starts.
    let mut unread_from = limit;
    while pos < limit {
        if pos >= unread_from {
            pos = line_end(text, pos, limit);
            unread_from = limit;
            continue;
        }
        let token = lexer::token_at(text, pos);
        if token.kind == LETTER && is_block_letter(bytes[pos]) {
            return pos;
        }
        pos += token.len;
        if token.kind == NEWLINE {
            unread_from = read_end(text, pos, limit);
        }
    }
    limit
}

/// The first `needle` byte at or after `from` that is not inside a comment.
///
/// Each candidate is checked by lexing its line from the start (comments
/// never span lines) or from the end of the comment that hid the previous
/// candidate, so no byte is lexed twice however many candidates there are.
pub(crate) fn find_outside_comments(text: &str, from: usize, needle: u8) -> Option<usize> {
    let bytes = text.as_bytes();
    let mut pos = from;
    while let Some(i) = memchr::memchr(needle, &bytes[pos..]) {
        let candidate = pos + i;
        let mut at = memchr::memrchr2(b'\n', b'\r', &bytes[pos..candidate]).map_or(pos, |i| pos + i + 1);
        loop {
            let token = lexer::token_at(text, at);
            if at + token.len > candidate {
                if token.kind != COMMENT {
                    return Some(candidate);
                }
                pos = at + token.len;
                break;
            }
            at += token.len;
        }
    }
    None
}

/// `line-too-long` for the lines of `region`, whose start counts as a line
/// start and whose end as a line end.
pub(crate) fn long_lines(text: &str, region: Range<usize>) -> Vec<SyntaxError> {
    let bytes = &text.as_bytes()[..region.end];
    let mut errors = Vec::new();
    let mut line_start = region.start;
    let terminators = memchr::memchr2_iter(b'\n', b'\r', &bytes[region.start..]).map(|i| region.start + i);
    for line_end in terminators.chain(std::iter::once(region.end)) {
        if line_end < line_start {
            // The `\n` of a `\r\n` pair.
            continue;
        }
        if line_end - line_start > MAX_LINE_CHARS {
            let line = &text[line_start..line_end];
            let chars = line.chars().count();
            if chars > MAX_LINE_CHARS {
                let excess = line.char_indices().nth(MAX_LINE_CHARS).map_or(0, |(i, _)| i);
                let unread = if line.len() > MAX_READ_LINE {
                    format!("; ncc reads only its first {MAX_READ_LINE} bytes")
                } else {
                    String::new()
                };
                errors.push(SyntaxError::new(
                    E::LineTooLong,
                    range(line_start + excess..line_end),
                    format!(
                        "line is {chars} characters long; the control accepts at most {MAX_LINE_CHARS} per line (a block may continue on the next line){unread}"
                    ),
                ));
            }
        }
        line_start = line_end + 1;
        if bytes.get(line_end) == Some(&b'\r') && bytes.get(line_end + 1) == Some(&b'\n') {
            line_start += 1;
        }
    }
    errors
}

struct Parser<'a> {
    text: &'a str,
    pos: usize,
    /// Where reading stops: `region_end`, or before it where the read part
    /// of the current line ends (`MAX_READ_LINE`).
    end: usize,
    region_end: usize,
    errors: Vec<SyntaxError>,
    /// Keeps `errors` short on lines with thousands of them.
    limiter: LineLimiter<'a, E>,
    green: GreenFactory<'a>,
    /// The number that ended the last word or assignment, while only
    /// spaces follow it: a number after those spaces is a split number.
    last_number: Option<Range<usize>>,
    /// Reused for the children of each block.
    block_children: Vec<GreenElement>,
    /// Copied from the catalogue once, for the hot loop.
    letters: GrammarLetters,
}

impl<'a> Parser<'a> {
    fn new(text: &'a str, pos: usize, end: usize) -> Self {
        let mut parser = Parser {
            text,
            pos,
            end,
            region_end: end,
            errors: Vec::new(),
            limiter: LineLimiter::new(text),
            green: GreenFactory::new(),
            last_number: None,
            block_children: Vec::with_capacity(32),
            letters: grammar_letters(),
        };
        parser.move_to(pos);
        parser
    }

    /// Continues at `pos`, which may be on another line.
    fn move_to(&mut self, pos: usize) {
        self.pos = pos;
        let line_start = line_start(self.text, pos);
        self.end = read_end(self.text, line_start, self.region_end);
    }

    /// Reads the line that starts at the parser's position.
    fn new_line(&mut self) {
        self.end = read_end(self.text, self.pos, self.region_end);
    }

    /// Steps over `token`. After a line break a new line starts; after the
    /// rest of a line that is not read (unread, or after `*`) comes its line
    /// break, read as usual.
    fn advance(&mut self, token: Token) {
        self.pos += token.len;
        if matches!(token.kind, NEWLINE | UNREAD | TRAILER) {
            self.new_line();
        }
    }

    fn token_at(&self, pos: usize) -> Option<Token> {
        crate::lexing::bounded_token(self.text, pos, self.end, self.region_end, lexer::token_at)
    }

    fn peek(&self) -> Option<Token> {
        self.token_at(self.pos)
    }

    fn byte_at(&self, pos: usize) -> u8 {
        self.text.as_bytes()[pos]
    }

    fn skip_whitespace(&self, mut pos: usize) -> usize {
        while let Some(Token { kind: WHITESPACE, len }) = self.token_at(pos) {
            pos += len;
        }
        pos
    }

    fn kind_at(&self, pos: usize) -> Option<SyntaxKind> {
        self.token_at(pos).map(|t| t.kind)
    }

    fn at_block_start(&self) -> bool {
        self.kind_at(self.pos) == Some(LETTER) && self.letters.is_block(self.byte_at(self.pos))
    }

    fn error(&mut self, kind: E, r: Range<usize>, message: impl Into<String>) {
        let r = range(r);
        if self.limiter.keep(r.start(), kind) {
            self.errors.push(SyntaxError::new(kind, r, message));
        }
    }

    fn into_errors(self) -> Errors {
        Errors { kept: self.errors, omitted: self.limiter.finish() }
    }

    /// Consumes the next token as a green token.
    fn bump(&mut self) -> GreenElement {
        let token = self.peek().expect("bump past the end");
        let text = &self.text[self.pos..self.pos + token.len];
        self.advance(token);
        self.green.token(token.kind, text)
    }

    fn bump_trivia(&mut self, token: Token) -> GreenElement {
        if token.kind == COMMENT && self.byte_at(self.pos) != b'"' {
            let quote_len = self.text[self.pos..].chars().next().map_or(1, char::len_utf8);
            self.error(
                E::TypographicQuote,
                self.pos..self.pos + quote_len,
                "typographic quote: the control only knows the straight double quote `\"` for comments",
            );
        }
        self.bump()
    }

    fn header(&mut self) -> GreenNode {
        let start = self.pos;
        let mut children = vec![self.bump()];
        let value_at = self.skip_whitespace(self.pos);
        if matches!(self.kind_at(value_at), Some(NUMBER | PLUS | MINUS)) {
            self.value(&mut children);
        } else {
            self.error(
                E::MissingProgramNumber,
                start..start + 1,
                "the program header `%` must be followed by the program number (1 to 999999), e.g. `%100`",
            );
        }
        while let Some(token) = self.peek() {
            match token.kind {
                WHITESPACE | COMMENT => children.push(self.bump_trivia(token)),
                _ => break,
            }
        }
        green::node(HEADER, children)
    }

    /// A block: its `N` word, then everything up to the next `N`. Called at
    /// anything else, it collects the words that lack their `N`.
    fn block(&mut self) -> GreenNode {
        let mut children = std::mem::take(&mut self.block_children);
        if self.at_block_start() {
            children.push(self.block_number());
        } else {
            self.missing_block_number();
        }
        loop {
            // Fast paths for what CAM output is made of; each builds exactly
            // the tree the general path below would.
            match self.text.as_bytes()[..self.end].get(self.pos) {
                // The end, or where reading the line stops: the general path.
                None => {}
                Some(b' ') if !matches!(self.text.as_bytes()[..self.end].get(self.pos + 1), Some(b' ' | b'\t')) => {
                    children.push(self.green.space());
                    self.pos += 1;
                    continue;
                }
                Some(b'\n') => {
                    children.push(self.green.newline());
                    self.pos += 1;
                    self.new_line();
                    self.last_number = None;
                    continue;
                }
                Some(b'A'..=b'Z') => {
                    if let Some(word) = self.simple_word() {
                        children.push(word);
                        continue;
                    }
                }
                _ => {}
            }
            let Some(token) = self.peek() else { break };
            let item_start = self.pos;
            let number_before = self.last_number.take();
            let child = match token.kind {
                WHITESPACE => {
                    self.last_number = number_before;
                    self.bump()
                }
                NEWLINE | COMMENT | UNREAD => self.bump_trivia(token),
                LETTER if self.letters.is_block(self.byte_at(self.pos)) => break,
                STAR => break,
                LETTER if self.at_parameter_assignment(self.pos) => self.parameter_assignment(),
                LETTER if self.foreign_text_len() > 0 => {
                    let len = self.foreign_text_len();
                    let text = &self.text[self.pos..self.pos + len];
                    self.pos += len;
                    self.error(
                        E::UnexpectedCharacter,
                        item_start..self.pos,
                        format!(
                            "unexpected text `{}`: an address letter must be followed by its value; text belongs in a comment `\"…\"`",
                            visible::quoted(text)
                        ),
                    );
                    NodeOrToken::Node(green::node(ERROR, [self.green.token(ERROR_TOKEN, text)]))
                }
                LETTER | AMP => self.word(),
                SLASH => self.block_skip(),
                NUMBER => {
                    let (kind, message, start) = match number_before {
                        Some(number) => (
                            E::SpaceInNumber,
                            "space inside a number: the control rejects a value interrupted by spaces; join the digits"
                                .to_owned(),
                            number.start,
                        ),
                        None => (
                            E::NumberWithoutAddress,
                            format!(
                                "number `{}` without an address letter",
                                visible::quoted(&self.text[self.pos..self.pos + token.len])
                            ),
                            item_start,
                        ),
                    };
                    let element = self.bump();
                    self.error(kind, start..self.pos, message);
                    NodeOrToken::Node(green::node(ERROR, [element]))
                }
                PLUS | MINUS => {
                    let mut children = vec![self.bump()];
                    if self.kind_at(self.pos) == Some(NUMBER) {
                        children.push(self.bump());
                    }
                    self.error(E::SignWithoutAddress, item_start..self.pos, "signed value without an address letter");
                    NodeOrToken::Node(green::node(ERROR, children))
                }
                EQ => self
                    .error_token(E::MisplacedEquals, "`=` outside a parameter assignment; assignments read `R12=5.`"),
                PERCENT => self
                    .error_token(E::MisplacedPercent, "`%` starts a program only in the header at the top of the file"),
                ERROR_TOKEN => {
                    let text = &self.text[self.pos..self.pos + token.len];
                    let message = if text.starts_with(',') {
                        "unexpected `,`: the decimal separator is `.`".to_owned()
                    } else {
                        format!(
                            "unexpected `{}`: outside comments only addresses, numbers, signs, `=`, `/`, `&` and spaces are allowed",
                            visible::quoted(text)
                        )
                    };
                    self.error_token(E::UnexpectedCharacter, message)
                }
                _ => unreachable!("token {:?} inside a block", token.kind),
            };
            children.push(child);
        }
        self.last_number = None;
        let block = green::node(BLOCK, children.drain(..));
        self.block_children = children;
        block
    }

    /// `N` and its digits, or the general word path for anything unusual.
    fn block_number(&mut self) -> GreenElement {
        let bytes = &self.text.as_bytes()[..self.end];
        let start = self.pos;
        let digits = bytes[start + 1..].iter().take_while(|b| b.is_ascii_digit()).count();
        let plain = bytes[start].is_ascii_uppercase() && digits > 0 && bytes.get(start + 1 + digits) != Some(&b'.');
        if !plain {
            return self.word();
        }
        self.pos = start + 1 + digits;
        self.last_number = Some(start + 1..self.pos);
        let number = self.green.token(NUMBER, &self.text[start + 1..self.pos]);
        NodeOrToken::Node(green::node(WORD, [self.green.letter(bytes[start]), number]))
    }

    /// Length of a run of three or more letters none of which has a value,
    /// like `MSG` or `comme`: foreign text, reported once rather than letter
    /// by letter. The run stops before `N`, which always starts a block.
    fn foreign_text_len(&self) -> usize {
        crate::lexing::foreign_text_len(
            &self.text.as_bytes()[self.pos..self.end],
            |b| self.letters.is_block(b),
            |run| self.at_value(self.skip_whitespace(self.pos + run)),
        )
    }

    fn missing_block_number(&mut self) {
        let end = self.peek().map_or(self.pos, |t| self.pos + t.len);
        self.error(
            E::MissingBlockNumber,
            self.pos..end,
            "every block must begin with its block number `N`; these words belong to no block",
        );
    }

    fn error_token(&mut self, kind: E, message: impl Into<String>) -> GreenElement {
        let start = self.pos;
        let element = self.bump();
        self.error(kind, start..self.pos, message);
        NodeOrToken::Node(green::node(ERROR, [element]))
    }

    /// A word: address letter (or `&`), optional spaces, value.
    fn word(&mut self) -> GreenElement {
        if let Some(word) = self.simple_word() {
            return word;
        }
        let start = self.pos;
        let mut children = vec![self.address_letter()];
        let value_at = self.skip_whitespace(self.pos);
        if self.at_value(value_at) {
            self.value(&mut children);
            if self.letters.is_parameter(self.byte_at(start)) {
                let written = visible::quoted(&self.text[start..self.pos]);
                self.error(
                    E::ParameterWithoutAssignment,
                    start..self.pos,
                    format!("`{written}` assigns nothing: write `{written}=<value>` to set the parameter, or put it after an address (`X{written}`) to use it"),
                );
            }
        } else {
            let address = &self.text[start..start + 1];
            let message = if self.letters.is_block(self.byte_at(start)) {
                "block number missing: write it after `N`, e.g. `N10`".to_owned()
            } else {
                format!(
                    "address `{address}` has no value; write a number (`{address}0` for zero) or a parameter (`{address}R1`)"
                )
            };
            self.error(E::MissingValue, start..start + 1, message);
        }
        NodeOrToken::Node(green::node(WORD, children))
    }

    /// The common case, uppercase letter, optional sign and a number,
    /// served from the word cache. Block numbers are unique, so caching them
    /// would only cost memory; `R` words need the general path's diagnostic.
    fn simple_word(&mut self) -> Option<GreenElement> {
        let bytes = &self.text.as_bytes()[..self.end];
        let start = self.pos;
        let letter = bytes[start];
        if !letter.is_ascii_uppercase() || self.letters.is_block(letter) || self.letters.is_parameter(letter) {
            return None;
        }
        let sign_len = usize::from(matches!(bytes.get(start + 1), Some(b'-' | b'+')));
        let number_start = start + 1 + sign_len;
        let int = bytes[number_start..].iter().take_while(|b| b.is_ascii_digit()).count();
        let mut end = number_start + int;
        if bytes.get(end) == Some(&b'.') {
            end += 1;
            end += bytes[end..].iter().take_while(|b| b.is_ascii_digit()).count();
        }
        if end - number_start - usize::from(end > number_start + int) == 0 {
            return None;
        }
        self.pos = end;
        self.last_number = Some(number_start..end);
        Some(self.green.simple_word(&self.text[start..end], sign_len))
    }

    fn address_letter(&mut self) -> GreenElement {
        let at = self.pos;
        if self.byte_at(at).is_ascii_lowercase() {
            let upper = self.byte_at(at).to_ascii_uppercase() as char;
            self.error(
                E::LowercaseAddress,
                at..at + 1,
                format!(
                    "lower-case address `{}`; the control's addresses are upper-case `{upper}`",
                    self.byte_at(at) as char
                ),
            );
        }
        self.bump()
    }

    /// Whether a value (sign, number or parameter reference) starts at `pos`.
    fn at_value(&self, pos: usize) -> bool {
        match self.kind_at(pos) {
            Some(PLUS | MINUS | NUMBER) => true,
            Some(LETTER) => self.letters.is_parameter(self.byte_at(pos)) && !self.at_parameter_assignment(pos),
            _ => false,
        }
    }

    /// Parses `[spaces] [sign [spaces]] (number | parameter reference)` into
    /// `children`; the caller checked [`Parser::at_value`].
    fn value(&mut self, children: &mut Vec<GreenElement>) {
        while self.kind_at(self.pos) == Some(WHITESPACE) {
            children.push(self.bump());
        }
        if let Some(PLUS | MINUS) = self.kind_at(self.pos) {
            let sign_start = self.pos;
            if self.byte_at(sign_start) >= 0x80 {
                self.error(
                    E::TypographicMinus,
                    sign_start..sign_start + 3,
                    "typographic minus: the control only knows the ASCII minus `-`",
                );
            }
            children.push(self.bump());
            let digits_at = self.skip_whitespace(self.pos);
            let value_follows = self.kind_at(digits_at) == Some(NUMBER)
                || (self.kind_at(digits_at) == Some(LETTER) && self.letters.is_parameter(self.byte_at(digits_at)));
            if !value_follows {
                self.error(E::MissingValue, sign_start..self.pos, "sign without digits after it");
                return;
            }
            if digits_at > self.pos {
                self.error(
                    E::SpaceAfterSign,
                    sign_start..digits_at,
                    "space between the sign and the digits: the control rejects it; write the sign next to the number",
                );
                while self.pos < digits_at {
                    children.push(self.bump());
                }
            }
        }
        match self.kind_at(self.pos) {
            Some(NUMBER) => children.push(self.number()),
            Some(LETTER) => children.push(self.parameter_reference()),
            _ => unreachable!("value() without a value"),
        }
    }

    fn number(&mut self) -> GreenElement {
        let start = self.pos;
        let element = self.bump();
        if self.text[start..self.pos].bytes().all(|b| b == b'.') {
            self.error(E::NumberWithoutDigits, start..self.pos, "a number needs at least one digit (`0.` for zero)");
        }
        self.last_number = Some(start..self.pos);
        element
    }

    /// `R` and the parameter number: the `R10` of `FR10`.
    fn parameter_reference(&mut self) -> GreenElement {
        let children =
            self.parameter_letter_and_number("`R` must be followed by the parameter number (0 to 95), e.g. `XR1`");
        NodeOrToken::Node(green::node(PARAM_REF, children))
    }

    /// `R`, spaces and the parameter number, or `R` and an error.
    fn parameter_letter_and_number(&mut self, missing: &str) -> Vec<GreenElement> {
        let start = self.pos;
        let mut children = vec![self.address_letter()];
        let number_at = self.skip_whitespace(self.pos);
        if self.kind_at(number_at) == Some(NUMBER) {
            while self.pos < number_at {
                children.push(self.bump());
            }
            children.push(self.number());
        } else {
            self.error(E::MissingParameterNumber, start..start + 1, missing);
        }
        children
    }

    /// `R`, optional number, optional spaces, `=`.
    fn at_parameter_assignment(&self, pos: usize) -> bool {
        if self.kind_at(pos) != Some(LETTER) || !self.letters.is_parameter(self.byte_at(pos)) {
            return false;
        }
        let mut at = self.skip_whitespace(pos + 1);
        if let Some(Token { kind: NUMBER, len }) = self.token_at(at) {
            at = self.skip_whitespace(at + len);
        }
        self.kind_at(at) == Some(EQ)
    }

    /// `R12=-0.864`, spaces allowed around `=`.
    fn parameter_assignment(&mut self) -> GreenElement {
        let start = self.pos;
        let mut children = self.parameter_letter_and_number("parameter number missing: assignments read `R12=5.`");
        while self.kind_at(self.pos) == Some(WHITESPACE) {
            children.push(self.bump());
        }
        let eq = self.pos;
        children.push(self.bump());
        let value_at = self.skip_whitespace(self.pos);
        if self.at_value(value_at) {
            self.value(&mut children);
        } else {
            self.error(E::MissingValue, start..eq + 1, "parameter assignment without a value after `=`");
        }
        NodeOrToken::Node(green::node(PARAM_ASSIGN, children))
    }

    /// `/`, and a digit directly after it (which the control ignores).
    fn block_skip(&mut self) -> GreenElement {
        let mut children = vec![self.bump()];
        if self.kind_at(self.pos) == Some(NUMBER) {
            children.push(self.bump());
        }
        NodeOrToken::Node(green::node(BLOCK_SKIP, children))
    }

    /// `*` and the rest of the file: comments and line breaks are kept as
    /// such, anything else is text the control never reads.
    fn end(&mut self) -> GreenNode {
        let mut children = vec![self.bump()];
        let mut ignored: Option<Range<usize>> = None;
        while let Some(token) = self.peek() {
            match token.kind {
                WHITESPACE | NEWLINE | COMMENT => children.push(self.bump()),
                _ => {
                    let start = self.pos;
                    let line_end = line_end(self.text, start, self.text.len());
                    children.push(self.green.token(TRAILER, &self.text[start..line_end]));
                    self.advance(Token { kind: TRAILER, len: line_end - start });
                    let first = ignored.map_or(start, |r| r.start);
                    ignored = Some(first..line_end);
                }
            }
        }
        if let Some(ignored) = ignored {
            self.error(E::TextAfterEnd, ignored, "text after the physical end `*` is never read by the control");
        }
        green::node(END, children)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn many_hidden_markers_are_skipped_in_one_pass() {
        // A quadratic search would not finish on this.
        let text = format!("\"{}\"%1\nN1 \"{}\n*", "%".repeat(1 << 20), "*".repeat(1 << 20));
        assert_eq!(find_outside_comments(&text, 0, b'%'), Some((1 << 20) + 2));
        assert_eq!(find_outside_comments(&text, 0, b'*'), Some(text.len() - 1));
    }

    #[test]
    fn parallel_parse_equals_sequential_parse() {
        let mut text = String::from("leader\n%12 \"big\"\n\"before\"\nG90 X1\n");
        let pieces = [
            "N1 G1 X1.5 Y-2 \"c N2\"\n Y3\n",
            "N2 R1=864 XR1 \u{201C}typo\n",
            "N3 X36.  12 / Y 4.\r\n",
            "N4 X1 N5 Y2 # 7\n\n",
            "n6 comment text\n",
            // More errors of one kind than a line keeps, on lines that the
            // split into parts cuts.
            "N7 X X X X X X X X X X X X X 1 2 3 4 5 6 7 8 9 1 2 3 4\n",
            "N8 X N9 X N10 X N11 X N12 X N13 X N14 X N15 X N16 X N17 X N18 X N19 X\n",
            // Block numbers past the read part of a line start no block.
            &"N20 X1 Y2 ".repeat(150),
            "\n",
        ];
        for i in 0..2000 {
            text.push_str(pieces[i % pieces.len()]);
        }
        text.push_str("* \"end\"\nN99\n");
        let sequential = parse_source_file_with(&text, usize::MAX);
        assert!(!sequential.2.is_empty(), "no line had errors left out");
        let parallel = parse_source_file_with(&text, 0);
        assert_eq!(sequential, parallel);
        assert_eq!(rowan::SyntaxNode::<crate::NcLanguage>::new_root(parallel.0).to_string(), text);
    }

    /// A line of megabytes is read up to `MAX_READ_LINE` bytes and the rest
    /// kept as one token: its tree does not grow with its length.
    #[test]
    fn a_long_line_is_read_up_to_the_limit() {
        let line: String = (0..1_000_000u32).map(|i| b"N1X.5G=Y-2"[(i * 7 % 10) as usize] as char).collect();
        for text in [format!("%1\n{line}\nN2 X1\n"), format!("%1 \"{line}\nN2 X1\n"), format!("{line}\r\nN2 X1")] {
            let (green, errors, _) = parse_source_file(&text);
            let root = crate::SyntaxNode::new_root(green);
            assert_eq!(root.to_string(), text);
            assert!(root.descendants_with_tokens().count() < 2_000, "{}", root.descendants_with_tokens().count());
            let unread: Vec<_> = root.descendants_with_tokens().filter(|e| e.kind() == UNREAD).collect();
            assert_eq!(unread.len(), 1);
            let line_start = text.find(&line[..20]).unwrap_or(0);
            let unread_start = usize::from(unread[0].text_range().start());
            assert!(unread_start >= line_start + MAX_READ_LINE - 4 && unread_start <= line_start + MAX_READ_LINE);
            // The block after the long line is read.
            let last = root.descendants().filter(|n| n.kind() == BLOCK).last().unwrap();
            assert!(last.to_string().starts_with("N2 X1"), "{last}");
            assert!(errors.iter().any(|e| e.message.contains("ncc reads only its first 1024 bytes")));
        }
    }
}
