//! What the lexers and parsers of all dialects share: tokens, numbers and
//! lines.

use crate::SyntaxKind;

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
