//! Signature help in a Sinumerik file: inside a call's parentheses, the
//! signature of what it calls with the parameter the cursor is in. A
//! predefined function's and a cycle's come from the catalogue; a
//! program's from its PROC line (in the file, or in the workspace's file
//! named after it), else from the file's EXTERN declaration.

use ncc_syntax::{SyntaxKind, SyntaxNode, SyntaxToken, TextRange, TextSize};

use super::{
    catalogue,
    navigation::{program_files, program_key},
};
use crate::{
    db::{Db, SourceFile},
    ide::{SignatureHelp, SignatureParameter},
    sinumerik::model::{FileModel, file_model},
};

pub(crate) fn signature_help(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<SignatureHelp> {
    let root = file.parse(db).syntax_node();
    let token = token_before(&root, offset)?;
    let list = token.parent_ancestors().filter(|node| node.kind() == SyntaxKind::ARG_LIST).find(|list| {
        let paren = |kind| list.children_with_tokens().find(|child| child.kind() == kind).map(|c| c.text_range());
        paren(SyntaxKind::L_PAREN).is_some_and(|open| open.end() <= offset)
            && paren(SyntaxKind::R_PAREN).is_none_or(|close| offset <= close.start())
    })?;
    let call = list.parent().filter(|node| matches!(node.kind(), SyntaxKind::CALL_STMT | SyntaxKind::CALL_EXPR))?;
    let name = call.first_token().filter(|token| token.kind() == SyntaxKind::IDENT)?.text().to_ascii_uppercase();
    let commas =
        list.children_with_tokens().filter(|c| c.kind() == SyntaxKind::COMMA && c.text_range().end() <= offset);
    let (mut help, repeats) = signature(db, file, &name)?;
    let last = help.parameters.len().checked_sub(1);
    help.active_parameter = match commas.count() {
        position if Some(position) <= last => Some(position),
        _ if repeats => last,
        _ => None,
    };
    Some(help)
}

/// The significant token that ends at or before `offset` on its line.
fn token_before(root: &SyntaxNode, offset: TextSize) -> Option<SyntaxToken> {
    if offset > root.text_range().end() {
        return None;
    }
    let mut token = root.token_at_offset(offset).left_biased()?;
    while token.kind().is_trivia() {
        token = token.prev_token()?;
    }
    Some(token)
}

/// The signature of what `name` (upper case) calls, and whether its last
/// parameter is a list (`REAL…`) that takes every further argument.
fn signature(db: &dyn Db, file: SourceFile, name: &str) -> Option<(SignatureHelp, bool)> {
    let catalogue = catalogue();
    if let Some(function) = catalogue.function(name) {
        let label = function.signature();
        let mut from = 0;
        let parameters = function
            .parameters
            .iter()
            .map(|parameter| {
                let written = format!("{} {}", parameter.ty, parameter.name);
                let start = label[from..].find(&written).map_or(label.len(), |at| from + at);
                from = (start + written.len()).min(label.len());
                let range = TextRange::new(TextSize::of(&label[..start]), TextSize::of(&label[..from]));
                SignatureParameter { range, documentation: Some(parameter.meaning.clone()) }
            })
            .collect();
        let documentation = Some(format!("**{}**: {}", function.title, function.summary));
        let repeats = function.parameters.last().is_some_and(|parameter| parameter.ty.ends_with('…'));
        return Some((SignatureHelp { label, documentation, parameters, active_parameter: None }, repeats));
    }
    if let Some(cycle) = catalogue.cycles_for(name).find(|cycle| !cycle.arguments.is_empty()) {
        let arguments = cycle.arguments.iter().map(|argument| {
            let unit = argument.unit.as_ref().map(|unit| format!(" ({unit})")).unwrap_or_default();
            (format!("{} {}", argument.ty, argument.name), Some(format!("{}{unit}", argument.meaning)))
        });
        let documentation = format!("**{}**: {}", cycle.title, cycle.summary);
        return Some((built(&cycle.code, arguments, Some(documentation)), false));
    }
    let key = program_key(name);
    let own = file_model(db, file);
    let procs = std::iter::once(file).chain(program_files(db, &key).filter(|&other| other != file));
    if let Some(help) = procs.into_iter().find_map(|other| proc_signature(db, other, file_model(db, other), &key)) {
        return Some((help, false));
    }
    let declared = own.model.externs.iter().find(|d| program_key(&d.declaration.name) == key)?;
    let text = file.text(db);
    let parameters =
        declared.declaration.parameters.iter().map(|p| (written(text, own, declared.block, p.range), None));
    let documentation = Some("Declared by `EXTERN` in this file.".to_owned());
    Some((built(&declared.declaration.name, parameters, documentation), false))
}

/// The signature of the PROC `key` of `file`, its parameters as written.
pub(super) fn proc_signature(db: &dyn Db, file: SourceFile, model: &FileModel, key: &str) -> Option<SignatureHelp> {
    let proc = model.model.procs.iter().find(|d| program_key(&d.declaration.name) == key)?;
    let text = file.text(db);
    let parameters = proc.declaration.parameters.iter().map(|p| (written(text, model, proc.block, p.range), None));
    let documentation = format!("`PROC` of {}", file.path(db));
    Some(built(&proc.declaration.name, parameters, Some(documentation)))
}

/// A parameter's text, blanks collapsed: `VAR REAL T[3,4]`.
fn written(text: &str, model: &FileModel, block: usize, range: TextRange) -> String {
    text[model.in_file(block, range)].split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `NAME(first, second)` with each parameter's place in it.
fn built(
    name: &str,
    parameters: impl Iterator<Item = (String, Option<String>)>,
    documentation: Option<String>,
) -> SignatureHelp {
    let mut label = format!("{name}(");
    let mut places = Vec::new();
    for (index, (text, documentation)) in parameters.enumerate() {
        if index > 0 {
            label.push_str(", ");
        }
        let range = TextRange::at(TextSize::of(label.as_str()), TextSize::of(text.as_str()));
        places.push(SignatureParameter { range, documentation });
        label.push_str(&text);
    }
    label.push(')');
    SignatureHelp { label, documentation, parameters: places, active_parameter: None }
}
