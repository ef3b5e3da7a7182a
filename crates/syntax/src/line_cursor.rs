//! Reading a region of lines token by token, for the dialects whose block
//! is a line (Haas lathe, Sinumerik): the position, the read part of the
//! line (`MAX_READ_LINE`), the errors with their per-line limit and the
//! green tokens. Each dialect's parser holds one and reaches it through
//! `Deref`, and the shared expression parser reads through it.

use std::{
    marker::PhantomData,
    ops::{DerefMut, Range},
};

use rowan::{GreenNode, NodeOrToken};

use crate::{
    SyntaxError, SyntaxErrorKind as E,
    SyntaxKind::{self, *},
    error::Errors,
    expr::{Ahead, ExprInput},
    green::{self, GreenElement, GreenFactory},
    lexing::{MAX_READ_LINE, Token, bounded_token, line_start, number_len, range, read_end},
    limit::LineLimiter,
};

/// A syntax error a token read whole carries: its kind, its length from the
/// token's start and its message.
pub(crate) type TokenError = (E, usize, String);

/// A dialect's lexer, called statically (the parse's hottest path).
pub(crate) trait Lexer {
    /// The token at `pos`.
    fn token_at(text: &str, pos: usize) -> Token;
    /// The error a token of `kind` and `text` carries, if any (an unclosed
    /// comment or string).
    fn unclosed(kind: SyntaxKind, text: &str) -> Option<TokenError>;
}

/// A dialect's parser of line blocks, which the shared drivers of
/// `line_blocks` run over a region.
pub(crate) trait LineParser<'a>: DerefMut<Target = LineCursor<'a, Self::Lexer>> {
    type Lexer: Lexer;
    /// A parser at `pos`, a line start, that reads up to `region_end`.
    fn new(text: &'a str, pos: usize, region_end: usize) -> Self;
    /// The block (the line, with its line break) at the position.
    fn block(&mut self) -> GreenNode;
}

pub(crate) struct LineCursor<'a, L> {
    pub(crate) text: &'a str,
    pub(crate) pos: usize,
    /// Where reading stops: `region_end`, or before it where the read part
    /// of the current line ends (`MAX_READ_LINE`).
    pub(crate) end: usize,
    region_end: usize,
    errors: Vec<SyntaxError>,
    limiter: LineLimiter<'a, E>,
    pub(crate) green: GreenFactory<'a>,
    /// The allocation of the last block's children, which the next reuses.
    block_children: Vec<GreenElement>,
    lexer: PhantomData<L>,
}

impl<'a, L: Lexer> LineCursor<'a, L> {
    pub(crate) fn new(text: &'a str, pos: usize, region_end: usize) -> Self {
        let mut cursor = LineCursor {
            text,
            pos,
            end: region_end,
            region_end,
            errors: Vec::new(),
            limiter: LineLimiter::new(text),
            green: GreenFactory::new(),
            block_children: Vec::new(),
            lexer: PhantomData,
        };
        cursor.move_to(pos, region_end);
        cursor
    }

    /// Continues at `pos`, a line start, reading up to `region_end`.
    pub(crate) fn move_to(&mut self, pos: usize, region_end: usize) {
        self.pos = pos;
        self.region_end = region_end;
        self.end = read_end(self.text, line_start(self.text, pos), region_end);
    }

    pub(crate) fn token_at(&self, pos: usize) -> Option<Token> {
        bounded_token(self.text, pos, self.end, self.region_end, L::token_at)
    }

    pub(crate) fn kind_at(&self, pos: usize) -> Option<SyntaxKind> {
        self.token_at(pos).map(|t| t.kind)
    }

    pub(crate) fn peek(&self) -> Option<Token> {
        self.token_at(self.pos)
    }

    /// The first position at or after `pos` that is not whitespace.
    pub(crate) fn skip_whitespace(&self, mut pos: usize) -> usize {
        while let Some(Token { kind: WHITESPACE, len }) = self.token_at(pos) {
            pos += len;
        }
        pos
    }

    pub(crate) fn report(&mut self, kind: E, r: Range<usize>, message: impl Into<String>) {
        let r = range(r);
        if self.limiter.keep(r.start(), kind) {
            self.errors.push(SyntaxError::new(kind, r, message));
        }
    }

    /// Reports `kind` from `start` to the position.
    pub(crate) fn report_from(&mut self, kind: E, start: usize, message: impl Into<String>) {
        self.report(kind, start..self.pos, message);
    }

    /// The errors reported so far; the cursor starts a fresh list.
    pub(crate) fn take_errors(&mut self) -> Errors {
        let limiter = std::mem::replace(&mut self.limiter, LineLimiter::new(self.text));
        Errors { kept: std::mem::take(&mut self.errors), omitted: limiter.finish() }
    }

    /// Consumes the next token, reporting the line past its read part and
    /// what the dialect's lexer says is left open.
    pub(crate) fn bump(&mut self) -> GreenElement {
        let token = self.peek().expect("bump past the end");
        let start = self.pos;
        let text = &self.text[start..start + token.len];
        self.pos += token.len;
        match token.kind {
            NEWLINE => self.end = read_end(self.text, self.pos, self.region_end),
            UNREAD => self.report(
                E::LineTooLong,
                start..self.pos,
                format!("line longer than {MAX_READ_LINE} bytes; ncc reads only its first {MAX_READ_LINE} bytes"),
            ),
            kind => {
                if let Some((error, len, message)) = L::unclosed(kind, text) {
                    self.report(error, start..start + len, message);
                }
            }
        }
        self.green.shared_token(token.kind, text)
    }

    /// An empty list for a block's children, with the capacity the last
    /// block's had: most blocks need no allocation of their own.
    pub(crate) fn take_block_children(&mut self) -> Vec<GreenElement> {
        std::mem::take(&mut self.block_children)
    }

    /// The `BLOCK` node of `children` (from [`Self::take_block_children`]).
    pub(crate) fn block_node(&mut self, mut children: Vec<GreenElement>) -> GreenNode {
        let block = green::node(BLOCK, children.drain(..));
        self.block_children = children;
        block
    }

    /// A lone space or a line feed, the commonest tokens, consumed without
    /// lexing: the element `bump` gives for them. `None`, reading nothing,
    /// for anything else.
    pub(crate) fn plain_trivia(&mut self) -> Option<GreenElement> {
        let bytes = &self.text.as_bytes()[..self.end];
        match bytes.get(self.pos)? {
            b' ' if !matches!(bytes.get(self.pos + 1), Some(b' ' | b'\t')) => {
                self.pos += 1;
                Some(self.green.space())
            }
            b'\n' => {
                self.pos += 1;
                self.end = read_end(self.text, self.pos, self.region_end);
                Some(self.green.newline())
            }
            _ => None,
        }
    }

    /// The common word, served from the word cache: an upper-case letter,
    /// an optional sign and a number with a digit, and no byte of `glued`
    /// right after it that would make it something else (a second point,
    /// an `=`, an exponent); `None`, reading nothing, for any other text.
    pub(crate) fn simple_word(&mut self, glued: &[u8]) -> Option<GreenElement> {
        let bytes = &self.text.as_bytes()[..self.end];
        let start = self.pos;
        let sign_len = usize::from(matches!(bytes.get(start + 1), Some(b'-' | b'+')));
        let number_start = start + 1 + sign_len;
        let len = number_len(&bytes[number_start..]);
        let end = number_start + len;
        let has_digit = bytes[number_start..end].iter().any(u8::is_ascii_digit);
        if !bytes[start].is_ascii_uppercase() || !has_digit || bytes.get(end).is_some_and(|b| glued.contains(b)) {
            return None;
        }
        self.pos = end;
        Some(self.green.simple_word(&self.text[start..end], sign_len))
    }

    /// Consumes whitespace and comments into `children`.
    pub(crate) fn trivia(&mut self, children: &mut Vec<GreenElement>) {
        while let Some(WHITESPACE | COMMENT) = self.kind_at(self.pos) {
            children.push(self.bump());
        }
    }

    /// Consumes the next token as an `ERROR` node, reported as `kind`.
    pub(crate) fn error_node(&mut self, kind: E, message: impl Into<String>) -> GreenElement {
        let start = self.pos;
        let element = self.bump();
        self.report(kind, start..self.pos, message);
        NodeOrToken::Node(green::node(ERROR, [element]))
    }
}

/// A dialect's parser reads expressions through its cursor.
impl<'a, L: Lexer, P: DerefMut<Target = LineCursor<'a, L>>> ExprInput<'a> for P {
    fn text(&self) -> &'a str {
        self.deref().text
    }

    fn pos(&self) -> usize {
        self.deref().pos
    }

    fn significant_at(&self, mut from: usize) -> Option<Ahead> {
        loop {
            let token = self.deref().token_at(from)?;
            match token.kind {
                WHITESPACE | COMMENT => from += token.len,
                NEWLINE | UNREAD => return None,
                kind => return Some(Ahead { kind, range: (from, from + token.len) }),
            }
        }
    }

    fn token_kind_at(&self, pos: usize) -> Option<SyntaxKind> {
        self.deref().kind_at(pos)
    }

    fn bump(&mut self) -> GreenElement {
        self.deref_mut().bump()
    }

    fn bump_trivia(&mut self, into: &mut Vec<GreenElement>) {
        self.deref_mut().trivia(into);
    }

    fn error(&mut self, kind: E, range: Range<usize>, message: String) {
        self.deref_mut().report(kind, range, message);
    }
}
