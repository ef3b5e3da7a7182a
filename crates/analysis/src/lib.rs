//! Semantic analysis of partprograms.
//!
//! This layer turns syntax trees into what editors and the command line
//! show: diagnostics today; the program model, hover and navigation as they
//! arrive. Everything here is plain Rust data with text ranges; converting
//! to line/column, LSP or terminal output is the caller's business.

use ncc_syntax::Parse;
pub use ncc_syntax::{Dialect, Severity, TextRange, TextSize};

/// A finding in one file.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Diagnostic {
    pub range: TextRange,
    pub severity: Severity,
    /// Stable identifier, e.g. `S002`.
    pub code: &'static str,
    /// Stable readable name, e.g. `space-in-number`.
    pub name: &'static str,
    pub message: String,
}

/// Every diagnostic of a parsed program, in source order.
pub fn diagnostics(parse: &Parse) -> Vec<Diagnostic> {
    parse
        .errors()
        .iter()
        .map(|error| Diagnostic {
            range: error.range,
            severity: error.severity(),
            code: error.kind.code(),
            name: error.kind.name(),
            message: error.message.clone(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn syntax_errors_become_diagnostics() {
        let parse = Parse::new("%1\nN10 X36.  12\n", Dialect::Cnc8x6);
        let diagnostics = diagnostics(&parse);
        assert_eq!(diagnostics.len(), 1);
        let d = &diagnostics[0];
        assert_eq!((d.code, d.name, d.severity), ("S002", "space-in-number", Severity::Error));
        assert_eq!(d.range, TextRange::new(8.into(), 15.into()));
    }
}
