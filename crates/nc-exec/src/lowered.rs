//! A file's blocks lowered, kept in chunks: the editor's analysis lowers a
//! chunk again only when an edit touches it, and a run reads the same
//! chunks instead of lowering the whole text once more.

use std::sync::Arc;

use ncc_syntax::{TextRange, TextSize};

#[derive(Debug, Clone)]
pub struct Lowered<B> {
    /// Each block's range in the file.
    pub ranges: Vec<TextRange>,
    /// The chunks' blocks, in order.
    chunks: Vec<Arc<Vec<B>>>,
    /// The index of each chunk's first block.
    firsts: Vec<usize>,
}

/// Chunks an edit did not touch are the same chunks: compared by address,
/// an edit compares the blocks of the chunk it touched only.
impl<B: PartialEq> PartialEq for Lowered<B> {
    fn eq(&self, other: &Self) -> bool {
        self.ranges == other.ranges
            && self.firsts == other.firsts
            && self.chunks.len() == other.chunks.len()
            && self.chunks.iter().zip(&other.chunks).all(|(a, b)| Arc::ptr_eq(a, b) || a == b)
    }
}

impl<B> Lowered<B> {
    /// The blocks of a file read whole, one chunk.
    pub fn whole(blocks: Vec<B>, ranges: Vec<TextRange>) -> Lowered<B> {
        Lowered { ranges, chunks: vec![Arc::new(blocks)], firsts: vec![0] }
    }

    /// The blocks of `chunks` in order, each chunk with its offset and its
    /// blocks' lengths.
    pub fn from_chunks<'a>(
        chunks: impl ExactSizeIterator<Item = (TextSize, Arc<Vec<B>>, &'a [TextSize])>,
    ) -> Lowered<B> {
        let mut lowered = Lowered { ranges: Vec::new(), chunks: Vec::with_capacity(chunks.len()), firsts: Vec::new() };
        for (mut offset, blocks, lengths) in chunks {
            debug_assert_eq!(blocks.len(), lengths.len());
            lowered.firsts.push(lowered.ranges.len());
            lowered.ranges.extend(lengths.iter().map(|&len| {
                let range = TextRange::at(offset, len);
                offset += len;
                range
            }));
            lowered.chunks.push(blocks);
        }
        lowered
    }

    /// How many blocks the file has.
    pub fn count(&self) -> usize {
        self.ranges.len()
    }

    /// Block `index`.
    pub fn block(&self, index: usize) -> &B {
        let chunk = self.firsts.partition_point(|&first| first <= index) - 1;
        &self.chunks[chunk][index - self.firsts[chunk]]
    }

    /// The blocks from `start` on, in order.
    pub fn blocks_from(&self, start: usize) -> impl Iterator<Item = &B> + Clone {
        let chunk = self.firsts.partition_point(|&first| first <= start).saturating_sub(1);
        let skip = start.saturating_sub(self.firsts.get(chunk).copied().unwrap_or(0));
        self.chunks[chunk.min(self.chunks.len())..].iter().flat_map(|chunk| chunk.iter()).skip(skip)
    }

    /// Every block, in order.
    pub fn iter(&self) -> impl Iterator<Item = &B> + Clone {
        self.chunks.iter().flat_map(|chunk| chunk.iter())
    }

    /// A range of block `index` (block-relative) in the file.
    pub fn in_file(&self, index: usize, range: TextRange) -> TextRange {
        range + self.ranges[index].start()
    }

    /// The line (from 1) that holds `offset`: a block is a line.
    pub fn line_at(&self, offset: TextSize) -> usize {
        self.ranges.partition_point(|range| range.end() <= offset) + 1
    }

    /// The index of the block that starts at `start`.
    pub fn block_starting_at(&self, start: TextSize) -> Option<usize> {
        self.ranges.binary_search_by_key(&start, |range| range.start()).ok()
    }

    /// The index of the block at `offset`; a position at a block's end
    /// (before its line break) belongs to it.
    pub fn block_at(&self, offset: TextSize) -> Option<usize> {
        let index = self.ranges.partition_point(|range| range.end() <= offset);
        match self.ranges.get(index) {
            Some(range) if range.contains_inclusive(offset) => Some(index),
            _ => index.checked_sub(1).filter(|&before| self.ranges[before].end() == offset),
        }
    }
}
