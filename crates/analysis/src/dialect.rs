//! Where the analysis turns to the dialect in use: one function per thing a
//! dialect does, each an exhaustive `match` on [`Dialect`], so a new
//! dialect is added here and the neutral modules never name one.

use nc_exec::run::LoweredProgram;
use ncc_syntax::Dialect;

use crate::{
    Config, Rule, cnc8x6,
    db::{Db, SourceFile},
    diagnostic, findings,
    findings::Findings,
    haas_lathe,
    lower::{BlockData, Word},
    sinumerik,
};

/// The rules of the dialect's checks, by check module.
fn check_rules(dialect: Dialect) -> &'static [&'static [&'static Rule]] {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::checks::RULES,
        Dialect::HaasLathe => haas_lathe::checks::RULES,
        Dialect::Sinumerik => sinumerik::checks::RULES,
    }
}

impl Rule {
    /// Every rule: the parser's syntax diagnostics, every dialect's checks,
    /// the report limits, then the executor's.
    pub fn all() -> impl Iterator<Item = &'static Rule> {
        let checks = Dialect::ALL
            .into_iter()
            .flat_map(|dialect| check_rules(dialect).iter().flat_map(|rules| rules.iter().copied()));
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
        Dialect::Sinumerik => sinumerik::checks::local_findings(db, file),
    }
}

/// The findings of the rules that follow the program's flow.
pub(crate) fn flow_findings(db: &dyn Db, file: SourceFile) -> &Findings {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => cnc8x6::flow::flow_diagnostics(db, file),
        Dialect::HaasLathe => haas_lathe::checks::flow_findings(db, file),
        Dialect::Sinumerik => sinumerik::checks::flow_findings(db, file),
    }
}

/// Prepares answers about the state anywhere in `file` (see
/// [`crate::Analysis::prepare_states`]).
pub(crate) fn prepare_states(db: &dyn Db, file: SourceFile) {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => cnc8x6::states::prepare(db, file),
        Dialect::HaasLathe => haas_lathe::states::prepare(db, file),
        // Hover reads nothing prepared about a Sinumerik file.
        Dialect::Sinumerik => {}
    }
}

/// The blocks of `file` as its run reads them, from the analysis's
/// lowered chunks; `None` where the run lowers the text itself.
pub(crate) fn lowered_program(db: &dyn Db, file: SourceFile) -> Option<LoweredProgram> {
    match file.parse(db).dialect() {
        // The run reads its text as it goes.
        Dialect::Cnc8x6 => None,
        Dialect::HaasLathe => Some(LoweredProgram::HaasLathe(haas_lathe::model::file_model(db, file).unit.clone())),
        Dialect::Sinumerik => Some(LoweredProgram::Sinumerik(sinumerik::model::file_model(db, file).unit.clone())),
    }
}

/// Whether the machine can run the code `letter` + `number` (completion
/// leaves out those it cannot).
pub(crate) fn code_fits_machine(dialect: Dialect, letter: char, number: u32, config: &Config) -> bool {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::ide::code_fits_machine(letter, number, config),
        // The machine description names no options of these controls.
        Dialect::HaasLathe | Dialect::Sinumerik => true,
    }
}

/// Whether `word` is the code that starts a subprogram.
pub(crate) fn starts_unit(dialect: Dialect, block: &BlockData, word: &Word) -> bool {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::ide::starts_unit(block, word),
        // Only `O` starts a program, and it is no word of a block.
        Dialect::HaasLathe => false,
        // `PROC` starts one, a statement rather than a word.
        Dialect::Sinumerik => false,
    }
}

/// The name of a subprogram with neither number nor label.
pub(crate) fn unnamed_unit(dialect: Dialect) -> &'static str {
    match dialect {
        Dialect::Cnc8x6 => cnc8x6::ide::UNNAMED_UNIT,
        Dialect::HaasLathe | Dialect::Sinumerik => "program",
    }
}
