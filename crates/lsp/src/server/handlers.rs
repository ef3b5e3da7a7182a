//! Each request's answer from the analysis, converted to the protocol.

use std::collections::HashMap;

use ncc_analysis::NavigationTarget;
use tower_lsp_server::ls_types as lsp;

use super::{Snapshot, convert};

pub(crate) fn capabilities() -> lsp::ServerCapabilities {
    lsp::ServerCapabilities {
        position_encoding: Some(lsp::PositionEncodingKind::UTF16),
        text_document_sync: Some(lsp::TextDocumentSyncCapability::Options(lsp::TextDocumentSyncOptions {
            open_close: Some(true),
            change: Some(lsp::TextDocumentSyncKind::INCREMENTAL),
            ..Default::default()
        })),
        hover_provider: Some(lsp::HoverProviderCapability::Simple(true)),
        definition_provider: Some(lsp::OneOf::Left(true)),
        code_action_provider: Some(lsp::CodeActionProviderCapability::Options(lsp::CodeActionOptions {
            code_action_kinds: Some(vec![lsp::CodeActionKind::QUICKFIX]),
            ..Default::default()
        })),
        ..Default::default()
    }
}

pub(crate) fn hover(s: &Snapshot, position: lsp::Position) -> Option<lsp::Hover> {
    let hover = s.analysis.hover(s.file, s.map.offset(position))?;
    Some(lsp::Hover {
        contents: lsp::HoverContents::Markup(convert::markdown(hover.markdown)),
        range: Some(s.map.range(hover.range)),
    })
}

pub(crate) fn definition(s: &Snapshot, position: lsp::Position) -> Vec<NavigationTarget> {
    s.analysis.goto_definition(s.file, s.map.offset(position))
}

/// The quick fixes of the diagnostics that touch `range`.
pub(crate) fn code_actions(s: &Snapshot, range: lsp::Range) -> lsp::CodeActionResponse {
    let range = s.map.range_offsets(range);
    let mut diagnostics = s.analysis.local_diagnostics(s.file);
    diagnostics.extend(s.analysis.flow_diagnostics(s.file));
    let mut actions = Vec::new();
    for diagnostic in diagnostics.iter().filter(|d| d.range.intersect(range).is_some() && !d.fixes.is_empty()) {
        let converted = convert::diagnostic(&s.map, &s.uri, diagnostic);
        let only_fix = diagnostic.fixes.len() == 1;
        for fix in &diagnostic.fixes {
            let edits = fix.edits.iter().map(|edit| s.map.text_edit(edit)).collect();
            actions.push(lsp::CodeActionOrCommand::CodeAction(lsp::CodeAction {
                title: fix.title.clone(),
                kind: Some(lsp::CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![converted.clone()]),
                edit: Some(lsp::WorkspaceEdit {
                    changes: Some(HashMap::from([(s.uri.clone(), edits)])),
                    ..Default::default()
                }),
                is_preferred: Some(only_fix),
                ..Default::default()
            }));
        }
    }
    actions
}
