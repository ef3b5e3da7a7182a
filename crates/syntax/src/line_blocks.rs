//! Parsing for dialects whose blocks are lines (Haas, Sinumerik): large
//! programs in parts on all cores, and after an edit only the lines it
//! touched.
//!
//! A part that starts at a line start parses alone, so a large body is
//! split at line starts and its parts parsed in parallel; the runs are
//! formed in one pass over all parts, so they do not depend on the split.
//!
//! A block is a line, so the blocks an edit can change are the one before
//! it (a line break deleted or inserted at its end joins or splits it) up
//! to the one holding its end; every other block keeps its text and so its
//! tree. The runs around them are regrouped (see `runs`). Edits that touch
//! the text outside the blocks, or that the dialect refuses (a tape mark
//! appearing), make us return `None` and the caller parses the whole text
//! again. Property tests check that the result always equals a full parse.

use std::ops::Range;

use rowan::{GreenNode, GreenNodeData, NodeOrToken, TextRange, TextSize};

use crate::{
    SyntaxError, SyntaxErrorKind, SyntaxKind, SyntaxNode, TextEdit,
    encoding::BYTE_ORDER_MARK,
    error::{Errors, sort_errors},
    green::GreenElement,
    limit::Omitted,
    line_cursor::LineParser,
    runs::{RunBuilder, regroup},
};

/// Bodies from this size on are parsed in parts on all cores.
pub(crate) const PARALLEL_THRESHOLD: usize = 1 << 20;

/// The blocks of `body` (which starts at a line start) grouped into runs,
/// parsed by `P` in parts on all cores when the body is at least
/// `parallel_threshold` long, and their errors.
pub(crate) fn parse_in_parts<'a, P: LineParser<'a>>(
    text: &'a str,
    body: Range<usize>,
    parallel_threshold: usize,
) -> (Vec<GreenElement>, Errors) {
    let bounds = if body.len() < parallel_threshold {
        vec![body.start, body.end]
    } else {
        split_at_lines(text, body.clone(), rayon::current_num_threads() * 4)
    };
    let parse_part = |i: usize| parse_blocks::<P>(text, bounds[i]..bounds[i + 1], &[]);
    let parts: Vec<_> = if bounds.len() > 2 {
        use rayon::prelude::*;
        (0..bounds.len() - 1).into_par_iter().map(parse_part).collect()
    } else {
        vec![parse_part(0)]
    };
    let mut errors = Errors::default();
    let mut runs = RunBuilder::new(text, body.start);
    for (blocks, block_errors) in parts {
        for block in blocks {
            runs.push(block);
        }
        errors.append(block_errors);
    }
    (runs.finish(), errors)
}

/// Parses the blocks (lines) of `region`, which starts at a line start.
/// `replaced` are blocks of an older tree whose words the new blocks share.
fn parse_blocks<'a, P: LineParser<'a>>(
    text: &'a str,
    region: Range<usize>,
    replaced: &[&GreenNodeData],
) -> (Vec<GreenElement>, Errors) {
    let mut parser = P::new(text, region.start, region.end);
    for block in replaced {
        parser.green.share_words_of(block);
    }
    // A block a line: sized once, a part's list is not copied as it grows.
    let lines = memchr::memchr_iter(b'\n', &text.as_bytes()[region.clone()]).count() + 1;
    let mut blocks = Vec::with_capacity(lines);
    while parser.pos < region.end {
        blocks.push(NodeOrToken::Node(parser.block()));
    }
    (blocks, parser.take_errors())
}

/// About `parts` parts of `region`, each starting at a line start.
fn split_at_lines(text: &str, region: Range<usize>, parts: usize) -> Vec<usize> {
    let mut bounds = vec![region.start];
    for k in 1..parts {
        let from = (region.start + region.len() * k / parts).max(bounds[bounds.len() - 1]);
        match text[from..region.end].find('\n') {
            Some(newline) if from + newline + 1 < region.end => bounds.push(from + newline + 1),
            _ => break,
        }
    }
    bounds.push(region.end);
    bounds
}

/// A tree with its errors, as [`crate::Parse`] holds them.
pub(crate) type Parts = (GreenNode, Vec<SyntaxError>, Vec<Omitted<SyntaxErrorKind>>);

/// What a dialect decides in a reparse.
pub(crate) struct LineDialect<E, R> {
    /// Whether the edit may be applied to the old tree at all (its range
    /// is known to lie in the old text).
    pub(crate) edit_ok: E,
    /// Whether the new text of the reparsed lines may be parsed as blocks.
    pub(crate) region_ok: R,
}

/// The reparse of `old` after `edit`, the blocks parsed by `P`.
pub(crate) fn reparse_line_blocks<'a, P, E, R>(
    old: (&GreenNode, &[SyntaxError], &[Omitted<SyntaxErrorKind>]),
    edit: &TextEdit,
    new_text: &'a str,
    dialect: LineDialect<E, R>,
) -> Option<Parts>
where
    P: LineParser<'a>,
    E: FnOnce(&SyntaxNode) -> bool,
    R: FnOnce(&SyntaxNode, &str) -> bool,
{
    let (old_green, old_errors, old_omitted) = old;
    let root = SyntaxNode::new_root(old_green.clone());
    let old_len = root.text_range().end();
    if edit.delete.end() > old_len || new_text.len() != usize::from(old_len - edit.delete.len()) + edit.insert.len() {
        return None;
    }
    if !(dialect.edit_ok)(&root) {
        return None;
    }
    let runs: Vec<SyntaxNode> = root.children().filter(|n| n.kind() == SyntaxKind::BLOCK_RUN).collect();
    let (first_run, last_run) = (runs.first()?, runs.last()?);
    let body = TextRange::new(first_run.text_range().start(), last_run.text_range().end());
    let (s, e) = (edit.delete.start(), edit.delete.end());
    // Text after the blocks (a closing tape mark): an edit at its line's
    // start would glue text onto it.
    let closing = body.end() < old_len;
    // A byte-order mark is read only at the very start of the file.
    let near_mark = usize::from(s) < BYTE_ORDER_MARK.len_utf8();
    if near_mark || s < body.start() || e > body.end() || (e == body.end() && closing) {
        return None;
    }
    let one = TextSize::from(1);
    let first = block_at(&root, s.max(body.start() + one) - one)?;
    let last = if e < body.end() { block_at(&root, e)? } else { block_at(&root, body.end() - one)? };
    let region_start = first.text_range().start();
    let old_region_end = last.text_range().end();

    let delta = i64::from(u32::from(TextSize::of(edit.insert.as_str()))) - i64::from(u32::from(edit.delete.len()));
    let shift = |offset: TextSize| TextSize::from((i64::from(u32::from(offset)) + delta) as u32);
    let start = usize::from(region_start);
    let new_end = usize::from(shift(old_region_end));
    if !(dialect.region_ok)(&root, &new_text[start..new_end]) {
        return None;
    }
    let (blocks, block_errors) = parse_blocks::<P>(new_text, start..new_end, &[first.green(), last.green()]);
    let stop = (old_region_end < body.end()).then(|| block_at(&root, old_region_end)).flatten();
    let end_index = last_run.index() + 1;
    let green = regroup(&root, &first, blocks, stop.as_ref(), new_text, end_index);

    // Every error lies on one line, so in one block: those of the replaced
    // blocks are recomputed, the later ones move by `delta`.
    // A zero-width error at the very end of the blocks belongs to the last.
    let in_region = |at: TextSize| {
        at >= region_start && (at < old_region_end || (at == old_region_end && old_region_end == body.end()))
    };
    let moved = |range: TextRange| {
        if range.start() >= old_region_end { TextRange::new(shift(range.start()), shift(range.end())) } else { range }
    };
    let mut errors: Vec<SyntaxError> = old_errors
        .iter()
        .filter(|error| !in_region(error.range.start()))
        .map(|error| SyntaxError { range: moved(error.range), ..error.clone() })
        .collect();
    errors.extend(block_errors.kept);
    sort_errors(&mut errors);
    let mut omitted: Vec<Omitted<_>> = old_omitted
        .iter()
        .filter(|o| !in_region(o.at))
        .map(|o| {
            let line_and_at = moved(TextRange::new(o.line, o.at));
            Omitted { line: line_and_at.start(), at: line_and_at.end(), ..*o }
        })
        .collect();
    omitted.extend(block_errors.omitted);
    omitted.sort_by_key(|o| (o.at, o.kind));
    Some((green, errors, omitted))
}

/// The block (in its run) that contains the character at `offset`.
fn block_at(root: &SyntaxNode, offset: TextSize) -> Option<SyntaxNode> {
    let at = TextRange::at(offset, TextSize::from(1));
    let run = root.child_or_token_at_range(at)?.into_node().filter(|n| n.kind() == SyntaxKind::BLOCK_RUN)?;
    match run.child_or_token_at_range(at)? {
        NodeOrToken::Node(node) if node.kind() == SyntaxKind::BLOCK => Some(node),
        _ => None,
    }
}
