//! The Haas lathe interpreter: the modal state, motion and time of the
//! file's first program, block by block, in the order the control runs
//! them, with the programs it calls.
//!
//! What runs:
//! - Motion: G00 (the slowest axis at its own rapid rate, lathe manual
//!   §5.8 (001:543-547)), G01, arcs G02/G03 by R (negative for more than
//!   180°) or by I/K (I a radius, both incremental from the start), G02
//!   turning clockwise seen with +Z to the right and +X up (lathe manual
//!   §5.8 (001:591-668)). X and U are diameters, Z and W lengths; U and W
//!   count from the last position and mix with X and Z in one block
//!   (lathe manual §5.4 (001:480-555)).
//! - Coordinates (module `coordinates`): the work offsets G54–G59 and
//!   G110–G129 of the machine's table or as G10 writes them, the local
//!   shift G52, moves in machine coordinates G53 and the reference point
//!   returns G28 and G29.
//! - The skip move G31 as a feed move to its end point: the run has no
//!   skip input, so the move takes the longest it can.
//! - Tool-nose radius compensation G41/G42/G40 (module `nose`) with the
//!   nose radius and tip of the offset T selects, in the passes along the
//!   contour of G70–G73 too.
//! - Feed and spindle: F per revolution (G99) or per minute (G98), S in
//!   rpm (G97) or m/min of cutting speed (G96), the speed limit G50 S,
//!   the spindle M03/M04/M05, dwell G04 P (ms without a decimal point,
//!   seconds with one, lathe manual §5.3 (001:55-71)), exact stop G09 and
//!   G61/G64; each step records the rpm the spindle is commanded to
//!   ([`Step::spindle`]), for the velocity model's spindle run-up.
//! - The path's modes of Haas's documentation (not in the manual, which
//!   names the codes only, 001:232, 001:279), held until changed: the
//!   corner tolerance of G187 (E, or the smoothness level P1–P3, or
//!   without either Setting 85) and the look-ahead limit of G103 P (P1:
//!   every junction stops, as unjoined blocks do); their figures and
//!   model are `super::dynamics`'s.
//! - The canned cycles as moves of their block ([`super::cycles`],
//!   [`super::roughing`]): thread cutting G32; the box cycles G90, G92,
//!   G94, modal, repeated by each block that moves; G70–G73 over the P..Q
//!   contour, the run going on after the Q block once a roughing cycle has
//!   run (lathe manual §6.9 item 8, inferred there) and after the block of
//!   G70; G74–G76; the drilling and tapping cycles G81–G89, G184 at every
//!   block that moves while one is in force, until G80, G00 or G01.
//! - Subprograms and macro calls (module `calls`): M97, M98 (a program of
//!   the file, or of a file beside it that the run's [`Environment`]
//!   finds), M99 and G65 with its arguments, each with its repeat count L.
//! - Macro statements through [`super::eval`]: assignments, `IF … GOTO`,
//!   `IF … THEN`, `GOTO`, `WHILE … DOn` … `ENDn`; the step budget bounds
//!   the loops.
//! - M00/M01 stops, M02/M30 end the run; T changes the tool and selects
//!   its offset; other M functions are counted.
//!
//! A run into a sink hands on each step once no later block can change it:
//! all but the last one or few that tool-nose radius compensation may still
//! change, a batch at a time. It takes the checkpoints the sink asks for
//! before blocks of the main program that it has not gone past yet, so that
//! every step before a checkpoint is of a block before it: outside calls,
//! before a call of a subprogram written after the main program or of
//! another file, and without compensation in force; and resumes from them.
//! Not before a block where a cycle after it reads a contour before it (G70
//! after the contour G71 went past), and a later pass of a loop takes none:
//! the text before such a block would decide the run after it. A
//! checkpoint's course includes the block numbers before it, which `GOTO`,
//! M97 and M99 P look up, and the text of the blocks the run jumped over,
//! which a later jump may run.
//!
//! The modal state is the catalogue's: every group starts at its default
//! (G01, G18, G21, G40, G54, G64, G80, G97, G99, M05, …) and a modal code
//! replaces its group's.
//!
//! Everything else is reported once per kind as not run yet and moves
//! nothing, so that a total never silently leaves work out: live-tool
//! tapping G95, inch units G20, mirror image G101, tool-nose radius
//! compensation in the cycles that have no pass along a contour, corner
//! chamfers and angles on G01 (and in the contour of G70 and G73; the
//! roughing of G71 and G72 ignores them).
//!
//! Assumptions the manual does not settle:
//! - A step's X is the radius, as CNC8x6 keeps it under diameter
//!   programming ([`Trace::diameter_axis`] is X): the program's X50. is 25
//!   in the geometry, lengths and times.
//! - Arcs lie in the plane (Z, X), so that clockwise in it is clockwise
//!   with +Z to the right and +X up.
//! - Under G96 the rpm is 1000·Vc/(π·D), at most the G50 limit, and
//!   follows the diameter along a line (the time is its integral); along an
//!   arc it is the one at the mean diameter. The limit holds under G97 too.
//!   The machine's own spindle maximum is not modelled.
//! - F is the lead of G32, G92 and G76 under G98 as under G99 (the manual:
//!   "F = feed per revolution = thread pitch", §6.8 (001:1490)).
//! - A cycle changes no modal state but its own (the box cycles' target,
//!   the drilling words) and the spindle G84/G184 switch on; the modes of
//!   the contour's blocks stay with them.
//! - G64, the default, joins blocks continuously; G09 and G61 stop exactly.
//! - Under G96 the control commands, as a rapid move or a block without
//!   a cut starts, the rpm of the diameter where it ends; a cut commands
//!   the rpm of its start and follows the diameter to its end.
//! - A G187 or G103 word the control cannot take (a P other than 1–3, an
//!   E not above 0; a negative or fractional G103 P; a P in a block of
//!   both, which could be either's) stops the run, as an alarm would.
//! - A computed dwell P (`P#1`) counts in ms, as a literal without a point.
//! - A word whose variable is vacant is left out (Fanuc convention).
//! - Block delete `/` is off: the blocks run.
//! - `GOTO n` goes to the first block numbered n in the program.
//! - T is recorded as written (`T101`: tool 1, offset 1); its last two
//!   digits select the offset (`Txxyy`, lathe manual §7.1 (001:825-826)),
//!   so that `T1` selects offset 1.

use std::{
    f64::consts::TAU,
    ops::{Deref, Range},
    sync::Arc,
};

use ncc_syntax::{Dialect, Parse, TextRange};

use super::{
    cycles::Point,
    dynamics,
    eval::{EvalError, MacroValue, Variables},
    lower::{Expr, ExprKind, HaasBlock, Statement, Value, Word, block_nodes},
    modes::Modes,
    program::{Contour, Program, ProgramModel},
};
use crate::{
    arc::{CircleArc, OffCircle, centre_by_radius, circle_through},
    compensation::Side,
    compensation_driver::Driver,
    known::Known,
    lowered::Lowered,
    machine::MachineConfig,
    trace::{
        Axes, Called, Checkpoint, DELIVERY_BATCH, Environment, Finding, Motion, Path, PathMode, Position, Resumable,
        RunRule, Step, StepSink, Stop, Tool, Trace, Undelivered, covers, fold, goes_on, merged, round3, slot,
    },
    transform::{Frame, by_letter, over_axes},
};

pub(crate) use coordinates::reset_frame;

/// The catalogue's groups the interpreter reads.
const MOTION: &str = "G1";
const DRILLING: &str = "G9";
const FEED_MODE: &str = "G10";
const SPEED_MODE: &str = "G12S";
const EXACT_STOP: &str = "G13";
const SPINDLE: &str = "M2";

/// Runs the first program of `text` on `machine` for at most `budget`
/// blocks, reading the programs it calls from other files through `files`,
/// from its start or from `checkpoint`, and handing the steps to `sink` as
/// they are final when there is one.
pub(crate) fn run_in(
    text: &str,
    lowered: Option<&Arc<Unit>>,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    mut sink: Option<&mut dyn StepSink>,
    checkpoint: Option<&Checkpoint>,
) -> Trace {
    let unit = lowered.cloned().unwrap_or_else(|| Arc::new(Unit::read(text)));
    let mut interpreter = Interpreter::new(Arc::new(machine.clone()), files, text, unit);
    let start = checkpoint.and_then(|checkpoint| interpreter.resume(checkpoint));
    interpreter.run(budget, start, sink.as_deref_mut());
    interpreter.end_compensation();
    if let Some(sink) = sink {
        interpreter.deliver(sink, true);
    }
    let (tool_centre, compensated) = interpreter.compensation.into_parts();
    Trace {
        axes: machine.step_axes().to_vec(),
        diameter_axis: Some(b'X'),
        reset_frame: reset_frame(machine),
        frames: interpreter.frames,
        tool_centre,
        compensated,
        messages: Vec::new(),
        steps: interpreter.steps.steps,
        findings: interpreter.findings,
        tools: interpreter.tools,
        files: interpreter.called,
        blocks_run: interpreter.executed,
        written: Vec::new(),
    }
}

/// One file of a run, lowered: the program's (source 0) or one that a
/// call read. The editor's analysis keeps the program's between edits and
/// hands it to the run of the same text.
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    pub blocks: Lowered<HaasBlock>,
    pub model: ProgramModel,
}

/// A unit is its blocks, with the program model beside them.
impl Deref for Unit {
    type Target = Lowered<HaasBlock>;

    fn deref(&self) -> &Lowered<HaasBlock> {
        &self.blocks
    }
}

impl Unit {
    pub fn read(text: &str) -> Unit {
        let parse = Parse::new(text, Dialect::HaasLathe);
        // Sized first (the root's runs hold the blocks): a large file's
        // blocks were copied again and again as the vectors grew.
        let runs = parse.green().children().filter_map(rowan::NodeOrToken::into_node);
        let most = runs.map(|run| run.children().len()).sum();
        let (mut ranges, mut blocks) = (Vec::with_capacity(most), Vec::with_capacity(most));
        for (range, block) in block_nodes(parse.green()) {
            ranges.push(range);
            blocks.push(HaasBlock::lower(block));
        }
        let model = ProgramModel::new(blocks.as_slice());
        Unit { blocks: Lowered::whole(blocks, ranges), model }
    }

    /// The contour of the cycle in block `cycle`.
    fn contour(&self, cycle: usize) -> Option<&Contour> {
        self.model.contours().find(|contour| contour.cycle == cycle)
    }
}

/// Where a block is: its file (as [`Step::source`]), the program in that
/// file ([`ProgramModel::programs`]) and the block's index in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Place {
    source: usize,
    program: usize,
    block: usize,
}

/// Which block runs after one.
enum Flow {
    Next,
    /// A block of the same program.
    Jump(usize),
    /// Into a call, or back from one.
    Go(Place),
    End,
}

/// A block's move, before it becomes a step.
#[derive(Clone, PartialEq)]
struct Moved {
    motion: Motion,
    path: Path,
    length: f64,
    duration: f64,
    feed: Option<f64>,
}

const STILL: Moved = Moved { motion: Motion::None, path: Path::Straight, length: 0.0, duration: 0.0, feed: None };

/// What a block's step records besides its move.
#[derive(Default)]
struct Facts {
    stop: Option<Stop>,
    exact: bool,
    m_functions: u8,
    tool_change: bool,
    /// The tool-nose radius compensation its move runs with.
    nose: Option<Side>,
    /// A G53 block: it ends in machine coordinates.
    machine: bool,
}

/// The run between two blocks of the main program outside calls, which a
/// [`Checkpoint`] keeps: the modal state, the position and frames, the
/// variables, the cycles' words, the offset and feed in force.
#[derive(Clone)]
struct Resumed {
    machine: Arc<MachineConfig>,
    modes: Modes,
    variables: Variables,
    position: Position,
    frames: Vec<Frame>,
    frame: usize,
    coordinates: coordinates::Coordinates,
    offset: u8,
    feed: Option<f64>,
    speed: f64,
    speed_limit: Option<f64>,
    corner_tolerance: f64,
    look_ahead: u32,
    last_rpm: f32,
    cycles: canned::CycleState,
    reported: Vec<String>,
    /// What the run after the checkpoint may read of the text before it,
    /// besides the blocks it ran, which a run revisiting them shows in its
    /// steps: the block numbers, which `GOTO`, M97, M99 P and contours look
    /// up, and the text of the blocks it went past without running them.
    before: u64,
    /// Steps made before it.
    steps: usize,
}

impl Resumable for Resumed {
    fn steps(&self) -> usize {
        self.steps
    }

    fn set_steps(&mut self, steps: usize) {
        self.steps = steps;
    }

    fn same_course(&self, other: &Resumed) -> bool {
        // Every field named, so that a new one must be placed here.
        let Resumed {
            machine,
            modes,
            variables,
            position,
            frames,
            frame,
            coordinates,
            offset,
            feed,
            speed,
            speed_limit,
            corner_tolerance,
            look_ahead,
            last_rpm,
            cycles,
            reported,
            before,
            steps: _,
        } = self;
        **machine == *other.machine
            && *modes == other.modes
            && *variables == other.variables
            && *position == other.position
            && *frames == other.frames
            && *frame == other.frame
            && *coordinates == other.coordinates
            && *offset == other.offset
            && *feed == other.feed
            && *speed == other.speed
            && *speed_limit == other.speed_limit
            && *corner_tolerance == other.corner_tolerance
            && *look_ahead == other.look_ahead
            && *last_rpm == other.last_rpm
            && *cycles == other.cycles
            && *reported == other.reported
            && *before == other.before
    }
}

/// The blocks of `unit` before which a run takes no checkpoint because a
/// cycle after them reads a contour that starts before them (G70 after
/// the contour G71 skipped): the text before such a checkpoint would
/// decide the run after it. Sorted and apart.
fn contours_read_back(unit: &Unit) -> Vec<Range<usize>> {
    let spans = unit
        .model
        .contours()
        .filter(|contour| *contour.blocks.start() < contour.cycle)
        .map(|contour| contour.blocks.start() + 1..contour.cycle + 1)
        .collect();
    merged(spans)
}

struct Interpreter<'a> {
    machine: Arc<MachineConfig>,
    /// Where the programs that calls name are read from.
    files: &'a dyn Environment,
    /// The program's text.
    text: &'a str,
    /// The files of the run: the program's, then those calls read, in the
    /// order of [`Interpreter::called`].
    units: Vec<Arc<Unit>>,
    called: Vec<Called>,
    /// The file of the block being run.
    source: usize,
    /// The calls being run, the innermost last.
    calls: Vec<calls::Call>,
    modes: Modes,
    variables: Variables,
    /// Program coordinates in the frame in force, X as a radius.
    position: Position,
    /// The frames of the steps, and the one in force.
    frames: Vec<Frame>,
    frame: usize,
    coordinates: coordinates::Coordinates,
    /// The tool offset T selects.
    offset: u8,
    /// Tool-nose radius compensation in force, the tool path it made, and
    /// the steps it ran over.
    compensation: Driver,
    /// F as written: mm/rev or mm/min by the feed mode.
    feed: Option<f64>,
    /// S as written: rpm under G97, m/min under G96.
    speed: f64,
    /// G50 S.
    speed_limit: Option<f64>,
    /// The corner tolerance in mm (Setting 85, or G187's), and the blocks
    /// the control reads ahead, G103 P (0: no limit).
    corner_tolerance: f64,
    look_ahead: u32,
    /// The rpm the last step ended with ([`Step::spindle`]).
    last_rpm: f32,
    steps: Undelivered,
    findings: Vec<Finding>,
    tools: Vec<Tool>,
    executed: usize,
    /// Keys of what was reported once.
    reported: Vec<String>,
    /// A finding the control stops on was made.
    stopped: bool,
    cycles: canned::CycleState,
    /// One past the furthest block of the main file run, and what a run
    /// after it may read of the text before it ([`Resumed::before`]).
    reached: usize,
    before: u64,
}

impl<'a> Interpreter<'a> {
    fn new(machine: Arc<MachineConfig>, files: &'a dyn Environment, text: &'a str, unit: Arc<Unit>) -> Self {
        let corner_tolerance = dynamics::corner_rounding(&machine);
        let mut interpreter = Interpreter {
            machine,
            files,
            text,
            units: vec![unit],
            called: Vec::new(),
            source: 0,
            calls: Vec::new(),
            modes: Modes::at_reset(Dialect::HaasLathe.catalogue()),
            variables: Variables::at_power_on(),
            position: [0.0; 26],
            frames: Vec::new(),
            frame: 0,
            coordinates: coordinates::Coordinates::default(),
            offset: 0,
            compensation: Driver::default(),
            feed: None,
            speed: 0.0,
            speed_limit: None,
            corner_tolerance,
            look_ahead: 0,
            last_rpm: 0.0,
            steps: Undelivered::default(),
            findings: Vec::new(),
            tools: Vec::new(),
            executed: 0,
            reported: Vec::new(),
            stopped: false,
            cycles: canned::CycleState::default(),
            reached: 0,
            before: 0,
        };
        interpreter.start_coordinates();
        interpreter
    }

    /// Runs the file's first program for at most `budget` blocks, with the
    /// programs it calls, from its start or from `start`; hands `sink` the
    /// steps as they are final and the checkpoints it asks for.
    fn run(&mut self, budget: usize, start: Option<Place>, mut sink: Option<&mut (dyn StepSink + '_)>) {
        let Some(first) = self.units[0].model.programs.first() else { return };
        let mut place = start.unwrap_or(Place { source: 0, program: 0, block: first.blocks.start });
        self.reached = self.reached.max(first.blocks.start);
        let read_back = contours_read_back(&self.units[0]);
        loop {
            let unit = Arc::clone(&self.units[place.source]);
            let program = &unit.model.programs[place.program];
            self.source = place.source;
            if !program.blocks.contains(&place.block) {
                self.ran_off(place, &unit);
                return;
            }
            // A block of the main file the run has not gone past yet, in
            // the main program or in a call.
            let fresh = place.source == 0 && place.block >= self.reached;
            if fresh {
                self.pass_to(place.block);
            }
            if let Some(sink) = sink.as_deref_mut()
                && fresh
                && self.calls.is_empty()
                && self.called.is_empty()
                && !self.compensation.is_active()
                && !covers(&read_back, place.block)
                && sink.checkpoint_wanted(place.block, unit.ranges[place.block].start())
            {
                self.deliver(sink, false);
                let offset = unit.ranges[place.block].start();
                let checkpoint =
                    Checkpoint { state: Box::new(self.resumed()), block: place.block, offset, executed: self.executed };
                if sink.checkpoint(checkpoint).is_break() {
                    return;
                }
            }
            if fresh {
                self.before = fold(self.before, (0u8, unit.block(place.block).number.and_then(|n| n.value)));
                self.reached = place.block + 1;
            }
            if self.executed >= budget {
                let message = format!("the run went past its budget of {budget} blocks");
                self.finding(RunRule::StepBudget, unit.ranges[place.block], &message);
                return;
            }
            self.executed += 1;
            if !goes_on(self.files, self.executed) {
                return;
            }
            let flow = self.block(place, program);
            if self.stopped {
                return;
            }
            place = match flow {
                Flow::Next => Place { block: place.block + 1, ..place },
                Flow::Jump(block) => Place { block, ..place },
                Flow::Go(to) => to,
                Flow::End => return,
            };
            if let Some(sink) = sink.as_deref_mut()
                && self.steps.steps.len() >= DELIVERY_BATCH
            {
                self.deliver(sink, false);
                if sink.closed() {
                    return;
                }
            }
        }
    }

    /// Hands `sink` the steps no later block can change: all at the `end`,
    /// else those before the first one tool-nose radius compensation may
    /// still change.
    fn deliver(&mut self, sink: &mut dyn StepSink, end: bool) {
        let open = self.compensation.open_step().filter(|_| !end);
        let Driver { tool_centre, compensated, .. } = &mut self.compensation;
        self.steps.deliver(sink, open, &self.frames, compensated, tool_centre);
    }

    /// Goes past the blocks of the main file from the furthest one run to
    /// `block`, which a jump, a cycle or a call has skipped.
    fn pass_to(&mut self, block: usize) {
        let unit = Arc::clone(&self.units[0]);
        for skipped in self.reached..block {
            let text = &self.text[unit.ranges[skipped]];
            self.before = fold(self.before, (1u8, unit.block(skipped).number.and_then(|n| n.value), text));
        }
        self.reached = block;
    }

    /// The state to resume from before the next block, every step before it
    /// handed on.
    fn resumed(&self) -> Resumed {
        // Every field named, so that a new one must be placed here.
        let Interpreter {
            machine,
            files: _,
            text: _,
            units: _,
            // None read: a checkpoint is taken only before the program
            // calls another file.
            called: _,
            source: _,
            calls: _,
            modes,
            variables,
            position,
            frames,
            frame,
            coordinates,
            offset,
            // None in force at a checkpoint; its path is reported by the
            // run up to the checkpoint.
            compensation: _,
            findings: _,
            tools: _,
            feed,
            speed,
            speed_limit,
            corner_tolerance,
            look_ahead,
            last_rpm,
            steps,
            executed: _,
            reported,
            stopped: _,
            cycles,
            reached: _,
            before,
        } = self;
        Resumed {
            machine: Arc::clone(machine),
            modes: modes.clone(),
            variables: variables.clone(),
            position: *position,
            frames: frames.clone(),
            frame: *frame,
            coordinates: coordinates.clone(),
            offset: *offset,
            feed: *feed,
            speed: *speed,
            speed_limit: *speed_limit,
            corner_tolerance: *corner_tolerance,
            look_ahead: *look_ahead,
            last_rpm: *last_rpm,
            cycles: cycles.clone(),
            reported: reported.clone(),
            before: *before,
            steps: steps.next(),
        }
    }

    /// Goes on from `checkpoint`, a checkpoint of a run of this program on
    /// this machine: where it resumes; `None`, to run from the start, for a
    /// checkpoint of another control or machine, or of a block this text
    /// does not have there.
    fn resume(&mut self, checkpoint: &Checkpoint) -> Option<Place> {
        let state = checkpoint.state::<Resumed>()?;
        let program = self.units[0].model.programs.first()?;
        let block = checkpoint.block;
        let here = program.blocks.contains(&block) && self.units[0].ranges[block].start() == checkpoint.offset;
        if !here || *state.machine != *self.machine {
            return None;
        }
        let Resumed {
            machine,
            modes,
            variables,
            position,
            frames,
            frame,
            coordinates,
            offset,
            feed,
            speed,
            speed_limit,
            corner_tolerance,
            look_ahead,
            last_rpm,
            cycles,
            reported,
            before,
            steps,
        } = state.clone();
        (self.machine, self.modes, self.variables, self.position) = (machine, modes, variables, position);
        (self.frames, self.frame, self.coordinates, self.offset) = (frames, frame, coordinates, offset);
        (self.feed, self.speed, self.speed_limit, self.cycles) = (feed, speed, speed_limit, cycles);
        (self.corner_tolerance, self.look_ahead, self.last_rpm) = (corner_tolerance, look_ahead, last_rpm);
        (self.reported, self.before, self.steps.delivered) = (reported, before, steps);
        (self.executed, self.reached) = (checkpoint.executed, block);
        Some(Place { source: 0, program: 0, block })
    }

    /// The run has reached the end of the program at `place` without M30,
    /// M02 or M99.
    fn ran_off(&mut self, place: Place, unit: &Unit) {
        let program = &unit.model.programs[place.program];
        if !self.calls.is_empty() {
            let last = program.blocks.end.checked_sub(1).and_then(|last| unit.ranges.get(last));
            let message = "the called program ends without M99: the control stops";
            self.finding(RunRule::MacrocycleWithoutReturn, last.copied().unwrap_or_default(), message);
        } else if let Some(&range) = unit.ranges.get(place.block).filter(|_| unit.model.programs.len() > 1) {
            self.finding(RunRule::RunsIntoSubprogram, range, "the program runs into the next one without M30 or M02");
        }
    }

    /// Runs the block at `place` of `program`: its codes, motion, macro
    /// statement, then its call or return.
    fn block(&mut self, place: Place, program: &Program) -> Flow {
        let unit = Arc::clone(&self.units[place.source]);
        let (block, range) = (&unit.block(place.block), unit.ranges[place.block]);
        if block.words.is_empty() && block.statements.is_empty() && block.corners.is_empty() {
            return Flow::Next;
        }
        if block.has_code(b'G', 65) {
            // Its other words are the macro's arguments.
            let (start, flow) = (self.position, self.macro_call(place, block, range));
            if !self.stopped {
                self.record(range, &start, STILL, Facts::default());
            }
            return flow;
        }
        if block.has_code(b'G', 103) && block.has_code(b'G', 187) && block.word(b'P').is_some() {
            let message =
                "G103 and G187 both read P: the block cannot tell whose it is; write them in blocks of their own";
            self.finding(RunRule::ValueRefused, range, message);
            return Flow::End;
        }
        let mut flow = Flow::Next;
        let (mut dwell, mut exact_stop, mut still, mut cycle, mut coordinates) = (false, false, false, None, None);
        let mut skip = false;
        for code in block.codes(b'G') {
            self.modes.set('G', code);
            match code {
                0..=3 | 32 | 80 | 90 | 92 | 94 => self.cycles.drilling = Default::default(),
                18 | 21 | 40..=42 | 50 | 54..=59 | 61 | 64 | 96..=100 | 110..=129 => {}
                103 => self.limit_look_ahead(block, range),
                187 => self.accuracy(block, range),
                4 => dwell = true,
                9 => exact_stop = true,
                20 => self.not_run("inch units G20 (the run reads mm)", range),
                10 | 28 | 29 | 52 | 53 => coordinates = Some(code),
                31 => skip = true,
                81..=89 | 184 => {}
                95 => self.not_run("live-tool rigid tapping G95", range),
                101 => self.not_run("mirror image G101", range),
                70..=76 => {
                    cycle = Some(code);
                    if (71..=73).contains(&code) {
                        let after = unit.contour(place.block).map(|contour| contour.blocks.end() + 1);
                        flow = after.map_or(Flow::Next, Flow::Jump);
                    }
                }
                _ => {
                    still = true;
                    self.not_run(&format!("G{code}"), range);
                }
            }
        }
        self.update_frame();
        // Where the block's move starts, in the frame it runs in.
        let start = self.position;
        let (mut stop, mut m_functions, mut end, mut call) = (None, 0u8, false, None);
        for code in block.codes(b'M') {
            self.modes.set('M', code);
            match code {
                0 => stop = Some(Stop::Program),
                1 => stop = Some(Stop::Optional),
                2 | 30 => end = true,
                3..=5 => {}
                97..=99 => call = Some(code),
                _ => m_functions = m_functions.saturating_add(1),
            }
        }
        if let Some(feed) = block.word(b'F').and_then(|word| self.number(word, range)) {
            self.feed = Some(feed);
        }
        if let Some(speed) = block.word(b'S').and_then(|word| self.number(word, range)) {
            if block.has_code(b'G', 50) {
                self.speed_limit = Some(speed);
            } else {
                self.speed = speed;
            }
        }
        let tool = block.word(b'T').and_then(|word| self.number(word, range)).map(|tool| tool as u32);
        if let Some(tool) = tool {
            self.offset = (tool % 100) as u8;
            if !self.tools.contains(&Tool::Number(tool)) {
                self.tools.push(Tool::Number(tool));
            }
        }
        let moved = if dwell {
            self.dwell(block, range)
        } else if let Some(code) = coordinates {
            self.coordinates(code, block, range)
        } else if let Some(code) = cycle {
            self.canned(code, place.block, block, range)
        } else if still {
            STILL
        } else if skip {
            self.skip_move(block, range)
        } else {
            self.motion(block, range)
        };
        if self.stopped {
            return Flow::End;
        }
        for statement in &block.statements {
            flow = self.statement(statement, range, place.block, program);
            if self.stopped {
                return Flow::End;
            }
        }
        if let Some(code) = call {
            flow = self.call_or_return(code, place, block, range, program);
            if self.stopped {
                return Flow::End;
            }
        }
        let facts = Facts {
            stop,
            exact: exact_stop || self.modes.get(EXACT_STOP) == Some(61),
            m_functions,
            tool_change: tool.is_some(),
            // G28, G29 and G53 run without compensation.
            nose: if coordinates.is_some() { None } else { self.nose_side() },
            machine: coordinates == Some(53),
        };
        self.record(range, &start, moved, facts);
        if end { Flow::End } else { flow }
    }

    /// Adds the block's steps, the block having started at `start`: the
    /// moves of its cycle before the last, then its own `moved`, each
    /// followed by tool-nose radius compensation.
    fn record(&mut self, range: TextRange, start: &Position, moved: Moved, facts: Facts) {
        let (frame, end) = match facts.machine {
            true => (self.frame_of([0.0; 2]), self.in_machine(&self.position)),
            false => (self.frame, self.position),
        };
        let step = Step {
            source: self.source,
            range,
            motion: moved.motion,
            path: moved.path,
            duration: moved.duration,
            length: moved.length,
            feed: moved.feed,
            end: over_axes(&end, self.machine.step_axes()),
            frame,
            stop: facts.stop,
            path_mode: match facts.exact {
                true => PathMode::ExactStop,
                false if self.look_ahead == 1 => PathMode::Stop,
                false => PathMode::Continuous,
            },
            m_functions: facts.m_functions,
            tool_change: facts.tool_change,
            dynamic_set: 1,
            mergeable: false,
            jerk_limited: false,
            // Each step's own, from where it starts and ends: below.
            spindle: [0.0; 2],
            corner_tolerance: self.corner_tolerance as f32,
        };
        // A cycle's moves run with the compensation it gives them.
        let nose = self.cycles.nose.take().unwrap_or(facts.nose);
        let mut from = [start[slot(b'Z')], start[slot(b'X')]];
        for canned::CycleStep { moved: Moved { motion, path, length, duration, feed }, end, stop, nose } in
            std::mem::take(&mut self.cycles.pending)
        {
            let (m_functions, tool_change) = (0, false);
            let to = self.plane_point(&end);
            let spindle = self.commanded_rpm(motion, from[1], to[1]);
            let moved = Step {
                motion,
                path,
                duration,
                length,
                feed,
                end,
                stop,
                m_functions,
                tool_change,
                spindle,
                ..step.clone()
            };
            self.steps.push(moved);
            self.compensate(self.steps.next() - 1, from, to, nose);
            from = to;
        }
        let to = self.plane_point(&step.end);
        let step = Step { spindle: self.commanded_rpm(step.motion, from[1], to[1]), ..step };
        self.steps.push(step);
        self.compensate(self.steps.next() - 1, from, to, nose);
    }

    /// A step end's (Z, X radius).
    fn plane_point(&self, end: &Axes) -> Point {
        let position = by_letter(end, self.machine.step_axes());
        [position[slot(b'Z')], position[slot(b'X')]]
    }

    /// G187: the corner tolerance from this block on is E's, else that of
    /// the smoothness level P, else Setting 85.
    fn accuracy(&mut self, block: &HaasBlock, range: TextRange) {
        let tolerance = block.word(b'E').and_then(|word| self.number(word, range));
        let level = block.word(b'P').and_then(|word| self.number(word, range));
        self.corner_tolerance = match (tolerance, level) {
            (Some(tolerance), _) if tolerance > 0.0 => tolerance,
            (Some(_), _) => {
                self.finding(RunRule::ValueRefused, range, "G187 E is the corner tolerance: a length above 0 mm");
                return;
            }
            (None, Some(level)) => match dynamics::smoothness_level(level) {
                Some(tolerance) => tolerance,
                None => {
                    let message = "G187 P is the smoothness level: 1 (rough), 2 (medium) or 3 (finish)";
                    self.finding(RunRule::ValueRefused, range, message);
                    return;
                }
            },
            (None, None) => dynamics::corner_rounding(&self.machine),
        };
    }

    /// G103: the control reads at most P blocks ahead from this block on;
    /// without P, or with P0, as many as it can.
    fn limit_look_ahead(&mut self, block: &HaasBlock, range: TextRange) {
        let blocks = block.word(b'P').and_then(|word| self.number(word, range)).unwrap_or(0.0);
        if blocks < 0.0 || blocks.fract() != 0.0 {
            self.finding(RunRule::ValueRefused, range, "G103 P is a number of blocks, a whole number from 0");
            return;
        }
        self.look_ahead = blocks as u32;
    }

    fn dwell(&mut self, block: &HaasBlock, range: TextRange) -> Moved {
        match block.word(b'P').and_then(|word| self.seconds(word, range)) {
            Some(duration) => Moved { motion: Motion::Dwell, duration, ..STILL },
            None => STILL,
        }
    }

    /// A dwell's P in seconds: ms without a decimal point, seconds with one
    /// (lathe manual §5.3 (001:55-71)).
    fn seconds(&mut self, word: &Word, range: TextRange) -> Option<f64> {
        let seconds_written = matches!(&word.value, Some(Value::Literal(decimal)) if decimal.has_point());
        let value = self.number(word, range)?;
        Some(if seconds_written { value } else { value / 1000.0 })
    }

    /// The block's move to its end point in the motion mode in force.
    fn motion(&mut self, block: &HaasBlock, range: TextRange) -> Moved {
        let start = self.position;
        let Some(end) = self.end_point(block, range, &start) else { return STILL };
        if let Some(code) = self.modes.get(DRILLING).filter(|&code| code != 80) {
            // The drilling cycle in force runs at the position instead.
            return self.drilling(code, block, range, &end);
        }
        let motion = self.modes.get(MOTION);
        if let Some(code @ (32 | 90 | 92 | 94)) = motion {
            return self.modal_cycle(code, block, range, &end);
        }
        self.unrun_corners(block, range, motion);
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let (from, to) = ([start[z], start[x]], [end[z], end[x]]);
        let (path, length) = match motion {
            Some(code @ (2 | 3)) => {
                let Some(arc) = self.arc(block, range, from, to, code == 3) else { return STILL };
                let path = Path::Arc { plane: (b'Z', b'X'), centre: arc.centre, clockwise: arc.sweep < 0.0 };
                (path, arc.length())
            }
            _ => (Path::Straight, (to[0] - from[0]).hypot(to[1] - from[1])),
        };
        self.position = end;
        if motion == Some(0) {
            return Moved { motion: Motion::Rapid, path, length, duration: self.rapid_seconds(from, to), feed: None };
        }
        self.feed_move(range, from, to, path, length)
    }

    /// G31: a straight feed move to the block's end point. The run has no
    /// skip input, so the move goes all the way: the longest it can take.
    fn skip_move(&mut self, block: &HaasBlock, range: TextRange) -> Moved {
        let start = self.position;
        let Some(end) = self.end_point(block, range, &start) else { return STILL };
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let (from, to) = ([start[z], start[x]], [end[z], end[x]]);
        self.position = end;
        self.feed_move(range, from, to, Path::Straight, (to[0] - from[0]).hypot(to[1] - from[1]))
    }

    /// Reports the corner words of a G01 block, which the run leaves out.
    fn unrun_corners(&mut self, block: &HaasBlock, range: TextRange, motion: Option<u32>) {
        // I and K with G40 give the direction the compensation leaves along
        // (lathe manual §7.1 (001:1058-1064)), which moves no end point.
        let letters = if block.has_code(b'G', 40) { "RA" } else { "IKRA" };
        if motion == Some(1) && (!block.corners.is_empty() || letters.bytes().any(|l| block.word(l).is_some())) {
            self.not_run("corner chamfers, roundings and angles on G01 (the line runs to its end point)", range);
        }
    }

    /// Where the block's X, U, Z and W words lead from `start`; `None` when
    /// it has none.
    fn end_point(&mut self, block: &HaasBlock, range: TextRange, start: &Position) -> Option<Position> {
        let mut end = *start;
        let mut moves = false;
        for word in &block.words {
            let (axis, incremental) = match word.letter {
                b'X' => (b'X', false),
                b'U' => (b'X', true),
                b'Z' => (b'Z', false),
                b'W' => (b'Z', true),
                _ => continue,
            };
            let Some(value) = self.number(word, range) else { continue };
            // X and U are diameters; the control counts in µm of them.
            let written = if axis == b'X' { 2.0 } else { 1.0 };
            let at = &mut end[slot(axis)];
            *at = round3(if incremental { *at * written + value } else { value }) / written;
            moves = true;
        }
        moves.then_some(end)
    }

    /// Seconds of a rapid move from `from` to `to` (Z, X radius): the
    /// slowest axis at its own rate.
    fn rapid_seconds(&self, from: [f64; 2], to: [f64; 2]) -> f64 {
        let minutes = [(b'X', to[1] - from[1]), (b'Z', to[0] - from[0])]
            .map(|(axis, delta)| delta.abs() / f64::from(self.machine.axis_rapid_rate(axis)))
            .into_iter()
            .fold(0.0, f64::max);
        minutes * 60.0
    }

    /// The arc from `from` to `to` in the plane (Z, X), radii on X; `None`
    /// after reporting an end point off its circle.
    fn arc(
        &mut self,
        block: &HaasBlock,
        range: TextRange,
        from: [f64; 2],
        to: [f64; 2],
        ccw: bool,
    ) -> Option<CircleArc> {
        let tolerance = self.machine.arc_tolerance();
        let centre = match block.word(b'R').and_then(|word| self.number(word, range)) {
            Some(radius) => match centre_by_radius(from, to, radius, ccw, tolerance) {
                Some(centre) => centre,
                None => {
                    let message = format!("no arc of radius {} mm joins the start and the end point", radius.abs());
                    self.finding(RunRule::ArcOffCircle, range, &message);
                    return None;
                }
            },
            None => {
                let mut offset = |letter| block.word(letter).and_then(|word| self.number(word, range)).unwrap_or(0.0);
                let (k, i) = (offset(b'K'), offset(b'I'));
                [from[0] + k, from[1] + i]
            }
        };
        match circle_through(from, to, centre, ccw, tolerance) {
            Ok(arc) => Some(arc),
            Err(OffCircle { start_radius, end_radius }) => {
                let message = format!(
                    "the end point does not lie on the circle: {} mm from the centre, the start {} mm, more than the tolerance {tolerance} mm apart",
                    round3(end_radius),
                    round3(start_radius)
                );
                self.finding(RunRule::ArcOffCircle, range, &message);
                None
            }
        }
    }

    /// A feed move of `length` mm from `from` to `to` (Z, X radius) along
    /// `path`.
    fn feed_move(&mut self, range: TextRange, from: [f64; 2], to: [f64; 2], path: Path, length: f64) -> Moved {
        let minutes = self.feed_minutes(range, from, to, length, path == Path::Straight);
        // Per minute the path feed is F itself, not F back from the time.
        let per_minute = self.feed.filter(|_| self.modes.get(FEED_MODE) == Some(98));
        let (duration, feed) =
            minutes.map_or((0.0, None), |minutes| (minutes * 60.0, per_minute.or(Some(length / minutes))));
        Moved { motion: Motion::Feed, path, length, duration, feed }
    }

    /// Minutes of a feed move of `length` mm from `from` to `to` (Z, X
    /// radius), along a line or an arc; `None` after reporting why the axes
    /// cannot move. Under G96 the rpm follows the radius up to the G50
    /// limit: exactly along a line, at the mean radius along an arc.
    fn feed_minutes(&mut self, range: TextRange, from: [f64; 2], to: [f64; 2], length: f64, line: bool) -> Option<f64> {
        let Some(feed) = self.feed.filter(|&feed| feed > 0.0) else {
            self.finding(
                RunRule::MotionWithoutFeed,
                range,
                "no feed F programmed before this motion: G01–G03 need one",
            );
            return None;
        };
        if self.modes.get(FEED_MODE) == Some(98) {
            return Some(length / feed);
        }
        let rpm = self.spindle_rpm(range, (from[1] + to[1]) / 2.0)?;
        if line && self.modes.get(SPEED_MODE) == Some(96) {
            let limit = self.speed_limit.unwrap_or(f64::INFINITY);
            return Some(turning_minutes(length, [from[1], to[1]], 1000.0 * self.speed / TAU, limit) / feed);
        }
        Some(length / (feed * rpm))
    }

    /// The spindle's rpm at `radius`: 0 when it stands, S under G97, the
    /// cutting speed S (m/min) over the circumference under G96 (infinite
    /// at the centre without a limit), at most the G50 limit.
    fn rpm_at(&self, radius: f64) -> f64 {
        let spindle_on = matches!(self.modes.get(SPINDLE), Some(3 | 4));
        let limit = self.speed_limit.unwrap_or(f64::INFINITY);
        match self.modes.get(SPEED_MODE) {
            _ if !spindle_on => 0.0,
            Some(96) => (1000.0 * self.speed / (TAU * radius.abs())).min(limit),
            _ => self.speed.min(limit),
        }
    }

    /// The rpm the control commands as a `motion` from radius `from` to
    /// `to` starts and ends, negative under M04 ([`Step::spindle`]): a
    /// cut's follows the radius, any other step's is the one at its end.
    /// Where G96 has no limit at the centre the rpm stays as it was.
    fn commanded_rpm(&mut self, motion: Motion, from: f64, to: f64) -> [f32; 2] {
        let sign = if self.modes.get(SPINDLE) == Some(4) { -1.0 } else { 1.0 };
        let last = self.last_rpm;
        let at = |radius: f64| {
            let rpm = self.rpm_at(radius);
            if rpm.is_finite() { (sign * rpm) as f32 } else { last }
        };
        let rpm = match motion {
            Motion::Feed => [at(from), at(to)],
            _ => [at(to); 2],
        };
        self.last_rpm = rpm[1];
        rpm
    }

    /// The spindle's rpm at `radius` ([`Interpreter::rpm_at`]); `None`
    /// after reporting a spindle that does not turn.
    fn spindle_rpm(&mut self, range: TextRange, radius: f64) -> Option<f64> {
        let rpm = self.rpm_at(radius);
        if !rpm.is_finite() {
            self.not_run("constant cutting speed G96 at the spindle's centre without a G50 limit", range);
            return None;
        }
        if rpm <= 0.0 {
            let message =
                "feed per revolution (G99) or a thread with the spindle stopped or at S0: the axes cannot move";
            self.finding(RunRule::MotionWithoutFeed, range, message);
            return None;
        }
        Some(rpm)
    }

    fn statement(&mut self, statement: &Statement, range: TextRange, at: usize, program: &Program) -> Flow {
        match statement {
            Statement::Assign { target, value, .. } => {
                if let Err(error) = self.variables.assign(target, value) {
                    self.eval_failed(error, range);
                }
                Flow::Next
            }
            Statement::If { condition, then, .. } => match (self.condition(condition, range), then) {
                (true, Some(then)) => self.statement(then, range, at, program),
                _ => Flow::Next,
            },
            Statement::Goto { target, .. } => self.goto(target, range, program),
            Statement::LoopStart { condition, .. } => {
                let Some(end) = program.loop_end(at) else {
                    self.finding(RunRule::CallTargetMissing, range, "no END with the loop's number after its DO");
                    return Flow::End;
                };
                // `DOn` without WHILE loops for ever.
                let runs = condition.as_ref().is_none_or(|condition| self.condition(condition, range));
                if runs { Flow::Next } else { Flow::Jump(end + 1) }
            }
            Statement::LoopEnd { .. } => match program.loop_start(at) {
                Some(start) => Flow::Jump(start),
                None => {
                    self.finding(RunRule::CallTargetMissing, range, "no DO with the loop's number before its END");
                    Flow::End
                }
            },
        }
    }

    fn goto(&mut self, target: &Expr, range: TextRange, program: &Program) -> Flow {
        let number = match self.variables.eval(target) {
            Ok(Known::Is(MacroValue::Number(value))) if value >= 0.0 => value.round() as u64,
            Ok(Known::Unknown) => {
                self.unknown(range);
                return Flow::End;
            }
            Ok(_) => {
                self.finding(RunRule::CallTargetMissing, range, "GOTO names no block number");
                return Flow::End;
            }
            Err(error) => {
                self.eval_failed(error, range);
                return Flow::End;
            }
        };
        match program.block_numbers.get(&number).and_then(|blocks| blocks.first()) {
            Some(&block) => Flow::Jump(block),
            None => {
                self.finding(
                    RunRule::CallTargetMissing,
                    range,
                    &format!("no block N{number} in this program to go to"),
                );
                Flow::End
            }
        }
    }

    /// A condition's truth; an unknown one is reported and taken as false.
    fn condition(&mut self, condition: &Expr, range: TextRange) -> bool {
        match self.variables.condition(condition) {
            Ok(Known::Is(truth)) => truth,
            Ok(Known::Unknown) => {
                self.unknown(range);
                false
            }
            Err(error) => {
                self.eval_failed(error, range);
                false
            }
        }
    }

    /// A word's value; `None` when it has none (vacant, unknown, or an
    /// error reported).
    fn number(&mut self, word: &Word, range: TextRange) -> Option<f64> {
        match self.word_value(word, range)? {
            Known::Is(MacroValue::Number(value)) => Some(value),
            Known::Is(MacroValue::Vacant) => None,
            Known::Unknown => {
                self.unknown(range);
                None
            }
        }
    }

    /// A word's value as the variables hold it; `None` when it has none
    /// written or after reporting an error.
    fn word_value(&mut self, word: &Word, range: TextRange) -> Option<Known<MacroValue>> {
        let (negative, value) = match word.value.as_ref()? {
            Value::Literal(decimal) => return Some(Known::Is(MacroValue::Number(decimal.to_f64()))),
            Value::Variable { negative, index } => {
                let variable = Expr { kind: ExprKind::Variable(Box::new(index.clone())), range: index.range };
                (*negative, self.variables.eval(&variable))
            }
            Value::Bracket { negative, expr } => (*negative, self.variables.eval(expr)),
        };
        match value {
            Ok(Known::Is(MacroValue::Number(value))) if negative => Some(Known::Is(MacroValue::Number(-value))),
            Ok(value) => Some(value),
            Err(error) => {
                self.eval_failed(error, range);
                None
            }
        }
    }

    fn unknown(&mut self, range: TextRange) {
        let message = "a variable whose value the run does not know (system variables, the kept commons #500–#699): what uses it is left out";
        self.report_once(RunRule::ParameterUnknown, "unknown variable", range, message);
    }

    fn eval_failed(&mut self, error: EvalError, range: TextRange) {
        let message = match error {
            EvalError::DivisionByZero { .. } => "a division by zero".to_owned(),
            EvalError::OutOfDomain { function, .. } => format!("{function:?} of a value outside its domain"),
            EvalError::NoSuchVariable { number, .. } => format!("there is no macro variable #{number}"),
            EvalError::VacantVariableNumber { .. } => "a variable number from a vacant variable".to_owned(),
            EvalError::ReadOnlyVariable { number, .. } => format!("#{number} cannot be written"),
            EvalError::Malformed { .. } => "a malformed expression".to_owned(),
        };
        self.finding(RunRule::ArithmeticFailed, range, &format!("{message}: the control stops"));
    }

    fn not_run(&mut self, what: &str, range: TextRange) {
        let message = format!("the executor does not run {what} yet: the time leaves them out");
        self.report_once(RunRule::NotRunYet, what, range, &message);
    }

    fn report_once(&mut self, rule: RunRule, key: &str, range: TextRange, message: &str) {
        if !self.reported.iter().any(|done| done == key) {
            self.reported.push(key.to_owned());
            self.finding(rule, range, message);
        }
    }

    fn finding(&mut self, rule: RunRule, range: TextRange, message: &str) {
        self.stopped |= rule.stops();
        self.findings.push(Finding { rule, source: self.source, range, message: message.to_owned() });
    }
}

/// Minutes of a line `length` mm long from radius `radii[0]` to `radii[1]`
/// at 1 mm per revolution, the spindle at min(`k`/|r|, `limit`) rpm (G96):
/// the integral of max(|r|/k, 1/limit) along the line, the radius changing
/// linearly.
fn turning_minutes(length: f64, [from, to]: [f64; 2], k: f64, limit: f64) -> f64 {
    // The radius under which the limit holds.
    let clamp = k / limit;
    let per_mm = |r: f64| (r.abs() / k).max(1.0 / limit);
    // The integral of `per_mm` from 0 to r.
    let integral = |r: f64| {
        let a = r.abs();
        let part = if a <= clamp { a / limit } else { clamp / limit + (a * a - clamp * clamp) / (2.0 * k) };
        part.copysign(r)
    };
    if (to - from).abs() < 1e-9 {
        length * per_mm(from)
    } else {
        length * (integral(to) - integral(from)) / (to - from)
    }
}

mod calls;
mod canned;
mod coordinates;
mod nose;
#[cfg(test)]
mod tests;
