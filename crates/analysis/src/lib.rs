//! Semantic analysis of partprograms.
//!
//! An [`AnalysisHost`] owns the incremental database: programs go in as
//! text, edits are applied as text edits (reparsing only the touched
//! blocks), and an [`Analysis`] snapshot answers questions: diagnostics,
//! hover, go to definition and the state at a block. Every
//! answer is plain Rust data with text ranges; line/column conversion, LSP
//! and terminal output are the caller's business.

mod changed;
pub mod cnc8x6;
mod config;
mod db;
mod diagnostic;
mod dialect;
mod findings;
mod haas_lathe;
mod ide;
pub mod interactive;
mod lowered;
mod sinumerik;
mod suppress;

use std::sync::Arc;

/// Blocks as plain data, lowered the same way for the executor.
pub(crate) use nc_exec::cnc8x6::lower;
/// What the flow walk may not know.
pub use nc_exec::known::Known;
use ncc_syntax::Parse;
pub use ncc_syntax::{Dialect, Severity, TextEdit, TextRange, TextSize};
pub use salsa::Cancelled;
use salsa::Setter;

use crate::db::{Db, Settings};
pub use crate::ide::{
    completion::{CompletionItem, CompletionKind},
    cycle_time::{
        BlockTime, BlockTimes, BreakAt, CycleTimeHints, CycleTotals, Estimate, RunInput, WorkspaceFiles, clock,
        estimate, short_time,
    },
    folding::{Fold, FoldKind},
    highlight::{HighlightKind, HighlightRange},
    inlay::{InlayHint, InlayHintKind},
    references::{Reference, ReferenceKind},
    symbols::{DocumentSymbol, SymbolKind},
};
pub use crate::{
    config::{
        CONFIG_FILE, Config, CycleVersion, Dialects, FormatConfig, LetterCase, Level, MachineConfig, NumberStyle,
        ReportConfig, SinumerikConfig, WordOrder, WordSpacing, parse_constant,
    },
    db::{RootDatabase, SourceFile},
    diagnostic::{Diagnostic, Fix, Related, Rule},
    findings::{Findings, OmittedFindings},
    ide::{HoverResult, NavigationTarget, Renaming, SignatureHelp, SignatureParameter, renumber::RenumberError},
    suppress::Suppressions,
};

/// A file of the analysis.
pub type FileId = SourceFile;

/// Owns the database; the only way to change inputs.
pub struct AnalysisHost {
    db: RootDatabase,
}

impl Default for AnalysisHost {
    fn default() -> Self {
        AnalysisHost::new(Config::default())
    }
}

impl AnalysisHost {
    /// A host whose files are in the default dialect.
    pub fn new(config: Config) -> AnalysisHost {
        AnalysisHost::in_dialect(Dialect::default(), config)
    }

    /// A host whose files are in `dialect`: a workspace is one project in
    /// one dialect (a program calls only programs of its own dialect).
    pub fn in_dialect(dialect: Dialect, config: Config) -> AnalysisHost {
        AnalysisHost::with_database(RootDatabase::default(), dialect, config)
    }

    /// A host over `db` (e.g. one that logs executions).
    pub fn with_database(db: RootDatabase, dialect: Dialect, config: Config) -> AnalysisHost {
        Settings::new(&db, dialect, config.for_dialect(dialect), Vec::new());
        AnalysisHost { db }
    }

    /// Adds a file of the workspace (a program or a macrocycle file).
    pub fn add_file(&mut self, path: impl Into<String>, text: impl Into<String>) -> FileId {
        let text = Arc::new(text.into());
        let parse = Parse::new(&text, self.dialect());
        let file = SourceFile::new(&self.db, path.into(), text, parse);
        let settings = Settings::get(&self.db);
        let mut files = settings.files(&self.db).clone();
        files.push(file);
        settings.set_files(&mut self.db).to(files);
        file
    }

    /// Removes a file from the workspace, and everything computed from it
    /// (its handle must not be used again).
    pub fn remove_file(&mut self, file: FileId) {
        self.release(file);
        let settings = Settings::get(&self.db);
        let files: Vec<SourceFile> = settings.files(&self.db).iter().copied().filter(|&f| f != file).collect();
        // A new revision: salsa frees the results `release` replaced.
        settings.set_files(&mut self.db).to(files);
    }

    /// Replaces a file's text; what was computed from the old one goes at
    /// once, not when the file is next analysed (a document that closes
    /// may never be).
    pub fn set_text(&mut self, file: FileId, text: impl Into<String>) {
        self.replace_text(file, Arc::new(text.into()));
    }

    fn replace_text(&mut self, file: FileId, text: Arc<String>) {
        self.release(file);
        let parse = Parse::new(&text, self.dialect());
        file.set_text(&mut self.db).to(text);
        file.set_parse(&mut self.db).to(parse);
    }

    /// Lets go of everything computed from a file's text. Salsa keeps a
    /// query's result until the query runs again, and an input for good;
    /// so the file's queries run once on an empty text, which leaves next
    /// to nothing, and the chunks of its old tree go with their results.
    /// The results replaced are freed at the next revision.
    fn release(&mut self, file: FileId) {
        if let Some(cache) = self.db.dialect_cache().get() {
            cache.forget(file);
        }
        let empty = Parse::new("", self.dialect());
        file.set_text(&mut self.db).to(Arc::default());
        file.set_parse(&mut self.db).to(empty);
        self.analysis().diagnostics(file);
    }

    /// Applies an edit, reparsing only the blocks it touches.
    pub fn apply_edit(&mut self, file: FileId, edit: &TextEdit) {
        // Taking the text out of the database (which cancels the snapshots)
        // lets a text nobody else holds be edited in place: copying a large
        // file on every keystroke costs more than everything else an edit
        // does.
        let mut text = file.set_text(&mut self.db).to(Arc::default());
        let replaces_most = edit.delete.len() + edit.delete.len() > TextSize::of(text.as_str());
        match Arc::get_mut(&mut text) {
            Some(owned) => edit.apply(owned),
            None => {
                let mut copy = String::with_capacity(text.len() + edit.insert.len());
                copy.push_str(&text);
                edit.apply(&mut copy);
                text = Arc::new(copy);
            }
        }
        // An edit of most of the text (a paste over it, a whole format)
        // is a new text: what was computed from the old one goes first, as
        // in `set_text`. Its results are then freed before the new text is
        // analysed, not held beside the new ones until the next key, which
        // would wait for them to be dropped.
        if replaces_most {
            return self.replace_text(file, text);
        }
        let parse = file.parse(&self.db).reparse(edit, &text);
        file.set_text(&mut self.db).to(text);
        file.set_parse(&mut self.db).to(parse);
    }

    fn dialect(&self) -> Dialect {
        *Settings::get(&self.db).dialect(&self.db)
    }

    pub fn set_config(&mut self, config: Config) {
        Settings::get(&self.db).set_config(&mut self.db).to(config);
    }

    /// A snapshot for queries, usable from another thread.
    pub fn analysis(&self) -> Analysis {
        Analysis { db: self.db.clone() }
    }

    /// The database, for tests that inspect query executions.
    pub fn db(&self) -> &RootDatabase {
        &self.db
    }
}

impl std::fmt::Debug for AnalysisHost {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AnalysisHost").finish_non_exhaustive()
    }
}

/// Answers about the current inputs. Clones answer in parallel.
#[derive(Clone)]
pub struct Analysis {
    db: RootDatabase,
}

impl std::fmt::Debug for Analysis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Analysis").finish_non_exhaustive()
    }
}

impl Analysis {
    /// Every diagnostic of a file after configuration and suppression
    /// comments, sorted by position.
    pub fn diagnostics(&self, file: FileId) -> Vec<Diagnostic> {
        let mut all = self.local_findings(file);
        all.append(self.flow_findings(file));
        self.limit(file, all)
    }

    /// The findings that need no flow walk (syntax, blocks, program
    /// structure): after an edit these cost only the edited chunk, so an
    /// editor can show them at once and the flow findings when they come.
    /// Unlimited: [`Analysis::limit`] makes them a report.
    pub fn local_findings(&self, file: FileId) -> Findings {
        local_findings(&self.db, file).clone()
    }

    /// The findings of the rules that follow the program's flow,
    /// configured; unlimited.
    pub fn flow_findings(&self, file: FileId) -> Findings {
        configured_flow_findings(&self.db, file).clone()
    }

    /// The diagnostics every report of `file` shows: at most
    /// `ncc_syntax::limit::PER_LINE` a line and the configured number a
    /// file, sorted, with one finding each that counts what was left out.
    pub fn limit(&self, file: FileId, findings: Findings) -> Vec<Diagnostic> {
        let max_per_file = Settings::get(&self.db).config(&self.db).report.max_findings;
        findings::limit(file.text(&self.db), findings, max_per_file)
    }

    /// What the thing at `offset` is: a code's or an address's
    /// documentation, a parameter's with its known values there.
    pub fn hover(&self, file: FileId, offset: TextSize) -> Option<HoverResult> {
        ide::hover(&self.db, file, offset)
    }

    /// Where the thing at `offset` is defined: a call's subprogram or
    /// macrocycle file, a jump's block, the assignments a parameter's value
    /// comes from.
    pub fn goto_definition(&self, file: FileId, offset: TextSize) -> Vec<NavigationTarget> {
        ide::goto_definition(&self.db, file, offset)
    }

    /// The modal state and parameters before the block at `offset` of a
    /// CNC8x6 program, each time the program reaches it.
    pub fn states_at(
        &self,
        file: FileId,
        offset: TextSize,
    ) -> Vec<(cnc8x6::flow::ModalState, cnc8x6::flow::ParamState)> {
        ide::states_at(&self.db, file, offset)
    }

    /// Prepares answers about the modal state (hover) anywhere in the main
    /// body: walks it once, or after an edit across the edit, leaving
    /// checkpoints. Long, but a question meanwhile waits a millisecond at
    /// most; meant for idle time.
    pub fn prepare_states(&self, file: FileId) {
        dialect::prepare_states(&self.db, file);
    }

    /// The outline: program units, and the blocks jumps go to in each.
    pub fn document_symbols(&self, file: FileId) -> Vec<DocumentSymbol> {
        ide::document_symbols(&self.db, file)
    }

    /// Program units and runs of comment lines, sorted by start.
    pub fn folding_ranges(&self, file: FileId) -> Vec<Fold> {
        ide::folding_ranges(&self.db, file)
    }

    /// Every token classified, for semantic highlighting.
    pub fn highlight(&self, file: FileId) -> Vec<HighlightRange> {
        ide::highlight::highlight(&self.db, file, None)
    }

    /// The highlighting of the blocks (and header, end) that overlap `range`.
    pub fn highlight_range(&self, file: FileId, range: TextRange) -> Vec<HighlightRange> {
        ide::highlight::highlight(&self.db, file, Some(range))
    }

    /// The name at `offset` that [`Analysis::rename`] would change, or why
    /// none can be renamed there.
    pub fn prepare_rename(&self, file: FileId, offset: TextSize) -> Result<TextRange, String> {
        ide::prepare_rename(&self.db, file, offset)
    }

    /// The edits that give the name at `offset` the name `new_name`
    /// wherever it is written (a program: in every file of the workspace,
    /// and its file renamed), or why they cannot (the name is not one the
    /// control takes, or is taken).
    pub fn rename(&self, file: FileId, offset: TextSize, new_name: &str) -> Result<Renaming, String> {
        ide::rename(&self.db, file, offset, new_name)
    }

    /// The signature of the call whose parentheses hold `offset`, with the
    /// parameter there.
    pub fn signature_help(&self, file: FileId, offset: TextSize) -> Option<SignatureHelp> {
        ide::signature_help(&self.db, file, offset)
    }

    /// The definition (with `include_declaration`) and the uses of the
    /// subprogram, macrocycle, jump target or parameter at `offset`.
    pub fn references(&self, file: FileId, offset: TextSize, include_declaration: bool) -> Vec<Reference> {
        ide::references(&self.db, file, offset, include_declaration)
    }

    /// The edits that format the file in the project's style (`[format]`
    /// in `ncc.toml`; what it does is in `ide/format.rs`): one per changed
    /// line, sorted. With `range`, only the lines it touches change.
    pub fn format(&self, file: FileId, range: Option<TextRange>) -> Vec<TextEdit> {
        ide::format(&self.db, file, range)
    }

    /// The edits that renumber the file's blocks `start`, `start + step`,
    /// … in file order and rewrite every reference to them (jumps, contour
    /// P/Q, local calls) to its block's new number; or, where a target is
    /// computed, missing or ambiguous, why renumbering could change what
    /// the program does.
    pub fn renumber(&self, file: FileId, start: u64, step: u64) -> Result<Vec<TextEdit>, RenumberError> {
        ide::renumber(&self.db, file, start, step)
    }

    /// What may be written at `offset`, most relevant first.
    pub fn completions(&self, file: FileId, offset: TextSize) -> Vec<CompletionItem> {
        ide::completion::completions(&self.db, file, offset)
    }

    /// The inlay hints of the blocks `range` touches (of every block
    /// without one).
    pub fn inlay_hints(&self, file: FileId, range: Option<TextRange>) -> Vec<InlayHint> {
        ide::inlay_hints(&self.db, file, range)
    }

    /// What a run of the program `file` needs (its text, the machine, the
    /// workspace's macrocycle and cycle files), to estimate its cycle time
    /// without holding this snapshot; `None` for a macrocycle or cycle file.
    pub fn run_input(&self, file: FileId) -> Option<RunInput> {
        ide::cycle_time::run_input(&self.db, file)
    }

    /// Where a program's totals belong: its `%` header, or its first block.
    pub fn program_head(&self, file: FileId) -> Option<TextRange> {
        ide::cycle_time::program_head(&self.db, file)
    }

    /// The language of every file.
    pub fn dialect(&self) -> Dialect {
        *Settings::get(&self.db).dialect(&self.db)
    }

    pub fn path(&self, file: FileId) -> String {
        file.path(&self.db).clone()
    }

    /// The file's text. Holding it past the next edit makes that edit copy
    /// the text instead of changing it in place.
    pub fn text(&self, file: FileId) -> Arc<String> {
        file.text(&self.db).clone()
    }
}

/// Syntax, block and program-structure findings of a file, configured.
#[salsa::tracked(returns(ref))]
fn local_findings(db: &dyn Db, file: SourceFile) -> Findings {
    let parse = file.parse(db);
    let mut all = Findings {
        diagnostics: parse.errors().iter().map(Diagnostic::from_syntax).collect(),
        omitted: parse.omitted().iter().map(|o| o.map(|kind| (kind.code(), kind.severity()))).collect(),
    };
    all.append(dialect::local_findings(db, file));
    configure(db, file, all)
}

/// The flow walk's findings of a file, configured.
#[salsa::tracked(returns(ref))]
fn configured_flow_findings(db: &dyn Db, file: SourceFile) -> Findings {
    configure(db, file, dialect::flow_findings(db, file).clone())
}

/// Applies suppression comments and the configured levels, and limits
/// per line.
fn configure(db: &dyn Db, file: SourceFile, all: Findings) -> Findings {
    let config = Settings::get(db).config(db);
    let suppressions = Suppressions::of(file.text(db), file.parse(db));
    let diagnostics = all
        .diagnostics
        .into_iter()
        .filter(|d| !suppressions.silences(d.range.start(), d.code, d.name))
        .filter_map(|d| config.adjust(d))
        .collect();
    let omitted = all
        .omitted
        .into_iter()
        .filter_map(|o| {
            let (code, severity) = o.kind;
            let name = Rule::find(code).map_or(code, |rule| rule.name);
            if suppressions.silences(o.at, code, name) {
                return None;
            }
            let severity = config.severity(code, name, severity)?;
            Some(o.map(|_| (code, severity)))
        })
        .collect();
    Findings::of(file.text(db), diagnostics, omitted)
}
