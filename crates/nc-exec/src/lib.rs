//! The executor of partprograms.
//!
//! It will lower syntax trees to an executable form, run them on a model of
//! the control (modal state, parameters and their arithmetic, subprograms,
//! fixed cycles, geometry with nalgebra) and produce a printable trace with
//! the predicted cycle time. The crate is part of the workspace layout from
//! the start so that the layering (analysis calls into the executor's
//! evaluator, never the other way round) is fixed early; it holds no code
//! until the executor is built.
