//! A Haas file as the rules see it: its blocks lowered, where each stands,
//! and the program model (programs, block numbers, contours, references).

use nc_exec::haas_lathe::{
    lower::{HaasBlock, Statement, block_nodes},
    program::{ProgramModel, Reference, ReferenceKind},
};
use ncc_syntax::{TextRange, TextSize};

use crate::db::{Db, SourceFile};

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FileModel {
    /// Each block's range in the file.
    pub ranges: Vec<TextRange>,
    pub blocks: Vec<HaasBlock>,
    pub model: ProgramModel,
}

impl FileModel {
    /// A range of block `index` (block-relative) in the file.
    pub fn in_file(&self, index: usize, range: TextRange) -> TextRange {
        range + self.ranges[index].start()
    }

    /// Where block `index`'s word `letter` + `number` stands in the file,
    /// or the block's start when it has none.
    pub fn code_range(&self, index: usize, letter: u8, number: u32) -> TextRange {
        let word = self.blocks[index]
            .words
            .iter()
            .find(|w| w.letter == letter && w.value.as_ref().and_then(|v| v.whole_number()) == Some(u64::from(number)));
        self.in_file(index, word.map_or(TextRange::empty(0.into()), |w| w.range))
    }

    /// Where a reference's number stands: the P or Q word, or the GOTO
    /// statement.
    pub fn reference_range(&self, reference: Reference) -> TextRange {
        let letter = match reference.kind {
            ReferenceKind::ContourEnd => b'Q',
            ReferenceKind::Goto => {
                let goto = self.blocks[reference.block].statements.iter().map(statement_range).next();
                return self.in_file(reference.block, goto.unwrap_or_default());
            }
            _ => b'P',
        };
        self.word_range(reference.block, letter).unwrap_or_else(|| self.in_file(reference.block, TextRange::default()))
    }

    /// Block `index`'s number word in the file, else its start.
    pub fn number_range(&self, index: usize) -> TextRange {
        self.in_file(index, self.blocks[index].number.map_or_else(TextRange::default, |number| number.range))
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

    /// Where block `index`'s first word `letter` stands in the file.
    pub fn word_range(&self, index: usize, letter: u8) -> Option<TextRange> {
        self.blocks[index].word(letter).map(|w| self.in_file(index, w.range))
    }
}

/// The file's model, rebuilt when its text changes.
#[salsa::tracked(returns(ref))]
pub(crate) fn file_model(db: &dyn Db, file: SourceFile) -> FileModel {
    let parse = file.parse(db);
    let (ranges, blocks): (Vec<TextRange>, Vec<HaasBlock>) =
        block_nodes(parse.green()).map(|(range, block)| (range, HaasBlock::lower(block))).unzip();
    let model = ProgramModel::new(&blocks);
    FileModel { ranges, blocks, model }
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
