//! The program model of one file over its lowered blocks: the programs in
//! it, their block numbers, the P/Q contours of G70–G73 (lathe manual §6.9
//! (001:1556-1574)) and the targets of M97, M98, G65 and GOTO.
//!
//! What it finds is plain data ([`Finding`]); the checker turns it into
//! diagnostics and the runner follows the targets.

use std::{
    collections::BTreeMap,
    ops::{Range, RangeInclusive},
};

use ncc_syntax::{Dialect, Parse};

use super::lower::{HaasBlock, Statement, Value, Word, block_nodes};

/// A file's lowered blocks by index: a slice, or the parts an editor keeps
/// them in (lowered again only where an edit touched them).
pub trait Blocks {
    fn count(&self) -> usize;
    fn at(&self, index: usize) -> &HaasBlock;

    /// The blocks of `range`, in order.
    fn span(&self, range: Range<usize>) -> impl Iterator<Item = &HaasBlock> {
        range.map(|index| self.at(index))
    }

    /// The indices of the [`marked`] blocks of `range`, in order: all the
    /// model reads besides the blocks of contours.
    fn marked(&self, range: Range<usize>) -> impl Iterator<Item = usize> {
        range.filter(|&index| marked(self.at(index)))
    }
}

/// Whether the model reads `block` (a program's start, a block number, a
/// macro statement, a contour cycle, a call) or the program's end (M30,
/// M02, M99), so that a long program is read through the few blocks that
/// say anything to it.
pub fn marked(block: &HaasBlock) -> bool {
    block.program.is_some()
        || block.number.is_some()
        || !block.statements.is_empty()
        || block.codes(b'G').any(|code| CONTOUR_CYCLES.contains(&code))
        || block.codes(b'M').any(|code| matches!(code, 2 | 30 | 99))
        || CALLS.iter().any(|&(letter, number, _)| block.has_code(letter, number))
}

impl Blocks for [HaasBlock] {
    fn count(&self) -> usize {
        self.len()
    }

    fn at(&self, index: usize) -> &HaasBlock {
        &self[index]
    }

    fn span(&self, range: Range<usize>) -> impl Iterator<Item = &HaasBlock> {
        self[range].iter()
    }
}

/// One program: from its `O` line to the next, or the blocks before the
/// first `O` line when they hold anything.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Program {
    /// `None` for blocks before any `O` line or an `O` without a number.
    pub number: Option<u32>,
    pub title: Option<String>,
    /// Indices into the file's blocks.
    pub blocks: Range<usize>,
    /// Every block carrying each number, in file order: numbers need not be
    /// unique or increasing (lathe manual §5.1 (001:2833-2837)).
    pub block_numbers: BTreeMap<u64, Vec<usize>>,
    /// Each `DOn` block with the nearest `ENDn` after it, by index in the
    /// file: the loops the run and the checker follow alike.
    pub loops: Vec<(usize, usize)>,
}

impl Program {
    /// The `ENDn` block of the loop that `DOn` block `start` opens.
    pub fn loop_end(&self, start: usize) -> Option<usize> {
        self.loops.iter().find(|&&(from, _)| from == start).map(|&(_, end)| end)
    }

    /// The `DOn` block of the innermost loop that `ENDn` block `end` closes.
    pub fn loop_start(&self, end: usize) -> Option<usize> {
        self.loops.iter().rev().find(|&&(_, to)| to == end).map(|&(start, _)| start)
    }
}

/// A block that names another block or program by number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reference {
    /// The index of the naming block.
    pub block: usize,
    pub kind: ReferenceKind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceKind {
    /// P of G70–G73: the contour's first block.
    ContourStart,
    /// Q of G70–G73: the contour's last block.
    ContourEnd,
    /// `M97 P`: a local subprogram, a block of the same program.
    LocalCall,
    /// `M98 P`: a program, in the file or the control's memory.
    ProgramCall,
    /// `G65 P`: a macro program, like `M98`.
    MacroCall,
    /// `GOTO n`, alone or after `IF`.
    Goto,
}

/// Where a reference leads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A block of the same program.
    Block(usize),
    /// A program of the file (index into [`ProgramModel::programs`]).
    Program(usize),
    /// A program number not in the file: in the control's memory, or
    /// missing there too.
    External(u64),
}

/// What the model finds.
#[derive(Debug, Clone, PartialEq)]
pub enum Finding {
    /// A cycle without P or Q, or a call without P (lathe manual §9 rule 27
    /// (001:1572-1573)).
    MissingAddress {
        block: usize,
        letter: u8,
    },
    /// The target is not a literal whole number (`P#1`, `GOTO #4`): only a
    /// run knows it.
    ComputedTarget(Reference),
    /// No block of the program has the number (lathe manual §9 rules 28
    /// and 54).
    TargetNotFound {
        reference: Reference,
        number: u64,
    },
    /// Several blocks of the program have the number (lathe manual §9
    /// rule 30).
    AmbiguousTarget {
        reference: Reference,
        number: u64,
        blocks: Vec<usize>,
    },
    /// Resolved references.
    Resolved {
        reference: Reference,
        target: Target,
    },
    /// The Q block comes before the P block (lathe manual §9 rule 29).
    QBeforeP {
        cycle: usize,
        p: usize,
        q: usize,
    },
    Contour(Contour),
}

/// The contour of a G70–G73 block.
#[derive(Debug, Clone, PartialEq)]
pub struct Contour {
    /// The cycle block.
    pub cycle: usize,
    /// 70, 71, 72 or 73.
    pub code: u32,
    /// The blocks P to Q.
    pub blocks: RangeInclusive<usize>,
    /// G71 only.
    pub roughing_type: Option<RoughingType>,
    /// The axis a Type I contour must not reverse along: X for G71 Type I,
    /// Z for G72.
    pub monotony: Option<AxisMonotony>,
    /// Words of the contour the cycle does not execute.
    pub ignored: Vec<IgnoredWord>,
}

/// G71's type, chosen by the P block (lathe manual §6.9 item 9
/// (001:1943, 2028-2029)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoughingType {
    /// The P block moves one axis: the contour must be monotonic in X.
    TypeI,
    /// The P block moves X (or U) and Z (or W): pockets allowed.
    TypeII,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisMonotony {
    /// `X` or `Z`.
    pub axis: u8,
    pub monotony: Monotony,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Monotony {
    /// The end points never turn back along the axis.
    Monotonic,
    /// The first block whose end point turns back.
    Reverses { block: usize },
    /// The first block with a computed coordinate: only a run can tell.
    Undetermined { block: usize },
}

/// A word inside a contour that the cycle ignores.
#[derive(Debug, Clone, PartialEq)]
pub struct IgnoredWord {
    pub block: usize,
    pub word: Word,
    pub why: Ignored,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ignored {
    /// F, S and T inside P..Q are not executed (lathe manual §6.9 item 4
    /// (001:1564, 1649)); for G72/G73 an inference.
    FeedSpeedTool,
    /// `,C`/`,R` and I/K/R on G01: roughing ignores chamfers and roundings
    /// (lathe manual §6.9 item 10 (001:3103)).
    CornerInRoughing,
    /// `A` angles: roughing executes only X/Z (lathe manual §6.9 item 10
    /// (001:3191-3193)).
    AngleInRoughing,
}

/// The calls by code whose P names their target (lathe manual §6.21
/// (001:135, 346-347)); M97 takes P as on Haas controls, not the manual's
/// `N` (lathe manual §11 OQ-15).
const CALLS: [(u8, u32, ReferenceKind); 3] = [
    (b'M', 97, ReferenceKind::LocalCall),
    (b'M', 98, ReferenceKind::ProgramCall),
    (b'G', 65, ReferenceKind::MacroCall),
];

/// The G codes of the cycles that run a contour P..Q.
const CONTOUR_CYCLES: RangeInclusive<u32> = 70..=73;

/// What the `letter` word (P or Q) of `block` names: a contour's first or
/// last block (G70–G73), or a call's target (P of M97, M98, G65).
pub fn reference_kind(block: &HaasBlock, letter: u8) -> Option<ReferenceKind> {
    let contour = block.codes(b'G').any(|code| CONTOUR_CYCLES.contains(&code));
    match letter {
        b'P' if contour => Some(ReferenceKind::ContourStart),
        b'Q' if contour => Some(ReferenceKind::ContourEnd),
        b'P' => CALLS.iter().find(|&&(l, number, _)| block.has_code(l, number)).map(|&(_, _, kind)| kind),
        _ => None,
    }
}

/// The programs of a file and what the model finds in them.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramModel {
    pub programs: Vec<Program>,
    /// In block order of the referring block.
    pub findings: Vec<Finding>,
}

impl ProgramModel {
    pub fn new(blocks: &(impl Blocks + ?Sized)) -> ProgramModel {
        let programs = split_programs(blocks);
        let mut model = ProgramModel { programs, findings: Vec::new() };
        for program in 0..model.programs.len() {
            model.read_references(blocks, program);
        }
        model
    }

    /// The program holding block `index`.
    pub fn program_of(&self, index: usize) -> Option<&Program> {
        self.programs.iter().find(|p| p.blocks.contains(&index))
    }

    /// The contours found, in file order.
    pub fn contours(&self) -> impl Iterator<Item = &Contour> {
        self.findings.iter().filter_map(|f| match f {
            Finding::Contour(contour) => Some(contour),
            _ => None,
        })
    }

    fn read_references(&mut self, blocks: &(impl Blocks + ?Sized), program: usize) {
        let range = self.programs[program].blocks.clone();
        // Read only for a program with a contour cycle: most have none.
        let mut motions = None;
        for index in blocks.marked(range.clone()) {
            let block = blocks.at(index);
            for code in block.codes(b'G') {
                if CONTOUR_CYCLES.contains(&code) {
                    let motions = motions.get_or_insert_with(|| motion_codes(blocks, range.clone()));
                    self.read_cycle(blocks, program, index, code, motions);
                }
            }
            for (letter, number, kind) in CALLS {
                if block.has_code(letter, number) {
                    self.read_call(block, program, Reference { block: index, kind });
                }
            }
            for statement in &block.statements {
                let goto = match statement {
                    Statement::If { then: Some(then), .. } => then.as_ref(),
                    other => other,
                };
                if let Statement::Goto { target, .. } = goto {
                    let reference = Reference { block: index, kind: ReferenceKind::Goto };
                    match target.whole_number() {
                        Some(number) => {
                            if let Some(target) = self.resolve_block(program, reference, number) {
                                self.findings.push(Finding::Resolved { reference, target: Target::Block(target) });
                            }
                        }
                        None => self.findings.push(Finding::ComputedTarget(reference)),
                    }
                }
            }
        }
    }

    /// The number a word names, or the finding that it names none.
    fn target_number(&mut self, word: Option<&Word>, reference: Reference, letter: u8) -> Option<u64> {
        match word.and_then(|w| w.value.as_ref()) {
            None => {
                self.findings.push(Finding::MissingAddress { block: reference.block, letter });
                None
            }
            Some(value) => {
                let number = value.whole_number();
                if number.is_none() {
                    self.findings.push(Finding::ComputedTarget(reference));
                }
                number
            }
        }
    }

    /// The one block of `program` numbered `number`.
    fn resolve_block(&mut self, program: usize, reference: Reference, number: u64) -> Option<usize> {
        match self.programs[program].block_numbers.get(&number).map(Vec::as_slice) {
            None | Some([]) => {
                self.findings.push(Finding::TargetNotFound { reference, number });
                None
            }
            Some([block]) => Some(*block),
            Some(blocks) => {
                let blocks = blocks.to_vec();
                self.findings.push(Finding::AmbiguousTarget { reference, number, blocks });
                None
            }
        }
    }

    fn read_call(&mut self, block: &HaasBlock, program: usize, reference: Reference) {
        let Some(number) = self.target_number(block.word(b'P'), reference, b'P') else { return };
        let target = match reference.kind {
            ReferenceKind::LocalCall => match self.resolve_block(program, reference, number) {
                Some(block) => Target::Block(block),
                None => return,
            },
            _ => self
                .programs
                .iter()
                .position(|p| p.number.map(u64::from) == Some(number))
                .map_or(Target::External(number), Target::Program),
        };
        self.findings.push(Finding::Resolved { reference, target });
    }

    /// A G70–G73 block: its P and Q, then its contour. `motions` are the
    /// motion codes in force after each block of the program.
    fn read_cycle(
        &mut self,
        blocks: &(impl Blocks + ?Sized),
        program: usize,
        cycle: usize,
        code: u32,
        motions: &[Option<u32>],
    ) {
        let block = blocks.at(cycle);
        let start = Reference { block: cycle, kind: ReferenceKind::ContourStart };
        let end = Reference { block: cycle, kind: ReferenceKind::ContourEnd };
        let p = self.target_number(block.word(b'P'), start, b'P');
        let q = self.target_number(block.word(b'Q'), end, b'Q');
        let p = p.and_then(|number| self.resolve_block(program, start, number));
        let q = q.and_then(|number| self.resolve_block(program, end, number));
        for (reference, block) in [(start, p), (end, q)] {
            if let Some(block) = block {
                self.findings.push(Finding::Resolved { reference, target: Target::Block(block) });
            }
        }
        let (Some(p), Some(q)) = (p, q) else { return };
        if q < p {
            self.findings.push(Finding::QBeforeP { cycle, p, q });
            return;
        }
        let contour = p..q + 1;
        let roughing_type = (code == 71).then(|| {
            let writes = |abs, inc| blocks.at(p).word(abs).is_some() || blocks.at(p).word(inc).is_some();
            if writes(b'X', b'U') && writes(b'Z', b'W') { RoughingType::TypeII } else { RoughingType::TypeI }
        });
        let monotonic_axis = match (code, roughing_type) {
            (71, Some(RoughingType::TypeI)) => Some((b'X', b'U')),
            (72, _) => Some((b'Z', b'W')),
            _ => None,
        };
        let monotony = monotonic_axis
            .map(|(axis, inc)| AxisMonotony { axis, monotony: monotony(blocks, contour.clone(), axis, inc) });
        let program_start = self.programs[program].blocks.start;
        let motion_in = |index: usize| motions.get(index - program_start).copied().flatten();
        let ignored = ignored_words(blocks, contour, code, motion_in);
        self.findings.push(Finding::Contour(Contour { cycle, code, blocks: p..=q, roughing_type, monotony, ignored }));
    }
}

/// Splits the file's blocks at its `O` lines.
/// The number of the program a run of `text` runs, the file's first, as
/// [`ProgramModel`] splits the file: `None` when blocks before any `O` line
/// make the first program, or its `O` has no number.
pub fn first_program_number(text: &str) -> Option<u32> {
    let parse = Parse::new(text, Dialect::HaasLathe);
    let first = block_nodes(parse.green()).map(|(_, block)| HaasBlock::lower(block)).find(HaasBlock::has_content);
    first?.program?.number
}

fn split_programs(blocks: &(impl Blocks + ?Sized)) -> Vec<Program> {
    let count = blocks.count();
    let starts: Vec<usize> = blocks.marked(0..count).filter(|&index| blocks.at(index).program.is_some()).collect();
    let mut programs = Vec::new();
    let first = starts.first().copied().unwrap_or(count);
    if blocks.span(0..first).any(HaasBlock::has_content) || starts.is_empty() {
        programs.push(program(blocks, None, None, 0..first));
    }
    for (i, &start) in starts.iter().enumerate() {
        let end = starts.get(i + 1).copied().unwrap_or(count);
        let header = blocks.at(start).program.as_ref();
        let number = header.and_then(|h| h.number);
        let title = header.and_then(|h| h.title.clone());
        programs.push(program(blocks, number, title, start..end));
    }
    programs
}

fn program(
    blocks: &(impl Blocks + ?Sized),
    number: Option<u32>,
    title: Option<String>,
    range: Range<usize>,
) -> Program {
    let mut block_numbers: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
    for index in blocks.marked(range.clone()) {
        if let Some(value) = blocks.at(index).number.and_then(|n| n.value) {
            block_numbers.entry(value).or_default().push(index);
        }
    }
    let loops = loop_pairs(blocks, range.clone());
    Program { number, title, blocks: range, block_numbers, loops }
}

/// Each `DOn` block of `range` with the nearest `ENDn` after it in `range`,
/// by index in the file.
fn loop_pairs(blocks: &(impl Blocks + ?Sized), range: Range<usize>) -> Vec<(usize, usize)> {
    let loop_id = |block: &HaasBlock, starts: bool| {
        block.statements.iter().find_map(|statement| match statement {
            Statement::LoopStart { id, .. } if starts => Some(*id),
            Statement::LoopEnd { id, .. } if !starts => Some(*id),
            _ => None,
        })
    };
    let mut pairs = Vec::new();
    for start in blocks.marked(range.clone()) {
        let Some(id) = loop_id(blocks.at(start), true) else { continue };
        let end = blocks.marked(start + 1..range.end).find(|&later| loop_id(blocks.at(later), false) == Some(id));
        if let Some(end) = end {
            pairs.push((start, end));
        }
    }
    pairs
}

/// The motion code (G00–G03) in force after each block of `range`, as far
/// as literal codes tell.
fn motion_codes(blocks: &(impl Blocks + ?Sized), range: Range<usize>) -> Vec<Option<u32>> {
    let mut motion = None;
    blocks
        .span(range)
        .map(|block| {
            if let Some(code) = block.codes(b'G').filter(|code| *code <= 3).last() {
                motion = Some(code);
            }
            motion
        })
        .collect()
}

/// Whether the end points of the contour's blocks along `axis` (absolute)
/// or `inc` (incremental) never turn back. Arcs are judged by their end
/// points.
fn monotony(blocks: &(impl Blocks + ?Sized), contour: Range<usize>, axis: u8, inc: u8) -> Monotony {
    let mut position: Option<f64> = None;
    let mut direction: Option<bool> = None;
    for (index, block) in contour.clone().zip(blocks.span(contour)) {
        let literal = |letter| match block.word(letter).map(|w| w.value.as_ref()) {
            None => Ok(None),
            Some(Some(Value::Literal(decimal))) => Ok(Some(decimal.to_f64())),
            Some(_) => Err(()),
        };
        let (Ok(absolute), Ok(increment)) = (literal(axis), literal(inc)) else {
            return Monotony::Undetermined { block: index };
        };
        let (delta, next) = match (absolute, increment) {
            (Some(to), _) => (position.map(|from| to - from), Some(to)),
            (None, Some(by)) => (Some(by), position.map(|from| from + by)),
            (None, None) => (None, position),
        };
        position = next;
        if let Some(delta) = delta.filter(|d| d.abs() > 1e-9) {
            let increasing = delta > 0.0;
            match direction {
                Some(known) if known != increasing => return Monotony::Reverses { block: index },
                _ => direction = Some(increasing),
            }
        }
    }
    Monotony::Monotonic
}

/// The words of the contour's blocks the cycle `code` does not execute.
fn ignored_words(
    blocks: &(impl Blocks + ?Sized),
    contour: Range<usize>,
    code: u32,
    motion_in: impl Fn(usize) -> Option<u32>,
) -> Vec<IgnoredWord> {
    let roughing = matches!(code, 71 | 72);
    let mut ignored = Vec::new();
    for (index, block) in contour.clone().zip(blocks.span(contour)) {
        let linear = motion_in(index) == Some(1);
        for word in &block.words {
            let why = match word.letter {
                b'F' | b'S' | b'T' => Some(Ignored::FeedSpeedTool),
                b'I' | b'K' | b'R' if roughing && linear => Some(Ignored::CornerInRoughing),
                b'A' if roughing => Some(Ignored::AngleInRoughing),
                _ => None,
            };
            if let Some(why) = why {
                ignored.push(IgnoredWord { block: index, word: word.clone(), why });
            }
        }
        if roughing {
            ignored.extend(block.corners.iter().map(|word| IgnoredWord {
                block: index,
                word: word.clone(),
                why: Ignored::CornerInRoughing,
            }));
        }
    }
    ignored
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    fn model(text: &str) -> ProgramModel {
        let parse = Parse::new(text, Dialect::HaasLathe);
        let tree = parse.green();
        let blocks: Vec<HaasBlock> = block_nodes(tree).map(|(_, block)| HaasBlock::lower(block)).collect();
        ProgramModel::new(blocks.as_slice())
    }

    fn reference(block: usize, kind: ReferenceKind) -> Reference {
        Reference { block, kind }
    }

    #[test]
    fn e14_is_a_type_i_g71_over_n10_to_n20_and_monotonic() {
        let model = model(include_str!("../../../syntax/test_data/haas-lathe/e14_g71_type1_program.nc"));
        assert_eq!(model.programs.len(), 1);
        assert_eq!((model.programs[0].number, model.programs[0].blocks.clone()), (Some(1234), 0..24));
        let contours: Vec<&Contour> = model.contours().collect();
        assert_eq!(contours.len(), 2);
        let (g71, g70) = (contours[0], contours[1]);
        assert_eq!((g71.code, g71.cycle, g71.blocks.clone()), (71, 6, 7..=16));
        assert_eq!(g71.roughing_type, Some(RoughingType::TypeI));
        assert_eq!(g71.monotony, Some(AxisMonotony { axis: b'X', monotony: Monotony::Monotonic }));
        assert!(g71.ignored.is_empty());
        assert_eq!((g70.code, g70.blocks.clone(), g70.roughing_type, g70.monotony), (70, 7..=16, None, None));
        // Besides the contours, the four resolved P and Q words.
        assert_eq!(model.findings.len(), 6, "{:?}", model.findings);
    }

    #[test]
    fn loops_pair_each_do_with_the_nearest_end_of_its_number() {
        // Blocks: 0 O1, 1 WHILE … DO1, 2 DO2, 3 END2, 4 END1, 5 END3, 6 DO3, 7 M30.
        let model = model("O1\nWHILE [#1 LT 3] DO1\nDO2\nEND2\nEND1\nEND3\nDO3\nM30\n");
        let program = &model.programs[0];
        assert_eq!(program.loops, [(1, 4), (2, 3)]);
        assert_eq!((program.loop_end(1), program.loop_start(4), program.loop_start(3)), (Some(4), Some(1), Some(2)));
        // An END before its DO, and a DO without END, pair with nothing.
        assert_eq!((program.loop_start(5), program.loop_end(6)), (None, None));
    }

    #[test]
    fn e17_template_is_a_type_ii_g71() {
        let model = model(include_str!("../../../syntax/test_data/haas-lathe/e17_g71_type2_template.nc"));
        let g71 = model.contours().next().expect("the G71 contour");
        assert_eq!((g71.blocks.clone(), g71.roughing_type, g71.monotony), (7..=14, Some(RoughingType::TypeII), None));
    }

    #[test]
    fn a_cycle_without_p_or_q_names_the_missing_address() {
        let model = model("G71 Q20 U0.3 D2. F0.3\nN20 X10.\nG70 P20\n");
        assert_eq!(
            model.findings,
            vec![
                Finding::MissingAddress { block: 0, letter: b'P' },
                Finding::Resolved { reference: reference(0, ReferenceKind::ContourEnd), target: Target::Block(1) },
                Finding::MissingAddress { block: 2, letter: b'Q' },
                Finding::Resolved { reference: reference(2, ReferenceKind::ContourStart), target: Target::Block(1) },
            ]
        );
    }

    #[test]
    fn p_and_q_must_name_one_block_of_the_same_program_in_order() {
        let not_found = model("G70 P5 Q6\nN5 X1.\n");
        let end = reference(0, ReferenceKind::ContourEnd);
        let start = reference(0, ReferenceKind::ContourStart);
        assert_eq!(
            not_found.findings,
            vec![
                Finding::TargetNotFound { reference: end, number: 6 },
                Finding::Resolved { reference: start, target: Target::Block(1) }
            ]
        );

        let reversed = model("N20 X1.\nN10 X2.\nG70 P10 Q20\n");
        assert_eq!(reversed.findings.last(), Some(&Finding::QBeforeP { cycle: 2, p: 1, q: 0 }));

        let duplicated = model("N10 X1.\nN10 X2.\nN20 X3.\nG70 P10 Q20\n");
        let start = reference(3, ReferenceKind::ContourStart);
        let ambiguous = Finding::AmbiguousTarget { reference: start, number: 10, blocks: vec![0, 1] };
        assert_eq!(duplicated.findings.first(), Some(&ambiguous));

        let computed = model("G70 P#1 Q20\nN20 X1.\n");
        assert_eq!(
            computed.findings.first(),
            Some(&Finding::ComputedTarget(reference(0, ReferenceKind::ContourStart)))
        );

        // N10 of the first program is not visible from the second.
        let other_program = model("O1\nN10 X1.\nM30\nO2\nG70 P10 Q10\n");
        let start = reference(4, ReferenceKind::ContourStart);
        assert!(other_program.findings.contains(&Finding::TargetNotFound { reference: start, number: 10 }));
    }

    #[test]
    fn type_i_contours_must_not_turn_back() {
        let g71 = model("G71 P1 Q4 U.3 W.1 D2. F.3\nN1 G00 X20.\nG01 Z-10.\nU-10. Z-20.\nN4 X30.\n");
        let contour = g71.contours().next().expect("a contour");
        assert_eq!(contour.roughing_type, Some(RoughingType::TypeI));
        assert_eq!(contour.monotony, Some(AxisMonotony { axis: b'X', monotony: Monotony::Reverses { block: 4 } }));

        let g72 = model("G72 P1 Q3 U.3 W.1 D2. F.3\nN1 G00 Z-20.\nG01 X40. W5.\nN3 Z-30.\n");
        let contour = g72.contours().next().expect("a contour");
        assert_eq!(contour.roughing_type, None);
        assert_eq!(contour.monotony, Some(AxisMonotony { axis: b'Z', monotony: Monotony::Reverses { block: 3 } }));

        let computed = model("G71 P1 Q2 U.3 D2. F.3\nN1 G00 X20.\nN2 X#1\n");
        let contour = computed.contours().next().expect("a contour");
        assert_eq!(contour.monotony.map(|m| m.monotony), Some(Monotony::Undetermined { block: 2 }));
    }

    #[test]
    fn roughing_ignores_corners_angles_and_feed_speed_tool_inside_the_contour() {
        let text = "G71 P1 Q3 U.3 D2. F.3\nN1 G00 X20.\nG01 Z-10. K-1. F0.2 ,R1.\nN3 X30. A45. S100\nG70 P1 Q3\n";
        let file = model(text);
        let ignored = |contour: &Contour| -> Vec<(usize, char, Ignored)> {
            contour.ignored.iter().map(|i| (i.block, char::from(i.word.letter), i.why)).collect()
        };
        let contours: Vec<&Contour> = file.contours().collect();
        assert_eq!(
            ignored(contours[0]),
            vec![
                (2, 'K', Ignored::CornerInRoughing),
                (2, 'F', Ignored::FeedSpeedTool),
                (2, 'R', Ignored::CornerInRoughing),
                (3, 'A', Ignored::AngleInRoughing),
                (3, 'S', Ignored::FeedSpeedTool),
            ]
        );
        // G70 finishes with corners and angles; only F, S and T are ignored.
        assert_eq!(ignored(contours[1]), vec![(2, 'F', Ignored::FeedSpeedTool), (3, 'S', Ignored::FeedSpeedTool)]);
        // I, K and R on an arc are its centre and radius, not a corner.
        let arc = model("G71 P1 Q2 U.3 D2. F.3\nN1 G00 X20.\nN2 G02 X30. Z-5. R5.\n");
        assert!(arc.contours().all(|c| c.ignored.is_empty()));
    }

    #[test]
    fn calls_and_jumps_resolve_to_blocks_and_programs() {
        let text = "O100 (MAIN)\nM97 P50\nM98 P200\nM98 P300\nG65 P100 A1.\nGOTO 60\nIF [#1 GT 0] GOTO 50\nM97\nN50 M99\n\
                    O200\nM99\n";
        let model = model(text);
        assert_eq!(model.programs.len(), 2);
        assert_eq!(model.programs[0].title.as_deref(), Some("MAIN"));
        assert_eq!(model.program_of(9).and_then(|p| p.number), Some(200));
        assert_eq!(
            model.findings,
            vec![
                Finding::Resolved { reference: reference(1, ReferenceKind::LocalCall), target: Target::Block(8) },
                Finding::Resolved { reference: reference(2, ReferenceKind::ProgramCall), target: Target::Program(1) },
                Finding::Resolved {
                    reference: reference(3, ReferenceKind::ProgramCall),
                    target: Target::External(300)
                },
                Finding::Resolved { reference: reference(4, ReferenceKind::MacroCall), target: Target::Program(0) },
                Finding::TargetNotFound { reference: reference(5, ReferenceKind::Goto), number: 60 },
                Finding::Resolved { reference: reference(6, ReferenceKind::Goto), target: Target::Block(8) },
                Finding::MissingAddress { block: 7, letter: b'P' },
            ]
        );
    }

    #[test]
    fn a_file_without_o_is_one_unnamed_program_with_every_block_number() {
        let model = model("\nN1 X1.\nN1 X2.\nN5 X3.\n");
        assert_eq!(model.programs.len(), 1);
        let program = &model.programs[0];
        assert_eq!((program.number, program.blocks.clone()), (None, 0..4));
        assert_eq!(program.block_numbers.get(&1), Some(&vec![1, 2]));
        assert_eq!(program.block_numbers.get(&5), Some(&vec![3]));
    }

    #[test]
    fn the_run_s_program_number_is_the_first_program_s() {
        assert_eq!(first_program_number("%\nO1234 (T)\nG00 X1.\nO5\n%\n"), Some(1234));
        assert_eq!(first_program_number("\n(NOTE)\nO7\nG00 X1.\n"), Some(7));
        // Blocks before the first O line are the program a run runs.
        assert_eq!(first_program_number("G00 X1.\nO5\n"), None);
        assert_eq!(first_program_number(""), None);
    }

    #[test]
    fn every_fixture_has_a_model() {
        let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../syntax/test_data/haas-lathe");
        let mut read = 0;
        for entry in std::fs::read_dir(fixtures).expect("the Haas fixtures") {
            let path = entry.expect("a directory entry").path();
            if path.extension().is_some_and(|e| e == "nc") {
                let model = model(&std::fs::read_to_string(&path).expect("a fixture"));
                assert!(!model.programs.is_empty(), "{}", path.display());
                read += 1;
            }
        }
        assert!(read >= 10, "only {read} fixtures found");
    }

    proptest! {
        #[test]
        fn any_program_text_has_a_model(lines in prop::collection::vec(prop::sample::select(vec![
            "O1", "O2 (T)", "N10 G00 X20.", "N10 Z-5.", "N20 G01 X#1 K1.", "U-3. W2. ,C1.", "G71 P10 Q20 U.3 D2.",
            "G72 P20 Q10", "G70 P10", "G73 Q20", "M97 P20", "M98 P2", "G65 P#1", "GOTO 10", "IF [#1 GT 0] GOTO #2",
            "", "%", "N", "P", "G71 P10. Q20",
        ]), 0..30)) {
            model(&lines.join("\n"));
        }
    }
}
