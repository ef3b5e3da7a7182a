//! The Sinumerik dialect's part of the analysis: the file's blocks and
//! program model, read once per edit, for what the editor features ask.

pub(crate) mod model;
