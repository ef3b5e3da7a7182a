//! Benchmark support: a deterministic CAM-like program generator that writes
//! the same toolpath in CNC8x6 and in ISO/NGC syntax, so that ncc and peer
//! tools can be measured on equal work; a parametric Sinumerik program;
//! seeded edits of those programs; a
//! language-server client that drives `ncc lsp` for the latency benchmark
//! and the server's end-to-end tests; and the lookup of the executor's peer,
//! LinuxCNC's `rs274`.

pub mod cnc8x6;
pub mod edits;
mod lcg;
pub mod lsp_client;
pub mod rs274;
pub mod sinumerik;
