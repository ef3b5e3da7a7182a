//! Reading the parsers' green trees, which every dialect's lowering does:
//! children with their ranges, token kinds and trivia. Lowering reads green
//! nodes, not the red tree, so that an edit re-lowers only the blocks it
//! touched.

use ncc_syntax::{NcLanguage, SyntaxKind, TextRange, TextSize};
use rowan::{GreenNodeData, GreenTokenData, NodeOrToken};

pub(crate) type GreenRef<'a> = NodeOrToken<&'a GreenNodeData, &'a GreenTokenData>;

pub(crate) fn kind(raw: rowan::SyntaxKind) -> SyntaxKind {
    <NcLanguage as rowan::Language>::kind_from_raw(raw)
}

/// The children of a green node with their ranges, `start` being the node's.
pub(crate) fn children(node: &GreenNodeData, start: TextSize) -> impl Iterator<Item = (TextRange, GreenRef<'_>)> {
    let mut offset = start;
    node.children().map(move |child| {
        let range = TextRange::at(offset, child.text_len());
        offset = range.end();
        (range, child)
    })
}

/// The child as a token of kind `wanted`.
pub(crate) fn token_of(child: GreenRef<'_>, wanted: SyntaxKind) -> Option<&GreenTokenData> {
    match child {
        NodeOrToken::Token(token) if kind(token.kind()) == wanted => Some(token),
        _ => None,
    }
}

pub(crate) fn is_trivia(child: GreenRef<'_>) -> bool {
    matches!(kind(child.kind()), SyntaxKind::WHITESPACE | SyntaxKind::COMMENT | SyntaxKind::NEWLINE)
}

/// Block skip `/` or `/n` at a block's start, as the line dialects write it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Skip {
    /// The digit of `/1` … `/9`; `None` for `/`.
    pub level: Option<u8>,
    pub range: TextRange,
}

impl Skip {
    /// Lowers a `BLOCK_SKIP` node at `range`.
    pub(crate) fn lower(node: &GreenNodeData, range: TextRange) -> Skip {
        let level = children(node, range.start())
            .find_map(|(_, c)| token_of(c, SyntaxKind::NUMBER))
            .and_then(|t| t.text().parse().ok());
        Skip { level, range }
    }
}
