//! Coordinate transformations (G31, G34–G39) and zero offsets.

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    flow::{FlowCheck, Visit},
};

declare_rules! {}

#[derive(Default)]
pub(crate) struct Transformations;

impl FlowCheck for Transformations {
    fn block(&mut self, _visit: &Visit<'_>, _out: &mut Vec<Diagnostic>) {}
}
