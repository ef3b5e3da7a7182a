//! A Sinumerik file as the rules and the editor see it: its blocks lowered, where each
//! stands, and the program model (labels, structures, declarations, jumps,
//! calls).
//!
//! Blocks are lowered per chunk ([`chunk_blocks`]): after an edit only the
//! chunk the edit touched is lowered again, and the file model shares the
//! other chunks' blocks. The program model is rebuilt from what each chunk
//! lists of them: its numbered blocks and the few others the model reads.

use std::{ops::Deref, path::Path, sync::Arc};

use crate::{
    db::{BlockChunk, Db, SourceFile, file_chunks},
    interactive::between_blocks,
    lowered::lowered,
};
use nc_exec::sinumerik::{
    Unit,
    lower::SinumerikBlock,
    program::{SinumerikModel, block_number, marked},
};

/// The lowered blocks of a chunk, in order.
#[salsa::tracked(returns(ref))]
pub(crate) fn chunk_blocks<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Arc<Vec<SinumerikBlock>> {
    Arc::new(chunk.blocks(db).map(SinumerikBlock::lower).collect())
}

/// What the program model reads of a chunk: its numbered blocks and its
/// marked ones, by index in the chunk.
#[derive(Debug, PartialEq, Eq)]
struct ChunkMarks {
    numbered: Vec<(u64, u32)>,
    marked: Vec<u32>,
}

#[salsa::tracked(returns(ref))]
fn chunk_marks<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> ChunkMarks {
    let blocks = || chunk_blocks(db, chunk).iter().enumerate().map(|(index, block)| (index as u32, block));
    ChunkMarks {
        numbered: blocks().filter_map(|(index, block)| Some((block_number(block)?, index))).collect(),
        marked: blocks().filter(|(_, block)| marked(block)).map(|(index, _)| index).collect(),
    }
}

/// The file's blocks and program model, as a run of its text reads them
/// too.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FileModel {
    pub unit: Arc<Unit>,
}

/// A file model is its unit: the blocks, with the program model beside
/// them.
impl Deref for FileModel {
    type Target = Unit;

    fn deref(&self) -> &Unit {
        &self.unit
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
    let blocks = lowered(db, file, |chunk| chunk_blocks(db, chunk).clone());
    let chunks = file_chunks(db, file);
    let numbered = chunks.iter().flat_map(|chunk| {
        let numbered = chunk_marks(db, chunk.chunk).numbered.iter();
        numbered.map(|&(number, index)| (number, chunk.first + index as usize))
    });
    let marked = chunks.iter().flat_map(|chunk| {
        let blocks = chunk_blocks(db, chunk.chunk);
        let marked = chunk_marks(db, chunk.chunk).marked.iter();
        marked.map(|&index| (chunk.first + index as usize, &blocks[index as usize])).inspect(|_| between_blocks(db))
    });
    let model = SinumerikModel::from_marks(numbered, marked);
    FileModel { unit: Arc::new(Unit { blocks, model }) }
}
