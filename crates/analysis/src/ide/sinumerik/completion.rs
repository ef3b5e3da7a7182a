//! What completion adds in a Sinumerik file besides the catalogue's words:
//! system variables after `$`, the file's variables with their types,
//! labels after a jump, and the workspace's programs with their
//! parameters as a snippet.

use ncc_catalog::Item;
use ncc_syntax::{Dialect, SyntaxKind, TextRange};

use super::{
    blocks, catalogue,
    navigation::{declared, name_run, program_key},
    outline::declared_type,
    signature::proc_signature,
};
use crate::{
    db::{Db, Settings, SourceFile},
    ide::completion::{CompletionItem, CompletionKind, Site},
    sinumerik::model::file_model,
};

/// The jumps that name a target after them.
const JUMPS_TO_TARGETS: [&str; 4] = ["GOTO", "GOTOF", "GOTOB", "GOTOC"];

/// Whether `word` is a jump that a label follows.
pub(super) fn takes_label(word: &str) -> bool {
    JUMPS_TO_TARGETS.iter().any(|jump| jump.eq_ignore_ascii_case(word))
}

/// The system variables the catalogue documents, then the prefixes of
/// those it does not; `replace` starts at the `$`.
pub(super) fn system_variables(site: &Site<'_>, replace: TextRange) -> Vec<CompletionItem> {
    let catalogue = catalogue();
    let variables = catalogue.system_variables.iter().map(|variable| {
        let documentation = Item::SystemVariable(variable).markdown(catalogue);
        site.item(variable.name.clone(), CompletionKind::Variable, variable.title.clone(), Some(documentation), replace)
    });
    let prefixes = catalogue.variable_prefixes.iter().map(|prefix| {
        let documentation = Item::UndocumentedVariable(prefix).markdown(catalogue);
        site.item(prefix.prefix.clone(), CompletionKind::Variable, prefix.title.clone(), Some(documentation), replace)
    });
    variables.chain(prefixes).collect()
}

/// The labels of the file, once each, as written. Read from the tree, as
/// the variables are: completion asks at every keystroke, and nothing of
/// the rest of the file is needed.
pub(super) fn labels(db: &dyn Db, file: SourceFile, site: &Site<'_>, replace: TextRange) -> Vec<CompletionItem> {
    let text = file.text(db);
    let root = file.parse(db).syntax_node();
    let mut seen: Vec<String> = Vec::new();
    let mut items = Vec::new();
    for label in blocks(&root).flat_map(|block| block.children()).filter(|node| node.kind() == SyntaxKind::LABEL) {
        let Some((name, range)) = name_run(label.children_with_tokens()) else { continue };
        if seen.contains(&name) {
            continue;
        }
        seen.push(name);
        let line = text[..usize::from(range.start())].matches('\n').count() + 1;
        items.push(site.item(
            text[range].to_owned(),
            CompletionKind::Label,
            format!("label, line {line}"),
            None,
            replace,
        ));
    }
    items
}

/// The variables the file declares (DEF, PROC parameters), with their
/// types.
pub(super) fn variables(db: &dyn Db, file: SourceFile, site: &Site<'_>, replace: TextRange) -> Vec<CompletionItem> {
    let text = file.text(db);
    let root = file.parse(db).syntax_node();
    let declarations = blocks(&root)
        .flat_map(|block| block.children())
        .filter(|statement| matches!(statement.kind(), SyntaxKind::DEF_STMT | SyntaxKind::PROC_STMT))
        .flat_map(|statement| statement.children());
    let mut seen: Vec<String> = Vec::new();
    let mut items = Vec::new();
    for (name, range) in declarations.filter_map(|node| declared(&node)) {
        if seen.contains(&name) {
            continue;
        }
        seen.push(name);
        let detail = declared_type(text, &root, range).unwrap_or_default();
        items.push(site.item(text[range].to_owned(), CompletionKind::Variable, detail, None, replace));
    }
    items
}

/// The programs of the other files of the workspace: a call with the
/// PROC's parameters as placeholders.
pub(super) fn programs(db: &dyn Db, file: SourceFile, site: &Site<'_>, replace: TextRange) -> Vec<CompletionItem> {
    let mut items = Vec::new();
    for &other in Settings::get(db).files(db).iter().filter(|&&other| other != file) {
        if other.parse(db).dialect() != Dialect::Sinumerik {
            continue;
        }
        let model = file_model(db, other);
        let Some(header) = model.model.header() else { continue };
        let proc = &header.declaration;
        let Some(signature) = proc_signature(db, other, model, &program_key(&proc.name)) else { continue };
        let mut item =
            site.item(proc.name.clone(), CompletionKind::Program, signature.label, signature.documentation, replace);
        if !proc.parameters.is_empty() {
            let placeholders: Vec<String> = proc
                .parameters
                .iter()
                .enumerate()
                .map(|(index, parameter)| format!("${{{}:{}}}", index + 1, parameter.name.as_deref().unwrap_or("_")))
                .collect();
            item.insert_text = format!("{}({})", proc.name, placeholders.join(", "));
            item.snippet = true;
        }
        items.push(item);
    }
    items
}
