//! The walk over a Sinumerik file with the modal state, for the rules that
//! need what is in force at a block: the codes of the groups (the run's
//! [`Modes`]), the feed, the spindle speed, where the tool stands, which
//! frame its coordinates count in, and the programmable frame composed as
//! the run composes it (from the values frame commands and CYCLE800 write,
//! and R parameters set to numbers).
//!
//! It visits each block once, in file order. A main program starts at
//! reset (the catalogue's defaults, no F, no S); a subprogram (a PROC, an
//! SPF file) from an unknown state, since its caller's is not known here,
//! but without a modal call (MCALL) in force, under G90 and ORIEULER.
//! Where the file's order is not the run's order, it keeps what holds
//! whichever way the program goes:
//!
//! - IF/ELSE/ENDIF: after the ENDIF, what both branches agree on.
//! - A loop (WHILE, FOR, REPEAT, LOOP) starts from the state before it
//!   with everything its body may change forgotten, and a WHILE or FOR,
//!   which may not run at all, ends so too.
//! - A jump's target (every label and block number when a target is
//!   computed) and the block after an unconditional jump, a RET or an end
//!   of program start from an unknown state.
//! - A call of a program, a repeated section and a modal call of a program
//!   may change anything: after them nothing is known. A cycle leaves the
//!   tool where the walk cannot say.
//!
//! A block-delete block (`/`) is taken to run: a finding after it holds on
//! the way where it runs.
//!
//! An unknown value never produces a finding, so a rule reports only what
//! holds on a way the program really runs.

use std::{ops::ControlFlow, sync::Arc};

use nc_exec::{
    known::Known,
    sinumerik::{
        cycles::swivel,
        frames::{FrameCommand, FrameKind, Plane, ProgrammableFrame},
        lower::{
            Call, Callee, Command, Dimension, Expr, ExprKind, JumpKind, Place, PlaceKind, SinumerikBlock, Statement,
            StatementKind, UnaryOp, Word, WordValue, is_axis,
        },
        modes::{
            Modes,
            groups::{DIMENSIONS, FRAMES, MACHINE_COORDINATES, MOTION, PATH_MODE, PLANE, UNITS, WORK_OFFSETS},
        },
        program::{Resolved, Structure, StructureKind},
    },
};
use ncc_catalog::{Catalogue, Code, Cycle, Dialect};
use ncc_syntax::TextRange;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::lowered::Watched;
use crate::{
    db::Db,
    sinumerik::{
        checks::visit::{is_transformation, signed_value, written_places},
        model::FileModel,
    },
};

/// The codes of the motion group that cut a thread: they move at the
/// pitch and spindle speed, not at F.
const THREADS: [&str; 3] = ["G33", "G331", "G332"];

/// Points closer than this, in mm, are the same: the thesis's CAM output
/// repeats the current point to a few tenths of a µm.
pub(crate) const SAME_POINT_MM: f64 = 0.001;

/// The cycle that swivels the working plane.
const SWIVEL_CYCLE: &str = "CYCLE800";

/// The path axes.
pub(crate) const PATH_AXES: [&str; 3] = ["X", "Y", "Z"];

/// The axes and orientation words whose positions the walk follows: the
/// path axes first, then the rotary axes, the orientation's angles (A2 …)
/// and its vector (A3 …).
pub(crate) const FOLLOWED: [&str; 12] = ["X", "Y", "Z", "A", "B", "C", "A2", "B2", "C2", "A3", "B3", "C3"];

/// Nothing known of where the tool stands.
const NOWHERE: [Known<f64>; FOLLOWED.len()] = [Known::Unknown; FOLLOWED.len()];

fn catalogue() -> &'static Catalogue {
    Dialect::Sinumerik.catalogue()
}

/// What the control holds between blocks, as far as the walk knows.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct State {
    pub modes: Modes,
    /// The feed F: `Is(None)` before any was programmed.
    pub feed: Known<Option<f64>>,
    /// The spindle speed S: `Is(None)` before any was programmed.
    pub speed: Known<Option<f64>>,
    /// The [`FOLLOWED`] axes and words, in the frame in force.
    pub position: [Known<f64>; FOLLOWED.len()],
    /// The frame the positions count in: the block that last changed the
    /// frame, a work offset or the transformation, `Is(None)` for the one
    /// the program started in.
    pub frame: Known<Option<usize>>,
    /// The programmable frame in force, composed from the frame commands
    /// with the values they write (digest rule 74).
    pub composed: Known<Arc<ProgrammableFrame>>,
    /// The R parameters last set to a number (`R1=0.18`), by number: what
    /// a frame command or CYCLE800 may read of them.
    parameters: Vec<(u64, f64)>,
    /// A modal call (MCALL) in force, which runs at every move.
    pub modal_call: Known<Option<ModalCall>>,
}

/// A modal call (MCALL) in force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ModalCall {
    /// A program's, which may change anything.
    Program,
    /// A hole cycle's (the catalogue's `hole`): it leaves the tool above
    /// the hole, where the move put it.
    Hole(&'static Cycle),
    /// Another cycle's.
    Cycle,
}

impl ModalCall {
    fn of(callee: &Callee) -> ModalCall {
        match callee {
            Callee::Cycle(name) => catalogue().hole_cycle(name).map_or(ModalCall::Cycle, ModalCall::Hole),
            _ => ModalCall::Program,
        }
    }
}

impl State {
    /// At reset, as a main program starts.
    pub(crate) fn at_reset() -> State {
        State {
            modes: Modes::at_reset(),
            feed: Known::Is(None),
            speed: Known::Is(None),
            position: NOWHERE,
            frame: Known::Is(None),
            composed: Known::Is(Arc::default()),
            parameters: Vec::new(),
            modal_call: Known::Is(None),
        }
    }

    /// Nothing known.
    pub(crate) fn unknown() -> State {
        State {
            modes: Modes::unknown(),
            feed: Known::Unknown,
            speed: Known::Unknown,
            position: NOWHERE,
            frame: Known::Unknown,
            composed: Known::Unknown,
            parameters: Vec::new(),
            modal_call: Known::Unknown,
        }
    }

    /// As a subprogram starts: its caller's state is not known, and it is
    /// taken to be called without a modal call in force, as programs
    /// mostly are (else every move would forget everything), and under
    /// G90.
    fn subprogram_start() -> State {
        let mut state = State { frame: Known::Is(None), modal_call: Known::Is(None), ..State::unknown() };
        // Coordinates are taken as absolute and orientation angles as Euler
        // angles until the subprogram says: the thesis's subprograms never
        // write G90 or ORIEULER (L26–L28).
        for assumed in ["G90", "ORIEULER"] {
            if let Some(code) = catalogue().code_named(assumed) {
                state.modes.set(code);
            }
        }
        state
    }

    /// Forgets everything but the modal call, which only MCALL changes.
    fn forget(&mut self) {
        *self = State { modal_call: self.modal_call, ..State::unknown() };
    }

    /// What holds whichever of the two ways the program took.
    fn join(&self, other: &State) -> State {
        fn same<T: PartialEq + Clone>(a: &Known<T>, b: &Known<T>) -> Known<T> {
            if a == b { a.clone() } else { Known::Unknown }
        }
        State {
            modes: self.modes.join(&other.modes),
            feed: same(&self.feed, &other.feed),
            speed: same(&self.speed, &other.speed),
            position: std::array::from_fn(|axis| same(&self.position[axis], &other.position[axis])),
            frame: same(&self.frame, &other.frame),
            composed: same(&self.composed, &other.composed),
            parameters: self.parameters.iter().filter(|p| other.parameters.contains(p)).copied().collect(),
            modal_call: same(&self.modal_call, &other.modal_call),
        }
    }

    /// The motion code in force.
    pub(crate) fn motion(&self) -> Option<&'static str> {
        self.modes.get(MOTION)
    }

    /// Whether the motion in force moves at the feed F.
    pub(crate) fn feed_motion(&self) -> Known<bool> {
        match self.motion() {
            Some(code) => Known::Is(code != "G0" && !THREADS.contains(&code)),
            None => Known::Unknown,
        }
    }

    /// Whether a continuous-path mode (G64, G641–G645) is in force.
    pub(crate) fn continuous_path(&self) -> Known<bool> {
        match self.modes.get(PATH_MODE) {
            Some(code) => Known::Is(code != "G60"),
            None => Known::Unknown,
        }
    }

    /// The effect of block `index`; whether it moves an axis. `variables`:
    /// the names the program declares, which a word like `X=5` assigns.
    pub(crate) fn apply(&mut self, index: usize, block: &SinumerikBlock, variables: &Variables<'_>) -> bool {
        let catalogue = catalogue();
        let mut codes: Vec<&'static Code> = Vec::new();
        for statement in &block.statements {
            self.parameter_written(statement);
            match &statement.kind {
                StatementKind::Word(word) => self.function_word(index, word, &mut codes),
                StatementKind::Command(command) => match catalogue.word_code(&command.name) {
                    Some(code) if code.group.as_deref() == Some(FRAMES) => self.frame(index, command),
                    Some(code) => codes.push(code),
                    None if is_transformation(&command.name) => self.new_frame(index),
                    None => {}
                },
                // `G[8]=R1`: a group's code only the run knows, maybe a
                // work offset's.
                StatementKind::Assign { target, .. } if target.kind == PlaceKind::GroupCode => {
                    self.codes_unknown();
                    self.composed = Known::Unknown;
                }
                _ => {}
            }
        }
        let in_group = |group: &str| codes.iter().any(|code| code.group.as_deref() == Some(group));
        // The block's coordinates count in the new system.
        if [WORK_OFFSETS, UNITS].into_iter().any(in_group) {
            self.new_frame(index);
        }
        for &code in &codes {
            self.modes.set(code);
        }
        let dwell = codes.iter().any(|code| code.code == "G4");
        let moved = self.values(block, dwell, variables);
        // Machine coordinates for the block, or a reference point: where
        // the tool ends in the frame is not known.
        if in_group(MACHINE_COORDINATES) || codes.iter().any(|code| matches!(code.code.as_str(), "G74" | "G75")) {
            self.position = NOWHERE;
        }
        for statement in &block.statements {
            match &statement.kind {
                StatementKind::Call(call) => self.call(index, call),
                StatementKind::ModalCall(call) => {
                    self.modal_call = Known::Is(call.as_ref().map(|call| ModalCall::of(&call.callee)));
                }
                StatementKind::RepeatSection { .. } => self.forget(),
                _ => {}
            }
        }
        if moved {
            match self.modal_call {
                Known::Is(None) => {}
                Known::Is(Some(ModalCall::Hole(_))) => self.forget_tool_axis(),
                Known::Is(Some(ModalCall::Cycle)) => self.position = NOWHERE,
                Known::Is(Some(ModalCall::Program)) | Known::Unknown => self.forget(),
            }
        }
        moved
    }

    /// A code only the run knows (`G=R1`, `G[8]=R1`): any group's, a work
    /// offset's too.
    fn codes_unknown(&mut self) {
        self.modes = Modes::unknown();
        self.position = NOWHERE;
        self.frame = Known::Unknown;
    }

    /// The working plane in force.
    pub(crate) fn plane(&self) -> Option<Plane> {
        self.modes.get(PLANE).and_then(Plane::from_code)
    }

    /// Block `index` changed the frame, a work offset or the
    /// transformation: the positions count anew.
    fn new_frame(&mut self, index: usize) {
        self.position = NOWHERE;
        self.frame = Known::Is(Some(index));
    }

    /// A hole cycle ran: the tool stands above the hole, at a height along
    /// the tool axis the walk does not follow.
    fn forget_tool_axis(&mut self) {
        match self.plane() {
            Some(plane) => self.position[plane.axes()[2]] = Known::Unknown,
            None => self.position = NOWHERE,
        }
    }

    /// A frame moves the coordinates: those of the axes an additive
    /// translation, scale or mirror names (`ATRANS X-300`), every one for
    /// a rotation or a frame that replaces the one in force.
    fn frame(&mut self, index: usize, command: &Command) {
        self.frame = Known::Is(Some(index));
        let frame_command = FrameCommand::from_name(&command.name);
        let named_only = frame_command.is_some_and(|c| c.additive && c.kind != FrameKind::Rotation);
        for (axis, name) in FOLLOWED.iter().enumerate() {
            if !named_only || command.words.iter().any(|word| word.address == *name) {
                self.position[axis] = Known::Unknown;
            }
        }
        self.composed = match frame_command {
            Some(frame_command) => self.composed_with(frame_command, command).map_or(Known::Unknown, Known::Is),
            None => Known::Unknown,
        };
    }

    /// What a statement writes to R parameters.
    fn parameter_written(&mut self, statement: &Statement) {
        written_places(statement, &mut |place, _| {
            if place.kind == PlaceKind::Parameter {
                match parameter_number(place) {
                    Some(number) => self.parameters.retain(|&(known, _)| known != number),
                    None => self.parameters.clear(),
                }
            }
        });
        if let StatementKind::Assign { target, value } = &statement.kind
            && target.kind == PlaceKind::Parameter
            && let Some(number) = parameter_number(target)
            && let Some(value) = self.number(value)
        {
            self.parameters.push((number, value));
        }
    }

    /// An expression's value, where it is a number, or an R parameter the
    /// walk knows, with its sign.
    fn number(&self, expr: &Expr) -> Option<f64> {
        match &expr.kind {
            ExprKind::Number(number) => Some(number.value()),
            ExprKind::Unary(UnaryOp::Minus, operand) => self.number(operand).map(|value| -value),
            ExprKind::Unary(UnaryOp::Plus, operand) => self.number(operand),
            ExprKind::Name(place) if place.kind == PlaceKind::Parameter => {
                let number = parameter_number(place)?;
                self.parameters.iter().find(|&&(known, _)| known == number).map(|&(_, value)| value)
            }
            _ => None,
        }
    }

    /// A word's value, as [`State::number`].
    fn word_number(&self, value: &WordValue) -> Option<f64> {
        match value {
            WordValue::Expr { expr, .. } => self.number(expr),
            literal => signed_value(literal),
        }
    }

    /// The programmable frame after a call of CYCLE800, as the run swivels
    /// it, where the walk knows every argument (the swivel data record, a
    /// string, is not read) and, for an additive swivel, the frame before.
    fn swivelled(&self, call: &Call) -> Option<Arc<ProgrammableFrame>> {
        if !matches!(&call.callee, Callee::Cycle(name) if name == SWIVEL_CYCLE) {
            return None;
        }
        let arguments = call
            .arguments
            .iter()
            .map(|argument| match argument {
                None => Some(None),
                Some(Expr { kind: ExprKind::String(_), .. }) => Some(None),
                Some(expr) => self.number(expr).map(Some),
            })
            .collect::<Option<Vec<_>>>()?;
        let swivel = swivel(&arguments).ok()?;
        let mut frame = match &self.composed {
            Known::Is(frame) => ProgrammableFrame::clone(frame),
            Known::Unknown if !swivel.additive => ProgrammableFrame::default(),
            Known::Unknown => return None,
        };
        swivel.apply_to(&mut frame);
        Some(Arc::new(frame))
    }

    /// The programmable frame after `command`, as the run composes it,
    /// where the walk knows the frame before it (unless the command
    /// replaces it), the plane, the units and every value it writes.
    fn composed_with(&self, frame_command: FrameCommand, command: &Command) -> Option<Arc<ProgrammableFrame>> {
        let mut frame = match (&self.composed, frame_command.additive) {
            (_, false) => ProgrammableFrame::default(),
            (Known::Is(frame), true) => ProgrammableFrame::clone(frame),
            (Known::Unknown, true) => return None,
        };
        let plane = self.plane()?;
        let per_unit = self.modes.mm_per_unit()?;
        let values = command
            .words
            .iter()
            .map(|word| {
                let value = self.word_number(word.value.as_ref()?)?;
                let value = if frame_command.kind == FrameKind::Translation { value * per_unit } else { value };
                Some((word.address.as_str(), value))
            })
            .collect::<Option<Vec<_>>>()?;
        frame.apply(frame_command, &values, plane).ok()?;
        Some(Arc::new(frame))
    }

    /// A G or M word: its code, or what it makes unknown.
    fn function_word(&mut self, index: usize, word: &Word, codes: &mut Vec<&'static Code>) {
        let catalogue = catalogue();
        let literal = match &word.value {
            Some(WordValue::Literal(number)) => number.whole().and_then(|n| u32::try_from(n).ok()),
            _ => None,
        };
        match (word.address.as_str(), literal) {
            ("G", Some(number)) => match catalogue.code('G', number) {
                Some(code) => codes.push(code),
                // A code the catalogue does not list (`G505`): it may
                // move the origin.
                None => self.new_frame(index),
            },
            ("G", None) => self.codes_unknown(),
            ("M", Some(number)) => codes.extend(catalogue.code('M', number)),
            // `M=R1`, `M1=3`, `SPOS=0`: another spindle or a value the
            // walk does not know.
            (address, _) if address.starts_with('M') || address.starts_with("SPOS") => self.forget_m_groups(),
            _ => {}
        }
    }

    fn forget_m_groups(&mut self) {
        for group in &catalogue().groups {
            if group.id.starts_with('M') {
                self.modes.forget(&group.id);
            }
        }
    }

    /// F, S and the path axes; whether the block moves an axis.
    fn values(&mut self, block: &SinumerikBlock, dwell: bool, variables: &Variables<'_>) -> bool {
        let incremental = match self.modes.get(DIMENSIONS) {
            Some(code) => Known::Is(code == "G91"),
            None => Known::Unknown,
        };
        let mut moved = false;
        for statement in &block.statements {
            let StatementKind::Word(word) = &statement.kind else { continue };
            if assigns(word, variables) {
                continue;
            }
            let value = word.value.as_ref().and_then(signed_value);
            match word.address.as_str() {
                // In a G4 block F and S give the dwell.
                "F" | "S" if dwell => {}
                "F" => self.feed = value.map_or(Known::Unknown, |value| Known::Is(Some(value))),
                "S" => self.speed = value.map_or(Known::Unknown, |value| Known::Is(Some(value))),
                address if address.starts_with('S') && address[1..].bytes().all(|b| b.is_ascii_digit()) => {
                    self.speed = Known::Unknown;
                }
                address => {
                    if is_axis(address) {
                        moved = true;
                    }
                    let Some(axis) = FOLLOWED.iter().position(|a| *a == address) else { continue };
                    let incremental = match &word.value {
                        Some(WordValue::Expr { dimension: Some(dimension), .. }) => {
                            Known::Is(*dimension == Dimension::Incremental)
                        }
                        _ => incremental,
                    };
                    self.position[axis] = match (value, incremental) {
                        (Some(value), Known::Is(true)) => match self.position[axis] {
                            Known::Is(from) => Known::Is(from + value),
                            Known::Unknown => Known::Unknown,
                        },
                        (Some(value), Known::Is(false)) => Known::Is(value),
                        _ => Known::Unknown,
                    };
                }
            }
        }
        moved
    }

    fn call(&mut self, index: usize, call: &Call) {
        let callee = &call.callee;
        if matches!(callee, Callee::Predefined(_)) {
            return;
        }
        match ModalCall::of(callee) {
            ModalCall::Hole(_) => self.forget_tool_axis(),
            // CYCLE800 swivels the plane; other cycles leave the tool where
            // the walk cannot say.
            ModalCall::Cycle => {
                self.new_frame(index);
                self.composed = self.swivelled(call).map_or(Known::Unknown, Known::Is);
            }
            ModalCall::Program => self.forget(),
        }
    }
}

/// The number of `R5` or `R[5]`; `None` for a computed one.
fn parameter_number(place: &Place) -> Option<u64> {
    match place.indices.as_slice() {
        [Expr { kind: ExprKind::Number(number), .. }] => number.whole(),
        _ => None,
    }
}

/// The names a program declares (DEF, its PROC's parameters), upper case.
pub(crate) type Variables<'a> = FxHashSet<&'a str>;

/// Whether a word assigns a declared variable (`X=5` after `DEF REAL X`),
/// as the run reads it.
fn assigns(word: &Word, variables: &Variables<'_>) -> bool {
    matches!(&word.value, Some(WordValue::Expr { dimension: None, .. })) && variables.contains(word.address.as_str())
}

/// A G2/G3 block's arc given by its radius CR, as the walk knows it: the
/// two coordinates of the plane in force at its start and end, and CR as
/// written (negative: the longer arc).
pub(crate) struct RadiusArc<'a> {
    /// The plane's axes, in the order G2 turns clockwise.
    pub axes: [&'static str; 2],
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub radius: f64,
    pub counter_clockwise: bool,
    /// The `CR=…` statement.
    pub written: &'a Statement,
}

impl RadiusArc<'_> {
    /// The arc of block `block`, moved from `from` to `state`'s position;
    /// `None` when it is no CR arc or an end is not known.
    pub(crate) fn of<'a>(block: &'a SinumerikBlock, from: &[Known<f64>], state: &State) -> Option<RadiusArc<'a>> {
        let counter_clockwise = match state.motion()? {
            "G2" => false,
            "G3" => true,
            _ => return None,
        };
        let (written, radius) = block.statements.iter().find_map(|statement| match &statement.kind {
            StatementKind::Word(word) if word.address == "CR" => Some((statement, word.value.as_ref()?)),
            _ => None,
        })?;
        let radius = signed_value(radius)?;
        let [a, b, _] = state.plane()?.axes();
        let known = |position: &[Known<f64>], axis: usize| position[axis].known();
        Some(RadiusArc {
            axes: [PATH_AXES[a], PATH_AXES[b]],
            from: [known(from, a)?, known(from, b)?],
            to: [known(&state.position, a)?, known(&state.position, b)?],
            radius,
            counter_clockwise,
            written,
        })
    }
}

/// Whether a block's statements end the way on to the next block: an end
/// of program, RET, or an unconditional jump. A jump that finds no target
/// is left out: the parser or a rule reports it, and what follows it is
/// not reported again.
fn ends_way(block: &SinumerikBlock, index: usize, failed: &FxHashSet<(usize, TextRange)>) -> bool {
    block.program_end().is_some()
        || block.statements.iter().any(|statement| match &statement.kind {
            StatementKind::Jump(jump) => jump.kind != JumpKind::GotoC && !failed.contains(&(index, jump.range)),
            _ => false,
        })
}

/// One block as the walk sees it.
pub(crate) struct Step<'a> {
    pub index: usize,
    pub block: &'a SinumerikBlock,
    /// Where the tool stood before the block.
    pub from: [Known<f64>; FOLLOWED.len()],
    /// The state after the block.
    pub state: &'a State,
    /// Whether the block moves an axis.
    pub moves: bool,
    /// Whether a way the program runs reaches the block: not after an end
    /// or an unconditional jump unless a jump or a structure leads there.
    pub reached: bool,
    /// The control structure the block opens.
    pub opens: Option<&'a Structure>,
}

impl Step<'_> {
    /// The range of the block's first statement that `matches`.
    pub(crate) fn find(&self, file: &FileModel, matches: impl Fn(&Statement) -> bool) -> Option<TextRange> {
        self.block.statements.iter().find(|s| matches(s)).map(|s| file.in_file(self.index, s.range))
    }

    /// The range of the block's first statement, for a finding on the
    /// whole move; the block has one, since it moves.
    pub(crate) fn first_statement(&self, file: &FileModel) -> TextRange {
        file.in_file(self.index, self.block.statements[0].range)
    }
}

/// What may hold on either of two ways; `None` is a way no run takes.
fn join(a: Option<State>, b: Option<State>) -> Option<State> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.join(&b)),
        (a, b) => a.or(b),
    }
}

/// `entry` with everything blocks `body` may change forgotten: the state
/// at the top of a loop over them, whichever time round.
fn looped(
    mut entry: State,
    file: &FileModel,
    body: std::ops::RangeInclusive<usize>,
    variables: &Variables<'_>,
) -> State {
    for index in body {
        let mut after = entry.clone();
        after.apply(index, file.block(index), variables);
        entry = entry.join(&after);
    }
    entry
}

/// Walks `file` from reset (`main`) or from an unknown state, calling
/// `visit` at each block with the state after it, until `visit` breaks.
///
/// A jump forward hands its state to its target, which joins it with the
/// way into it; a jump back makes its target the top of a loop up to the
/// jump, as WHILE does.
pub(crate) fn walk(db: &dyn Db, file: &FileModel, main: bool, mut visit: impl FnMut(Step<'_>) -> ControlFlow<()>) {
    let model = &file.model;
    let count = file.ranges.len();
    let mut variables: Variables<'_> = model.definitions.iter().map(|d| d.declared.name.as_str()).collect();
    if let Some(proc) = model.header() {
        variables.extend(proc.declaration.parameters.iter().filter_map(|p| p.name.as_deref()));
    }
    // By block: its forward jumps' targets; by target: the last block that
    // jumps back to it.
    let mut forward: FxHashMap<usize, Vec<usize>> = FxHashMap::default();
    let mut back_from: FxHashMap<usize, usize> = FxHashMap::default();
    // Blocks a way the walk cannot follow reaches: computed targets,
    // repeated sections.
    let mut unknown_ways = vec![false; count];
    let mut computed = false;
    let mut failed = FxHashSet::default();
    for site in &model.jumps {
        let target = match site.resolved {
            Resolved::Block(target) => target,
            Resolved::Start => 0,
            Resolved::Computed => {
                computed = true;
                continue;
            }
            Resolved::NotFound { .. } | Resolved::NoTarget => {
                failed.insert((site.block, site.jump.range));
                continue;
            }
        };
        if target > site.block {
            forward.entry(site.block).or_default().push(target);
        } else {
            let last = back_from.entry(target).or_insert(site.block);
            *last = (*last).max(site.block);
        }
    }
    if computed {
        for &block in model.labels.values().flatten().chain(model.block_numbers.blocks()) {
            unknown_ways[block] = true;
        }
    }
    // Without MCALL in the file, no modal call is ever in force.
    let mut modal_calls = false;
    for statement in file.blocks(db).flat_map(|block| &block.statements) {
        match &statement.kind {
            StatementKind::RepeatSection { start, .. } => {
                for &target in model.labels.get(start).into_iter().flatten() {
                    unknown_ways[target] = true;
                }
            }
            StatementKind::ModalCall(_) => modal_calls = true,
            _ => {}
        }
    }
    let mut opens: FxHashMap<usize, &Structure> = FxHashMap::default();
    let mut middles: FxHashMap<usize, &Structure> = FxHashMap::default();
    let mut closes: FxHashMap<usize, &Structure> = FxHashMap::default();
    for structure in &model.structures {
        opens.insert(structure.start, structure);
        if let Some(middle) = structure.middle {
            middles.insert(middle, structure);
        }
        closes.insert(structure.end, structure);
    }
    let unknown = || {
        let mut state = State::unknown();
        if !modal_calls {
            state.modal_call = Known::Is(None);
        }
        state
    };
    // By a structure's start: for an IF the state of the way not taken,
    // for a loop the state it ends with.
    let mut saved: FxHashMap<usize, Option<State>> = FxHashMap::default();
    // By target: the states forward jumps bring.
    let mut arriving: FxHashMap<usize, State> = FxHashMap::default();
    let mut way = Some(if main { State::at_reset() } else { State::subprogram_start() });
    for (index, block) in file.blocks(db).enumerate() {
        if unknown_ways[index] {
            way = Some(unknown());
        }
        way = join(way, arriving.remove(&index));
        if let Some(&last) = back_from.get(&index) {
            way = Some(looped(way.unwrap_or_else(unknown), file, index..=last, &variables));
        }
        if let Some(structure) = middles.get(&index)
            && let Some(other) = saved.get_mut(&structure.start)
        {
            std::mem::swap(&mut way, other);
        }
        if let Some(structure) = closes.get(&index)
            && let Some(other) = saved.remove(&structure.start)
        {
            way = join(way, other);
        }
        if let Some(structure) = opens.get(&index)
            && structure.kind != StructureKind::If
        {
            way = way.map(|entry| looped(entry, file, structure.start..=structure.end, &variables));
            if matches!(structure.kind, StructureKind::While | StructureKind::For) {
                saved.insert(structure.start, way.clone());
            }
        }
        let reached = way.is_some();
        let mut state = way.unwrap_or_else(unknown);
        let from = state.position;
        let moves = state.apply(index, block, &variables);
        if visit(Step { index, block, from, state: &state, moves, reached, opens: opens.get(&index).copied() })
            .is_break()
        {
            return;
        }
        if let Some(structure) = opens.get(&index)
            && structure.kind == StructureKind::If
        {
            saved.insert(structure.start, reached.then(|| state.clone()));
        }
        if reached {
            for &target in forward.get(&index).into_iter().flatten() {
                let brought = join(arriving.remove(&target), Some(state.clone()));
                arriving.extend(brought.map(|brought| (target, brought)));
            }
        }
        way = (reached && !ends_way(block, index, &failed)).then_some(state);
    }
}
