//! Lossless syntax trees for CNC partprograms.
//!
//! The tree holds every byte of the input: parsing never fails and
//! `parse.syntax_node().to_string()` is always the input text. Problems are
//! reported next to the tree as [`SyntaxError`]s with exact ranges.
//!
//! This crate knows the grammar of each [`Dialect`], not what codes mean:
//! `G41` is a word with address `G` and value `41` here; the meaning of
//! addresses, codes and parameters lives in the dialect catalogue and in the
//! analysis.

mod cnc8x6;
mod decimal;
pub mod encoding;
mod error;
mod expr;
mod green;
mod haas_lathe;
mod lexing;
pub mod limit;
mod line_blocks;
mod line_cursor;
mod runs;
mod sinumerik;
mod syntax_kind;
pub mod visible;

use std::sync::Arc;

use rowan::GreenNode;
pub use rowan::{TextRange, TextSize};

pub use ncc_catalog::Dialect;

/// The typed layer over the tree (the CNC8x6 dialect's).
pub use crate::cnc8x6::ast;
/// The Haas lathe's macro statement words, with their forms.
pub use crate::haas_lathe::STATEMENT_KEYWORDS as HAAS_STATEMENT_KEYWORDS;
pub use crate::{
    cnc8x6::{BlockParser, MAX_LINE_CHARS},
    decimal::{Decimal, Sign},
    error::{Severity, SyntaxError, SyntaxErrorKind},
    limit::Omitted,
    syntax_kind::{NcLanguage, SyntaxElement, SyntaxKind, SyntaxNode, SyntaxToken},
};

/// A replacement of `delete` (a range of the old text) by `insert`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct TextEdit {
    pub delete: TextRange,
    pub insert: String,
}

impl TextEdit {
    pub fn replace(delete: TextRange, insert: impl Into<String>) -> TextEdit {
        TextEdit { delete, insert: insert.into() }
    }

    /// Applies the edit to `text`.
    pub fn apply(&self, text: &mut String) {
        text.replace_range(std::ops::Range::<usize>::from(self.delete), &self.insert);
    }
}

/// The result of parsing: the green tree and the syntax errors.
///
/// Cheap to clone; equal parses compare equal, which incremental
/// computations use to stop early.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Parse {
    green: GreenNode,
    errors: Arc<[SyntaxError]>,
    omitted: Arc<[Omitted<SyntaxErrorKind>]>,
    dialect: Dialect,
}

impl Parse {
    /// Parses a whole program.
    pub fn new(text: &str, dialect: Dialect) -> Parse {
        let (green, errors, omitted) = match dialect {
            Dialect::Cnc8x6 => cnc8x6::parse_source_file(text),
            Dialect::HaasLathe => haas_lathe::parse_source_file(text),
            Dialect::Sinumerik => sinumerik::parse_source_file(text),
        };
        Parse { green, errors: errors.into(), omitted: omitted.into(), dialect }
    }

    /// Parses `new_text`, the result of applying `edit` to the text of this
    /// parse, reusing every block the edit cannot have changed. The result
    /// equals `Parse::new(new_text, dialect)`.
    pub fn reparse(&self, edit: &TextEdit, new_text: &str) -> Parse {
        let reparsed = match self.dialect {
            Dialect::Cnc8x6 => cnc8x6::reparse_blocks(self, edit, new_text),
            Dialect::HaasLathe => haas_lathe::reparse_blocks(self, edit, new_text),
            Dialect::Sinumerik => sinumerik::reparse_blocks(self, edit, new_text),
        };
        reparsed.unwrap_or_else(|| Parse::new(new_text, self.dialect))
    }

    pub fn dialect(&self) -> Dialect {
        self.dialect
    }

    pub fn green(&self) -> &GreenNode {
        &self.green
    }

    pub fn syntax_node(&self) -> SyntaxNode {
        SyntaxNode::new_root(self.green.clone())
    }

    pub fn tree(&self) -> ast::SourceFile {
        <ast::SourceFile as ast::AstNode>::cast(self.syntax_node()).expect("the root is a SOURCE_FILE")
    }

    /// Syntax errors sorted by position: on a line, the first
    /// [`limit::PER_LINE`] of each kind.
    pub fn errors(&self) -> &[SyntaxError] {
        &self.errors
    }

    /// The syntax errors left out of [`Parse::errors`], counted per line
    /// and kind.
    pub fn omitted(&self) -> &[Omitted<SyntaxErrorKind>] {
        &self.omitted
    }

    /// The tree and the errors as text, for tests and `ncc parse`.
    pub fn debug_dump(&self) -> String {
        let mut dump = format!("{:#?}", self.syntax_node());
        for error in self.errors.iter() {
            dump.push_str(&format!("{error}\n"));
        }
        for omitted in self.omitted.iter() {
            let Omitted { kind, at, count, .. } = omitted;
            dump.push_str(&format!("{count} more {}[{}] from {at:?} on its line\n", kind.severity(), kind.code()));
        }
        dump
    }
}
