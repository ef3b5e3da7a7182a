//! Where the analysis turns to the dialect in use: one function per thing a
//! dialect does, each an exhaustive `match` on [`Dialect`], so a new
//! dialect is added here and the neutral modules never name one.

use ncc_syntax::{Dialect, TextEdit, TextRange, TextSize};

use crate::{
    Config, DocumentSymbol, Fold, HoverResult, InlayHint, NavigationTarget, Reference, Rule, cnc8x6,
    db::{Db, SourceFile},
    diagnostic, findings,
    findings::Findings,
    haas_lathe, ide,
    lower::{BlockData, Word},
};

/// The rules of the dialect's checks, by check module.
fn check_rules(dialect: Dialect) -> &'static [&'static [&'static Rule]] {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::checks::RULES,
        Dialect::HaasLathe => haas_lathe::checks::RULES,
    }
}

impl Rule {
    /// Every rule: the parser's syntax diagnostics, every dialect's checks,
    /// the report limits, then the executor's.
    pub fn all() -> impl Iterator<Item = &'static Rule> {
        let checks =
            Dialect::all().flat_map(|dialect| check_rules(dialect).iter().flat_map(|rules| rules.iter().copied()));
        diagnostic::syntax_rules().chain(checks).chain(findings::RULES.iter().copied()).chain(diagnostic::run_rules())
    }

    /// The rule with this code or name.
    pub fn find(key: &str) -> Option<&'static Rule> {
        Rule::all().find(|rule| rule.code == key || rule.name == key)
    }
}

/// The findings of `file` that need no flow walk, besides the syntax's.
pub(crate) fn local_findings(db: &dyn Db, file: SourceFile) -> Findings {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => cnc8x6::checks::local_findings(db, file),
        Dialect::HaasLathe => haas_lathe::checks::local_findings(db, file),
    }
}

/// The findings of the rules that follow the program's flow.
pub(crate) fn flow_findings(db: &dyn Db, file: SourceFile) -> &Findings {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => cnc8x6::flow::flow_diagnostics(db, file),
        Dialect::HaasLathe => haas_lathe::checks::flow_findings(db, file),
    }
}

/// Prepares answers about the state anywhere in `file` (see
/// [`crate::Analysis::prepare_states`]).
pub(crate) fn prepare_states(db: &dyn Db, file: SourceFile) {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => cnc8x6::states::prepare(db, file),
        // Hover reads nothing prepared about a Haas file.
        Dialect::HaasLathe => {}
    }
}

/// Whether the machine can run the code `letter` + `number` (completion
/// leaves out those it cannot).
pub(crate) fn code_fits_machine(dialect: Dialect, letter: char, number: u32, config: &Config) -> bool {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::ide::code_fits_machine(letter, number, config),
        // The machine description names no options of a Haas lathe.
        Dialect::HaasLathe => true,
    }
}

/// What the centre words of the block's arc mean, by address letter, when
/// the block draws one.
pub(crate) fn arc_centre(dialect: Dialect, block: &BlockData, config: &Config) -> Vec<(u8, String)> {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::ide::arc_centre(block, config),
        Dialect::HaasLathe => haas_lathe::ide::arc_centre(block),
    }
}

/// Whether `word` is the code that starts a subprogram.
pub(crate) fn starts_unit(dialect: Dialect, block: &BlockData, word: &Word) -> bool {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::ide::starts_unit(block, word),
        // Only `O` starts a program, and it is no word of a block.
        Dialect::HaasLathe => false,
    }
}

/// The name of a subprogram with neither number nor label.
pub(crate) fn unnamed_unit(dialect: Dialect) -> &'static str {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::ide::UNNAMED_UNIT,
        Dialect::HaasLathe => "program",
    }
}

/// What the thing at `offset` is.
pub(crate) fn hover(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<HoverResult> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::hover(db, file, offset),
        Dialect::HaasLathe => haas_lathe::ide::hover(db, file, offset),
    }
}

/// Where the thing at `offset` is defined.
pub(crate) fn goto_definition(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<NavigationTarget> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::goto_definition(db, file, offset),
        Dialect::HaasLathe => haas_lathe::ide::goto_definition(db, file, offset),
    }
}

/// The definition and uses of the thing at `offset`.
pub(crate) fn references(db: &dyn Db, file: SourceFile, offset: TextSize, include_declaration: bool) -> Vec<Reference> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::references::references(db, file, offset, include_declaration),
        Dialect::HaasLathe => haas_lathe::ide::references(db, file, offset, include_declaration),
    }
}

/// The outline.
pub(crate) fn document_symbols(db: &dyn Db, file: SourceFile) -> Vec<DocumentSymbol> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::symbols::document_symbols(db, file),
        Dialect::HaasLathe => haas_lathe::ide::document_symbols(db, file),
    }
}

/// The folds.
pub(crate) fn folding_ranges(db: &dyn Db, file: SourceFile) -> Vec<Fold> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::folding::folding_ranges(db, file),
        Dialect::HaasLathe => haas_lathe::ide::folding_ranges(db, file),
    }
}

/// The edits that format the file.
pub(crate) fn format(db: &dyn Db, file: SourceFile) -> Vec<TextEdit> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::format::format(file.text(db), file.parse(db)),
        // No style is defined for Haas programs yet: formatting changes nothing.
        Dialect::HaasLathe => Vec::new(),
    }
}

/// The inlay hints of the blocks `range` touches.
pub(crate) fn inlay_hints(db: &dyn Db, file: SourceFile, range: Option<TextRange>) -> Vec<InlayHint> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::inlay::inlay_hints(db, file, range),
        // The cycle time's hints come from the run, for every dialect.
        Dialect::HaasLathe => Vec::new(),
    }
}

/// The CNC8x6 walk's states before the block at `offset`; none in a file of
/// another dialect.
pub(crate) fn states_at(
    db: &dyn Db,
    file: SourceFile,
    offset: TextSize,
) -> Vec<(cnc8x6::flow::ModalState, cnc8x6::flow::ParamState)> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => ide::states_at(db, file, offset),
        Dialect::HaasLathe => Vec::new(),
    }
}
