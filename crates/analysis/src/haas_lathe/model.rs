//! A Haas file as the rules see it: its blocks lowered, where each stands,
//! and the program model (programs, block numbers, contours, references).

use nc_exec::haas_lathe::{
    lower::{HaasBlock, block_nodes},
    program::ProgramModel,
};
use ncc_syntax::TextRange;

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
