//! The salsa database: inputs and the queries computed from them.
//!
//! Inputs are the files (text and parse, kept in step by the host) and the
//! settings (configuration and the workspace's file list). Per-block work is
//! keyed by the block's green node, interned by identity: after an edit,
//! the incremental reparse keeps every untouched block's node, so only the
//! blocks the edit touched are lowered and checked again.

use std::{
    hash::{Hash, Hasher},
    sync::{Arc, Mutex},
};

use ncc_syntax::{
    Parse, SyntaxKind, SyntaxNode, TextSize,
    ast::{self, AstNode},
};
use rowan::GreenNode;

use crate::{Config, Diagnostic, lower::BlockData};

#[salsa::db]
pub trait Db: salsa::Database {}

/// A program file of the workspace.
#[salsa::input(debug)]
pub struct SourceFile {
    #[returns(ref)]
    pub path: String,
    #[returns(ref)]
    pub text: Arc<str>,
    /// The parse of `text`; the host updates both together, reparsing
    /// incrementally after an edit.
    #[returns(ref)]
    pub parse: Parse,
}

/// What holds for the whole workspace.
#[salsa::input(singleton, debug)]
pub struct Settings {
    #[returns(ref)]
    pub config: Config,
    /// Every file of the workspace (main programs and macrocycle files).
    #[returns(ref)]
    pub files: Vec<SourceFile>,
}

/// A block's green node, compared and hashed by identity: blocks the
/// reparse kept are the same node, and the interned value keeps the node
/// alive, so an address is never reused while it is a key.
#[derive(Debug, Clone)]
pub struct BlockGreen(pub GreenNode);

impl PartialEq for BlockGreen {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq::<rowan::GreenNodeData>(&*self.0, &*other.0)
    }
}

impl Eq for BlockGreen {}

impl Hash for BlockGreen {
    fn hash<H: Hasher>(&self, state: &mut H) {
        std::ptr::hash::<rowan::GreenNodeData, H>(&*self.0, state);
    }
}

#[salsa::interned(debug)]
pub struct BlockSyntax<'db> {
    #[returns(ref)]
    pub green: BlockGreen,
}

/// A block of a file and where it starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, salsa::SalsaValue)]
pub struct FileBlock<'db> {
    pub syntax: BlockSyntax<'db>,
    pub offset: TextSize,
}

/// The blocks of a file, in order.
#[salsa::tracked(returns(ref))]
pub fn file_blocks(db: &dyn Db, file: SourceFile) -> Vec<FileBlock<'_>> {
    let root = file.parse(db).syntax_node();
    root.children()
        .filter(|node| node.kind() == SyntaxKind::BLOCK)
        .map(|node| FileBlock {
            syntax: BlockSyntax::new(db, BlockGreen(node.green().to_owned())),
            offset: node.text_range().start(),
        })
        .collect()
}

/// One block as plain data, ranges relative to its start.
#[salsa::tracked(returns(ref))]
pub fn lower_block<'db>(db: &'db dyn Db, block: BlockSyntax<'db>) -> BlockData {
    let node = SyntaxNode::new_root(block.green(db).0.clone());
    BlockData::lower(&ast::Block::cast(node).expect("interned blocks are BLOCK nodes"))
}

/// The findings about one block that need nothing but the block and the
/// configuration; ranges relative to the block's start.
#[salsa::tracked(returns(ref))]
pub fn block_diagnostics<'db>(db: &'db dyn Db, block: BlockSyntax<'db>) -> Vec<Diagnostic> {
    let config = Settings::get(db).config(db);
    crate::checks::block::check(lower_block(db, block), config)
}

/// The database. Cloning it gives a handle for another thread.
#[salsa::db]
#[derive(Clone, Default)]
pub struct RootDatabase {
    storage: salsa::Storage<Self>,
    log: Option<Arc<Mutex<Vec<String>>>>,
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
impl Db for RootDatabase {}
