//! Blocks lowered to plain data: the words, codes and parameter assignments
//! of one block, with ranges relative to the block's start.
//!
//! Lowering depends only on the block's own text (its green node), so the
//! analysis re-lowers only the blocks an edit touched. The executor and the
//! analysis read programs through this one lowering.

use std::fmt;

use ncc_catalog::{AddressRole, Dialect};
use ncc_syntax::{Decimal, NcLanguage, Sign, SyntaxKind, TextRange, TextSize, ast};
use rowan::{GreenNodeData, NodeOrToken};

/// One block.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct BlockData {
    /// The block number, if the block has one.
    pub number: Option<Number>,
    /// The block holds `/`.
    pub skip: Vec<TextRange>,
    pub words: Vec<Word>,
    pub assignments: Vec<Assignment>,
    /// Comments with their range and whether they are closed.
    pub comments: Vec<Comment>,
    /// The block's length in bytes.
    pub len: TextSize,
    /// `/` immediately followed by a digit, which the control ignores.
    pub skip_digits: Vec<TextRange>,
}

/// A block number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Number {
    pub value: Option<u64>,
    pub range: TextRange,
}

/// An address with its value.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Word {
    /// Upper-case ASCII letter, or `&`.
    pub letter: u8,
    pub value: Option<Value>,
    pub range: TextRange,
    pub address_range: TextRange,
    /// The value's range, sign included.
    pub value_range: Option<TextRange>,
}

/// A word's or an assignment's value.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Value {
    /// A number as written, with its sign.
    Literal(Decimal),
    /// A parameter reference `R<index>`, with the sign written before it.
    Parameter { negative: bool, index: Option<u32>, index_range: TextRange },
}

/// `R<index>=<value>`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Assignment {
    pub index: Option<u32>,
    pub value: Option<Value>,
    pub range: TextRange,
    pub index_range: TextRange,
    pub value_range: Option<TextRange>,
}

/// A comment.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Comment {
    pub range: TextRange,
    pub closed: bool,
    pub body: String,
    /// Program text precedes the comment on its line.
    pub after_words: bool,
}

impl BlockData {
    /// Lowers a `BLOCK` green node. Works on the green tree directly: no red
    /// tree is built, which makes lowering a large program several times
    /// cheaper.
    pub fn lower(block: &GreenNodeData) -> BlockData {
        let block_letter = Dialect::Cnc8x6.catalogue().letter_with_role(AddressRole::BlockNumber);
        let mut data = BlockData {
            number: None,
            skip: Vec::new(),
            words: Vec::new(),
            assignments: Vec::new(),
            comments: Vec::new(),
            len: block.text_len(),
            skip_digits: Vec::new(),
        };
        let mut line_has_words = false;
        for (range, child) in children(block, TextSize::from(0)) {
            match child {
                NodeOrToken::Token(token) => match kind(token.kind()) {
                    SyntaxKind::NEWLINE => line_has_words = false,
                    SyntaxKind::WHITESPACE => {}
                    SyntaxKind::COMMENT => {
                        let (body, closed) = ast::comment_parts(token.text());
                        data.comments.push(Comment {
                            range,
                            closed,
                            body: body.to_owned(),
                            after_words: line_has_words,
                        });
                    }
                    _ => line_has_words = true,
                },
                NodeOrToken::Node(node) => {
                    line_has_words = true;
                    match kind(node.kind()) {
                        SyntaxKind::WORD => {
                            let word = lower_word(node, range);
                            let first = data.words.is_empty() && data.number.is_none();
                            if first && Some(word.letter) == block_letter {
                                let value = match &word.value {
                                    Some(Value::Literal(d)) => d.scaled(0).and_then(|v| u64::try_from(v).ok()),
                                    _ => None,
                                };
                                data.number = Some(Number { value, range: word.range });
                            }
                            data.words.push(word);
                        }
                        SyntaxKind::PARAM_ASSIGN => data.assignments.push(lower_assignment(node, range)),
                        SyntaxKind::BLOCK_SKIP => {
                            data.skip.push(range);
                            let digit =
                                children(node, range.start()).find(|(_, c)| kind(c.kind()) == SyntaxKind::NUMBER);
                            if let Some((digit, _)) = digit {
                                data.skip_digits.push(digit);
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        data
    }

    /// The words with `letter`.
    pub fn words_with(&self, letter: u8) -> impl Iterator<Item = &Word> {
        self.words.iter().filter(move |w| w.letter == letter)
    }

    /// The first word with `letter`.
    pub fn word(&self, letter: u8) -> Option<&Word> {
        self.words_with(letter).next()
    }

    /// The G or M codes written as literals, with their words.
    pub fn codes(&self, letter: u8) -> impl Iterator<Item = (u32, &Word)> {
        self.words_with(letter).filter_map(|w| match &w.value {
            Some(Value::Literal(decimal)) => (!decimal.has_point() && decimal.sign().is_none())
                .then(|| decimal.scaled(0).and_then(|v| u32::try_from(v).ok()))
                .flatten()
                .map(|code| (code, w)),
            _ => None,
        })
    }

    /// Whether the block has the literal code `letter` `number` (G01 → 'G', 1).
    pub fn has_code(&self, letter: u8, number: u32) -> bool {
        self.codes(letter).any(|(code, _)| code == number)
    }

    /// Whether the block holds nothing but its number (and comments).
    pub fn is_empty(&self) -> bool {
        self.body_words().next().is_none() && self.assignments.is_empty() && self.skip.is_empty()
    }

    /// Words other than the block number.
    pub fn body_words(&self) -> impl Iterator<Item = &Word> {
        let skip = usize::from(self.number.is_some());
        self.words.iter().skip(skip)
    }
}

fn kind(raw: rowan::SyntaxKind) -> SyntaxKind {
    <NcLanguage as rowan::Language>::kind_from_raw(raw)
}

type GreenRef<'a> = NodeOrToken<&'a GreenNodeData, &'a rowan::GreenTokenData>;

/// The children of a green node with their ranges, `start` being the node's.
fn children(node: &GreenNodeData, start: TextSize) -> impl Iterator<Item = (TextRange, GreenRef<'_>)> {
    let mut offset = start;
    node.children().map(move |child| {
        let range = TextRange::at(offset, child.text_len());
        offset = range.end();
        (range, child)
    })
}

/// A word: address, then its value.
fn lower_word(node: &GreenNodeData, range: TextRange) -> Word {
    let mut items = children(node, range.start());
    let (address_range, address) = items.next().expect("a word starts with its address");
    let letter = match address {
        NodeOrToken::Token(token) => token.text().as_bytes()[0].to_ascii_uppercase(),
        NodeOrToken::Node(_) => b'?',
    };
    let (value, value_range) = lower_value(items, range.end());
    Word { letter, value, range, address_range, value_range }
}

/// `R12=-0.864`.
fn lower_assignment(node: &GreenNodeData, range: TextRange) -> Assignment {
    let mut items = children(node, range.start());
    let (letter_range, _) = items.next().expect("an assignment starts with R");
    let mut index = None;
    let mut index_range = letter_range;
    for (item_range, item) in items.by_ref() {
        match kind(item.kind()) {
            SyntaxKind::NUMBER => {
                index_range = item_range;
                index = number(item).and_then(|d| d.scaled(0)).and_then(|v| u32::try_from(v).ok());
            }
            SyntaxKind::EQ => break,
            _ => {}
        }
    }
    let (value, value_range) = lower_value(items, range.end());
    Assignment { index, value, range, index_range, value_range }
}

/// What follows an address or `=`: spaces, a sign, a number or `R<n>`.
fn lower_value<'a>(
    items: impl Iterator<Item = (TextRange, GreenRef<'a>)>,
    end: TextSize,
) -> (Option<Value>, Option<TextRange>) {
    let mut sign = None;
    let mut start = None;
    for (range, item) in items {
        let item_kind = kind(item.kind());
        if item_kind == SyntaxKind::WHITESPACE && start.is_none() {
            continue;
        }
        start.get_or_insert(range.start());
        let value_range = start.map(|s| TextRange::new(s, end));
        match (item_kind, item) {
            (SyntaxKind::PLUS, _) => sign = Some(Sign::Plus),
            (SyntaxKind::MINUS, _) => sign = Some(Sign::Minus),
            (SyntaxKind::NUMBER, NodeOrToken::Token(token)) => {
                return (Decimal::parse(sign, token.text()).map(Value::Literal), value_range);
            }
            (SyntaxKind::PARAM_REF, NodeOrToken::Node(param)) => {
                let digits = children(param, range.start()).find(|(_, c)| kind(c.kind()) == SyntaxKind::NUMBER);
                let (index_range, index) = match digits {
                    Some((index_range, digits)) => {
                        (index_range, number(digits).and_then(|d| d.scaled(0)).and_then(|v| u32::try_from(v).ok()))
                    }
                    None => (range, None),
                };
                return (
                    Some(Value::Parameter { negative: sign == Some(Sign::Minus), index, index_range }),
                    value_range,
                );
            }
            _ => {}
        }
    }
    (None, start.map(|s| TextRange::new(s, end)))
}

fn number(item: GreenRef<'_>) -> Option<Decimal> {
    match item {
        NodeOrToken::Token(token) => Decimal::parse(None, token.text()),
        NodeOrToken::Node(_) => None,
    }
}

/// The block as the executor reads it, on one line (what `ncc lower`
/// prints): the block number, `/` when the block may be skipped, the words
/// in order with their values as written (`R<n>` for a parameter, `?` for
/// a missing value), then the parameter assignments, which take effect
/// after the block's motion. Comments and layout are not part of it.
impl fmt::Display for BlockData {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut words = self.words.iter().map(Word::to_string);
        let number = self.number.and_then(|_| words.next());
        let skip = (!self.skip.is_empty()).then(|| "/".to_owned());
        let assignments = self.assignments.iter().map(Assignment::to_string);
        let items: Vec<String> = number.into_iter().chain(skip).chain(words).chain(assignments).collect();
        f.write_str(&items.join(" "))
    }
}

impl fmt::Display for Word {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", char::from(self.letter), Written(self.value.as_ref()))
    }
}

impl fmt::Display for Assignment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.index {
            Some(index) => write!(f, "R{index}={}", Written(self.value.as_ref())),
            None => write!(f, "R?={}", Written(self.value.as_ref())),
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Literal(decimal) => write!(f, "{decimal}"),
            Value::Parameter { negative, index, .. } => {
                let sign = if *negative { "-" } else { "" };
                match index {
                    Some(index) => write!(f, "{sign}R{index}"),
                    None => write!(f, "{sign}R?"),
                }
            }
        }
    }
}

/// A value that may be missing, as the IR prints it.
struct Written<'a>(Option<&'a Value>);

impl fmt::Display for Written<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(value) => write!(f, "{value}"),
            None => f.write_str("?"),
        }
    }
}

#[cfg(test)]
mod tests {
    use expect_test::expect;
    use ncc_syntax::{Dialect, Parse, ast::AstNode};

    use super::BlockData;

    #[test]
    fn blocks_print_as_the_executor_reads_them() {
        // A block goes on over lines until the next N; `/` belongs to the
        // block it follows the number of.
        let text = "%1\nN10 / G01 X-R24 Y.5 \"A COMMENT\"\n  Z+2.50 F R5=1101110 R6=-R7\nN20 GR20 L10 Q9999 R=3\n";
        let parse = Parse::new(text, Dialect::Cnc8x6);
        let lowered: Vec<String> =
            parse.tree().blocks().map(|block| BlockData::lower(block.syntax().green()).to_string()).collect();
        expect![[r#"
            [
                "N10 / G01 X-R24 Y.5 Z+2.50 F? R5=1101110 R6=-R7",
                "N20 GR20 L10 Q9999 R?=3",
            ]
        "#]]
        .assert_debug_eq(&lowered);
    }
}
