//! The MEFI CNC8x6 dialect: its lexer, parser and incremental reparser.

mod lexer;
mod parser;
mod reparse;

pub use parser::MAX_LINE_CHARS;
pub(crate) use parser::parse_source_file;
pub(crate) use reparse::reparse_blocks;
