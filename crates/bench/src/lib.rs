//! Benchmark support: a deterministic CAM-like program generator that writes
//! the same toolpath in CNC8x6 and in ISO/NGC syntax, so that ncc and peer
//! tools can be measured on equal work.

pub mod progen;
