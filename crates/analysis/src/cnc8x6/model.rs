//! The program model: what kind of file, its program units, block numbers
//! and calls.
//!
//! A partprogram is its main body up to the block with M02/M30, followed by
//! subprograms (`G79 L..` up to their last `G70`). A macrocycle file (`L<number>`) is one
//! such unit; a fixed-cycle file (`$PC`) is a sequence of them.

use std::{ops::Range, sync::Arc};

use ncc_syntax::{TextRange, TextSize};
use rustc_hash::FxHashMap;

use crate::{
    cnc8x6::chunks,
    db::{self, Db, SourceFile},
    lower::{BlockData, Value},
};

/// What a file is, by its name and first lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FileKind {
    Program,
    /// A macrocycle file `L<number>`.
    Macrocycle(u32),
    /// A fixed-cycle file, which starts with the keyword `$PC`.
    CycleFile,
}

impl FileKind {
    /// The kind of the file at `path` whose text before the first block is
    /// `prelude`.
    pub fn of(path: &str, prelude: &str) -> FileKind {
        let digits =
            file_stem(path).strip_prefix(['L', 'l']).filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()));
        if let Some(number) = digits.and_then(|d| d.parse().ok()) {
            return FileKind::Macrocycle(number);
        }
        if prelude.contains("$PC") { FileKind::CycleFile } else { FileKind::Program }
    }
}

/// A file's name without its directory and extension.
pub(crate) fn file_stem(path: &str) -> &str {
    let name = path.rsplit(['/', '\\']).next().unwrap_or(path);
    name.split('.').next().unwrap_or(name)
}

/// A program unit: the main body, a subprogram, a macrocycle or a cycle body.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Unit {
    /// The `L` of its `G79` block; `None` for the main body.
    pub number: Option<u32>,
    /// Indices of its blocks.
    pub blocks: Range<usize>,
    /// Whether it has a G70; a body may return from several places and
    /// ends at its last G70.
    pub closed: bool,
}

/// A call or jump written in a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Transfer {
    /// `G71 L`: a subprogram of this file.
    Subprogram(u32),
    /// `G72 L`: a macrocycle file.
    Macrocycle(u32),
    /// `G73 L`: a block of the same unit.
    Jump(u32),
}

/// What the program model needs of one block (ranges relative to where
/// the summary's owner puts them: the chunk in [`ChunkSummary`], the file
/// in [`Program::block`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BlockSummary {
    pub offset: TextSize,
    pub len: TextSize,
    pub number: Option<u64>,
    pub number_range: Option<TextRange>,
    /// The first word, where diagnostics about the whole block point.
    pub head: TextRange,
    /// `G79`, with its L if written as a number.
    pub starts_unit: Option<Option<u32>>,
    /// The G70 word.
    pub closes_unit: Option<TextRange>,
    /// M02 or M30.
    pub ends_program: bool,
    pub transfer: Option<(Transfer, TextRange)>,
}

impl BlockSummary {
    pub(crate) fn of(block: &BlockData, offset: TextSize) -> BlockSummary {
        BlockSummary {
            offset,
            len: block.len,
            number: block.number.and_then(|n| n.value),
            number_range: block.number.map(|n| n.range + offset),
            head: block.words.first().map_or(TextRange::empty(offset), |w| w.range + offset),
            starts_unit: block.has_code(b'G', 79).then(|| literal(block, b'L').map(|(n, _)| n)),
            closes_unit: block.codes(b'G').find(|(c, _)| *c == 70).map(|(_, w)| w.range + offset),
            ends_program: block.has_code(b'M', 2) || block.has_code(b'M', 30),
            transfer: transfer(block).map(|(t, range)| (t, range + offset)),
        }
    }

    fn shifted(&self, by: TextSize) -> BlockSummary {
        let shift = |r: TextRange| r + by;
        BlockSummary {
            offset: self.offset + by,
            number_range: self.number_range.map(shift),
            head: shift(self.head),
            closes_unit: self.closes_unit.map(shift),
            transfer: self.transfer.map(|(t, r)| (t, shift(r))),
            ..*self
        }
    }

    /// Where the block ends.
    pub fn end(&self) -> TextSize {
        self.offset + self.len
    }
}

/// What the program model keeps of a chunk: its blocks' summaries
/// (relative to the chunk), and indexes that let the model and its checks
/// skip the blocks that matter to nothing but themselves.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ChunkSummary {
    pub blocks: Vec<BlockSummary>,
    /// Blocks that start or close a unit, or end the program.
    marks: Vec<u32>,
    /// Blocks with a call or a jump.
    transfers: Vec<u32>,
    /// Block numbers with their blocks, sorted.
    numbers: Vec<(u64, u32)>,
}

impl ChunkSummary {
    pub(crate) fn new(blocks: Vec<BlockSummary>) -> ChunkSummary {
        let indices = |keep: fn(&BlockSummary) -> bool| {
            blocks.iter().enumerate().filter(|(_, b)| keep(b)).map(|(i, _)| i as u32).collect::<Vec<u32>>()
        };
        let marks = indices(|b| b.starts_unit.is_some() || b.closes_unit.is_some() || b.ends_program);
        let transfers = indices(|b| b.transfer.is_some());
        let mut numbers: Vec<(u64, u32)> =
            blocks.iter().enumerate().filter_map(|(i, b)| Some((b.number?, i as u32))).collect();
        numbers.sort_unstable();
        ChunkSummary { blocks, marks, transfers, numbers }
    }
}

/// A chunk in the model: where it starts, and its first block's index.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ChunkBlocks {
    pub offset: TextSize,
    pub first: usize,
    pub summary: Arc<ChunkSummary>,
}

impl ChunkBlocks {
    fn indices<'a>(&'a self, local: &'a [u32]) -> impl Iterator<Item = usize> + 'a {
        local.iter().map(|&i| self.first + i as usize)
    }
}

/// The structure of one file. Blocks are kept per chunk, relative to it,
/// so that an edit rebuilds the model from shared chunk summaries without
/// touching every block.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Program {
    pub kind: FileKind,
    chunks: Vec<ChunkBlocks>,
    block_count: usize,
    pub units: Vec<Unit>,
    /// The block that ends the main body (M02 or M30).
    pub end_of_main: Option<usize>,
    /// `G79` blocks found before the main body's end.
    pub early_unit_starts: Vec<usize>,
    /// Blocks after the main body that belong to no subprogram.
    pub stray_blocks: Vec<usize>,
    /// G70 blocks in the main body.
    pub stray_g70: Vec<usize>,
}

impl Program {
    pub fn block_count(&self) -> usize {
        self.block_count
    }

    /// Block `index`, with file offsets.
    pub fn block(&self, index: usize) -> BlockSummary {
        self.get_block(index).unwrap_or_else(|| panic!("block {index} of {}", self.block_count))
    }

    pub fn get_block(&self, index: usize) -> Option<BlockSummary> {
        let chunk = &self.chunks[self.chunks.partition_point(|c| c.first <= index).checked_sub(1)?];
        chunk.summary.blocks.get(index - chunk.first).map(|b| b.shifted(chunk.offset))
    }

    /// The blocks of `range`, with file offsets.
    pub fn blocks_in(&self, range: Range<usize>) -> impl Iterator<Item = BlockSummary> + '_ {
        range.map(|index| self.block(index))
    }

    /// The index of the block that holds `offset` (a block's end belongs to
    /// it, but where the next block starts the cursor is on that one).
    pub fn block_index_at(&self, offset: TextSize) -> Option<usize> {
        let chunk = self.chunks.partition_point(|c| c.offset <= offset).checked_sub(1)?;
        let chunk = &self.chunks[chunk];
        let local = offset - chunk.offset;
        let blocks = &chunk.summary.blocks;
        let index = blocks.partition_point(|b| b.end() < local);
        let block = blocks.get(index).filter(|b| b.offset <= local)?;
        let next = if block.end() == local { self.get_block(chunk.first + index + 1) } else { None };
        match next {
            Some(next) if next.offset == offset => Some(chunk.first + index + 1),
            _ => Some(chunk.first + index),
        }
    }

    /// The blocks with a call or a jump.
    pub fn transfers(&self) -> impl Iterator<Item = usize> + '_ {
        self.chunks.iter().flat_map(|c| c.indices(&c.summary.transfers))
    }

    /// The blocks numbered `number`, in order.
    pub fn numbered(&self, number: u64) -> impl Iterator<Item = usize> + '_ {
        self.chunks.iter().flat_map(move |c| {
            let numbers = &c.summary.numbers;
            let from = numbers.partition_point(|&(n, _)| n < number);
            numbers[from..].iter().take_while(move |&&(n, _)| n == number).map(|&(_, i)| c.first + i as usize)
        })
    }

    /// Every block number with its block, sorted by number per chunk; the
    /// chunks' number ranges, for finding duplicates without hashing every
    /// block.
    pub(crate) fn chunk_numbers(&self) -> impl Iterator<Item = (usize, &[(u64, u32)])> + '_ {
        self.chunks.iter().map(|c| (c.first, c.summary.numbers.as_slice()))
    }

    /// Whether the file has a main body (the first unit, without a number).
    pub fn has_main(&self) -> bool {
        self.units.first().is_some_and(|u| u.number.is_none())
    }

    /// The index of the unit holding block `index`, if any.
    pub fn unit_index(&self, index: usize) -> Option<usize> {
        // Subprograms do not overlap one another; a misplaced one lies
        // inside the main body's range and owns its blocks.
        let subprograms = usize::from(self.has_main())..self.units.len();
        let found = self.units[subprograms.clone()].partition_point(|u| u.blocks.start <= index);
        let candidate = (found > 0).then(|| subprograms.start + found - 1);
        candidate
            .filter(|&u| self.units[u].blocks.contains(&index))
            .or_else(|| (self.has_main() && self.units[0].blocks.contains(&index)).then_some(0))
    }

    /// The unit holding block `index`.
    pub fn unit_of(&self, index: usize) -> Option<&Unit> {
        self.unit_index(index).map(|u| &self.units[u])
    }

    /// The subprogram `G79 L<number>` of this file.
    pub fn subprogram(&self, number: u32) -> Option<&Unit> {
        self.units.iter().find(|u| u.number == Some(number))
    }

    /// The block a `G73 L<number>` in block `from` jumps to: the first block
    /// with that number in the same unit.
    pub fn jump_target(&self, from: usize, number: u32) -> Option<usize> {
        let unit = self.unit_of(from)?;
        self.numbered(u64::from(number)).find(|index| unit.blocks.contains(index))
    }
}

/// The literal value of the first `letter` word, as an integer.
fn literal(block: &BlockData, letter: u8) -> Option<(u32, TextRange)> {
    block.words_with(letter).find_map(|w| match &w.value {
        Some(Value::Literal(l)) => l.scaled(0).and_then(|v| u32::try_from(v).ok()).map(|v| (v, w.range)),
        _ => None,
    })
}

/// What the `L` of a call or jump names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TransferKind {
    Subprogram,
    Macrocycle,
    Jump,
}

/// The block's call or jump code (G71, G72, G73), whether or not its `L`
/// has a value yet: what the `L` names, and the code's range.
pub(crate) fn transfer_kind(block: &BlockData) -> Option<(TransferKind, TextRange)> {
    let (code, range) = block.codes(b'G').find(|(c, _)| matches!(c, 71..=73)).map(|(c, w)| (c, w.range))?;
    let kind = match code {
        71 => TransferKind::Subprogram,
        72 => TransferKind::Macrocycle,
        _ => TransferKind::Jump,
    };
    Some((kind, range))
}

fn transfer(block: &BlockData) -> Option<(Transfer, TextRange)> {
    let (target, _) = literal(block, b'L')?;
    let (kind, range) = transfer_kind(block)?;
    let transfer = match kind {
        TransferKind::Subprogram => Transfer::Subprogram(target),
        TransferKind::Macrocycle => Transfer::Macrocycle(target),
        TransferKind::Jump => Transfer::Jump(target),
    };
    Some((transfer, range))
}

/// The structure of a file.
#[salsa::tracked(returns(ref))]
pub fn program(db: &dyn Db, file: SourceFile) -> Program {
    let kind = file_kind(db, file);
    let chunks: Vec<ChunkBlocks> = db::file_chunks(db, file)
        .iter()
        .map(|c| ChunkBlocks {
            offset: c.offset,
            first: c.first,
            summary: chunks::chunk_summaries(db, c.chunk).clone(),
        })
        .collect();
    let block_count = chunks.last().map_or(0, |c| c.first + c.summary.blocks.len());
    let mut program = Program {
        kind,
        chunks,
        block_count,
        units: Vec::new(),
        end_of_main: None,
        early_unit_starts: Vec::new(),
        stray_blocks: Vec::new(),
        stray_g70: Vec::new(),
    };
    // Partprograms start in their main body; the other files, and a
    // program file that starts with `G79`, in units only.
    let starts_with_unit = program.get_block(0).is_some_and(|b| b.starts_unit.is_some());
    let mut in_main = kind == FileKind::Program && !starts_with_unit;
    if in_main {
        program.units.push(Unit { number: None, blocks: 0..0, closed: false });
    }
    let mut open: Option<usize> = in_main.then_some(0);
    // The last G70 of the open subprogram after the main body: a body may
    // return from several places, and it ends at its last G70.
    let mut last_g70: Option<usize> = None;
    // Only marked blocks change the state; the blocks between them join
    // the open unit, or none.
    let marks: Vec<usize> = program.chunks.iter().flat_map(|c| c.indices(&c.summary.marks)).collect();
    let mut next = 0;
    for index in marks {
        assign(&mut program, open, next..index);
        next = index + 1;
        let summary = program.block(index);
        if let Some(number) = summary.starts_unit {
            if in_main {
                program.early_unit_starts.push(index);
            }
            end_unit(&mut program, open, last_g70.take());
            program.units.push(Unit { number, blocks: index..index, closed: false });
            open = Some(program.units.len() - 1);
        }
        assign(&mut program, open, index..index + 1);
        let ends_main = in_main && open == Some(0) && summary.ends_program;
        if summary.closes_unit.is_some() {
            match open {
                // A subprogram inside the main body returns to it at its
                // first G70 (it is misplaced anyway).
                Some(u) if in_main && program.units[u].number.is_some() => {
                    program.units[u].closed = true;
                    open = Some(0);
                }
                Some(u) if program.units[u].number.is_some() => {
                    program.units[u].closed = true;
                    last_g70 = Some(index);
                }
                _ => program.stray_g70.push(index),
            }
        }
        if ends_main {
            program.end_of_main = Some(index);
            in_main = false;
            open = None;
        }
    }
    assign(&mut program, open, next..block_count);
    end_unit(&mut program, open, last_g70);
    program
}

/// Puts `blocks` into unit `open`, or among the stray blocks.
fn assign(program: &mut Program, open: Option<usize>, blocks: Range<usize>) {
    if blocks.is_empty() {
        return;
    }
    match open {
        Some(u) => program.units[u].blocks.end = blocks.end,
        None => program.stray_blocks.extend(blocks),
    }
}

/// Ends unit `open` at its last G70, if it has one: the blocks after it
/// belong to no unit, since the body returns before them.
fn end_unit(program: &mut Program, open: Option<usize>, last_g70: Option<usize>) {
    let (Some(unit), Some(last)) = (open, last_g70) else { return };
    let after = last + 1..program.units[unit].blocks.end;
    program.stray_blocks.extend(after);
    program.units[unit].blocks.end = last + 1;
}

/// The kind of a file.
pub fn file_kind(db: &dyn Db, file: SourceFile) -> FileKind {
    let path = file.path(db);
    let kind = FileKind::of(path, prelude(db, file));
    // The file the machine loads as its cycle file is one, even when its
    // `$PC` is missing.
    let configured = db::Settings::get(db).config(db).machine.cycle_file.as_deref();
    let named = configured.is_some_and(|name| file_stem(name).eq_ignore_ascii_case(file_stem(path)));
    if kind == FileKind::Program && named { FileKind::CycleFile } else { kind }
}

/// The text before the first block: comments, and a cycle file's `$PC`.
pub fn prelude(db: &dyn Db, file: SourceFile) -> &str {
    let text = file.text(db);
    let first_block = db::file_chunks(db, file).first().map_or(text.len(), |c| usize::from(c.offset));
    &text[..first_block]
}

/// Whether the file has the `%` header and the `*` end.
pub fn header_and_end(db: &dyn Db, file: SourceFile) -> (bool, bool) {
    let tree = file.parse(db).tree();
    (tree.header().is_some(), tree.end().is_some())
}

/// The macrocycle files of the workspace by number.
#[salsa::tracked(returns(ref))]
pub fn macrocycles(db: &dyn Db) -> FxHashMap<u32, Vec<SourceFile>> {
    let mut map: FxHashMap<u32, Vec<SourceFile>> = FxHashMap::default();
    for &file in db::Settings::get(db).files(db) {
        if let FileKind::Macrocycle(number) = file_kind(db, file) {
            map.entry(number).or_default().push(file);
        }
    }
    map
}
