//! A Haas file as the rules see it: its blocks lowered, where each stands,
//! and the program model (programs, block numbers, contours, references).
//!
//! Blocks are lowered per chunk ([`chunk_blocks`]): after an edit only the
//! chunk the edit touched is lowered again. The program model is rebuilt
//! from them.

use std::{
    ops::{Deref, Range},
    sync::Arc,
};

use nc_exec::haas_lathe::{
    interpreter::Unit,
    lower::{HaasBlock, Statement},
    program::{Blocks, ProgramModel, Reference, ReferenceKind, marked},
};
use ncc_syntax::TextRange;

use crate::{
    db::{BlockChunk, Db, SourceFile, file_chunks},
    lowered::{Lowered, lowered},
};

/// The lowered blocks of a chunk, in order.
#[salsa::tracked(returns(ref))]
pub(crate) fn chunk_blocks<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Arc<Vec<HaasBlock>> {
    Arc::new(chunk.blocks(db).map(HaasBlock::lower).collect())
}

/// The indices in a chunk of the blocks the program model reads.
#[salsa::tracked(returns(ref))]
fn chunk_marks<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Vec<u32> {
    let blocks = chunk_blocks(db, chunk).iter();
    blocks.enumerate().filter(|(_, block)| marked(block)).map(|(index, _)| index as u32).collect()
}

/// The file's blocks, with the indices of the marked ones.
#[derive(Debug, Clone, Copy)]
pub(crate) struct HaasBlocks<'a> {
    lowered: &'a Lowered<HaasBlock>,
    /// In order.
    marks: &'a [usize],
}

impl Blocks for HaasBlocks<'_> {
    fn count(&self) -> usize {
        self.lowered.count()
    }

    fn at(&self, index: usize) -> &HaasBlock {
        self.lowered.block(index)
    }

    fn span(&self, range: Range<usize>) -> impl Iterator<Item = &HaasBlock> {
        self.lowered.blocks_from(range.start).take(range.len())
    }

    fn marked(&self, range: Range<usize>) -> impl Iterator<Item = usize> {
        let first = self.marks.partition_point(|&index| index < range.start);
        self.marks[first..].iter().copied().take_while(move |&index| index < range.end)
    }
}

/// The file's blocks and program model, as a run of its text reads them
/// too, and which blocks the model reads.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FileModel {
    pub unit: Arc<Unit>,
    /// In order.
    marks: Vec<usize>,
}

/// A file model is its unit: the blocks, with the program model beside
/// them.
impl Deref for FileModel {
    type Target = Unit;

    fn deref(&self) -> &Unit {
        &self.unit
    }
}

impl FileModel {
    /// The blocks, with the ones the program model reads.
    pub fn blocks(&self) -> HaasBlocks<'_> {
        HaasBlocks { lowered: &self.unit.blocks, marks: &self.marks }
    }

    /// Where block `index`'s word `letter` + `number` stands in the file,
    /// or the block's start when it has none.
    pub fn code_range(&self, index: usize, letter: u8, number: u32) -> TextRange {
        self.in_file(index, code_range(self.block(index), letter, number))
    }

    /// Where a reference's number stands: the P or Q word, or the GOTO
    /// statement.
    pub fn reference_range(&self, reference: Reference) -> TextRange {
        let letter = match reference.kind {
            ReferenceKind::ContourEnd => b'Q',
            ReferenceKind::Goto => {
                let goto = self.block(reference.block).statements.iter().map(statement_range).next();
                return self.in_file(reference.block, goto.unwrap_or_default());
            }
            _ => b'P',
        };
        self.word_range(reference.block, letter).unwrap_or_else(|| self.in_file(reference.block, TextRange::default()))
    }

    /// Block `index`'s number word in the file, else its start.
    pub fn number_range(&self, index: usize) -> TextRange {
        self.in_file(index, self.block(index).number.map_or_else(TextRange::default, |number| number.range))
    }

    /// Where block `index`'s first word `letter` stands in the file.
    pub fn word_range(&self, index: usize, letter: u8) -> Option<TextRange> {
        self.block(index).word(letter).map(|w| self.in_file(index, w.range))
    }
}

/// Where `block`'s word `letter` + `number` stands in it, or its start
/// when it has none.
pub(crate) fn code_range(block: &HaasBlock, letter: u8, number: u32) -> TextRange {
    let word = block
        .words
        .iter()
        .find(|w| w.letter == letter && w.value.as_ref().and_then(|v| v.whole_number()) == Some(u64::from(number)));
    word.map_or(TextRange::empty(0.into()), |w| w.range)
}

/// The file's model, rebuilt when its text changes.
#[salsa::tracked(returns(ref))]
pub(crate) fn file_model(db: &dyn Db, file: SourceFile) -> FileModel {
    let blocks = lowered(db, file, |chunk| chunk_blocks(db, chunk).clone());
    let marks: Vec<usize> = file_chunks(db, file)
        .iter()
        .flat_map(|chunk| chunk_marks(db, chunk.chunk).iter().map(|&index| chunk.first + index as usize))
        .collect();
    let model = ProgramModel::new(&HaasBlocks { lowered: &blocks, marks: &marks });
    FileModel { unit: Arc::new(Unit { blocks, model }), marks }
}

fn statement_range(statement: &Statement) -> TextRange {
    match statement {
        Statement::Assign { range, .. }
        | Statement::If { range, .. }
        | Statement::Goto { range, .. }
        | Statement::LoopStart { range, .. }
        | Statement::LoopEnd { range, .. } => *range,
    }
}
