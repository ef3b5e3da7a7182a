//! Program structure: header and end, units, block numbers, calls and jumps.

use ncc_syntax::{TextEdit, TextRange, TextSize, ast::AstNode};
use rustc_hash::FxHashMap;

use crate::{
    Diagnostic,
    cnc8x6::model::{self, FileKind, Program, Transfer, Unit},
    db::{Db, SourceFile},
    diagnostic::declare_rules,
};

declare_rules! {
    MISSING_PROGRAM_HEADER = "P101", "missing-program-header", Error, "A partprogram without its `%` header.";
    INVALID_PROGRAM_NUMBER = "P102", "invalid-program-number", Error, "A program number outside 1 to 999999.";
    MISSING_PHYSICAL_END = "P103", "missing-physical-end", Info, "No `*` at the end, needed only for loading over a serial line.";
    DUPLICATE_BLOCK_NUMBER = "P104", "duplicate-block-number", Error, "A block number used twice in one file.";
    MISSING_PROGRAM_END = "P105", "missing-program-end", Error, "A main program without M02 or M30 in its last block.";
    CODE_AFTER_PROGRAM_END = "P106", "code-after-program-end", Error, "Blocks after M02/M30 that belong to no subprogram.", unnecessary;
    MISPLACED_SUBPROGRAM = "P107", "misplaced-subprogram", Error, "A subprogram before the main program's end.";
    MISSING_G70 = "P109", "missing-g70", Error, "A subprogram or macrocycle without its closing G70 block.";
    G70_OUTSIDE_SUBPROGRAM = "P110", "g70-outside-subprogram", Warning, "G70 in the main program, outside any subprogram.";
    TOO_MANY_SUBPROGRAMS = "P111", "too-many-subprograms", Error, "More than 99 subprograms in one file.";
    DUPLICATE_SUBPROGRAM = "P112", "duplicate-subprogram", Error, "Two subprograms with the same number.";
    UNDEFINED_SUBPROGRAM = "P113", "undefined-subprogram", Error, "G71 calls a subprogram the file does not define.";
    UNDEFINED_MACROCYCLE = "P114", "undefined-macrocycle", Warning, "G72 calls a macrocycle file the workspace does not have.";
    MACROCYCLE_NUMBER_MISMATCH = "P115", "macrocycle-number-mismatch", Error, "A macrocycle file whose G79 L differs from its name.";
    MACROCYCLE_WITHOUT_G79 = "P116", "macrocycle-without-g79", Error, "A macrocycle or cycle file that does not start with `G79 L..`.";
    DUPLICATE_MACROCYCLE = "P117", "duplicate-macrocycle", Error, "Two macrocycle files with the same number.";
    JUMP_TARGET_NOT_IN_UNIT = "P118", "jump-target-not-in-unit", Error, "G73 jumps to a block outside its program unit, or to none.";
    NESTED_SUBPROGRAM_CALL = "P119", "nested-subprogram-call", Info, "G71 inside a subprogram, which the manual does not describe.";
    CYCLE_NUMBER_UNREACHABLE = "P120", "cycle-number-unreachable", Warning, "A fixed-cycle body with a number outside 81 to 89.", unnecessary;
    FLOW_NOT_FOLLOWED = "P121", "flow-not-followed", Info, "A block after which the checker cannot follow the program: a jump or call from a parameter with no known value, or a loop longer than it runs.";
}

pub(crate) fn check(db: &dyn Db, file: SourceFile) -> Vec<Diagnostic> {
    let program = model::program(db, file);
    let mut out = Vec::new();
    check_header_and_end(db, file, program, &mut out);
    check_block_numbers(program, &mut out);
    check_units(db, file, program, &mut out);
    check_transfers(db, program, &mut out);
    out
}

pub(crate) fn file_start(db: &dyn Db, file: SourceFile) -> TextRange {
    let text = file.text(db);
    let first_char = text.chars().next().map_or(0, char::len_utf8);
    TextRange::at(TextSize::from(0), TextSize::from(first_char as u32))
}

fn check_header_and_end(db: &dyn Db, file: SourceFile, program: &Program, out: &mut Vec<Diagnostic>) {
    let tree = file.parse(db).tree();
    match tree.header() {
        None if program.kind == FileKind::Program => out.push(Diagnostic::new(
            &MISSING_PROGRAM_HEADER,
            file_start(db, file),
            "a partprogram must start with `%` and its number (1 to 999999), e.g. `%100 \"NAME\"`",
        )),
        None => {}
        Some(header) => {
            if let Some(number) = header.number() {
                let value = number.scaled(0).filter(|_| !number.has_point() && number.sign().is_none());
                if !value.is_some_and(|v| (1..=999_999).contains(&v)) {
                    let range = header.number_token().map_or(header.text_range(), |t| t.text_range());
                    out.push(Diagnostic::new(
                        &INVALID_PROGRAM_NUMBER,
                        range,
                        format!("program number `{number}`: it must be a whole number from 1 to 999999, without sign or decimal point"),
                    ));
                }
            }
        }
    }
    if program.kind == FileKind::Program && tree.end().is_none() {
        let last = program.block_count().checked_sub(1);
        let range = last.map_or_else(|| file_start(db, file), |last| head(program, last));
        out.push(Diagnostic::new(
            &MISSING_PHYSICAL_END,
            range,
            "no physical end `*` after the last block: the control's editor adds it, but loading over a serial line needs it",
        ));
    }
}

/// Block numbers are unique in a file (in a fixed-cycle file, per body).
///
/// Programs number their blocks mostly in order, so the chunks' number
/// ranges rarely overlap: only chunks whose ranges overlap are compared,
/// and each chunk's numbers come sorted.
fn check_block_numbers(program: &Program, out: &mut Vec<Diagnostic>) {
    let mut chunks: Vec<(usize, &[(u64, u32)])> = program.chunk_numbers().filter(|(_, n)| !n.is_empty()).collect();
    chunks.sort_by_key(|(_, numbers)| numbers[0].0);
    let highest = |numbers: &[(u64, u32)]| numbers[numbers.len() - 1].0;
    let mut start = 0;
    while start < chunks.len() {
        // The chunks whose number ranges overlap this one's, transitively.
        let mut end = start + 1;
        let mut max = highest(chunks[start].1);
        while end < chunks.len() && chunks[end].1[0].0 <= max {
            max = max.max(highest(chunks[end].1));
            end += 1;
        }
        let cluster = &chunks[start..end];
        // Alone, a chunk's sorted numbers show its duplicates side by side.
        if cluster.len() > 1 || cluster[0].1.windows(2).any(|pair| pair[0].0 == pair[1].0) {
            let blocks = cluster
                .iter()
                .flat_map(|&(first, numbers)| numbers.iter().map(move |&(number, i)| (number, first + i as usize)))
                .collect();
            report_duplicates(program, blocks, out);
        }
        start = end;
    }
}

/// Reports the later uses of each number among `blocks` (number, block
/// index).
fn report_duplicates(program: &Program, mut blocks: Vec<(u64, usize)>, out: &mut Vec<Diagnostic>) {
    blocks.sort_unstable();
    for same in blocks.chunk_by(|a, b| a.0 == b.0).filter(|same| same.len() > 1) {
        // The first use in each scope: the file, or a fixed-cycle body.
        let mut firsts: Vec<(Option<usize>, TextRange)> = Vec::new();
        for &(number, index) in same {
            let scope = if program.kind == FileKind::CycleFile { program.unit_index(index) } else { None };
            let Some(range) = program.block(index).number_range else { continue };
            match firsts.iter().find(|(s, _)| *s == scope) {
                Some(&(_, first)) => out.push(
                    Diagnostic::new(
                        &DUPLICATE_BLOCK_NUMBER,
                        range,
                        format!("block number N{number} is already used: block numbers must be unique from `%` to `*`, subprograms included"),
                    )
                    .with_related(None, first, "first used here"),
                ),
                None => firsts.push((scope, range)),
            }
        }
    }
}

/// The range of a block's first word, where diagnostics about the block point.
fn head(program: &Program, index: usize) -> TextRange {
    program.block(index).head
}

fn check_units(db: &dyn Db, file: SourceFile, program: &Program, out: &mut Vec<Diagnostic>) {
    if program.kind == FileKind::Program && program.block_count() > 0 && !program.has_main() {
        out.push(Diagnostic::new(
            &MISSING_PROGRAM_END,
            head(program, 0),
            "this file starts with `G79`, so it has no main program ending with M02/M30: \
             a partprogram starts with its main program, and a macrocycle file is named `L<number>`",
        ));
    } else if program.kind == FileKind::Program && program.block_count() > 0 && program.end_of_main.is_none() {
        let last_main = program.units[0].blocks.end.saturating_sub(1);
        out.push(Diagnostic::new(
            &MISSING_PROGRAM_END,
            head(program, last_main),
            "the main program has no M02 or M30: its last block must end the program (subprograms follow after it)",
        ));
    }
    for &index in &program.early_unit_starts {
        let end = program.end_of_main.map(|e| head(program, e));
        let mut diagnostic = Diagnostic::new(
            &MISPLACED_SUBPROGRAM,
            head(program, index),
            "this subprogram starts before the main program's end: subprograms go after the block with M02 or M30",
        );
        if let Some(end) = end {
            diagnostic = diagnostic.with_related(None, end, "the main program ends here");
        }
        out.push(diagnostic);
    }
    // In macrocycle and cycle files, blocks before the first unit are what
    // `macrocycle-without-g79` reports.
    let first_unit = program.units.first().map_or(usize::MAX, |u| u.blocks.start);
    let stray: Vec<usize> = match program.kind {
        FileKind::Program => program.stray_blocks.clone(),
        _ => program.stray_blocks.iter().copied().filter(|&b| b > first_unit).collect(),
    };
    if let Some(&first) = stray.first() {
        let last = *stray.last().expect("not empty");
        let range = head(program, first).cover(head(program, last));
        let message = if program.has_main() {
            "blocks after M02/M30 must belong to a subprogram (`G79 L..` … `G70`); the control never runs these"
        } else {
            "blocks outside `G79 L..` … `G70` are never run"
        };
        let mut diagnostic = Diagnostic::new(&CODE_AFTER_PROGRAM_END, range, message);
        if let Some(end) = program.end_of_main {
            diagnostic = diagnostic.with_related(None, head(program, end), "the main program ends here");
        }
        out.push(diagnostic);
    }
    for &index in &program.stray_g70 {
        out.push(Diagnostic::new(
            &G70_OUTSIDE_SUBPROGRAM,
            program.block(index).closes_unit.unwrap_or_else(|| head(program, index)),
            "G70 ends a subprogram or macrocycle; in the main program it has no subprogram to end",
        ));
    }

    let subprograms: Vec<&Unit> = program.units.iter().filter(|u| u.number.is_some()).collect();
    if program.kind == FileKind::Program && subprograms.len() > 99 {
        out.push(Diagnostic::new(
            &TOO_MANY_SUBPROGRAMS,
            head(program, subprograms[99].blocks.start),
            format!("{} subprograms in one partprogram; the control takes at most 99", subprograms.len()),
        ));
    }
    let mut numbers: FxHashMap<u32, usize> = FxHashMap::default();
    for unit in &subprograms {
        let start = unit.blocks.start;
        let number = unit.number.expect("subprograms have numbers");
        if let Some(&first) = numbers.get(&number) {
            out.push(
                Diagnostic::new(
                    &DUPLICATE_SUBPROGRAM,
                    head(program, start),
                    format!("subprogram L{number} is defined twice"),
                )
                .with_related(None, head(program, first), "first defined here"),
            );
        } else {
            numbers.insert(number, start);
        }
        if !unit.closed {
            out.push(missing_g70(db, file, program, unit));
        }
        if program.kind == FileKind::CycleFile && !(81..=89).contains(&number) {
            out.push(Diagnostic::new(
                &CYCLE_NUMBER_UNREACHABLE,
                head(program, start),
                format!("cycle body L{number}: only G81 to G89 call fixed cycles, so this body can never run"),
            ));
        }
    }
    if let FileKind::Macrocycle(name) = program.kind {
        check_macrocycle_file(db, file, program, name, out);
    }
}

/// Missing G70, with a quick fix that closes the unit after its last block.
fn missing_g70(db: &dyn Db, file: SourceFile, program: &Program, unit: &Unit) -> Diagnostic {
    let number = unit.number.expect("subprograms have numbers");
    let last = unit.blocks.end - 1;
    let insert_at = program.block(last).end();
    let numbers: Vec<u64> = program.blocks_in(unit.blocks.clone()).filter_map(|b| b.number).collect();
    let step = match numbers.as_slice() {
        [.., a, b] if b > a => b - a,
        _ => 1,
    };
    let mut next = numbers.last().copied().unwrap_or(0) + step;
    while program.numbered(next).next().is_some() {
        next += 1;
    }
    let text = file.text(db);
    let at = usize::from(insert_at);
    let needs_newline = at > 0 && !matches!(text.as_bytes()[at - 1], b'\n' | b'\r');
    let insert = format!("{}N{next} G70\n", if needs_newline { "\n" } else { "" });
    let reached = if unit.blocks.end < program.block_count() { "the next one starts" } else { "the file ends" };
    let what = match program.kind {
        FileKind::Program => "subprogram",
        FileKind::Macrocycle(_) => "macrocycle",
        FileKind::CycleFile => "cycle body",
    };
    Diagnostic::new(
        &MISSING_G70,
        head(program, unit.blocks.start),
        format!("{what} L{number} has no closing G70 block: {reached} before it is closed"),
    )
    .with_related(None, head(program, last), "its last block")
    .with_fix(
        format!("Insert `N{next} G70` after the last block"),
        vec![TextEdit::replace(TextRange::empty(insert_at), insert)],
    )
}

fn check_macrocycle_file(db: &dyn Db, file: SourceFile, program: &Program, name: u32, out: &mut Vec<Diagnostic>) {
    let Some(first) = program.units.first() else {
        if program.block_count() > 0 {
            out.push(Diagnostic::new(
                &MACROCYCLE_WITHOUT_G79,
                head(program, 0),
                format!("a macrocycle file starts with the block `N.. G79 L{name}`"),
            ));
        }
        return;
    };
    if first.blocks.start != 0 {
        out.push(Diagnostic::new(
            &MACROCYCLE_WITHOUT_G79,
            head(program, 0),
            format!("a macrocycle file starts with the block `N.. G79 L{name}`"),
        ));
    }
    if let Some(number) = first.number.filter(|&n| n != name) {
        out.push(Diagnostic::new(
            &MACROCYCLE_NUMBER_MISMATCH,
            head(program, first.blocks.start),
            format!("the file is named L{name} but defines macrocycle L{number}: `G72 L{name}` looks the file up by its name"),
        ));
    }
    let siblings = model::macrocycles(db).get(&name).map_or(&[][..], Vec::as_slice);
    if let Some(other) = siblings.iter().find(|&&other| other != file) {
        out.push(
            Diagnostic::new(
                &DUPLICATE_MACROCYCLE,
                head(program, first.blocks.start),
                format!(
                    "macrocycle L{name} is also in {}: the control must not load two files of one macrocycle",
                    other.path(db)
                ),
            )
            .with_related(
                Some(other.path(db).clone()),
                TextRange::empty(TextSize::from(0)),
                "the other file",
            ),
        );
    }
}

fn check_transfers(db: &dyn Db, program: &Program, out: &mut Vec<Diagnostic>) {
    for index in program.transfers() {
        let Some((transfer, range)) = program.block(index).transfer else { continue };
        let in_subprogram = program.unit_of(index).is_some_and(|u| u.number.is_some());
        match transfer {
            Transfer::Subprogram(number) => {
                if program.subprogram(number).is_none() {
                    let message = if program.kind == FileKind::Program {
                        format!(
                            "no subprogram L{number} in this file: G71 calls a `G79 L{number}` … `G70` subprogram after M02/M30 (G72 calls macrocycle files)"
                        )
                    } else {
                        format!(
                            "G71 L{number}: subprograms can be called only from their own partprogram; a macrocycle calls other macrocycles with G72"
                        )
                    };
                    out.push(Diagnostic::new(&UNDEFINED_SUBPROGRAM, range, message));
                } else if in_subprogram && program.kind == FileKind::Program {
                    out.push(Diagnostic::new(
                        &NESTED_SUBPROGRAM_CALL,
                        range,
                        "a subprogram calling another subprogram is not described in the manual; check that the control supports it",
                    ));
                }
            }
            Transfer::Macrocycle(number) => {
                if !model::macrocycles(db).contains_key(&number) {
                    out.push(Diagnostic::new(
                        &UNDEFINED_MACROCYCLE,
                        range,
                        format!(
                            "no macrocycle file L{number} in the workspace; the control needs it loaded as `L{number}`"
                        ),
                    ));
                }
            }
            Transfer::Jump(target) => {
                if program.unit_of(index).is_some() && program.jump_target(index, target).is_none() {
                    let elsewhere = program.numbered(u64::from(target)).next();
                    let message = match elsewhere {
                        Some(_) => format!(
                            "N{target} is in another program unit: G73 jumps only within the main program, one subprogram or one macrocycle"
                        ),
                        None => format!("no block N{target} to jump to in this program unit"),
                    };
                    let mut diagnostic = Diagnostic::new(&JUMP_TARGET_NOT_IN_UNIT, range, message);
                    if let Some(target_range) = elsewhere.and_then(|i| program.block(i).number_range) {
                        diagnostic = diagnostic.with_related(None, target_range, "the block is here");
                    }
                    out.push(diagnostic);
                }
            }
        }
    }
}
