//! The editor's answers for a Haas lathe file: hover, go to definition,
//! references, the outline, folding and completion, all from the file's
//! model (`crate::haas_lathe::model`).

pub(crate) mod completion;
pub(crate) mod renumber;

use std::path::Path;

use nc_exec::haas_lathe::{
    lower::{Expr, ExprKind, HaasBlock, Statement, Value, Word},
    modes::Modes,
    program::{Finding, ReferenceKind, Target},
};
use ncc_catalog::{AddressRole, Catalogue, Item, program_file_number};
use ncc_syntax::{Dialect, TextRange, TextSize};

use super::{
    HoverResult, NavigationTarget,
    folding::{Fold, FoldKind, with_comment_runs},
    references::{Reference, ReferenceKind as Use},
    symbols::{DocumentSymbol, SymbolKind},
};
use crate::{
    Known,
    db::{Db, Settings, SourceFile},
    haas_lathe::{
        model::{FileModel, file_model},
        states::walk_between,
    },
};

/// What the cursor is on inside a block (ranges in the block).
enum Under<'a> {
    Word(&'a Word),
    /// `#n` with a literal number.
    Variable {
        number: u32,
        range: TextRange,
    },
    /// A function's name: `SIN` of `SIN[…]`.
    Function {
        name: &'static str,
        range: TextRange,
    },
}

fn under(block: &HaasBlock, at: TextSize) -> Option<Under<'_>> {
    let mut expressions: Vec<&Expr> = Vec::new();
    for word in block.words.iter().chain(&block.corners) {
        match &word.value {
            Some(Value::Variable { index, .. }) if word.value_range.is_some_and(|r| r.contains_inclusive(at)) => {
                let range = word.value_range.unwrap_or(word.range);
                if let Some(number) = literal(index) {
                    return Some(Under::Variable { number, range });
                }
                expressions.push(index);
            }
            Some(Value::Bracket { expr, .. }) if expr.range.contains_inclusive(at) => expressions.push(expr),
            _ if word.range.contains_inclusive(at) => return Some(Under::Word(word)),
            _ => {}
        }
    }
    for statement in &block.statements {
        statement_expressions(statement, &mut expressions);
    }
    expressions.iter().find_map(|expr| in_expression(expr, at))
}

fn statement_expressions<'a>(statement: &'a Statement, out: &mut Vec<&'a Expr>) {
    match statement {
        Statement::Assign { target, value, .. } => {
            out.push(target);
            out.push(value);
        }
        Statement::If { condition, then, .. } => {
            out.push(condition);
            if let Some(then) = then {
                statement_expressions(then, out);
            }
        }
        Statement::Goto { target, .. } => out.push(target),
        Statement::LoopStart { condition: Some(condition), .. } => out.push(condition),
        Statement::LoopStart { condition: None, .. } | Statement::LoopEnd { .. } => {}
    }
}

/// The variable or function name at `at` inside `expr`.
fn in_expression(expr: &Expr, at: TextSize) -> Option<Under<'_>> {
    if !expr.range.contains_inclusive(at) {
        return None;
    }
    match &expr.kind {
        ExprKind::Variable(index) => match literal(index) {
            Some(number) => Some(Under::Variable { number, range: expr.range }),
            None => in_expression(index, at),
        },
        ExprKind::Unary(_, operand) => in_expression(operand, at),
        ExprKind::Binary(_, left, right) => in_expression(left, at).or_else(|| in_expression(right, at)),
        ExprKind::Call(function, arguments) => {
            let name = function.name();
            let name_range = TextRange::at(expr.range.start(), TextSize::of(name));
            if name_range.contains_inclusive(at) {
                return Some(Under::Function { name, range: name_range });
            }
            arguments.iter().find_map(|argument| in_expression(argument, at))
        }
        ExprKind::Literal(_) | ExprKind::Malformed => None,
    }
}

fn literal(expr: &Expr) -> Option<u32> {
    expr.whole_number().and_then(|number| u32::try_from(number).ok())
}

/// Each block's start with the number of `WHILE … DOn` loops whose body
/// holds it, for the formatter's indentation.
pub(crate) fn nesting_levels(db: &dyn Db, file: SourceFile) -> Vec<(TextSize, u32)> {
    let model = file_model(db, file);
    let loops = model.model.programs.iter().flat_map(|program| &program.loops);
    let starts: Vec<TextSize> = model.ranges.iter().map(|range| range.start()).collect();
    super::levels(loops.map(|&(start, end)| (start, None, end)), &starts)
}

pub(crate) fn hover(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<HoverResult> {
    let model = file_model(db, file);
    let index = model.block_at(offset)?;
    let start = model.ranges[index].start();
    let catalogue = Dialect::HaasLathe.catalogue();
    let (items, range) = match under(model.block(index), offset - start)? {
        Under::Word(word) => (word_items(catalogue, word)?, word.range),
        Under::Variable { number, range } => (catalogue.items(&format!("param:{number}"))?, range),
        Under::Function { name, range } => {
            let operation = catalogue.operations.iter().find(|op| op.symbol.as_deref() == Some(name))?;
            (vec![Item::Operation(operation)], range)
        }
    };
    let item = items.iter().find(|item| !matches!(item, Item::Group(_)))?;
    let mut markdown = item.markdown(catalogue);
    if let Some(target) = target_text(db, file, model, range + start) {
        markdown = format!("{target}\n\n{markdown}");
    }
    markdown.push_str(&modal_text(&modal_states(db, file, index)));
    Some(HoverResult { range: range + start, markdown })
}

/// The codes in force before block `index`, once per distinct state the
/// checker's walk reaches it in (none for a block it does not reach): as
/// a block of its program, and as a block of each contour that holds it.
fn modal_states(db: &dyn Db, file: SourceFile, index: usize) -> Vec<String> {
    let model = file_model(db, file);
    let Some(program) = model.model.programs.iter().position(|p| p.blocks.contains(&index)) else {
        return Vec::new();
    };
    // The cycles that run the block in their contours run it from their
    // own state.
    let cycles = model.model.contours().filter(|c| c.blocks.contains(&index)).map(|c| c.cycle);
    let (first, last) = cycles.fold((index, index), |(first, last), cycle| (first.min(cycle), last.max(cycle)));
    let catalogue = Dialect::HaasLathe.catalogue();
    let mut states = Vec::new();
    walk_between(db, file, program, first, last, &mut |visit| {
        if visit.index != index {
            return;
        }
        let line = modal_line(catalogue, &visit.before.modes);
        if !states.contains(&line) {
            states.push(line);
        }
    });
    states
}

/// The codes in force in `modes`: every G group, and the M groups the
/// program changed.
fn modal_line(catalogue: &Catalogue, modes: &Modes) -> String {
    let mut codes = Vec::new();
    let mut unknown = false;
    for group in &catalogue.groups {
        let letter = group.id.chars().next().unwrap_or('G');
        match modes.known(&group.id) {
            // Of the many M groups, those the program changed.
            Known::Is(Some(number)) if letter == 'G' || group.default.as_deref() != Some(&format!("M{number:02}")) => {
                codes.push(format!("{letter}{number:02}"));
            }
            Known::Is(_) => {}
            Known::Unknown => unknown = true,
        }
    }
    match (codes.is_empty(), unknown) {
        (true, true) => "not known here (after a jump, a loop or a call)".to_owned(),
        (false, true) => format!("`{}` · other groups not known", codes.join(" ")),
        (_, false) => format!("`{}`", codes.join(" ")),
    }
}

/// The modal states before a block, for its hover.
fn modal_text(states: &[String]) -> String {
    match states {
        [] => String::new(),
        [one] => format!("\n\n---\n\n**Modal state before this block:** {one}"),
        many => format!(
            "\n\n---\n\n**Modal states before this block** (one per way it is reached):\n\n- {}",
            many.join("\n- ")
        ),
    }
}

/// The catalogue's entries for a word: `G71` for a code, the address for
/// any other letter.
fn word_items<'a>(catalogue: &'a Catalogue, word: &Word) -> Option<Vec<Item<'a>>> {
    let letter = char::from(word.letter);
    let code = word.value.as_ref().and_then(Value::whole_number).and_then(|n| u32::try_from(n).ok());
    let query = match code {
        Some(number) if catalogue.role_of(word.letter) == Some(AddressRole::Function) => format!("{letter}{number}"),
        _ => letter.to_string(),
    };
    catalogue.items(&query)
}

/// Where the reference at `range` leads, in words, for the hover's first
/// line: `Contour's first block: line 8, N10 G00 X17.`.
fn target_text(db: &dyn Db, file: SourceFile, model: &FileModel, range: TextRange) -> Option<String> {
    let targets = definitions(db, file, model, range.start());
    let reference = references_at(model, range.start()).next()?;
    let what = match reference.kind {
        ReferenceKind::ContourStart => "The contour's first block",
        ReferenceKind::ContourEnd => "The contour's last block",
        ReferenceKind::LocalCall => "Calls the local subprogram at",
        ReferenceKind::ProgramCall | ReferenceKind::MacroCall => "Calls the program at",
        ReferenceKind::Goto => "Jumps to",
    };
    let place = match targets.first() {
        None => "which is not in the workspace".to_owned(),
        Some(target) => {
            let text = target.file.text(db);
            let line = text[..usize::from(target.range.start())].matches('\n').count() + 1;
            let name = if target.file == file { String::new() } else { format!("{} ", target.file.path(db)) };
            format!("{name}line {line}, `{}`", &text[target.range])
        }
    };
    Some(format!("{what}: {place}."))
}

/// The resolved references whose number stands at `offset`.
fn references_at(model: &FileModel, offset: TextSize) -> impl Iterator<Item = nc_exec::haas_lathe::program::Reference> {
    model.model.findings.iter().filter_map(move |finding| match finding {
        Finding::Resolved { reference, .. } if model.reference_range(*reference).contains_inclusive(offset) => {
            Some(*reference)
        }
        _ => None,
    })
}

/// Block `index`'s line, without its line break.
fn line_range(db: &dyn Db, file: SourceFile, model: &FileModel, index: usize) -> TextRange {
    let range = model.ranges[index];
    let line = file.text(db)[range].trim_end_matches(['\n', '\r']);
    TextRange::at(range.start(), TextSize::of(line))
}

fn block_target(db: &dyn Db, file: SourceFile, model: &FileModel, index: usize) -> NavigationTarget {
    let range = line_range(db, file, model, index);
    let block = model.block(index);
    let name = block.number.map(|number| number.range).or(block.program.as_ref().map(|program| program.range));
    let focus = name.map_or(range, |name| model.in_file(index, name));
    NavigationTarget { file, range, focus }
}

/// The programs of the workspace: each file's by number with the block
/// that starts them, an `O` line, or the first block of a file named after
/// a number no `O` line of it has (`O01234.nc`).
fn workspace_programs(db: &dyn Db) -> Vec<(u32, SourceFile, usize)> {
    let mut programs = Vec::new();
    for &other in Settings::get(db).files(db) {
        let model = file_model(db, other);
        let mut numbers: Vec<u32> = Vec::new();
        for program in &model.model.programs {
            if let Some(number) = program.number.filter(|number| !numbers.contains(number)) {
                numbers.push(number);
                programs.push((number, other, program.blocks.start));
            }
        }
        if let Some(number) = program_file_number(Path::new(other.path(db))).filter(|number| !numbers.contains(number))
            && model.count() > 0
        {
            programs.push((number, other, 0));
        }
    }
    programs
}

/// The files of the workspace holding program `number`.
fn program_files(db: &dyn Db, number: u64) -> Vec<NavigationTarget> {
    workspace_programs(db)
        .into_iter()
        .filter(|&(program, _, _)| u64::from(program) == number)
        .map(|(_, file, start)| block_target(db, file, file_model(db, file), start))
        .collect()
}

/// Where the reference at `offset` leads.
fn definitions(db: &dyn Db, file: SourceFile, model: &FileModel, offset: TextSize) -> Vec<NavigationTarget> {
    let mut targets = Vec::new();
    for finding in &model.model.findings {
        let Finding::Resolved { reference, target } = finding else { continue };
        if !model.reference_range(*reference).contains_inclusive(offset) {
            continue;
        }
        match *target {
            Target::Block(index) => targets.push(block_target(db, file, model, index)),
            Target::Program(program) => {
                targets.push(block_target(db, file, model, model.model.programs[program].blocks.start))
            }
            Target::External(number) => targets.extend(program_files(db, number)),
        }
    }
    targets
}

pub(crate) fn goto_definition(db: &dyn Db, file: SourceFile, offset: TextSize) -> Vec<NavigationTarget> {
    definitions(db, file, file_model(db, file), offset)
}

/// The block number at `offset`, or the block a reference there names.
fn block_named_at(model: &FileModel, offset: TextSize) -> Option<usize> {
    let own = model.block_at(offset).filter(|&index| {
        model.block(index).number.is_some_and(|number| model.in_file(index, number.range).contains_inclusive(offset))
    });
    own.or_else(|| {
        model.model.findings.iter().find_map(|finding| match finding {
            Finding::Resolved { reference, target: Target::Block(index) }
                if model.reference_range(*reference).contains_inclusive(offset) =>
            {
                Some(*index)
            }
            _ => None,
        })
    })
}

pub(crate) fn references(db: &dyn Db, file: SourceFile, offset: TextSize, include_declaration: bool) -> Vec<Reference> {
    let model = file_model(db, file);
    let Some(block) = block_named_at(model, offset) else { return Vec::new() };
    let mut found = Vec::new();
    if include_declaration {
        found.push(Reference { file, range: model.number_range(block), kind: Use::Definition });
    }
    for finding in &model.model.findings {
        if let Finding::Resolved { reference, target: Target::Block(index) } = finding
            && *index == block
        {
            let kind = if reference.kind == ReferenceKind::LocalCall { Use::Call } else { Use::Jump };
            found.push(Reference { file, range: model.reference_range(*reference), kind });
        }
    }
    found
}

pub(crate) fn document_symbols(db: &dyn Db, file: SourceFile) -> Vec<DocumentSymbol> {
    let model = file_model(db, file);
    let targets: Vec<usize> = model
        .model
        .findings
        .iter()
        .filter_map(|finding| match finding {
            Finding::Resolved { target: Target::Block(index), .. } => Some(*index),
            _ => None,
        })
        .collect();
    let mut symbols = Vec::new();
    for program in &model.model.programs {
        let Some(range) = blocks_range(db, file, model, program.blocks.clone()) else { continue };
        let first = program.blocks.start;
        let selection = model.block(first).program.as_ref().map_or(range, |o| model.in_file(first, o.range));
        let mut children = Vec::new();
        for index in program.blocks.clone() {
            let block = model.block(index);
            if let Some(tool) = block.word(b'T') {
                let name = format!("T{}", value_text(tool));
                let detail = block.comments.first().map(|comment| comment.body.trim().to_owned());
                let range = line_range(db, file, model, index);
                let selection_range = model.in_file(index, tool.range);
                let kind = SymbolKind::Tool;
                children.push(DocumentSymbol { name, kind, detail, range, selection_range, children: Vec::new() });
            }
            if targets.contains(&index)
                && let Some(number) = block.number.and_then(|number| number.value)
            {
                children.push(DocumentSymbol {
                    name: format!("N{number}"),
                    kind: SymbolKind::JumpTarget,
                    detail: None,
                    range: line_range(db, file, model, index),
                    selection_range: model.number_range(index),
                    children: Vec::new(),
                });
            }
        }
        symbols.push(DocumentSymbol {
            name: program.number.map_or_else(|| "program".to_owned(), |number| format!("O{number}")),
            kind: SymbolKind::Program,
            detail: program.title.clone(),
            range,
            selection_range: selection,
            children,
        });
    }
    symbols
}

/// A word's value as written in the outline (`0101` of `T0101`).
fn value_text(word: &Word) -> String {
    match &word.value {
        Some(Value::Literal(decimal)) => decimal.to_string(),
        _ => "?".to_owned(),
    }
}

/// From the first block's start to the end of the last block's line.
fn blocks_range(db: &dyn Db, file: SourceFile, model: &FileModel, blocks: std::ops::Range<usize>) -> Option<TextRange> {
    let last = blocks.end.checked_sub(1)?;
    let first = model.ranges.get(blocks.start)?;
    Some(TextRange::new(first.start(), line_range(db, file, model, last).end()))
}

/// Programs, loops (`DOn` … `ENDn`) and contours (P … Q), and runs of
/// comment lines.
pub(crate) fn folding_ranges(db: &dyn Db, file: SourceFile) -> Vec<Fold> {
    let model = file_model(db, file);
    let mut regions: Vec<std::ops::Range<usize>> = model.model.programs.iter().map(|p| p.blocks.clone()).collect();
    for program in &model.model.programs {
        regions.extend(program.loops.iter().map(|&(start, end)| start..end + 1));
    }
    regions.extend(model.model.contours().map(|contour| *contour.blocks.start()..*contour.blocks.end() + 1));
    // G70 finishes the contour G71 roughed: one fold.
    regions.sort_by_key(|blocks| (blocks.start, blocks.end));
    regions.dedup();
    let folds = regions
        .into_iter()
        .filter_map(|blocks| blocks_range(db, file, model, blocks))
        .map(|range| Fold { range, kind: FoldKind::Region })
        .collect();
    with_comment_runs(db, file, folds)
}

#[cfg(test)]
mod tests {
    use ncc_syntax::{Dialect, TextRange};

    use super::*;
    use crate::{AnalysisHost, Config, FileId, TextEdit, haas_lathe::states::STRIDE, haas_lathe::walk::walk};

    /// Long programs with contours, loops and jumps: the repository's
    /// programs repeated, so that checkpoints fall inside programs and
    /// contours, and a finishing cycle whose contour comes later with
    /// checkpoints between.
    fn long_programs() -> Vec<String> {
        let programs = [
            include_str!("../../../syntax/test_data/haas-lathe/e14_g71_type1_program.nc"),
            include_str!("../../../syntax/test_data/haas-lathe/e12_g71_g70_skeleton.nc"),
            include_str!("../../../syntax/test_data/haas-lathe/macro_program.nc"),
            include_str!("../../../syntax/test_data/haas-lathe/e22_corner_examples.nc"),
            include_str!("../../../../examples/haas-lathe/O1000.nc"),
        ];
        let mut long: Vec<String> = programs
            .iter()
            .map(|text| {
                // Without tape marks: the text after a closing `%` is not read.
                let once: String =
                    text.lines().filter(|line| line.trim() != "%").map(|line| format!("{line}\n")).collect();
                once.repeat(3 * STRIDE / once.lines().count() + 1)
            })
            .collect();
        long.push(format!(
            "O2\nG54 G00 X50. Z2.\nG70 P100 Q110 F0.1\n{}N100 G01 X20. G42\nG02 X30. Z-5. R5.\nN110 G01 Z-20. G40\nM30\n",
            "G01 Z-1. F0.1\nG00 Z2. M08\n".repeat(STRIDE)
        ));
        long
    }

    /// Hover's states of every block against those a walk of the whole
    /// file gives.
    fn assert_hover_states_are_the_whole_walks(host: &AnalysisHost, file: FileId, what: &str) {
        let db = host.db();
        let catalogue = Dialect::HaasLathe.catalogue();
        let model = file_model(db, file);
        let mut whole: Vec<Vec<String>> = vec![Vec::new(); model.count()];
        walk(model, &mut |visit| {
            let line = modal_line(catalogue, &visit.before.modes);
            if !whole[visit.index].contains(&line) {
                whole[visit.index].push(line);
            }
        });
        let reached = whole.iter().filter(|states| !states.is_empty()).count();
        assert!(reached > 2 * STRIDE, "{reached} of {} blocks reached", whole.len());
        for (index, states) in whole.iter().enumerate() {
            assert_eq!(&modal_states(db, file, index), states, "block {index} {what}");
        }
    }

    /// A hover walks from a checkpoint: each block gets the states a walk
    /// of the whole file gives it, before and after the checkpoints are
    /// prepared, and after edits that change the modal state, with and
    /// without preparing between them.
    #[test]
    fn hover_states_from_checkpoints_are_those_of_the_whole_walk_across_edits() {
        for text in long_programs() {
            let mut host = AnalysisHost::in_dialect(Dialect::HaasLathe, Config::default());
            let file = host.add_file("O1.nc", text.as_str());
            assert_hover_states_are_the_whole_walks(&host, file, "unprepared");
            host.analysis().prepare_states(file);
            assert_hover_states_are_the_whole_walks(&host, file, "prepared");
            // G00 and G01 swapped at places spread over the file; a line
            // break now and then moves the blocks.
            let mut seed = 7_u64;
            for edit in 0..12 {
                seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                let current = host.analysis().text(file);
                let codes: Vec<usize> = current.match_indices("G0").map(|(at, _)| at + 2).collect();
                let at = codes[(seed >> 33) as usize % codes.len()];
                let (insert, delete) = match (edit % 5, &current[at..=at]) {
                    (4, _) => ("\n", 0),
                    (_, "0") => ("1", 1),
                    (_, "1") => ("0", 1),
                    _ => ("", 0),
                };
                let (at, insert, delete) = match current.find("Z-20. G40") {
                    // A contour after its cycle, checkpoints between: the
                    // feed mode it leaves holds after the cycle.
                    Some(contour_end) if edit == 1 => (contour_end + 9, " G98", 0),
                    _ => (at, insert, delete),
                };
                let range = TextRange::at(TextSize::from(at as u32), TextSize::from(delete));
                host.apply_edit(file, &TextEdit::replace(range, insert));
                if edit % 3 == 0 {
                    host.analysis().prepare_states(file);
                }
                // Some edits pile up before a question.
                if edit % 4 == 2 {
                    continue;
                }
                assert_hover_states_are_the_whole_walks(&host, file, &format!("after edit {edit} at {at}"));
            }
        }
    }
}
