//! The Haas lathe dialect's part of the analysis: the file's blocks and
//! program model, read once per edit, the rules, and what the editor
//! features ask the dialect.

pub(crate) mod checks;
pub(crate) mod ide;
pub(crate) mod model;
pub(crate) mod states;
pub(crate) mod walk;
