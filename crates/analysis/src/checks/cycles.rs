//! Fixed cycles G81–G89: calls, their parameters and the cycle file.

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    flow::{FlowCheck, Visit},
};

declare_rules! {}

#[derive(Default)]
pub(crate) struct Cycles;

impl FlowCheck for Cycles {
    fn block(&mut self, _visit: &Visit<'_>, _out: &mut Vec<Diagnostic>) {}
}
