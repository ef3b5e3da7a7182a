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

use rowan::NodeOrToken;

use crate::{
    SyntaxKind,
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
