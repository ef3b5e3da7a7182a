//! The flow walk: the modal state and the parameter values, block by block,
//! in the order the control runs the program.
//!
//! The main program starts in the state of the priority block (the
//! catalogue's group defaults, F0, S0, &0) with unknown parameters. A G71
//! call walks its subprogram with the caller's state and continues with the
//! state the subprogram leaves; a G72 call does the same with the workspace's
//! macrocycle file (or makes everything unknown when the file is missing).
//! Jumps, returns and repetitions go where the executor goes
//! ([`program_flow`] decides for both): a block a known jump skips is not
//! walked, and a loop is walked run by run, up to [`REPEAT_BUDGET`] blocks.
//! Subprograms nobody calls, macrocycle files and cycle bodies are walked
//! from an unknown state. Unknown values never produce findings: a rule
//! reports only what it can prove. So where a parameter with no known value
//! decides the way, the walk forgets what it knew where the ways may meet
//! (flow-not-followed says so).
//!
//! Checks are [`FlowCheck`]s that see every block each time it runs, with
//! the state before and after it.

use std::{ops::Range, sync::Arc};

use nc_exec::{
    cnc8x6::arith::{self, ArithError, BlockArithmetic, Parameters, Raw, UnknownMachine},
    cnc8x6::modes::{Group, Modes},
    cnc8x6::program_flow::{self, BlockFlow, JumpCounts},
    known::Known,
};
use ncc_catalog::{AddressRole, Catalogue};
use ncc_syntax::{Decimal, Sign, TextRange, TextSize};
use rustc_hash::FxHashMap;

use crate::{
    Config, Diagnostic,
    cnc8x6::checks::structure::FLOW_NOT_FOLLOWED,
    cnc8x6::model::{self, FileKind, Program},
    db::{self, Db, Settings, SourceFile},
    findings::Findings,
    interactive::between_blocks,
    lower::{BlockData, Value, Word},
};

/// A modal value as programmed: its number and where it was written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Setting {
    /// The value as written, or for a parameter its raw value as the
    /// address reads it.
    pub value: Decimal,
    pub range: TextRange,
}

/// What the control keeps from block to block.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ModalState {
    /// The code in force in each G and M group (`None`: no code).
    pub modes: Modes<Known<Option<u32>>>,
    /// F, S, T, D and `&`; `None`: not programmed since the start (the
    /// priority block's zero).
    pub feed: Known<Option<Setting>>,
    pub speed: Known<Option<Setting>>,
    pub tool: Known<Option<Setting>>,
    pub offset: Known<Option<Setting>>,
    pub length: Known<Option<Setting>>,
    /// The programmed end position per axis letter (index = letter − `A`),
    /// in program coordinates, in micrometres (thousandths of a degree for
    /// rotary axes) as written: X stays a diameter under G74.
    pub position: [Known<i64>; 26],
    /// The axis the last G10 gave a helix lead (`None`: no lead since the
    /// start).
    pub helix_lead_axis: Known<Option<u8>>,
    /// Whether D has been written since the start. D is not in the priority
    /// block, so `offset` starts unknown and cannot tell this.
    pub offset_written: Known<bool>,
}

impl ModalState {
    fn settings(&self) -> [&Known<Option<Setting>>; 5] {
        [&self.feed, &self.speed, &self.tool, &self.offset, &self.length]
    }

    pub(crate) fn settings_mut(&mut self) -> [&mut Known<Option<Setting>>; 5] {
        [&mut self.feed, &mut self.speed, &mut self.tool, &mut self.offset, &mut self.length]
    }

    /// Makes the settings changed since `before` point at `call`: they were
    /// written in a macrocycle file, whose ranges mean nothing here.
    fn point_settings_at(&mut self, before: &ModalState, call: TextRange) {
        for (setting, old) in self.settings_mut().into_iter().zip(before.settings()) {
            if *setting != *old
                && let Known::Is(Some(changed)) = setting
            {
                changed.range = call;
            }
        }
    }

    /// The state after reset: the priority block.
    pub fn reset() -> ModalState {
        ModalState {
            modes: Modes::reset(),
            feed: Known::Is(None),
            speed: Known::Is(None),
            tool: Known::Unknown,
            offset: Known::Unknown,
            length: Known::Is(None),
            helix_lead_axis: Known::Is(None),
            offset_written: Known::Is(false),
            ..ModalState::unknown()
        }
    }

    /// The programmed position of axis `letter`, if known.
    pub fn position(&self, letter: u8) -> Option<i64> {
        self.position.get(usize::from(letter.to_ascii_uppercase().wrapping_sub(b'A')))?.known()
    }

    pub fn unknown() -> ModalState {
        ModalState {
            modes: Modes::all(Known::Unknown),
            feed: Known::Unknown,
            speed: Known::Unknown,
            tool: Known::Unknown,
            offset: Known::Unknown,
            length: Known::Unknown,
            position: [Known::Unknown; 26],
            helix_lead_axis: Known::Unknown,
            offset_written: Known::Unknown,
        }
    }

    /// The code in force in G group `group`, if known.
    pub fn g(&self, group: usize) -> Option<Option<u32>> {
        self.modes.get(Group::g(group)).known()
    }

    /// The code in force in M group `group`, if known.
    pub fn m(&self, group: usize) -> Option<Option<u32>> {
        self.modes.get(Group::m(group)).known()
    }

    /// Whether `code` is known to be the code in force in its G group.
    pub fn has_g(&self, group: usize, code: u32) -> bool {
        self.modes.get(Group::g(group)) == Known::Is(Some(code))
    }
}

/// Where a parameter's value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Origin {
    pub range: TextRange,
    /// The value was written with a decimal point.
    pub point: bool,
    /// Set by parameter arithmetic, not by an assignment.
    pub computed: bool,
}

/// Parameter values and where they came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParamState {
    pub values: Parameters,
    pub origins: Vec<Option<Origin>>,
    /// The walk started at the program's start, so a parameter without an
    /// origin has not been assigned by the program.
    pub from_start: bool,
}

impl ParamState {
    pub fn unknown() -> ParamState {
        ParamState { values: Parameters::unknown(), origins: vec![None; arith::PARAMETER_COUNT], from_start: false }
    }

    /// The parameters at the start of a program: values left from earlier
    /// programs, none assigned yet.
    pub fn program_start() -> ParamState {
        ParamState { from_start: true, ..ParamState::unknown() }
    }

    pub fn get(&self, index: u32) -> Option<(Raw, Option<Origin>)> {
        let index = usize::try_from(index).ok().filter(|&i| i < arith::PARAMETER_COUNT)?;
        Some((self.values.get(index)?, self.origins[index]))
    }
}

/// A parameter reference resolved to its value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Substitution {
    /// The raw value (sign of the reference applied).
    pub raw: Raw,
    pub origin: Option<Origin>,
}

/// One block as a check sees it.
pub(crate) struct Visit<'a> {
    pub block: &'a BlockData,
    /// Where the block starts in the file.
    pub offset: TextSize,
    pub before: &'a ModalState,
    pub after: &'a ModalState,
    /// Parameter values before the block.
    pub params: &'a ParamState,
    /// Parameter values after the block's assignments and arithmetic.
    pub params_after: &'a ParamState,
    /// The substituted value of each word (same order as `block.words`);
    /// `None` for literals and unknown parameters.
    pub substitutions: &'a [Option<Substitution>],
    /// G and M codes of the block, literal or substituted.
    pub codes: &'a [(u8, u32, TextRange)],
    /// The failure of the block's parameter arithmetic, if it has one.
    pub arithmetic_error: Option<&'a (TextRange, ArithError)>,
    pub config: &'a Config,
    /// The programmed end position of the block's own motion (as in
    /// [`ModalState::position`]), where a fixed cycle running in the block
    /// starts; `after.position` is unknown then, as the cycle moves the tool.
    pub reached: &'a [Known<i64>; 26],
}

impl Visit<'_> {
    /// A block-relative range as a file range.
    pub fn range(&self, range: TextRange) -> TextRange {
        range + self.offset
    }

    /// Whether the block has code `letter` `number` (literal or substituted).
    pub fn has_code(&self, letter: u8, number: u32) -> bool {
        self.codes.iter().any(|&(l, n, _)| l == letter && n == number)
    }

    /// The file range of code `letter` `number` in the block.
    pub fn code_range(&self, letter: u8, number: u32) -> Option<TextRange> {
        self.codes.iter().find(|&&(l, n, _)| l == letter && n == number).map(|&(_, _, r)| r)
    }
}

/// A rule that needs the modal state or parameter values.
pub(crate) trait FlowCheck {
    /// Called for every block in run order.
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>);

    /// Called when a program unit ends, with the state at its end.
    fn end_of_unit(&mut self, _state: &ModalState, _last: Option<(TextSize, &BlockData)>, _out: &mut Vec<Diagnostic>) {}
}

/// The state before block `index` of `file` each time the walk reaches it
/// (a subprogram called twice is reached twice); for a block of the main
/// body, the first time, from the checkpoints.
pub fn states_before(db: &dyn Db, file: SourceFile, index: usize) -> Vec<(ModalState, ParamState)> {
    match crate::cnc8x6::states::main_state_before(db, file, index) {
        Some(state) => vec![state],
        None => walked_states(db, file, index),
    }
}

/// The state before block `index` each time a walk of the whole file
/// reaches it.
pub(crate) fn walked_states(db: &dyn Db, file: SourceFile, index: usize) -> Vec<(ModalState, ParamState)> {
    let program = model::program(db, file);
    let Some(block) = program.get_block(index) else { return Vec::new() };
    let seen = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
    let probe = Probe { offset: block.offset, seen: seen.clone() };
    let mut walk = Walk::new(db, file, program, vec![Box::new(probe)]);
    walk.run();
    drop(walk);
    std::rc::Rc::try_unwrap(seen).map(|cell| cell.into_inner()).unwrap_or_default()
}

/// Records the state at one block.
struct Probe {
    offset: TextSize,
    seen: std::rc::Rc<std::cell::RefCell<Vec<(ModalState, ParamState)>>>,
}

impl FlowCheck for Probe {
    fn block(&mut self, visit: &Visit<'_>, _out: &mut Vec<Diagnostic>) {
        if visit.offset == self.offset {
            self.seen.borrow_mut().push((visit.before.clone(), visit.params.clone()));
        }
    }
}

/// Diagnostics of the rules that follow the program's flow, limited per line.
#[salsa::tracked(returns(ref))]
pub fn flow_diagnostics(db: &dyn Db, file: SourceFile) -> Findings {
    let program = model::program(db, file);
    let mut walk = Walk::new(db, file, program, crate::cnc8x6::checks::flow_checks());
    walk.run();
    let mut out = walk.out;
    // A block run several times (a subprogram called from several places,
    // a loop) repeats its findings, maybe with other values: the first
    // run's is kept (the sort is stable).
    out.sort_by_key(|d| (d.range.start(), d.range.end(), d.code));
    out.dedup_by(|later, first| (later.range, later.code) == (first.range, first.code));
    Findings::of(file.text(db), out, Vec::new())
}

/// The lowered blocks of a file, each lowered when a walk first reaches it
/// (a question walks a few dozen blocks of a chunk of hundreds).
struct Blocks<'db> {
    db: &'db dyn Db,
    program: &'db Program,
    chunks: &'db [db::FileChunk<'db>],
    /// Kept for blocks walked again: subprograms called more than once.
    cache: FxHashMap<usize, Arc<BlockData>>,
}

impl<'db> Blocks<'db> {
    /// Blocks kept at most; a walk mostly goes forward.
    const KEPT: usize = 4096;

    fn new(db: &'db dyn Db, file: SourceFile) -> Self {
        let chunks = db::file_chunks(db, file).as_slice();
        Blocks { db, program: model::program(db, file), chunks, cache: FxHashMap::default() }
    }

    /// Block `index` with its file offset.
    fn get(&mut self, index: usize) -> (TextSize, Arc<BlockData>) {
        // A walk over a large file is one long query: an edit waiting to
        // change the inputs waits for this check (an atomic load).
        between_blocks(self.db);
        let offset = self.program.block(index).offset;
        if let Some(block) = self.cache.get(&index) {
            return (offset, block.clone());
        }
        if self.cache.len() >= Self::KEPT {
            self.cache.clear();
        }
        let chunk = &self.chunks[self.chunks.partition_point(|chunk| chunk.first <= index) - 1];
        let green = chunk.chunk.block(self.db, index - chunk.first).expect("the model's blocks are the chunks' blocks");
        let block = Arc::new(BlockData::lower(green));
        self.cache.insert(index, block.clone());
        (offset, block)
    }
}

/// Block `index` of `file`, lowered, with its file offset.
pub fn lowered_block(db: &dyn Db, file: SourceFile, index: usize) -> Option<(TextSize, BlockData)> {
    let blocks_in_file = model::program(db, file).block_count();
    (index < blocks_in_file).then(|| {
        let (offset, block) = Blocks::new(db, file).get(index);
        (offset, Arc::unwrap_or_clone(block))
    })
}

/// How deep calls are followed (runaway recursion is the executor's
/// business, not the checker's).
const MAX_CALL_DEPTH: usize = 8;

/// How many blocks a walk runs again for loops and repeated calls, beyond
/// running each block once: about a fifth of a second, so that a huge
/// repetition count holds up neither `ncc check` nor the editor.
const REPEAT_BUDGET: usize = 100_000;

/// What decides which block of a unit the walk runs next, besides the
/// state.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Course {
    /// The jumps taken, counted as the executor counts them.
    jumps: JumpCounts,
    /// Blocks ahead that a jump the walk could not decide may reach: there
    /// the walk forgets the state, which may be another one.
    merges: Vec<usize>,
    /// Jump blocks that may or may not have jumped: their count is unknown.
    unsure: Vec<usize>,
    /// The walk could not tell which block runs next: it goes through the
    /// rest of the unit in order, knowing no state, since any of its blocks
    /// may run next.
    lost: bool,
}

impl Course {
    /// Gives up following the unit.
    fn lose(&mut self) {
        *self = Course { lost: true, ..Course::default() };
    }

    /// Moves the course with the blocks of the main body (`moved` gives a
    /// block's new index); `false` if a block it holds has none.
    pub(crate) fn move_blocks(&mut self, moved: impl Fn(usize) -> Option<usize>) -> bool {
        let mut blocks = self.merges.iter_mut().chain(&mut self.unsure);
        blocks.all(|block| moved(*block).map(|to| *block = to).is_some()) && self.jumps.move_blocks(moved)
    }
}

/// Why the walk cannot decide where a block goes: the word whose parameter
/// has no known value.
enum Undecided<'a> {
    /// Any block of the unit may run next.
    Course(&'a Word),
    /// The block jumps to block N`label`, or goes on.
    Jump(&'a Word, u32),
    /// The block calls, but what or how often is unknown.
    Call(&'a Word),
}

pub(crate) struct Walk<'db> {
    db: &'db dyn Db,
    program: &'db Program,
    catalogue: &'static Catalogue,
    config: &'db Config,
    checks: Vec<Box<dyn FlowCheck>>,
    blocks: Blocks<'db>,
    out: Vec<Diagnostic>,
    /// Subprograms on the call stack (by unit index).
    pub(crate) stack: Vec<usize>,
    called: Vec<bool>,
    /// The hull of the blocks of the subprograms entered, and of the
    /// blocks that decided the jumps taken, since the last
    /// [`Walk::take_entered`].
    entered: Option<Range<usize>>,
    /// Blocks run again so far (see [`REPEAT_BUDGET`]).
    pub(crate) repeated: usize,
    /// The program ended (M02/M30, or a jump to no block stopped it).
    ended: bool,
    /// The walk started at the program's start; a unit walked from an
    /// unknown state (a macrocycle file, a subprogram nobody calls) knows
    /// too little to say where it stops following.
    from_program_start: bool,
}

impl<'db> Walk<'db> {
    pub(crate) fn new(
        db: &'db dyn Db,
        file: SourceFile,
        program: &'db Program,
        checks: Vec<Box<dyn FlowCheck>>,
    ) -> Self {
        Walk {
            db,
            program,
            catalogue: Settings::get(db).dialect(db).catalogue(),
            config: Settings::get(db).config(db),
            checks,
            blocks: Blocks::new(db, file),
            out: Vec::new(),
            stack: Vec::new(),
            called: vec![false; program.units.len()],
            entered: None,
            repeated: 0,
            ended: false,
            from_program_start: false,
        }
    }

    fn run(&mut self) {
        let has_main = self.program.has_main();
        if has_main {
            let (mut state, mut params) = (ModalState::reset(), ParamState::program_start());
            self.from_program_start = true;
            self.walk_unit(0, &mut state, &mut params);
            self.from_program_start = false;
        }
        for unit in 0..self.program.units.len() {
            let is_main = has_main && unit == 0;
            let called = self.program.kind == FileKind::Program && self.called[unit];
            if !is_main && !called {
                self.ended = false;
                self.walk_unit(unit, &mut ModalState::unknown(), &mut ParamState::unknown());
            }
        }
    }

    /// Runs a unit from `state`, which it leaves as at the unit's end.
    fn walk_unit(&mut self, unit: usize, state: &mut ModalState, params: &mut ParamState) {
        self.stack.push(unit);
        let blocks = self.program.units[unit].blocks.clone();
        let mut course = Course::default();
        let (mut at, mut last) = (Some(blocks.start).filter(|_| !blocks.is_empty()), None);
        while let Some(index) = at {
            at = self.step(index, &mut course, state, params);
            last = Some(index);
        }
        let last_block = last.map(|index| self.blocks.get(index));
        for check in &mut self.checks {
            check.end_of_unit(state, last_block.as_ref().map(|(offset, block)| (*offset, &**block)), &mut self.out);
        }
        self.stack.pop();
    }

    /// Runs block `index` (and what it calls) from `state`, which it
    /// leaves as after the block, and tells which block of the unit runs
    /// next (`None`: the unit's run ends), deciding as the executor does.
    /// In place: a walk without checks then copies no state.
    pub(crate) fn step(
        &mut self,
        index: usize,
        course: &mut Course,
        state: &mut ModalState,
        params: &mut ParamState,
    ) -> Option<usize> {
        let (offset, block) = self.blocks.get(index);
        let (substitutions, codes) = self.visit(&block, offset, state, params);
        let unit = *self.stack.last().expect("a block runs in a unit");
        let blocks = self.program.units[unit].blocks.clone();
        let next = Some(index + 1).filter(|next| blocks.contains(next));
        if course.lost {
            forget(state, params);
            return next;
        }
        let in_subprogram = !(unit == 0 && self.program.has_main());
        let mut decided = self.block_flow(&block, &substitutions, &codes, params, in_subprogram);
        // A jump that may have been taken before may have used up its count.
        if let (Ok(BlockFlow::Jump { label, .. }), Some(word)) = (&decided, block.word(b'L'))
            && course.unsure.contains(&index)
        {
            decided = Err(Undecided::Jump(word, *label));
        }
        let flow = match decided {
            Ok(flow) => flow,
            Err(Undecided::Jump(word, label)) => {
                let target = self.program.jump_target(index, label);
                course.jumps.passed(index);
                if let Some(target) = target.filter(|&target| target > index) {
                    let why = unknown_parameter(word, course.unsure.contains(&index));
                    self.not_followed(word, offset, format!("{why}, so the checker cannot tell whether the program jumps to N{label} here: it checks N{label} knowing no modal state or parameter values"));
                    for (blocks, block) in [(&mut course.merges, target), (&mut course.unsure, index)] {
                        if !blocks.contains(&block) {
                            blocks.push(block);
                        }
                    }
                    return self.arrive(index, next, course, state, params);
                }
                // Back: the section may run any number of times more.
                if target.is_some() {
                    return self.lose(word, offset, course, state, params, next);
                }
                // To no block, which stops the control: going on is the only
                // way on.
                return self.arrive(index, next, course, state, params);
            }
            Err(Undecided::Course(word)) => return self.lose(word, offset, course, state, params, next),
            Err(Undecided::Call(word)) => {
                let why = unknown_parameter(word, false);
                self.not_followed(word, offset, format!("{why}, so the checker cannot tell what this block calls or how often: it knows no modal state or parameter values after it"));
                forget(state, params);
                return self.arrive(index, next, course, state, params);
            }
        };
        let code_range = |code: u32| codes.iter().find(|&&(l, n, _)| l == b'G' && n == code).map(|&(_, _, r)| r);
        let to = match flow {
            BlockFlow::Next => {
                course.jumps.passed(index);
                course.unsure.retain(|&at| at != index);
                next
            }
            BlockFlow::End => {
                self.ended = true;
                None
            }
            BlockFlow::Return => next.filter(|_| !in_subprogram),
            BlockFlow::Call { label, times, macrocycle } => {
                let range = code_range(if macrocycle { 72 } else { 71 }).unwrap_or(TextRange::empty(offset));
                self.call(label, times, macrocycle, range, state, params);
                next.filter(|_| !self.ended)
            }
            BlockFlow::Jump { label, times } => {
                // A jump to no block stops the control (jump-target-not-in-unit).
                let Some(target) = self.program.jump_target(index, label) else {
                    self.ended = true;
                    return None;
                };
                if !course.jumps.jumps(index, times) {
                    course.unsure.retain(|&at| at != index);
                    return self.arrive(index, next, course, state, params);
                }
                let again = (index + 1).saturating_sub(target);
                if self.repeated + again > REPEAT_BUDGET {
                    let range = code_range(73).unwrap_or(TextRange::empty(offset));
                    self.not_followed_at(range, format!("the checker runs loops for at most {REPEAT_BUDGET} blocks, and this jump back to N{label} goes on beyond that: it checks the rest of this program unit without the modal state and parameter values"));
                    course.lose();
                    forget(state, params);
                    return next;
                }
                self.repeated += again;
                // Where the jump goes depends on the block numbers from the
                // unit's start on.
                self.enter(blocks.start..index.max(target) + 1);
                Some(target)
            }
        };
        self.arrive(index, to, course, state, params)
    }

    /// Gives up following the unit after the block at `offset`, because of
    /// its word `word`; goes on with `next`.
    fn lose(
        &mut self,
        word: &Word,
        offset: TextSize,
        course: &mut Course,
        state: &mut ModalState,
        params: &mut ParamState,
        next: Option<usize>,
    ) -> Option<usize> {
        let why = unknown_parameter(word, false);
        self.not_followed(word, offset, format!("{why}, so the checker cannot tell which block runs after this one: it checks the rest of this program unit without the modal state and parameter values"));
        course.lose();
        forget(state, params);
        next
    }

    /// The walk goes from block `from` to block `to` (`None`: the unit's
    /// run ends): where a jump it could not decide may lead as well, it
    /// forgets the state.
    fn arrive(
        &mut self,
        from: usize,
        to: Option<usize>,
        course: &mut Course,
        state: &mut ModalState,
        params: &mut ParamState,
    ) -> Option<usize> {
        if course.merges.is_empty() {
            return to;
        }
        let Some(to) = to else {
            // The other way may leave the unit with another state.
            forget(state, params);
            return None;
        };
        if let Some(&passed) = course.merges.iter().filter(|&&merge| from < merge && merge < to).min() {
            // A jump past a block the other way reaches: both ways run the
            // blocks after it.
            let (offset, block) = self.blocks.get(from);
            let label = block.word(b'L').map_or(self.program.block(from).head, |word| word.range + offset);
            self.not_followed_at(label, "this jump passes a block that a jump the checker cannot decide may lead to: it checks the rest of this program unit without the modal state and parameter values".to_owned());
            course.lose();
            forget(state, params);
            return Some(passed);
        }
        if let Some(at) = course.merges.iter().position(|&merge| merge == to) {
            course.merges.swap_remove(at);
            forget(state, params);
        }
        Some(to)
    }

    /// Where block `block` passes control on (see [`program_flow::block_flow`]):
    /// its codes as substituted before the block, L and Q as it leaves
    /// `params`.
    fn block_flow<'b>(
        &self,
        block: &'b BlockData,
        substitutions: &[Option<Substitution>],
        codes: &[(u8, u32, TextRange)],
        params: &ParamState,
        in_subprogram: bool,
    ) -> Result<BlockFlow, Undecided<'b>> {
        let has = |letter: u8, number: u32| codes.iter().any(|&(l, n, _)| l == letter && n == number);
        let integer = |word: &Word| program_flow::integer(word, &params.values);
        let unknown = |word: &&Word| match &word.value {
            Some(value @ Value::Parameter { .. }) => arith::reference(value, &params.values).is_none(),
            _ => false,
        };
        let unknown_code = block.words.iter().zip(substitutions).find(|(word, substitution)| {
            word.letter == b'G' && matches!(word.value, Some(Value::Parameter { .. })) && substitution.is_none()
        });
        let (label, count) = (block.word(b'L'), block.word(b'Q'));
        if let Some((word, _)) = unknown_code {
            // In a subprogram the code may be G70; with L, a call or a jump
            // (G73 to L, G78 going on: 02 §5.6).
            match label.filter(|label| !unknown(label)).and_then(integer) {
                _ if in_subprogram => return Err(Undecided::Course(word)),
                Some(label) if !self.callable(label) => return Err(Undecided::Jump(word, label)),
                _ if label.is_some() => return Err(Undecided::Course(word)),
                _ => {}
            }
        }
        let jumps = has(b'G', 73);
        if jumps || has(b'G', 71) || has(b'G', 72) {
            if let Some(word) = label.filter(unknown) {
                return Err(if jumps { Undecided::Course(word) } else { Undecided::Call(word) });
            }
            let counted = count.filter(|_| !has(b'G', 4));
            if let Some(word) = counted.filter(unknown) {
                return Err(match label.and_then(integer) {
                    Some(label) if jumps => Undecided::Jump(word, label),
                    _ => Undecided::Call(word),
                });
            }
        }
        Ok(program_flow::block_flow(block, has, integer))
    }

    /// Whether a call of `label` would find a subprogram or a macrocycle.
    fn callable(&self, label: u32) -> bool {
        self.program.subprogram(label).is_some() || model::macrocycles(self.db).contains_key(&label)
    }

    /// Reports that the walk does not follow the program past the word
    /// `word` of the block at `offset`.
    fn not_followed(&mut self, word: &Word, offset: TextSize, message: String) {
        self.not_followed_at(word.range + offset, message);
    }

    fn not_followed_at(&mut self, range: TextRange, message: String) {
        // Only a walk that checks reports; the others give the state.
        if !self.checks.is_empty() && self.from_program_start {
            self.out.push(Diagnostic::new(&FLOW_NOT_FOLLOWED, range, message));
        }
    }

    /// Adds `blocks` to the hull [`Walk::take_entered`] gives.
    fn enter(&mut self, blocks: Range<usize>) {
        self.entered = Some(match self.entered.take() {
            Some(hull) => hull.start.min(blocks.start)..hull.end.max(blocks.end),
            None => blocks,
        });
    }

    /// The hull of the blocks of the subprograms entered and the jumps taken
    /// since the last call (`None`: none).
    pub(crate) fn take_entered(&mut self) -> Option<Range<usize>> {
        self.entered.take()
    }

    /// Follows a call, `times` runs of the callee with the caller's state.
    fn call(
        &mut self,
        label: u32,
        times: u32,
        macrocycle: bool,
        call: TextRange,
        state: &mut ModalState,
        params: &mut ParamState,
    ) {
        if self.stack.len() >= MAX_CALL_DEPTH {
            self.not_followed_at(call, format!("calls nest deeper here than the {MAX_CALL_DEPTH} levels the checker follows: it knows no modal state or parameter values after this block"));
            return forget(state, params);
        }
        if macrocycle {
            return self.call_macrocycle(label, times, call, state, params);
        }
        let Some(unit) = self.program.units.iter().position(|u| u.number == Some(label)) else {
            // No such subprogram: undefined-subprogram reports the call.
            return forget(state, params);
        };
        if self.stack.contains(&unit) {
            self.not_followed_at(call, format!("L{label} is running already: the checker does not follow a subprogram into itself, and knows no modal state or parameter values after this block"));
            return forget(state, params);
        }
        self.called[unit] = true;
        let blocks = self.program.units[unit].blocks.clone();
        self.enter(blocks.clone());
        for run in 0..times {
            if run > 0 && !self.repeat(blocks.len(), call, state, params) {
                return;
            }
            self.walk_unit(unit, state, params);
            if self.ended {
                return;
            }
        }
    }

    /// Follows a macrocycle call: its file's findings belong to that file;
    /// here only the state it leaves matters.
    fn call_macrocycle(
        &mut self,
        label: u32,
        times: u32,
        call: TextRange,
        state: &mut ModalState,
        params: &mut ParamState,
    ) {
        let Some(file) = model::macrocycles(self.db).get(&label).and_then(|files| files.first().copied()) else {
            // No such file: undefined-macrocycle reports the call.
            return forget(state, params);
        };
        let program = model::program(self.db, file);
        if program.units.is_empty() {
            return forget(state, params);
        }
        let mut inner = Walk::new(self.db, file, program, Vec::new());
        inner.stack = vec![usize::MAX; self.stack.len()];
        let origins_before = params.origins.clone();
        let settings_before = state.clone();
        for run in 0..times {
            if run > 0 && !self.repeat(program.units[0].blocks.len(), call, state, params) {
                return;
            }
            inner.walk_unit(0, state, params);
            if inner.ended {
                self.ended = true;
                return;
            }
        }
        state.point_settings_at(&settings_before, call);
        // Ranges in the macrocycle's file mean nothing here: what it
        // assigned comes from the call.
        for (origin, before) in params.origins.iter_mut().zip(origins_before) {
            if *origin != before {
                *origin = origin.map(|_| Origin { range: call, point: false, computed: true });
            }
        }
    }

    /// Whether the budget allows running `blocks` blocks of a call once
    /// more; if not, says so and forgets the state.
    fn repeat(&mut self, blocks: usize, call: TextRange, state: &mut ModalState, params: &mut ParamState) -> bool {
        if self.repeated + blocks > REPEAT_BUDGET {
            self.not_followed_at(call, format!("the checker runs repeated calls for at most {REPEAT_BUDGET} blocks, and this one goes on beyond that: it knows no modal state or parameter values after this block"));
            forget(state, params);
            return false;
        }
        self.repeated += blocks;
        true
    }

    /// Takes the state over one block, and runs the checks on it; gives
    /// the block's substitutions and codes.
    fn visit(
        &mut self,
        block: &BlockData,
        offset: TextSize,
        state: &mut ModalState,
        params: &mut ParamState,
    ) -> (Vec<Option<Substitution>>, Codes) {
        let substitutions: Vec<Option<Substitution>> = block.words.iter().map(|w| substitute(w, params)).collect();
        let codes = codes(block, &substitutions, offset);
        let before = (!self.checks.is_empty()).then(|| (state.clone(), params.clone()));
        self.apply(state, block, &substitutions, &codes, offset);
        let reached = state.position;
        // A fixed cycle moves the tool in its body.
        if matches!(state.g(8), Some(Some(81..=89)) | None) {
            state.position = [Known::Unknown; 26];
        }
        let arithmetic_error = self.assign(block, offset, params);
        let Some((before, params_before)) = before else { return (substitutions, codes) };
        let visit = Visit {
            block,
            offset,
            before: &before,
            after: state,
            params: &params_before,
            params_after: params,
            substitutions: &substitutions,
            codes: &codes,
            arithmetic_error: arithmetic_error.as_ref(),
            config: self.config,
            reached: &reached,
        };
        for check in &mut self.checks {
            check.block(&visit, &mut self.out);
        }
        (substitutions, codes)
    }

    /// Takes the modal state over a block.
    fn apply(
        &self,
        after: &mut ModalState,
        block: &BlockData,
        substitutions: &[Option<Substitution>],
        codes: &[(u8, u32, TextRange)],
        offset: TextSize,
    ) {
        // When constant cutting speed ends without a new S, the control
        // keeps the speed it last reached, not the S written (a cutting speed).
        let maybe_css = |state: &ModalState| !matches!(state.g(6), Some(Some(94 | 95)));
        let css_before = maybe_css(after);
        for &(letter, number, _) in codes {
            after.modes.set(letter, number);
        }
        let indirect_code = block.words.iter().zip(substitutions).any(|(w, s)| {
            matches!(w.letter, b'G' | b'M') && matches!(w.value, Some(Value::Parameter { .. })) && s.is_none()
        });
        if indirect_code {
            // A code from an unknown parameter may be any code.
            after.modes = Modes::all(Known::Unknown);
            after.helix_lead_axis = Known::Unknown;
        }
        if codes.iter().any(|&(l, n, _)| l == b'G' && n == 10) {
            // `N10 Z1.05 G10`: the axis written is the one the helix drives.
            let axis = block.words.iter().find(|w| self.catalogue.role_of(w.letter) == Some(AddressRole::Axis));
            if let Some(axis) = axis {
                after.helix_lead_axis = Known::Is(Some(axis.letter));
            }
        }
        // With G76, S is the CSS speed limit, not the spindle speed.
        let speed_limit = codes.iter().any(|&(letter, number, _)| letter == b'G' && number == 76);
        let writes_speed =
            !speed_limit && block.words.iter().any(|w| self.catalogue.role_of(w.letter) == Some(AddressRole::Speed));
        for (word, substitution) in block.words.iter().zip(substitutions) {
            let slot = match self.catalogue.role_of(word.letter) {
                Some(AddressRole::Feed) => &mut after.feed,
                Some(AddressRole::Speed) if !speed_limit => &mut after.speed,
                Some(AddressRole::Tool) => &mut after.tool,
                Some(AddressRole::Offset) => {
                    after.offset_written = Known::Is(true);
                    &mut after.offset
                }
                Some(AddressRole::LengthCompensation) => &mut after.length,
                _ => continue,
            };
            *slot = match setting(word, *substitution, offset) {
                Some(setting) => Known::Is(Some(setting)),
                None => Known::Unknown,
            };
        }
        if css_before && !maybe_css(after) && !writes_speed {
            after.speed = Known::Unknown;
        }
        self.move_axes(after, block, substitutions, codes);
    }

    /// The programmed end position after a block.
    fn move_axes(
        &self,
        after: &mut ModalState,
        block: &BlockData,
        substitutions: &[Option<Substitution>],
        codes: &[(u8, u32, TextRange)],
    ) {
        let has = |code: u32| codes.iter().any(|&(l, n, _)| l == b'G' && n == code);
        // Offsets and transformations move the program's coordinate system
        // under the tool.
        let frame_changes = [92, 93, 53, 54, 55, 56, 57, 58, 59, 35, 36, 37, 38, 39, 31].iter().any(|&c| has(c));
        let transformed = !matches!(after.g(11), Some(None | Some(34)));
        if frame_changes || transformed {
            after.position = [Known::Unknown; 26];
            return;
        }
        let data_block = [10, 92, 93].iter().any(|&c| has(c));
        if !data_block {
            let incremental = after.g(9).map(|code| code == Some(91));
            for (word, substitution) in block.words.iter().zip(substitutions) {
                if self.catalogue.role_of(word.letter) != Some(AddressRole::Axis) {
                    continue;
                }
                let slot = &mut after.position[usize::from(word.letter - b'A')];
                *slot = match (thousandths(word, *substitution), incremental, *slot) {
                    (Some(v), Some(false), _) => Known::Is(v),
                    (Some(v), Some(true), Known::Is(from)) => Known::Is(from + v),
                    _ => Known::Unknown,
                };
            }
        }
        // A helix moves its lead axis without a word for it.
        let helix = after.has_g(2, 9) && matches!(after.g(0), Some(Some(2 | 3)));
        if helix && !data_block {
            match after.helix_lead_axis {
                Known::Is(Some(axis)) => after.position[usize::from(axis - b'A')] = Known::Unknown,
                _ => after.position = [Known::Unknown; 26],
            }
        }
    }

    /// Applies the block's assignments and parameter arithmetic to `params`.
    fn assign(&self, block: &BlockData, offset: TextSize, params: &mut ParamState) -> Option<(TextRange, ArithError)> {
        arith::assign(block, &mut params.values);
        for assignment in &block.assignments {
            let Some(index) = assignment.index.map(|i| i as usize).filter(|&i| i < arith::PARAMETER_COUNT) else {
                continue;
            };
            let range = assignment.value_range.unwrap_or(assignment.range) + offset;
            let point = matches!(&assignment.value, Some(Value::Literal(decimal)) if decimal.has_point());
            params.origins[index] = Some(Origin { range, point, computed: false });
        }
        if !block.codes(b'G').any(|(code, _)| (26..=29).contains(&code)) {
            return None;
        }
        let before = params.values.clone();
        match arith::compute(block, &mut params.values, &mut UnknownMachine, &self.config.machine) {
            BlockArithmetic::None => None,
            BlockArithmetic::UnknownWord => {
                *params = ParamState::unknown();
                None
            }
            BlockArithmetic::Ran { function, words, result } => {
                let range = function + offset;
                let targets: Vec<usize> = words.iter().map(|word| usize::from(word.target)).collect();
                for index in 0..arith::PARAMETER_COUNT {
                    if params.values.get(index) != before.get(index) || targets.contains(&index) {
                        params.origins[index] = Some(Origin { range, point: false, computed: true });
                    }
                }
                result.err().map(|error| (range, error))
            }
        }
    }
}

/// Forgets everything the walk knew: what runs next is unknown.
fn forget(state: &mut ModalState, params: &mut ParamState) {
    *state = ModalState::unknown();
    *params = ParamState::unknown();
}

/// Why the walk cannot read `word`: a parameter with no known value, or
/// (`unsure`) a jump that may have been taken already.
fn unknown_parameter(word: &Word, unsure: bool) -> String {
    match word.value {
        _ if unsure => "whether this jump was taken before is unknown, and with it whether it is taken now".to_owned(),
        Some(Value::Parameter { index: Some(index), negative, .. }) => {
            let sign = if negative { "-" } else { "" };
            format!("`{}{sign}R{index}`: R{index} has no known value here", char::from(word.letter))
        }
        _ => format!("`{}` has no readable value", char::from(word.letter)),
    }
}

/// The value a parameter reference substitutes, if known.
fn substitute(word: &Word, params: &ParamState) -> Option<Substitution> {
    let Some(Value::Parameter { negative, index: Some(index), .. }) = word.value else { return None };
    let (raw, origin) = params.get(index)?;
    Some(Substitution { raw: if negative { -raw } else { raw }, origin })
}

/// Thousandths as a plain number: 1500 → `1.5`.
pub(crate) fn show_thousandths(value: i64) -> String {
    let text = format!("{:.3}", value as f64 / 1000.0);
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// A dimensional word's value in thousandths of its unit (µm for lengths):
/// its literal, or the raw value of a known parameter.
pub(crate) fn thousandths(word: &Word, substitution: Option<Substitution>) -> Option<i64> {
    match (&word.value, substitution) {
        (Some(Value::Literal(d)), _) => d.scaled(3).and_then(|v| i64::try_from(v).ok()),
        (Some(Value::Parameter { .. }), Some(s)) => Some(s.raw),
        _ => None,
    }
}

/// A block's G and M codes (letter, number, file range).
type Codes = Vec<(u8, u32, TextRange)>;

/// The block's G and M codes: literal, or substituted with a known value.
fn codes(block: &BlockData, substitutions: &[Option<Substitution>], offset: TextSize) -> Codes {
    let mut codes = Vec::new();
    for (word, substitution) in block.words.iter().zip(substitutions) {
        if !matches!(word.letter, b'G' | b'M') {
            continue;
        }
        let number = match (&word.value, substitution) {
            (Some(Value::Literal(d)), _) if !d.has_point() && d.sign().is_none() => {
                d.scaled(0).and_then(|v| u32::try_from(v).ok())
            }
            // A dimensionless address reads the raw digits (`R21=40` → G40).
            (Some(Value::Parameter { .. }), Some(s)) => u32::try_from(s.raw).ok(),
            _ => None,
        };
        if let Some(number) = number {
            codes.push((word.letter, number, word.range + offset));
        }
    }
    codes
}

/// A modal word's setting: its literal, or the substituted raw value read
/// as the address reads it (dimensionless digits; F in mm/min).
fn setting(word: &Word, substitution: Option<Substitution>, offset: TextSize) -> Option<Setting> {
    let range = word.range + offset;
    match (&word.value, substitution) {
        (Some(Value::Literal(value)), _) => Some(Setting { value: *value, range }),
        (Some(Value::Parameter { .. }), Some(s)) => {
            let sign = (s.raw < 0).then_some(Sign::Minus);
            Decimal::parse(sign, &s.raw.unsigned_abs().to_string()).map(|value| Setting { value, range })
        }
        _ => None,
    }
}
