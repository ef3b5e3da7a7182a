//! Incremental reparsing: after an edit, reparse only the blocks it touched.
//!
//! Like rust-analyzer's block reparsing, but at CNC granularity: the blocks
//! around the edit are reparsed from the new text until parsing reaches a
//! block start that also started a block before the edit; the new blocks
//! replace the old ones, and the runs around them are regrouped (see
//! `runs`), so only the touched runs and the root are rebuilt. Everything
//! the edit could change beyond blocks (the header, the preamble, the
//! physical end `*`, words before the first block) makes us return `None`
//! and the caller parses the whole text again. A property test checks that
//! the result always equals a full parse.

use rowan::{NodeOrToken, TextRange, TextSize};

use super::{
    is_block_letter,
    lexer::TYPOGRAPHIC_QUOTES,
    parser::{self, line_end, line_start},
};
use crate::{
    Parse, SyntaxError, SyntaxErrorKind, SyntaxKind, SyntaxNode, TextEdit,
    error::sort_errors,
    limit::{Omitted, keep_per_line},
    runs::{deleted_text, regroup},
};

pub(crate) fn reparse_blocks(old: &Parse, edit: &TextEdit, new_text: &str) -> Option<Parse> {
    let root = old.syntax_node();
    let old_len = root.text_range().end();
    if edit.delete.end() > old_len || new_text.len() != usize::from(old_len - edit.delete.len()) + edit.insert.len() {
        return None;
    }
    // `%` decides the preamble and `*` the physical end: both are global, and
    // a quote or a line break can hide or reveal one on its line.
    let global = |c: char| c == '%' || c == '*';
    let deleted = deleted_text(&root, edit.delete);
    if edit.insert.contains(global) || deleted.contains(global) {
        return None;
    }
    let comment_delimiter =
        |c: char| matches!(c, '"' | '\n' | '\r') || TYPOGRAPHIC_QUOTES.iter().any(|q| q.starts_with(c));
    if edit.insert.contains(comment_delimiter) || deleted.contains(comment_delimiter) {
        let start = usize::from(edit.delete.start());
        let lines = line_start(new_text, start)..line_end(new_text, start + edit.insert.len(), new_text.len());
        if new_text[lines].contains(global) {
            return None;
        }
    }

    // Where reading a long line stops depends on where the line starts,
    // which an edit on it moves for the blocks after the edit.
    let edit_start = usize::from(edit.delete.start());
    let edited_lines =
        line_end(new_text, edit_start + edit.insert.len(), new_text.len()) - line_start(new_text, edit_start);
    if edited_lines.max(edited_lines + usize::from(edit.delete.len()) - edit.insert.len())
        > crate::lexing::MAX_READ_LINE
    {
        return None;
    }

    let layout = Layout::of(&root);
    let first_block = layout.first_block?;
    let body_end = layout.body_end;
    let (s, e) = (edit.delete.start(), edit.delete.end());
    if s < first_block || e > body_end || body_end == first_block {
        return None;
    }

    // The block just before the edit can grow (text appended to it) and the
    // block after it can lose its `N`: both are reparsed.
    let lo = s.max(first_block + TextSize::from(1)) - TextSize::from(1);
    let first = block_at(&root, lo)?;
    let last = if e < body_end { block_at(&root, e)? } else { block_at(&root, body_end - TextSize::from(1))? };
    let region_start = first.text_range().start();
    let old_region_end = last.text_range().end();

    let delta = i64::from(u32::from(TextSize::of(edit.insert.as_str()))) - i64::from(u32::from(edit.delete.len()));
    let shift = |offset: TextSize| TextSize::from((i64::from(u32::from(offset)) + delta) as u32);
    let unshift = |offset: usize| TextSize::from((offset as i64 - delta) as u32);
    let limit = usize::from(shift(body_end));
    let start = usize::from(region_start);
    if start >= limit || !is_block_letter(new_text.as_bytes()[start]) {
        return None;
    }

    // Reparse until a block start that was a block start before the edit.
    let min_end = usize::from(shift(old_region_end));
    // The new blocks share the words of the old ones, as a full parse would.
    let (blocks, block_errors, stop) = parser::parse_blocks_until(
        new_text,
        start..limit,
        |at| at >= min_end && old_block_starts_at(&root, unshift(at), body_end),
        &[first.green(), last.green()],
    );

    let stop_block = if stop >= limit { None } else { Some(block_at(&root, unshift(stop))?) };
    let green = regroup(&root, &first, blocks, stop_block.as_ref(), new_text, layout.end_index);

    // Errors: block errors of the replaced region and line-length errors of
    // every line touching it are recomputed; later errors move by `delta`.
    let old_stop = unshift(stop);
    let line_lo = line_start(new_text, start).max(layout.lines_from);
    let line_hi = line_end(new_text, stop, limit);
    let old_line_hi = unshift(line_hi);
    let line_lo_size = TextSize::from(line_lo as u32);
    // A line that had errors left out needs them back when the edit removes
    // some of its kept ones: only a full parse has them.
    let touched =
        |o: &Omitted<SyntaxErrorKind>| o.line <= old_line_hi && (o.line >= line_lo_size || o.at >= line_lo_size);
    if old.omitted().iter().any(touched) {
        return None;
    }
    let move_after_stop = |range: TextRange| {
        if range.start() >= old_stop { TextRange::new(shift(range.start()), shift(range.end())) } else { range }
    };
    let mut errors: Vec<_> = old
        .errors()
        .iter()
        .filter(|error| {
            let at = error.range.start();
            let in_lines = at >= line_lo_size && at <= old_line_hi;
            let in_blocks = at >= region_start && at < old_stop;
            !(in_blocks || (error.kind == SyntaxErrorKind::LineTooLong && in_lines))
        })
        .map(|error| SyntaxError { range: move_after_stop(error.range), ..error.clone() })
        .collect();
    errors.extend(block_errors.kept);
    errors.extend(parser::long_lines(new_text, line_lo..line_hi));
    sort_errors(&mut errors);
    // Only the touched lines can have more errors of a kind than they keep.
    let new_line_hi = TextSize::from(line_hi as u32);
    let touched_from = errors.partition_point(|e| e.range.start() < line_lo_size);
    let touched_to = errors.partition_point(|e| e.range.start() <= new_line_hi);
    let after = errors.split_off(touched_to);
    let touched_errors = errors.split_off(touched_from);
    let mut omitted = block_errors.omitted;
    errors.extend(keep_per_line(new_text, touched_errors, &mut omitted, |e| e.range.start(), |e| e.kind));
    errors.extend(after);
    omitted.extend(old.omitted().iter().map(|o| {
        let moved = move_after_stop(TextRange::new(o.line, o.at));
        Omitted { line: moved.start(), at: moved.end(), ..*o }
    }));
    omitted.sort_by_key(|o| (o.at, o.kind));
    Some(Parse { green, errors: errors.into(), omitted: omitted.into(), dialect: old.dialect })
}

/// Where the blocks are among the children of the root.
struct Layout {
    /// Start of the first block that begins with its `N`.
    first_block: Option<TextSize>,
    /// Where the body ends: at `*`, or at the end of the text.
    body_end: TextSize,
    /// Index of the child after the last block.
    end_index: usize,
    /// Where line-length counting starts (the header, or the start).
    lines_from: usize,
}

impl Layout {
    fn of(root: &SyntaxNode) -> Layout {
        let (body_end, end_index) = match root.last_child() {
            Some(end) if end.kind() == SyntaxKind::END => (end.text_range().start(), end.index()),
            _ => (root.text_range().end(), root.green().children().len()),
        };
        let mut first_block = None;
        let mut lines_from = 0;
        for child in root.children() {
            match child.kind() {
                SyntaxKind::HEADER => lines_from = usize::from(child.text_range().start()),
                // Numbered blocks are in runs; the unnumbered ones before
                // them are not.
                SyntaxKind::BLOCK_RUN => {
                    first_block = Some(child.text_range().start());
                    break;
                }
                _ => {}
            }
        }
        Layout { first_block, body_end, end_index, lines_from }
    }
}

fn starts_with_block_number(block: &SyntaxNode) -> bool {
    block.first_token().is_some_and(|t| t.kind() == SyntaxKind::LETTER && is_block_letter(t.text().as_bytes()[0]))
}

/// The numbered block (in its run) that contains the character at `offset`.
fn block_at(root: &SyntaxNode, offset: TextSize) -> Option<SyntaxNode> {
    let at = TextRange::at(offset, TextSize::from(1));
    let run = root.child_or_token_at_range(at)?.into_node().filter(|n| n.kind() == SyntaxKind::BLOCK_RUN)?;
    match run.child_or_token_at_range(at)? {
        NodeOrToken::Node(node) if node.kind() == SyntaxKind::BLOCK && starts_with_block_number(&node) => Some(node),
        _ => None,
    }
}

fn old_block_starts_at(root: &SyntaxNode, offset: TextSize, body_end: TextSize) -> bool {
    offset < body_end && block_at(root, offset).is_some_and(|block| block.text_range().start() == offset)
}

#[cfg(test)]
mod tests {
    use crate::{Dialect, Parse, TextEdit, TextRange, TextSize, ast::AstNode};

    #[test]
    fn untouched_blocks_are_shared_with_the_old_tree() {
        let text = "%1\nN10 X1\nN20 X2\nN30 X3\nN40 X4\nN50 X5\n*\n";
        let old = Parse::new(text, Dialect::Cnc8x6);
        let at = TextSize::from(text.find("X3").unwrap() as u32 + 1);
        let edit = TextEdit::replace(TextRange::new(at, at + TextSize::from(1)), "7 Y8");
        let mut new_text = text.to_owned();
        edit.apply(&mut new_text);
        let new = old.reparse(&edit, &new_text);
        assert_eq!(new, Parse::new(&new_text, Dialect::Cnc8x6));

        let blocks = |parse: &Parse| -> Vec<*const rowan::GreenNodeData> {
            parse.tree().blocks().map(|block| block.syntax().green() as *const rowan::GreenNodeData).collect()
        };
        let (old_blocks, new_blocks) = (blocks(&old), blocks(&new));
        // Five blocks: only N30 is reparsed.
        assert_eq!(old_blocks.len(), new_blocks.len());
        for i in [0, 1, 3, 4] {
            assert_eq!(old_blocks[i], new_blocks[i], "node {i} was rebuilt");
        }
        assert_ne!(old_blocks[2], new_blocks[2]);
    }

    #[test]
    fn a_reparsed_block_shares_its_unchanged_words_as_a_full_parse_does() {
        // `G01` and `Y-2.` are one node each in a full parse: the edit to
        // N20's X leaves them shared, however long the session.
        let text = "%1\nN10 G01 X1. Y-2.\nN20 G01 X3. Y-2.\nN30 G01 X5. Y-2.\n*\n";
        let mut parse = Parse::new(text, Dialect::Cnc8x6);
        let mut text = text.to_owned();
        for digit in ["7", "8", "9"] {
            let at = TextSize::from(text.find("N20 G01 X").unwrap() as u32 + 9);
            let edit = TextEdit::replace(TextRange::new(at, at + TextSize::from(1)), digit);
            edit.apply(&mut text);
            parse = parse.reparse(&edit, &text);
        }
        assert_eq!(parse, Parse::new(&text, Dialect::Cnc8x6));
        let words = |word: &str| -> Vec<*const rowan::GreenNodeData> {
            parse
                .syntax_node()
                .descendants()
                .filter(|node| node.text() == word)
                .map(|node| std::ptr::from_ref::<rowan::GreenNodeData>(node.green()))
                .collect()
        };
        for word in ["G01", "Y-2."] {
            let nodes = words(word);
            assert_eq!(nodes.len(), 3, "{word}");
            assert!(nodes.iter().all(|&node| node == nodes[0]), "{word} is not shared: {nodes:?}");
        }
    }
}
