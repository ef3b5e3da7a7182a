//! The executor of partprograms.
//!
//! It will lower syntax trees to an executable form, run them on a model of
//! the control (modal state, parameters and their arithmetic, subprograms,
//! fixed cycles, geometry with nalgebra) and produce a printable trace with
//! the predicted cycle time. The crate is part of the workspace layout from
//! the start so that the layering (analysis calls into the executor's
//! evaluator, never the other way round) is fixed early.
//!
//! What exists so far:
//! - [`arith`]: the parameter-arithmetic evaluator of G26–G29 (control words
//!   in R5–R8, operations 0–51). It works on partly unknown parameters, so
//!   the static analysis uses it as well.
//! - [`lower`]: blocks as plain data (words, parameter assignments,
//!   comments), read from the syntax tree; the analysis uses it too.
//! - [`machine`]: the machine a program runs on, and [`tables`]: its zero
//!   offsets and tool corrections with readers for the control's files.

pub mod arith;
pub mod lower;
pub mod machine;
pub mod run;
pub mod tables;
