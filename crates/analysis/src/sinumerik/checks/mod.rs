//! The Sinumerik rules (digest §6), coded `K` + the rule's number there;
//! rules the digest does not list are numbered from K101.
//!
//! Rules that read one block ([`block`]) run per chunk of blocks, cached
//! by salsa, so an edit checks again only the chunk it touched; the rules
//! on the whole program ([`program`], [`names`], [`types`]) are one pass
//! each over the file model and come with the flow findings.
//!
//! The rules on motion and technology ([`motion`]), on the order of
//! operations ([`operations`]) and on the tool's orientation
//! ([`orientation`]) read the modal state of one walk over the file
//! ([`crate::sinumerik::walk`]).
//!
//! Not checked here:
//! - rules 1, 2, 10, 11, 12, 13 and 14 are the parser's (`space-in-word`,
//!   `unexpected-character`, `parenthesis-comment`, the block skip's place,
//!   `unclosed-string`, `template-placeholder`; an elided line, `...` or
//!   `…`, is a placeholder or a character the control does not read, and
//!   the seed's listings hold them as comments);
//! - rules 3, 5, 6, 8, 9 are ISO conventions or off for Sinumerik, and
//!   25, 30, 33–36 ISO words (G28, H, G92 as a preset, M97–M98) that
//!   Sinumerik writes otherwise;
//! - rule 17 is the run's timing of G0 (each axis at its own rate, the
//!   slowest deciding), K016 and G0's hover; rule 24 is the run's travel
//!   limit of a rotary axis (E002 `beyond-axis-range`, `limits` in degrees);
//! - rules 21, 73 and 74 are hover: the arc a CR chooses (the editor's
//!   hover over CR), the catalogue's text of CUT3DC and CUT3DF, and the
//!   programmable frame a frame command leaves (the hover over it);
//! - computed jump targets (`GOTOF "N"<<R3`) are the run's.

pub(crate) mod block;
pub(crate) mod calls;
pub(crate) mod motion;
pub(crate) mod names;
pub(crate) mod operations;
pub(crate) mod orientation;
pub(crate) mod parameters;
pub(crate) mod program;
pub(crate) mod types;
pub(crate) mod visit;

use std::{ops::ControlFlow, path::Path};

use nc_exec::sinumerik::lower::Callee;

use crate::{
    Diagnostic, Rule, SinumerikConfig,
    db::{BlockChunk, Db, Settings, SourceFile, file_chunks},
    findings::{self, Findings},
    sinumerik::{
        model::{FileModel, chunk_blocks, file_model, is_main_program},
        walk,
    },
};

/// The rules of every check module.
pub(crate) static RULES: &[&[&Rule]] = &[
    block::RULES,
    calls::RULES,
    program::RULES,
    motion::RULES,
    operations::RULES,
    orientation::RULES,
    names::RULES,
    parameters::RULES,
    types::RULES,
];

/// The findings of a file's single blocks, chunk by chunk.
pub(crate) fn local_findings(db: &dyn Db, file: SourceFile) -> Findings {
    let mut diagnostics = Vec::new();
    for chunk in file_chunks(db, file) {
        diagnostics.extend(chunk_findings(db, chunk.chunk).iter().map(|d| d.clone().shifted(chunk.offset)));
    }
    Findings { diagnostics, omitted: Vec::new() }
}

/// The findings of the single blocks of a chunk; ranges relative to the
/// chunk's start.
#[salsa::tracked(returns(ref))]
fn chunk_findings<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Vec<Diagnostic> {
    let config = Settings::get(db).config(db);
    let text = chunk.green(db).0.to_string();
    let mut start = 0;
    let mut diagnostics = Vec::new();
    for block in chunk_blocks(db, chunk).iter() {
        let end = start + usize::from(block.len);
        let mut found: Vec<Diagnostic> = block::check(block, &text[start..end], config)
            .into_iter()
            .map(|d| d.shifted((start as u32).into()))
            .collect();
        findings::sort_diagnostics(&mut found);
        diagnostics.extend(found);
        start = end;
    }
    diagnostics
}

/// The findings of the rules on the whole program.
#[salsa::tracked(returns(ref))]
pub(crate) fn flow_findings(db: &dyn Db, file: SourceFile) -> Findings {
    let model = file_model(db, file);
    let settings = Settings::get(db);
    let config = settings.config(db);
    let text = file.text(db).as_str();
    let mut signatures = types::Signatures::new();
    for other in settings.files(db) {
        let other_model = file_model(db, *other);
        if let Some(proc) = other_model.model.header() {
            signatures.entry(proc.declaration.name.as_str()).or_insert((other.path(db).as_str(), other_model, proc));
        }
    }
    // A control file (`_N_PART_SPF`) is found as the run finds it.
    let find = |control_name: &str| {
        settings
            .files(db)
            .iter()
            .copied()
            .find(|other| ncc_catalog::is_control_file(Path::new(other.path(db)), control_name))
    };
    let in_workspace = |control_name: &str| find(control_name).is_some();
    let resolve = |callee: &Callee| callee.control_files()?.iter().find_map(|name| find(name));
    let mut diagnostics = program::check(db, model, &in_workspace);
    let main = is_main_program(db, file);
    diagnostics.extend(walk_findings(db, model, main, &config.sinumerik));
    diagnostics.extend(names::check(db, model, text, config));
    let reads: Vec<&parameters::Reads> =
        settings.files(db).iter().map(|other| parameters::parameter_reads(db, *other)).collect();
    let read = |number| reads.iter().any(|reads| reads.any || reads.indices.contains(&number));
    let resolved =
        |callee: &Callee| matches!(callee, Callee::Cycle(_) | Callee::Predefined(_)) || resolve(callee).is_some();
    diagnostics.extend(parameters::check(db, model, &read, &resolved));
    diagnostics.extend(calls::check(db, file, model, main, &resolve));
    diagnostics.extend(types::check(db, model, &signatures));
    findings::sort_diagnostics(&mut diagnostics);
    Findings { diagnostics, omitted: Vec::new() }
}

/// The findings of the rules on the modal state, from one walk.
fn walk_findings(db: &dyn Db, file: &FileModel, main: bool, config: &SinumerikConfig) -> Vec<Diagnostic> {
    let mut motion = motion::Motion::new(file, main);
    let mut operations = operations::Operations::new(config.stock_top);
    let mut orientation = orientation::Orientation::new(&config.ball_nose_tools);
    let mut out = Vec::new();
    walk::walk(db, file, main, |step| {
        motion.step(file, &step, &mut out);
        operations.step(file, &step, &mut out);
        orientation.step(file, &step, &mut out);
        ControlFlow::Continue(())
    });
    motion.report_unreached(file, &mut out);
    out
}

#[cfg(test)]
mod tests;
