//! The Haas lathe dialect (classic control, Fanuc-style ISO code): lexer,
//! parser and incremental reparser.
//!
//! Not yet a [`crate::Dialect`]: until it is registered there, it is
//! reached through [`parse`] and [`reparse`].

mod lexer;
mod parser;
mod reparse;

use rowan::GreenNode;

use crate::{SyntaxError, SyntaxErrorKind, TextEdit, limit::Omitted};

/// A parse of a Haas program: the tree, the errors in canonical order
/// (the first [`crate::limit::PER_LINE`] of each kind on a line) and the
/// counts of those left out.
pub type HaasParse = (GreenNode, Vec<SyntaxError>, Vec<Omitted<SyntaxErrorKind>>);

/// Parses a whole Haas lathe program.
pub fn parse(text: &str) -> HaasParse {
    parser::parse_source_file(text)
}

/// Parses `new_text`, the result of applying `edit` to the text of `old`,
/// reusing every block the edit cannot have changed. The result equals
/// `parse(new_text)`.
pub fn reparse(old: &HaasParse, edit: &TextEdit, new_text: &str) -> HaasParse {
    reparse::reparse_blocks(old, edit, new_text).unwrap_or_else(|| parse(new_text))
}

/// The tree and the errors of `parse` as text, for tests.
pub fn debug_dump(parse: &HaasParse) -> String {
    crate::debug_dump(&parse.0, &parse.1, &parse.2)
}
