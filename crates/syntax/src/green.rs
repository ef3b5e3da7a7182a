//! Building green trees fast.
//!
//! A CAM program repeats the same few tokens millions of times. Tokens whose
//! text is fixed (address letters, one space, line breaks, signs) are built
//! once per parser and shared; whole words are shared through a cache keyed
//! by their text, because a word's subtree is a function of its text. Green
//! nodes are immutable and reference counted, so sharing is invisible to
//! every user of the tree. Each parser (and so each thread of a parallel
//! parse) has its own set: threads never contend for one reference count.

use std::borrow::Cow;

use rowan::{GreenNode, GreenNodeData, GreenToken, NodeOrToken};
use rustc_hash::FxHashMap;

use crate::SyntaxKind::{self, *};

pub(crate) type GreenElement = NodeOrToken<GreenNode, GreenToken>;

pub(crate) fn node(
    kind: SyntaxKind,
    children: impl IntoIterator<Item = GreenElement, IntoIter: ExactSizeIterator>,
) -> GreenNode {
    GreenNode::new(kind.into(), children)
}

pub(crate) struct GreenFactory<'a> {
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
    /// Simple words of up to eight bytes, keyed by their bytes packed into
    /// an integer: hashing and comparing them is a multiply and a compare.
    short_words: FxHashMap<u64, GreenNode>,
    /// Keyed by the text parsed, or by a copy for a word of another tree.
    long_words: FxHashMap<Cow<'a, str>, GreenNode>,
    /// Other tokens of up to eight bytes by kind, length (any byte, zero
    /// too, may be in them) and packed bytes: the names, numbers and
    /// operators of expressions recur all over a program, and a shared
    /// token saves an allocation each time.
    short_tokens: FxHashMap<(rowan::SyntaxKind, usize, u64), GreenToken>,
}

impl<'a> GreenFactory<'a> {
    pub(crate) fn new() -> Self {
        let new = |kind: SyntaxKind, text: &str| GreenToken::new(kind.into(), text);
        let letters =
            (b'A'..=b'Z').chain(b'a'..=b'z').map(|b| new(LETTER, std::str::from_utf8(&[b]).expect("ASCII"))).collect();
        GreenFactory {
            letters,
            space: new(WHITESPACE, " "),
            lf: new(NEWLINE, "\n"),
            crlf: new(NEWLINE, "\r\n"),
            plus: new(PLUS, "+"),
            minus: new(MINUS, "-"),
            eq: new(EQ, "="),
            amp: new(AMP, "&"),
            slash: new(SLASH, "/"),
            percent: new(PERCENT, "%"),
            star: new(STAR, "*"),
            short_words: FxHashMap::default(),
            long_words: FxHashMap::default(),
            short_tokens: FxHashMap::default(),
        }
    }

    /// A green token for `text`, shared when its text is one of the fixed ones.
    pub(crate) fn token(&self, kind: SyntaxKind, text: &str) -> GreenElement {
        self.fixed_token(kind, text).unwrap_or_else(|| NodeOrToken::Token(GreenToken::new(kind.into(), text)))
    }

    /// Like [`Self::token`], but a token of up to eight bytes is shared with
    /// every other of its kind and text.
    pub(crate) fn shared_token(&mut self, kind: SyntaxKind, text: &str) -> GreenElement {
        if let Some(fixed) = self.fixed_token(kind, text) {
            return fixed;
        }
        let Some(key) = short_key(text) else { return NodeOrToken::Token(GreenToken::new(kind.into(), text)) };
        let shared = self
            .short_tokens
            .entry((kind.into(), text.len(), key))
            .or_insert_with(|| GreenToken::new(kind.into(), text));
        NodeOrToken::Token(shared.clone())
    }

    /// The shared token of `kind` and `text` when its text is a fixed one.
    fn fixed_token(&self, kind: SyntaxKind, text: &str) -> Option<GreenElement> {
        let shared = match (kind, text.as_bytes()) {
            (LETTER, [letter]) => return Some(self.letter(*letter)),
            (WHITESPACE, b" ") => &self.space,
            (NEWLINE, b"\n") => &self.lf,
            (NEWLINE, b"\r\n") => &self.crlf,
            (PLUS, b"+") => &self.plus,
            (MINUS, b"-") => &self.minus,
            (EQ, _) => &self.eq,
            (AMP, _) => &self.amp,
            (SLASH, _) => &self.slash,
            (PERCENT, _) => &self.percent,
            (STAR, _) => &self.star,
            _ => return None,
        };
        Some(NodeOrToken::Token(shared.clone()))
    }

    pub(crate) fn space(&self) -> GreenElement {
        NodeOrToken::Token(self.space.clone())
    }

    pub(crate) fn newline(&self) -> GreenElement {
        NodeOrToken::Token(self.lf.clone())
    }

    /// The token of an ASCII letter.
    pub(crate) fn letter(&self, letter: u8) -> GreenElement {
        let index = match letter {
            b'A'..=b'Z' => usize::from(letter - b'A'),
            _ => 26 + usize::from(letter.to_ascii_lowercase() - b'a'),
        };
        NodeOrToken::Token(self.letters[index].clone())
    }

    /// The `WORD` node of `text` = upper-case letter, optional sign of
    /// `sign_len` bytes, number.
    pub(crate) fn simple_word(&mut self, text: &'a str, sign_len: usize) -> GreenElement {
        let word = if let Some(key) = short_key(text) {
            match self.short_words.get(&key) {
                Some(word) => word.clone(),
                None => {
                    let word = self.build_simple_word(text, sign_len);
                    self.short_words.insert(key, word.clone());
                    word
                }
            }
        } else {
            match self.long_words.get(text) {
                Some(word) => word.clone(),
                None => {
                    let word = self.build_simple_word(text, sign_len);
                    self.long_words.insert(Cow::Borrowed(text), word.clone());
                    word
                }
            }
        };
        NodeOrToken::Node(word)
    }

    /// Shares the simple words of `tree` (a block of the tree a reparse
    /// replaces) with the nodes built from now on. A reparsed block would
    /// otherwise get its own copy of every word, which a full parse shares
    /// with the other blocks: over a long session the tree would grow
    /// towards a copy per block.
    pub(crate) fn share_words_of(&mut self, tree: &GreenNodeData) {
        for child in tree.children() {
            let NodeOrToken::Node(node) = child else { continue };
            if node.kind() != WORD.into() {
                self.share_words_of(node);
                continue;
            }
            let Some(text) = simple_word_text(node) else { continue };
            match short_key(&text) {
                Some(key) => self.short_words.entry(key).or_insert_with(|| node.to_owned()),
                None => self.long_words.entry(Cow::Owned(text)).or_insert_with(|| node.to_owned()),
            };
        }
    }

    fn build_simple_word(&self, text: &str, sign_len: usize) -> GreenNode {
        let (letter, rest) = text.split_at(1);
        let (sign, number) = rest.split_at(sign_len);
        let letter = self.letter(letter.as_bytes()[0]);
        let number = self.token(NUMBER, number);
        match sign {
            "" => node(WORD, [letter, number]),
            sign => {
                let kind = if sign == "+" { PLUS } else { MINUS };
                node(WORD, [letter, self.token(kind, sign), number])
            }
        }
    }
}

/// The key of a simple word of up to eight bytes: its bytes packed into an
/// integer (simple words hold no zero byte, so the padding cannot collide).
fn short_key(text: &str) -> Option<u64> {
    let mut key = [0u8; 8];
    key.get_mut(..text.len())?.copy_from_slice(text.as_bytes());
    Some(u64::from_le_bytes(key))
}

/// The text of `word` when it is a simple word as [`GreenFactory::simple_word`]
/// builds it: an upper-case letter, an optional sign, a number.
fn simple_word_text(word: &GreenNodeData) -> Option<String> {
    let mut tokens = word.children().map(NodeOrToken::into_token);
    let letter = tokens.next()??;
    let mut next = tokens.next()??;
    let sign = if next.kind() == PLUS.into() || next.kind() == MINUS.into() {
        let sign = next;
        next = tokens.next()??;
        Some(sign)
    } else {
        None
    };
    let simple = letter.kind() == LETTER.into()
        && letter.text().bytes().all(|b| b.is_ascii_uppercase())
        && next.kind() == NUMBER.into()
        && tokens.next().is_none();
    simple.then(|| [Some(letter), sign, Some(next)].into_iter().flatten().map(|token| token.text()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_tokens_are_those_of_their_kind_and_text() {
        let mut green = GreenFactory::new();
        let text = |element: GreenElement| element.into_token().unwrap().text().to_owned();
        let address = |element: &GreenElement| std::ptr::from_ref::<rowan::GreenTokenData>(element.as_token().unwrap());
        let first = green.shared_token(IDENT, "DEPTH");
        assert_eq!(address(&first), address(&green.shared_token(IDENT, "DEPTH")));
        assert_ne!(first, green.shared_token(NUMBER, "DEPTH"));
        // Zero bytes pad the key: the length tells `A` from `A\0`.
        assert_eq!(text(green.shared_token(ERROR_TOKEN, "A\0")), "A\0");
        assert_eq!(text(green.shared_token(ERROR_TOKEN, "A")), "A");
        assert_eq!(text(green.shared_token(STRING, "\"LONGER TEXT\"")), "\"LONGER TEXT\"");
    }
}
