//! The Haas lathe lexer: turns text into tokens on demand.
//!
//! Lexing is stateless, as in CNC8x6: the token at a position depends only
//! on the text from that position on, and no token spans a line break, so
//! the parser can restart at any line.
//!
//! Letters: at an upper-case letter, the longest keyword (statement word,
//! operator or function name, see [`keywords`]) that the text starts with
//! is one `IDENT` token; without one, the letter alone is a `LETTER` (an
//! address). So `GOTO5` is `GOTO` `5` but `G05` is `G` `05`, `DO1` is `DO`
//! `1` but `D0` is `D` `0`, `EQ` is one token but `E1.` is `E` `1.`, and
//! `SINX` is `SIN` `X`. Keywords are upper-case only: a lower-case letter is
//! always an address (reported by the parser).

use std::sync::OnceLock;

use crate::{
    SyntaxKind::*,
    lexing::{Token, number_len, run_len},
};

/// The words of the statements, each with the form it belongs to;
/// operators and functions come from the catalogue.
pub const STATEMENT_KEYWORDS: [(&str, &str); 6] = [
    ("IF", "IF [condition] GOTO n, or IF [condition] THEN #v = e"),
    ("THEN", "IF [condition] THEN #v = e"),
    ("GOTO", "GOTO n: go on at block Nn"),
    ("WHILE", "WHILE [condition] DOn … ENDn"),
    ("DO", "DOn … ENDn: loop n, while the condition of a WHILE before it holds"),
    ("END", "ENDn: the end of loop n"),
];

/// Every keyword, longest first.
pub(crate) fn keywords() -> &'static [String] {
    static KEYWORDS: OnceLock<Vec<String>> = OnceLock::new();
    KEYWORDS.get_or_init(|| {
        let operations = &ncc_catalog::Dialect::HaasLathe.catalogue().operations;
        let named = operations
            .iter()
            .filter_map(|operation| operation.symbol.clone())
            .filter(|symbol| symbol.len() >= 2 && symbol.bytes().all(|b| b.is_ascii_uppercase()));
        let mut keywords: Vec<String> = STATEMENT_KEYWORDS.iter().map(|(k, _)| (*k).to_owned()).chain(named).collect();
        keywords.sort_by(|a, b| b.len().cmp(&a.len()).then(a.cmp(b)));
        keywords.dedup();
        keywords
    })
}

/// Lexes the token starting at `pos` (which must be `< text.len()`).
pub(crate) fn token_at(text: &str, pos: usize) -> Token {
    let bytes = text.as_bytes();
    let (kind, len) = match bytes[pos] {
        b' ' | b'\t' => (WHITESPACE, run_len(&bytes[pos..], |b| b == b' ' || b == b'\t')),
        b'\n' => (NEWLINE, 1),
        b'\r' => (NEWLINE, if bytes.get(pos + 1) == Some(&b'\n') { 2 } else { 1 }),
        b'(' => (COMMENT, comment_len(bytes, pos, true)),
        b';' => (COMMENT, comment_len(bytes, pos, false)),
        b'A'..=b'Z' => match keyword_len(&bytes[pos..]) {
            0 => (LETTER, 1),
            len => (IDENT, len),
        },
        b'a'..=b'z' => (LETTER, 1),
        // A run of points is one placeholder (`X..`, `....`), which the
        // parser reports once.
        b'.' if bytes.get(pos + 1) == Some(&b'.') => (NUMBER, run_len(&bytes[pos..], |b| b == b'.')),
        b'0'..=b'9' | b'.' => (NUMBER, number_len(&bytes[pos..])),
        b'+' => (PLUS, 1),
        b'-' => (MINUS, 1),
        b'*' => (STAR, 1),
        b'/' => (SLASH, 1),
        b'=' => (EQ, 1),
        b'#' => (HASH, 1),
        b'[' => (L_BRACK, 1),
        b']' => (R_BRACK, 1),
        b',' => (COMMA, 1),
        b'%' => (PERCENT, 1),
        _ => (ERROR_TOKEN, crate::lexing::unknown_run_len(text, pos, KNOWN)),
    };
    Token { kind, len }
}

fn keyword_len(rest: &[u8]) -> usize {
    // Every keyword is two upper-case letters or more: an address followed
    // by anything else (`X12.`, `G01`) starts none, without a search.
    if !rest.get(1).is_some_and(u8::is_ascii_uppercase) {
        return 0;
    }
    keywords().iter().find(|keyword| rest.starts_with(keyword.as_bytes())).map_or(0, String::len)
}

/// `(` runs to its `)` (included) or to the end of the line; `;` to the end
/// of the line. Nothing inside is tokenised.
fn comment_len(bytes: &[u8], pos: usize, parenthesis: bool) -> usize {
    let rest = &bytes[pos + 1..];
    let line = memchr::memchr2(b'\n', b'\r', rest).unwrap_or(rest.len());
    match memchr::memchr(b')', &rest[..line]) {
        Some(close) if parenthesis => close + 2,
        _ => line + 1,
    }
}

/// What ends a run of characters the language does not know, besides
/// letters and digits.
const KNOWN: &str = " \t\n\r(;+-*/=#[],%.";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SyntaxKind;

    fn lex_all(text: &str) -> Vec<(SyntaxKind, &str)> {
        crate::lexing::lex_all(text, token_at)
    }

    #[test]
    fn keywords_include_the_catalogue_functions() {
        for keyword in ["GOTO", "WHILE", "SIN", "ATAN", "EQ", "MOD", "XOR", "FUP"] {
            assert!(keywords().iter().any(|k| k == keyword), "{keyword}");
        }
    }

    #[test]
    fn a_run_of_points_is_one_token() {
        assert_eq!(
            lex_all("X...Z.5."),
            vec![(LETTER, "X"), (NUMBER, "..."), (LETTER, "Z"), (NUMBER, ".5"), (NUMBER, ".")]
        );
    }

    #[test]
    fn unknown_characters_group_until_a_known_token() {
        assert_eq!(lex_all("€$X"), vec![(ERROR_TOKEN, "€$"), (LETTER, "X")]);
    }
}
