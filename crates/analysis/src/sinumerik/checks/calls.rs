//! Rules on the calls between the workspace's programs (digest §6 rules 37
//! and 41), over the programs the calls find in the workspace.
//!
//! Assumptions, where the digest is silent:
//! - Rule 41 counts the levels a main program's calls reach through the
//!   workspace's programs; a call of a program the workspace does not
//!   have, a computed call and a call back into a program already on the
//!   way (recursion, the run's E008) add nothing.
//! - Rule 37 reads only a repetition count written as a number, and a
//!   subprogram that writes a frame or work offset, or moves
//!   incrementally (G91, IC), as one that moves somewhere else each run.

use std::path::Path;

use nc_exec::sinumerik::{
    lower::{Callee, Dimension, StatementKind, WordValue},
    modes::groups::{FRAMES, WORK_OFFSETS},
    program::PROGRAM_LEVELS,
};
use ncc_catalog::Dialect;
use ncc_syntax::TextRange;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::lowered::Watched;
use crate::{
    Diagnostic,
    db::{Db, SourceFile},
    diagnostic::declare_rules,
    sinumerik::{
        checks::visit::{g_number, is_transformation},
        model::{FileModel, file_model},
        walk::PATH_AXES,
    },
};

declare_rules! {
    REPEATED_IN_PLACE = "K037", "repeated-in-place", Warning, "A subprogram called to run several times (P) that moves to absolute coordinates and shifts no frame or work offset: every run machines the same place.";
    CALL_DEPTH = "K041", "program-levels-exceeded", Error, "Calls nested deeper than the control's 16 program levels, or a cycle, which takes 3 levels, called from deeper than the 11th subprogram.";
}

/// The deepest level a cycle may be called from: the 11th subprogram, the
/// main program being level 1 (004:1464-1466).
const CYCLE_CALLER_LEVEL: usize = 12;

/// The workspace's program a call runs, if the workspace has it.
pub(crate) type Resolve<'a> = dyn Fn(&Callee) -> Option<SourceFile> + 'a;

/// How deep a program's calls reach below it.
#[derive(Clone, Copy)]
struct Reach {
    /// The levels of the longest chain of calls from the program down,
    /// its own included.
    levels: usize,
    /// The level, the program's own being 1, of the deepest program on
    /// the way that calls a cycle.
    cycle_caller: Option<usize>,
    /// The program the longest chain goes on to.
    next: Option<SourceFile>,
}

struct Depths<'a> {
    db: &'a dyn Db,
    resolve: &'a Resolve<'a>,
    known: FxHashMap<SourceFile, Reach>,
    on_the_way: FxHashSet<SourceFile>,
}

impl Depths<'_> {
    fn reach(&mut self, file: SourceFile) -> Reach {
        if let Some(reach) = self.known.get(&file) {
            return *reach;
        }
        self.on_the_way.insert(file);
        let mut reach = Reach { levels: 1, cycle_caller: None, next: None };
        for site in &file_model(self.db, file).model.calls {
            if let Some(below) = self.below(&site.callee) {
                let (levels, cycle_caller, next) = below;
                if levels + 1 > reach.levels {
                    reach.levels = levels + 1;
                    reach.next = next;
                }
                reach.cycle_caller = reach.cycle_caller.max(cycle_caller.map(|level| level + 1));
            } else if matches!(site.callee, Callee::Cycle(_)) {
                reach.cycle_caller = reach.cycle_caller.max(Some(1));
            }
        }
        self.on_the_way.remove(&file);
        self.known.insert(file, reach);
        reach
    }

    /// The reach of the program a call runs: its levels, its cycle
    /// caller's level, itself.
    fn below(&mut self, callee: &Callee) -> Option<(usize, Option<usize>, Option<SourceFile>)> {
        let called = (self.resolve)(callee).filter(|called| !self.on_the_way.contains(called))?;
        let reach = self.reach(called);
        Some((reach.levels, reach.cycle_caller, Some(called)))
    }

    /// The names of the programs down the longest chain from `file`.
    fn chain(&self, mut file: Option<SourceFile>) -> Vec<String> {
        let mut names = Vec::new();
        while let Some(at) = file {
            names.push(file_name(self.db, at));
            file = self.known.get(&at).and_then(|reach| reach.next);
        }
        names
    }
}

fn file_name(db: &dyn Db, file: SourceFile) -> String {
    let path = file.path(db);
    Path::new(path).file_name().and_then(|name| name.to_str()).unwrap_or(path).to_owned()
}

/// Rule 41, for a main program; rule 37 for every program.
pub(crate) fn check(
    db: &dyn Db,
    file: SourceFile,
    model: &FileModel,
    main: bool,
    resolve: &Resolve<'_>,
) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    if main {
        depth(db, file, model, resolve, &mut out);
    }
    repeated(db, model, resolve, &mut out);
    out
}

/// The range of the call statement of `site` in its block.
fn call_range(model: &FileModel, block: usize, callee: &Callee) -> TextRange {
    let statement = model.block(block).statements.iter().find(|statement| match &statement.kind {
        StatementKind::Call(call) | StatementKind::ModalCall(Some(call)) => call.callee == *callee,
        _ => false,
    });
    model.in_file(block, statement.map_or_else(TextRange::default, |statement| statement.range))
}

fn depth(db: &dyn Db, file: SourceFile, model: &FileModel, resolve: &Resolve<'_>, out: &mut Vec<Diagnostic>) {
    let mut depths = Depths { db, resolve, known: FxHashMap::default(), on_the_way: FxHashSet::from_iter([file]) };
    let mut levels_reported = false;
    let mut cycle_reported = false;
    for site in &model.model.calls {
        let Some((levels, cycle_caller, next)) = depths.below(&site.callee) else { continue };
        let range = call_range(model, site.block, &site.callee);
        let chain = || [file_name(db, file)].into_iter().chain(depths.chain(next)).collect::<Vec<_>>().join(" → ");
        if levels + 1 > PROGRAM_LEVELS && !levels_reported {
            levels_reported = true;
            let message = format!(
                "this call leads {} program levels deep ({}): the control has {PROGRAM_LEVELS}, the main program's included",
                levels + 1,
                chain()
            );
            out.push(Diagnostic::new(&CALL_DEPTH, range, message));
        }
        if let Some(level) = cycle_caller.map(|level| level + 1)
            && level > CYCLE_CALLER_LEVEL
            && !cycle_reported
        {
            cycle_reported = true;
            let message = format!(
                "down this call a cycle is called from program level {level}: a cycle takes 3 levels, so it may be called from the 11th subprogram (level {CYCLE_CALLER_LEVEL}) at the deepest"
            );
            out.push(Diagnostic::new(&CALL_DEPTH, range, message));
        }
    }
}

/// Rule 37: a program called with a repetition count above 1.
fn repeated(db: &dyn Db, model: &FileModel, resolve: &Resolve<'_>, out: &mut Vec<Diagnostic>) {
    for site in &model.model.calls {
        let statement = model.block(site.block).statements.iter().find_map(|statement| match &statement.kind {
            StatementKind::Call(call) if call.callee == site.callee => Some((statement, call)),
            _ => None,
        });
        let Some((statement, call)) = statement else { continue };
        let runs = match call.repetitions.as_deref() {
            Some(WordValue::Literal(number)) => number.value(),
            _ => continue,
        };
        if runs <= 1.0 {
            continue;
        }
        let Some(called) = resolve(&site.callee) else { continue };
        let Some(absolute) = *in_place(db, called) else { continue };
        let message = format!(
            "{} runs {runs} times and moves to absolute coordinates with no frame or work offset shifted between the runs: each run machines the same place; program the subprogram incrementally (G91) or shift a frame in it (ATRANS) (004:1248-1258)",
            file_name(db, called)
        );
        let range = model.in_file(site.block, statement.range);
        out.push(Diagnostic::new(&REPEATED_IN_PLACE, range, message).with_related(
            Some(called.path(db).clone()),
            absolute,
            "a move to absolute coordinates",
        ));
    }
}

/// The first move to absolute coordinates of a program that never moves
/// incrementally and shifts no frame or work offset, or `None`.
#[salsa::tracked(returns(ref))]
fn in_place(db: &dyn Db, file: SourceFile) -> Option<TextRange> {
    let catalogue = Dialect::Sinumerik.catalogue();
    let model = file_model(db, file);
    let mut first = None;
    for (index, block) in model.blocks(db).enumerate() {
        for statement in &block.statements {
            match &statement.kind {
                StatementKind::Command(command) => {
                    let shifts = catalogue.word_code(&command.name).is_some_and(|code| {
                        matches!(code.group.as_deref(), Some(FRAMES | WORK_OFFSETS)) || code.code == "G91"
                    }) || is_transformation(&command.name);
                    if shifts {
                        return None;
                    }
                }
                StatementKind::Word(word) if word.address == "G" => {
                    let code = g_number(word).and_then(|n| catalogue.code('G', n));
                    // A code the catalogue does not list (`G505`) may shift.
                    if code.is_none_or(|code| code.group.as_deref() == Some(WORK_OFFSETS) || code.code == "G91") {
                        return None;
                    }
                }
                StatementKind::Word(word) if PATH_AXES.contains(&word.address.as_str()) => {
                    if matches!(&word.value, Some(WordValue::Expr { dimension: Some(Dimension::Incremental), .. })) {
                        return None;
                    }
                    first.get_or_insert(model.in_file(index, word.range));
                }
                _ => {}
            }
        }
    }
    first
}
