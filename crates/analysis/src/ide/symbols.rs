//! The outline of a file: its program units, and the blocks that jumps go
//! to inside each unit.
//!
//! Everything comes from the cached program model; the tree is read only
//! at the few blocks a symbol starts or ends at.

use ncc_syntax::{
    SyntaxKind, SyntaxNode, TextRange, TextSize,
    ast::{self, AstNode},
};
use rustc_hash::FxHashMap;

use crate::{
    cnc8x6::model::{self, FileKind, Program, Transfer, Unit},
    db::{Db, SourceFile},
    dialect,
    lower::BlockData,
};

/// An entry of the outline.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DocumentSymbol {
    pub name: String,
    pub kind: SymbolKind,
    /// What the unit's first comment says, how often it is called, …
    pub detail: Option<String>,
    /// From the unit's start to the end of its last block's last line of
    /// program text (comment lines after it describe what follows).
    pub range: TextRange,
    /// The name in the text: the header's `%number`, the `L` of `G79`, the
    /// block number.
    pub selection_range: TextRange,
    pub children: Vec<DocumentSymbol>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SymbolKind {
    /// The main body of a partprogram.
    Program,
    /// `G79 L<n>` … `G70` after the main body.
    Subprogram,
    /// The body of a macrocycle file `L<n>`.
    Macrocycle,
    /// A body of a fixed-cycle file (`$PC`).
    CycleBody,
    /// A block that a jump, call or contour names (CNC8x6: `G73 L<n>` of
    /// the same unit; Haas: P, Q, M97 P, GOTO).
    JumpTarget,
    /// A tool change (Haas: a `T` word), where a lathe program's operations
    /// begin.
    Tool,
    /// A control structure (Sinumerik `IF` … `ENDIF`, `CASE`), holding
    /// what is inside it.
    Structure,
    /// A declared variable (Sinumerik `DEF`).
    Variable,
}

pub(crate) fn document_symbols(db: &dyn Db, file: SourceFile) -> Vec<DocumentSymbol> {
    let outline = Outline::new(db, file);
    let program = outline.program;
    let mut calls: FxHashMap<u32, usize> = FxHashMap::default();
    for index in program.transfers() {
        if let Some((Transfer::Subprogram(number), _)) = program.block(index).transfer {
            *calls.entry(number).or_default() += 1;
        }
    }
    let mut symbols = Vec::new();
    for (index, unit) in program.units.iter().enumerate() {
        let Some(range) = outline.unit_range(index) else { continue };
        let first = outline.block(unit.blocks.start);
        let lowered = first.as_ref().map(|node| (node.text_range().start(), BlockData::lower(node.green())));
        let label = lowered.as_ref().and_then(|(offset, block)| Some(block.word(b'L')?.range + *offset));
        let comment = first.as_ref().and_then(first_comment).or_else(|| leading_comment(&outline, unit));
        let first_focus = program.get_block(unit.blocks.start).map_or(range, block_focus);
        let symbol = |kind, name: String, detail| DocumentSymbol {
            name,
            kind,
            detail,
            range,
            selection_range: label.unwrap_or(first_focus),
            children: jump_targets(&outline, unit),
        };
        let name = match (unit.number, label) {
            (Some(number), _) => format!("L{number}"),
            (None, Some(label)) => outline.text[label].to_owned(),
            (None, None) => dialect::unnamed_unit(file.parse(db).dialect()).to_owned(),
        };
        symbols.push(match program.kind {
            FileKind::Program if outline.is_main(index) => {
                let header = outline.header.as_ref();
                let number = header.and_then(ast::Header::number_token);
                let selection = match (header, &number) {
                    (Some(header), Some(number)) => {
                        TextRange::new(header.text_range().start(), number.text_range().end())
                    }
                    (Some(header), None) => header.percent().text_range(),
                    (None, _) => first_focus,
                };
                let name = match &number {
                    Some(number) => format!("%{}", number.text()),
                    None => main_name(outline.path),
                };
                let detail = header.and_then(|h| h.comment()).and_then(|c| comment_text(&c)).or(comment);
                DocumentSymbol { selection_range: selection, ..symbol(SymbolKind::Program, name, detail) }
            }
            FileKind::Program => {
                let called = match unit.number.and_then(|n| calls.get(&n)) {
                    Some(count) => format!("called {count}×"),
                    None => "not called".to_owned(),
                };
                let detail = match comment {
                    Some(comment) => format!("{comment} · {called}"),
                    None => called,
                };
                symbol(SymbolKind::Subprogram, name, Some(detail))
            }
            FileKind::Macrocycle(_) => symbol(SymbolKind::Macrocycle, name, comment),
            FileKind::CycleFile => symbol(SymbolKind::CycleBody, name, comment),
        });
    }
    symbols
}

/// The name of a main program without a numbered header: its file's.
fn main_name(path: &str) -> String {
    match model::file_stem(path) {
        "" => "program".to_owned(),
        stem => stem.to_owned(),
    }
}

/// What to select of a block: its number, or its first word.
fn block_focus(block: model::BlockSummary) -> TextRange {
    block.number_range.unwrap_or(block.head)
}

/// The blocks of `unit` that its jumps go to, each with where it is jumped
/// from.
fn jump_targets(outline: &Outline<'_>, unit: &Unit) -> Vec<DocumentSymbol> {
    let program = outline.program;
    let mut targets: FxHashMap<u32, Option<usize>> = FxHashMap::default();
    let mut sources: Vec<(usize, usize)> = Vec::new();
    for from in unit.blocks.clone() {
        if let Some((Transfer::Jump(number), _)) = program.block(from).transfer
            && let Some(target) = *targets.entry(number).or_insert_with(|| program.jump_target(from, number))
        {
            sources.push((target, from));
        }
    }
    sources.sort_unstable();
    sources
        .chunk_by(|a, b| a.0 == b.0)
        .map(|group| {
            let target = program.block(group[0].0);
            let from: Vec<String> =
                group.iter().filter_map(|&(_, from)| Some(format!("N{}", program.block(from).number?))).collect();
            let end = outline.block(group[0].0).map_or(target.end(), |node| content_end(&node));
            DocumentSymbol {
                name: target.number.map_or_else(String::new, |n| format!("N{n}")),
                kind: SymbolKind::JumpTarget,
                detail: (!from.is_empty()).then(|| format!("jumped to from {}", from.join(", "))),
                range: TextRange::new(target.offset, end),
                selection_range: block_focus(target),
                children: Vec::new(),
            }
        })
        .collect()
}

/// The first comment in a node, without its quotes and blanks.
fn first_comment(node: &SyntaxNode) -> Option<String> {
    let comment = node.children_with_tokens().filter_map(|e| e.into_token()).find_map(ast::Comment::cast)?;
    comment_text(&comment)
}

/// The first of the comment lines right before a unit: they belong to the
/// block before it, but describe the unit.
fn leading_comment(outline: &Outline<'_>, unit: &Unit) -> Option<String> {
    let before = outline.block(unit.blocks.start.checked_sub(1)?)?;
    let end = content_end(&before);
    let comments = before.children_with_tokens().filter_map(|e| e.into_token()).filter_map(ast::Comment::cast);
    comments.filter(|c| c.syntax().text_range().start() >= end).find_map(|c| comment_text(&c))
}

fn comment_text(comment: &ast::Comment) -> Option<String> {
    let body = comment.body().trim();
    (!body.is_empty()).then(|| body.to_owned())
}

/// Where the last line with program text of a block (or header) ends.
pub(crate) fn content_end(node: &SyntaxNode) -> TextSize {
    let mut end = node.text_range().start();
    let mut line_has_text = false;
    for element in node.children_with_tokens() {
        match element.kind() {
            SyntaxKind::NEWLINE => line_has_text = false,
            SyntaxKind::WHITESPACE => {}
            SyntaxKind::COMMENT if !line_has_text => {}
            _ => {
                line_has_text = true;
                end = element.text_range().end();
            }
        }
    }
    end
}

/// A file's program model with its tree, to read the blocks units start
/// and end at.
pub(super) struct Outline<'db> {
    pub program: &'db Program,
    pub text: &'db str,
    path: &'db str,
    root: SyntaxNode,
    header: Option<ast::Header>,
}

impl<'db> Outline<'db> {
    pub fn new(db: &'db dyn Db, file: SourceFile) -> Outline<'db> {
        let tree = file.parse(db).tree();
        Outline {
            program: model::program(db, file),
            text: file.text(db),
            path: file.path(db),
            header: tree.header(),
            root: tree.syntax().clone(),
        }
    }

    /// The tree node of block `index`, found by its range without walking
    /// the blocks before it.
    pub fn block(&self, index: usize) -> Option<SyntaxNode> {
        let info = self.program.get_block(index)?;
        let range = TextRange::at(info.offset, info.len);
        let node = self.root.child_or_token_at_range(range)?.into_node()?;
        match node.kind() {
            SyntaxKind::BLOCK_RUN => node.child_or_token_at_range(range)?.into_node(),
            _ => Some(node),
        }
    }

    /// Whether unit `index` is the main body of a partprogram (a file that
    /// starts with `G79` has none).
    fn is_main(&self, index: usize) -> bool {
        index == 0
            && self.program.kind == FileKind::Program
            && self.program.units[0].number.is_none()
            && self.program.get_block(self.program.units[0].blocks.start).is_none_or(|b| b.starts_unit.is_none())
    }

    /// The range of unit `index`: the main body from its header, any unit to
    /// its last block's last line of program text. `None` for a main body
    /// with neither header nor blocks.
    pub fn unit_range(&self, index: usize) -> Option<TextRange> {
        let unit = &self.program.units[index];
        let header = self.header.as_ref().filter(|_| self.is_main(index));
        let start = match header {
            Some(header) => header.text_range().start(),
            None => self.program.get_block(unit.blocks.start)?.offset,
        };
        let last = match unit.blocks.end.checked_sub(1).filter(|&last| last >= unit.blocks.start) {
            Some(last) => self.block(last)?,
            None => header?.syntax().clone(),
        };
        Some(TextRange::new(start, content_end(&last)))
    }
}
