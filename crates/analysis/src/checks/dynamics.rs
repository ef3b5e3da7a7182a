//! Path dynamics: continuity modes G23/G24, block durations, junctions.

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    flow::{FlowCheck, Visit},
};

declare_rules! {}

#[derive(Default)]
pub(crate) struct Dynamics;

impl FlowCheck for Dynamics {
    fn block(&mut self, _visit: &Visit<'_>, _out: &mut Vec<Diagnostic>) {}
}
