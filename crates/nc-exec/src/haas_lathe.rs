//! The Haas lathe dialect's part of the executor (classic control,
//! Fanuc-style ISO code): its block IR and lowering, the macro-expression
//! evaluator and the program model (programs, block numbers, the P/Q
//! contours of G70–G73 and the targets of calls and jumps).

pub mod eval;
pub mod lower;
pub mod program;
