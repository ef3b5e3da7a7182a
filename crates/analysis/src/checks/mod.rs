//! The rules, by what they need to decide.

pub(crate) mod block;
