//! A typed view of the tree: programs, blocks, words, parameters, comments.
//!
//! Every type wraps a node or token of the lossless tree and reads it on
//! demand; nothing is copied out. Later layers walk these types, never raw
//! node kinds.

use rowan::{NodeOrToken, TextRange};

use crate::{Decimal, Sign, SyntaxKind, SyntaxNode, SyntaxToken};

/// A typed node.
pub trait AstNode: Sized {
    fn cast(node: SyntaxNode) -> Option<Self>;
    fn syntax(&self) -> &SyntaxNode;

    fn text_range(&self) -> TextRange {
        self.syntax().text_range()
    }
}

macro_rules! ast_node {
    ($(#[$doc:meta])* $name:ident = $kind:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq, Eq, Hash)]
        pub struct $name(SyntaxNode);

        impl AstNode for $name {
            fn cast(node: SyntaxNode) -> Option<Self> {
                (node.kind() == SyntaxKind::$kind).then(|| $name(node))
            }

            fn syntax(&self) -> &SyntaxNode {
                &self.0
            }
        }
    };
}

ast_node!(
    /// The whole file.
    SourceFile = SOURCE_FILE
);
ast_node!(
    /// `%number "comment"`.
    Header = HEADER
);
ast_node!(
    /// A block: `N10 G01 X5 "comment"`, possibly over several lines.
    Block = BLOCK
);
ast_node!(
    /// An address and its value: `X-.5`, `G01`, `FR10`, `&1201`.
    Word = WORD
);
ast_node!(
    /// `R10` used as a value.
    ParamRef = PARAM_REF
);
ast_node!(
    /// `R12=-0.864`.
    ParamAssign = PARAM_ASSIGN
);
ast_node!(
    /// Block skip `/`.
    BlockSkip = BLOCK_SKIP
);
ast_node!(
    /// `*` and everything after it.
    End = END
);

fn child<N: AstNode>(parent: &SyntaxNode) -> Option<N> {
    parent.children().find_map(N::cast)
}

fn token(parent: &SyntaxNode, kind: SyntaxKind) -> Option<SyntaxToken> {
    parent.children_with_tokens().filter_map(NodeOrToken::into_token).find(|t| t.kind() == kind)
}

fn sign_of(parent: &SyntaxNode) -> Option<Sign> {
    parent.children_with_tokens().filter_map(NodeOrToken::into_token).find_map(|t| match t.kind() {
        SyntaxKind::PLUS => Some(Sign::Plus),
        SyntaxKind::MINUS => Some(Sign::Minus),
        _ => None,
    })
}

impl SourceFile {
    /// Text before `%`, skipped by the control.
    pub fn preamble(&self) -> Option<SyntaxToken> {
        // Only text before the first node can be the preamble; stopping
        // there keeps this cheap on files of a million blocks.
        self.0
            .children_with_tokens()
            .take_while(|element| element.as_node().is_none())
            .filter_map(NodeOrToken::into_token)
            .find(|t| t.kind() == SyntaxKind::PREAMBLE)
    }

    pub fn header(&self) -> Option<Header> {
        // The header is the first node when there is one.
        self.0.first_child().and_then(Header::cast)
    }

    /// All blocks in order, including words that lack their `N` (see
    /// [`Block::number`]).
    pub fn blocks(&self) -> impl Iterator<Item = Block> + use<> {
        self.0
            .children()
            .flat_map(|child| {
                let run = child.kind() == SyntaxKind::BLOCK_RUN;
                let in_run = run.then(|| child.children()).into_iter().flatten();
                (!run).then_some(child).into_iter().chain(in_run)
            })
            .filter_map(Block::cast)
    }

    /// Comments outside any block: between the header and the first block.
    pub fn comments(&self) -> impl Iterator<Item = Comment> + use<> {
        comments(&self.0)
    }

    pub fn end(&self) -> Option<End> {
        // The end follows every block: look from the back.
        std::iter::successors(self.0.last_child(), SyntaxNode::prev_sibling)
            .take_while(|node| !matches!(node.kind(), SyntaxKind::BLOCK | SyntaxKind::BLOCK_RUN))
            .find_map(End::cast)
    }
}

fn comments(node: &SyntaxNode) -> impl Iterator<Item = Comment> + use<> {
    node.children_with_tokens().filter_map(NodeOrToken::into_token).filter_map(Comment::cast)
}

impl Header {
    pub fn percent(&self) -> SyntaxToken {
        token(&self.0, SyntaxKind::PERCENT).expect("a header starts with `%`")
    }

    pub fn number_token(&self) -> Option<SyntaxToken> {
        token(&self.0, SyntaxKind::NUMBER)
    }

    /// The program number as written (`%35` → 35).
    pub fn number(&self) -> Option<Decimal> {
        Decimal::parse(sign_of(&self.0), self.number_token()?.text())
    }

    pub fn comment(&self) -> Option<Comment> {
        comments(&self.0).next()
    }
}

/// What a block holds, in order.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum BlockItem {
    Word(Word),
    Assign(ParamAssign),
    Skip(BlockSkip),
    Comment(Comment),
    /// Input the parser could not place; a syntax error covers it.
    Error(SyntaxNode),
}

impl Block {
    /// The block number word, `None` for words written before any `N`.
    pub fn number(&self) -> Option<Word> {
        self.words().next().filter(Word::is_block_number)
    }

    pub fn items(&self) -> impl Iterator<Item = BlockItem> + use<> {
        self.0.children_with_tokens().filter_map(|element| match element {
            NodeOrToken::Node(node) => Some(match node.kind() {
                SyntaxKind::WORD => BlockItem::Word(Word(node)),
                SyntaxKind::PARAM_ASSIGN => BlockItem::Assign(ParamAssign(node)),
                SyntaxKind::BLOCK_SKIP => BlockItem::Skip(BlockSkip(node)),
                _ => BlockItem::Error(node),
            }),
            NodeOrToken::Token(token) => Comment::cast(token).map(BlockItem::Comment),
        })
    }

    /// Words in order, the `N` word first.
    pub fn words(&self) -> impl Iterator<Item = Word> + use<> {
        self.0.children().filter_map(Word::cast)
    }

    pub fn assignments(&self) -> impl Iterator<Item = ParamAssign> + use<> {
        self.0.children().filter_map(ParamAssign::cast)
    }

    pub fn comments(&self) -> impl Iterator<Item = Comment> + use<> {
        comments(&self.0)
    }

    pub fn skip(&self) -> Option<BlockSkip> {
        child(&self.0)
    }

    /// Whether the block holds nothing but its number (and trivia).
    pub fn is_empty(&self) -> bool {
        self.items().all(|item| match item {
            BlockItem::Word(word) => word.is_block_number(),
            BlockItem::Comment(_) => true,
            _ => false,
        })
    }
}

/// The value of a word or assignment.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A number as written, with its sign.
    Literal(Decimal),
    /// A parameter reference, with the sign written before it (if any).
    Parameter { sign: Option<Sign>, param: ParamRef },
}

fn value_of(node: &SyntaxNode) -> Option<Value> {
    // The value is what follows the address (and, for assignments, the `=`).
    let after = node
        .children_with_tokens()
        .skip_while(|e| node.kind() == SyntaxKind::PARAM_ASSIGN && e.kind() != SyntaxKind::EQ)
        .skip(1);
    let mut sign = None;
    for element in after {
        match element {
            NodeOrToken::Token(t) if t.kind() == SyntaxKind::PLUS => sign = Some(Sign::Plus),
            NodeOrToken::Token(t) if t.kind() == SyntaxKind::MINUS => sign = Some(Sign::Minus),
            NodeOrToken::Token(t) if t.kind() == SyntaxKind::NUMBER => {
                return Decimal::parse(sign, t.text()).map(Value::Literal);
            }
            NodeOrToken::Node(n) => return ParamRef::cast(n).map(|param| Value::Parameter { sign, param }),
            NodeOrToken::Token(_) => {}
        }
    }
    None
}

impl Word {
    pub fn address_token(&self) -> SyntaxToken {
        self.0.first_token().expect("a word starts with its address")
    }

    /// Whether the address is the block-number letter (`N`).
    pub fn is_block_number(&self) -> bool {
        super::is_block_letter(self.address_token().text().as_bytes()[0])
    }

    /// The address, upper-cased (`&` for length compensation).
    pub fn letter(&self) -> char {
        char::from(self.address_token().text().as_bytes()[0].to_ascii_uppercase())
    }

    pub fn value(&self) -> Option<Value> {
        value_of(&self.0)
    }

    /// The range of the value (sign included), for diagnostics.
    pub fn value_range(&self) -> Option<TextRange> {
        let mut elements = self.0.children_with_tokens().skip(1).skip_while(|e| e.kind() == SyntaxKind::WHITESPACE);
        let first = elements.next()?;
        Some(TextRange::new(first.text_range().start(), self.0.text_range().end()))
    }
}

impl ParamRef {
    pub fn number_token(&self) -> Option<SyntaxToken> {
        token(&self.0, SyntaxKind::NUMBER)
    }

    /// The parameter number as written (`R05` → 5 with two digits).
    pub fn index(&self) -> Option<Decimal> {
        Decimal::parse(None, self.number_token()?.text())
    }
}

impl ParamAssign {
    pub fn number_token(&self) -> Option<SyntaxToken> {
        self.0
            .children_with_tokens()
            .take_while(|e| e.kind() != SyntaxKind::EQ)
            .filter_map(NodeOrToken::into_token)
            .find(|t| t.kind() == SyntaxKind::NUMBER)
    }

    /// The parameter number as written.
    pub fn index(&self) -> Option<Decimal> {
        Decimal::parse(None, self.number_token()?.text())
    }

    pub fn value(&self) -> Option<Value> {
        value_of(&self.0)
    }
}

impl BlockSkip {
    /// The digit written after `/`, which the control ignores.
    pub fn digit(&self) -> Option<SyntaxToken> {
        token(&self.0, SyntaxKind::NUMBER)
    }
}

impl End {
    pub fn star(&self) -> SyntaxToken {
        token(&self.0, SyntaxKind::STAR).expect("the end starts with `*`")
    }

    pub fn comment(&self) -> Option<Comment> {
        comments(&self.0).next()
    }

    /// Text after `*` that is not a comment.
    pub fn ignored(&self) -> impl Iterator<Item = SyntaxToken> + use<> {
        self.0.children_with_tokens().filter_map(NodeOrToken::into_token).filter(|t| t.kind() == SyntaxKind::TRAILER)
    }
}

/// A comment token.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Comment(SyntaxToken);

impl Comment {
    pub fn cast(token: SyntaxToken) -> Option<Comment> {
        (token.kind() == SyntaxKind::COMMENT).then(|| Comment(token))
    }

    pub fn syntax(&self) -> &SyntaxToken {
        &self.0
    }

    /// Whether the comment has its closing quote (else it ends at the line end).
    pub fn is_closed(&self) -> bool {
        comment_parts(self.0.text()).1
    }

    /// The text between the quotes.
    pub fn body(&self) -> &str {
        comment_parts(self.0.text()).0
    }
}

/// A comment token's text split into its body and whether it is closed.
pub fn comment_parts(text: &str) -> (&str, bool) {
    let open = text.chars().next().map_or(0, char::len_utf8);
    let closed = text.len() > open && text[open..].ends_with(['"', '\u{201C}', '\u{201D}', '\u{201E}']);
    let close = if closed { text.chars().next_back().map_or(0, char::len_utf8) } else { 0 };
    (&text[open..text.len() - close], closed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dialect, Parse};

    fn file(text: &str) -> SourceFile {
        Parse::new(text, Dialect::Cnc8x6).tree()
    }

    #[test]
    fn typed_view_of_a_program() {
        let file = file("%35 \"PART\"\nN10 G01 X-.5 FR10 R12= -0.864 \"cut\n/1 Y 3.\nN20\n*\n");
        let header = file.header().unwrap();
        assert_eq!(header.number().unwrap().to_string(), "35");
        assert_eq!(header.comment().unwrap().body(), "PART");

        let blocks: Vec<_> = file.blocks().collect();
        assert_eq!(blocks.len(), 2);
        let words: Vec<_> = blocks[0].words().map(|w| (w.letter(), w.syntax().to_string())).collect();
        assert_eq!(
            words,
            [('N', "N10"), ('G', "G01"), ('X', "X-.5"), ('F', "FR10"), ('Y', "Y 3.")].map(|(l, t)| (l, t.to_owned()))
        );
        let x = blocks[0].words().nth(2).unwrap();
        assert_eq!(x.value(), Some(Value::Literal(Decimal::parse(Some(Sign::Minus), ".5").unwrap())));
        let f = blocks[0].words().nth(3).unwrap();
        let Some(Value::Parameter { sign: None, param }) = f.value() else { panic!("FR10 is a parameter") };
        assert_eq!(param.index().unwrap().to_string(), "10");

        let assign = blocks[0].assignments().next().unwrap();
        assert_eq!(assign.index().unwrap().to_string(), "12");
        assert_eq!(assign.value(), Some(Value::Literal(Decimal::parse(Some(Sign::Minus), "0.864").unwrap())));

        let comment = blocks[0].comments().next().unwrap();
        assert!(!comment.is_closed());
        assert_eq!(comment.body(), "cut");
        assert_eq!(blocks[0].skip().unwrap().digit().unwrap().text(), "1");
        assert!(blocks[1].is_empty());
        assert!(file.end().is_some());
    }

    #[test]
    fn words_before_the_first_block_have_no_number() {
        let file = file("%1\nG90 X1\nN10 X2\n");
        let blocks: Vec<_> = file.blocks().collect();
        assert!(blocks[0].number().is_none());
        assert_eq!(blocks[1].number().unwrap().value().unwrap(), Value::Literal(Decimal::parse(None, "10").unwrap()));
    }
}
