//! The CNC8x6 dialect's part of the executor: its block IR and lowering,
//! value formats, modal groups, arcs, parameter arithmetic, program flow, fixed
//! cycles, table files, the interpreter and the writer of expanded
//! programs.

pub mod arcs;
pub mod arith;
pub(crate) mod cycles;
pub mod dynamics;
pub mod expand;
pub mod formats;
pub(crate) mod interpreter;
pub mod lower;
pub mod modes;
pub mod program_flow;
pub mod tables;
