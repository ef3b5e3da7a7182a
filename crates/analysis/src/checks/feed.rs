//! Feed and spindle speed: ranges, limits and constant cutting speed.

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    flow::{FlowCheck, Visit},
};

declare_rules! {}

#[derive(Default)]
pub(crate) struct Feed;

impl FlowCheck for Feed {
    fn block(&mut self, _visit: &Visit<'_>, _out: &mut Vec<Diagnostic>) {}
}
