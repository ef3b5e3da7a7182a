//! The Siemens Sinumerik dialect's part of the analysis: the file's blocks,
//! lowered per chunk, the program model over them, and the rules; the
//! editor features read the same model.

pub(crate) mod checks;
pub(crate) mod model;
pub(crate) mod walk;

/// The longest block the control reads (004:284-286).
pub(crate) const MAX_BLOCK_CHARS: usize = 512;
