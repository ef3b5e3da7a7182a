//! The MEFI CNC8x6 dialect: its typed syntax tree, lexer, parser and
//! incremental reparser.

pub mod ast;
mod lexer;
mod parser;
mod reparse;

use std::sync::OnceLock;

use ncc_catalog::{AddressRole, Dialect};

/// The letters the grammar gives a role, from the dialect's address table.
#[derive(Clone, Copy)]
pub(crate) struct GrammarLetters {
    block: u8,
    parameter: u8,
}

impl GrammarLetters {
    /// Whether the letter starts a block (`N`), in either case.
    pub(crate) fn is_block(self, byte: u8) -> bool {
        byte.to_ascii_uppercase() == self.block
    }

    /// Whether the letter is the parameter letter (`R`), in either case.
    pub(crate) fn is_parameter(self, byte: u8) -> bool {
        byte.to_ascii_uppercase() == self.parameter
    }
}

pub(crate) fn grammar_letters() -> GrammarLetters {
    *grammar_letters_ref()
}

fn grammar_letters_ref() -> &'static GrammarLetters {
    static LETTERS: OnceLock<GrammarLetters> = OnceLock::new();
    LETTERS.get_or_init(|| {
        let catalogue = Dialect::Cnc8x6.catalogue();
        let letter = |role| catalogue.letter_with_role(role).unwrap_or_else(|| panic!("no {role:?} address"));
        GrammarLetters { block: letter(AddressRole::BlockNumber), parameter: letter(AddressRole::Parameter) }
    })
}

/// Whether the letter starts a block (`N`), in either case.
pub(crate) fn is_block_letter(byte: u8) -> bool {
    grammar_letters().is_block(byte)
}

pub(crate) use parser::parse_source_file;
pub use parser::{BlockParser, MAX_LINE_CHARS};
pub(crate) use reparse::reparse_blocks;
