//! The Haas lathe dialect (classic control, Fanuc-style ISO code): lexer,
//! parser and incremental reparser.

mod lexer;
mod parser;
mod reparse;

pub use lexer::STATEMENT_KEYWORDS;
pub(crate) use parser::parse_source_file;
pub(crate) use reparse::reparse_blocks;
