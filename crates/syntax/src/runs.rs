//! Grouping blocks into runs (`BLOCK_RUN`).
//!
//! A run ends after a block whose text hash has its top [`SPREAD_BITS`]
//! bits zero (once the run has [`MIN_RUN`] blocks), or at [`MAX_RUN`] blocks. The
//! decision depends on the block's text and the run's length only, so two
//! groupings of the same blocks that start at the same block agree from
//! the first run end they share: an incremental reparse regroups from the
//! run the edit touched until it meets an old run end, and gets exactly the
//! runs of a full parse.

use std::hash::Hasher;

use rowan::{NodeOrToken, TextRange};

use crate::{
    SyntaxKind, SyntaxNode,
    green::{self, GreenElement},
};

/// About one block in 2^8 ends a run: runs of ~300 blocks keep both the
/// root and each run small.
const SPREAD_BITS: u32 = 8;
/// Identical blocks (unnumbered repeats) would otherwise end a run each.
const MIN_RUN: usize = 64;
const MAX_RUN: usize = 1024;

/// Groups blocks, given in text order, into runs.
pub(crate) struct RunBuilder<'t> {
    text: &'t str,
    /// Where the next block starts in `text`.
    offset: usize,
    current: Vec<GreenElement>,
    runs: Vec<GreenElement>,
}

impl<'t> RunBuilder<'t> {
    /// A builder whose first block starts at `offset` of `text`.
    pub(crate) fn new(text: &'t str, offset: usize) -> Self {
        RunBuilder { text, offset, current: Vec::new(), runs: Vec::new() }
    }

    /// Adds the next block; returns whether it ended a run.
    pub(crate) fn push(&mut self, block: GreenElement) -> bool {
        let len = usize::from(block.text_len());
        let block_text = &self.text.as_bytes()[self.offset..self.offset + len];
        self.offset += len;
        self.current.push(block);
        let count = self.current.len();
        let ends = count >= MAX_RUN || (count >= MIN_RUN && hash(block_text) >> (u64::BITS - SPREAD_BITS) == 0);
        if ends {
            self.close();
        }
        ends
    }

    /// The runs, the last one ended wherever the blocks ended.
    pub(crate) fn finish(mut self) -> Vec<GreenElement> {
        if !self.current.is_empty() {
            self.close();
        }
        self.runs
    }

    fn close(&mut self) {
        let blocks = std::mem::take(&mut self.current);
        self.runs.push(NodeOrToken::Node(green::node(SyntaxKind::BLOCK_RUN, blocks)));
    }
}

/// FxHash mixes its high bits best.
fn hash(bytes: &[u8]) -> u64 {
    let mut hasher = rustc_hash::FxHasher::default();
    hasher.write(bytes);
    hasher.finish()
}

/// The root with the blocks from `first` up to `stop` (or to the end of the
/// body) replaced by `blocks`, regrouped into runs from the start of
/// `first`'s run until a new run ends where an old one did.
pub(crate) fn regroup(
    root: &SyntaxNode,
    first: &SyntaxNode,
    blocks: Vec<GreenElement>,
    stop: Option<&SyntaxNode>,
    new_text: &str,
    end_index: usize,
) -> rowan::GreenNode {
    let first_run = first.parent().expect("reparsed blocks are in runs");
    let mut runs = RunBuilder::new(new_text, usize::from(first_run.text_range().start()));
    let kept_before = first_run.green().children().take(first.index()).map(|c| c.to_owned()).collect::<Vec<_>>();
    for block in kept_before.into_iter().chain(blocks) {
        runs.push(block);
    }
    let root_green = root.green();
    let replaced_end = match stop {
        None => end_index,
        Some(stop) => {
            let stop_run = stop.parent().expect("reparsed blocks are in runs");
            let mut tail = stop_run.green().children().skip(stop.index()).map(|c| c.to_owned()).collect::<Vec<_>>();
            let mut replaced_end = stop_run.index() + 1;
            loop {
                let mut synced = false;
                for block in tail {
                    synced = runs.push(block);
                }
                // A new run ends where an old one did: every later run is as before.
                if synced || replaced_end == end_index {
                    break replaced_end;
                }
                let next = root_green.children().nth(replaced_end).and_then(NodeOrToken::into_node);
                let Some(next) = next.filter(|n| n.kind() == SyntaxKind::BLOCK_RUN.into()) else { break replaced_end };
                tail = next.children().map(|c| c.to_owned()).collect();
                replaced_end += 1;
            }
        }
    };
    root_green.splice_children(first_run.index()..replaced_end, runs.finish())
}

/// The text of `range`, read from the smallest element that covers it
/// (walking the whole tree's text would make every edit cost a full pass).
pub(crate) fn deleted_text(root: &SyntaxNode, range: TextRange) -> String {
    if range.is_empty() {
        return String::new();
    }
    let covering = root.covering_element(range);
    let start = usize::from(range.start() - covering.text_range().start());
    let text = match covering {
        NodeOrToken::Node(node) => node.to_string(),
        NodeOrToken::Token(token) => token.text().to_owned(),
    };
    text[start..start + usize::from(range.len())].to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dialect, Parse};

    #[test]
    fn long_programs_are_grouped_into_runs_of_bounded_size() {
        let text: String = (0..20_000).map(|i| format!("N{i} X{}\n", i % 997)).collect();
        let parse = Parse::new(&text, Dialect::Cnc8x6);
        let runs: Vec<usize> =
            parse.green().children().filter_map(|c| c.into_node()).map(|run| run.children().len()).collect();
        assert_eq!(runs.iter().sum::<usize>(), 20_000);
        assert!(runs.len() > 20_000 / MAX_RUN && runs.len() < 20_000 / MIN_RUN, "{} runs", runs.len());
        assert!(runs.iter().all(|&len| len <= MAX_RUN));
        assert!(runs[..runs.len() - 1].iter().all(|&len| len >= MIN_RUN));
    }
}
