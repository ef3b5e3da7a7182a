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
//! - [`cycles`]: the built-in fixed cycles G81–G89 (milling and lathe), as
//!   lists of moves for the runner, when the machine loads no cycle file.
//! - [`lower`]: blocks as plain data (words, parameter assignments,
//!   comments), read from the syntax tree; the analysis uses it too.

pub mod arith;
pub mod cycles;
pub mod lower;
pub mod machine;
pub mod modes;
pub mod run;
