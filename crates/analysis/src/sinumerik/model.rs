//! A Sinumerik file as the rules and the editor see it: its blocks lowered, where each
//! stands, and the program model (labels, structures, declarations, jumps,
//! calls).
//!
//! Blocks are lowered per chunk ([`chunk_blocks`]): after an edit only the
//! chunk the edit touched is lowered again, and the file model shares the
//! other chunks' blocks. The program model is rebuilt from them, one pass
//! over the blocks.

use std::{path::Path, sync::Arc};

use nc_exec::sinumerik::{lower::SinumerikBlock, program::SinumerikModel};
use ncc_syntax::{TextRange, TextSize};

use crate::db::{BlockChunk, Db, SourceFile, file_chunks};

/// The lowered blocks of a chunk, in order.
#[salsa::tracked(returns(ref))]
pub(crate) fn chunk_blocks<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Arc<Vec<SinumerikBlock>> {
    Arc::new(chunk.blocks(db).map(SinumerikBlock::lower).collect())
}

#[derive(Debug, Clone)]
pub(crate) struct FileModel {
    /// Each block's range in the file.
    pub ranges: Vec<TextRange>,
    /// The chunks' blocks, in order.
    chunks: Vec<Arc<Vec<SinumerikBlock>>>,
    /// The index of each chunk's first block.
    firsts: Vec<usize>,
    pub model: SinumerikModel,
}

/// Chunks an edit did not touch are the same chunks: compared by address,
/// an edit compares the blocks of the chunk it touched only.
impl PartialEq for FileModel {
    fn eq(&self, other: &Self) -> bool {
        self.ranges == other.ranges
            && self.firsts == other.firsts
            && self.chunks.len() == other.chunks.len()
            && self.chunks.iter().zip(&other.chunks).all(|(a, b)| Arc::ptr_eq(a, b) || a == b)
            && self.model == other.model
    }
}

impl FileModel {
    /// Block `index`.
    pub fn block(&self, index: usize) -> &SinumerikBlock {
        let chunk = self.firsts.partition_point(|&first| first <= index) - 1;
        &self.chunks[chunk][index - self.firsts[chunk]]
    }

    /// Every block, in order. A walk over a large file is one long query:
    /// each block read is a point where an edit waiting to change the
    /// inputs cancels it (an atomic load).
    pub fn blocks<'a>(&'a self, db: &'a dyn Db) -> impl Iterator<Item = &'a SinumerikBlock> + Clone {
        self.chunks.iter().flat_map(|chunk| chunk.iter()).inspect(move |_| db.unwind_if_revision_cancelled())
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
}

/// Whether the file is a main program, which starts at reset: no PROC
/// line, and neither its name (`PART.SPF`, `_N_PART_SPF`) nor its header
/// line says a subprogram.
pub(crate) fn is_main_program(db: &dyn Db, file: SourceFile) -> bool {
    let model = file_model(db, file);
    let subprogram = |name: &str| {
        let name = name.to_ascii_uppercase();
        name.ends_with(".SPF") || name.ends_with("_SPF")
    };
    let file_name = Path::new(file.path(db)).file_name().and_then(|name| name.to_str()).unwrap_or_default();
    let header = model.ranges.first().and_then(|_| model.block(0).header.as_ref());
    model.model.header().is_none() && !subprogram(file_name) && !header.is_some_and(|header| subprogram(&header.name))
}

/// The file's model, rebuilt when its text changes.
#[salsa::tracked(returns(ref))]
pub(crate) fn file_model(db: &dyn Db, file: SourceFile) -> FileModel {
    let mut ranges = Vec::new();
    let mut chunks = Vec::new();
    let mut firsts = Vec::new();
    for chunk in file_chunks(db, file) {
        let blocks = chunk_blocks(db, chunk.chunk);
        firsts.push(chunk.first);
        let mut offset = chunk.offset;
        for block in blocks.iter() {
            ranges.push(TextRange::at(offset, block.len));
            offset += block.len;
        }
        chunks.push(blocks.clone());
    }
    // Cancellable at each block, as `FileModel::blocks`.
    let blocks = chunks.iter().flat_map(|chunk| chunk.iter()).inspect(|_| db.unwind_if_revision_cancelled());
    let model = SinumerikModel::new(blocks);
    FileModel { ranges, chunks, firsts, model }
}
