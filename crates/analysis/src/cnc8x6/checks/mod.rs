//! The rules, by what they need to decide.

pub(crate) mod arith;
pub(crate) mod block;
pub(crate) mod cycles;
pub(crate) mod dynamics;
pub(crate) mod feed;
pub(crate) mod geometry;
pub(crate) mod motion;
pub(crate) mod params;
pub(crate) mod structure;
pub(crate) mod threads;
pub(crate) mod transform;

use crate::{
    cnc8x6::{chunks, flow::FlowCheck},
    db::{self, Db, SourceFile},
    findings::Findings,
};

/// The rules of every check module.
pub(crate) static RULES: &[&[&crate::Rule]] = &[
    block::RULES,
    structure::RULES,
    params::RULES,
    arith::RULES,
    motion::RULES,
    geometry::RULES,
    feed::RULES,
    threads::RULES,
    transform::RULES,
    cycles::RULES,
    dynamics::RULES,
];

/// The findings of a file that need no flow walk: of its blocks, one by
/// one, and of its structure.
pub(crate) fn local_findings(db: &dyn Db, file: SourceFile) -> Findings {
    let mut all = Findings::default();
    for chunk in db::file_chunks(db, file) {
        all.append(chunks::chunk_diagnostics(db, chunk.chunk).clone().shifted(chunk.offset));
    }
    all.diagnostics.extend(structure::check(db, file));
    all.diagnostics.extend(cycles::check_file(db, file));
    all
}

/// The checks that follow the program's flow, fresh for one walk.
pub(crate) fn flow_checks() -> Vec<Box<dyn FlowCheck>> {
    vec![
        Box::new(params::Parameters),
        Box::new(arith::Arithmetic::default()),
        Box::new(motion::Motion::default()),
        Box::new(geometry::Geometry),
        Box::new(feed::Feed::default()),
        Box::new(threads::Threads::default()),
        Box::new(transform::Transformations::default()),
        Box::new(cycles::Cycles::default()),
        Box::new(dynamics::Dynamics::default()),
    ]
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    use crate::Rule;

    #[test]
    fn codes_and_names_are_unique() {
        let mut codes = HashSet::new();
        let mut names = HashSet::new();
        for rule in Rule::all() {
            assert!(codes.insert(rule.code), "code {} twice", rule.code);
            assert!(names.insert(rule.name), "name {} twice", rule.name);
            assert!(rule.summary.ends_with('.'), "{}: summary is a sentence", rule.name);
        }
    }
}
