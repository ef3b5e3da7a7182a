//! The block times of an estimate in shared pieces. An estimate after an
//! edit keeps the pieces of the previous one before the part it reran, and
//! takes those after it moved (a shift of offsets and clock per piece):
//! copying and dropping 100,000 block times per edit took most of the
//! time of a resumed estimate.

use std::{ops::Range, sync::Arc};

use super::BlockTime;

/// Pieces that hold fewer blocks than this together are merged, so that
/// edits do not split the blocks into ever more pieces: two neighbours
/// hold more, and a lookup searches a few dozen pieces.
const MERGED_PIECE: usize = 4096;

/// Block times in text order.
#[derive(Debug, Clone, Default)]
pub struct BlockTimes {
    pieces: Vec<Piece>,
    len: usize,
}

/// Blocks `range` of a shared run of block times, moved.
#[derive(Debug, Clone)]
struct Piece {
    blocks: Arc<[BlockTime]>,
    range: Range<usize>,
    /// The index of its first block among all.
    first: usize,
    shift: i64,
    clock: f64,
}

impl Piece {
    fn len(&self) -> usize {
        self.range.len()
    }

    fn get(&self, index: usize) -> BlockTime {
        self.blocks[self.range.start + index].moved(self.shift, self.clock)
    }
}

impl BlockTimes {
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The block at `index`, moved to where it is now.
    pub fn get(&self, index: usize) -> Option<BlockTime> {
        let piece = self.piece_of(index)?;
        Some(piece.get(index - piece.first))
    }

    pub fn last(&self) -> Option<BlockTime> {
        self.len.checked_sub(1).and_then(|index| self.get(index))
    }

    /// The blocks from `first` on.
    pub fn iter_from(&self, first: usize) -> impl Iterator<Item = BlockTime> + '_ {
        let at = self.pieces.partition_point(|piece| piece.first + piece.len() <= first);
        self.pieces[at..]
            .iter()
            .flat_map(move |piece| (first.saturating_sub(piece.first)..piece.len()).map(|i| piece.get(i)))
    }

    pub fn iter(&self) -> impl Iterator<Item = BlockTime> + '_ {
        self.iter_from(0)
    }

    /// The number of blocks before the first one for which `before` is
    /// false (they are sorted by it).
    pub fn partition_point(&self, before: impl Fn(&BlockTime) -> bool) -> usize {
        let (mut low, mut high) = (0, self.len);
        while low < high {
            let middle = low + (high - low) / 2;
            match self.get(middle).is_some_and(|block| before(&block)) {
                true => low = middle + 1,
                false => high = middle,
            }
        }
        low
    }

    fn piece_of(&self, index: usize) -> Option<&Piece> {
        let at = self.pieces.partition_point(|piece| piece.first <= index);
        self.pieces[..at].last().filter(|piece| index < piece.first + piece.len())
    }

    /// The first `count` blocks, shared.
    pub(super) fn prefix(&self, count: usize) -> BlockTimes {
        self.slice(0..count.min(self.len))
    }

    /// Blocks `range`, shared.
    pub(super) fn slice(&self, range: Range<usize>) -> BlockTimes {
        let mut sliced = BlockTimes::default();
        for piece in &self.pieces {
            let start = range.start.max(piece.first);
            let end = range.end.min(piece.first + piece.len());
            if start < end {
                let inner = piece.range.start + start - piece.first..piece.range.start + end - piece.first;
                sliced.push(Piece { range: inner, ..piece.clone() });
            }
        }
        sliced
    }

    /// These blocks `shift` bytes later in the text, their runs `clock`
    /// seconds later.
    pub(super) fn moved(mut self, shift: i64, clock: f64) -> BlockTimes {
        for piece in &mut self.pieces {
            piece.shift += shift;
            piece.clock += clock;
        }
        self
    }

    /// `blocks` after these, as they are.
    pub(super) fn push_owned(&mut self, blocks: Vec<BlockTime>) {
        let range = 0..blocks.len();
        self.push(Piece { blocks: blocks.into(), range, first: 0, shift: 0, clock: 0.0 });
    }

    pub(super) fn append(&mut self, other: BlockTimes) {
        for piece in other.pieces {
            self.push(piece);
        }
    }

    /// The blocks, copied.
    pub(super) fn to_vec(&self) -> Vec<BlockTime> {
        self.iter().collect()
    }

    /// Adds `piece` at the end, merged with the pieces before it while
    /// they hold fewer than [`MERGED_PIECE`] blocks together.
    fn push(&mut self, mut piece: Piece) {
        if piece.range.is_empty() {
            return;
        }
        let mut together = piece.len();
        let mut merged_from = self.pieces.len();
        while let Some(before) = merged_from.checked_sub(1).map(|at| &self.pieces[at])
            && together + before.len() < MERGED_PIECE
        {
            together += before.len();
            merged_from -= 1;
        }
        if merged_from < self.pieces.len() {
            self.len = self.pieces[merged_from].first;
            let mut merged = Vec::with_capacity(together);
            for before in self.pieces.drain(merged_from..) {
                merged.extend((0..before.len()).map(|i| before.get(i)));
            }
            merged.extend((0..piece.len()).map(|i| piece.get(i)));
            let range = 0..merged.len();
            piece = Piece { blocks: merged.into(), range, first: 0, shift: 0, clock: 0.0 };
        }
        piece.first = self.len;
        self.len += piece.len();
        self.pieces.push(piece);
    }
}

#[cfg(test)]
mod tests {
    use ncc_syntax::{TextRange, TextSize};

    use super::*;

    fn block(start: u32, clock: f64) -> BlockTime {
        BlockTime {
            range: TextRange::at(TextSize::new(start), TextSize::new(5)),
            start: clock,
            end: clock + 1.0,
            total: 1.0,
            executions: 1,
            profile: Default::default(),
            breaks: Default::default(),
        }
    }

    fn owned(range: Range<u32>) -> BlockTimes {
        let mut times = BlockTimes::default();
        times.push_owned(range.map(|i| block(10 * i, f64::from(i))).collect());
        times
    }

    /// Slices, moves and appends give the blocks a copy would, and keep
    /// the pieces few.
    #[test]
    fn pieces_hold_the_blocks_a_copy_would() {
        let all = owned(0..20_000);
        // An edit that reran blocks 9000..9100 as 150 blocks, 500 bytes and
        // 3 s longer.
        let mut edited = all.prefix(9000);
        edited.push_owned((0..150).map(|i| block(90_000 + 10 * i, 9000.0 + f64::from(i))).collect());
        edited.append(all.slice(9100..20_000).moved(500, 3.0));
        let mut expected = all.to_vec()[..9000].to_vec();
        expected.extend((0..150).map(|i| block(90_000 + 10 * i, 9000.0 + f64::from(i))));
        expected.extend(all.to_vec()[9100..].iter().map(|block| block.moved(500, 3.0)));
        assert_eq!(edited.to_vec(), expected);
        assert_eq!(edited.len(), expected.len());
        for index in [0, 8999, 9000, 9149, 9150, expected.len() - 1] {
            assert_eq!(edited.get(index).as_ref(), expected.get(index));
        }
        assert_eq!(edited.get(expected.len()), None);
        assert_eq!(edited.iter_from(9140).collect::<Vec<_>>(), expected[9140..]);
        let offset = TextSize::new(90_000 + 10 * 149);
        assert_eq!(edited.partition_point(|block| block.range.start() <= offset), 9150);
        // Many small edits: the pieces stay few.
        for at in (100..19_000).step_by(97) {
            let mut next = edited.prefix(at);
            next.push_owned(vec![block(10 * at as u32, at as f64)]);
            next.append(edited.slice(at + 1..edited.len()));
            edited = next;
        }
        assert_eq!(edited.len(), expected.len());
        assert!(edited.pieces.len() <= 2 * edited.len() / MERGED_PIECE + 2, "{} pieces", edited.pieces.len());
        assert!(edited.pieces.iter().zip(&edited.pieces[1..]).all(|(a, b)| a.first + a.len() == b.first));
    }
}
