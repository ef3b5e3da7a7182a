//! What the tests of the dialects whose blocks are lines (Haas lathe,
//! Sinumerik) share: fragments of a dialect's programs glued at random,
//! the checks every parse must pass, and the edits whose reparse must
//! equal a full parse.

use ncc_syntax::{Dialect, Parse, SyntaxKind, TextEdit, TextRange, TextSize};
use proptest::prelude::*;

/// Up to 60 of `fragments`, glued at random.
pub fn glued(fragments: &'static [&'static str]) -> impl Strategy<Value = String> + Clone {
    prop::collection::vec(prop::sample::select(fragments), 0..60).prop_map(|parts| parts.concat())
}

/// Up to 8 characters of `fragments` glued at random: text to insert.
pub fn insertion(fragments: &'static [&'static str]) -> impl Strategy<Value = String> {
    glued(fragments).prop_map(|text| text.chars().take(8).collect())
}

pub fn range(start: usize, end: usize) -> TextRange {
    TextRange::new(TextSize::from(start as u32), TextSize::from(end as u32))
}

fn char_boundary(text: &str, at: usize) -> usize {
    (0..=at.min(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap()
}

/// The tree holds `text` byte for byte, and every error lies inside it, on
/// character boundaries, with a message.
pub fn assert_well_formed(text: &str, parse: &Parse) {
    assert_eq!(parse.syntax_node().to_string(), text);
    for error in parse.errors() {
        let r = std::ops::Range::<usize>::from(error.range);
        assert!(r.end <= text.len() && text.is_char_boundary(r.start) && text.is_char_boundary(r.end), "{error}");
        assert!(!error.message.is_empty());
    }
}

/// Replacing `len` bytes at `start` of `text` (both moved into the text and
/// onto character boundaries) with `insert` and reparsing gives the parse
/// of the new text.
pub fn reparse_equals_full_parse(
    dialect: Dialect,
    text: &str,
    start: usize,
    len: usize,
    insert: String,
) -> Result<(), TestCaseError> {
    let start = char_boundary(text, start % (text.len() + 1));
    let end = char_boundary(text, start + len);
    let edit = TextEdit::replace(range(start, end), insert);
    let mut new_text = text.to_owned();
    edit.apply(&mut new_text);
    let old = Parse::new(text, dialect);
    prop_assert_eq!(old.reparse(&edit, &new_text), Parse::new(&new_text, dialect));
    Ok(())
}

/// Deleting each character of `text`, and inserting each of `inserts` at
/// each position, reparses to the same result as a full parse; `name` says
/// which text failed.
pub fn assert_every_edit_reparses_like_a_full_parse(dialect: Dialect, name: &str, text: &str, inserts: &[&str]) {
    let old = Parse::new(text, dialect);
    let boundaries: Vec<usize> = (0..=text.len()).filter(|&i| text.is_char_boundary(i)).collect();
    let mut edits = Vec::new();
    for pair in boundaries.windows(2) {
        edits.push(TextEdit::replace(range(pair[0], pair[1]), ""));
    }
    for &at in &boundaries {
        for insert in inserts {
            edits.push(TextEdit::replace(range(at, at), *insert));
        }
    }
    for edit in edits {
        let mut new_text = text.to_owned();
        edit.apply(&mut new_text);
        assert_eq!(old.reparse(&edit, &new_text), Parse::new(&new_text, dialect), "{name}: {edit:?}");
    }
}

/// Replaces the character at `at` of `text` by `insert` and checks that
/// the reparse equals a full parse and keeps every block but the
/// `changed`-th (of `blocks`) as the very node of the old tree.
pub fn assert_only_one_block_rebuilt(
    dialect: Dialect,
    text: &str,
    at: usize,
    insert: &str,
    blocks: usize,
    changed: usize,
) {
    let old = Parse::new(text, dialect);
    let edit = TextEdit::replace(range(at, at + 1), insert);
    let mut new_text = text.to_owned();
    edit.apply(&mut new_text);
    let new = old.reparse(&edit, &new_text);
    assert_eq!(new, Parse::new(&new_text, dialect));
    let block_nodes = |parse: &Parse| -> Vec<*const rowan::GreenNodeData> {
        parse
            .syntax_node()
            .descendants()
            .filter(|n| n.kind() == SyntaxKind::BLOCK)
            .map(|n| std::ptr::from_ref::<rowan::GreenNodeData>(n.green()))
            .collect()
    };
    let (old_blocks, new_blocks) = (block_nodes(&old), block_nodes(&new));
    assert_eq!(old_blocks.len(), blocks);
    for i in 0..blocks {
        assert_eq!(old_blocks[i] == new_blocks[i], i != changed, "block {i}");
    }
}

/// The significant tokens of `text`, as (kind, text).
pub fn tokens(dialect: Dialect, text: &str) -> Vec<(SyntaxKind, String)> {
    Parse::new(text, dialect)
        .syntax_node()
        .descendants_with_tokens()
        .filter_map(|e| e.into_token())
        .filter(|t| !matches!(t.kind(), SyntaxKind::WHITESPACE | SyntaxKind::NEWLINE))
        .map(|t| (t.kind(), t.text().to_owned()))
        .collect()
}
