//! The Haas lathe rules (lathe manual §9), coded `L` + the rule's number
//! there; rules the manual does not list are numbered from L101.

pub(crate) mod contours;

use crate::{
    db::{Db, SourceFile},
    findings::Findings,
    haas_lathe::model::file_model,
};

/// The rules of every check module.
pub(crate) static RULES: &[&[&crate::Rule]] = &[contours::RULES];

/// The findings of a file that need no flow walk.
pub(crate) fn local_findings(db: &dyn Db, file: SourceFile) -> Findings {
    let model = file_model(db, file);
    Findings { diagnostics: contours::check(model), omitted: Vec::new() }
}

/// The findings of the rules that follow the program's flow.
#[salsa::tracked(returns(ref))]
pub(crate) fn flow_findings(_db: &dyn Db, _file: SourceFile) -> Findings {
    Findings::default()
}
