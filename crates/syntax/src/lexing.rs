//! What the lexers and parsers of all dialects share: tokens, numbers and
//! lines.

use std::ops::Range;

use rowan::{TextRange, TextSize};

use crate::SyntaxKind;

/// A byte range of the text as a `TextRange`.
pub(crate) fn range(r: Range<usize>) -> TextRange {
    TextRange::new(TextSize::from(r.start as u32), TextSize::from(r.end as u32))
}

/// A token: its kind and its length in bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Token {
    pub(crate) kind: SyntaxKind,
    pub(crate) len: usize,
}

pub(crate) fn run_len(bytes: &[u8], pred: impl Fn(u8) -> bool) -> usize {
    bytes.iter().position(|&b| !pred(b)).unwrap_or(bytes.len())
}

/// `[0-9]* ('.' [0-9]*)?`: digits with at most one decimal point.
pub(crate) fn number_len(bytes: &[u8]) -> usize {
    let int = run_len(bytes, |b| b.is_ascii_digit());
    if bytes.get(int) == Some(&b'.') { int + 1 + run_len(&bytes[int + 1..], |b| b.is_ascii_digit()) } else { int }
}

/// How many bytes of a line ncc reads; the rest is one `UNREAD` token.
/// Far beyond any control's line length, so nothing a person or a CAM
/// system writes is cut, but bounded: a line of megabytes of random text
/// would otherwise become millions of words, each a node of the tree.
pub const MAX_READ_LINE: usize = 1024;

/// Where the read part of the line that starts at `line_start` ends (it
/// may end earlier, at its line break), at most `limit`.
pub(crate) fn read_end(text: &str, line_start: usize, limit: usize) -> usize {
    let mut end = line_start + MAX_READ_LINE;
    while end < limit && !text.is_char_boundary(end) {
        end += 1;
    }
    end.min(limit)
}

/// Where the line holding `at` starts.
pub(crate) fn line_start(text: &str, at: usize) -> usize {
    memchr::memrchr2(b'\n', b'\r', &text.as_bytes()[..at]).map_or(0, |i| i + 1)
}

/// Where the line holding `at` ends (before its line break), at most `limit`.
pub(crate) fn line_end(text: &str, at: usize, limit: usize) -> usize {
    memchr::memchr2(b'\n', b'\r', &text.as_bytes()[at..limit]).map_or(limit, |i| at + i)
}

/// Length of a run of three or more letters at the start of `bytes` none of
/// which has a value, like `MSG` or `roughing`: foreign text, which the
/// parsers report once rather than letter by letter. The run stops before a
/// letter `stops_before` names; `value_after(len)` tells whether a value
/// follows the run's first `len` bytes (then its last letter is a word).
pub(crate) fn foreign_text_len(
    bytes: &[u8],
    stops_before: impl Fn(u8) -> bool,
    value_after: impl Fn(usize) -> bool,
) -> usize {
    let run = bytes.iter().take_while(|&&b| b.is_ascii_alphabetic() && !stops_before(b)).count();
    let last_has_value = run > 0 && value_after(run);
    let text_len = run - usize::from(last_has_value);
    if text_len >= 3 { text_len } else { 0 }
}

/// The token `lex` finds at `pos`, bounded by the line's read part (up to
/// `read_end`) and the region (up to `region_end`): past the read part the
/// rest of the line is one `UNREAD` token, and a line break is whole even
/// where reading the line stops at it.
pub(crate) fn bounded_token(
    text: &str,
    pos: usize,
    read_end: usize,
    region_end: usize,
    lex: impl Fn(&str, usize) -> Token,
) -> Option<Token> {
    if pos >= region_end {
        return None;
    }
    if pos >= read_end {
        let unread = line_end(text, pos, region_end) - pos;
        if unread > 0 {
            return Some(Token { kind: SyntaxKind::UNREAD, len: unread });
        }
    }
    let token = lex(text, pos);
    let end = if token.kind == SyntaxKind::NEWLINE { region_end } else { read_end };
    Some(Token { kind: token.kind, len: token.len.min(end - pos) })
}

/// The length of the run of characters the language does not know at
/// `pos`, up to a letter, a digit or a character of `known`: one stray
/// word of foreign text yields one diagnostic.
pub(crate) fn unknown_run_len(text: &str, pos: usize, known: &str) -> usize {
    let mut end = pos;
    for (offset, ch) in text[pos..].char_indices() {
        if offset > 0 && (ch.is_ascii_alphanumeric() || known.contains(ch)) {
            break;
        }
        end = pos + offset + ch.len_utf8();
    }
    end - pos
}

/// Every token `lex` finds in `text`, with its text: for the lexers' tests.
#[cfg(test)]
pub(crate) fn lex_all(text: &str, lex: fn(&str, usize) -> Token) -> Vec<(SyntaxKind, &str)> {
    let mut pos = 0;
    let mut out = Vec::new();
    while pos < text.len() {
        let token = lex(text, pos);
        assert!(token.len > 0);
        out.push((token.kind, &text[pos..pos + token.len]));
        pos += token.len;
    }
    out
}
