//! Parameter arithmetic G26–G29: the control words and their operands.

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    flow::{FlowCheck, Visit},
};

declare_rules! {}

#[derive(Default)]
pub(crate) struct Arithmetic;

impl FlowCheck for Arithmetic {
    fn block(&mut self, _visit: &Visit<'_>, _out: &mut Vec<Diagnostic>) {}
}
