//! The Haas lathe dialect's part of the executor (classic control,
//! Fanuc-style ISO code): its block IR and lowering, the macro-expression
//! evaluator, the modal state, the program model (programs, block
//! numbers, the P/Q contours of G70–G73 and the targets of calls and
//! jumps), the canned cycles as moves (the one-block cycles, and the
//! contour cycles G70–G73), the interpreter that runs a program into a
//! trace, the velocity policy that times it, the writer of expanded
//! programs, and the offset pages a machine's configuration gives.

pub mod cycles;
pub mod dynamics;
pub mod eval;
pub mod expand;
pub mod interpreter;
pub mod lower;
pub mod modes;
pub mod offsets;
pub mod program;
pub mod roughing;
