//! Conversions between the analysis's byte offsets and plain types and the
//! protocol's UTF-16 positions and LSP types.

use std::sync::Arc;

use ncc_analysis::{Diagnostic, Severity, TextEdit, TextRange, TextSize};
use tower_lsp_server::ls_types::{self as lsp, Uri};

use crate::positions::{Columns, TextIndex};

/// A document's text with its line index.
#[derive(Debug, Clone)]
pub(crate) struct LineMap {
    pub text: Arc<String>,
    index: Arc<TextIndex>,
}

/// Byte offsets to protocol positions: the line index without the text, for
/// work that may outlive the next edit (a holder of the text makes the edit
/// copy it instead of changing it in place).
#[derive(Debug, Clone)]
pub(crate) struct Positions(Arc<TextIndex>);

impl Positions {
    pub fn position(&self, offset: TextSize) -> lsp::Position {
        let (line, character) = self.0.line_col(offset, Columns::Utf16);
        lsp::Position::new(line, character)
    }

    pub fn range(&self, range: TextRange) -> lsp::Range {
        lsp::Range::new(self.position(range.start()), self.position(range.end()))
    }
}

impl LineMap {
    pub fn new(text: Arc<String>) -> LineMap {
        let index = Arc::new(TextIndex::new(&text));
        LineMap { text, index }
    }

    /// The map of `text`, which `edit` made from the text `before` indexes.
    pub fn edited(before: &Positions, edit: &TextEdit, text: Arc<String>) -> LineMap {
        let index = Arc::new(before.0.edited(edit, &text));
        LineMap { text, index }
    }

    pub fn positions(&self) -> Positions {
        Positions(self.index.clone())
    }

    /// The byte offset of a position; positions past a line's end or past
    /// the last line are clamped to the end, as editors expect, and one
    /// between the halves of a surrogate pair moves to the character's start.
    pub fn offset(&self, position: lsp::Position) -> TextSize {
        let len = self.index.len();
        let Some(start) = self.index.line_start(position.line) else { return len };
        let next = self.index.line_start(position.line + 1).unwrap_or(len);
        let line = &self.text[usize::from(start)..usize::from(next)];
        let content = ["\r\n", "\n", "\r"].iter().find_map(|end| line.strip_suffix(end)).unwrap_or(line);
        let end = start + TextSize::of(content);
        self.index.offset_in_line(start, end, position.character)
    }

    pub fn range_offsets(&self, range: lsp::Range) -> TextRange {
        let start = self.offset(range.start);
        let end = self.offset(range.end).max(start);
        TextRange::new(start, end)
    }

    pub fn position(&self, offset: TextSize) -> lsp::Position {
        self.positions().position(offset)
    }

    pub fn range(&self, range: TextRange) -> lsp::Range {
        self.positions().range(range)
    }

    /// Applies a protocol change; returns the edit in byte offsets.
    pub fn edit(&self, change: &lsp::TextDocumentContentChangeEvent) -> TextEdit {
        let delete = match change.range {
            Some(range) => self.range_offsets(range),
            None => TextRange::up_to(self.index.len()),
        };
        TextEdit::replace(delete, change.text.clone())
    }

    pub fn text_edit(&self, edit: &TextEdit) -> lsp::TextEdit {
        lsp::TextEdit { range: self.range(edit.delete), new_text: edit.insert.clone() }
    }
}

pub(crate) fn diagnostic(map: &Positions, uri: &Uri, diagnostic: &Diagnostic) -> lsp::Diagnostic {
    let severity = match diagnostic.severity {
        Severity::Error => lsp::DiagnosticSeverity::ERROR,
        Severity::Warning => lsp::DiagnosticSeverity::WARNING,
        Severity::Info => lsp::DiagnosticSeverity::INFORMATION,
        Severity::Hint => lsp::DiagnosticSeverity::HINT,
    };
    let related = diagnostic
        .related
        .iter()
        .filter_map(|related| {
            // Related places in other files carry their own ranges, which
            // this document's line map cannot convert; the message keeps
            // the file's name.
            let location = match &related.file {
                None => lsp::Location::new(uri.clone(), map.range(related.range)),
                Some(path) => lsp::Location::new(Uri::from_file_path(path)?, lsp::Range::default()),
            };
            Some(lsp::DiagnosticRelatedInformation { location, message: related.message.clone() })
        })
        .collect::<Vec<_>>();
    lsp::Diagnostic {
        range: map.range(diagnostic.range),
        severity: Some(severity),
        code: Some(lsp::NumberOrString::String(diagnostic.code.to_owned())),
        code_description: None,
        source: Some("ncc".to_owned()),
        message: format!("{} [{}]", diagnostic.message, diagnostic.name),
        related_information: (!related.is_empty()).then_some(related),
        tags: diagnostic.unnecessary.then(|| vec![lsp::DiagnosticTag::UNNECESSARY]),
        data: None,
    }
}

pub(crate) fn markdown(text: String) -> lsp::MarkupContent {
    lsp::MarkupContent { kind: lsp::MarkupKind::Markdown, value: text }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_count_utf16_units_and_clamp() {
        // `č` is two bytes and one UTF-16 unit; `𝄞` four bytes, two units.
        let map = LineMap::new(Arc::new("N1 (č𝄞)\r\nN2 X1\n".to_owned()));
        let at = |line, character| u32::from(map.offset(lsp::Position::new(line, character)));
        assert_eq!(at(0, 5), 6, "after `č`");
        assert_eq!(at(0, 7), 10, "after the surrogate pair");
        assert_eq!(at(0, 6), 6, "inside the pair: its start");
        assert_eq!(at(0, 99), 11, "past the line's end: before CRLF");
        assert_eq!(at(1, 3), 16);
        assert_eq!(at(9, 0), 19, "past the last line: the end");
        assert_eq!(map.position(TextSize::from(10)), lsp::Position::new(0, 7));
        assert_eq!(map.position(TextSize::from(99)), lsp::Position::new(2, 0));
    }

    #[test]
    fn a_lone_carriage_return_ends_a_line_as_the_protocol_says() {
        let map = LineMap::new(Arc::new("%1\rN10 X1\rN20 Y\r".to_owned()));
        assert_eq!(map.position(TextSize::from(14)), lsp::Position::new(2, 4));
        assert_eq!(u32::from(map.offset(lsp::Position::new(2, 4))), 14);
        assert_eq!(u32::from(map.offset(lsp::Position::new(1, 99))), 9, "before the line's `\\r`");
    }

    #[test]
    fn changes_become_byte_edits() {
        let map = LineMap::new(Arc::new("N1 (ř)\nN2\n".to_owned()));
        let change = lsp::TextDocumentContentChangeEvent {
            range: Some(lsp::Range::new(lsp::Position::new(0, 5), lsp::Position::new(1, 1))),
            range_length: None,
            text: "x".into(),
        };
        let edit = map.edit(&change);
        assert_eq!(edit.delete, TextRange::new(6.into(), 9.into()));
        let full = lsp::TextDocumentContentChangeEvent { range: None, range_length: None, text: "N5".into() };
        assert_eq!(map.edit(&full).delete, TextRange::new(0.into(), 11.into()));
    }
}
