//! Answers for editors: hover and go to definition, as plain data.
//!
//! Both start from the block under the cursor, lowered, and the word in it;
//! what the program knows there (parameter values, where they were set)
//! comes from the flow walk, stopped at nothing: every time the walk reaches
//! the block counts, so a subprogram called with different values shows
//! them all.

mod cnc8x6;
mod common_ends;
pub(crate) mod completion;
pub(crate) mod cycle_time;
pub(crate) mod folding;
pub(crate) mod format;
mod haas_lathe;
pub(crate) mod highlight;
pub(crate) mod inlay;
pub(crate) mod references;
pub(crate) mod renumber;
mod sinumerik;
pub(crate) mod symbols;

use ncc_catalog::{AddressRole, Item};
use ncc_syntax::{Dialect, TextEdit, TextRange, TextSize};

use nc_exec::known::Known;

use crate::{
    cnc8x6::flow::{self, ModalState, ParamState, show_thousandths},
    cnc8x6::model::{self, Transfer},
    db::{Db, Settings, SourceFile},
    lower::{BlockData, Value, Word},
};

/// Text to show for the thing under the cursor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HoverResult {
    /// What the text describes.
    pub range: TextRange,
    pub markdown: String,
}

/// A place to go to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NavigationTarget {
    pub file: SourceFile,
    /// The whole target, e.g. a subprogram's `G79` block.
    pub range: TextRange,
    /// The part to select: the block number, or the assignment.
    pub focus: TextRange,
}

/// What a rename changes: the edits of each file, and the files renamed
/// with the program they hold (a Sinumerik program is found by its file's
/// name), each with its new path.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Renaming {
    pub edits: Vec<(SourceFile, Vec<TextEdit>)>,
    pub moved: Vec<(SourceFile, String)>,
}

impl Renaming {
    /// The edits of `file`.
    pub fn in_file(&self, file: SourceFile) -> &[TextEdit] {
        self.edits.iter().find(|(edited, _)| *edited == file).map_or(&[], |(_, edits)| edits)
    }
}

/// A called procedure's or function's signature, for the call the cursor
/// is in.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SignatureHelp {
    /// `PROFIL(REAL C, BOOL H, REAL X)`.
    pub label: String,
    /// Markdown.
    pub documentation: Option<String>,
    pub parameters: Vec<SignatureParameter>,
    /// The parameter the cursor is in; `None` past the last.
    pub active_parameter: Option<usize>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SignatureParameter {
    /// Where the parameter stands in the signature's label.
    pub range: TextRange,
    /// Markdown.
    pub documentation: Option<String>,
}

/// What the thing at `offset` is.
pub(crate) fn hover(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<HoverResult> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => hover_in_unit(db, file, offset),
        Dialect::HaasLathe => haas_lathe::hover(db, file, offset),
        Dialect::Sinumerik => sinumerik::hover(db, file, offset),
    }
}

/// Where the thing at `offset` is defined.
pub(crate) fn goto_definition(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<NavigationTarget> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => definition_in_unit(db, file, offset),
        Dialect::HaasLathe => haas_lathe::goto_definition(db, file, offset),
        Dialect::Sinumerik => sinumerik::goto_definition(db, file, offset),
    }
}

/// The definition and uses of the thing at `offset`.
pub(crate) fn references(
    db: &dyn Db,
    file: SourceFile,
    offset: TextSize,
    include_declaration: bool,
) -> Vec<references::Reference> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => references::references(db, file, offset, include_declaration),
        Dialect::HaasLathe => haas_lathe::references(db, file, offset, include_declaration),
        Dialect::Sinumerik => sinumerik::references(db, file, offset, include_declaration),
    }
}

/// The name at `offset` that a rename changes, or why none can be.
pub(crate) fn prepare_rename(db: &dyn Db, file: SourceFile, offset: TextSize) -> Result<TextRange, String> {
    let dialect = file.parse(db).dialect();
    match dialect {
        Dialect::Sinumerik => sinumerik::prepare_rename(db, file, offset),
        Dialect::HaasLathe | Dialect::Cnc8x6 => Err(format!("{} programs have no names to rename", dialect.title())),
    }
}

/// The edits that give the thing at `offset` the name `new_name`, or why
/// they cannot.
pub(crate) fn rename(db: &dyn Db, file: SourceFile, offset: TextSize, new_name: &str) -> Result<Renaming, String> {
    match file.parse(db).dialect() {
        Dialect::Sinumerik => sinumerik::rename(db, file, offset, new_name),
        Dialect::HaasLathe | Dialect::Cnc8x6 => prepare_rename(db, file, offset).map(|_| Renaming::default()),
    }
}

/// The signature of the call the cursor is in.
pub(crate) fn signature_help(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<SignatureHelp> {
    match file.parse(db).dialect() {
        Dialect::Sinumerik => sinumerik::signature_help(db, file, offset),
        // Their calls take no arguments in parentheses.
        Dialect::HaasLathe | Dialect::Cnc8x6 => None,
    }
}

/// The outline.
pub(crate) fn document_symbols(db: &dyn Db, file: SourceFile) -> Vec<symbols::DocumentSymbol> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => symbols::document_symbols(db, file),
        Dialect::HaasLathe => haas_lathe::document_symbols(db, file),
        Dialect::Sinumerik => sinumerik::document_symbols(db, file),
    }
}

/// The folds.
pub(crate) fn folding_ranges(db: &dyn Db, file: SourceFile) -> Vec<folding::Fold> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => folding::folding_ranges(db, file),
        Dialect::HaasLathe => haas_lathe::folding_ranges(db, file),
        Dialect::Sinumerik => sinumerik::folding_ranges(db, file),
    }
}

/// The edits that format the file, or the lines `range` touches, in the
/// project's style.
pub(crate) fn format(db: &dyn Db, file: SourceFile, range: Option<TextRange>) -> Vec<TextEdit> {
    let style = Settings::get(db).config(db).format;
    let levels = match file.parse(db).dialect() {
        _ if style.indent.is_none() => Vec::new(),
        Dialect::Sinumerik => sinumerik::nesting_levels(db, file),
        Dialect::HaasLathe => haas_lathe::nesting_levels(db, file),
        // A CNC8x6 program has no nested structures to indent.
        Dialect::Cnc8x6 => Vec::new(),
    };
    format::format(file.text(db), file.parse(db), style, range, &levels)
}

/// The nesting level of blocks from the depth of the structures around
/// them: `spans` are each structure's start and end block and its middle
/// (ELSE) block, which stand at the structure's own level; `starts` are
/// the blocks' starts in the file.
fn levels(spans: impl Iterator<Item = (usize, Option<usize>, usize)>, starts: &[TextSize]) -> Vec<(TextSize, u32)> {
    let mut change = vec![0i64; starts.len() + 1];
    for (start, middle, end) in spans.filter(|&(start, _, end)| start < end && end < starts.len()) {
        change[start + 1] += 1;
        change[end] -= 1;
        if let Some(middle) = middle.filter(|&middle| start < middle && middle < end) {
            change[middle] -= 1;
            change[middle + 1] += 1;
        }
    }
    let mut level = 0i64;
    starts
        .iter()
        .zip(&change)
        .map(|(&start, &change)| {
            level += change;
            (start, u32::try_from(level).unwrap_or(0))
        })
        .collect()
}

/// The edits that renumber the file's blocks from `start` by `step`, with
/// every reference to them, or why that could change what it does.
pub(crate) fn renumber(
    db: &dyn Db,
    file: SourceFile,
    start: u64,
    step: u64,
) -> Result<Vec<TextEdit>, renumber::RenumberError> {
    let parse = file.parse(db);
    let numbering = match parse.dialect() {
        Dialect::Cnc8x6 => cnc8x6::renumber::numbering(db, file),
        Dialect::HaasLathe => haas_lathe::renumber::numbering(db, file),
        Dialect::Sinumerik => sinumerik::renumber::numbering(db, file),
    }?;
    renumber::edits(file.text(db), parse.dialect().catalogue(), &numbering, start, step)
}

/// The inlay hints of the blocks `range` touches.
pub(crate) fn inlay_hints(db: &dyn Db, file: SourceFile, range: Option<TextRange>) -> Vec<inlay::InlayHint> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => inlay::inlay_hints(db, file, range),
        // Parameter values are CNC8x6's; the cycle time's hints come from
        // the run, for every dialect.
        Dialect::HaasLathe | Dialect::Sinumerik => Vec::new(),
    }
}

/// The CNC8x6 walk's states before the block at `offset`; none in a file
/// of another dialect.
pub(crate) fn states_at(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<(ModalState, ParamState)> {
    match file.parse(db).dialect() {
        Dialect::Cnc8x6 => {
            block_index_at(db, file, offset).map(|index| flow::states_before(db, file, index)).unwrap_or_default()
        }
        Dialect::HaasLathe | Dialect::Sinumerik => Vec::new(),
    }
}

/// The index of the block of `file` at `offset` (a position at a block's
/// end belongs to it, so the cursor after the last character still finds
/// the word).
fn block_index_at(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<usize> {
    model::program(db, file).block_index_at(offset)
}

/// The block at `offset`, lowered, with its index and file offset.
pub(crate) fn block_at(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<(usize, TextSize, BlockData)> {
    let index = block_index_at(db, file, offset)?;
    let (start, block) = flow::lowered_block(db, file, index)?;
    Some((index, start, block))
}

/// What the cursor is on inside a block.
enum Target<'a> {
    Word(&'a Word),
    /// A parameter: referenced in a word, or assigned (`index_range`).
    Parameter {
        index: u32,
        range: TextRange,
    },
}

fn target_at(block: &BlockData, at: TextSize) -> Option<Target<'_>> {
    let contains = |range: TextRange| range.contains_inclusive(at);
    // `R12` in `XR12` or `R1=R12`, sign included.
    let reference = |value: &Option<Value>, range: Option<TextRange>| match (value, range) {
        (Some(Value::Parameter { index: Some(index), .. }), Some(range)) if contains(range) => {
            Some(Target::Parameter { index: *index, range })
        }
        _ => None,
    };
    for word in &block.words {
        if let Some(target) = reference(&word.value, word.value_range) {
            return Some(target);
        }
        if contains(word.range) {
            return Some(Target::Word(word));
        }
    }
    for assignment in &block.assignments {
        if let Some(target) = reference(&assignment.value, assignment.value_range) {
            return Some(target);
        }
        let assigned = TextRange::new(assignment.range.start(), assignment.index_range.end());
        if let Some(index) = assignment.index
            && contains(assigned)
        {
            return Some(Target::Parameter { index, range: assigned });
        }
    }
    None
}

fn hover_in_unit(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<HoverResult> {
    let (index, start, block) = block_at(db, file, offset)?;
    let catalogue = Settings::get(db).dialect(db).catalogue();
    match target_at(&block, offset - start)? {
        Target::Word(word) => {
            let literal = match &word.value {
                Some(Value::Literal(value)) => value.scaled(0).and_then(|v| u32::try_from(v).ok()),
                _ => None,
            };
            let letter = char::from(word.letter);
            let query = match literal {
                Some(number) if catalogue.role_of(word.letter) == Some(AddressRole::Function) => {
                    format!("{letter}{number}")
                }
                _ => letter.to_string(),
            };
            let items = catalogue.items(&query)?;
            let item = items.iter().find(|item| !matches!(item, Item::Group(_)))?;
            let mut markdown = item.markdown(catalogue);
            if letter == 'L'
                && let Some(call) = call_text(db, file, index)
            {
                markdown = format!("{call}\n\n{markdown}");
            }
            markdown.push_str(&modal_text(&flow::states_before(db, file, index)));
            Some(HoverResult { range: word.range + start, markdown })
        }
        Target::Parameter { index: number, range } => {
            let items = catalogue.items(&format!("param:{number}"))?;
            let mut markdown = items.first()?.markdown(catalogue);
            let states = flow::states_before(db, file, index);
            markdown.push_str(&values_text(number, states.iter().map(|(_, params)| params)));
            markdown.push_str(&modal_text(&states));
            Some(HoverResult { range: range + start, markdown })
        }
    }
}

/// What a `G71`/`G72`/`G73` block's L calls, in words.
fn call_text(db: &dyn Db, file: SourceFile, index: usize) -> Option<String> {
    let (transfer, _) = model::program(db, file).block(index).transfer?;
    let what = match transfer {
        Transfer::Subprogram(n) => format!("Calls subprogram L{n}"),
        Transfer::Macrocycle(n) => format!("Calls macrocycle file L{n}"),
        Transfer::Jump(n) => format!("Jumps to block N{n}"),
    };
    let missing = if transfer_targets(db, file, index, transfer).is_empty() { ", which does not exist" } else { "" };
    Some(format!("{what}{missing}."))
}

/// The modal state before the block: active G codes, F, S, T and D, once
/// per distinct state the walk reached the block in.
fn modal_text(states: &[(ModalState, ParamState)]) -> String {
    let mut lines: Vec<String> = Vec::new();
    for (state, _) in states {
        let mut parts: Vec<String> = Vec::new();
        let codes: Vec<String> = state
            .modes
            .g_groups()
            .filter_map(|slot| slot.known().flatten())
            .map(|code| format!("G{code:02}"))
            .collect();
        parts.push(format!("`{}`", codes.join(" ")));
        let settings = [('F', &state.feed), ('S', &state.speed), ('T', &state.tool), ('D', &state.offset)];
        for (letter, setting) in settings {
            parts.push(match setting {
                Known::Is(Some(setting)) => format!("{letter}`{}`", setting.value),
                Known::Is(None) => format!("{letter}`0`"),
                Known::Unknown => format!("{letter} unknown"),
            });
        }
        let line = parts.join(" · ");
        if !lines.contains(&line) {
            lines.push(line);
        }
    }
    match lines.as_slice() {
        [] => String::new(),
        [one] => format!("\n\n---\n\n**Modal state before this block:** {one}"),
        many => format!("\n\n---\n\n**Modal states before this block** (one per call):\n\n- {}", many.join("\n- ")),
    }
}

/// The parameter's values before the block, as the walk found them.
fn values_text<'a>(number: u32, states: impl Iterator<Item = &'a ParamState>) -> String {
    let mut values: Vec<String> = Vec::new();
    for params in states {
        let value = match params.get(number) {
            Some((raw, _)) => format!("`{}` ({raw} thousandths)", show_thousandths(raw)),
            None => "unknown here".to_owned(),
        };
        if !values.contains(&value) {
            values.push(value);
        }
    }
    match values.as_slice() {
        [] => "\n\n**Value before this block:** never reached from the program's start".to_owned(),
        [one] => format!("\n\n**Value before this block:** {one}"),
        many => format!("\n\n**Values before this block** (one per call): {}", many.join(", ")),
    }
}

fn definition_in_unit(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<NavigationTarget> {
    let Some((index, start, block)) = block_at(db, file, offset) else { return Vec::new() };
    match target_at(&block, offset - start) {
        Some(Target::Parameter { index: number, .. }) => {
            let mut targets: Vec<NavigationTarget> = flow::states_before(db, file, index)
                .iter()
                .filter_map(|(_, params)| params.get(number)?.1)
                .map(|origin| NavigationTarget { file, range: origin.range, focus: origin.range })
                .collect();
            targets.sort_by_key(|t| t.range.start());
            targets.dedup();
            targets
        }
        // The call's L, or its G71/G72/G73.
        Some(Target::Word(word)) => {
            let program = model::program(db, file);
            match program.block(index).transfer {
                Some((transfer, code)) if word.letter == b'L' || code == word.range + start => {
                    transfer_targets(db, file, index, transfer)
                }
                _ => Vec::new(),
            }
        }
        _ => Vec::new(),
    }
}

/// Where a call or jump in block `index` goes.
fn transfer_targets(db: &dyn Db, file: SourceFile, index: usize, transfer: Transfer) -> Vec<NavigationTarget> {
    let program = model::program(db, file);
    let block_target = |file: SourceFile, program: &model::Program, block: usize| {
        let info = program.block(block);
        NavigationTarget {
            file,
            range: TextRange::new(info.offset, info.end()),
            focus: info.number_range.unwrap_or(info.head),
        }
    };
    match transfer {
        Transfer::Subprogram(number) => {
            program.subprogram(number).map(|unit| block_target(file, program, unit.blocks.start)).into_iter().collect()
        }
        Transfer::Macrocycle(number) => model::macrocycles(db)
            .get(&number)
            .into_iter()
            .flatten()
            .filter_map(|&macro_file| {
                let macro_program = model::program(db, macro_file);
                let unit = macro_program.units.first()?;
                Some(block_target(macro_file, macro_program, unit.blocks.start))
            })
            .collect(),
        Transfer::Jump(number) => {
            program.jump_target(index, number).map(|block| block_target(file, program, block)).into_iter().collect()
        }
    }
}
