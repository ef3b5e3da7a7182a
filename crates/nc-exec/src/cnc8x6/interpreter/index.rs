//! The program's blocks as the run reaches them: the index of numbered
//! blocks, read ahead in batches, and the program units.

use std::{
    borrow::Cow,
    ops::{ControlFlow, Range},
    sync::{
        atomic::{AtomicBool, Ordering},
        mpsc::{self, Receiver},
    },
    thread::{Scope, ScopedJoinHandle},
};

use ncc_syntax::{TextRange, TextSize};
use rowan::GreenNode;

use crate::{
    cnc8x6::lower::{BlockData, BlockReader, PlainReader, Value},
    cnc8x6::program_flow::{BlockFlow, whole_number},
};

use super::support::*;
use crate::trace::expected_blocks;

/// A subprogram or macrocycle call being run.
pub(super) struct Call {
    /// The block after the call.
    pub(super) back: usize,
    /// Runs left, this one included.
    pub(super) remaining: u32,
    /// The body's first block after its `G79`.
    pub(super) start: usize,
    /// A fixed cycle of the cycle file: the state to restore on return, and
    /// the flow of its block, which goes on then.
    pub(super) cycle: Option<(Box<Snapshot>, BlockFlow)>,
}

/// The blocks of the program and the macrocycle files loaded so far, one
/// index space. A block is kept as where it is and lowered again each time
/// it runs, so that a program of a million blocks costs little more memory
/// than its text: plain blocks are read from the text, others from their
/// syntax tree.
#[derive(Default)]
pub(super) struct Blocks<'a> {
    /// Each block's text range in its file.
    pub(super) ranges: Vec<TextRange>,
    /// The first block of each file, in file order.
    file_starts: Vec<usize>,
    /// The syntax trees of the blocks the plain reader does not read, by
    /// block, in block order (few in CAM output).
    trees: Vec<(usize, GreenNode)>,
    pub(super) units: Units,
    /// The text of each file added so far.
    pub(super) texts: Vec<Cow<'a, str>>,
    pub(super) plain: PlainReader,
}

impl<'a> Blocks<'a> {
    /// Adds a file's blocks; returns where its body starts running (after
    /// the `G79` a macrocycle file opens with), `None` for a file without
    /// blocks.
    pub(super) fn add(&mut self, text: Cow<'a, str>) -> Option<usize> {
        self.add_reading(text, 0, |_, _, _| ControlFlow::Continue(()))
    }

    /// Like [`Blocks::add`], and gives `each` each block as it is lowered,
    /// with whether it starts a subprogram, until it breaks; reads from
    /// byte `from` on (a block's start).
    fn add_reading(
        &mut self,
        text: Cow<'a, str>,
        from: usize,
        mut each: impl FnMut(TextRange, &mut BlockData, bool) -> ControlFlow<()>,
    ) -> Option<usize> {
        let first = self.ranges.len();
        let mut opens_with_g79 = false;
        let expected = expected_blocks(&text);
        self.ranges.reserve(expected);
        self.units.numbers.reserve(expected);
        self.file_starts.push(first);
        let mut reader = BlockReader::new(&text);
        reader.skip_to(from);
        let mut data = BlockData::default();
        while let Some((range, tree)) = reader.next_into(&mut data) {
            let index = self.ranges.len();
            opens_with_g79 |= index == first && data.has_code(b'G', 79);
            let starts_subprogram = self.units.add(index, self.texts.len(), &data, index == first);
            self.ranges.push(range);
            self.trees.extend(tree.map(|tree| (index, tree)));
            if each(range, &mut data, starts_subprogram).is_break() {
                break;
            }
        }
        self.units.numbers.sort_unstable();
        self.texts.push(text);
        (first < self.ranges.len()).then_some(if opens_with_g79 { first + 1 } else { first })
    }

    /// The range and the file of block `index`.
    pub(super) fn block(&self, index: usize) -> Option<(TextRange, usize)> {
        let range = *self.ranges.get(index)?;
        Some((range, self.file_starts.partition_point(|&start| start <= index) - 1))
    }

    /// Lowers block `index` into `data`.
    pub(super) fn lower(&self, index: usize, data: &mut BlockData) {
        match self.trees.binary_search_by_key(&index, |&(at, _)| at) {
            Ok(tree) => *data = BlockData::lower(&self.trees[tree].1),
            Err(_) => {
                let Some((range, source)) = self.block(index) else { return };
                let range = Range::<usize>::from(range);
                let read = self.plain.lower(&self.texts[source], range.start, range.end, data);
                debug_assert_eq!(read, Some(range.end), "a plain block reads alike every time");
            }
        }
    }
}

/// Blocks the index pass hands to the run at a time.
const STREAM_BATCH: usize = 1024;

/// The program's blocks while the index pass still reads them on a
/// thread of its own, then all blocks of the run. Going block after block,
/// the run takes each block as the index pass lowered it, so a large
/// program is lowered once and on two cores; the first call, jump or
/// cycle waits for the whole index.
pub(super) enum Index<'a, 's> {
    Streaming(Stream<'a, 's>),
    Complete(Blocks<'a>),
}

pub(super) struct Stream<'a, 's> {
    /// The program, and whether the stream starts at a checkpoint after
    /// its first block (the index pass then indexes the blocks after it
    /// only).
    pub(super) text: &'a str,
    pub(super) resumed: bool,
    /// Set when the run needs every block: the index pass then goes on
    /// once it stops streaming; else it stops with the run.
    whole_index_wanted: std::sync::Arc<AtomicBool>,
    pub(super) batches: Receiver<Vec<Streamed>>,
    /// Batches taken, back to the index pass with the run's spent block
    /// data, whose room it fills again.
    taken_batches: mpsc::SyncSender<Vec<Streamed>>,
    pub(super) batch: Vec<Streamed>,
    /// Blocks of `batch` the run has taken.
    pub(super) taken: usize,
    /// The index of `batch[taken]`.
    pub(super) next: usize,
    index_pass: ScopedJoinHandle<'s, Blocks<'a>>,
}

/// A block of the program as the index pass lowered it.
pub(super) struct Streamed {
    pub(super) range: TextRange,
    pub(super) data: BlockData,
    pub(super) starts_subprogram: bool,
}

impl<'a, 's> Index<'a, 's> {
    /// Starts the index pass over `text`, from the start or from `from`:
    /// a block's offset and index.
    pub(super) fn start(scope: &'s Scope<'s, 'a>, text: &'a str, from: Option<(TextSize, usize)>) -> Index<'a, 's> {
        let (offset, first) = from.map_or((0, 0), |(offset, block)| (usize::from(offset), block));
        let (sender, batches) = mpsc::sync_channel::<Vec<Streamed>>(4);
        let (taken_batches, returned) = mpsc::sync_channel::<Vec<Streamed>>(4);
        let whole_index_wanted = std::sync::Arc::new(AtomicBool::new(false));
        let wanted = whole_index_wanted.clone();
        let index_pass = scope.spawn(move || {
            let whole_index_wanted = wanted;
            let mut blocks = Blocks::default();
            let mut batch = Vec::with_capacity(STREAM_BATCH);
            // A batch the run took, whose block data the next blocks reuse.
            let mut spent: Vec<Streamed> = Vec::new();
            // Until the run stops taking blocks in order.
            let mut streaming = true;
            blocks.add_reading(Cow::Borrowed(text), offset, |range, data, starts_subprogram| {
                if !streaming {
                    return ControlFlow::Continue(());
                }
                let room = spent.pop().map(|spent| spent.data).unwrap_or_default();
                batch.push(Streamed { range, data: std::mem::replace(data, room), starts_subprogram });
                if batch.len() == STREAM_BATCH {
                    let mut next = match returned.try_recv() {
                        Ok(taken) => std::mem::replace(&mut spent, taken),
                        Err(_) => Vec::with_capacity(STREAM_BATCH),
                    };
                    next.clear();
                    let full = std::mem::replace(&mut batch, next);
                    streaming = sender.send(full).is_ok();
                    // A run that ended needs no index.
                    if !streaming && !whole_index_wanted.load(Ordering::SeqCst) {
                        return ControlFlow::Break(());
                    }
                }
                ControlFlow::Continue(())
            });
            if streaming && !batch.is_empty() {
                // The run may have ended already.
                let _ = sender.send(batch);
            }
            blocks
        });
        let resumed = first > 0;
        Index::Streaming(Stream {
            text,
            resumed,
            whole_index_wanted,
            batches,
            taken_batches,
            batch: Vec::new(),
            taken: 0,
            next: first,
            index_pass,
        })
    }

    /// Whether block `at` comes from the stream: the run goes block after
    /// block.
    pub(super) fn streams(&self, at: usize) -> bool {
        matches!(self, Index::Streaming(stream) if stream.next == at)
    }

    /// The block at `at`, when it was streamed.
    pub(super) fn streamed(&mut self, at: usize) -> Option<&mut Streamed> {
        let Index::Streaming(stream) = self else { return None };
        if at != stream.next {
            return None;
        }
        if stream.taken == stream.batch.len() {
            let taken = std::mem::take(&mut stream.batch);
            let _ = stream.taken_batches.try_send(taken);
            // A closed channel: the index pass has sent every block.
            stream.batch = stream.batches.recv().ok()?;
            stream.taken = 0;
        }
        stream.batch.get_mut(stream.taken)
    }

    /// The range and the file of block `at`.
    pub(super) fn block(&mut self, at: usize) -> Option<(TextRange, usize)> {
        if let Some(streamed) = self.streamed(at) {
            return Some((streamed.range, 0));
        }
        self.complete().block(at)
    }

    pub(super) fn starts_subprogram(&mut self, at: usize) -> bool {
        match self.streamed(at) {
            Some(streamed) => streamed.starts_subprogram,
            None => self.complete().units.starts_subprogram(at),
        }
    }

    /// Lowers block `at` into `data`.
    pub(super) fn lower(&mut self, at: usize, data: &mut BlockData) {
        match self.streamed(at) {
            Some(streamed) => {
                std::mem::swap(data, &mut streamed.data);
                if let Index::Streaming(stream) = self {
                    stream.taken += 1;
                    stream.next += 1;
                }
            }
            None => self.complete().lower(at, data),
        }
    }

    /// All blocks, once the index pass is done.
    pub(super) fn complete(&mut self) -> &mut Blocks<'a> {
        if let Index::Streaming(_) = self {
            let Index::Streaming(stream) = std::mem::replace(self, Index::Complete(Blocks::default())) else {
                unreachable!()
            };
            // The index pass stops streaming and finishes the index, but
            // for a resumed run, whose index starts at its checkpoint.
            stream.whole_index_wanted.store(!stream.resumed, Ordering::SeqCst);
            drop(stream.batches);
            let mut blocks = stream.index_pass.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            if stream.resumed {
                // Jumps and calls may go to blocks before the checkpoint.
                blocks = Blocks::default();
                blocks.add(Cow::Borrowed(stream.text));
            }
            *self = Index::Complete(blocks);
        }
        match self {
            Index::Complete(blocks) => blocks,
            Index::Streaming(_) => unreachable!("the index is complete"),
        }
    }
}

/// Where the subprograms start, and the block numbers of each unit.
#[derive(Default)]
pub(super) struct Units {
    /// Subprogram starts (`G79 L`): the block index, its file and the label.
    pub(super) starts: Vec<(usize, usize, u32)>,
    /// Where each unit starts, in block order (each file's first unit is
    /// its main body or macrocycle body, then one per subprogram): the
    /// units are runs of blocks.
    unit_starts: Vec<usize>,
    /// Block numbers with their block, sorted; only numbers a jump can
    /// name (`L` is at most 4 digits), in a million-block program's index.
    pub(super) numbers: Vec<(u32, u32)>,
}

impl Units {
    /// Indexes block `index` of file `source`; `opens_file` for a file's
    /// first block. The caller sorts `numbers` after the file. Returns
    /// whether the block starts a subprogram.
    pub(super) fn add(&mut self, index: usize, source: usize, block: &BlockData, opens_file: bool) -> bool {
        if opens_file {
            self.unit_starts.push(index);
        }
        // Each `G79` opens a unit: a subprogram, a cycle file's body, or a
        // macrocycle file's body (whose file opened one already).
        if block.has_code(b'G', 79) {
            self.unit_starts.push(index);
            let label = match block.word(b'L').and_then(|word| word.value.as_ref()) {
                Some(Value::Literal(decimal)) => whole_number(decimal),
                _ => None,
            };
            self.starts.extend(label.map(|label| (index, source, label)));
        }
        let number = block.number.and_then(|number| u32::try_from(number.value?).ok());
        if let Some((number, index)) = number.zip(u32::try_from(index).ok()) {
            self.numbers.push((number, index));
        }
        self.starts.last().is_some_and(|&(at, _, _)| at == index)
    }

    pub(super) fn starts_subprogram(&self, index: usize) -> bool {
        self.starts.iter().any(|&(at, _, _)| at == index)
    }

    /// The first block of subprogram `label` of file `source`, after its `G79`.
    pub(super) fn subprogram(&self, source: usize, label: u32) -> Option<usize> {
        self.starts.iter().find(|&&(_, file, l)| file == source && l == label).map(|&(at, _, _)| at + 1)
    }

    /// The unit of block `index`.
    fn unit_of(&self, index: usize) -> usize {
        self.unit_starts.partition_point(|&start| start <= index)
    }

    /// The block numbered `label` in the unit of block `from`.
    pub(super) fn jump_target(&self, from: usize, label: u32) -> Option<usize> {
        let unit = self.unit_of(from);
        let first = self.numbers.partition_point(|&(number, _)| number < label);
        self.numbers[first..]
            .iter()
            .take_while(|&&(number, _)| number == label)
            .map(|&(_, at)| at as usize)
            .find(|&at| self.unit_of(at) == unit)
    }
}
