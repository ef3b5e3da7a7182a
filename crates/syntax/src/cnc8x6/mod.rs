//! The MEFI CNC8x6 dialect: its lexer, parser and incremental reparser.

mod lexer;
mod parser;
mod reparse;

use std::sync::OnceLock;

use ncc_catalog::{AddressRole, Dialect};

/// The letters the grammar gives a role, from the dialect's address table.
struct GrammarLetters {
    block: u8,
    parameter: u8,
}

fn grammar_letters() -> &'static GrammarLetters {
    static LETTERS: OnceLock<GrammarLetters> = OnceLock::new();
    LETTERS.get_or_init(|| {
        let catalogue = Dialect::Cnc8x6.catalogue();
        let letter = |role| catalogue.letter_with_role(role).unwrap_or_else(|| panic!("no {role:?} address"));
        GrammarLetters { block: letter(AddressRole::BlockNumber), parameter: letter(AddressRole::Parameter) }
    })
}

/// Whether the letter starts a block (`N`), in either case.
pub(crate) fn is_block_letter(byte: u8) -> bool {
    byte.to_ascii_uppercase() == grammar_letters().block
}

/// Whether the letter is the parameter letter (`R`), in either case.
pub(crate) fn is_parameter_letter(byte: u8) -> bool {
    byte.to_ascii_uppercase() == grammar_letters().parameter
}

pub use parser::MAX_LINE_CHARS;
pub(crate) use parser::parse_source_file;
pub(crate) use reparse::reparse_blocks;
