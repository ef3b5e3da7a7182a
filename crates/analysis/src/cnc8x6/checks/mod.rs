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

use crate::cnc8x6::flow::FlowCheck;

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
    crate::findings::RULES,
];

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
