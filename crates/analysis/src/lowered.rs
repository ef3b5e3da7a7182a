//! A file's blocks lowered chunk by chunk, for the dialects whose model is
//! built from lowered blocks (Haas, Sinumerik).
//!
//! Each dialect lowers a chunk in a tracked query of its own, so after an
//! edit only the chunk the edit touched is lowered again, and the file's
//! blocks share the other chunks' vectors, as does a run of the file.

use std::sync::Arc;

pub(crate) use nc_exec::lowered::Lowered;
use ncc_syntax::TextSize;

use crate::{
    db::{BlockChunk, Db, SourceFile, file_chunks},
    interactive::between_blocks,
};

/// The blocks of `file`, each chunk's from `lower` (the dialect's query).
pub(crate) fn lowered<'db, B>(
    db: &'db dyn Db,
    file: SourceFile,
    lower: impl Fn(BlockChunk<'db>) -> Arc<Vec<B>>,
) -> Lowered<B> {
    let chunks = file_chunks(db, file).iter();
    Lowered::from_chunks(
        chunks.map(|chunk| (chunk.offset, lower(chunk.chunk), chunk_lengths(db, chunk.chunk).as_slice())),
    )
}

/// The lengths of a chunk's blocks, apart from the lowered blocks: after
/// an edit the file's block ranges are laid out from them, where reading
/// every lowered block's length cost a cache miss per block.
#[salsa::tracked(returns(ref))]
fn chunk_lengths<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Vec<TextSize> {
    chunk.blocks(db).map(|block| block.text_len()).collect()
}

/// A file's lowered blocks as the analysis reads them.
pub(crate) trait Watched<B> {
    /// Every block, in order. A walk over a large file is one long query:
    /// each block read is a point where an edit waiting to change the
    /// inputs cancels it and a request makes it give way (atomic loads).
    fn blocks<'a>(&'a self, db: &'a dyn Db) -> impl Iterator<Item = &'a B> + Clone
    where
        B: 'a;
}

impl<B> Watched<B> for Lowered<B> {
    fn blocks<'a>(&'a self, db: &'a dyn Db) -> impl Iterator<Item = &'a B> + Clone
    where
        B: 'a,
    {
        self.iter().inspect(move |_| between_blocks(db))
    }
}
