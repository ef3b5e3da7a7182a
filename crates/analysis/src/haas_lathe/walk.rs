//! The walk over a Haas file's programs with the modal state, for the rules
//! that need what is in force before a block.
//!
//! It follows each program in file order, from power-on (the catalogue's
//! defaults, macro variables as at power-on) for a main program and from an
//! unknown state for a subprogram (a program that returns with M99: its
//! caller's state is not known here). What it assumes where the order of
//! the file is not the order of the run:
//!
//! - A roughing cycle G71–G73 runs its contour P..Q (the blocks are walked
//!   as the cycle's, from the state before it), returns to its start point
//!   and goes on after the Q block when Q lies after it (lathe manual §6.9
//!   item 8, inferred there); G70 runs its contour and goes on after
//!   itself. The contour's F, S and T are not run (001:1564, 1649). Modal
//!   codes the contour changes are taken as unknown after the cycle.
//! - Jumps and loops: the state is forgotten (every value unknown) at a
//!   GOTO's target (at every numbered block when a GOTO's target is
//!   computed), at a `DOn` and after its `ENDn`, and after an unconditional
//!   GOTO. A block-delete `/` block may or may not run: after it holds
//!   only what both ways agree on.
//! - Calls (M97, M98, G65) may change anything: the state after them is
//!   unknown. So is every block after M30, M02 or M99 (local subprograms,
//!   reached only by M97).
//!
//! So a finding holds for a way the program really runs, and a value the
//! walk cannot know (a computed word, a forgotten state) is unknown, never
//! wrong.

use std::{collections::BTreeSet, ops::ControlFlow};

use nc_exec::{
    haas_lathe::{
        eval::{MacroValue, Variables},
        lower::{ExprKind, HaasBlock, Statement, Value, Word},
        modes::Modes,
        program::{Blocks, Contour, Finding, Program, ReferenceKind, Target},
    },
    known::Known,
};
use ncc_catalog::{Catalogue, Dialect, split_code};

use crate::haas_lathe::model::FileModel;

/// The catalogue's groups the walk reads.
pub(crate) const MOTION: &str = "G1";
pub(crate) const COMPENSATION: &str = "G7";
pub(crate) const DRILLING: &str = "G9";
pub(crate) const WORK_OFFSET: &str = "G12";
pub(crate) const SPEED_MODE: &str = "G12S";
pub(crate) const THREAD_CHAMFER: &str = "M10";

/// Whether a program has set a value that holds until set again (F, G50
/// S).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Setting {
    /// Not since the program started.
    Unset,
    Set,
    /// Not known.
    Unknown,
}

impl Setting {
    fn join(self, other: Setting) -> Setting {
        if self == other { self } else { Setting::Unknown }
    }
}

/// The corner (chamfer or rounding, I/K/R on G01) a block asked for, which
/// the next move must complete (lathe manual §5.8 (001:2994-2995)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Corner {
    /// The block with the corner word.
    pub block: usize,
    /// Its index in the block's words.
    pub word: usize,
    /// The axis the corner's block moves along (`X` or `Z`), when one.
    pub along: Option<u8>,
}

/// What the control holds between blocks, as far as the walk knows.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct State {
    pub modes: Modes,
    pub variables: Variables,
    /// F or E, the feed or the thread's pitch.
    pub feed: Setting,
    /// G50 S.
    pub speed_limit: Setting,
    /// X (a diameter) and Z in work coordinates.
    pub x: Known<f64>,
    pub z: Known<f64>,
    /// A code of the motion group was written since the program started.
    pub motion_written: Known<bool>,
    /// A work offset or G53 was written since the program started.
    pub origin_chosen: Known<bool>,
    /// The block that switched compensation on (G41/G42) or off (G40)
    /// whose first move is still to come.
    pub compensation_change: Option<usize>,
    pub corner: Option<Corner>,
}

impl State {
    /// At power-on, as a main program starts.
    fn at_start(catalogue: &'static Catalogue) -> State {
        State {
            modes: Modes::at_reset(catalogue),
            variables: Variables::at_power_on(),
            feed: Setting::Unset,
            speed_limit: Setting::Unset,
            x: Known::Unknown,
            z: Known::Unknown,
            motion_written: Known::Is(false),
            origin_chosen: Known::Is(false),
            compensation_change: None,
            corner: None,
        }
    }

    /// Nothing known.
    fn unknown(catalogue: &'static Catalogue) -> State {
        State {
            modes: Modes::unknown(catalogue),
            variables: Variables::unknown(),
            feed: Setting::Unknown,
            speed_limit: Setting::Unknown,
            x: Known::Unknown,
            z: Known::Unknown,
            motion_written: Known::Unknown,
            origin_chosen: Known::Unknown,
            compensation_change: None,
            corner: None,
        }
    }

    /// What holds whichever of the two ways the program took.
    fn join(&self, other: &State) -> State {
        fn same<T: PartialEq + Copy>(a: Known<T>, b: Known<T>) -> Known<T> {
            if a == b { a } else { Known::Unknown }
        }
        let variables = if self.variables == other.variables { self.variables.clone() } else { Variables::unknown() };
        State {
            modes: self.modes.join(&other.modes),
            variables,
            feed: self.feed.join(other.feed),
            speed_limit: self.speed_limit.join(other.speed_limit),
            x: same(self.x, other.x),
            z: same(self.z, other.z),
            motion_written: same(self.motion_written, other.motion_written),
            origin_chosen: same(self.origin_chosen, other.origin_chosen),
            compensation_change: self
                .compensation_change
                .filter(|_| self.compensation_change == other.compensation_change),
            corner: self.corner.filter(|_| self.corner == other.corner),
        }
    }

    /// The value of a word: its literal, or its expression over the
    /// variables; unknown when not known or vacant.
    pub fn number(&self, word: &Word) -> Known<f64> {
        let (negative, value) = match word.value.as_ref() {
            None => return Known::Unknown,
            Some(Value::Literal(decimal)) => return Known::Is(decimal.to_f64()),
            Some(Value::Variable { negative, index }) => {
                let variable = nc_exec::haas_lathe::lower::Expr {
                    kind: ExprKind::Variable(Box::new(index.clone())),
                    range: index.range,
                };
                (*negative, self.variables.eval(&variable))
            }
            Some(Value::Bracket { negative, expr }) => (*negative, self.variables.eval(expr)),
        };
        match value {
            Ok(Known::Is(MacroValue::Number(value))) => Known::Is(if negative { -value } else { value }),
            _ => Known::Unknown,
        }
    }

    /// The code in force in `group` (`None`: no code of the group).
    pub fn code(&self, group: &str) -> Known<Option<u32>> {
        self.modes.known(group)
    }

    /// Whether `code` is known to be in force in `group`.
    pub fn is(&self, group: &str, code: u32) -> bool {
        self.code(group) == Known::Is(Some(code))
    }
}

/// What a block does with its axis words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// No axis word, no motion.
    Still,
    /// A move by the motion code in force: G00–G03, G32.
    Move(Known<u32>),
    /// A cycle that returns to its start point: G70–G76 and the turning
    /// cycles G90/G92/G94 in force.
    Cycle(u32),
    /// A drilling cycle at the block's position (written or in force).
    Drill,
    /// The axis words belong to another code (G53, G28, G52, G65 …), or
    /// what runs is not known.
    Other,
}

/// What the walk learnt running a contour for its cycle.
#[derive(Debug, Clone, Default)]
pub(crate) struct ContourRun {
    /// The end points (X as a diameter, Z) of its feed moves along the
    /// contour, where known.
    pub feed_points: Vec<(f64, f64)>,
    /// What the P block does.
    pub p_kind: Option<Kind>,
}

/// A block as the rules see it in the walk.
pub(crate) struct Visit<'a> {
    pub file: &'a FileModel,
    /// The program's index in the model.
    pub program: usize,
    pub index: usize,
    pub block: &'a HaasBlock,
    pub kind: Kind,
    pub before: &'a State,
    pub after: &'a State,
    /// The cycle whose contour this block is run as.
    pub contour: Option<&'a Contour>,
    /// For a cycle block with a contour: what running it showed.
    pub run: Option<&'a ContourRun>,
}

impl Visit<'_> {
    /// A word's range in the file.
    pub fn range(&self, word: &Word) -> ncc_syntax::TextRange {
        self.file.in_file(self.index, word.range)
    }

    /// The block's first G code `number`'s range, else the block's start.
    pub fn code_range(&self, number: u32) -> ncc_syntax::TextRange {
        self.file.code_range(self.index, b'G', number)
    }

    /// Whether the block writes the G code `number`.
    pub fn writes(&self, number: u32) -> bool {
        self.block.has_code(b'G', number)
    }
}

/// Walks every program of `file`, showing `visit` each block it runs.
pub(crate) fn walk(file: &FileModel, visit: &mut dyn FnMut(&Visit<'_>)) {
    let catalogue = Dialect::HaasLathe.catalogue();
    for (index, program) in file.model.programs.iter().enumerate() {
        let mut walker = Walker { file, catalogue, program: index, visit };
        let start = walker.start(program);
        let from = Resume { at: program.blocks.start, state: start };
        walker.program(program, from, usize::MAX, &mut |_| ControlFlow::Continue(()));
    }
}

/// Where the walk of a program stands between two blocks: the next block
/// to run and the state before it.
#[derive(Debug, Clone)]
pub(crate) struct Resume {
    pub at: usize,
    pub state: State,
}

/// Walks program `program` of `file` from `from` until it passes block
/// `until`, showing `visit` each block it runs, and `stand` each place it
/// stands at between blocks (where it may resume), which may end it.
pub(crate) fn walk_from(
    file: &FileModel,
    program: usize,
    from: Resume,
    until: usize,
    visit: &mut dyn FnMut(&Visit<'_>),
    stand: &mut dyn FnMut(&Resume) -> ControlFlow<()>,
) {
    let catalogue = Dialect::HaasLathe.catalogue();
    let mut walker = Walker { file, catalogue, program, visit };
    walker.program(&file.model.programs[program], from, until, stand);
}

/// The state program `program` of `file` starts in.
pub(crate) fn program_start(file: &FileModel, program: usize) -> State {
    let catalogue = Dialect::HaasLathe.catalogue();
    let walker = Walker { file, catalogue, program, visit: &mut |_| {} };
    walker.start(&file.model.programs[program])
}

/// The blocks of `program` where the walk forgets the state: jump targets
/// and loops.
pub(crate) fn joins(file: &FileModel, program: &Program) -> BTreeSet<usize> {
    let mut joins = BTreeSet::new();
    for finding in &file.model.findings {
        match finding {
            Finding::Resolved { reference, target: Target::Block(target) }
                if reference.kind == ReferenceKind::Goto && program.blocks.contains(&reference.block) =>
            {
                joins.insert(*target);
            }
            Finding::ComputedTarget(reference)
                if reference.kind == ReferenceKind::Goto && program.blocks.contains(&reference.block) =>
            {
                joins.extend(program.block_numbers.values().flatten());
            }
            _ => {}
        }
    }
    for &(start, end) in &program.loops {
        joins.insert(start);
        joins.insert(end + 1);
    }
    joins
}

struct Walker<'a, 'v> {
    file: &'a FileModel,
    catalogue: &'static Catalogue,
    program: usize,
    visit: &'v mut dyn FnMut(&Visit<'_>),
}

/// A block run: the state after it, what it did with its axis words and,
/// after a roughing cycle, the block the run goes on with.
struct Step {
    after: State,
    kind: Kind,
    next: Option<usize>,
}

impl<'a> Walker<'a, '_> {
    /// The state `program` starts in: power-on for a main program, nothing
    /// known for a subprogram.
    fn start(&self, program: &Program) -> State {
        // The ends are marked blocks.
        let blocks = self.file.blocks();
        let ends = || blocks.marked(program.blocks.clone()).map(|index| blocks.at(index));
        let subprogram = ends().any(|block| block.has_code(b'M', 99)) && !ends().any(ends_program);
        if subprogram { State::unknown(self.catalogue) } else { State::at_start(self.catalogue) }
    }

    fn program(
        &mut self,
        program: &Program,
        from: Resume,
        until: usize,
        stand: &mut dyn FnMut(&Resume) -> ControlFlow<()>,
    ) {
        let blocks = &self.file.unit.blocks;
        let joins = joins(self.file, program);
        let mut here = from;
        while here.at < program.blocks.end && here.at <= until {
            if joins.contains(&here.at) {
                here.state = State::unknown(self.catalogue);
            }
            if !blocks.block(here.at).has_content() {
                here.at += 1;
                continue;
            }
            let step = self.block(here.at, &here.state, None);
            here = Resume { at: step.next.unwrap_or(here.at + 1), state: step.after };
            if stand(&here).is_break() {
                return;
            }
        }
    }

    /// Runs block `at` from `before`, in the contour of a cycle or not.
    fn block(&mut self, at: usize, before: &State, contour: Option<&Contour>) -> Step {
        let block = self.file.block(at);
        let mut after = before.clone();
        let kind = self.apply(at, before, &mut after, contour.is_some());
        let mut next = None;
        let cycle = match kind {
            Kind::Cycle(70..=73) if contour.is_none() => self.contour_of(at),
            _ => None,
        };
        let run = cycle.map(|cycle| {
            let (run, end) = self.run_contour(cycle, &after);
            after.modes = after.modes.join(&end.modes);
            // A roughing cycle goes on after its contour, when that follows.
            if cycle.code != 70 && *cycle.blocks.end() > at {
                next = Some(cycle.blocks.end() + 1);
            }
            run
        });
        (self.visit)(&Visit {
            file: self.file,
            program: self.program,
            index: at,
            block,
            kind,
            before,
            after: &after,
            contour,
            run: run.as_ref(),
        });
        if block.skip.is_some() {
            after = after.join(before);
        }
        if ends_flow(block) {
            after = State::unknown(self.catalogue);
        }
        Step { after, kind, next }
    }

    fn contour_of(&self, cycle: usize) -> Option<&'a Contour> {
        self.file.model.contours().find(|contour| contour.cycle == cycle)
    }

    /// Runs the blocks of `contour` for its cycle from `start`; what it
    /// showed and the state at its end.
    fn run_contour(&mut self, contour: &Contour, start: &State) -> (ContourRun, State) {
        let mut run = ContourRun::default();
        let mut state = start.clone();
        for at in contour.blocks.clone() {
            if !self.file.block(at).has_content() {
                continue;
            }
            let step = self.block(at, &state, Some(contour));
            if at == *contour.blocks.start() {
                run.p_kind = Some(step.kind);
            }
            // The move that cancels the compensation departs from the contour.
            let departs = self.file.block(at).has_code(b'G', 40);
            if let (Kind::Move(Known::Is(1..=3)), Known::Is(x), Known::Is(z), false) =
                (step.kind, step.after.x, step.after.z, departs)
            {
                run.feed_points.push((x, z));
            }
            state = step.after;
        }
        (run, state)
    }

    /// Block `at`'s effects on `after` (a copy of `before`); what it does
    /// with its axis words.
    fn apply(&self, at: usize, before: &State, after: &mut State, in_contour: bool) -> Kind {
        let block = self.file.block(at);
        for code in block.codes(b'G') {
            after.modes.set('G', code);
            let group = self.catalogue.group_of('G', code).map(|group| group.id.as_str());
            if group == Some(MOTION) {
                after.motion_written = Known::Is(true);
            }
            if code == 53 || group == Some(WORK_OFFSET) {
                after.origin_chosen = Known::Is(true);
            }
        }
        for code in block.codes(b'M') {
            after.modes.set('M', code);
        }
        if !in_contour && (block.word(b'F').is_some() || block.word(b'E').is_some()) {
            after.feed = Setting::Set;
        }
        if block.has_code(b'G', 50) && block.word(b'S').is_some() {
            after.speed_limit = Setting::Set;
        }
        let kind = classify(block, after);
        move_to(block, kind, before, after);
        let switched = [40, 41, 42].iter().any(|&code| block.has_code(b'G', code))
            && before.code(COMPENSATION) != Known::Unknown
            && after.code(COMPENSATION) != before.code(COMPENSATION);
        after.compensation_change = match kind {
            Kind::Still if switched => Some(at),
            Kind::Still => before.compensation_change,
            _ => None,
        };
        after.corner = match kind {
            Kind::Still => before.corner,
            _ => corner(self.catalogue, at, block, kind),
        };
        for statement in &block.statements {
            run_statement(statement, &mut after.variables);
        }
        if block.word(b'T').is_some() && !in_contour {
            // The new tool's offset moves the programmed point.
            after.x = Known::Unknown;
            after.z = Known::Unknown;
        }
        if calls(block) {
            *after = State::unknown(self.catalogue);
        }
        kind
    }
}

/// What the block does with its axis words, given the state after its
/// codes.
fn classify(block: &HaasBlock, after: &State) -> Kind {
    let catalogue = Dialect::HaasLathe.catalogue();
    let is_cycle = |code: u32| catalogue.cycles_for(&format!("G{code:02}")).next().is_some();
    let group_of = |code: u32| catalogue.group_of('G', code).map(|group| group.id.as_str());
    // G65's words are the macro's arguments.
    if block.has_code(b'G', 65) {
        return Kind::Other;
    }
    for code in block.codes(b'G') {
        match group_of(code) {
            Some(DRILLING | MOTION | COMPENSATION) => {}
            _ if is_cycle(code) => return Kind::Cycle(code),
            _ => {
                let axes = ["X", "Z", "U", "W"];
                if catalogue.code('G', code).is_some_and(|c| c.allows.iter().any(|a| axes.contains(&a.as_str()))) {
                    return Kind::Other;
                }
            }
        }
    }
    let moves = axis_words(block);
    // A drilling cycle runs where it is written and at every X, Z or C
    // after (001:1077-1080).
    let drills = block.codes(b'G').any(|code| drilling_cycle(catalogue, code)) || block.word(b'C').is_some();
    match after.code(DRILLING) {
        Known::Is(Some(code)) if drilling_cycle(catalogue, code) && (moves || drills) => return Kind::Drill,
        Known::Unknown if moves => return Kind::Other,
        _ => {}
    }
    if !moves {
        return Kind::Still;
    }
    match after.code(MOTION) {
        Known::Is(Some(code)) if is_cycle(code) => Kind::Cycle(code),
        Known::Is(Some(code)) => Kind::Move(Known::Is(code)),
        _ => Kind::Move(Known::Unknown),
    }
}

/// Whether G`number` is a drilling cycle: a code of the drilling group
/// other than the one that cancels them.
pub(crate) fn drilling_cycle(catalogue: &Catalogue, number: u32) -> bool {
    let Some(group) = catalogue.group_of('G', number).filter(|group| group.id == DRILLING) else { return false };
    group.default.as_deref().and_then(split_code) != Some(('G', number))
}

/// Where the block leaves the tool.
fn move_to(block: &HaasBlock, kind: Kind, before: &State, after: &mut State) {
    let offset = after.code(WORK_OFFSET);
    if offset != before.code(WORK_OFFSET) || offset == Known::Unknown {
        after.x = Known::Unknown;
        after.z = Known::Unknown;
    }
    match kind {
        // A cycle returns to its start point.
        Kind::Still | Kind::Cycle(_) => {}
        Kind::Move(motion) => {
            after.x = end(block, after, b'X', b'U', after.x);
            after.z = end(block, after, b'Z', b'W', after.z);
            // A line by angle ends where the angle takes the other axis.
            if motion == Known::Is(1) && block.word(b'A').is_some() {
                let catalogue = Dialect::HaasLathe.catalogue();
                if !taken(catalogue, block, b'A') {
                    if block.word(b'X').is_none() && block.word(b'U').is_none() {
                        after.x = Known::Unknown;
                    }
                    if block.word(b'Z').is_none() && block.word(b'W').is_none() {
                        after.z = Known::Unknown;
                    }
                }
            }
        }
        Kind::Drill | Kind::Other => {
            after.x = Known::Unknown;
            after.z = Known::Unknown;
        }
    }
}

/// The end of an axis: the absolute word, else the start plus the
/// incremental one (X and U are diameters).
fn end(block: &HaasBlock, state: &State, absolute: u8, incremental: u8, from: Known<f64>) -> Known<f64> {
    if let Some(word) = block.word(absolute) {
        return state.number(word);
    }
    match (block.word(incremental), from) {
        (None, from) => from,
        (Some(word), Known::Is(from)) => match state.number(word) {
            Known::Is(by) => Known::Is(from + by),
            Known::Unknown => Known::Unknown,
        },
        (Some(_), Known::Unknown) => Known::Unknown,
    }
}

/// The corner a G01 move's I, K or R asks for.
fn corner(catalogue: &Catalogue, at: usize, block: &HaasBlock, kind: Kind) -> Option<Corner> {
    if kind != Kind::Move(Known::Is(1)) {
        return None;
    }
    let word = block
        .words
        .iter()
        .position(|w| matches!(w.letter, b'I' | b'K' | b'R') && !taken(catalogue, block, w.letter))?;
    let x = block.word(b'X').is_some() || block.word(b'U').is_some();
    let z = block.word(b'Z').is_some() || block.word(b'W').is_some();
    let along = match (x, z) {
        (true, false) => Some(b'X'),
        (false, true) => Some(b'Z'),
        _ => None,
    };
    Some(Corner { block: at, word, along })
}

/// Whether the block has an X, Z, U or W word.
pub(crate) fn axis_words(block: &HaasBlock) -> bool {
    block.words.iter().any(|w| matches!(w.letter, b'X' | b'Z' | b'U' | b'W'))
}

/// Whether a code of the block besides the motion reads `letter` (G40 its
/// I/K, a cycle its I/K/R/A), so that it is no corner or angle of G01.
pub(crate) fn taken(catalogue: &Catalogue, block: &HaasBlock, letter: u8) -> bool {
    let letter = char::from(letter).to_string();
    block.codes(b'G').any(|code| {
        catalogue.group_of('G', code).is_none_or(|group| group.id != MOTION)
            && catalogue.code('G', code).is_some_and(|c| c.allows.contains(&letter) || c.requires.contains(&letter))
    })
}

fn run_statement(statement: &Statement, variables: &mut Variables) {
    match statement {
        Statement::Assign { target, value, .. } => {
            // An error stops the control, which the run reports.
            let _ = variables.assign(target, value);
        }
        Statement::If { condition, then: Some(then), .. } => match variables.condition(condition) {
            Ok(Known::Is(true)) => run_statement(then, variables),
            Ok(Known::Is(false)) | Err(_) => {}
            Ok(Known::Unknown) => {
                let mut ran = variables.clone();
                run_statement(then, &mut ran);
                if ran != *variables {
                    *variables = Variables::unknown();
                }
            }
        },
        _ => {}
    }
}

/// M30 or M02.
pub(crate) fn ends_program(block: &HaasBlock) -> bool {
    block.has_code(b'M', 30) || block.has_code(b'M', 2)
}

/// After the block the run does not go on with the next one: an end, a
/// return, an unconditional GOTO, a loop's END.
fn ends_flow(block: &HaasBlock) -> bool {
    ends_program(block)
        || block.has_code(b'M', 99)
        || block.statements.iter().any(|s| matches!(s, Statement::Goto { .. } | Statement::LoopEnd { .. }))
}

/// M97, M98 or G65: the callee may change anything.
fn calls(block: &HaasBlock) -> bool {
    block.has_code(b'M', 97) || block.has_code(b'M', 98) || block.has_code(b'G', 65)
}
