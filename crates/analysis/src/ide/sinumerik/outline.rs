//! The outline of a Sinumerik file: the PROC header holding what follows
//! it, the labels, the DEF'd variables, and the control structures the
//! program model matched (IF, WHILE, FOR, REPEAT, LOOP) and CASE lines,
//! each structure holding what lies inside it.

use std::cmp::Reverse;

use ncc_syntax::{SyntaxKind, SyntaxNode, SyntaxToken, TextRange, TextSize};

use super::{blocks, line_range};
use crate::{
    db::{Db, SourceFile},
    ide::symbols::{DocumentSymbol, SymbolKind},
    sinumerik::model::file_model,
};

pub(crate) fn document_symbols(db: &dyn Db, file: SourceFile) -> Vec<DocumentSymbol> {
    let text = file.text(db);
    let model = file_model(db, file);
    let root = file.parse(db).syntax_node();
    let mut nodes: Vec<Option<SyntaxNode>> = vec![None; model.ranges.len()];
    for block in blocks(&root) {
        if let Some(index) = model.block_starting_at(block.text_range().start()) {
            nodes[index] = Some(block);
        }
    }
    let symbol = |name: String, kind, detail, range, selection_range| DocumentSymbol {
        name,
        kind,
        detail,
        range,
        selection_range,
        children: Vec::new(),
    };
    let mut flat = Vec::new();
    for block in nodes.iter().flatten() {
        let line = line_range(text, block);
        for statement in block.children() {
            match statement.kind() {
                SyntaxKind::LABEL => {
                    let Some(name) = name_token(&statement, 0) else { continue };
                    flat.push(symbol(name.text().to_owned(), SymbolKind::JumpTarget, None, line, name.text_range()));
                }
                SyntaxKind::CASE_STMT => {
                    let of = statement.children_with_tokens().find(|c| c.as_token().is_some_and(|t| t.text() == "OF"));
                    let end = of.map_or(statement.text_range().end(), |of| of.text_range().end());
                    let head = TextRange::new(statement.text_range().start(), end);
                    flat.push(symbol(collapsed(&text[head]), SymbolKind::Structure, None, line, head));
                }
                _ => {}
            }
        }
    }
    if let Some(header) = model.model.header()
        && let Some(block) = &nodes[header.block]
        && let Some(statement) = block.children().find(|node| node.kind() == SyntaxKind::PROC_STMT)
        && let Some(name) = name_token(&statement, 1)
    {
        let after_name = TextRange::new(name.text_range().end(), statement.text_range().end());
        let signature = text[after_name].trim();
        let range = TextRange::new(block.text_range().start(), TextSize::of(text.trim_end()));
        let detail = (!signature.is_empty()).then(|| signature.to_owned());
        flat.push(symbol(name.text().to_owned(), SymbolKind::Subprogram, detail, range, name.text_range()));
    }
    for definition in &model.model.definitions {
        let declared = model.in_file(definition.block, definition.declared.range);
        let Some(name) = declared_name(&root, declared) else { continue };
        let detail = declared_type(text, &root, name);
        flat.push(symbol(text[name].to_owned(), SymbolKind::Variable, detail, declared, name));
    }
    for structure in &model.model.structures {
        let (Some(start), Some(end)) = (&nodes[structure.start], &nodes[structure.end]) else { continue };
        let Some(statement) =
            start.children().find(|node| matches!(node.kind(), SyntaxKind::IF_STMT | SyntaxKind::LOOP_START))
        else {
            continue;
        };
        let range = TextRange::new(start.text_range().start(), line_range(text, end).end());
        let keyword = statement.first_token().map_or(statement.text_range(), |token| token.text_range());
        let name = collapsed(&statement.text().to_string());
        flat.push(symbol(name, SymbolKind::Structure, None, range, keyword));
    }
    nest(flat)
}

/// The first name of a node: a label's, a `PROC`'s after the keyword.
fn name_token(node: &SyntaxNode, skip: usize) -> Option<SyntaxToken> {
    node.children_with_tokens()
        .filter_map(|child| child.into_token())
        .filter(|token| token.kind() == SyntaxKind::IDENT)
        .nth(skip)
}

/// The smallest node of one of `kinds` that holds `range`.
fn enclosing(root: &SyntaxNode, range: TextRange, kinds: &[SyntaxKind]) -> Option<SyntaxNode> {
    let element = root.covering_element(range);
    let node = element.as_node().cloned().or_else(|| element.parent())?;
    node.ancestors().find(|node| kinds.contains(&node.kind()))
}

/// The name a `VAR_DECL` at `range` declares, as written.
fn declared_name(root: &SyntaxNode, range: TextRange) -> Option<TextRange> {
    let declaration = enclosing(root, range, &[SyntaxKind::VAR_DECL])?;
    let mut tokens = declaration
        .children_with_tokens()
        .take_while(|c| matches!(c.kind(), SyntaxKind::IDENT | SyntaxKind::LETTER | SyntaxKind::NUMBER))
        .map(|c| c.text_range());
    let first = tokens.next()?;
    Some(tokens.fold(first, |name, token| name.cover(token)))
}

/// The type of the variable or parameter whose name is at `name`, as
/// written: `STRING[50]`, `VAR REAL`.
pub(super) fn declared_type(text: &str, root: &SyntaxNode, name: TextRange) -> Option<String> {
    let declaration = enclosing(root, name, &[SyntaxKind::VAR_DECL, SyntaxKind::PARAM])?;
    let type_of = |node: &SyntaxNode| node.children().find(|child| child.kind() == SyntaxKind::TYPE);
    let written = match declaration.kind() {
        SyntaxKind::PARAM => {
            let ty = type_of(&declaration)?;
            TextRange::new(declaration.text_range().start(), ty.text_range().end())
        }
        _ => type_of(&declaration.parent()?)?.text_range(),
    };
    Some(collapsed(&text[written]))
}

/// Text on one line, blanks collapsed.
fn collapsed(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The symbols nested by their ranges: each in the smallest PROC or
/// structure that holds it.
fn nest(mut flat: Vec<DocumentSymbol>) -> Vec<DocumentSymbol> {
    fn attach(stack: &mut [DocumentSymbol], roots: &mut Vec<DocumentSymbol>, symbol: DocumentSymbol) {
        match stack.last_mut() {
            Some(parent) => parent.children.push(symbol),
            None => roots.push(symbol),
        }
    }
    flat.sort_by_key(|symbol| (symbol.range.start(), Reverse(symbol.range.end())));
    let mut roots = Vec::new();
    let mut stack: Vec<DocumentSymbol> = Vec::new();
    for symbol in flat {
        while let Some(top) = stack.pop() {
            let holds = matches!(top.kind, SymbolKind::Subprogram | SymbolKind::Structure);
            if holds && top.range.contains_range(symbol.range) {
                stack.push(top);
                break;
            }
            attach(&mut stack, &mut roots, top);
        }
        stack.push(symbol);
    }
    while let Some(done) = stack.pop() {
        attach(&mut stack, &mut roots, done);
    }
    roots
}
