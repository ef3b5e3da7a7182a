//! The Sinumerik lexer: turns text into tokens on demand.
//!
//! Lexing is stateless, as in the other dialects: the token at a position
//! depends only on the text from that position on, and no token spans a
//! line break, so the parser can restart at any line.
//!
//! Where names end and addresses begin (seed 004:1444-1450: a name's first
//! two characters are letters; `_FINISH` (004:3995) shows that `_` may
//! start one):
//!
//! * A letter followed by a letter or `_`, or `_` itself, starts a name:
//!   the run of letters, digits and `_` is one `IDENT` (`GOTOF`, `CYCLE800`,
//!   `CUT3DC`, `_N_MAIN_MPF`, `OTOL`, `var_i`).
//! * Any other letter is one `LETTER`, an address: `X10` is `X` `10`,
//!   `G641` is `G` `641`, `A3=1` is `A` `3` `=` `1` (the parser makes an
//!   address with an extension of it), and `X10Y20` is two words.
//! * `$` with a name after it is one `IDENT`: a system variable `$P_UIFR`,
//!   or with `$$` machine data read in the main run (`$$MA_…`, as the
//!   control's own files write them).
//!
//! Case does not matter to names (004:1450), so letters of either case lex
//! alike; the parser compares keywords ignoring case.
//!
//! `(` never starts a comment (digest §1.4); only `;` does, to the end of
//! the line. Strings `"…"` and quoted constants `'H1F'` end at their
//! closing quote or at the end of the line.

use crate::{
    SyntaxKind::*,
    lexing::{Token, number_len, run_len},
};

/// Lexes the token starting at `pos` (which must be `< text.len()`).
pub(crate) fn token_at(text: &str, pos: usize) -> Token {
    let bytes = text.as_bytes();
    let rest = &bytes[pos..];
    let next = rest.get(1).copied();
    let (kind, len) = match rest[0] {
        b' ' | b'\t' => (WHITESPACE, run_len(rest, |b| b == b' ' || b == b'\t')),
        b'\n' => (NEWLINE, 1),
        b'\r' => (NEWLINE, if next == Some(b'\n') { 2 } else { 1 }),
        b';' => (COMMENT, line_len(rest)),
        b'"' | b'\'' => (STRING, quoted_len(rest)),
        b'_' => (IDENT, name_len(rest)),
        b'A'..=b'Z' | b'a'..=b'z' if next.is_some_and(|b| b.is_ascii_alphabetic() || b == b'_') => {
            (IDENT, name_len(rest))
        }
        b'A'..=b'Z' | b'a'..=b'z' => (LETTER, 1),
        b'$' => match system_variable_len(rest) {
            0 => (ERROR_TOKEN, crate::lexing::unknown_run_len(text, pos, KNOWN)),
            len => (IDENT, len),
        },
        // A run of points is one placeholder (`X..`, `...`), which the
        // parser reports once.
        b'.' if next == Some(b'.') => (NUMBER, run_len(rest, |b| b == b'.')),
        b'0'..=b'9' | b'.' => (NUMBER, number_with_exponent_len(rest)),
        b'+' => (PLUS, 1),
        b'-' => (MINUS, 1),
        b'*' => (STAR, 1),
        b'/' => (SLASH, 1),
        b'=' if next == Some(b'=') => (EQ_EQ, 2),
        b'=' => (EQ, 1),
        b'<' => match next {
            Some(b'<') => (CONCAT, 2),
            Some(b'=') => (LT_EQ, 2),
            Some(b'>') => (NEQ, 2),
            _ => (LT, 1),
        },
        b'>' if next == Some(b'=') => (GT_EQ, 2),
        b'>' => (GT, 1),
        b'(' => (L_PAREN, 1),
        b')' => (R_PAREN, 1),
        b'[' => (L_BRACK, 1),
        b']' => (R_BRACK, 1),
        b',' => (COMMA, 1),
        b':' => (COLON, 1),
        b'%' => (PERCENT, 1),
        _ => (ERROR_TOKEN, crate::lexing::unknown_run_len(text, pos, KNOWN)),
    };
    Token { kind, len }
}

/// `$NAME`, or `$$NAME` (machine data read in the main run); 0 when no
/// name follows.
fn system_variable_len(rest: &[u8]) -> usize {
    let dollars = if rest.get(1) == Some(&b'$') { 2 } else { 1 };
    match rest.get(dollars) {
        Some(b) if b.is_ascii_alphabetic() || *b == b'_' => dollars + name_len(&rest[dollars..]),
        _ => 0,
    }
}

fn name_len(rest: &[u8]) -> usize {
    run_len(rest, |b| b.is_ascii_alphanumeric() || b == b'_')
}

/// To the end of the line, its break excluded.
fn line_len(rest: &[u8]) -> usize {
    memchr::memchr2(b'\n', b'\r', rest).unwrap_or(rest.len())
}

/// The opening quote to the same closing quote, or to the end of the line.
fn quoted_len(rest: &[u8]) -> usize {
    let line = line_len(rest);
    match memchr::memchr(rest[0], &rest[1..line]) {
        Some(close) => close + 2,
        None => line,
    }
}

/// A number, with the exponent `EX` of Sinumerik's notation for very
/// large and small values (`1.5EX-3`) when digits follow it.
fn number_with_exponent_len(rest: &[u8]) -> usize {
    let len = number_len(rest);
    let after = &rest[len..];
    if after.len() >= 3 && after[..2].eq_ignore_ascii_case(b"EX") {
        let sign = usize::from(matches!(after[2], b'+' | b'-'));
        let digits = run_len(&after[2 + sign..], |b| b.is_ascii_digit());
        if digits > 0 && len > 0 && rest[..len].iter().any(u8::is_ascii_digit) {
            return len + 2 + sign + digits;
        }
    }
    len
}

/// What ends a run of characters the language does not know, besides
/// letters and digits.
const KNOWN: &str = " \t\n\r;\"'+-*/=<>()[],:%._$";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SyntaxKind;

    fn lex_all(text: &str) -> Vec<(SyntaxKind, &str)> {
        crate::lexing::lex_all(text, token_at)
    }

    #[test]
    fn names_start_with_two_letters_or_an_underscore() {
        assert_eq!(
            lex_all("X10Y-2 A3=CR _N_A_MPF CUT3DC"),
            vec![
                (LETTER, "X"),
                (NUMBER, "10"),
                (LETTER, "Y"),
                (MINUS, "-"),
                (NUMBER, "2"),
                (WHITESPACE, " "),
                (LETTER, "A"),
                (NUMBER, "3"),
                (EQ, "="),
                (IDENT, "CR"),
                (WHITESPACE, " "),
                (IDENT, "_N_A_MPF"),
                (WHITESPACE, " "),
                (IDENT, "CUT3DC"),
            ]
        );
    }

    #[test]
    fn operators_take_their_longest_form() {
        let operators: Vec<_> =
            lex_all("<< <= <> < >= > == = <<=").into_iter().filter(|(kind, _)| *kind != WHITESPACE).collect();
        assert_eq!(
            operators,
            vec![
                (CONCAT, "<<"),
                (LT_EQ, "<="),
                (NEQ, "<>"),
                (LT, "<"),
                (GT_EQ, ">="),
                (GT, ">"),
                (EQ_EQ, "=="),
                (EQ, "="),
                (CONCAT, "<<"),
                (EQ, "=")
            ]
        );
    }

    #[test]
    fn strings_and_comments_end_at_the_line() {
        assert_eq!(
            lex_all("\"a;b\"\"c\n;x\"y\r\n$P_F'H1"),
            vec![
                (STRING, "\"a;b\""),
                (STRING, "\"c"),
                (NEWLINE, "\n"),
                (COMMENT, ";x\"y"),
                (NEWLINE, "\r\n"),
                (IDENT, "$P_F"),
                (STRING, "'H1"),
            ]
        );
    }

    #[test]
    fn exponents_need_digits() {
        assert_eq!(lex_all("1.5EX-3"), vec![(NUMBER, "1.5EX-3")]);
        assert_eq!(lex_all("1EXIT"), vec![(NUMBER, "1"), (IDENT, "EXIT")]);
    }

    #[test]
    fn unknown_characters_group_until_a_known_token() {
        assert_eq!(lex_all("€#X"), vec![(ERROR_TOKEN, "€#"), (LETTER, "X")]);
        assert_eq!(
            lex_all("$ $$1 $$A"),
            vec![
                (ERROR_TOKEN, "$"),
                (WHITESPACE, " "),
                (ERROR_TOKEN, "$"),
                (ERROR_TOKEN, "$"),
                (NUMBER, "1"),
                (WHITESPACE, " "),
                (IDENT, "$$A")
            ]
        );
    }
}
