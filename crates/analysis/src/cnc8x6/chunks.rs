//! The work done per chunk of blocks: lowering, the checks of single
//! blocks and the summaries the program model reads.

use std::sync::Arc;

use ncc_syntax::{TextSize, limit::LineLimiter};

use crate::{
    Diagnostic,
    cnc8x6::{
        checks,
        model::{BlockSummary, ChunkSummary},
    },
    db::{BlockChunk, Db, Settings},
    findings::{self, Findings},
    lower::BlockData,
};

/// The blocks of a chunk lowered, each with its offset from the chunk's
/// start. Lowering is cheap and its results are large, so they are rebuilt
/// on demand rather than stored.
pub(crate) fn lower_chunk<'a>(
    db: &'a dyn Db,
    chunk: BlockChunk<'a>,
) -> impl Iterator<Item = (TextSize, BlockData)> + 'a {
    let mut offset = TextSize::from(0);
    chunk.blocks(db).map(move |green| {
        let block = (offset, BlockData::lower(green));
        offset += green.text_len();
        block
    })
}

/// The findings about the blocks of a chunk that need nothing but each
/// block and the configuration, limited per line of the chunk; ranges
/// relative to the chunk's start.
#[salsa::tracked(returns(ref))]
pub(crate) fn chunk_diagnostics<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Findings {
    let config = Settings::get(db).config(db);
    let text = chunk.green(db).0.to_string();
    let mut limiter = LineLimiter::new(&text);
    let mut diagnostics = Vec::new();
    for (offset, data) in lower_chunk(db, chunk) {
        let mut block: Vec<Diagnostic> =
            checks::block::check(&data, config).into_iter().map(|d| d.shifted(offset)).collect();
        findings::sort_diagnostics(&mut block);
        diagnostics.extend(block.into_iter().filter(|d| limiter.keep(d.range.start(), findings::key(d))));
    }
    Findings { diagnostics, omitted: limiter.finish() }
}

/// What the program model needs of each block of a chunk; ranges relative
/// to the chunk's start.
#[salsa::tracked(returns(ref))]
pub(crate) fn chunk_summaries<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Arc<ChunkSummary> {
    Arc::new(ChunkSummary::new(lower_chunk(db, chunk).map(|(offset, data)| BlockSummary::of(&data, offset)).collect()))
}
