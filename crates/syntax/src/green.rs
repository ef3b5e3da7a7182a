//! Building green trees fast.
//!
//! A CAM program repeats the same few tokens millions of times. Tokens whose
//! text is fixed (address letters, one space, line breaks, signs) are built
//! once per process and shared; whole words are shared through a per-parse
//! cache keyed by their text, because a word's subtree is a function of its
//! text. Green nodes are immutable and reference counted, so sharing is
//! invisible to every user of the tree.

use std::sync::OnceLock;

use rowan::{GreenNode, GreenToken, NodeOrToken};
use rustc_hash::FxHashMap;

use crate::SyntaxKind::{self, *};

pub(crate) type GreenElement = NodeOrToken<GreenNode, GreenToken>;

struct SharedTokens {
    /// `A`–`Z` then `a`–`z`.
    letters: Vec<GreenToken>,
    space: GreenToken,
    lf: GreenToken,
    crlf: GreenToken,
    plus: GreenToken,
    minus: GreenToken,
    eq: GreenToken,
    amp: GreenToken,
    slash: GreenToken,
    percent: GreenToken,
    star: GreenToken,
}

fn shared() -> &'static SharedTokens {
    static SHARED: OnceLock<SharedTokens> = OnceLock::new();
    SHARED.get_or_init(|| {
        let letters = (b'A'..=b'Z')
            .chain(b'a'..=b'z')
            .map(|b| GreenToken::new(LETTER.into(), std::str::from_utf8(&[b]).unwrap()))
            .collect();
        let token = |kind: SyntaxKind, text: &str| GreenToken::new(kind.into(), text);
        SharedTokens {
            letters,
            space: token(WHITESPACE, " "),
            lf: token(NEWLINE, "\n"),
            crlf: token(NEWLINE, "\r\n"),
            plus: token(PLUS, "+"),
            minus: token(MINUS, "-"),
            eq: token(EQ, "="),
            amp: token(AMP, "&"),
            slash: token(SLASH, "/"),
            percent: token(PERCENT, "%"),
            star: token(STAR, "*"),
        }
    })
}

/// A green token for `text`, shared when its text is one of the fixed ones.
pub(crate) fn token(kind: SyntaxKind, text: &str) -> GreenToken {
    let shared = shared();
    let hit = match (kind, text.as_bytes()) {
        (LETTER, [b @ b'A'..=b'Z']) => Some(&shared.letters[usize::from(b - b'A')]),
        (LETTER, [b @ b'a'..=b'z']) => Some(&shared.letters[26 + usize::from(b - b'a')]),
        (WHITESPACE, b" ") => Some(&shared.space),
        (NEWLINE, b"\n") => Some(&shared.lf),
        (NEWLINE, b"\r\n") => Some(&shared.crlf),
        (PLUS, b"+") => Some(&shared.plus),
        (MINUS, b"-") => Some(&shared.minus),
        (EQ, _) => Some(&shared.eq),
        (AMP, _) => Some(&shared.amp),
        (SLASH, _) => Some(&shared.slash),
        (PERCENT, _) => Some(&shared.percent),
        (STAR, _) => Some(&shared.star),
        _ => None,
    };
    match hit {
        Some(token) => token.clone(),
        None => GreenToken::new(kind.into(), text),
    }
}

pub(crate) fn node(kind: SyntaxKind, children: impl IntoIterator<Item = GreenElement, IntoIter: ExactSizeIterator>) -> GreenNode {
    GreenNode::new(kind.into(), children)
}

/// Deduplicates simple words (`X12.5`, `G01`, `Z-1.018`) by their text.
#[derive(Default)]
pub(crate) struct WordCache<'a> {
    words: FxHashMap<&'a str, GreenNode>,
}

impl<'a> WordCache<'a> {
    /// The `WORD` node for `text` = letter, optional sign, number.
    pub(crate) fn simple_word(&mut self, text: &'a str, sign_len: usize) -> GreenNode {
        if let Some(node) = self.words.get(text) {
            return node.clone();
        }
        let (letter, rest) = text.split_at(1);
        let (sign, number) = rest.split_at(sign_len);
        let letter = NodeOrToken::Token(token(LETTER, letter));
        let number = NodeOrToken::Token(token(NUMBER, number));
        let word = match sign {
            "" => node(WORD, [letter, number]),
            sign => {
                let kind = if sign == "+" { PLUS } else { MINUS };
                node(WORD, [letter, NodeOrToken::Token(token(kind, sign)), number])
            }
        };
        self.words.insert(text, word.clone());
        word
    }
}
