//! Blocks lowered to plain data: the words, codes and parameter assignments
//! of one block, with ranges relative to the block's start.
//!
//! Lowering depends only on the block's own text (its green node), so the
//! analysis re-lowers only the blocks an edit touched. The executor and the
//! analysis read programs through this one lowering.

use std::fmt;

use ncc_catalog::{AddressRole, Dialect};
use ncc_syntax::{BlockParser, Decimal, Sign, SyntaxKind, TextRange, TextSize, ast};
use rowan::{GreenNode, GreenNodeData, NodeOrToken};

use crate::green::{GreenRef, children, kind};

/// One block.
#[derive(Debug, Default, Clone, PartialEq, Eq, Hash)]
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

/// Reads a program's blocks in order: plain blocks (see [`PlainReader`])
/// from their text, the others from their syntax tree, which the reader
/// hands over to keep. No tree of the whole program is built.
#[derive(Debug)]
pub struct BlockReader<'a> {
    text: &'a str,
    plain: PlainReader,
    parser: BlockParser<'a>,
    at: usize,
    end: usize,
}

impl<'a> BlockReader<'a> {
    pub fn new(text: &'a str) -> BlockReader<'a> {
        let parser = BlockParser::new(text);
        let body = parser.body();
        BlockReader { text, plain: PlainReader::default(), parser, at: body.start, end: body.end }
    }

    /// Goes on at byte `at` (a block's start) when that is further on.
    pub fn skip_to(&mut self, at: usize) {
        self.at = self.at.max(at);
    }

    /// Lowers the next block into `data` (reusing its buffers); returns
    /// its range, and its syntax tree when it is not plain.
    pub fn next_into(&mut self, data: &mut BlockData) -> Option<(TextRange, Option<GreenNode>)> {
        if self.at >= self.end {
            return None;
        }
        let (range, tree) = match self.plain.lower(self.text, self.at, self.end, data) {
            Some(end) => (TextRange::new(offset(self.at), offset(end)), None),
            None => {
                let (range, tree) = self.parser.block_at(self.at)?;
                *data = BlockData::lower(&tree);
                (range, Some(tree))
            }
        };
        self.at = range.end().into();
        Some((range, tree))
    }
}

fn offset(at: usize) -> TextSize {
    TextSize::from(at as u32)
}

/// Lowers blocks straight from their text when they have the shape CAM
/// output is made of: the block number `N<digits>`, then words
/// `<letter><sign?><number>` or `<letter><sign?>R<n>`, assignments
/// `R<n>=<value>`, comments, spaces and line breaks. Any other block
/// is left to its syntax tree and [`BlockData::lower`]; both read a block
/// alike (a property test holds them to it). A large program runs without
/// its tree this way.
#[derive(Debug, Clone, Copy)]
pub struct PlainReader {
    block: u8,
    parameter: u8,
}

impl Default for PlainReader {
    fn default() -> Self {
        let catalogue = Dialect::Cnc8x6.catalogue();
        let letter = |role| catalogue.letter_with_role(role).unwrap_or(0);
        PlainReader { block: letter(AddressRole::BlockNumber), parameter: letter(AddressRole::Parameter) }
    }
}

impl PlainReader {
    /// Lowers the block that starts at `at` in `text[..end]` into `data`
    /// (reusing its buffers) and returns where the block ends: at the next
    /// block number or at `end`. `None` when the block is not plain; `data`
    /// is then unspecified.
    pub fn lower(&self, text: &str, at: usize, end: usize, data: &mut BlockData) -> Option<usize> {
        let bytes = &text.as_bytes()[..end];
        let offset = |pos: usize| offset(pos - at);
        let span = |from: usize, to: usize| TextRange::new(offset(from), offset(to));
        data.words.clear();
        data.assignments.clear();
        data.comments.clear();
        data.skip.clear();
        data.skip_digits.clear();
        if bytes.get(at) != Some(&self.block) {
            return None;
        }
        let digits = digits_at(bytes, at + 1);
        if digits == 0 || bytes.get(at + 1 + digits) == Some(&b'.') {
            return None;
        }
        let number_end = at + 1 + digits;
        let value = Decimal::parse(None, &text[at + 1..number_end]);
        data.number = Some(Number {
            value: value.and_then(|d| d.scaled(0)).and_then(|v| u64::try_from(v).ok()),
            range: span(at, number_end),
        });
        data.words.push(Word {
            letter: self.block,
            value: value.map(Value::Literal),
            range: span(at, number_end),
            address_range: span(at, at + 1),
            value_range: Some(span(at + 1, number_end)),
        });
        let mut pos = number_end;
        let mut line_has_words = true;
        loop {
            let Some(&byte) = bytes.get(pos) else {
                data.len = offset(pos);
                return Some(pos);
            };
            match byte {
                b' ' | b'\t' => pos += 1,
                b'\n' => {
                    line_has_words = false;
                    pos += 1;
                }
                b'\r' if bytes.get(pos + 1) == Some(&b'\n') => {
                    line_has_words = false;
                    pos += 2;
                }
                b'"' => {
                    let comment_end = memchr::memchr3(b'"', b'\n', b'\r', &bytes[pos + 1..])
                        .map_or(end, |i| pos + 1 + i + usize::from(bytes[pos + 1 + i] == b'"'));
                    let (body, closed) = ast::comment_parts(&text[pos..comment_end]);
                    data.comments.push(Comment {
                        range: span(pos, comment_end),
                        closed,
                        body: body.to_owned(),
                        after_words: line_has_words,
                    });
                    pos = comment_end;
                }
                letter if letter == self.block => {
                    data.len = offset(pos);
                    return Some(pos);
                }
                letter if letter == self.parameter => {
                    let index_digits = digits_at(bytes, pos + 1);
                    let eq = pos + 1 + index_digits;
                    if index_digits == 0 || bytes.get(eq) != Some(&b'=') {
                        return None;
                    }
                    let (value, value_end) = self.value(text, end, eq + 1, &span)?;
                    data.assignments.push(Assignment {
                        index: index(&text[pos + 1..eq]),
                        value: Some(value),
                        range: span(pos, value_end),
                        index_range: span(pos + 1, eq),
                        value_range: Some(span(eq + 1, value_end)),
                    });
                    line_has_words = true;
                    pos = value_end;
                }
                letter if letter.is_ascii_uppercase() => {
                    let (value, value_end) = self.value(text, end, pos + 1, &span)?;
                    data.words.push(Word {
                        letter,
                        value: Some(value),
                        range: span(pos, value_end),
                        address_range: span(pos, pos + 1),
                        value_range: Some(span(pos + 1, value_end)),
                    });
                    line_has_words = true;
                    pos = value_end;
                }
                _ => return None,
            }
        }
    }

    /// A value at `at`: a sign, then a number with at least one digit or a
    /// parameter reference `R<n>` (not an assignment's `R<n>=`); and where
    /// it ends.
    fn value(
        &self,
        text: &str,
        end: usize,
        at: usize,
        span: &impl Fn(usize, usize) -> TextRange,
    ) -> Option<(Value, usize)> {
        let bytes = &text.as_bytes()[..end];
        let sign = match bytes.get(at) {
            Some(b'-') => Some(Sign::Minus),
            Some(b'+') => Some(Sign::Plus),
            _ => None,
        };
        let start = at + usize::from(sign.is_some());
        if bytes.get(start) == Some(&self.parameter) {
            let digits = digits_at(bytes, start + 1);
            let value_end = start + 1 + digits;
            if digits == 0 || matches!(bytes.get(value_end), Some(b'.' | b'=')) {
                return None;
            }
            let reference = Value::Parameter {
                negative: sign == Some(Sign::Minus),
                index: index(&text[start + 1..value_end]),
                index_range: span(start + 1, value_end),
            };
            return Some((reference, value_end));
        }
        let int = digits_at(bytes, start);
        let mut value_end = start + int;
        if bytes.get(value_end) == Some(&b'.') {
            value_end += 1 + digits_at(bytes, value_end + 1);
        }
        if value_end - start == usize::from(value_end > start + int) {
            return None;
        }
        Decimal::parse(sign, &text[start..value_end]).map(|decimal| (Value::Literal(decimal), value_end))
    }
}

fn digits_at(bytes: &[u8], at: usize) -> usize {
    bytes.get(at..).map_or(0, |rest| rest.iter().take_while(|b| b.is_ascii_digit()).count())
}

/// A parameter number as the tree lowering reads it.
fn index(digits: &str) -> Option<u32> {
    Decimal::parse(None, digits).and_then(|d| d.scaled(0)).and_then(|v| u32::try_from(v).ok())
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
