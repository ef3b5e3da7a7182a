//! The CNC8x6 dialect's part of the benchmarks.

pub mod progen;
