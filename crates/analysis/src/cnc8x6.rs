//! The CNC8x6 dialect's part of the analysis: its program model (units,
//! block numbers, calls and jumps), the walk in run order with its modal
//! and parameter state, the checkpoints of that state for hover, and the
//! rules.

pub(crate) mod checks;
pub(crate) mod chunks;
pub mod flow;
pub(crate) mod ide;
pub(crate) mod model;
pub(crate) mod states;
