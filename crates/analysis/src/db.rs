//! The salsa database: inputs and the queries computed from them.
//!
//! Inputs are the files (text and parse, kept in step by the host) and the
//! settings (configuration and the workspace's file list). Block work is
//! keyed by chunks of blocks identified by their nodes: after an edit, the
//! incremental reparse keeps every untouched block's node, so only the
//! chunk the edit touched is lowered and checked again.

use std::sync::{Arc, Mutex, OnceLock};

use ncc_syntax::{Dialect, Parse, SyntaxKind, TextSize};
use rowan::GreenNode;

use crate::Config;

#[salsa::db]
pub trait Db: salsa::Database {
    /// What the dialect of the settings keeps outside salsa, made by its
    /// first use: a database holds files of one dialect.
    fn dialect_cache(&self) -> &OnceLock<Box<dyn DialectCache>>;
}

/// What a dialect keeps about files outside salsa, because it stays valid
/// across edits (the checkpoints of the flow walk's state). Unwind safe, as
/// a snapshot's question may be cancelled by unwinding.
pub trait DialectCache: std::any::Any + Send + Sync + std::panic::RefUnwindSafe + std::panic::UnwindSafe {
    /// Lets go of what is kept about `file`.
    fn forget(&self, file: SourceFile);
}

/// A program file of the workspace.
#[salsa::input(debug)]
pub struct SourceFile {
    #[returns(ref)]
    pub path: String,
    #[returns(ref)]
    pub text: Arc<String>,
    /// The parse of `text`; the host updates both together, reparsing
    /// incrementally after an edit.
    #[returns(ref)]
    pub parse: Parse,
}

/// What holds for the whole workspace.
#[salsa::input(singleton, debug)]
pub struct Settings {
    /// The language of every file; the parser and the catalogue follow it.
    pub dialect: Dialect,
    #[returns(ref)]
    pub config: Config,
    /// Every file of the workspace (main programs and macrocycle files).
    #[returns(ref)]
    pub files: Vec<SourceFile>,
}

/// A chunk's node, compared by identity: nodes the reparse kept are the
/// same node.
#[derive(Debug, Clone)]
pub struct BlockGreen(pub GreenNode);

impl PartialEq for BlockGreen {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq::<rowan::GreenNodeData>(&*self.0, &*other.0)
    }
}

impl Eq for BlockGreen {}

/// The unit of incremental work: a run of blocks (`BLOCK_RUN`), or one
/// block outside any run (words before the first numbered block). Chunks
/// keep every query small (salsa's bookkeeping gets slow for queries with
/// a million dependencies) and memory low (per-block results are kept as a
/// compact summary, full block data is rebuilt when needed). The reparse
/// rebuilds only the runs an edit touches, so the other chunks, and their
/// results, stay as they were.
///
/// [`file_chunks`] creates the chunks of a file's tree and gives each its
/// node, so a chunk whose node the tree no longer has goes, with its node
/// and its results, when `file_chunks` runs again. (Interned, replaced
/// chunks stayed until salsa happened to reuse their slots, ever more over
/// a long session; and a field of a tracked struct stays in its slot after
/// the struct goes, until the slot is reused.)
#[salsa::tracked(debug)]
pub struct BlockChunk<'db> {
    /// Where the chunk's node is: it identifies the chunk among those
    /// `file_chunks` created before, whose nodes live while they do.
    address: usize,
}

/// The node of a chunk, which `file_chunks` gives every chunk it creates.
#[salsa::tracked(returns(ref), specify)]
fn chunk_green<'db>(_db: &'db dyn Db, _chunk: BlockChunk<'db>) -> BlockGreen {
    unreachable!("file_chunks gives every chunk it creates its node")
}

impl<'db> BlockChunk<'db> {
    pub(crate) fn green(self, db: &'db dyn Db) -> &'db BlockGreen {
        chunk_green(db, self)
    }

    /// The chunk's run node, when it is a run rather than a lone block.
    fn run(self, db: &'db dyn Db) -> Option<&'db rowan::GreenNodeData> {
        let node: &'db rowan::GreenNodeData = &self.green(db).0;
        (node.kind() == SyntaxKind::BLOCK_RUN.into()).then_some(node)
    }

    /// The chunk's blocks, in order.
    pub fn blocks(self, db: &'db dyn Db) -> impl Iterator<Item = &'db rowan::GreenNodeData> + 'db {
        let run = self.run(db);
        let lone = run.is_none().then(|| &*self.green(db).0);
        let in_run = run.map(|run| run.children().filter_map(rowan::NodeOrToken::into_node)).into_iter().flatten();
        lone.into_iter().chain(in_run)
    }

    /// Block `at` of the chunk.
    pub fn block(self, db: &'db dyn Db, at: usize) -> Option<&'db rowan::GreenNodeData> {
        match self.run(db) {
            Some(run) => run.children().nth(at)?.into_node(),
            None => (at == 0).then(|| &*self.green(db).0),
        }
    }

    pub fn len(self, db: &'db dyn Db) -> usize {
        self.run(db).map_or(1, |run| run.children().len())
    }
}

/// A chunk of a file, where it starts, and the index of its first block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, salsa::SalsaValue)]
pub struct FileChunk<'db> {
    pub chunk: BlockChunk<'db>,
    pub offset: TextSize,
    pub first: usize,
}

/// The file's blocks in chunks, in order.
#[salsa::tracked(returns(ref))]
pub fn file_chunks(db: &dyn Db, file: SourceFile) -> Vec<FileChunk<'_>> {
    // The green tree is walked directly: red nodes would allocate.
    let root = file.parse(db).green();
    let mut chunks = Vec::new();
    let mut offset = TextSize::from(0);
    let mut first = 0;
    for child in root.children() {
        let len = child.text_len();
        if let rowan::NodeOrToken::Node(node) = child
            && (node.kind() == SyntaxKind::BLOCK.into() || node.kind() == SyntaxKind::BLOCK_RUN.into())
        {
            let chunk = BlockChunk::new(db, std::ptr::from_ref(node).addr());
            chunk_green::specify(db, chunk, BlockGreen(node.to_owned()));
            chunks.push(FileChunk { chunk, offset, first });
            first += chunk.len(db);
        }
        offset += len;
    }
    chunks
}

/// The database. Cloning it gives a handle for another thread.
#[salsa::db]
#[derive(Clone, Default)]
pub struct RootDatabase {
    storage: salsa::Storage<Self>,
    log: Option<Arc<Mutex<Vec<String>>>>,
    dialect_cache: Arc<OnceLock<Box<dyn DialectCache>>>,
}

impl RootDatabase {
    /// A database that records which queries execute, for tests.
    pub fn with_execution_log() -> RootDatabase {
        let log: Arc<Mutex<Vec<String>>> = Arc::default();
        let sink = log.clone();
        RootDatabase {
            storage: salsa::Storage::new(Some(Box::new(move |event: salsa::Event| {
                if let salsa::EventKind::WillExecute { database_key } = event.kind {
                    sink.lock().expect("log lock").push(format!("{database_key:?}"));
                }
            }))),
            log: Some(log),
            dialect_cache: Arc::default(),
        }
    }

    /// The queries executed since the last call (with an execution log).
    pub fn take_executions(&self) -> Vec<String> {
        self.log.as_ref().map(|log| std::mem::take(&mut *log.lock().expect("log lock"))).unwrap_or_default()
    }
}

impl std::fmt::Debug for RootDatabase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RootDatabase").finish_non_exhaustive()
    }
}

#[salsa::db]
impl salsa::Database for RootDatabase {}

#[salsa::db]
impl Db for RootDatabase {
    fn dialect_cache(&self) -> &OnceLock<Box<dyn DialectCache>> {
        &self.dialect_cache
    }
}

#[cfg(test)]
mod tests {
    use super::file_chunks;
    use crate::{AnalysisHost, TextEdit, TextRange, TextSize};

    /// An edit replaces the chunk it touched: the database keeps the chunks
    /// of the current tree and their results, not those of every chunk an
    /// edit of a long session replaced.
    #[test]
    fn replaced_chunks_go_with_their_results() {
        let blocks = 3000;
        let mut text = String::from("%1 \"CHUNKS\"\n");
        for n in 1..=blocks {
            text.push_str(&format!("N{n} G01 X{n}. Y-{n}.\n"));
        }
        text.push_str("N9999 M30\n*\n");
        let mut host = AnalysisHost::default();
        let file = host.add_file("main.NCP", text.as_str());
        for n in (7..blocks).step_by(11) {
            let at = text.find(&format!("N{n} G01 X")).unwrap() + format!("N{n} G01 X").len();
            let edit = TextEdit::replace(TextRange::empty(TextSize::from(at as u32)), "1");
            host.apply_edit(file, &edit);
            edit.apply(&mut text);
            assert!(host.analysis().local_findings(file).diagnostics.is_empty());
        }
        let chunks = file_chunks(host.db(), file).len();
        assert!(chunks > 5, "{chunks} chunks");
        let db: &mut dyn salsa::Database = &mut host.db;
        let usage = db.memory_usage();
        let kept = usage.structs.iter().find(|s| s.debug_name() == "BlockChunk").map(|s| s.count());
        assert_eq!(kept, Some(chunks), "chunks kept, {chunks} in the tree");
        for query in ["chunk_diagnostics", "chunk_summaries"] {
            assert_eq!(usage.queries.get(query).map(|q| q.count()), Some(chunks), "results of {query}");
        }
    }
}
