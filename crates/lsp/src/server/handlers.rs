//! Each request's answer from the analysis, converted to the protocol.

use std::collections::HashMap;

use ncc_analysis::{
    CompletionKind, Dialect, DocumentSymbol, FoldKind, NavigationTarget, ReferenceKind, Renaming, SymbolKind,
};
use ncc_catalog::AddressRole;
use tower_lsp_server::ls_types as lsp;

use super::{Snapshot, convert, semantic};

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
            code_action_kinds: Some(vec![lsp::CodeActionKind::QUICKFIX, lsp::CodeActionKind::SOURCE]),
            ..Default::default()
        })),
        completion_provider: Some(lsp::CompletionOptions {
            trigger_characters: Some(trigger_characters()),
            ..Default::default()
        }),
        inlay_hint_provider: Some(lsp::OneOf::Left(true)),
        code_lens_provider: Some(lsp::CodeLensOptions { resolve_provider: Some(false) }),
        references_provider: Some(lsp::OneOf::Left(true)),
        rename_provider: Some(lsp::OneOf::Right(lsp::RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: Default::default(),
        })),
        signature_help_provider: Some(lsp::SignatureHelpOptions {
            trigger_characters: Some(vec!["(".to_owned(), ",".to_owned()]),
            ..Default::default()
        }),
        document_highlight_provider: Some(lsp::OneOf::Left(true)),
        document_symbol_provider: Some(lsp::OneOf::Left(true)),
        folding_range_provider: Some(lsp::FoldingRangeProviderCapability::Simple(true)),
        semantic_tokens_provider: Some(lsp::SemanticTokensServerCapabilities::SemanticTokensOptions(
            lsp::SemanticTokensOptions {
                legend: semantic::legend(),
                full: Some(lsp::SemanticTokensFullOptions::Bool(true)),
                range: Some(true),
                ..Default::default()
            },
        )),
        document_formatting_provider: Some(lsp::OneOf::Left(true)),
        document_range_formatting_provider: Some(lsp::OneOf::Left(true)),
        execute_command_provider: Some(lsp::ExecuteCommandOptions {
            commands: vec![super::plot::COMMAND.to_owned()],
            ..Default::default()
        }),
        ..Default::default()
    }
}

/// The letters completion answers as soon as they are typed, in every
/// dialect (the capabilities are the server's, not a document's): the
/// codes', the call targets' (`L`; `P`, `Q`) and the parameters' (`R`, `#`).
fn trigger_characters() -> Vec<String> {
    let roles = [AddressRole::Function, AddressRole::Label, AddressRole::Parameter];
    let mut letters: Vec<String> = Dialect::ALL
        .into_iter()
        .flat_map(|dialect| dialect.catalogue().addresses.iter())
        .filter(|address| roles.contains(&address.role))
        .map(|address| address.letter.clone())
        .collect();
    letters.sort();
    letters.dedup();
    letters
}

/// The analysis's hover, then the predicted time and speed of the block.
pub(crate) fn hover(s: &Snapshot, position: lsp::Position) -> Option<lsp::Hover> {
    let offset = s.map.offset(position);
    let hover = s.analysis.hover(s.file, offset);
    let timed = s.cycle.as_ref().filter(|cycle| cycle.holds_at(offset)).and_then(|cycle| {
        let block = cycle.estimate.block_at(offset)?;
        Some((block.range, cycle.estimate.hover(offset)?))
    });
    let (range, markdown) = match (hover, timed) {
        (Some(hover), Some((_, time))) => (hover.range, format!("{}\n\n---\n\n{time}", hover.markdown)),
        (Some(hover), None) => (hover.range, hover.markdown),
        (None, Some((block, time))) => (block, time),
        (None, None) => return None,
    };
    Some(lsp::Hover {
        contents: lsp::HoverContents::Markup(convert::markdown(markdown)),
        range: Some(s.map.range(range)),
    })
}

pub(crate) fn definition(s: &Snapshot, position: lsp::Position) -> Vec<NavigationTarget> {
    s.analysis.goto_definition(s.file, s.map.offset(position))
}

/// The range of the name a rename changes, or why none can be renamed.
pub(crate) fn prepare_rename(s: &Snapshot, position: lsp::Position) -> Result<lsp::PrepareRenameResponse, String> {
    let range = s.analysis.prepare_rename(s.file, s.map.offset(position))?;
    Ok(lsp::PrepareRenameResponse::Range(s.map.range(range)))
}

/// What renaming the name at `position` changes, in every file.
pub(crate) fn rename(s: &Snapshot, position: lsp::Position, new_name: &str) -> Result<Renaming, String> {
    s.analysis.rename(s.file, s.map.offset(position), new_name)
}

/// The signature of the call at `position`; parameters by their place in
/// the label, in UTF-16 units.
pub(crate) fn signature_help(s: &Snapshot, position: lsp::Position) -> Option<lsp::SignatureHelp> {
    let help = s.analysis.signature_help(s.file, s.map.offset(position))?;
    let units = |end: ncc_analysis::TextSize| help.label[..usize::from(end)].encode_utf16().count() as u32;
    let parameters = help
        .parameters
        .iter()
        .map(|parameter| lsp::ParameterInformation {
            label: lsp::ParameterLabel::LabelOffsets([units(parameter.range.start()), units(parameter.range.end())]),
            documentation: parameter
                .documentation
                .clone()
                .map(|text| lsp::Documentation::MarkupContent(convert::markdown(text))),
        })
        .collect();
    let active = help.active_parameter.and_then(|index| u32::try_from(index).ok());
    Some(lsp::SignatureHelp {
        signatures: vec![lsp::SignatureInformation {
            label: help.label.clone(),
            documentation: help.documentation.map(|text| lsp::Documentation::MarkupContent(convert::markdown(text))),
            parameters: Some(parameters),
            active_parameter: active,
        }],
        active_signature: Some(0),
        active_parameter: active,
    })
}

/// The quick fixes of the diagnostics that touch `range`, and renumbering
/// on a line that starts with a block number when asked for (not where
/// the editor asks by itself as the cursor moves: it renumbers the whole
/// file).
pub(crate) fn code_actions(
    s: &Snapshot,
    range: lsp::Range,
    context: &lsp::CodeActionContext,
) -> lsp::CodeActionResponse {
    let range = s.map.range_offsets(range);
    let asked = context.trigger_kind != Some(lsp::CodeActionTriggerKind::AUTOMATIC);
    let renumbering = asked.then(|| renumber_action(s, range.start())).flatten();
    let diagnostics = s.analysis.diagnostics(s.file);
    let positions = s.map.positions();
    let mut actions = Vec::new();
    for diagnostic in diagnostics.iter().filter(|d| d.range.intersect(range).is_some() && !d.fixes.is_empty()) {
        let converted = convert::diagnostic(&positions, &s.uri, diagnostic);
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
    actions.extend(renumbering);
    actions
}

/// Renumbering the blocks N10, N20, … with every reference to them,
/// offered where the line at `at` starts with a block number; where a
/// computed or missing target makes it unsafe, offered disabled with the
/// reason.
fn renumber_action(s: &Snapshot, at: ncc_syntax::TextSize) -> Option<lsp::CodeActionOrCommand> {
    const START: u64 = 10;
    const STEP: u64 = 10;
    let text = s.analysis.text(s.file);
    let at = usize::from(at).min(text.len());
    let line_start = text[..at].rfind('\n').map_or(0, |newline| newline + 1);
    let line = text[line_start..].trim_start_matches([' ', '\t']).as_bytes();
    let letter = s.analysis.dialect().catalogue().letter_with_role(AddressRole::BlockNumber)?;
    if line.first().map(u8::to_ascii_uppercase) != Some(letter) || !line.get(1).is_some_and(u8::is_ascii_digit) {
        return None;
    }
    let (edit, disabled) = match s.analysis.renumber(s.file, START, STEP) {
        Ok(edits) => {
            let edits = edits.iter().map(|edit| s.map.text_edit(edit)).collect();
            let changes = HashMap::from([(s.uri.clone(), edits)]);
            (Some(lsp::WorkspaceEdit { changes: Some(changes), ..Default::default() }), None)
        }
        Err(error) => {
            let line = s.map.range(error.range).start.line + 1;
            (None, Some(lsp::CodeActionDisabled { reason: format!("line {line}: {}", error.message) }))
        }
    };
    Some(lsp::CodeActionOrCommand::CodeAction(lsp::CodeAction {
        title: format!("Renumber the blocks N{START}, N{}, … and the jumps to them", START + STEP),
        kind: Some(lsp::CodeActionKind::SOURCE),
        edit,
        disabled,
        ..Default::default()
    }))
}

pub(crate) fn completion(s: &Snapshot, position: lsp::Position) -> Vec<lsp::CompletionItem> {
    let items = s.analysis.completions(s.file, s.map.offset(position));
    // The analysis lists the most relevant first; the sort text keeps that.
    let width = items.len().to_string().len();
    items
        .into_iter()
        .enumerate()
        .map(|(rank, item)| lsp::CompletionItem {
            kind: Some(match item.kind {
                CompletionKind::Code | CompletionKind::Keyword => lsp::CompletionItemKind::KEYWORD,
                CompletionKind::Address => lsp::CompletionItemKind::FIELD,
                CompletionKind::Subprogram
                | CompletionKind::Macrocycle
                | CompletionKind::Program
                | CompletionKind::Function => lsp::CompletionItemKind::FUNCTION,
                CompletionKind::Block | CompletionKind::Label => lsp::CompletionItemKind::REFERENCE,
                CompletionKind::Parameter | CompletionKind::Variable => lsp::CompletionItemKind::VARIABLE,
            }),
            detail: Some(item.detail),
            documentation: item.documentation.map(|text| lsp::Documentation::MarkupContent(convert::markdown(text))),
            sort_text: Some(format!("{rank:0width$}")),
            filter_text: Some(item.label.clone()),
            text_edit: Some(lsp::CompletionTextEdit::Edit(lsp::TextEdit {
                range: s.map.range(item.replace),
                new_text: item.insert_text,
            })),
            insert_text_format: item.snippet.then_some(lsp::InsertTextFormat::SNIPPET),
            label: item.label,
            ..Default::default()
        })
        .collect()
}

/// The edits that format the document, or the lines `range` touches.
pub(crate) fn formatting(s: &Snapshot, range: Option<lsp::Range>) -> Vec<lsp::TextEdit> {
    let range = range.map(|range| s.map.range_offsets(range));
    s.analysis.format(s.file, range).iter().map(|edit| s.map.text_edit(edit)).collect()
}

/// The parameter values and, where the estimate holds, the cycle time.
pub(crate) fn inlay_hints(s: &Snapshot, range: lsp::Range) -> Vec<lsp::InlayHint> {
    let range = s.map.range_offsets(range);
    let mut hints = s.analysis.inlay_hints(s.file, Some(range));
    if let Some(cycle) = &s.cycle {
        let timed = cycle.estimate.inlay_hints(Some(range), s.cycle_hints);
        hints.extend(timed.into_iter().filter(|hint| cycle.holds_at(hint.offset)));
        // Parameter values and times can share a line; the client wants
        // them in order.
        hints.sort_by_key(|hint| hint.offset);
    }
    hints
        .into_iter()
        .map(|hint| lsp::InlayHint {
            position: s.map.position(hint.offset),
            label: lsp::InlayHintLabel::String(hint.label),
            kind: None,
            text_edits: None,
            tooltip: hint.tooltip.map(|text| lsp::InlayHintTooltip::MarkupContent(convert::markdown(text))),
            padding_left: Some(true),
            padding_right: None,
            data: None,
        })
        .collect()
}

/// The program's predicted total on its header.
pub(crate) fn code_lenses(s: &Snapshot) -> Vec<lsp::CodeLens> {
    let (Some(cycle), Some(head)) = (&s.cycle, s.analysis.program_head(s.file)) else { return Vec::new() };
    // A lens spans one line: the header's first.
    let start = s.map.position(head.start());
    vec![lsp::CodeLens {
        range: lsp::Range::new(start, start),
        // A title to show; no command runs when it is clicked.
        command: Some(lsp::Command { title: cycle.estimate.headline(), command: String::new(), arguments: None }),
        data: None,
    }]
}

pub(crate) fn references(
    s: &Snapshot,
    position: lsp::Position,
    include_declaration: bool,
) -> Vec<ncc_analysis::Reference> {
    s.analysis.references(s.file, s.map.offset(position), include_declaration)
}

/// Whether a reference is written (for document highlights and clients
/// that show it).
pub(crate) fn is_write(kind: ReferenceKind) -> bool {
    matches!(kind, ReferenceKind::Definition | ReferenceKind::Write)
}

pub(crate) fn document_symbols(s: &Snapshot) -> Vec<lsp::DocumentSymbol> {
    fn convert_symbol(s: &Snapshot, symbol: DocumentSymbol) -> lsp::DocumentSymbol {
        #[allow(deprecated)] // `deprecated` is a required field of the type.
        lsp::DocumentSymbol {
            name: symbol.name,
            detail: symbol.detail,
            kind: match symbol.kind {
                SymbolKind::Program => lsp::SymbolKind::MODULE,
                SymbolKind::Subprogram | SymbolKind::Macrocycle | SymbolKind::CycleBody => lsp::SymbolKind::FUNCTION,
                SymbolKind::JumpTarget => lsp::SymbolKind::KEY,
                SymbolKind::Tool => lsp::SymbolKind::EVENT,
                SymbolKind::Structure => lsp::SymbolKind::NAMESPACE,
                SymbolKind::Variable => lsp::SymbolKind::VARIABLE,
            },
            tags: None,
            deprecated: None,
            range: s.map.range(symbol.range),
            selection_range: s.map.range(symbol.selection_range),
            children: Some(symbol.children.into_iter().map(|child| convert_symbol(s, child)).collect()),
        }
    }
    s.analysis.document_symbols(s.file).into_iter().map(|symbol| convert_symbol(s, symbol)).collect()
}

pub(crate) fn folding_ranges(s: &Snapshot) -> Vec<lsp::FoldingRange> {
    s.analysis
        .folding_ranges(s.file)
        .into_iter()
        .filter_map(|fold| {
            let (start, end) = (s.map.position(fold.range.start()), s.map.position(fold.range.end()));
            (end.line > start.line).then(|| lsp::FoldingRange {
                start_line: start.line,
                end_line: end.line,
                kind: Some(match fold.kind {
                    FoldKind::Region => lsp::FoldingRangeKind::Region,
                    FoldKind::Comment => lsp::FoldingRangeKind::Comment,
                }),
                ..Default::default()
            })
        })
        .collect()
}

pub(crate) fn semantic_tokens(s: &Snapshot, range: Option<lsp::Range>) -> lsp::SemanticTokens {
    let ranges = match range {
        Some(range) => s.analysis.highlight_range(s.file, s.map.range_offsets(range)),
        None => s.analysis.highlight(s.file),
    };
    lsp::SemanticTokens { result_id: None, data: semantic::encode(&s.map, &ranges, s.analysis.dialect()) }
}
