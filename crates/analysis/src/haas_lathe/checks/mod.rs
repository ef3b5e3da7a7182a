//! The Haas lathe rules (lathe manual §9), coded `L` + the rule's number
//! there; rules the manual does not list, and second parts of a rule with
//! another severity, are numbered from L101.
//!
//! Rules 12 and 13 are the parser's (`doubled-decimal-point`,
//! `space-in-word`, `template-placeholder`); rule 33 says what not to flag
//! (G70 without roughing). Rule 51 (the feed of G84/G184 against S × the
//! pitch) is not checked: no word of the program states the pitch, under
//! G99 F is the pitch itself and under G98 F ÷ S is the only pitch there
//! is, so nothing can disagree.

pub(crate) mod block;
pub(crate) mod compensation;
pub(crate) mod contours;
pub(crate) mod cycles;
pub(crate) mod motion;
pub(crate) mod program;

use std::collections::BTreeSet;

use crate::{
    Diagnostic, Rule,
    db::{Db, Settings, SourceFile, file_chunks},
    findings::Findings,
    haas_lathe::{
        model::file_model,
        walk::{Visit, walk},
    },
    interactive::between_blocks,
};

/// The rules of every check module.
pub(crate) static RULES: &[&[&Rule]] =
    &[block::RULES, motion::RULES, compensation::RULES, contours::RULES, cycles::RULES, program::RULES];

/// The findings of a file that need no flow walk.
pub(crate) fn local_findings(db: &dyn Db, file: SourceFile) -> Findings {
    let model = file_model(db, file);
    let mut diagnostics = Vec::new();
    for chunk in file_chunks(db, file) {
        diagnostics.extend(block::chunk_findings(db, chunk.chunk).iter().map(|d| d.clone().shifted(chunk.offset)));
    }
    diagnostics.extend(contours::check(model));
    diagnostics.extend(compensation::check(model));
    diagnostics.extend(program::check(model));
    Findings { diagnostics: distinct(diagnostics), omitted: Vec::new() }
}

/// The findings of the rules that follow the program's flow.
#[salsa::tracked(returns(ref))]
pub(crate) fn flow_findings(db: &dyn Db, file: SourceFile) -> Findings {
    let model = file_model(db, file);
    let config = Settings::get(db).config(db);
    let mut out = Out::default();
    // A long walk: an edit waiting to change the inputs cancels it.
    walk(model, &mut |visit| {
        between_blocks(db);
        motion::visit(visit, config, &mut out);
        compensation::visit(visit, &mut out);
        contours::visit(visit, &mut out);
        cycles::visit(visit, &mut out);
        program::visit(visit, &mut out);
    });
    Findings { diagnostics: distinct(out.diagnostics), omitted: Vec::new() }
}

/// A contour is read, and walked, for every cycle that names it: one
/// finding each, with the first cycle's related places.
fn distinct(mut diagnostics: Vec<Diagnostic>) -> Vec<Diagnostic> {
    let key = |d: &Diagnostic| (d.range.start(), d.range.end(), d.code, d.message.clone());
    diagnostics.sort_by_key(key);
    diagnostics.dedup_by_key(|d| key(d));
    diagnostics
}

/// What the walk's rules find.
#[derive(Default)]
pub(crate) struct Out {
    diagnostics: Vec<Diagnostic>,
    /// The rules reported once per program, with the program.
    reported: BTreeSet<(&'static str, usize)>,
}

impl Out {
    pub(crate) fn push(&mut self, diagnostic: Diagnostic) {
        self.diagnostics.push(diagnostic);
    }

    /// Pushes the finding of a rule that one cause makes true for the rest
    /// of a program (no F yet, no motion code yet): its first only.
    pub(crate) fn once(&mut self, visit: &Visit<'_>, diagnostic: Diagnostic) {
        if self.reported.insert((diagnostic.code, visit.program)) {
            self.diagnostics.push(diagnostic);
        }
    }
}

#[cfg(test)]
mod tests {
    use nc_exec::haas_lathe::{
        lower::{HaasBlock, block_nodes},
        program::ProgramModel,
    };
    use ncc_syntax::{Dialect, Parse, TextSize};
    use proptest::prelude::*;

    use crate::{AnalysisHost, Config, haas_lathe::model::file_model};

    proptest! {
        /// Whatever the blocks and their order, the rules answer, inside
        /// the text, from the model the run has.
        #[test]
        fn any_program_is_checked(lines in prop::collection::vec(prop::sample::select(vec![
            "O1", "O2", "%", "G54 G00 X40. Z2.", "G01 Z-10. F0.2", "X#1 Z[#2 * 2.]", "G02 X50. Z-15. R-5.",
            "G03 U10. W-5. I5.", "G01 X30. K-3.", "G01 Z-20. I2. R1.", "G01 A110. X50.", "G42", "G40 G02 X1.",
            "G41 G01 X20. Z0", "T202", "G71 P10 Q20 U0.3 D2. F0.3", "G70 P10 Q20", "G73 P20 Q10 D0",
            "N10 G00 X20.", "N20 G01 X40. Z-30.", "N10 G02 X1. Z1.", "G81 Z-5. R2. F0.1", "Z-8.", "C90.", "G80",
            "G76 X27. Z-30. K-1. A60. P5 F2.", "G92 X30. Z-20. F2.", "G32 Z-10.", "M23", "G96 S200", "G50 S2000",
            "G53 X-100. Z-200.", "M97 P10", "M98 P2", "G65 P9010 A1.", "#1 = #1 + 1", "IF [#1 LT 3] GOTO 10",
            "GOTO #1", "WHILE [#1 LT 3] DO1", "END1", "/ G01 X10. F0.1", "M30", "M99", "G04", "X..", "",
        ]), 0..40), copies in 1..20usize) {
            // Copies make files of several chunks.
            let text = vec![lines.join("\n"); copies].join("\n");
            let mut host = AnalysisHost::in_dialect(Dialect::HaasLathe, Config::default());
            let file = host.add_file("O1.nc", text.as_str());
            for diagnostic in host.analysis().diagnostics(file) {
                prop_assert!(diagnostic.range.end() <= TextSize::of(text.as_str()), "{diagnostic:?}");
            }
            // The model read through the chunks' marked blocks is the one
            // the run reads from every block.
            let parse = Parse::new(&text, Dialect::HaasLathe);
            let blocks: Vec<HaasBlock> = block_nodes(parse.green()).map(|(_, block)| HaasBlock::lower(block)).collect();
            let model = file_model(host.db(), file);
            prop_assert_eq!(model.count(), blocks.len());
            prop_assert_eq!(&model.model, &ProgramModel::new(blocks.as_slice()));
        }
    }
}
