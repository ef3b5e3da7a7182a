//! Rule 65: an R parameter set with a comment that says what it means, which
//! no program of the workspace reads (L29's `R7=1 ;1=G01, 2=BSPLINE`).
//!
//! R parameters are global: any program of the workspace may read them, so
//! every file's reads count. A program that calls a program the workspace
//! does not have, or reads an R parameter by a computed index (`R[R1]`),
//! may read any of them: then the rule stays quiet.

use nc_exec::sinumerik::lower::{Callee, Expr, ExprKind, PlaceKind, StatementKind};
use rustc_hash::FxHashSet;

use crate::lowered::Watched;
use crate::{
    Diagnostic,
    db::{Db, SourceFile},
    diagnostic::declare_rules,
    sinumerik::{
        checks::visit::{all_exprs, written_places},
        model::{FileModel, file_model},
    },
};

declare_rules! {
    PARAMETER_NEVER_READ = "K065", "parameter-never-read", Info, "An R parameter set with a comment on its meaning that no program of the workspace reads.", unnecessary;
}

/// The R parameters a file reads.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Reads {
    /// By their index written as a number.
    pub indices: FxHashSet<u64>,
    /// An index computed (`R[R1]`): any parameter may be read.
    pub any: bool,
}

/// The literal index of an R parameter place, if it is one.
fn literal_index(indices: &[Expr]) -> Option<Option<u64>> {
    match indices {
        [Expr { kind: ExprKind::Number(number), .. }] => Some(number.whole()),
        _ => None,
    }
}

/// The R parameters `file` reads.
#[salsa::tracked(returns(ref))]
pub(crate) fn parameter_reads(db: &dyn Db, file: SourceFile) -> Reads {
    let mut reads = Reads::default();
    for block in file_model(db, file).blocks(db) {
        all_exprs(&block.statements, &mut |expr| {
            let ExprKind::Name(place) = &expr.kind else { return };
            if place.kind != PlaceKind::Parameter {
                return;
            }
            match literal_index(&place.indices) {
                Some(Some(index)) => {
                    reads.indices.insert(index);
                }
                _ => reads.any = true,
            }
        });
    }
    reads
}

/// `read`: whether a program of the workspace may read R parameter n;
/// `resolved`: whether the workspace has the program a call names.
pub(crate) fn check(
    db: &dyn Db,
    file: &FileModel,
    read: &dyn Fn(u64) -> bool,
    resolved: &dyn Fn(&Callee) -> bool,
) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let calls_elsewhere = file.model.calls.iter().any(|site| !resolved(&site.callee));
    if calls_elsewhere {
        return out;
    }
    for (index, block) in file.blocks(db).enumerate() {
        let Some(comment) = block.comments.first().filter(|c| !c.body.trim().is_empty()) else { continue };
        for statement in &block.statements {
            if !matches!(statement.kind, StatementKind::Assign { .. }) {
                continue;
            }
            written_places(statement, &mut |place, statement| {
                let Some(Some(number)) = literal_index(&place.indices).filter(|_| place.kind == PlaceKind::Parameter)
                else {
                    return;
                };
                if read(number) {
                    return;
                }
                let message = format!(
                    "R{number} is set and its comment says what it means ({}), but no program of the workspace reads it",
                    comment.body.trim()
                );
                out.push(Diagnostic::new(&PARAMETER_NEVER_READ, file.in_file(index, statement.range), message));
            });
        }
    }
    out
}
