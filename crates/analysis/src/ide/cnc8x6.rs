//! The editor's answers that only a CNC8x6 file gives.

pub(crate) mod completion;
pub(crate) mod renumber;
