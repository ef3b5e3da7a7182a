//! The CNC8x6 lexer: turns text into tokens on demand.
//!
//! Lexing is stateless: the token at a position depends only on the text from
//! that position on, so the parser can look ahead by lexing further and the
//! incremental reparser can restart at any block boundary. The two regions
//! the control treats specially (before `%` and after `*`) are cut out by the
//! parser, not here.

pub(crate) use crate::lexing::Token;
use crate::{
    SyntaxKind::*,
    lexing::{number_len, run_len},
};

/// Quotes that word processors put in place of `"`; accepted with a warning.
pub(crate) const TYPOGRAPHIC_QUOTES: [&str; 3] = ["\u{201C}", "\u{201D}", "\u{201E}"];
/// Dashes that printed manuals use in place of `-`; accepted with a warning.
pub(crate) const TYPOGRAPHIC_MINUSES: [&str; 2] = ["\u{2212}", "\u{2013}"];

/// Lexes the token starting at `pos` (which must be `< text.len()`).
pub(crate) fn token_at(text: &str, pos: usize) -> Token {
    let bytes = text.as_bytes();
    let byte = bytes[pos];
    let (kind, len) = match byte {
        b' ' | b'\t' => (WHITESPACE, run_len(&bytes[pos..], |b| b == b' ' || b == b'\t')),
        b'\n' => (NEWLINE, 1),
        b'\r' => (NEWLINE, if bytes.get(pos + 1) == Some(&b'\n') { 2 } else { 1 }),
        b'"' => (COMMENT, comment_len(text, pos, 1, false)),
        b'A'..=b'Z' | b'a'..=b'z' => (LETTER, 1),
        b'0'..=b'9' | b'.' => (NUMBER, number_len(&bytes[pos..])),
        b'+' => (PLUS, 1),
        b'-' => (MINUS, 1),
        b'&' => (AMP, 1),
        b'=' => (EQ, 1),
        b'/' => (SLASH, 1),
        b'%' => (PERCENT, 1),
        b'*' => (STAR, 1),
        _ => match typographic_at(text, pos) {
            Some(Typographic::Quote) => (COMMENT, comment_len(text, pos, 3, true)),
            Some(Typographic::Minus) => (MINUS, 3),
            None => (ERROR_TOKEN, unknown_run_len(text, pos)),
        },
    };
    Token { kind, len }
}

enum Typographic {
    Quote,
    Minus,
}

fn typographic_at(text: &str, pos: usize) -> Option<Typographic> {
    let rest = &text.as_bytes()[pos..];
    if rest.first() != Some(&0xE2) {
        return None;
    }
    let starts = |candidates: &[&str]| candidates.iter().any(|c| rest.starts_with(c.as_bytes()));
    if starts(&TYPOGRAPHIC_QUOTES) {
        Some(Typographic::Quote)
    } else if starts(&TYPOGRAPHIC_MINUSES) {
        Some(Typographic::Minus)
    } else {
        None
    }
}

/// A comment runs to its closing quote (included) or to the end of the line
/// (excluded). One opened by `"` closes only at `"`; one opened by a
/// typographic quote closes at any quote, straight or typographic.
fn comment_len(text: &str, pos: usize, open_len: usize, typographic: bool) -> usize {
    let bytes = text.as_bytes();
    let mut i = pos + open_len;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => return i + 1 - pos,
            b'\n' | b'\r' => return i - pos,
            0xE2 if typographic && matches!(typographic_at(text, i), Some(Typographic::Quote)) => {
                return i + 3 - pos;
            }
            _ => i += 1,
        }
    }
    i - pos
}

/// Characters the language does not know are grouped so that one stray
/// word of foreign text yields one diagnostic.
fn unknown_run_len(text: &str, pos: usize) -> usize {
    let mut end = pos;
    for (offset, ch) in text[pos..].char_indices() {
        let at = pos + offset;
        if at > pos && starts_known_token(text, at, ch) {
            break;
        }
        end = at + ch.len_utf8();
    }
    end - pos
}

fn starts_known_token(text: &str, pos: usize, ch: char) -> bool {
    match ch {
        ' ' | '\t' | '\n' | '\r' | '"' | '+' | '-' | '&' | '=' | '/' | '%' | '*' | '.' => true,
        c if c.is_ascii_alphanumeric() => true,
        _ => typographic_at(text, pos).is_some(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SyntaxKind;

    fn lex_all(text: &str) -> Vec<(SyntaxKind, &str)> {
        crate::lexing::lex_all(text, token_at)
    }

    #[test]
    fn numbers_keep_one_decimal_point() {
        assert_eq!(lex_all("1.2.3"), vec![(NUMBER, "1.2"), (NUMBER, ".3")]);
        assert_eq!(lex_all("384."), vec![(NUMBER, "384.")]);
        assert_eq!(lex_all("."), vec![(NUMBER, ".")]);
    }

    #[test]
    fn comments_end_at_line_end_or_quote() {
        assert_eq!(
            lex_all("\"a\" \"b\r\n"),
            vec![(COMMENT, "\"a\""), (WHITESPACE, " "), (COMMENT, "\"b"), (NEWLINE, "\r\n")]
        );
        assert_eq!(lex_all("\u{201C}ab\u{201D}x"), vec![(COMMENT, "\u{201C}ab\u{201D}"), (LETTER, "x")]);
        assert_eq!(lex_all("\"a\u{201D}b\""), vec![(COMMENT, "\"a\u{201D}b\"")]);
    }

    #[test]
    fn unknown_characters_group_until_a_known_token() {
        assert_eq!(lex_all("#€,X"), vec![(ERROR_TOKEN, "#€,"), (LETTER, "X")]);
        assert_eq!(lex_all("Č\u{2212}1"), vec![(ERROR_TOKEN, "Č"), (MINUS, "\u{2212}"), (NUMBER, "1")]);
    }
}
