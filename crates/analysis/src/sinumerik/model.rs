//! A Sinumerik file as the analysis sees it: its blocks lowered, where each
//! stands, and the program model (labels, block numbers, structures, PROC,
//! EXTERN and DEF declarations, jumps, calls).

use nc_exec::sinumerik::{
    lower::{SinumerikBlock, block_nodes},
    program::SinumerikModel,
};
use ncc_syntax::{TextRange, TextSize};

use crate::db::{Db, SourceFile};

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FileModel {
    /// Each block's range in the file.
    pub ranges: Vec<TextRange>,
    pub blocks: Vec<SinumerikBlock>,
    pub model: SinumerikModel,
}

impl FileModel {
    /// A range of block `index` (block-relative) in the file.
    pub fn in_file(&self, index: usize, range: TextRange) -> TextRange {
        range + self.ranges[index].start()
    }

    /// The index of the block that starts at `start`.
    pub fn block_starting_at(&self, start: TextSize) -> Option<usize> {
        self.ranges.binary_search_by_key(&start, |range| range.start()).ok()
    }
}

/// The file's model, rebuilt when its text changes.
#[salsa::tracked(returns(ref))]
pub(crate) fn file_model(db: &dyn Db, file: SourceFile) -> FileModel {
    let parse = file.parse(db);
    let (ranges, blocks): (Vec<TextRange>, Vec<SinumerikBlock>) =
        block_nodes(parse.green()).map(|(range, block)| (range, SinumerikBlock::lower(block))).unzip();
    let model = SinumerikModel::new(&blocks);
    FileModel { ranges, blocks, model }
}
