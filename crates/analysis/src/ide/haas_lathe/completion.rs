//! Completion in a Haas lathe file: the codes and addresses every dialect
//! completes ([`Site`]), and what the macro language and the program's
//! references add:
//!
//! * in the P or Q of a contour cycle G70–G73, the numbered blocks of the
//!   program: for P those after the cycle, for Q those from the block P
//!   names on (after the cycle while P names none); in the P of `M97` and
//!   after `GOTO`, every numbered block of the program; in the P of `M98`
//!   or `G65`, the programs of the file and of the workspace but the one
//!   the block is in. Each with its block's text;
//! * after `#`, the variables the file uses, with their values before the
//!   block as the checker's walk knows them, then the variables the
//!   catalogue documents: each of a range of up to [`LISTED_RANGE`], the
//!   first of a longer one;
//! * keywords: where a statement or a word starts, the addresses and codes
//!   and the statements' `IF`, `GOTO`, `WHILE`, `DO` and `END`; after
//!   `IF [...]`, `THEN` and `GOTO`; after `WHILE [...]`, `DO`; in an
//!   expression (in brackets, or after `=`) the functions where an operand
//!   starts and the named operators (`EQ`, `MOD`, …) after one. Functions
//!   and operators are the catalogue's that the parser reads, with the
//!   catalogue's text.
//!
//! The contexts are read from the block's text before the cursor, with its
//! comments blanked: a block being typed is rarely one the parser reads
//! whole. Only the variable list walks the file.

use std::collections::BTreeSet;

use nc_exec::{
    haas_lathe::{
        eval::MacroValue,
        lower::{BinaryOp, Expr, ExprKind, Function, HaasBlock, Value},
        program::{ReferenceKind, reference_kind},
    },
    known::Known,
};
use ncc_catalog::{AddressRole, Catalogue, Item};
use ncc_syntax::{Dialect, HAAS_STATEMENT_KEYWORDS, TextRange, TextSize};

use super::{statement_expressions, workspace_programs};
use crate::{
    db::{Db, SourceFile},
    haas_lathe::{
        ide::arc_centre,
        model::{FileModel, file_model},
        walk::walk,
    },
    ide::completion::{CompletionItem, CompletionKind, Site, Written, fenced},
};

/// The longest range of documented variables listed one by one.
const LISTED_RANGE: u32 = 32;

/// The statement words that start a statement (`THEN` only follows `IF`).
const STATEMENT_STARTS: [&str; 5] = ["IF", "GOTO", "WHILE", "DO", "END"];

pub(crate) fn completions(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<CompletionItem> {
    let model = file_model(db, file);
    let Some(index) = model.block_at(offset) else { return Vec::new() };
    let range = model.ranges[index];
    let block = model.block(index);
    let at = offset - range.start();
    if block.comments.iter().any(|c| c.range.start() < at && (at < c.range.end() || c.unclosed)) {
        return Vec::new();
    }
    let text = &file.text(db)[range];
    let site = Site::new(db, Dialect::HaasLathe, range.start(), written(block, Dialect::HaasLathe.catalogue()));
    let request = Request { site, model, file, index, block, text, before: blanked(text, block, at) };
    request.items()
}

/// The block's words, codes and arc centre, as the neutral lists read them.
fn written(block: &HaasBlock, catalogue: &Catalogue) -> Written {
    let codes = catalogue.function_letters().flat_map(|letter| block.code_words(letter));
    Written {
        words: block.words.iter().map(|word| (word.letter, word.range)).collect(),
        codes: codes.map(|(number, word)| (word.letter, number, word.range)).collect(),
        centre: arc_centre(block),
    }
}

/// The block's text up to `at`, its comments spaces (byte for byte, so
/// that offsets stay).
fn blanked(text: &str, block: &HaasBlock, at: TextSize) -> String {
    let mut before = text[..usize::from(at)].to_owned();
    for comment in &block.comments {
        let start = usize::from(comment.range.start()).min(before.len());
        let end = usize::from(comment.range.end()).min(before.len());
        before.replace_range(start..end, &" ".repeat(end - start));
    }
    before
}

struct Request<'a> {
    site: Site<'a>,
    model: &'a FileModel,
    file: SourceFile,
    index: usize,
    block: &'a HaasBlock,
    /// The block's text.
    text: &'a str,
    /// The block's text before the cursor, comments blanked.
    before: String,
}

impl Request<'_> {
    fn at(&self) -> TextSize {
        TextSize::of(self.before.as_str())
    }

    fn items(&self) -> Vec<CompletionItem> {
        let at = self.at();
        let digits_before = self.before.len() - self.before.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        let digits_after = self.text[usize::from(at)..].bytes().take_while(u8::is_ascii_digit).count();
        let number = TextRange::new(at - size(digits_before), at + size(digits_after));
        let ahead_of_number = &self.before[..self.before.len() - digits_before];
        if ahead_of_number.ends_with('#') {
            return self.variables(TextRange::new(number.start() - size(1), number.end()));
        }
        if ahead_of_number.trim_end().ends_with("GOTO") {
            let blocks = self.program_blocks();
            return self.blocks(blocks, |number| number.to_string(), number);
        }
        let inside = |range: TextRange| range.start() < at && at <= range.end();
        if let Some(word) = self.block.words.iter().find(|word| inside(word.range)) {
            let literal = !matches!(word.value, Some(Value::Variable { .. } | Value::Bracket { .. }));
            if let Some(kind) = reference_kind(self.block, word.letter).filter(|_| literal) {
                return self.targets(kind, word.letter, word.range);
            }
            if literal && self.site.catalogue.role_of(word.letter) == Some(AddressRole::Function) {
                return self.site.codes(word.letter, Some(word.range), word.range);
            }
            if word.value.is_some() {
                return Vec::new();
            }
        }
        self.keywords()
    }

    /// Where neither a reference nor a variable is written: keywords, and
    /// where a word starts the addresses and codes.
    fn keywords(&self) -> Vec<CompletionItem> {
        let at = self.at();
        let letters = self.before.len() - self.before.trim_end_matches(|c: char| c.is_ascii_uppercase()).len();
        let typed = TextRange::new(at - size(letters), at);
        let ahead = self.before[..self.before.len() - letters].trim_end();
        let depth: i32 = ahead.bytes().map(|b| i32::from(b == b'[') - i32::from(b == b']')).sum();
        if depth > 0 || ahead.contains('=') {
            return if operand_expected(ahead) { self.functions(typed) } else { self.operators(typed) };
        }
        if ahead.ends_with(']') {
            if has_word(ahead, "WHILE") {
                return self.statement_words(&["DO"], typed);
            }
            if has_word(ahead, "IF") {
                return self.statement_words(&["THEN", "GOTO"], typed);
            }
        }
        // No address has two letters: two typed make a keyword.
        let mut items = match letters {
            0 => self.site.new_word(None, typed),
            1 => self.site.new_word(Some(typed), typed),
            _ => Vec::new(),
        };
        items.extend(self.statement_words(&STATEMENT_STARTS, typed));
        items
    }

    fn statement_words(&self, words: &[&str], replace: TextRange) -> Vec<CompletionItem> {
        HAAS_STATEMENT_KEYWORDS
            .iter()
            .filter(|(word, _)| words.contains(word))
            .map(|&(word, form)| {
                self.site.item(word.to_owned(), CompletionKind::Keyword, form.to_owned(), None, replace)
            })
            .collect()
    }

    /// The catalogue's functions that the parser reads.
    fn functions(&self, replace: TextRange) -> Vec<CompletionItem> {
        self.operations(|symbol| Function::from_name(symbol).is_some(), CompletionKind::Function, replace)
    }

    /// The catalogue's operators written as words (`EQ`, `MOD`) that the
    /// parser reads; the symbols (`+`) need no completion.
    fn operators(&self, replace: TextRange) -> Vec<CompletionItem> {
        let named =
            |symbol: &str| BinaryOp::from_symbol(symbol).is_some() && symbol.bytes().all(|b| b.is_ascii_uppercase());
        self.operations(named, CompletionKind::Keyword, replace)
    }

    fn operations(&self, read: impl Fn(&str) -> bool, kind: CompletionKind, replace: TextRange) -> Vec<CompletionItem> {
        let catalogue = self.site.catalogue;
        catalogue
            .operations
            .iter()
            .filter_map(|operation| Some((operation.symbol.as_deref().filter(|symbol| read(symbol))?, operation)))
            .map(|(symbol, operation)| {
                let documentation = Item::Operation(operation).markdown(catalogue);
                self.site.item(symbol.to_owned(), kind, operation.title.clone(), Some(documentation), replace)
            })
            .collect()
    }

    /// The blocks of the program the block is in.
    fn program_blocks(&self) -> std::ops::Range<usize> {
        self.model.model.program_of(self.index).map_or(self.index..self.index, |program| program.blocks.clone())
    }

    /// What the `letter` word at `replace` names, being a reference of `kind`.
    fn targets(&self, kind: ReferenceKind, letter: u8, replace: TextRange) -> Vec<CompletionItem> {
        let program = self.program_blocks();
        let after_cycle = self.index + 1..program.end;
        let label = |number: u64| format!("{}{number}", char::from(letter));
        match kind {
            ReferenceKind::ContourStart => self.blocks(after_cycle, label, replace),
            ReferenceKind::ContourEnd => {
                let start = self.contour_start().unwrap_or(after_cycle.start);
                self.blocks(start..program.end, label, replace)
            }
            ReferenceKind::LocalCall | ReferenceKind::Goto => self.blocks(program, label, replace),
            ReferenceKind::ProgramCall | ReferenceKind::MacroCall => self.programs(replace),
        }
    }

    /// The one block of the program that the block's P names.
    fn contour_start(&self) -> Option<usize> {
        let number = self.block.word(b'P')?.value.as_ref()?.whole_number()?;
        match self.model.model.program_of(self.index)?.block_numbers.get(&number)?.as_slice() {
            [block] => Some(*block),
            _ => None,
        }
    }

    /// The numbered blocks among `blocks`, labelled by `label`.
    fn blocks(
        &self,
        blocks: std::ops::Range<usize>,
        label: impl Fn(u64) -> String,
        replace: TextRange,
    ) -> Vec<CompletionItem> {
        let text = self.file.text(self.site.db);
        blocks
            .filter_map(|index| {
                let number = self.model.block(index).number?.value?;
                let block = &text[self.model.ranges[index]];
                let line = block.lines().next().unwrap_or_default().trim_end().to_owned();
                Some(self.site.item(label(number), CompletionKind::Block, line, Some(fenced(block)), replace))
            })
            .collect()
    }

    /// The programs of the workspace but the block's own, by number.
    fn programs(&self, replace: TextRange) -> Vec<CompletionItem> {
        let db = self.site.db;
        let own = self.model.model.program_of(self.index).map(|program| program.blocks.start);
        let mut programs = workspace_programs(db);
        programs.retain(|&(_, file, start)| (file, Some(start)) != (self.file, own));
        programs.sort_by_key(|&(number, file, _)| (number, file.path(db).to_owned()));
        programs
            .into_iter()
            .map(|(number, file, start)| {
                let model = file_model(db, file);
                let title = model.model.program_of(start).and_then(|program| program.title.clone());
                let block = &file.text(db)[model.ranges[start]];
                let detail = title.map_or_else(
                    || block.lines().next().unwrap_or_default().trim_end().to_owned(),
                    |t| t.trim().to_owned(),
                );
                let documentation = format!("`{}`\n\n{}", file.path(db), fenced(block));
                self.site.item(format!("P{number}"), CompletionKind::Program, detail, Some(documentation), replace)
            })
            .collect()
    }

    /// The variables the file uses, those with a value before the block
    /// first, then those the catalogue documents.
    fn variables(&self, replace: TextRange) -> Vec<CompletionItem> {
        let catalogue = self.site.catalogue;
        let used = used_variables(self.model);
        let mut values: Vec<Vec<String>> = vec![Vec::new(); used.len()];
        walk(self.model, &mut |visit| {
            if visit.index != self.index {
                return;
            }
            for (number, seen) in used.iter().zip(&mut values) {
                let Some(value) = visit.before.variables.get(*number) else { continue };
                let shown = match value {
                    Known::Is(MacroValue::Number(value)) => format!("{}", Rounded(value)),
                    Known::Is(MacroValue::Vacant) => "vacant".to_owned(),
                    Known::Unknown => "not known".to_owned(),
                };
                if !seen.contains(&shown) {
                    seen.push(shown);
                }
            }
        });
        let mut items: Vec<(u8, CompletionItem)> = Vec::new();
        for (&number, values) in used.iter().zip(&values) {
            let known = values.iter().any(|value| value != "not known");
            let detail = if known { format!("= {}", values.join(" or ")) } else { range_title(catalogue, number) };
            let mut documentation = Item::Parameter(number).markdown(catalogue);
            if !values.is_empty() {
                documentation.push_str(&format!("\n\n---\n\n**Before this block:** {}", values.join(" or ")));
            }
            let item =
                self.site.item(format!("#{number}"), CompletionKind::Parameter, detail, Some(documentation), replace);
            items.push((u8::from(!known), item));
        }
        for range in &catalogue.parameter_ranges {
            let last = if range.last - range.first < LISTED_RANGE { range.last } else { range.first };
            for number in (range.first..=last).filter(|number| !used.contains(number)) {
                let detail = if last == range.last {
                    range.title.clone()
                } else {
                    format!("{} (#{}–#{})", range.title, range.first, range.last)
                };
                let documentation = Item::Parameter(number).markdown(catalogue);
                items.push((
                    2,
                    self.site.item(
                        format!("#{number}"),
                        CompletionKind::Parameter,
                        detail,
                        Some(documentation),
                        replace,
                    ),
                ));
            }
        }
        items.sort_by_key(|(tier, _)| *tier);
        items.into_iter().map(|(_, item)| item).collect()
    }
}

fn size(len: usize) -> TextSize {
    TextSize::try_from(len).unwrap_or_default()
}

/// The title of the catalogue's range holding `#number`.
fn range_title(catalogue: &Catalogue, number: u32) -> String {
    catalogue.parameter_ranges_of(number).next().map_or_else(|| "Macro variable".to_owned(), |r| r.title.clone())
}

/// Whether an operand comes next after `text` (trimmed): after an opening
/// bracket, `=`, a symbol or a named operator, or at the start.
fn operand_expected(text: &str) -> bool {
    let Some(last) = text.chars().next_back() else { return true };
    if matches!(last, '[' | '=' | '+' | '-' | '*' | '/' | ',') {
        return true;
    }
    let word = &text[text.trim_end_matches(|c: char| c.is_ascii_uppercase()).len()..];
    BinaryOp::from_symbol(word).is_some()
}

/// Whether `text` holds `word` as a keyword: not part of a longer run of
/// letters.
fn has_word(text: &str, word: &str) -> bool {
    text.match_indices(word).any(|(at, _)| {
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        !before.is_some_and(|c| c.is_ascii_uppercase()) && !after.is_some_and(|c| c.is_ascii_uppercase())
    })
}

/// The numbers of the variables `#n` the file writes or reads with a
/// literal number.
fn used_variables(model: &FileModel) -> BTreeSet<u32> {
    let mut used = BTreeSet::new();
    for block in model.blocks_from(0) {
        let mut expressions: Vec<&Expr> = Vec::new();
        for word in block.words.iter().chain(&block.corners) {
            match &word.value {
                Some(Value::Variable { index, .. }) => {
                    if let Some(number) = super::literal(index) {
                        used.insert(number);
                    }
                    expressions.push(index);
                }
                Some(Value::Bracket { expr, .. }) => expressions.push(expr),
                _ => {}
            }
        }
        for statement in &block.statements {
            statement_expressions(statement, &mut expressions);
        }
        while let Some(expr) = expressions.pop() {
            match &expr.kind {
                ExprKind::Variable(index) => {
                    if let Some(number) = super::literal(index) {
                        used.insert(number);
                    }
                    expressions.push(index);
                }
                ExprKind::Unary(_, operand) => expressions.push(operand),
                ExprKind::Binary(_, left, right) => expressions.extend([&**left, &**right]),
                ExprKind::Call(_, arguments) => expressions.extend(arguments),
                ExprKind::Literal(_) | ExprKind::Malformed => {}
            }
        }
    }
    used
}

/// A value as the list shows it: to four decimals, without trailing zeros.
struct Rounded(f64);

impl std::fmt::Display for Rounded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = format!("{:.4}", self.0);
        let text = text.trim_end_matches('0').trim_end_matches('.');
        f.write_str(if text == "-0" { "0" } else { text })
    }
}
