//! Find references: the definition and every use of the subprogram,
//! macrocycle, jump target or parameter under the cursor.
//!
//! Calls and jumps come from the cached program models; only the blocks
//! they are written in are lowered, for their `L` word. Parameter uses are
//! indexed per chunk of blocks and cached, so after an edit one chunk is
//! lowered again. Nothing here walks the program's flow.

use ncc_catalog::{AddressRole, split_code};
use ncc_syntax::{TextRange, TextSize};

use super::{Target, block_at, symbols::Outline, target_at};
use crate::{
    cnc8x6::{
        chunks,
        model::{self, FileKind, Program, Transfer},
    },
    db::{self, BlockChunk, Db, Settings, SourceFile},
    dialect,
    lower::{BlockData, Value},
};

/// A place where the thing is defined or used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reference {
    pub file: SourceFile,
    /// The `L` word of a call, jump or `G79`; a block number; `R12`.
    pub range: TextRange,
    pub kind: ReferenceKind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ReferenceKind {
    /// The `L` of a subprogram's or macrocycle's `G79`, or the number of a
    /// block that jumps go to.
    Definition,
    /// A parameter's value is read: `XR12`, `R1=R12`, or the control words
    /// R5–R8 that `G26`–`G29` run.
    Read,
    /// A parameter is assigned: `R12=5.`.
    Write,
    /// `G71 L<n>` or `G72 L<n>`.
    Call,
    /// `G73 L<n>`; a Sinumerik `GOTOF` to a label or block number.
    Jump,
    /// A Sinumerik `EXTERN` line: a program declared for its calls.
    Declaration,
}

/// The references of the thing at `offset`: the definition first, then the
/// uses, file by file in the workspace's order and by position in each.
///
/// A parameter's references are its assignments and the words that read
/// it, and the `G26`–`G29` words that run it as a control word. The
/// operands and targets of parameter arithmetic are not listed: they are
/// digits inside the control words, whose meaning depends on the operation,
/// on double precision (machine constant 283 and R95) and, for operation
/// 33, on other parameters' values, none of which the text fixes.
pub(crate) fn references(db: &dyn Db, file: SourceFile, offset: TextSize, include_declaration: bool) -> Vec<Reference> {
    let Some((index, start, block)) = block_at(db, file, offset) else { return Vec::new() };
    let program = model::program(db, file);
    let info = program.block(index);
    let mut references = match target_at(&block, offset - start) {
        Some(Target::Parameter { index: number, .. }) => parameter_references(db, file, number),
        Some(Target::Word(word)) => {
            let range = word.range + start;
            let on_label = word.letter == b'L';
            match (info.transfer, info.starts_unit) {
                _ if info.number_range == Some(range) => jump_target_references(db, file, program, index),
                (Some((transfer, code)), _) if on_label || code == range => {
                    transfer_references(db, file, program, index, transfer)
                }
                // Calls name a macrocycle file by its file name.
                (None, Some(Some(number)))
                    if on_label || dialect::starts_unit(file.parse(db).dialect(), &block, word) =>
                {
                    match program.kind {
                        FileKind::Macrocycle(own) if program.units.first().is_some_and(|u| u.blocks.start == index) => {
                            macrocycle_references(db, own)
                        }
                        _ => subprogram_references(db, file, program, number),
                    }
                }
                _ => Vec::new(),
            }
        }
        None => Vec::new(),
    };
    if !include_declaration {
        references.retain(|r| r.kind != ReferenceKind::Definition);
    }
    references
}

fn transfer_references(
    db: &dyn Db,
    file: SourceFile,
    program: &Program,
    index: usize,
    transfer: Transfer,
) -> Vec<Reference> {
    match transfer {
        Transfer::Subprogram(number) => subprogram_references(db, file, program, number),
        Transfer::Macrocycle(number) => macrocycle_references(db, number),
        Transfer::Jump(number) => {
            let target = program.jump_target(index, number);
            let mut references: Vec<Reference> =
                target.and_then(|target| block_number(file, program, target)).into_iter().collect();
            references.extend(jumps(db, file, program, index, number));
            references
        }
    }
}

/// The subprogram's `G79` and the file's calls of it.
fn subprogram_references(db: &dyn Db, file: SourceFile, program: &Program, number: u32) -> Vec<Reference> {
    let start = program.subprogram(number).map(|unit| unit.blocks.start);
    let mut references = labels_at(db, file, start, ReferenceKind::Definition);
    references.extend(labels(db, file, program, |t| t == Transfer::Subprogram(number), ReferenceKind::Call));
    references
}

/// The macrocycle files `L<number>` and every call of them in the workspace.
fn macrocycle_references(db: &dyn Db, number: u32) -> Vec<Reference> {
    let mut references = Vec::new();
    for &macro_file in model::macrocycles(db).get(&number).into_iter().flatten() {
        let program = model::program(db, macro_file);
        let first = program.units.first().map(|unit| unit.blocks.start);
        references.extend(labels_at(db, macro_file, first, ReferenceKind::Definition));
    }
    for &file in Settings::get(db).files(db) {
        let program = model::program(db, file);
        references.extend(labels(db, file, program, |t| t == Transfer::Macrocycle(number), ReferenceKind::Call));
    }
    references
}

/// The block number of block `index` and the jumps of its unit that go to it.
fn jump_target_references(db: &dyn Db, file: SourceFile, program: &Program, index: usize) -> Vec<Reference> {
    let mut references: Vec<Reference> = block_number(file, program, index).into_iter().collect();
    // Only the first block with a number in its unit is reached by jumps.
    let number = program.block(index).number.and_then(|n| u32::try_from(n).ok());
    if let Some(number) = number
        && program.jump_target(index, number) == Some(index)
    {
        references.extend(jumps(db, file, program, index, number));
    }
    references
}

fn block_number(file: SourceFile, program: &Program, index: usize) -> Option<Reference> {
    let range = program.block(index).number_range?;
    Some(Reference { file, range, kind: ReferenceKind::Definition })
}

/// The `G73 L<number>` blocks in the unit of block `index`.
fn jumps(db: &dyn Db, file: SourceFile, program: &Program, index: usize, number: u32) -> Vec<Reference> {
    let Some(unit) = program.unit_of(index) else { return Vec::new() };
    let blocks = program.transfers().filter(|b| {
        unit.blocks.contains(b) && program.block(*b).transfer.is_some_and(|(t, _)| t == Transfer::Jump(number))
    });
    labels_at(db, file, blocks, ReferenceKind::Jump)
}

/// The `L` words of the blocks whose transfer matches.
fn labels(
    db: &dyn Db,
    file: SourceFile,
    program: &Program,
    matches: impl Fn(Transfer) -> bool,
    kind: ReferenceKind,
) -> Vec<Reference> {
    let blocks = program.transfers().filter(|&b| program.block(b).transfer.is_some_and(|(t, _)| matches(t)));
    labels_at(db, file, blocks, kind)
}

/// The `L` word of each of `blocks` (block indices of `file`).
fn labels_at(
    db: &dyn Db,
    file: SourceFile,
    blocks: impl IntoIterator<Item = usize>,
    kind: ReferenceKind,
) -> Vec<Reference> {
    let mut blocks = blocks.into_iter().peekable();
    if blocks.peek().is_none() {
        return Vec::new();
    }
    let outline = Outline::new(db, file);
    blocks
        .filter_map(|index| {
            let node = outline.block(index)?;
            let lowered = BlockData::lower(node.green());
            let label = lowered.words_with(b'L').find(|w| matches!(w.value, Some(Value::Literal(_))))?;
            Some(Reference { file, range: label.range + node.text_range().start(), kind })
        })
        .collect()
}

/// Every assignment and read of parameter `number` in the file.
fn parameter_references(db: &dyn Db, file: SourceFile, number: u32) -> Vec<Reference> {
    let catalogue = Settings::get(db).dialect(db).catalogue();
    let letter = catalogue.letter_with_role(AddressRole::Parameter).map_or('R', char::from);
    let text = file.text(db);
    let mut references = Vec::new();
    for chunk in db::file_chunks(db, file) {
        for usage in chunk_parameter_uses(db, chunk.chunk).iter().filter(|u| u.number == number) {
            let mut range = usage.range + chunk.offset;
            // A read's range starts at its sign; the reference is `R12`.
            if usage.kind == ReferenceKind::Read
                && let Some(at) = text[range].rfind(|c: char| c.eq_ignore_ascii_case(&letter))
            {
                range = TextRange::new(range.start() + TextSize::of(&text[range][..at]), range.end());
            }
            references.push(Reference { file, range, kind: usage.kind });
        }
    }
    references
}

/// A read or write of a parameter in a chunk.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct ParameterUse {
    number: u32,
    kind: ReferenceKind,
    /// Relative to the chunk's start: `R12` of an assignment, the value
    /// (sign included) of a read, or the code that runs a control word.
    range: TextRange,
}

/// The parameter uses of a chunk's blocks, in order. Kept per chunk, so that
/// after an edit only the touched chunk is lowered again.
#[salsa::tracked(returns(ref))]
fn chunk_parameter_uses<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Vec<ParameterUse> {
    let catalogue = Settings::get(db).dialect(db).catalogue();
    let letter = catalogue.letter_with_role(AddressRole::Parameter).map(char::from);
    let mut uses = Vec::new();
    for (offset, block) in chunks::lower_chunk(db, chunk) {
        let first = uses.len();
        let words = block.words.iter().map(|w| (&w.value, w.value_range));
        let values = block.assignments.iter().map(|a| (&a.value, a.value_range));
        for (value, value_range) in words.chain(values) {
            if let (Some(Value::Parameter { index: Some(number), index_range, .. }), Some(range)) = (value, value_range)
            {
                let range = TextRange::new(range.start(), index_range.end()) + offset;
                uses.push(ParameterUse { number: *number, kind: ReferenceKind::Read, range });
            }
        }
        // Codes that run control words: G26 runs the word in R5.
        for (code, word) in catalogue.function_letters().flat_map(|letter| block.codes(letter)) {
            let Some(entry) = catalogue.code(char::from(word.letter), code) else { continue };
            for (_, number) in entry.requires.iter().filter_map(|r| split_code(r)).filter(|(l, _)| Some(*l) == letter) {
                uses.push(ParameterUse { number, kind: ReferenceKind::Read, range: word.range + offset });
            }
        }
        for assignment in &block.assignments {
            if let Some(number) = assignment.index {
                let range = TextRange::new(assignment.range.start(), assignment.index_range.end()) + offset;
                uses.push(ParameterUse { number, kind: ReferenceKind::Write, range });
            }
        }
        uses[first..].sort_by_key(|u| u.range.start());
    }
    uses
}
