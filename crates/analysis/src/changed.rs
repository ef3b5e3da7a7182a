//! What an edit changed between two trees of one file, by block: the
//! blocks and text it replaced, and where those around it moved. The
//! checkpoints a dialect keeps across edits follow it.

use std::ops::Range;

use ncc_syntax::{SyntaxKind, TextRange, TextSize};
use rowan::{GreenNode, NodeOrToken};

/// What an edit replaced: the root's children between the prefix and the
/// suffix the old and the new tree share.
#[derive(Debug)]
pub(crate) struct Changed {
    /// The old tree's blocks `old` are the new tree's `new` (same start).
    pub old: Range<usize>,
    pub new: Range<usize>,
    /// The text of the replaced children, old and new (same start).
    pub old_text: TextRange,
    pub new_text: TextRange,
}

impl Changed {
    /// Where the position before old block `index` is now (`None`: inside
    /// the change).
    pub fn position(&self, index: usize) -> Option<usize> {
        if index <= self.old.start {
            Some(index)
        } else if index >= self.old.end {
            Some(index - self.old.end + self.new.end)
        } else {
            None
        }
    }

    /// Where old blocks `range` are now (`None`: the change meets them).
    pub fn blocks(&self, range: &Range<usize>) -> Option<Range<usize>> {
        if range.start >= self.old.end {
            Some(range.start - self.old.end + self.new.end..range.end - self.old.end + self.new.end)
        } else if range.end <= self.old.start {
            Some(range.clone())
        } else {
            None
        }
    }

    /// Where old text `range` is now (`None`: the change meets it).
    pub fn range(&self, range: TextRange) -> Option<TextRange> {
        if range.start() >= self.old_text.end() {
            Some(TextRange::at(range.start() - self.old_text.end() + self.new_text.end(), range.len()))
        } else if range.end() <= self.old_text.start() {
            Some(range)
        } else {
            None
        }
    }
}

/// The change from `old` to `new`, two trees of one file: the longest
/// common prefix and suffix of their blocks (and the root's other
/// children), compared by identity (a reparse keeps the blocks and runs it
/// did not touch), leave the replaced blocks. Runs are compared whole
/// first, so only the runs the edit rebuilt are looked into. Identical
/// trees give an empty change at their end.
pub(crate) fn changed_blocks(old: &GreenNode, new: &GreenNode) -> Changed {
    let blocks_in = |child: &Child<'_>| match child {
        NodeOrToken::Node(node) if node.kind() == SyntaxKind::BLOCK_RUN.into() => node.children().len(),
        NodeOrToken::Node(node) => usize::from(node.kind() == SyntaxKind::BLOCK.into()),
        NodeOrToken::Token(_) => 0,
    };
    let (mut start, mut text_start) = (0, TextSize::from(0));
    let (old_root, new_root) = (old.children().collect::<Vec<_>>(), new.children().collect::<Vec<_>>());
    let (prefix, suffix) = common_ends(&old_root, &new_root, |child| {
        start += blocks_in(child);
        text_start += child.text_len();
    });
    // The blocks (and tokens) of the replaced root children, runs opened.
    fn opened<'a>(children: &[Child<'a>]) -> Vec<Child<'a>> {
        children
            .iter()
            .flat_map(|child| match child {
                NodeOrToken::Node(node) if node.kind() == SyntaxKind::BLOCK_RUN.into() => node.children().collect(),
                _ => vec![*child],
            })
            .collect()
    }
    let old_items = opened(&old_root[prefix..old_root.len() - suffix]);
    let new_items = opened(&new_root[prefix..new_root.len() - suffix]);
    let (prefix, suffix) = common_ends(&old_items, &new_items, |child| {
        start += blocks_in(child);
        text_start += child.text_len();
    });
    let replaced = |items: &[Child<'_>]| {
        let items = &items[prefix..items.len() - suffix];
        let blocks = start..start + items.iter().map(blocks_in).sum::<usize>();
        (blocks, TextRange::at(text_start, items.iter().map(|child| child.text_len()).sum()))
    };
    let ((old, old_text), (new, new_text)) = (replaced(&old_items), replaced(&new_items));
    Changed { old, new, old_text, new_text }
}

type Child<'a> = NodeOrToken<&'a rowan::GreenNodeData, &'a rowan::GreenTokenData>;

/// The lengths of the longest common prefix and suffix (not overlapping)
/// of two lists of children, by identity; `in_prefix` sees the prefix.
fn common_ends(old: &[Child<'_>], new: &[Child<'_>], mut in_prefix: impl FnMut(&Child<'_>)) -> (usize, usize) {
    let same = |(a, b): &(&Child<'_>, &Child<'_>)| match (a, b) {
        (NodeOrToken::Node(a), NodeOrToken::Node(b)) => std::ptr::eq(*a, *b),
        (NodeOrToken::Token(a), NodeOrToken::Token(b)) => std::ptr::eq(*a, *b),
        _ => false,
    };
    let mut prefix = 0;
    for (child, _) in old.iter().zip(new).take_while(same) {
        in_prefix(child);
        prefix += 1;
    }
    let suffix =
        old.iter().rev().zip(new.iter().rev()).take(old.len().min(new.len()) - prefix).take_while(same).count();
    (prefix, suffix)
}
