//! Blocks lowered to plain data: the words, codes and parameter assignments
//! of one block, with ranges relative to the block's start.
//!
//! Lowering depends only on the block's own text, so the database keys it by
//! the block's green node: an edit re-lowers the blocks it touched and no
//! other.

use ncc_syntax::{
    Decimal, Sign, SyntaxKind, SyntaxNode, TextRange, TextSize,
    ast::{self, AstNode, BlockItem},
};

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
    Literal(Literal),
    /// A parameter reference `R<index>`, with the sign written before it.
    Parameter {
        negative: bool,
        index: Option<u32>,
        index_range: TextRange,
    },
}

/// A number as written; `Decimal` with hashing on its text.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Literal {
    /// The written form, sign included (`-0.864`).
    pub text: String,
}

impl Literal {
    pub fn decimal(&self) -> Decimal {
        let (sign, digits) = match self.text.as_bytes().first() {
            Some(b'-') => (Some(Sign::Minus), &self.text[1..]),
            Some(b'+') => (Some(Sign::Plus), &self.text[1..]),
            _ => (None, self.text.as_str()),
        };
        Decimal::parse(sign, digits).expect("lowering keeps only numbers with digits")
    }
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
    pub fn lower(block: &ast::Block) -> BlockData {
        let start = block.syntax().text_range().start();
        let relative = |range: TextRange| range - start;
        let mut data = BlockData {
            number: None,
            skip: Vec::new(),
            words: Vec::new(),
            assignments: Vec::new(),
            comments: Vec::new(),
            len: block.syntax().text_range().len(),
            skip_digits: Vec::new(),
        };
        let mut line_has_words = false;
        for element in block.syntax().children_with_tokens() {
            match element.kind() {
                SyntaxKind::NEWLINE => line_has_words = false,
                SyntaxKind::WHITESPACE => {}
                SyntaxKind::COMMENT => {
                    let token = element.into_token().expect("a comment is a token");
                    let comment = ast::Comment::cast(token).expect("COMMENT");
                    data.comments.push(Comment {
                        range: relative(comment.syntax().text_range()),
                        closed: comment.is_closed(),
                        body: comment.body().to_owned(),
                        after_words: line_has_words,
                    });
                }
                _ => line_has_words = true,
            }
        }
        for item in block.items() {
            match item {
                BlockItem::Word(word) => {
                    let lowered = Word {
                        letter: word.letter() as u8,
                        value: word.value().and_then(|v| lower_value(v, &relative)),
                        range: relative(word.text_range()),
                        address_range: relative(word.address_token().text_range()),
                        value_range: word.value_range().map(relative),
                    };
                    if data.number.is_none() && data.words.is_empty() && word.is_block_number() {
                        let value = match &lowered.value {
                            Some(Value::Literal(literal)) => {
                                literal.decimal().scaled(0).and_then(|v| u64::try_from(v).ok())
                            }
                            _ => None,
                        };
                        data.number = Some(Number { value, range: lowered.range });
                    }
                    data.words.push(lowered);
                }
                BlockItem::Assign(assign) => {
                    let index_range = assign
                        .number_token()
                        .map(|t| t.text_range())
                        .unwrap_or_else(|| assign.syntax().first_token().expect("R").text_range());
                    data.assignments.push(Assignment {
                        index: assign.index().and_then(|d| d.scaled(0)).and_then(|v| u32::try_from(v).ok()),
                        value: assign.value().and_then(|v| lower_value(v, &relative)),
                        range: relative(assign.text_range()),
                        index_range: relative(index_range),
                        value_range: value_range_of(assign.syntax()).map(relative),
                    });
                }
                BlockItem::Skip(skip) => {
                    data.skip.push(relative(skip.text_range()));
                    if let Some(digit) = skip.digit() {
                        data.skip_digits.push(relative(digit.text_range()));
                    }
                }
                BlockItem::Comment(_) | BlockItem::Error(_) => {}
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
            Some(Value::Literal(literal)) => {
                let decimal = literal.decimal();
                (!decimal.has_point() && decimal.sign().is_none())
                    .then(|| decimal.scaled(0).and_then(|v| u32::try_from(v).ok()))
                    .flatten()
                    .map(|code| (code, w))
            }
            _ => None,
        })
    }

    /// Whether the block has the literal code `letter` `number` (G01 → 'G', 1).
    pub fn has_code(&self, letter: u8, number: u32) -> bool {
        self.codes(letter).any(|(code, _)| code == number)
    }

    /// Words other than the block number.
    pub fn body_words(&self) -> impl Iterator<Item = &Word> {
        let skip = usize::from(self.number.is_some());
        self.words.iter().skip(skip)
    }
}

fn lower_value(value: ast::Value, relative: &impl Fn(TextRange) -> TextRange) -> Option<Value> {
    Some(match value {
        ast::Value::Literal(decimal) => Value::Literal(Literal { text: decimal.to_string() }),
        ast::Value::Parameter { sign, param } => {
            let token = param.number_token();
            Value::Parameter {
                negative: sign == Some(Sign::Minus),
                index: param.index().and_then(|d| d.scaled(0)).and_then(|v| u32::try_from(v).ok()),
                index_range: relative(token.map_or(param.text_range(), |t| t.text_range())),
            }
        }
    })
}

/// The range of an assignment's value: from the sign or number after `=`.
fn value_range_of(node: &SyntaxNode) -> Option<TextRange> {
    let mut after_eq = node.children_with_tokens().skip_while(|e| e.kind() != SyntaxKind::EQ).skip(1);
    let first = after_eq.find(|e| e.kind() != SyntaxKind::WHITESPACE)?;
    Some(TextRange::new(first.text_range().start(), node.text_range().end()))
}
