//! Running a CNC8x6 program: the modal state, motion and time, block by
//! block, in the order the control runs them.
//!
//! What runs:
//! - The program's flow: subprogram calls G71 L Q and macrocycle files
//!   G72 L Q with their repetitions, jumps G73 L Q that run a section Q+1
//!   times, codes from parameters (`GR20`: 73 jumps, 78 does nothing), G04
//!   taking Q from a call in its block, M00/M01 stops, M02/M30, and a step
//!   budget against endless loops.
//! - Motion: G00, G01, arcs and helices G02/G03 (the centre from I/J/K, the
//!   plane from the two axes written, 01 §6.4; the helix's lead from G10
//!   under G09, 02 §4), threads G33, G90/G91.
//! - Feed and spindle: the modal machine of every group ([`Modes`]), F
//!   with its decimal-point rules per minute or per revolution and M37's
//!   1 : 100, S, constant cutting speed G96/G97 with the G76 limit, dwell
//!   (G04 Q, in 10 ms, after the block's motion).
//! - Parameters: assignments and arithmetic G26–G29 take effect after the
//!   block's motion, which reads the values from before them.
//! - Fixed cycles G81–G89 after the block's motion until G80: the bodies of
//!   the machine's cycle file with the state restored afterwards, or the
//!   built-in cycles ([`crate::cycles`]).
//!
//! - Offsets: zero offsets G53–G59 with G92/G93, length corrections D/&,
//!   and radius compensation G41/G42 ([`crate::compensation`]).
//!
//! - Coordinates: diameter programming G74/G75 on the machine's diameter
//!   axis (positions are radii), the recalculations G34–G37 and the
//!   transformations G38/G39/G31 ([`crate::transform`]).
//!
//! Where the control stops on an error, the run stops with a fatal
//! [`Finding`]: a value its address cannot take ([`crate::formats`]), a
//! position beyond an axis's range or the machine's travel limits, an arc
//! end point off its circle, a call, jump, cycle or arithmetic that cannot
//! run.
//!
//! A block's time is its path length over its feed (G00: the slowest axis
//! at its own rapid rate), plus dwells; ramps and block joining are the
//! velocity model's business. Everything else the control does is reported
//! once per kind as not run yet (copying G05–G07, axis slaving G08, the
//! reference point G30), so that a total never silently leaves something
//! out.

use std::{
    borrow::Cow,
    ops::{ControlFlow, Range},
    sync::{
        atomic::{AtomicBool, Ordering},
        mpsc::{self, Receiver},
    },
    thread::{Scope, ScopedJoinHandle},
};

use nalgebra::{Point2, Vector2};
use ncc_catalog::{AddressRole, Catalogue, Dialect};
use ncc_syntax::{TextRange, TextSize};
use rowan::GreenNode;
use smallvec::SmallVec;

use crate::{
    arith::{self, BlockArithmetic, Machine, Message, Parameters, Raw},
    compensation::{CompensationError, Compensator, Element, Settings, Side, ToolElement},
    cycles::{self, CycleError, CycleInput, CycleKind, CycleStep, Spindle},
    formats::{self, PlainLiterals},
    lower::{BlockData, BlockReader, PlainReader, Value, Word},
    machine::MachineConfig,
    modes::{Group, Modes},
    program_flow::{self, BlockFlow, JumpCounts, block_flow, whole_number},
    tables::{OffsetTable, ToolEntry, ToolTable},
    transform::{self, Frame, Kind, Recalculation, Refused, Transformation, Transformations},
};

/// Axes by letter (index = letter − `A`); positions in mm (degrees for
/// rotary axes).
pub type Position = [f64; 26];

/// What a block did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// No motion, no time.
    None,
    Rapid,
    Feed,
    Dwell,
}

/// What a run adds up to.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Totals {
    /// Seconds from the program's start to its end.
    pub total_time: f64,
    /// The same at the programmed feeds: the steps' own durations.
    pub programmed_time: f64,
    /// Seconds and mm by [`Motion`].
    time: [f64; 4],
    length: [f64; 4],
    /// M00 and M01 stops.
    pub program_stops: usize,
    pub optional_stops: usize,
}

impl Totals {
    /// Seconds spent in blocks of one kind.
    pub fn time(&self, motion: Motion) -> f64 {
        self.time[motion as usize]
    }

    /// Path length in mm of blocks of one kind.
    pub fn length(&self, motion: Motion) -> f64 {
        self.length[motion as usize]
    }

    /// These totals of a run whose part up to a point summed to `from`,
    /// after that part changed to sum to `to`.
    pub fn moved(&self, from: &Totals, to: &Totals) -> Totals {
        let shift = |value: f64, from: f64, to: f64| value - from + to;
        let count = |value: usize, from: usize, to: usize| (value + to).saturating_sub(from);
        Totals {
            total_time: shift(self.total_time, from.total_time, to.total_time),
            programmed_time: shift(self.programmed_time, from.programmed_time, to.programmed_time),
            time: std::array::from_fn(|i| shift(self.time[i], from.time[i], to.time[i])),
            length: std::array::from_fn(|i| shift(self.length[i], from.length[i], to.length[i])),
            program_stops: count(self.program_stops, from.program_stops, to.program_stops),
            optional_stops: count(self.optional_stops, from.optional_stops, to.optional_stops),
        }
    }

    /// Counts `step`, which took `duration` seconds.
    pub fn add(&mut self, step: &Step, duration: f64) {
        self.total_time += duration;
        self.programmed_time += step.duration;
        self.time[step.motion as usize] += duration;
        self.length[step.motion as usize] += step.length;
        match step.stop {
            Some(Stop::Program) => self.program_stops += 1,
            Some(Stop::Optional) => self.optional_stops += 1,
            None => {}
        }
    }
}

/// One block as it ran.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The file the block is in: 0 for the program, k for the k-th other
    /// file the run read ([`Trace::files`]).
    pub source: usize,
    /// The block's text range.
    pub range: TextRange,
    pub motion: Motion,
    /// The shape of the move.
    pub path: Path,
    pub duration: f64,
    /// Path length in mm.
    pub length: f64,
    /// The path feed in mm/min (`None` for rapid and non-motion blocks).
    pub feed: Option<f64>,
    /// The programmed position at the step's end, over the machine's axes
    /// ([`Trace::axes`]); it starts where the step before it ended.
    pub end: Axes,
    /// How program coordinates became machine ones in the step:
    /// `Trace::frames[frame]` (the zero offset, G37, the length correction
    /// and the transformations G38/G39/G31).
    pub frame: usize,
    /// The program stops after the block (M00, M01) until the operator
    /// starts it again; the run does not count the wait.
    pub stop: Option<Stop>,
    /// How the block joins the one before it (G group 2).
    pub joining: Joining,
    /// M functions the block runs besides program stops, ends and the tool
    /// change, and whether it changes the tool (M06); each takes the
    /// machine's time for it.
    pub m_functions: u8,
    pub tool_change: bool,
    /// The envelope velocity's dynamic set in force, 1 to 4 (`G23 I1` …
    /// `I4`; 1 after reset).
    pub dynamic_set: u8,
    /// A G01 line without technology functions (M, S, T, D), without F
    /// and not under G91, which machine constant R383 may merge into the
    /// move before it (04 §1.9.4).
    pub mergeable: bool,
}

/// What else a block does besides its motion, as its step records it.
#[derive(Debug, Clone, Copy, Default)]
struct Functions {
    m_functions: u8,
    tool_change: bool,
    mergeable: bool,
}

/// Block joining, group 2 (04 §1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Joining {
    /// G98, the basic state: every block ramps to a stop, with a pause
    /// before the next (also under the group's other codes, G05–G10).
    Basic,
    /// G24: tight joining, a stop and the wait for the in-position window.
    Tight,
    /// G23: continuity, manual or recognised as machine constant R97 says.
    Continuous,
}

/// A message operation 51 shows the operator; the program does not wait
/// for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OperatorMessage {
    /// The step of the block that showed it.
    pub step: usize,
    pub message: Message,
}

/// Steps that ran under radius compensation: their ends are the
/// programmed contour, the tool ran on [`Trace::tool_centre`].
#[derive(Debug, Clone, PartialEq)]
pub struct Compensated {
    pub steps: Range<usize>,
    /// The plane's axes, the order of the tool-centre path's coordinates.
    pub plane: (u8, u8),
}

/// Positions over the machine's axes 1–6, in their order: what a step
/// keeps, so that a run of a million blocks stays small.
pub type Axes = [f64; MAX_AXES];

/// The most axes a machine has (axes 1–6).
pub const MAX_AXES: usize = 6;

/// The shape of a move from its start to its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Path {
    Straight,
    /// An arc (a helix when other axes move too) in the plane of two axes
    /// (letters), turning about `centre` (absolute, in the plane's order).
    Arc {
        plane: (u8, u8),
        centre: [f64; 2],
        clockwise: bool,
    },
    /// A thread: `lead` mm per revolution at `speed` rpm.
    Thread {
        lead: f64,
        speed: f64,
    },
}

/// A program stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// M00: always.
    Program,
    /// M01: when the operator has selected AUT-M01.
    Optional,
}

/// A problem found while running, at a text range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// The file, as in [`Step::source`].
    pub source: usize,
    pub range: TextRange,
    pub message: String,
    /// The run stopped here (an error the control stops on).
    pub fatal: bool,
}

/// A whole run.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// The machine's axes, the order of [`Step::end`].
    pub axes: Vec<u8>,
    /// The machine's diameter axis: positions on it are radii, whether the
    /// program wrote diameters (G74) or radii (G75).
    pub diameter_axis: Option<u8>,
    /// From program to machine coordinates, per [`Step::frame`].
    pub frames: Vec<Frame>,
    /// The frame of the priority block: the zero offset G53 of the machine's
    /// tables as the run started.
    pub reset_frame: Frame,
    /// The tool-centre path of radius compensation, piece by piece in the
    /// order of their steps (`block` is the step's index).
    pub tool_centre: Vec<ToolElement>,
    pub compensated: Vec<Compensated>,
    /// The technologist's messages of operation 51, in the order shown.
    pub messages: Vec<OperatorMessage>,
    pub steps: Vec<Step>,
    pub findings: Vec<Finding>,
    /// Tools called with T, in order of first use.
    pub tools: Vec<u32>,
    /// The files the run read besides the program: source k is
    /// `files[k - 1]`.
    pub files: Vec<Called>,
    /// Blocks the run executed, the ones before a checkpoint it resumed
    /// from included (the step budget counts them).
    pub blocks_run: usize,
}

impl Trace {
    /// Time and length by kind of block, and the program stops, in one
    /// pass over the steps (a long run's steps are hundreds of megabytes).
    pub fn totals(&self) -> Totals {
        self.totals_with(self.steps.iter().map(|step| step.duration))
    }

    /// Like [`Trace::totals`], with the steps taking `durations` (those of
    /// the velocity model).
    pub fn totals_with(&self, durations: impl Iterator<Item = f64>) -> Totals {
        let mut totals = Totals::default();
        for (step, duration) in self.steps.iter().zip(durations) {
            totals.add(step, duration);
        }
        totals
    }

    /// The programmed position at the end, over the machine's axes.
    pub fn end(&self) -> Axes {
        self.steps.last().map_or([0.0; MAX_AXES], |step| step.end)
    }

    /// The programmed position at the end, by letter.
    pub fn end_position(&self) -> Position {
        self.position(&self.end())
    }

    /// Where step `index` starts in machine coordinates: where the one
    /// before it ended, or the machine zero.
    pub fn machine_start(&self, index: usize) -> Axes {
        index.checked_sub(1).map_or([0.0; MAX_AXES], |before| self.machine_end(before))
    }

    /// Where step `index` starts in the program coordinates it runs in.
    pub fn start_of(&self, index: usize) -> Axes {
        self.frames[self.steps[index].frame].to_program(&self.machine_start(index), &self.axes)
    }

    /// Axis values as a position by letter.
    pub fn position(&self, values: &Axes) -> Position {
        transform::by_letter(values, &self.axes)
    }

    /// Step `index`'s end in machine coordinates.
    pub fn machine_end(&self, index: usize) -> Axes {
        let step = &self.steps[index];
        self.frames[step.frame].to_machine(&step.end, &self.axes)
    }

    /// The value of axis `letter` in `values`, 0 for a letter the machine
    /// does not have.
    pub fn axis(&self, values: &Axes, letter: u8) -> f64 {
        self.axes.iter().position(|&axis| axis == letter).map_or(0.0, |i| values[i])
    }
}

/// How many blocks a run executes at most before it stops: a jump loop
/// that never ends or runaway recursion stops here with a finding.
pub const DEFAULT_STEP_BUDGET: usize = 10_000_000;

/// How deep subprogram calls nest before the run stops.
const MAX_CALL_DEPTH: usize = 64;

/// What a run needs from where it runs: the files a program uses besides
/// its own, and someone to tell how far it got.
pub trait Environment {
    /// The text of the macrocycle file `L<number>`.
    fn macrocycle(&self, number: u32) -> Option<String>;
    /// The text of the fixed-cycle file the machine names (`PCYKLYDG.NCP`).
    fn cycle_file(&self, name: &str) -> Option<String>;
    /// Called every [`PROGRESS_INTERVAL`] blocks with the number run so far.
    fn progress(&self, _blocks_run: usize) {}
}

/// How often a run reports its progress, in blocks.
pub const PROGRESS_INTERVAL: usize = 1 << 16;

/// The program alone: no other files.
#[derive(Debug, Clone, Copy)]
pub struct NoFiles;

impl Environment for NoFiles {
    fn macrocycle(&self, _number: u32) -> Option<String> {
        None
    }

    fn cycle_file(&self, _name: &str) -> Option<String> {
        None
    }
}

/// A file of the run besides the program.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Called {
    Macrocycle(u32),
    /// The machine's fixed-cycle file.
    CycleFile,
}

/// Runs the CNC8x6 program `text` from its first block to M02/M30 on `machine`,
/// following subprogram calls, macrocycle calls, fixed cycles (the
/// bodies of the machine's cycle file, or the built-in cycles) and jumps,
/// for at most `budget` blocks. Files are read from `files` when first
/// needed, and the run reports its progress there. Parameters start at
/// zero.
pub fn run(text: &str, files: &dyn Environment, machine: &MachineConfig, budget: usize) -> Trace {
    std::thread::scope(|scope| run_in(scope, text, files, machine, budget, None, None))
}

/// The frame of the priority block on `machine`, in which a run starts:
/// the zero offset G53 of its tables ([`Trace::reset_frame`]).
pub fn reset_frame(machine: &MachineConfig) -> Frame {
    Runner::new(std::sync::Arc::new(machine.clone())).frame_in_force()
}

/// Takes the steps of a run in order, each once no later block can change
/// it.
pub trait StepSink {
    fn step(&mut self, step: Step);

    /// Takes every step of `steps` in order, leaving it empty.
    fn steps(&mut self, steps: &mut Vec<Step>) {
        steps.drain(..).for_each(|step| self.step(step));
    }

    /// Takes, before the steps about to come, what they refer to: the
    /// run's frames and spans of radius compensation so far (a step's
    /// [`Step::frame`] indexes `frames`; the last span may grow), and the
    /// pieces of the tool-centre path that belong to those steps, in path
    /// order. The trace keeps them all too. A sink on a thread of its own
    /// ([`run_beside`]) does not take them.
    fn references(&mut self, _frames: &[Frame], _compensated: &[Compensated], _tool_centre: &[ToolElement]) {}

    /// Whether to take a [`Checkpoint`] before block `block`, which starts
    /// at `offset`; asked only where the run can take one.
    fn checkpoint_wanted(&mut self, _block: usize, _offset: TextSize) -> bool {
        false
    }

    /// Takes the checkpoint asked for, once it has every step before it;
    /// `Break` ends the run there.
    fn checkpoint(&mut self, _checkpoint: Checkpoint) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }

    /// Whether the sink takes no more steps (where it writes has closed):
    /// the run then ends after the batch it has just taken.
    fn closed(&self) -> bool {
        false
    }
}

/// The run between two blocks of the program's main body while it goes
/// block after block (no call, jump, file or radius compensation in
/// force): enough to run on from there, over the same text or one that
/// differs only before that block. A run resumed from it reports what
/// happens after it: its trace's findings, messages and tool-centre path
/// start there.
#[derive(Clone)]
pub struct Checkpoint {
    runner: Box<Runner>,
    /// The next block, and where it starts.
    block: usize,
    offset: TextSize,
    /// Blocks run before it, for the step budget.
    executed: usize,
}

impl std::fmt::Debug for Checkpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Checkpoint")
            .field("block", &self.block)
            .field("offset", &self.offset)
            .field("executed", &self.executed)
            .finish_non_exhaustive()
    }
}

impl Checkpoint {
    /// Where the next block starts.
    pub fn offset(&self) -> TextSize {
        self.offset
    }

    /// The index of the next block in the program.
    pub fn block(&self) -> usize {
        self.block
    }

    /// The machine the run ran on.
    pub fn machine(&self) -> &MachineConfig {
        &self.runner.machine
    }

    /// Blocks the run executed before it.
    pub fn blocks_run(&self) -> usize {
        self.executed
    }

    /// Steps the run made before it.
    pub fn steps(&self) -> usize {
        self.runner.delivered
    }

    /// Whether a run from here goes on as one from `other` does over the
    /// same text after their offsets: the same modes, position,
    /// parameters, tables and frames; the blocks and steps before them and
    /// what was reported may differ.
    pub fn same_course(&self, other: &Checkpoint) -> bool {
        self.runner.same_course(&other.runner)
    }

    /// This checkpoint in a text where its block starts `text` bytes
    /// later, after `blocks` more blocks and `steps` more steps.
    pub fn shifted(&self, text: i64, blocks: i64, steps: i64) -> Checkpoint {
        let mut shifted = self.clone();
        shifted.offset = shift_offset(self.offset, text);
        shifted.block = shift_count(self.block, blocks);
        shifted.executed = shift_count(self.executed, blocks);
        shifted.runner.delivered = shift_count(self.runner.delivered, steps);
        shifted
    }
}

/// `offset` moved by `by` bytes, held inside the text's range.
pub fn shift_offset(offset: TextSize, by: i64) -> TextSize {
    TextSize::from(u32::try_from((i64::from(u32::from(offset)) + by).max(0)).unwrap_or(u32::MAX))
}

/// `range` moved by `by` bytes.
pub fn shift_range(range: TextRange, by: i64) -> TextRange {
    TextRange::new(shift_offset(range.start(), by), shift_offset(range.end(), by))
}

/// `count` moved by `by`, never below zero.
pub fn shift_count(count: usize, by: i64) -> usize {
    usize::try_from((count as i64 + by).max(0)).unwrap_or(usize::MAX)
}

/// Like [`run`], handing the steps to `sink` as they are final instead of
/// keeping them: the trace's `steps` stay empty, and a run of any length
/// holds only the few steps radius compensation may still fix.
pub fn run_into(
    text: &str,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    sink: &mut dyn StepSink,
) -> Trace {
    std::thread::scope(|scope| run_in(scope, text, files, machine, budget, Some(sink), None))
}

/// Like [`run_into`], from `checkpoint` (a checkpoint of a run on the
/// same machine over a text that differs from `text` only after it), or
/// from the start without one.
pub fn resume_into(
    checkpoint: Option<&Checkpoint>,
    text: &str,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    sink: &mut dyn StepSink,
) -> Trace {
    std::thread::scope(|scope| run_in(scope, text, files, machine, budget, Some(sink), checkpoint))
}

/// Like [`run_into`], with `sink` on a thread of its own, so that what it
/// does with the steps (the velocity model) runs beside the executor;
/// returns the trace and the sink.
pub fn run_beside<S: StepSink + Send>(
    text: &str,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    mut sink: S,
) -> (Trace, S) {
    std::thread::scope(|scope| {
        let (sender, batches) = mpsc::sync_channel::<Vec<Step>>(8);
        let (recycle, emptied) = mpsc::sync_channel::<Vec<Step>>(8);
        let beside = scope.spawn(move || {
            for mut batch in batches {
                sink.steps(&mut batch);
                let _ = recycle.try_send(batch);
            }
            sink
        });
        let mut handing = Batches { batch: Vec::with_capacity(DELIVERY_BATCH), sender, emptied };
        let trace = run_in(scope, text, files, machine, budget, Some(&mut handing), None);
        let Batches { batch, sender, .. } = handing;
        // The sink's thread ends when the last batch is in and the channel
        // closes.
        let _ = sender.send(batch);
        drop(sender);
        (trace, beside.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
    })
}

/// Steps gathered for a sink on another thread, in batches it hands back
/// emptied: memory used again costs less than new memory.
struct Batches {
    batch: Vec<Step>,
    sender: mpsc::SyncSender<Vec<Step>>,
    emptied: Receiver<Vec<Step>>,
}

impl Batches {
    /// Sends the gathered batch on, with an emptied one in its place.
    fn send(&mut self) {
        let next = self.emptied.try_recv().unwrap_or_else(|_| Vec::with_capacity(DELIVERY_BATCH));
        let full = std::mem::replace(&mut self.batch, next);
        // A sink that panicked has closed the channel: the join says so.
        let _ = self.sender.send(full);
    }
}

impl StepSink for Batches {
    fn step(&mut self, step: Step) {
        self.batch.push(step);
        if self.batch.len() == DELIVERY_BATCH {
            self.send();
        }
    }

    /// A whole batch goes as it is, without copying its steps; `steps`
    /// gets an emptied batch's room.
    fn steps(&mut self, steps: &mut Vec<Step>) {
        if self.batch.is_empty() {
            std::mem::swap(&mut self.batch, steps);
            self.send();
        } else {
            steps.drain(..).for_each(|step| self.step(step));
        }
    }
}

/// Steps a streaming run gathers before it hands them on.
const DELIVERY_BATCH: usize = 1024;

fn run_in<'a, 's>(
    scope: &'s Scope<'s, 'a>,
    text: &'a str,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    mut sink: Option<&mut dyn StepSink>,
    checkpoint: Option<&Checkpoint>,
) -> Trace {
    let fresh = Runner::new(std::sync::Arc::new(machine.clone()));
    let reset_frame = fresh.frame_in_force();
    let (mut runner, mut index, mut at, mut executed) = match checkpoint {
        Some(checkpoint) if *checkpoint.runner.machine == *machine => (
            (*checkpoint.runner).clone(),
            Index::start(scope, text, Some((checkpoint.offset, checkpoint.block))),
            checkpoint.block,
            checkpoint.executed,
        ),
        _ => (fresh, Index::start(scope, text, None), 0, 0),
    };
    // Most programs run each block about once.
    runner.steps.reserve(if sink.is_some() { DELIVERY_BATCH } else { expected_blocks(text) });
    // Macrocycle numbers called, and where each file's body starts; the
    // cycle file's source once read; the files read, in source order.
    let mut loaded: Vec<(u32, Option<usize>)> = Vec::new();
    let mut cycle_file: Option<Option<usize>> = None;
    let mut called: Vec<Called> = Vec::new();
    // Calls being run: where to return, how many runs remain, where the
    // subprogram starts.
    let mut calls: Vec<Call> = Vec::new();
    let mut jumps = JumpCounts::default();
    // The rest of a block whose cycle of the cycle file has just run.
    let mut resume: Option<Flow> = None;
    let mut data = BlockData::default();
    while let Some((range, source)) = index.block(at) {
        if let Some(sink) = sink.as_deref_mut()
            && source == 0
            && resume.is_none()
            && calls.is_empty()
            && jumps.is_empty()
            && called.is_empty()
            && runner.compensator.is_none()
            && index.streams(at)
            && sink.checkpoint_wanted(at, range.start())
        {
            runner.deliver(sink, false);
            let checkpoint =
                Checkpoint { runner: Box::new(runner.for_checkpoint()), block: at, offset: range.start(), executed };
            if sink.checkpoint(checkpoint).is_break() {
                break;
            }
        }
        runner.source = source;
        if resume.is_none() && calls.is_empty() && index.starts_subprogram(at) {
            runner.finding(range, "the main body runs into a subprogram: it has no M02 or M30 before it", false);
            break;
        }
        executed += usize::from(resume.is_none());
        if executed % PROGRESS_INTERVAL == 0 {
            files.progress(executed);
        }
        if executed > budget {
            let message = format!("stopped after {budget} blocks: a jump loop that never ends or runaway calls?");
            runner.finding(range, &message, true);
            break;
        }
        let next = at + 1;
        let flow = match resume.take() {
            Some(flow) => flow,
            None => {
                index.lower(at, &mut data);
                runner.block(&data, range)
            }
        };
        let passes_on = flow == Flow::Block(BlockFlow::Next);
        at = match flow {
            Flow::Block(BlockFlow::End) => break,
            Flow::Block(BlockFlow::Next) => {
                jumps.passed(at);
                next
            }
            Flow::Block(BlockFlow::Return) => match calls.last_mut() {
                Some(call) if call.remaining > 1 => {
                    call.remaining -= 1;
                    call.start
                }
                Some(_) => calls.pop().map_or(next, |call| {
                    if let Some((snapshot, then)) = call.cycle {
                        runner.restore(*snapshot);
                        resume = Some(Flow::Block(then));
                    }
                    call.back
                }),
                None => next,
            },
            Flow::Cycle { number, then } => {
                let program = index.complete();
                let name = machine.cycle_file.as_deref().unwrap_or_default();
                let source = *cycle_file.get_or_insert_with(|| {
                    let text = files.cycle_file(name)?;
                    called.push(Called::CycleFile);
                    program.add(Cow::Owned(text))?;
                    Some(program.texts.len() - 1)
                });
                match source.and_then(|source| program.units.subprogram(source, number)) {
                    Some(start) => {
                        // Back to the calling block, to go on with its flow.
                        let cycle = Some((Box::new(runner.snapshot()), then));
                        runner.in_cycle = true;
                        calls.push(Call { back: at, remaining: 1, start, cycle });
                        start
                    }
                    None => {
                        let why = match source {
                            None => format!("the cycle file {name} the machine names is not in the project"),
                            Some(_) => format!("the cycle file {name} has no body G79 L{number}"),
                        };
                        runner.report_once(&why, range, &format!("{why}: the built-in cycle runs instead"));
                        if !runner.built_in_cycle_or_stop(number, range) {
                            break;
                        }
                        resume = Some(Flow::Block(then));
                        at
                    }
                }
            }
            Flow::Block(BlockFlow::Call { label, times, macrocycle: is_macrocycle }) => {
                let program = index.complete();
                let start = if is_macrocycle {
                    let known = loaded.iter().find(|&&(number, _)| number == label).map(|&(_, start)| start);
                    known.unwrap_or_else(|| {
                        let start = files.macrocycle(label).and_then(|text| {
                            called.push(Called::Macrocycle(label));
                            program.add(Cow::Owned(text))
                        });
                        loaded.push((label, start));
                        start
                    })
                } else {
                    program.units.subprogram(source, label)
                };
                match start {
                    Some(start) if calls.len() < MAX_CALL_DEPTH => {
                        calls.push(Call { back: next, remaining: times, start, cycle: None });
                        start
                    }
                    Some(_) => {
                        runner.finding(
                            range,
                            &format!("calls nest deeper than {MAX_CALL_DEPTH}: runaway recursion?"),
                            true,
                        );
                        break;
                    }
                    None if is_macrocycle => {
                        runner.finding(range, &format!("there is no macrocycle file L{label} to call"), true);
                        break;
                    }
                    None => {
                        runner.finding(
                            range,
                            &format!("there is no subprogram L{label} (G79 L{label}) in this file"),
                            true,
                        );
                        break;
                    }
                }
            }
            Flow::Block(BlockFlow::Jump { label, times }) => match index.complete().units.jump_target(at, label) {
                Some(target) if jumps.jumps(at, times) => target,
                Some(_) => next,
                None => {
                    runner.finding(range, &format!("no block N{label} in this program unit to jump to"), true);
                    break;
                }
            },
        };
        // Only another file's blocks can end without a way back.
        let leaves_file = |index: &mut Index<'_, '_>| index.complete().block(at).is_none_or(|(_, file)| file != source);
        if source != 0 && passes_on && leaves_file(&mut index) {
            runner.finding(range, "the macrocycle file ends without G70", true);
            break;
        }
        if let Some(sink) = sink.as_deref_mut()
            && runner.steps.len() >= DELIVERY_BATCH
        {
            runner.deliver(sink, false);
            if sink.closed() {
                break;
            }
        }
    }
    runner.finish_compensation();
    if let Some(sink) = sink {
        runner.deliver(sink, true);
    }
    // Pieces come in the order compensation fixes them, a block late.
    runner.tool_centre.sort_by_key(|piece| piece.block);
    Trace {
        axes: machine.step_axes().to_vec(),
        diameter_axis: machine.diameter_axis,
        tool_centre: runner.tool_centre,
        compensated: runner.compensated,
        messages: runner.messages,
        frames: runner.frames,
        reset_frame,
        steps: runner.steps,
        findings: runner.findings,
        tools: runner.tools,
        files: called,
        blocks_run: executed,
    }
}

/// A subprogram or macrocycle call being run.
struct Call {
    /// The block after the call.
    back: usize,
    /// Runs left, this one included.
    remaining: u32,
    /// The body's first block after its `G79`.
    start: usize,
    /// A fixed cycle of the cycle file: the state to restore on return, and
    /// the flow of its block, which goes on then.
    cycle: Option<(Box<Snapshot>, BlockFlow)>,
}

/// The blocks of the program and the macrocycle files loaded so far, one
/// index space. A block is kept as where it is and lowered again each time
/// it runs, so that a program of a million blocks costs little more memory
/// than its text: plain blocks are read from the text, others from their
/// syntax tree.
#[derive(Default)]
struct Blocks<'a> {
    /// Each block's text range in its file.
    ranges: Vec<TextRange>,
    /// The first block of each file, in file order.
    file_starts: Vec<usize>,
    /// The syntax trees of the blocks the plain reader does not read, by
    /// block, in block order (few in CAM output).
    trees: Vec<(usize, GreenNode)>,
    units: Units,
    /// The text of each file added so far.
    texts: Vec<Cow<'a, str>>,
    plain: PlainReader,
}

impl<'a> Blocks<'a> {
    /// Adds a file's blocks; returns where its body starts running (after
    /// the `G79` a macrocycle file opens with), `None` for a file without
    /// blocks.
    fn add(&mut self, text: Cow<'a, str>) -> Option<usize> {
        self.add_reading(text, 0, |_, _, _| ControlFlow::Continue(()))
    }

    /// Like [`Blocks::add`], and gives `each` each block as it is lowered,
    /// with whether it starts a subprogram, until it breaks; reads from
    /// byte `from` on (a block's start).
    fn add_reading(
        &mut self,
        text: Cow<'a, str>,
        from: usize,
        mut each: impl FnMut(TextRange, &mut BlockData, bool) -> ControlFlow<()>,
    ) -> Option<usize> {
        let first = self.ranges.len();
        let mut opens_with_g79 = false;
        let expected = expected_blocks(&text);
        self.ranges.reserve(expected);
        self.units.numbers.reserve(expected);
        self.file_starts.push(first);
        let mut reader = BlockReader::new(&text);
        reader.skip_to(from);
        let mut data = BlockData::default();
        while let Some((range, tree)) = reader.next_into(&mut data) {
            let index = self.ranges.len();
            opens_with_g79 |= index == first && data.has_code(b'G', 79);
            let starts_subprogram = self.units.add(index, self.texts.len(), &data, index == first);
            self.ranges.push(range);
            self.trees.extend(tree.map(|tree| (index, tree)));
            if each(range, &mut data, starts_subprogram).is_break() {
                break;
            }
        }
        self.units.numbers.sort_unstable();
        self.texts.push(text);
        (first < self.ranges.len()).then_some(if opens_with_g79 { first + 1 } else { first })
    }

    /// The range and the file of block `index`.
    fn block(&self, index: usize) -> Option<(TextRange, usize)> {
        let range = *self.ranges.get(index)?;
        Some((range, self.file_starts.partition_point(|&start| start <= index) - 1))
    }

    /// Lowers block `index` into `data`.
    fn lower(&self, index: usize, data: &mut BlockData) {
        match self.trees.binary_search_by_key(&index, |&(at, _)| at) {
            Ok(tree) => *data = BlockData::lower(&self.trees[tree].1),
            Err(_) => {
                let Some((range, source)) = self.block(index) else { return };
                let range = Range::<usize>::from(range);
                let read = self.plain.lower(&self.texts[source], range.start, range.end, data);
                debug_assert_eq!(read, Some(range.end), "a plain block reads alike every time");
            }
        }
    }
}

/// About as many blocks as a program of CAM output with this text has, or
/// more: memory reserved and never used costs nothing, growing costs copies.
pub fn expected_blocks(text: &str) -> usize {
    text.len() / 24
}

/// Blocks the index pass hands to the run at a time.
const STREAM_BATCH: usize = 1024;

/// The program's blocks while the index pass still reads them on a
/// thread of its own, then all blocks of the run. Going block after block,
/// the run takes each block as the index pass lowered it, so a large
/// program is lowered once and on two cores; the first call, jump or
/// cycle waits for the whole index.
enum Index<'a, 's> {
    Streaming(Stream<'a, 's>),
    Complete(Blocks<'a>),
}

struct Stream<'a, 's> {
    /// The program, and whether the stream starts at a checkpoint after
    /// its first block (the index pass then indexes the blocks after it
    /// only).
    text: &'a str,
    resumed: bool,
    /// Set when the run needs every block: the index pass then goes on
    /// once it stops streaming; else it stops with the run.
    whole_index_wanted: std::sync::Arc<AtomicBool>,
    batches: Receiver<Vec<Streamed>>,
    /// Batches taken, back to the index pass with the run's spent block
    /// data, whose room it fills again.
    taken_batches: mpsc::SyncSender<Vec<Streamed>>,
    batch: Vec<Streamed>,
    /// Blocks of `batch` the run has taken.
    taken: usize,
    /// The index of `batch[taken]`.
    next: usize,
    index_pass: ScopedJoinHandle<'s, Blocks<'a>>,
}

/// A block of the program as the index pass lowered it.
struct Streamed {
    range: TextRange,
    data: BlockData,
    starts_subprogram: bool,
}

impl<'a, 's> Index<'a, 's> {
    /// Starts the index pass over `text`, from the start or from `from`:
    /// a block's offset and index.
    fn start(scope: &'s Scope<'s, 'a>, text: &'a str, from: Option<(TextSize, usize)>) -> Index<'a, 's> {
        let (offset, first) = from.map_or((0, 0), |(offset, block)| (usize::from(offset), block));
        let (sender, batches) = mpsc::sync_channel::<Vec<Streamed>>(4);
        let (taken_batches, returned) = mpsc::sync_channel::<Vec<Streamed>>(4);
        let whole_index_wanted = std::sync::Arc::new(AtomicBool::new(false));
        let wanted = whole_index_wanted.clone();
        let index_pass = scope.spawn(move || {
            let whole_index_wanted = wanted;
            let mut blocks = Blocks::default();
            let mut batch = Vec::with_capacity(STREAM_BATCH);
            // A batch the run took, whose block data the next blocks reuse.
            let mut spent: Vec<Streamed> = Vec::new();
            // Until the run stops taking blocks in order.
            let mut streaming = true;
            blocks.add_reading(Cow::Borrowed(text), offset, |range, data, starts_subprogram| {
                if !streaming {
                    return ControlFlow::Continue(());
                }
                let room = spent.pop().map(|spent| spent.data).unwrap_or_default();
                batch.push(Streamed { range, data: std::mem::replace(data, room), starts_subprogram });
                if batch.len() == STREAM_BATCH {
                    let mut next = match returned.try_recv() {
                        Ok(taken) => std::mem::replace(&mut spent, taken),
                        Err(_) => Vec::with_capacity(STREAM_BATCH),
                    };
                    next.clear();
                    let full = std::mem::replace(&mut batch, next);
                    streaming = sender.send(full).is_ok();
                    // A run that ended needs no index.
                    if !streaming && !whole_index_wanted.load(Ordering::SeqCst) {
                        return ControlFlow::Break(());
                    }
                }
                ControlFlow::Continue(())
            });
            if streaming && !batch.is_empty() {
                // The run may have ended already.
                let _ = sender.send(batch);
            }
            blocks
        });
        let resumed = first > 0;
        Index::Streaming(Stream {
            text,
            resumed,
            whole_index_wanted,
            batches,
            taken_batches,
            batch: Vec::new(),
            taken: 0,
            next: first,
            index_pass,
        })
    }

    /// Whether block `at` comes from the stream: the run goes block after
    /// block.
    fn streams(&self, at: usize) -> bool {
        matches!(self, Index::Streaming(stream) if stream.next == at)
    }

    /// The block at `at`, when it was streamed.
    fn streamed(&mut self, at: usize) -> Option<&mut Streamed> {
        let Index::Streaming(stream) = self else { return None };
        if at != stream.next {
            return None;
        }
        if stream.taken == stream.batch.len() {
            let taken = std::mem::take(&mut stream.batch);
            let _ = stream.taken_batches.try_send(taken);
            // A closed channel: the index pass has sent every block.
            stream.batch = stream.batches.recv().ok()?;
            stream.taken = 0;
        }
        stream.batch.get_mut(stream.taken)
    }

    /// The range and the file of block `at`.
    fn block(&mut self, at: usize) -> Option<(TextRange, usize)> {
        if let Some(streamed) = self.streamed(at) {
            return Some((streamed.range, 0));
        }
        self.complete().block(at)
    }

    fn starts_subprogram(&mut self, at: usize) -> bool {
        match self.streamed(at) {
            Some(streamed) => streamed.starts_subprogram,
            None => self.complete().units.starts_subprogram(at),
        }
    }

    /// Lowers block `at` into `data`.
    fn lower(&mut self, at: usize, data: &mut BlockData) {
        match self.streamed(at) {
            Some(streamed) => {
                std::mem::swap(data, &mut streamed.data);
                if let Index::Streaming(stream) = self {
                    stream.taken += 1;
                    stream.next += 1;
                }
            }
            None => self.complete().lower(at, data),
        }
    }

    /// All blocks, once the index pass is done.
    fn complete(&mut self) -> &mut Blocks<'a> {
        if let Index::Streaming(_) = self {
            let Index::Streaming(stream) = std::mem::replace(self, Index::Complete(Blocks::default())) else {
                unreachable!()
            };
            // The index pass stops streaming and finishes the index, but
            // for a resumed run, whose index starts at its checkpoint.
            stream.whole_index_wanted.store(!stream.resumed, Ordering::SeqCst);
            drop(stream.batches);
            let mut blocks = stream.index_pass.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            if stream.resumed {
                // Jumps and calls may go to blocks before the checkpoint.
                blocks = Blocks::default();
                blocks.add(Cow::Borrowed(stream.text));
            }
            *self = Index::Complete(blocks);
        }
        match self {
            Index::Complete(blocks) => blocks,
            Index::Streaming(_) => unreachable!("the index is complete"),
        }
    }
}

/// Where the subprograms start, and the block numbers of each unit.
#[derive(Default)]
struct Units {
    /// Subprogram starts (`G79 L`): the block index, its file and the label.
    starts: Vec<(usize, usize, u32)>,
    /// Where each unit starts, in block order (each file's first unit is
    /// its main body or macrocycle body, then one per subprogram): the
    /// units are runs of blocks.
    unit_starts: Vec<usize>,
    /// Block numbers with their block, sorted; only numbers a jump can
    /// name (`L` is at most 4 digits), in a million-block program's index.
    numbers: Vec<(u32, u32)>,
}

impl Units {
    /// Indexes block `index` of file `source`; `opens_file` for a file's
    /// first block. The caller sorts `numbers` after the file. Returns
    /// whether the block starts a subprogram.
    fn add(&mut self, index: usize, source: usize, block: &BlockData, opens_file: bool) -> bool {
        if opens_file {
            self.unit_starts.push(index);
        }
        // Each `G79` opens a unit: a subprogram, a cycle file's body, or a
        // macrocycle file's body (whose file opened one already).
        if block.has_code(b'G', 79) {
            self.unit_starts.push(index);
            let label = match block.word(b'L').and_then(|word| word.value.as_ref()) {
                Some(Value::Literal(decimal)) => whole_number(decimal),
                _ => None,
            };
            self.starts.extend(label.map(|label| (index, source, label)));
        }
        let number = block.number.and_then(|number| u32::try_from(number.value?).ok());
        if let Some((number, index)) = number.zip(u32::try_from(index).ok()) {
            self.numbers.push((number, index));
        }
        self.starts.last().is_some_and(|&(at, _, _)| at == index)
    }

    fn starts_subprogram(&self, index: usize) -> bool {
        self.starts.iter().any(|&(at, _, _)| at == index)
    }

    /// The first block of subprogram `label` of file `source`, after its `G79`.
    fn subprogram(&self, source: usize, label: u32) -> Option<usize> {
        self.starts.iter().find(|&&(_, file, l)| file == source && l == label).map(|&(at, _, _)| at + 1)
    }

    /// The unit of block `index`.
    fn unit_of(&self, index: usize) -> usize {
        self.unit_starts.partition_point(|&start| start <= index)
    }

    /// The block numbered `label` in the unit of block `from`.
    fn jump_target(&self, from: usize, label: u32) -> Option<usize> {
        let unit = self.unit_of(from);
        let first = self.numbers.partition_point(|&(number, _)| number < label);
        self.numbers[first..]
            .iter()
            .take_while(|&&(number, _)| number == label)
            .map(|&(_, at)| at as usize)
            .find(|&at| self.unit_of(at) == unit)
    }
}

/// What runs after a block: its own flow, or first a fixed cycle's body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Flow {
    Block(BlockFlow),
    /// A fixed cycle's body in the cycle file, after the block's motion;
    /// then the block's own flow.
    Cycle {
        number: u32,
        then: BlockFlow,
    },
}

/// The control's state while a program runs.
#[derive(Clone)]
struct Runner {
    catalogue: &'static Catalogue,
    /// The file of the block being run.
    source: usize,
    machine: std::sync::Arc<MachineConfig>,
    modes: Modes,
    groups: Groups,
    /// F as programmed; its unit follows the feed mode in force.
    feed: Option<ProgrammedFeed>,
    /// S as programmed: rpm, or the cutting speed under constant cutting
    /// speed (0.1 m/min, or m/min as machine constant 329 selects).
    speed: f64,
    /// A fixed cycle's body of the cycle file is running: cycles do not
    /// start in it.
    in_cycle: bool,
    /// Radius compensation in force, and its machine constants.
    compensator: Option<Compensator>,
    compensation: Settings,
    /// Messages of operation 51, with the step of their block.
    messages: Vec<OperatorMessage>,
    /// The tool-centre path so far, and the steps compensation ran over.
    tool_centre: Vec<ToolElement>,
    compensated: Vec<Compensated>,
    /// Machine constant 329 decade 3: G96/G97 swapped (1, 3), S in m/min
    /// (2, 3); read once, as every block asks.
    css_setting: u8,
    /// Machine constant 329 decade 7: the length-compensation mode (0 = A).
    length_setting: u8,
    /// What the address of each machine axis holds (±69999.999), in the
    /// order of the axes, as bounds of the positions (radii on a diameter
    /// axis) with half a µm to spare, outside and under diameter
    /// programming G74; worked out once, as every move asks.
    axis_bounds: [[(f64, f64); MAX_AXES]; 2],
    /// The literals each address A–Z plainly takes, as every word asks.
    plain_literals: [PlainLiterals; 26],
    /// The zero-offset and correction tables, as the program changes them.
    offsets: OffsetTable,
    corrections: ToolTable,
    /// The envelope velocity's dynamic set, `G23 I1` … `I4`.
    dynamic_set: u8,
    /// The zero offset the block writes, which holds in it alone when it
    /// is G58 or G59.
    block_offset: Option<u8>,
    /// The helix's axis and its travel per turn in mm, from G10.
    helix_lead: Option<(u8, f64)>,
    /// The correction entry D and the length-compensation digits `&`.
    correction: u8,
    length_digits: u32,
    /// The length correction in force, by letter.
    length_shift: Position,
    /// Mirroring, scale and offset G35–G37, and the transformations
    /// G38/G39/G31.
    recalculation: Recalculation,
    transformations: Transformations,
    /// Diameter programming G74 (G75: radius): the machine's diameter axis
    /// is written as a diameter, and runs as a radius.
    diameter: bool,
    /// The frames the steps ran in; the last is in force.
    frames: Vec<Frame>,
    /// The speed limit of constant cutting speed set by `G76 S`, in rpm.
    speed_limit: Option<f64>,
    /// The spindle speed constant cutting speed reached last, which S
    /// takes when it ends (01 §6.9.1).
    speed_reached: Option<f64>,
    position: Position,
    params: Parameters,
    /// The steps not handed on yet: `steps[0]` is step `delivered`.
    steps: Vec<Step>,
    delivered: usize,
    findings: Vec<Finding>,
    /// T in force, and every T in order of first use.
    tool: Option<u32>,
    tools: Vec<u32>,
    /// Kinds of work already reported as not run.
    reported: Vec<String>,
}

impl Runner {
    fn new(machine: std::sync::Arc<MachineConfig>) -> Self {
        // The priority block: G01 G17 G90 G94 F0 S0 M05 ….
        let modes = Modes::reset();
        Runner {
            catalogue: Dialect::Cnc8x6.catalogue(),
            source: 0,
            groups: Groups::of(&modes),
            modes,
            feed: None,
            speed: 0.0,
            speed_limit: None,
            speed_reached: None,
            in_cycle: false,
            css_setting: machine.decade(329, 3),
            length_setting: machine.decade(329, 7),
            axis_bounds: [false, true].map(|diameter| {
                std::array::from_fn(|index| {
                    let Some(&axis) = machine.axes.get(index) else { return (f64::NEG_INFINITY, f64::INFINITY) };
                    let per_unit = if diameter && machine.diameter_axis == Some(axis) { 2.0 } else { 1.0 };
                    match Dialect::Cnc8x6.catalogue().address_of(axis).and_then(|address| address.bounds) {
                        // Exact: halving and doubling lose no bits.
                        Some((min, max)) => ((min - HALF_MICROMETRE) / per_unit, (max + HALF_MICROMETRE) / per_unit),
                        None => (f64::NEG_INFINITY, f64::INFINITY),
                    }
                })
            }),
            plain_literals: std::array::from_fn(|index| {
                PlainLiterals::of(Dialect::Cnc8x6.catalogue().address_of(b'A' + index as u8))
            }),
            compensator: None,
            compensation: Settings::of(&machine),
            tool_centre: Vec::new(),
            compensated: Vec::new(),
            messages: Vec::new(),
            offsets: machine.offsets.clone(),
            corrections: machine.tools.clone(),
            dynamic_set: 1,
            block_offset: None,
            helix_lead: None,
            correction: 0,
            length_digits: 0,
            length_shift: [0.0; 26],
            recalculation: Recalculation::default(),
            transformations: Transformations::default(),
            diameter: machine.diameter_axis.is_some(),
            frames: vec![Frame::default()],
            position: [0.0; 26],
            params: Parameters::zeroed(),
            steps: Vec::new(),
            delivered: 0,
            findings: Vec::new(),
            tool: None,
            tools: Vec::new(),
            reported: Vec::new(),
            machine,
        }
    }

    /// A copy to go on from, without what the run reported so far.
    fn for_checkpoint(&self) -> Runner {
        let mut copy = self.clone();
        copy.findings.clear();
        copy.messages.clear();
        copy.tool_centre.clear();
        copy.compensated.clear();
        copy.tools.clear();
        copy
    }

    /// See [`Checkpoint::same_course`].
    fn same_course(&self, other: &Runner) -> bool {
        // Every field named, so that a new one must be placed here.
        let Runner {
            catalogue: _,
            source,
            machine,
            modes,
            groups: _,
            feed,
            speed,
            in_cycle,
            compensator,
            compensation: _,
            messages: _,
            tool_centre: _,
            compensated: _,
            css_setting: _,
            length_setting: _,
            axis_bounds: _,
            plain_literals: _,
            offsets,
            corrections,
            dynamic_set,
            // Set anew by every block before it is read.
            block_offset: _,
            helix_lead,
            correction,
            length_digits,
            length_shift,
            recalculation,
            transformations,
            diameter,
            frames,
            speed_limit,
            speed_reached,
            position,
            params,
            steps,
            delivered: _,
            findings: _,
            tool,
            tools: _,
            reported,
        } = self;
        *source == other.source
            && **machine == *other.machine
            && *modes == other.modes
            && *feed == other.feed
            && *speed == other.speed
            && *in_cycle == other.in_cycle
            && compensator.is_none()
            && other.compensator.is_none()
            && *offsets == other.offsets
            && *corrections == other.corrections
            && *dynamic_set == other.dynamic_set
            && *helix_lead == other.helix_lead
            && *correction == other.correction
            && *length_digits == other.length_digits
            && *length_shift == other.length_shift
            && *recalculation == other.recalculation
            && *transformations == other.transformations
            && *diameter == other.diameter
            && *frames == other.frames
            && *speed_limit == other.speed_limit
            && *speed_reached == other.speed_reached
            && *position == other.position
            && *params == other.params
            && steps.is_empty()
            && other.steps.is_empty()
            && *tool == other.tool
            && *reported == other.reported
    }

    fn block(&mut self, block: &BlockData, range: TextRange) -> Flow {
        let at = |local: TextRange| local + range.start();
        let codes: SmallVec<[(u8, u32, TextRange); 8]> = block
            .words
            .iter()
            .filter(|word| matches!(word.letter, b'G' | b'M'))
            .filter_map(|word| Some((word.letter, self.integer(word)?, at(word.range))))
            .collect();
        let has = |letter: u8, number: u32| codes.iter().any(|&(l, n, _)| l == letter && n == number);
        if let Some((refused, message)) = self.refused_value(block, &codes) {
            self.finding(at(refused), &message, true);
            return Flow::Block(BlockFlow::End);
        }
        for word in &block.words {
            if let Some(Value::Parameter { index: Some(index), .. }) = word.value
                && (index as usize) < arith::PARAMETER_COUNT
                && self.params.get(index as usize).is_none()
            {
                let message = format!(
                    "R{index} holds a value the executor does not know (read from a table or register it does not model yet): words that use it are left out"
                );
                self.report_once(&format!("R{index}"), at(word.range), &message);
            }
        }
        let css_before = self.feed_mode().css;
        for &(letter, number, code_range) in &codes {
            self.modes.set(letter, number);
            match (letter, number) {
                // Modes the run reads where they matter; block joining
                // changes nothing before the velocity model.
                (b'G', 0..=4 | 33 | 17..=19 | 23 | 24 | 40..=42 | 53..=59 | 76 | 78 | 80..=93 | 94..=98)
                | (b'M', _) => {}
                // Program flow, which the caller follows, and the
                // arithmetic, which runs after the motion.
                (b'G', 26..=29 | 70..=73 | 79) => {}
                // The helix G09 and its lead G10, which the motion reads.
                (b'G', 9 | 10) => {}
                // Transformations, which the block is about.
                (b'G', 31 | 34..=39) => {}
                // Group G10 also holds the block's own G04/G92/G93, so the
                // programming mode is kept apart from it.
                (b'G', 74) => self.diameter = true,
                (b'G', 75) => self.diameter = false,
                _ => self.not_run(&format!("G{number:02}"), code_range),
            }
        }
        // Technology functions (M, S, T, D) and F keep R383 from merging
        // the block (04 §1.9.4).
        let mut technology = false;
        let mut writes_speed = false;
        let mut axes: SmallVec<[&Word; 8]> = SmallVec::new();
        for word in &block.words {
            let role = self.catalogue.role_of(word.letter);
            technology |= word.letter == b'M'
                || matches!(
                    role,
                    Some(AddressRole::Feed | AddressRole::Speed | AddressRole::Tool | AddressRole::Offset)
                );
            writes_speed |= role == Some(AddressRole::Speed);
            match role {
                Some(AddressRole::Axis) => axes.push(word),
                Some(AddressRole::Feed) => self.feed = self.programmed_feed(word),
                Some(AddressRole::Speed) => match self.count(word) {
                    // `G76 S` limits the speed of constant cutting speed.
                    Some(limit) if has(b'G', 76) => self.speed_limit = Some(limit),
                    Some(speed) => self.speed = speed,
                    None => {}
                },
                Some(AddressRole::Tool) => {
                    if let Some(tool) = self.integer(word) {
                        self.tool = Some(tool);
                        if !self.tools.contains(&tool) {
                            self.tools.push(tool);
                        }
                    }
                }
                Some(AddressRole::Offset) => {
                    if let Some(entry) = self.integer(word).and_then(|entry| u8::try_from(entry).ok()) {
                        self.correction = entry;
                    }
                }
                Some(AddressRole::LengthCompensation) => {
                    if let Some(digits) = self.integer(word) {
                        self.length_digits = digits;
                    }
                }
                _ => {}
            }
        }
        // When constant cutting speed ends, S keeps the speed it reached.
        if css_before && !self.feed_mode().css && !writes_speed {
            self.speed = self.speed_reached.take().unwrap_or(self.speed);
        }
        // A block of group 11 names its axes as the function's parameters:
        // it does not move (03 §3).
        if let Some(&(_, code, code_range)) = codes.iter().find(|&&(l, n, _)| l == b'G' && matches!(n, 31 | 34..=39)) {
            if let Err((message, fatal)) = self.transform(code, &axes, block) {
                self.finding(code_range, &message, fatal);
                if fatal {
                    return Flow::Block(BlockFlow::End);
                }
            }
            axes.clear();
        }
        // The helix lead block `N10 Z1.05 G10` names the axis the helix
        // drives and its travel per turn: it does not move (02 §4).
        if has(b'G', 10) {
            if let Some(word) = axes.first() {
                self.helix_lead = self.number(word).map(|lead| (word.letter, lead));
            }
            axes.clear();
        }
        // G58 and G59 hold in their own block only (01 §5.5).
        self.block_offset = codes
            .iter()
            .find(|&&(letter, number, _)| self.modes.group_of(letter, number) == Some(self.groups.zero_offset))
            .and_then(|&(_, number, _)| u8::try_from(number).ok());
        // A new zero offset holds from this block; a new length correction
        // from its first block of linear or rapid motion (02 §1.18.2).
        let motion = self.modes.active(self.groups.motion);
        // `G23 I1` … `I4` selects the envelope velocity's dynamic set (04
        // §2.2); in an arc block I is the centre.
        if has(b'G', 23)
            && !matches!(motion, Some(2 | 3))
            && let Some((set, word)) = block.word(b'I').and_then(|word| Some((self.integer(word)?, word)))
        {
            match u8::try_from(set) {
                Ok(set @ 1..=4) => self.dynamic_set = set,
                _ => self.finding(
                    at(word.range),
                    &format!("G23 I{set}: the dynamic sets are I1 to I4: the set in force stays"),
                    false,
                ),
            }
        }
        let shifts_length = !axes.is_empty() && matches!(motion, Some(0 | 1));
        self.shift_frame(shifts_length);
        let start = self.position;
        let writes_table = has(b'G', 92) || has(b'G', 93);
        // G04 Q dwells in 10 ms steps (02 §2.1), after the block's motion:
        // the cycles' `G01 ZR31 G04 QR29` drill, then dwell (03 §1).
        let dwell = has(b'G', 4).then(|| Moved {
            motion: Motion::Dwell,
            length: 0.0,
            duration: block.word(b'Q').and_then(|q| self.count(q)).unwrap_or(0.0) * 0.01,
            feed: None,
            path: Path::Straight,
        });
        let still = Moved { motion: Motion::None, length: 0.0, duration: 0.0, feed: None, path: Path::Straight };
        let (moved, dwell) = if writes_table {
            // G92/G93 write the table and move nothing (01 §5.6, §5.7).
            self.write_table(block, has(b'G', 93));
            (still, None)
        } else if axes.is_empty() {
            (dwell.unwrap_or(still), None)
        } else {
            let mut end = self.position;
            for word in &axes {
                if let Some(value) = self.number(word) {
                    let value = self.recalculation.apply(word.letter, value);
                    let written = self.written_per_unit(word.letter);
                    let slot = &mut end[usize::from(word.letter - b'A')];
                    // The control counts positions in whole µm, of the
                    // diameter on a diameter axis.
                    *slot = round3(if self.incremental() { *slot * written + value } else { value }) / written;
                }
            }
            self.position = end;
            let Some(moved) = self.moved(&Move { block, range, axes: &axes, start, end }) else {
                return Flow::Block(BlockFlow::End);
            };
            if let Some(message) = self.unreachable(&self.position) {
                self.finding(range, &message, true);
                return Flow::Block(BlockFlow::End);
            }
            (moved, dwell)
        };
        let stop = if has(b'M', 0) {
            Some(Stop::Program)
        } else if has(b'M', 1) {
            Some(Stop::Optional)
        } else {
            None
        };
        let path = moved.path;
        let m_functions = codes.iter().filter(|&&(letter, code, _)| letter == b'M' && !matches!(code, 0..=2 | 6 | 30));
        let functions = Functions {
            m_functions: u8::try_from(m_functions.count()).unwrap_or(u8::MAX),
            tool_change: has(b'M', 6),
            mergeable: moved.motion == Motion::Feed && motion == Some(1) && !technology && !self.incremental(),
        };
        let end = self.position;
        self.record(range, &end, moved, stop.filter(|_| dwell.is_none()), functions);
        if let Err(error) = self.compensate(start, path) {
            let range = self.step_mut(error.block()).range;
            self.finding(range, &format!("radius compensation: {error}"), true);
            return Flow::Block(BlockFlow::End);
        }
        if let Some(dwell) = dwell {
            self.record(range, &end, dwell, stop, Functions::default());
        }
        // Assignments and arithmetic take effect after the block's motion.
        arith::assign(block, &mut self.params);
        let mut machine = ProgramMachine {
            machine: &self.machine,
            position: &self.position,
            frame: &self.frames[self.frames.len() - 1],
            offsets: &mut self.offsets,
            corrections: &mut self.corrections,
            messages: &mut self.messages,
            step: self.delivered + self.steps.len() - 1,
            registers: Registers {
                modes: &self.modes,
                speed: self.speed,
                tool: self.tool,
                correction: self.correction,
            },
        };
        match arith::compute(block, &mut self.params, &mut machine, &self.machine) {
            BlockArithmetic::None | BlockArithmetic::Ran { result: Ok(()), .. } => {}
            BlockArithmetic::UnknownWord => {
                let message =
                    "a control word in R5–R8 has no value: it was computed from a value the executor does not know";
                self.finding(range, message, true);
                return Flow::Block(BlockFlow::End);
            }
            BlockArithmetic::Ran { function, result: Err(error), .. } => {
                self.finding(at(function), &format!("parameter arithmetic failed: {error}"), true);
                return Flow::Block(BlockFlow::End);
            }
        }
        // The active fixed cycle runs after the block's motion, in every
        // block until G80 (03 §1.4), but not inside its own body.
        let cycle = self.modes.active(self.groups.cycle).filter(|&number| (81..=89).contains(&number));
        if let Some(number) = cycle.filter(|_| !self.in_cycle) {
            if self.machine.cycle_file.is_some() {
                return Flow::Cycle { number, then: self.flow_of(block, has) };
            }
            if !self.built_in_cycle_or_stop(number, range) {
                return Flow::Block(BlockFlow::End);
            }
        }
        Flow::Block(self.flow_of(block, has))
    }

    /// The first value of the block the control refuses, with its range in
    /// the block: a literal or an assignment outside its address's format,
    /// or a parameter whose value the address cannot take (02 §3.6: the
    /// control checks them only as the block runs). `codes` are the
    /// block's G and M codes.
    fn refused_value(&self, block: &BlockData, codes: &[(u8, u32, TextRange)]) -> Option<(TextRange, String)> {
        let motion = codes
            .iter()
            .rev()
            .find(|&&(letter, number, _)| self.modes.modal_group_of(letter, number) == Some(self.groups.motion))
            .map_or(self.modes.active(self.groups.motion), |&(_, number, _)| Some(number));
        let thread = motion == Some(33);
        let machine = &*self.machine;
        for word in &block.words {
            if let Some(Value::Literal(decimal)) = &word.value
                && let Some(plain) = self.plain_literals.get(usize::from(word.letter.wrapping_sub(b'A')))
                && plain.take(decimal)
            {
                continue;
            }
            if let Some(Value::Parameter { index: Some(index), index_range, .. }) = &word.value
                && let Some(fault) = formats::parameter_number_fault(*index)
            {
                return Some((*index_range, fault.message));
            }
            let Some(address) = self.catalogue.address_of(word.letter) else { continue };
            let fault = match word.value.as_ref() {
                Some(Value::Literal(decimal)) => formats::literal_fault(address, decimal, machine),
                Some(value) => {
                    self.raw(value).and_then(|raw| formats::substitution_fault(address, raw, thread, machine))
                }
                None => None,
            };
            if let Some(fault) = fault {
                return Some((word.value_range.unwrap_or(word.range), fault.message));
            }
        }
        block.assignments.iter().find_map(|assignment| {
            if let Some(fault) = assignment.index.and_then(formats::parameter_number_fault) {
                return Some((assignment.index_range, fault.message));
            }
            let Some(Value::Literal(value)) = &assignment.value else { return None };
            let letter = self.catalogue.letter_with_role(AddressRole::Parameter)?;
            let fault = formats::assignment_fault(self.catalogue.address_of(letter)?, value)?;
            Some((assignment.value_range.unwrap_or(assignment.range), fault.message))
        })
    }

    /// What follows the block once its work is done ([`block_flow`]).
    fn flow_of(&self, block: &BlockData, has: impl Fn(u8, u32) -> bool) -> BlockFlow {
        block_flow(block, has, |word| self.integer(word))
    }

    /// Runs a block of group 11 with its axis words `axes`; the error says
    /// why the control refuses it, and whether it stops the program there.
    fn transform(&mut self, code: u32, axes: &[&Word], block: &BlockData) -> Result<(), (String, bool)> {
        let values: Vec<(u8, f64)> = axes.iter().filter_map(|w| Some((w.letter, self.number(w)?))).collect();
        let Some(kind) = Kind::of(code) else {
            match code {
                34 => self.recalculation = Recalculation::default(),
                35 => self.recalculation.mirror(axes.iter().map(|word| word.letter)),
                36 => {
                    let factors: Vec<f64> = values.iter().map(|&(_, value)| value).collect();
                    self.recalculation.set_scale(&factors).ok_or_else(|| {
                        ("G36 with a scale of 0 or a zero denominator: the control refuses it".to_owned(), true)
                    })?;
                }
                _ => self.recalculation.set_shift(values),
            }
            return Ok(());
        };
        let refused = |refused: Refused| {
            let fatal = refused != Refused::NotSet;
            let then = if fatal { "the control stops" } else { "the run goes on without it" };
            (format!("G{code}: {refused}: {then}"), fatal)
        };
        let angle = |letter: u8| block.word(letter).and_then(|word| self.number(word));
        if axes.is_empty() {
            // Alone it activates; with `I0` it cancels (000:6701–6740).
            return match angle(b'I') {
                None => self.transformations.activate(kind).map_err(refused),
                Some(0.0) => {
                    self.transformations.deactivate(kind);
                    Ok(())
                }
                Some(_) => Err((format!("G{code} with I but no axes neither sets, activates nor cancels it"), true)),
            };
        }
        // E divides the angles, for finer steps than 0.001° (000:6674–6678).
        let divisor = block.word(b'E').and_then(|word| self.number(word)).unwrap_or(1.0);
        if divisor <= 0.0 {
            return Err((format!("G{code}: the angle divisor E must be positive"), true));
        }
        let letters: &[u8] = if kind == Kind::Spatial { b"IJK" } else { b"I" };
        let mut angles = [0.0; 3];
        for (angle_of, &letter) in angles.iter_mut().zip(letters) {
            *angle_of = angle(letter).ok_or_else(|| {
                (format!("G{code} sets its parameters with {}: it is missing", char::from(letter)), true)
            })? / divisor;
        }
        self.transformations.set(kind, Transformation::new(&values, angles)).map_err(refused)
    }

    /// Takes the zero offset in force, G37, the length correction when
    /// `with_length` (a block of linear or rapid motion) and the active
    /// transformations into the frame from program to machine coordinates.
    /// The tool stays where it is, so its program position moves.
    fn shift_frame(&mut self, with_length: bool) {
        if with_length {
            self.length_shift = self.length_correction();
        }
        let axes = &self.machine.axes;
        let frame = self.frame_in_force();
        let current = self.frame();
        if frame == *current {
            return;
        }
        let position = self.machine_axes(&self.position);
        let program: Axes = if frame.transformations == current.transformations {
            // A translation alone moves the program position exactly.
            std::array::from_fn(|i| position[i] - (frame.translation[i] - current.translation[i]))
        } else {
            // The control recomputes the position in whole µm (000:6248–6252).
            frame.to_program(&current.to_machine(&position, axes), axes).map(round3)
        };
        for (&axis, value) in axes.iter().zip(program) {
            self.position[slot(axis)] = value;
        }
        self.frames.push(frame);
    }

    /// The frame the zero offset, G37, the length correction and the
    /// transformations in force make.
    fn frame_in_force(&self) -> Frame {
        let offset = self.offsets.offset(self.zero_offset_row());
        let mut translation = [0.0; MAX_AXES];
        for ((value, &axis), &offset) in translation.iter_mut().zip(&self.machine.axes).zip(&offset) {
            let letter = slot(axis);
            *value = self.length_shift[letter] + f64::from(offset) / 1000.0 + self.recalculation.shift[letter];
        }
        Frame { translation, transformations: self.transformations.active() }
    }

    /// The frame the tool's program position is in.
    fn frame(&self) -> &Frame {
        &self.frames[self.frames.len() - 1]
    }

    /// The length correction `&` and `D` select: mode A (machine constant
    /// 329 decade 7 = 0) adds (1) or subtracts (2) entry D's length per
    /// digit of `&` for axes 1–4; otherwise D alone applies the entry's
    /// lengths to every axis (mode B; mode C's switch is read as B).
    fn length_correction(&self) -> Position {
        let mut shift = [0.0; 26];
        if self.correction == 0 {
            return shift;
        }
        let entry = self.corrections.entry(self.correction);
        let mode_a = self.length_setting == 0;
        for (index, (&axis, &length)) in self.machine.axes.iter().zip(&entry.lengths).enumerate() {
            let sign = if mode_a {
                // `&k1k2k3k4`, right-aligned: k1 is the thousands digit.
                let digit = (index < 4).then(|| self.length_digits / 10u32.pow(3 - index as u32) % 10);
                match digit {
                    Some(1) => 1.0,
                    Some(2) => -1.0,
                    _ => 0.0,
                }
            } else {
                1.0
            };
            shift[slot(axis)] = sign * f64::from(length) / 1000.0;
        }
        shift
    }

    /// G92 writes the programmed values into the zero-offset row of the
    /// block's G5 code (or the one in force), or with D the R0–R4 of the
    /// block into that correction entry; G93 sets the row so that the
    /// programmed values become the tool's position (01 §5.6–5.7, 02 §1.4).
    fn write_table(&mut self, block: &BlockData, relative_to_tool: bool) {
        if !relative_to_tool
            && block.words.iter().any(|w| self.catalogue.role_of(w.letter) == Some(AddressRole::Offset))
        {
            let mut entry = self.corrections.entry(self.correction);
            for assignment in &block.assignments {
                let (Some(index), Some(Value::Literal(value))) = (assignment.index, &assignment.value) else {
                    continue;
                };
                let Some(raw) = arith::literal_raw(value).and_then(|raw| i32::try_from(raw).ok()) else { continue };
                // R0 is the radius (column 1), R1–R4 the lengths of axes 1–4.
                if index <= 4
                    && let Some(datum) = datum(&mut entry, index as usize + 1)
                {
                    *datum = raw;
                }
            }
            self.corrections.entries.insert(self.correction, entry);
            return;
        }
        let row = self.zero_offset_row();
        let mut values = self.offsets.offset(row);
        for word in block.words.iter().filter(|w| self.catalogue.role_of(w.letter) == Some(AddressRole::Axis)) {
            let (Some(index), Some(value)) =
                (self.machine.axes.iter().position(|&axis| axis == word.letter), self.number(word))
            else {
                continue;
            };
            let value = (value * 1000.0).round() as i32;
            values[index] = if relative_to_tool {
                let at = (self.position[slot(word.letter)] * 1000.0).round() as i32;
                values[index] + at - value
            } else {
                value
            };
        }
        self.offsets.rows.insert(row, values);
    }

    /// Follows the last step with radius compensation G41/G42 (02 §1.6–1.9):
    /// starts it on a line, passes each move in the plane to the
    /// [`Compensator`], cancels it on G40, and puts the tool-centre path's
    /// length and time on the steps it belongs to, one block late as the
    /// control's look-ahead fixes them.
    fn compensate(&mut self, start: Position, path: Path) -> Result<(), CompensationError> {
        let index = self.delivered + self.steps.len() - 1;
        let plane = match self.modes.active(self.groups.plane) {
            Some(18) => (b'Z', b'X'),
            Some(19) => (b'Y', b'Z'),
            _ => (b'X', b'Y'),
        };
        // Mirrored in one axis of the plane, the tool changes side.
        let flipped = self.recalculation.flips(plane);
        let side = match self.modes.active(self.groups.compensation) {
            Some(41) => Some(if flipped { Side::Right } else { Side::Left }),
            Some(42) => Some(if flipped { Side::Left } else { Side::Right }),
            _ => None,
        };
        let (a, b) = (slot(plane.0), slot(plane.1));
        let point = |position: &Position| Point2::new(position[a], position[b]);
        let (from, to) = (point(&start), point(&self.position));
        let moves_in_plane = from != to || matches!(path, Path::Arc { .. });
        let linear = matches!(self.step_mut(index).motion, Motion::Rapid | Motion::Feed) && path == Path::Straight;
        let pieces = match (self.compensator.take(), side) {
            (None, Some(side)) if moves_in_plane && linear => {
                let radius = f64::from(self.corrections.entry(self.correction).radius) / 1000.0;
                self.compensator = Some(Compensator::start(self.compensation, side, radius, index, from, to));
                self.compensated.push(Compensated { steps: index..index + 1, plane });
                return Ok(());
            }
            (Some(compensator), None) if moves_in_plane => compensator.cancel(index, to),
            (Some(mut compensator), _) => {
                let element = match path {
                    Path::Arc { centre, clockwise, .. } => {
                        Element::Arc { from, to, centre: Point2::new(centre[0], centre[1]), clockwise }
                    }
                    _ => Element::Line { from, to },
                };
                let pushed = if moves_in_plane { compensator.push(index, element) } else { Ok(Vec::new()) };
                // Kept on an error too, so that the run's end fixes the
                // element before the block the control stops at.
                self.compensator = Some(compensator);
                pushed?
            }
            (None, _) => return Ok(()),
        };
        // Compensation was in force when the block came.
        if let Some(compensated) = self.compensated.last_mut() {
            compensated.steps.end = index + 1;
        }
        self.charge(pieces);
        Ok(())
    }

    /// Ends radius compensation still in force where the run ends: the
    /// tool centre stays on the normal at the last programmed point
    /// ([`Compensator::finish`]), and the last element's length and time
    /// are those of its path there.
    fn finish_compensation(&mut self) {
        if let Some(compensator) = self.compensator.take() {
            self.charge(vec![compensator.finish()]);
        }
    }

    /// Puts the length and time of the tool-centre path's `pieces` on the
    /// steps they belong to, in place of the programmed ones.
    fn charge(&mut self, pieces: Vec<ToolElement>) {
        let Some(&Compensated { plane, .. }) = self.compensated.last() else { return };
        let (a, b) = (slot(plane.0), slot(plane.1));
        for piece in pieces {
            let length = piece.path.length();
            let step = self.step_mut(piece.block);
            let duration = match (step.motion, step.feed) {
                (Motion::Feed, Some(feed)) => length / (feed * piece.feed_scale) * 60.0,
                _ => {
                    let in_plane = |point: Point2<f64>| {
                        let mut position = [0.0; 26];
                        (position[a], position[b]) = (point.x, point.y);
                        position
                    };
                    self.rapid_seconds(&in_plane(piece.path.start()), &in_plane(piece.path.end()))
                }
            };
            // Pieces come in the order of their blocks, a block's over
            // one or two calls (its corner, then its contour): its first
            // one replaces the programmed length and time.
            let first = self.tool_centre.last().is_none_or(|last| last.block != piece.block);
            let step = self.step_mut(piece.block);
            if first {
                (step.length, step.duration) = (0.0, 0.0);
            }
            step.length += length;
            step.duration += duration;
            self.tool_centre.push(piece);
        }
    }

    /// Adds a step of the block at `range` that ends at `end`. Its start
    /// time follows from the durations when the run ends.
    /// Records a step; `functions` are its M functions and tool change.
    fn record(&mut self, range: TextRange, end: &Position, moved: Moved, stop: Option<Stop>, functions: Functions) {
        let Functions { m_functions, tool_change, mergeable } = functions;
        let Moved { motion, length, duration, feed, path } = moved;
        let (source, end, frame) = (self.source, self.machine_axes(end), self.frames.len() - 1);
        debug_assert!(
            [length, duration, feed.unwrap_or(0.0)].iter().chain(&end).all(|value| value.is_finite()),
            "no NaN or infinity leaves the executor: {end:?} {length} {duration} {feed:?}"
        );
        let joining = match self.modes.active(self.groups.joining) {
            Some(23) => Joining::Continuous,
            Some(24) => Joining::Tight,
            _ => Joining::Basic,
        };
        let step = Step {
            source,
            range,
            motion,
            path,
            duration,
            length,
            feed,
            end,
            frame,
            stop,
            joining,
            m_functions,
            tool_change,
            dynamic_set: self.dynamic_set,
            mergeable,
        };
        self.steps.push(step);
    }

    /// Step `index` of the run, not handed on yet.
    fn step_mut(&mut self, index: usize) -> &mut Step {
        &mut self.steps[index - self.delivered]
    }

    /// Hands `sink` the steps no later block can change: all at the `end`,
    /// else those before the first one radius compensation may still fix.
    fn deliver(&mut self, sink: &mut dyn StepSink, end: bool) {
        let open = match &self.compensator {
            Some(compensator) if !end => compensator.open_block() - self.delivered,
            _ => self.steps.len(),
        };
        // The pieces of the steps handed on so far come first; the others,
        // of the steps handed on now and of the open one, in the order
        // compensation fixed them.
        let first = self.tool_centre.partition_point(|piece| piece.block < self.delivered);
        self.delivered += open;
        let fresh = &mut self.tool_centre[first..];
        fresh.sort_by_key(|piece| piece.block);
        let fixed = first + fresh.partition_point(|piece| piece.block < self.delivered);
        sink.references(&self.frames, &self.compensated, &self.tool_centre[first..fixed]);
        if open == self.steps.len() {
            sink.steps(&mut self.steps);
        } else {
            self.steps.drain(..open).for_each(|step| sink.step(step));
        }
    }

    /// A position by letter over the machine's axes, as steps keep it.
    fn machine_axes(&self, position: &Position) -> Axes {
        transform::over_axes(position, &self.machine.axes)
    }

    /// The row of the zero-offset table in force (G53–G59): the block's
    /// own, else the modal one.
    fn zero_offset_row(&self) -> u8 {
        self.block_offset
            .or_else(|| self.modes.active(self.groups.zero_offset).and_then(|code| u8::try_from(code).ok()))
            .unwrap_or(53)
    }

    /// Runs a built-in cycle; `false` after reporting why it cannot run.
    fn built_in_cycle_or_stop(&mut self, number: u32, range: TextRange) -> bool {
        let result = self.built_in_cycle(number, range);
        if let Err(message) = &result {
            self.finding(range, message, true);
        }
        result.is_ok()
    }

    /// How many units the program writes per mm the axis `letter` moves:
    /// 2 on the diameter axis under diameter programming, else 1.
    fn written_per_unit(&self, letter: u8) -> f64 {
        if self.diameter && self.machine.diameter_axis == Some(letter) { 2.0 } else { 1.0 }
    }

    /// Runs one pass of a built-in fixed cycle from where the block ended
    /// and times its moves as steps of the block. Its F, S and spindle
    /// changes stay inside it (03 §1.4 I6). The error says why the
    /// control stops.
    fn built_in_cycle(&mut self, number: u32, range: TextRange) -> Result<(), String> {
        let spindle = match self.modes.active(self.groups.spindle) {
            Some(3) => Spindle::Clockwise,
            Some(4) => Spindle::CounterClockwise,
            Some(19) => Spindle::Oriented,
            _ => Spindle::Stopped,
        };
        // The cycles compute in the values as written (diameters under G74).
        let written = self.machine.diameter_axis.map(|axis| (slot(axis), self.written_per_unit(axis)));
        let scaled = |position: &Position, by: fn(f64, f64) -> f64| {
            let mut position = *position;
            if let Some((slot, factor)) = written {
                position[slot] = by(position[slot], factor);
            }
            position
        };
        let input = CycleInput {
            number,
            kind: CycleKind::of(self.machine.cycle_file.as_deref()),
            params: &self.params,
            position: scaled(&self.position, |value, factor| value * factor),
            incremental: self.incremental(),
            per_revolution: self.feed_mode().per_revolution,
            speed: self.speed,
            spindle,
            diameter: self.diameter,
        };
        let cycle = cycles::expand(&input)
            .map_err(|error: CycleError| format!("the fixed cycle G{number} cannot run: {error}"))?;
        let physical = |position: &Position| scaled(position, |value, factor| value / factor);
        let mut at = physical(&cycle.start);
        for step in &cycle.steps {
            let to = step.to().map_or(at, physical);
            if let Some(message) = self.unreachable(&to) {
                return Err(format!("the fixed cycle G{number}: {message}"));
            }
            let length = distance(&at, &to);
            let (motion, duration, feed, path) = match *step {
                CycleStep::Rapid { .. } => (Motion::Rapid, self.rapid_seconds(&at, &to), None, Path::Straight),
                CycleStep::Feed { .. } => {
                    let rate = step.feed_rate().map(|rate| rate * self.feed_factor()).filter(|&rate| rate > 0.0);
                    (Motion::Feed, rate.map_or(0.0, |rate| length / rate * 60.0), rate, Path::Straight)
                }
                CycleStep::Thread { thread, .. } => {
                    let minutes = thread_minutes(length, thread.lead, thread.speed);
                    let path = Path::Thread { lead: thread.lead, speed: thread.speed };
                    (Motion::Feed, minutes * 60.0, Some(length / minutes), path)
                }
                CycleStep::Dwell { seconds } => (Motion::Dwell, seconds, None, Path::Straight),
                CycleStep::Spindle { .. } => continue,
            };
            self.record(range, &to, Moved { motion, length, duration, feed, path }, None, Functions::default());
            at = to;
        }
        self.position = physical(&cycle.end());
        Ok(())
    }

    /// Seconds a rapid move takes: every real axis runs at its own rate,
    /// and the slowest to arrive sets the time.
    fn rapid_seconds(&self, start: &Position, end: &Position) -> f64 {
        let mut delta: Position = std::array::from_fn(|slot| end[slot] - start[slot]);
        self.frame().real_displacement(&mut delta);
        let minutes = (b'A'..=b'Z')
            .map(|letter| delta[slot(letter)].abs() / f64::from(self.machine.axis_rapid_rate(letter)))
            .fold(0.0, f64::max);
        minutes * 60.0
    }

    /// What a cycle of the cycle file keeps of the state before it: all of
    /// it, restored when the cycle's body returns (03 §1.4 I6).
    fn snapshot(&self) -> Snapshot {
        Snapshot {
            modes: self.modes.clone(),
            feed: self.feed,
            speed: self.speed,
            speed_limit: self.speed_limit,
            diameter: self.diameter,
            params: self.params.clone(),
        }
    }

    /// Back to the state before a cycle, where the cycle left the tool.
    fn restore(&mut self, snapshot: Snapshot) {
        Snapshot {
            modes: self.modes,
            feed: self.feed,
            speed: self.speed,
            speed_limit: self.speed_limit,
            diameter: self.diameter,
            params: self.params,
        } = snapshot;
        self.in_cycle = false;
    }

    fn finding(&mut self, range: TextRange, message: &str, fatal: bool) {
        self.findings.push(Finding { source: self.source, range, message: message.to_owned(), fatal });
    }

    /// Length, duration and feed of a block's move; `None` after
    /// reporting an error the control stops on.
    fn moved(&mut self, step: &Move<'_>) -> Option<Moved> {
        let (range, start, end) = (step.range, step.start, step.end);
        let straight = distance(&start, &end);
        let motion = self.modes.active(self.groups.motion);
        let moved = |motion, length, duration, feed, path| Some(Moved { motion, length, duration, feed, path });
        if motion == Some(0) {
            return moved(Motion::Rapid, straight, self.rapid_seconds(&start, &end), None, Path::Straight);
        }
        let arc = match motion {
            Some(2 | 3) => match self.arc(step, motion == Some(3)) {
                Ok(Some(arc)) => Some(arc),
                Ok(None) => return moved(Motion::Feed, straight, 0.0, None, Path::Straight),
                Err(()) => return None,
            },
            _ => None,
        };
        // The arc's sides may reach beyond a limit its ends keep within.
        if let Some(message) = arc.iter().flat_map(|arc| arc.sides(&end)).find_map(|side| self.unreachable(&side)) {
            self.finding(range, &format!("the arc's side: {message}"), true);
            return None;
        }
        let length = arc.as_ref().map_or(straight, Arc::length);
        let mode = self.feed_mode();
        // A thread's F is its lead, which M37 leaves alone.
        let feed = match motion {
            Some(33) => self.feed.map(|feed| feed.value(true)),
            _ => self.feed.map(|feed| feed.value(mode.per_revolution) * self.feed_factor()),
        };
        // Minutes, and the path feed in mm/min (the average where it varies).
        let timed = |minutes: f64| (minutes, length / minutes);
        let minutes = match (feed.filter(|&feed| feed > 0.0), mode) {
            (Some(lead), _) if motion == Some(33) => {
                (self.speed > 0.0).then(|| timed(thread_minutes(length, lead, self.speed)))
            }
            (Some(feed), FeedMode { per_revolution: false, .. }) => Some((length / feed, feed)),
            (Some(feed), FeedMode { per_revolution: true, css: false }) => {
                let rate = feed * self.speed;
                (rate > 0.0).then(|| (length / rate, rate))
            }
            (Some(feed), FeedMode { per_revolution: true, css: true }) => {
                self.css_minutes(step, arc.as_ref(), length, feed).map(timed)
            }
            (None, _) => None,
        };
        let path = match (&arc, feed) {
            (Some(arc), _) => Path::Arc {
                plane: (arc.plane.0 as u8 + b'A', arc.plane.1 as u8 + b'A'),
                centre: [arc.centre.x, arc.centre.y],
                clockwise: arc.sweep < 0.0,
            },
            (None, Some(lead)) if motion == Some(33) => Path::Thread { lead, speed: self.speed },
            _ => Path::Straight,
        };
        match minutes {
            Some((minutes, rate)) => moved(Motion::Feed, length, minutes * 60.0, Some(rate), path),
            None => {
                let why = match mode {
                    _ if feed.is_none_or(|feed| feed <= 0.0) => {
                        "no feed F programmed before this motion: G01–G03 need one"
                    }
                    _ if motion == Some(33) => "a thread (G33) with spindle speed S0: the axes cannot move",
                    FeedMode { css: true, .. } => {
                        "feed per revolution under constant cutting speed with cutting speed S0: the axes cannot move"
                    }
                    _ => "feed per revolution (G95) with spindle speed S0: the axes cannot move",
                };
                self.finding(range, why, false);
                moved(Motion::Feed, length, 0.0, None, path)
            }
        }
    }

    /// Feed units and constant cutting speed from group G6, with the swap
    /// of G96/G97 that machine constant 329 decade 3 selects (01 §6.9).
    fn feed_mode(&self) -> FeedMode {
        let swapped = matches!(self.css_setting, 1 | 3);
        match self.modes.active(self.groups.feed_units) {
            Some(95) => FeedMode { per_revolution: true, css: false },
            Some(96) => FeedMode { per_revolution: swapped, css: true },
            Some(97) => FeedMode { per_revolution: !swapped, css: true },
            _ => FeedMode { per_revolution: false, css: false },
        }
    }

    /// What the feed is multiplied by: M37 reduces it 1 : 100, M36 (the
    /// reset state) runs it as programmed (01 §6.6).
    fn feed_factor(&self) -> f64 {
        if self.modes.active(self.groups.feed_reduction) == Some(37) { 0.01 } else { 1.0 }
    }

    /// Why the control cannot move to `position` (program coordinates in
    /// the frame in force): an axis beyond what its address holds, or
    /// beyond its travel limits in machine coordinates, where the
    /// software limit switches work (03 §3.2).
    fn unreachable(&self, position: &Position) -> Option<String> {
        let axes = &self.machine.axes;
        let bounds = &self.axis_bounds[usize::from(self.diameter)];
        let beyond =
            axes.iter().zip(bounds).find(|&(&axis, &(low, high))| !(low..=high).contains(&position[slot(axis)]));
        if let Some((&axis, _)) = beyond {
            let letter = char::from(axis);
            // On a diameter axis the program holds the diameter.
            let written = position[slot(axis)] * self.written_per_unit(axis);
            let (min, max) = self.catalogue.address_of(axis).and_then(|address| address.bounds).unwrap_or_default();
            return Some(format!(
                "{letter} would reach {written:.3}, outside the range of `{letter}`: {min:.3} to {max:.3}: the control stops"
            ));
        }
        if self.machine.limits.is_empty() {
            return None;
        }
        let machine = self.frame().to_machine(&self.machine_axes(position), axes);
        for (&axis, &real) in axes.iter().zip(&machine) {
            let letter = char::from(axis);
            let limits = self.machine.limits.get(&axis).copied().unwrap_or_default();
            let beyond = |limit: Option<i32>, beyond: fn(f64, f64) -> bool| {
                limit.map(|limit| f64::from(limit) / 1000.0).filter(|&limit| beyond(round3(real), limit))
            };
            if let Some(limit) =
                beyond(limits.min, |value, min| value < min).or(beyond(limits.max, |value, max| value > max))
            {
                return Some(format!(
                    "{letter} would reach {real:.3} in machine coordinates, beyond its travel limit {limit:.3} (`limits` of the machine): the control stops at the software limit switch"
                ));
            }
        }
        None
    }

    fn incremental(&self) -> bool {
        self.modes.active(self.groups.dimensions) == Some(91)
    }

    /// Minutes a move takes with feed per revolution under constant cutting
    /// speed: the spindle turns at v / (2π r), r the distance of the
    /// controlling coordinate from the spindle axis, up to the `G76` limit
    /// (else 9999 rpm, the largest S); `None` when the cutting speed is 0.
    fn css_minutes(&mut self, step: &Move<'_>, arc: Option<&Arc>, length: f64, feed: f64) -> Option<f64> {
        // S in 0.1 m/min, or in m/min (decade 3 = 2 or 3); as mm/min.
        let per_unit = if matches!(self.css_setting, 2 | 3) { 1000.0 } else { 100.0 };
        let cutting_speed = self.speed * per_unit;
        if cutting_speed <= 0.0 {
            return None;
        }
        let limit = self.speed_limit.unwrap_or(MAX_SPINDLE_SPEED).min(MAX_SPINDLE_SPEED);
        // Machine constant 67 names the controlling coordinate by a code
        // the manual does not give; the run reads 1–6 as the axis number
        // and takes axis 1 otherwise.
        let axis = usize::try_from(self.machine.constant(67)).ok().filter(|n| (1..=6).contains(n)).unwrap_or(1);
        let letter = self.machine.axes.get(axis - 1).or(self.machine.axes.first()).copied().unwrap_or(b'X');
        let slot = slot(letter);
        let coordinate = |t: f64| {
            let straight = step.start[slot] + t * (step.end[slot] - step.start[slot]);
            arc.and_then(|arc| arc.coordinate(slot, t)).unwrap_or(straight)
        };
        let rpm = |t: f64| (cutting_speed / (std::f64::consts::TAU * coordinate(t).abs())).min(limit);
        self.speed_reached = Some(rpm(1.0));
        // Composite Simpson over the move: smooth except where the limit
        // sets in, where 512 intervals keep the error far below a µs.
        const INTERVALS: usize = 512;
        let h = 1.0 / INTERVALS as f64;
        let per_mm = |t: f64| 1.0 / (feed * rpm(t));
        let sum: f64 = (0..=INTERVALS)
            .map(|i| {
                let weight = if i == 0 || i == INTERVALS {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                weight * per_mm(i as f64 * h)
            })
            .sum();
        Some(length * sum * h / 3.0)
    }

    /// The arc of a G02/G03 block, or `None` after reporting why the block
    /// is not one; the error after reporting an end point the control
    /// stops on. Under a helix the axis of its lead turns with the arc.
    fn arc(&mut self, step: &Move<'_>, counter_clockwise: bool) -> Result<Option<Arc>, ()> {
        let Move { block, range, axes, start, end } = *step;
        let helix = self.helix_lead.filter(|_| self.modes.active(self.groups.joining) == Some(9));
        // Under a helix a word for its axis is not a coordinate of the arc.
        let mut letters: Vec<u8> = axes
            .iter()
            .map(|word| word.letter)
            .filter(|&letter| helix.is_none_or(|(axis, _)| axis != letter))
            .collect();
        letters.dedup();
        if letters.len() < 2 {
            let message = "an arc needs both coordinates of its plane, even when the end point equals the start";
            self.finding(range, message, false);
            return Ok(None);
        }
        // The plane's first axis is the one I measures along: X of XY, Y of
        // YZ, Z of ZX (01 §6.4).
        let (first, second) = plane(letters[0], letters[1]);
        let (a, b) = (usize::from(first - b'A'), usize::from(second - b'A'));
        // I and J are recalculated as the axes they measure along, and an
        // arc mirrored in one of its axes turns the other way.
        let centre_offset = |letter: u8, axis: u8| {
            let value = block.word(letter).and_then(|word| self.number(word)).unwrap_or(0.0);
            self.recalculation.apply(axis, value)
        };
        let counter_clockwise = counter_clockwise != self.recalculation.flips((first, second));
        let from = Vector2::new(start[a], start[b]);
        let to = Vector2::new(end[a], end[b]);
        let centre = from + Vector2::new(centre_offset(b'I', first), centre_offset(b'J', second));
        let (radius, end_radius) = ((from - centre).norm(), (to - centre).norm());
        let tolerance = self.machine.arc_tolerance();
        if (radius - end_radius).abs() > tolerance {
            let message = format!(
                "the end point does not lie on the circle: {} mm from the centre, the start {} mm, more than the tolerance {tolerance} mm apart: the control stops with error 7.56",
                round3(end_radius),
                round3(radius)
            );
            self.finding(range, &message, true);
            return Err(());
        }
        let angle_of = |point: Vector2<f64>| (point.y - centre.y).atan2(point.x - centre.x);
        let start_angle = angle_of(from);
        let mut sweep = angle_of(to) - start_angle;
        if counter_clockwise && sweep <= 0.0 {
            sweep += std::f64::consts::TAU;
        } else if !counter_clockwise && sweep >= 0.0 {
            sweep -= std::f64::consts::TAU;
        }
        // A third axis written in the block moves along with the arc; the
        // helix's axis travels its lead per full turn, whichever way the
        // arc turns (02 §4).
        let mut lead: f64 =
            letters[2..].iter().map(|&l| (end[usize::from(l - b'A')] - start[usize::from(l - b'A')]).powi(2)).sum();
        if let Some((axis, per_turn)) = helix.filter(|&(axis, _)| axis != first && axis != second) {
            let travel = per_turn * sweep.abs() / std::f64::consts::TAU;
            self.position[slot(axis)] = round3(start[slot(axis)] + travel);
            lead += (self.position[slot(axis)] - start[slot(axis)]).powi(2);
        }
        Ok(Some(Arc { plane: (a, b), centre, radius, start_angle, sweep, lead: lead.sqrt() }))
    }

    /// F as written: a literal, or a parameter's raw value read as digits
    /// without a point (`R26=0.200` is F200, 03 §1.6).
    fn programmed_feed(&self, word: &Word) -> Option<ProgrammedFeed> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => Some(ProgrammedFeed { value: decimal.to_f64(), point: decimal.has_point() }),
            value => self.raw(value).map(|raw| ProgrammedFeed { value: raw as f64, point: false }),
        }
    }

    /// A dimensional word's value: the literal as written (mm), or a
    /// parameter's raw thousandths.
    fn number(&self, word: &Word) -> Option<f64> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => Some(decimal.to_f64()),
            value => self.raw(value).map(|raw| raw as f64 / 1000.0),
        }
    }

    /// A dimensionless quantity (S in rpm, Q in 10 ms): the literal as
    /// written, or a parameter's raw digits (`R27=300` and `R27=0.300` are
    /// both S300, 03 §1.6).
    fn count(&self, word: &Word) -> Option<f64> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => Some(decimal.to_f64()),
            value => self.raw(value).map(|raw| raw as f64),
        }
    }

    /// A dimensionless word's whole number (codes, T): the literal, or a
    /// parameter's raw digits.
    fn integer(&self, word: &Word) -> Option<u32> {
        program_flow::integer(word, &self.params)
    }

    /// The raw value a parameter reference reads, sign applied.
    fn raw(&self, value: &Value) -> Option<Raw> {
        arith::reference(value, &self.params)
    }

    fn not_run(&mut self, what: &str, range: TextRange) {
        self.report_once(what, range, &format!("the executor does not run {what} yet: the time leaves them out"));
    }

    /// Reports a problem of kind `key` at its first place only.
    fn report_once(&mut self, key: &str, range: TextRange, message: &str) {
        if !self.reported.iter().any(|done| done == key) {
            self.reported.push(key.to_owned());
            self.finding(range, message, false);
        }
    }
}

/// What parameter arithmetic reads of the machine while a program runs:
/// the programmed positions (the measured ones are the machine
/// coordinates, as the run has no following error), the machine constants,
/// and the zero-offset and correction tables, which it may write.
///
/// The manual numbers the tables' columns without naming them; the run
/// reads an offset's column k as axis k, and a correction's column 1 as the
/// radius and columns 2–7 as the lengths of axes 1–6, in thousandths.
struct ProgramMachine<'r> {
    machine: &'r MachineConfig,
    position: &'r Position,
    frame: &'r Frame,
    offsets: &'r mut OffsetTable,
    corrections: &'r mut ToolTable,
    messages: &'r mut Vec<OperatorMessage>,
    /// The step of the block whose arithmetic runs.
    step: usize,
    registers: Registers<'r>,
}

/// What the block registers BWRK and AWRK (op 49 tables 4 and 5) hold of
/// the block that runs. The manual names their columns (M and G functions
/// by group, P, H, S, T, Q, D) but not how the two registers differ; the
/// arithmetic runs after the block's own codes took effect, so the run
/// reads both as the state then. P, H and Q, which the run does not keep,
/// are unknown.
struct Registers<'r> {
    modes: &'r Modes,
    speed: f64,
    tool: Option<u32>,
    correction: u8,
}

impl Registers<'_> {
    fn read(&self, group: u16, column: usize) -> Option<Raw> {
        let code = |letter: char| {
            let group = self.modes.find(&format!("{letter}{group}"))?;
            self.modes.active(group).map(Raw::from)
        };
        match column {
            1 => code('M'),
            2 => code('G'),
            5 => Some(self.speed.round() as Raw),
            6 => self.tool.map(Raw::from),
            8 => Some(Raw::from(self.correction)),
            _ => None,
        }
    }
}

impl ProgramMachine<'_> {
    fn axis_slot(&self, axis: u8) -> Option<usize> {
        Some(slot(*self.machine.axes.get(usize::from(axis).checked_sub(1)?)?))
    }
}

impl Machine for ProgramMachine<'_> {
    fn measured_position(&self, axis: u8) -> Option<Raw> {
        let index = usize::from(axis).checked_sub(1).filter(|&index| index < self.machine.axes.len())?;
        let axes = &self.machine.axes;
        let measured = self.frame.to_machine(&transform::over_axes(self.position, axes), axes);
        Some((measured.get(index)? * 1000.0).round() as Raw)
    }

    fn programmed_position(&self, axis: u8) -> Option<Raw> {
        Some((self.position[self.axis_slot(axis)?] * 1000.0).round() as Raw)
    }

    fn read_table(&self, table: u8, row: u16, column: u16) -> Option<Raw> {
        let column = usize::from(column);
        match table {
            1 => datum(&mut self.corrections.entry(u8::try_from(row).ok()?), column).map(|datum| Raw::from(*datum)),
            2 => {
                let row = u8::try_from(row).ok().filter(|row| (53..=59).contains(row))?;
                column.checked_sub(1).and_then(|axis| self.offsets.offset(row).get(axis).copied()).map(Raw::from)
            }
            3 => self.machine.known_constant(u32::from(row)),
            4 | 5 => self.registers.read(row, column),
            _ => None,
        }
    }

    fn write_table(&mut self, table: u8, row: u16, column: u16, value: Raw) {
        let (Ok(row), Ok(value), column) = (u8::try_from(row), i32::try_from(value), usize::from(column)) else {
            return;
        };
        match table {
            1 => {
                let mut entry = self.corrections.entry(row);
                if let Some(datum) = datum(&mut entry, column) {
                    *datum = value;
                    self.corrections.entries.insert(row, entry);
                }
            }
            2 if (53..=59).contains(&row) && (1..=6).contains(&column) => {
                let mut values = self.offsets.offset(row);
                values[column - 1] = value;
                self.offsets.rows.insert(row, values);
            }
            _ => {}
        }
    }

    fn message(&mut self, message: Message) {
        self.messages.push(OperatorMessage { step: self.step, message });
    }
}

/// Column `column` of a correction entry: 1 the radius, 2–7 the lengths of
/// axes 1–6.
fn datum(entry: &mut ToolEntry, column: usize) -> Option<&mut i32> {
    match column {
        1 => Some(&mut entry.radius),
        2..=7 => entry.lengths.get_mut(column - 2),
        _ => None,
    }
}

/// The index of an axis letter in a [`Position`].
pub(crate) fn slot(axis: u8) -> usize {
    usize::from(axis - b'A')
}

/// The groups the run reads, resolved once.
#[derive(Clone)]
struct Groups {
    motion: Group,
    joining: Group,
    feed_units: Group,
    cycle: Group,
    dimensions: Group,
    spindle: Group,
    zero_offset: Group,
    plane: Group,
    compensation: Group,
    feed_reduction: Group,
}

impl Groups {
    fn of(modes: &Modes) -> Groups {
        Groups {
            motion: modes.group("G0"),
            joining: modes.group("G2"),
            feed_units: modes.group("G6"),
            cycle: modes.group("G8"),
            dimensions: modes.group("G9"),
            spindle: modes.group("M2"),
            zero_offset: modes.group("G5"),
            plane: modes.group("G1"),
            compensation: modes.group("G3"),
            feed_reduction: modes.group("M4"),
        }
    }
}

/// Minutes a thread of `length` mm takes: the lead per revolution at
/// `speed` rpm, after waiting for the spindle's zero pulse, on average half
/// a revolution (01 §6.10).
fn thread_minutes(length: f64, lead: f64, speed: f64) -> f64 {
    length / (lead * speed) + 0.5 / speed
}

/// What a block's move did.
struct Moved {
    motion: Motion,
    length: f64,
    duration: f64,
    feed: Option<f64>,
    path: Path,
}

fn distance(start: &Position, end: &Position) -> f64 {
    (0..26).map(|i| (end[i] - start[i]).powi(2)).sum::<f64>().sqrt()
}

/// The state a fixed cycle of the cycle file restores when it returns.
struct Snapshot {
    modes: Modes,
    feed: Option<ProgrammedFeed>,
    speed: f64,
    speed_limit: Option<f64>,
    diameter: bool,
    params: Parameters,
}

/// F as written: `value` without a decimal point is mm/min or µm/rev,
/// with one m/min or mm/rev (01 §6.6).
#[derive(Debug, Clone, Copy, PartialEq)]
struct ProgrammedFeed {
    value: f64,
    point: bool,
}

impl ProgrammedFeed {
    /// mm/rev when `per_revolution`, else mm/min.
    fn value(self, per_revolution: bool) -> f64 {
        match (self.point, per_revolution) {
            (false, false) | (true, true) => self.value,
            (true, false) => self.value * 1000.0,
            (false, true) => self.value / 1000.0,
        }
    }
}

/// How F is read and the spindle turns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct FeedMode {
    /// F is per revolution (mm/rev) instead of per minute.
    per_revolution: bool,
    /// Constant cutting speed: S is a cutting speed, the spindle follows
    /// the controlling coordinate.
    css: bool,
}

/// The largest spindle speed S can program, the limit of constant cutting
/// speed without `G76` (the gear ranges' maxima are not configured).
const MAX_SPINDLE_SPEED: f64 = 9999.0;

/// An arc in the plane of axes (`a`, `b`) by slot, with a helix's lead.
struct Arc {
    plane: (usize, usize),
    centre: Vector2<f64>,
    radius: f64,
    start_angle: f64,
    /// Radians, positive counter-clockwise.
    sweep: f64,
    /// The travel of the other axes written, in mm.
    lead: f64,
}

impl Arc {
    fn length(&self) -> f64 {
        (self.radius * self.sweep).hypot(self.lead)
    }

    /// The points where the arc runs furthest along its plane's axes (at
    /// 0°, 90°, 180° and 270°) between its ends, the other axes at `end`.
    fn sides<'a>(&'a self, end: &'a Position) -> impl Iterator<Item = Position> + 'a {
        (0..4).filter_map(move |quarter| {
            let angle = f64::from(quarter) * std::f64::consts::FRAC_PI_2;
            let turned = if self.sweep > 0.0 { angle - self.start_angle } else { self.start_angle - angle };
            (turned.rem_euclid(std::f64::consts::TAU) < self.sweep.abs()).then(|| {
                let mut side = *end;
                side[self.plane.0] = round3(self.centre.x + self.radius * angle.cos());
                side[self.plane.1] = round3(self.centre.y + self.radius * angle.sin());
                side
            })
        })
    }

    /// The coordinate of slot `slot` at fraction `t` of the arc, when the
    /// slot is one of the plane's.
    fn coordinate(&self, slot: usize, t: f64) -> Option<f64> {
        let angle = self.start_angle + t * self.sweep;
        match slot {
            _ if slot == self.plane.0 => Some(self.centre.x + self.radius * angle.cos()),
            _ if slot == self.plane.1 => Some(self.centre.y + self.radius * angle.sin()),
            _ => None,
        }
    }
}

/// A block's move from `start` to `end`, by the axis words `axes`.
#[derive(Clone, Copy)]
struct Move<'b> {
    block: &'b BlockData,
    range: TextRange,
    axes: &'b [&'b Word],
    start: Position,
    end: Position,
}

/// The plane of two axes in the order I/J measure along them.
fn plane(one: u8, other: u8) -> (u8, u8) {
    match (one, other) {
        (b'X', b'Z') | (b'Z', b'X') => (b'Z', b'X'),
        (b'Z', b'Y') => (b'Y', b'Z'),
        (b'Y', b'X') => (b'X', b'Y'),
        pair => pair,
    }
}

/// A length on the control's µm grid.
/// Positions lie on the µm grid; half of one keeps float noise off the
/// bounds of the axes' ranges.
const HALF_MICROMETRE: f64 = 0.0005;

pub(crate) fn round3(value: f64) -> f64 {
    (value * 1000.0).round() / 1000.0
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use std::ops::ControlFlow;

    use ncc_syntax::TextSize;

    use super::{
        Axes, Called, Checkpoint, DELIVERY_BATCH, Environment, Motion, NoFiles, Path, Step, StepSink, Stop, Trace,
        resume_into, round3, run, run_into,
    };
    use crate::{
        machine::{MachineConfig, TravelLimits},
        tables::OffsetTable,
    };

    impl StepSink for Vec<Step> {
        fn step(&mut self, step: Step) {
            self.push(step);
        }
    }

    /// Takes steps until it has `room` of them, then is closed.
    struct Closing {
        taken: usize,
        room: usize,
    }

    impl StepSink for Closing {
        fn step(&mut self, _step: Step) {
            self.taken += 1;
        }

        fn closed(&self) -> bool {
            self.taken >= self.room
        }
    }

    #[test]
    fn a_streamed_run_ends_soon_after_its_sink_closes() {
        // Two nested loops: a million moves.
        let text = "%1\nN1 G91 G01 X1 F1000\nN2 X-1 G73 L1 Q999\nN3 Y.001 G73 L1 Q999\nN4 M30\n";
        let mut sink = Closing { taken: 0, room: 1 };
        let trace = run_into(text, &NoFiles, &MachineConfig::default(), 1_000_000, &mut sink);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert!(sink.taken <= 2 * DELIVERY_BATCH, "{} steps after the sink closed", sink.taken);
        assert!(trace.blocks_run <= 4 * DELIVERY_BATCH, "{} blocks run", trace.blocks_run);
    }

    #[test]
    fn a_streamed_run_hands_on_the_steps_a_kept_run_keeps() {
        // A compensated contour longer than a delivery batch, whose steps
        // compensation fixes a block late, then a loop of a subprogram.
        let mut text = String::from("%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\n");
        for i in 0..2200 {
            text.push_str(&format!("N{} X{} Y{}\n", 4 + i, (i + 1) * 2, (i % 2) * 3));
        }
        text.push_str("N3000 G40 X5000 Y-30\nN3001 G71 L5 Q40\nN3002 M30\nN3003 G79 L5\nN3004 G91 X1\nN3005 G90 G70\n");
        let kept = run(&text, &NoFiles, &MachineConfig::default(), 10_000);
        assert!(kept.findings.is_empty(), "{:?}", kept.findings);
        assert!(kept.steps.len() > 2 * DELIVERY_BATCH);
        let mut streamed = Vec::new();
        let trace = run_into(&text, &NoFiles, &MachineConfig::default(), 10_000, &mut streamed);
        assert!(trace.steps.is_empty());
        assert_eq!(streamed, kept.steps);
        assert_eq!(Trace { steps: streamed, ..trace }, kept);
    }

    /// The steps of a run after its first `before`, and a checkpoint
    /// every `every` blocks (none for 0).
    #[derive(Default)]
    struct Checkpoints {
        before: usize,
        steps: Vec<Step>,
        taken: Vec<Checkpoint>,
        every: usize,
    }

    impl StepSink for Checkpoints {
        fn step(&mut self, step: Step) {
            self.steps.push(step);
        }

        fn checkpoint_wanted(&mut self, block: usize, _offset: TextSize) -> bool {
            self.every > 0 && block.is_multiple_of(self.every)
        }

        fn checkpoint(&mut self, checkpoint: Checkpoint) -> ControlFlow<()> {
            assert_eq!(checkpoint.steps(), self.before + self.steps.len(), "every step before it is handed on");
            self.taken.push(checkpoint);
            ControlFlow::Continue(())
        }
    }

    /// Modal state, a parameter and a zero offset set early, then blocks
    /// in order, then a jump back and a subprogram call.
    fn resumable_program(first_x: &str) -> String {
        let mut text = format!("%1\nN1 G54 G90 G00 X{first_x} Y0 Z5 M03 S1000\nN2 R10=5.\nN3 G01 Z-1 F300\n");
        for i in 0..40 {
            text.push_str(&format!("N{} X{} YR10\n", 4 + i, i * 3));
        }
        text.push_str("N60 G91 X2\nN61 G90 G73 L30 Q2\nN62 G71 L7 Q2\nN63 M30\n");
        text.push_str("N70 G79 L7\nN71 G91 X1\nN72 G90 G70\n");
        text
    }

    #[test]
    fn a_run_resumed_from_a_checkpoint_goes_on_as_the_whole_run() {
        let machine = MachineConfig::default();
        let text = resumable_program("0");
        let mut whole = Checkpoints { every: 7, ..Checkpoints::default() };
        let trace = resume_into(None, &text, &NoFiles, &machine, 10_000, &mut whole);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        // Blocks 0, 7, …, 42: none once the jump has run.
        assert_eq!(whole.taken.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 7, 14, 21, 28, 35, 42]);
        for checkpoint in &whole.taken {
            let mut resumed = Checkpoints { before: checkpoint.steps(), every: 7, ..Checkpoints::default() };
            let trace = resume_into(Some(checkpoint), &text, &NoFiles, &machine, 10_000, &mut resumed);
            assert!(trace.findings.is_empty(), "{:?}", trace.findings);
            assert_eq!(resumed.steps, whole.steps[checkpoint.steps()..], "from block {}", checkpoint.block());
            let later: Vec<_> = whole.taken.iter().filter(|c| c.block() >= checkpoint.block()).collect();
            assert_eq!(resumed.taken.len(), later.len());
            for (again, first) in resumed.taken.iter().zip(later) {
                assert!(again.same_course(first) && again.offset() == first.offset());
            }
        }
    }

    #[test]
    fn checkpoints_after_an_edit_take_the_same_course_once_the_edit_no_longer_matters() {
        let machine = MachineConfig::default();
        let checkpoints = |text: &str| {
            let mut sink = Checkpoints { every: 7, ..Checkpoints::default() };
            resume_into(None, text, &NoFiles, &machine, 10_000, &mut sink);
            sink.taken
        };
        let before = checkpoints(&resumable_program("0"));
        // An absolute move written longer: the course is the same from the
        // next move on, three bytes later.
        let after = checkpoints(&resumable_program("1234"));
        for (after, before) in after.iter().zip(&before).skip(1) {
            let shifted = before.shifted(3, 0, 0);
            assert_eq!(after.offset(), shifted.offset());
            assert!(after.same_course(&shifted));
        }
        // Incremental coordinates carry the difference to the end.
        let incremental = checkpoints(&resumable_program("0").replace("N3 G01", "N3 G91 G01"));
        assert!(incremental.iter().zip(&before).skip(1).all(|(after, before)| !after.same_course(before)));
    }

    fn run_text(text: &str) -> Trace {
        run(text, &NoFiles, &MachineConfig::default(), 1000)
    }

    /// The macrocycle file L9001, and a cycle file, with the same text.
    struct Library(&'static str);

    impl Environment for Library {
        fn macrocycle(&self, number: u32) -> Option<String> {
            (number == 9001).then(|| self.0.to_owned())
        }

        fn cycle_file(&self, _name: &str) -> Option<String> {
            Some(self.0.to_owned())
        }
    }

    /// Durations (s) and lengths (mm) of the blocks, rounded to a
    /// microsecond and a micrometre.
    fn timing(trace: &Trace) -> Vec<(f64, f64)> {
        let round = |v: f64| (v * 1e6).round() / 1e6;
        trace.steps.iter().map(|step| (round(step.duration), round(step.length))).collect()
    }

    fn close(actual: f64, expected: f64) {
        assert!((actual - expected).abs() < 1e-9, "{actual} != {expected}");
    }

    #[test]
    fn rapid_and_linear_moves_take_length_over_rate() {
        let trace = run_text("%1\nN1 G00 X100 Y0\nN2 G01 X100 Y100 F600\nN3 X0 Y100 F1.2\nN4 M30\n");
        // Rapid: the longest axis travel over 10,000 mm/min; F600 is mm/min;
        // F1.2 (with a point) is m/min.
        assert_eq!(timing(&trace), [(0.6, 100.0), (10.0, 100.0), (5.0, 100.0), (0.0, 0.0)]);
        assert_eq!(trace.steps[1].feed, Some(600.0));
        assert_eq!(trace.steps[2].feed, Some(1200.0));
        close(trace.totals().total_time, 15.6);
        close(trace.totals().time(Motion::Rapid), 0.6);
        close(trace.totals().length(Motion::Feed), 200.0);
        let end = trace.end_position();
        assert_eq!([b'X', b'Y', b'Z'].map(|axis| end[usize::from(axis - b'A')]), [0.0, 100.0, 0.0]);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn feed_per_revolution_follows_the_spindle() {
        // F200 under G95 is 200 µm/rev, F0.5 is 0.5 mm/rev; at S500 that is
        // 100 and 250 mm/min.
        let trace = run_text("%1\nN1 G95 S500 G01 X10 F200\nN2 X20 F0.5\nN3 M30\n");
        assert_eq!(timing(&trace)[..2], [(6.0, 10.0), (2.4, 10.0)]);
        assert_eq!(trace.steps[1].feed, Some(250.0));
    }

    #[test]
    fn constant_cutting_speed_turns_the_spindle_by_the_radius() {
        use std::f64::consts::TAU;
        // G97: CSS with feed per revolution; S1000 is 100 m/min. Facing
        // from X50 to X10 at 0.2 mm/rev: the time is the integral of
        // 2πr / (f·v) over the path, 40 mm × 2π × 30 mm / (0.2 × 100,000).
        let text = "%1\nN1 G00 X50 Z0\nN2 G97 S1000 G01 X10 F0.2\nN3 G95 X20 F0.1\nN4 M30\n";
        let trace = run_text(text);
        close6(trace.steps[1].duration, 40.0 * TAU * 30.0 / (0.2 * 100_000.0) * 60.0);
        // When CSS ends without a new S, S keeps the speed reached at X10.
        let reached = 100_000.0 / (TAU * 10.0);
        close6(trace.steps[2].duration, 10.0 / (0.1 * reached) * 60.0);
        // With `G76 S1000` the spindle stops speeding up at the radius
        // where 100 m/min needs 1000 rpm.
        let text = "%1\nN1 G00 X50 Z0\nN2 G76 S1000\nN3 G97 S1000 G01 X10 F0.2\nN4 M30\n";
        let limit_radius = 100_000.0 / (TAU * 1000.0);
        let expected = TAU * (50.0f64.powi(2) - limit_radius.powi(2)) / 2.0 / (0.2 * 100_000.0)
            + (limit_radius - 10.0) / (0.2 * 1000.0);
        close6(run_text(text).steps[2].duration, expected * 60.0);
        // G96 is CSS with feed per minute: the spindle does not change the time.
        let trace = run_text("%1\nN1 G00 X50\nN2 G96 S1000 G01 X10 F200\nN3 M30\n");
        close6(trace.steps[1].duration, 12.0);
        // Machine constant 329 decade 3 = 3 swaps G96/G97 and reads S in
        // m/min: the manual's `G96 G1 F200 S90 X50` is 90 m/min, 0.2 mm/rev.
        let mut machine = MachineConfig::default();
        machine.constants.insert(329, 300);
        let text = "%1\nN1 G00 X100\nN2 G96 G1 F200 S90 X50\nN3 M30\n";
        let trace = run(text, &NoFiles, &machine, 100);
        close6(trace.steps[1].duration, 50.0 * TAU * 75.0 / (0.2 * 90_000.0) * 60.0);
    }

    #[test]
    fn diameter_programming_halves_the_diameter_axis() {
        use std::f64::consts::TAU;
        let lathe = MachineConfig {
            axes: b"XZ".to_vec(),
            diameter_axis: Some(b'X'),
            cycle_file: Some("PEVNECY5.NCP".to_owned()),
            ..MachineConfig::default()
        };
        let run_lathe = |text: &str| run(text, &NoFiles, &lathe, 1000);
        let text = "%1\nN1 G00 X40 Z0\nN2 G01 X50 F600\nN3 G91 X10\nN4 G90 G75 X20\nN5 G74 X20.001\nN6 G04 Q1\nN7 X30\nN8 M30\n";
        let trace = run_lathe(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
        // G74 is the lathe's start; G04 in group G10 does not end it.
        assert_eq!(x[..7], [20.0, 25.0, 30.0, 20.0, 10.0005, 10.0005, 15.0]);
        assert_eq!(timing(&trace)[1], (0.5, 5.0));
        // Constant cutting speed turns by the radius: facing from Ø100 to
        // Ø20 takes what it takes from radius 50 to 10.
        let trace = run_lathe("%1\nN1 G00 X100 Z0\nN2 G97 S1000 G01 X20 F0.2\nN3 M30\n");
        close6(trace.steps[1].duration, 40.0 * TAU * 30.0 / (0.2 * 100_000.0) * 60.0);
        // A built-in lathe cycle computes in diameters and runs in radii:
        // G82's first chip ends at Ø62 (see the cycles' own test).
        let text = "%1\nN1 G00 X104 Z2\nN2 R24=-4. R25=-2. R26=200 R27=0.001 R28=3. R29=2. R30=-40. R31=-10. G82\nN3 G80 M30\n";
        let trace = run_lathe(text);
        let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
        assert_eq!(x[2..6], [52.0, 31.0, 31.0, 52.0]);
    }

    fn close6(actual: f64, expected: f64) {
        assert!((actual - expected).abs() < 1e-6 * expected.abs().max(1.0), "{actual} != {expected}");
    }

    #[test]
    fn program_stops_are_marked_on_their_block() {
        let trace = run_text("%1\nN1 G00 X1 M00\nN2 M01\nN3 M30\n");
        let stops: Vec<Option<Stop>> = trace.steps.iter().map(|step| step.stop).collect();
        assert_eq!(stops, [Some(Stop::Program), Some(Stop::Optional), None]);
    }

    #[test]
    fn a_thread_turns_at_its_lead_after_the_zero_pulse() {
        // 15 mm at 1.5 mm/rev and S500: 0.02 min, plus half a revolution's
        // wait for the zero pulse, 0.001 min.
        let trace = run_text("%1\nN1 S500 M03 G00 X10 Z0\nN2 G33 Z-15. F1.5\nN3 M30\n");
        close6(trace.steps[1].duration, (0.02 + 0.001) * 60.0);
        assert_eq!(trace.steps[1].motion, Motion::Feed);
    }

    /// Drilling at X20 and X30 with G81 (RA Z2, RB Z-10, RC Z5, R26 F100),
    /// cancelled by G80 at X40.
    const DRILLING: &str = "%1\nN1 R26=100 R27=1000 R30=2. R31=-10. R32=5. M03\nN2 G00 X10 Y10 Z5\nN3 G81 X20\nN4 X30\nN5 G80 X40\nN6 M30\n";

    /// What each step did: the block's line, the motion and Z at its end.
    fn drilled(trace: &Trace) -> Vec<(String, Motion, f64)> {
        let z = usize::from(b'Z' - b'A');
        trace
            .steps
            .iter()
            .map(|s| (DRILLING[s.range].split(' ').next().unwrap().to_owned(), s.motion, trace.position(&s.end)[z]))
            .collect()
    }

    #[test]
    fn a_built_in_cycle_runs_after_each_block_until_g80() {
        let trace = run_text(DRILLING);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let n = |s: &str| s.to_owned();
        let drill = |block: &str| {
            [(n(block), Motion::Rapid, 2.0), (n(block), Motion::Feed, -10.0), (n(block), Motion::Rapid, 5.0)]
        };
        let mut expected =
            vec![(n("N1"), Motion::None, 0.0), (n("N2"), Motion::Rapid, 5.0), (n("N3"), Motion::Rapid, 5.0)];
        expected.extend(drill("N3"));
        expected.push((n("N4"), Motion::Rapid, 5.0));
        expected.extend(drill("N4"));
        expected.extend([(n("N5"), Motion::Rapid, 5.0), (n("N6"), Motion::None, 5.0)]);
        assert_eq!(drilled(&trace), expected);
        // 12 mm at F100, twice.
        close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 100.0 * 60.0);
    }

    #[test]
    fn a_cycle_file_body_runs_and_the_state_before_it_returns() {
        // The body feeds with G01 and R26; back in the program, G00 and no
        // F are in force again, so N4 and N5 are rapids.
        let body = "\"$PC\nN1 G79 L81\nN2 G00 G90 ZR30\nN3 G01 ZR31 FR26\nN4 G00 G70 ZR32\n*\n";
        let machine = MachineConfig { cycle_file: Some("PC.NCP".to_owned()), ..MachineConfig::default() };
        let trace = run(DRILLING, &Library(body), &machine, 1000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert_eq!(trace.files, [Called::CycleFile]);
        let lines: Vec<(usize, Motion)> = trace.steps.iter().map(|s| (s.source, s.motion)).collect();
        let body_steps = [(1, Motion::Rapid), (1, Motion::Feed), (1, Motion::Rapid)];
        let mut expected = vec![(0, Motion::None), (0, Motion::Rapid), (0, Motion::Rapid)];
        expected.extend(body_steps);
        expected.push((0, Motion::Rapid));
        expected.extend(body_steps);
        expected.extend([(0, Motion::Rapid), (0, Motion::None)]);
        assert_eq!(lines, expected);
        close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 100.0 * 60.0);
        // The block's own flow goes on after the body: a jump that repeats
        // the drilling block once, then M30 in a drilling block.
        let text = "%1\nN1 R26=100 R27=1000 R30=2. R31=-10. R32=5. M03\nN2 G00 G81 X20\nN3 G91 X10 G73 L3 Q1\nN4 X10 M30\nN5 X500\n";
        let trace = run(text, &Library(body), &machine, 1000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let drilled_at: Vec<f64> = trace
            .steps
            .iter()
            .filter(|step| step.motion == Motion::Feed)
            .map(|step| trace.axis(&step.end, b'X'))
            .collect();
        assert_eq!(drilled_at, [20.0, 30.0, 40.0, 50.0]);
        // Without the file, the built-in cycle runs and says why.
        let trace = run(DRILLING, &NoFiles, &machine, 1000);
        let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
        assert_eq!(
            messages,
            ["the cycle file PC.NCP the machine names is not in the project: the built-in cycle runs instead"]
        );
        close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 100.0 * 60.0);
    }

    /// Lengths of the steps, to the micrometre.
    fn lengths(trace: &Trace) -> Vec<f64> {
        trace.steps.iter().map(|step| (step.length * 1000.0).round() / 1000.0).collect()
    }

    #[test]
    fn zero_offsets_move_the_program_zero() {
        // G54 is X+100: the same programmed X10 is 100 mm further.
        let mut machine = MachineConfig::default();
        (machine.offsets, _) = OffsetTable::parse("$POS\nG54: X=100.0\n", &machine.axes);
        let trace = run("%1\nN1 G00 X10\nN2 G54 X10\nN3 M30\n", &NoFiles, &machine, 100);
        assert_eq!(lengths(&trace)[..2], [10.0, 100.0]);
        assert_eq!([trace.axis(&trace.steps[1].end, b'X'), trace.axis(&trace.machine_end(1), b'X')], [10.0, 110.0]);
        assert_eq!(trace.axis(&trace.start_of(1), b'X'), -90.0);

        // G92 writes the G55 row and moves nothing; the offset holds from
        // the next block.
        let trace = run_text("%1\nN1 G55 G92 X100.5 Y200.\nN2 G00 X0 Y0\nN3 M30\n");
        assert_eq!(lengths(&trace)[..2], [0.0, 223.831]); // √(100.5² + 200²)

        // G93 X10. at X30 puts the program zero 10 mm behind the tool: the
        // row becomes 0 + 30 − 10 = 20 (01 §5.7, case 2).
        let trace = run_text("%1\nN1 G00 X30\nN2 G55 G93 X10.\nN3 G00 X10\nN4 X0\nN5 M30\n");
        assert_eq!(lengths(&trace)[..4], [30.0, 0.0, 0.0, 10.0]);
        assert_eq!(trace.axis(&trace.machine_end(3), b'X'), 20.0);
    }

    #[test]
    fn length_corrections_shift_the_path_from_their_first_linear_block() {
        // D1 has Z length 50: `&0010` adds it to Z (axis 3) in the next G00
        // block; `&0` takes it off again.
        let text = "%1\nN1 G92 D1 R3=50.\nN2 D1 &0010 G00 Z0\nN3 Z10\nN4 &0\nN5 Z10\nN6 M30\n";
        let trace = run_text(text);
        assert_eq!(lengths(&trace)[..5], [0.0, 50.0, 10.0, 0.0, 50.0]);
        assert_eq!(trace.axis(&trace.machine_end(2), b'Z'), 60.0);
    }

    #[test]
    fn radius_compensation_runs_the_tool_centre_path() {
        // Radius 5 on the left (G41) of a corner turning left: the start
        // move ends on the first line's normal at (0, 5), the inside corner
        // is the intersection (45, 5), the last line ends on its normal at
        // (45, 50), and G40 leaves from there for (70, 70).
        let text =
            "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 Y50\nN6 G40 X70 Y70\nN7 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert_eq!(lengths(&trace)[..6], [0.0, 20.0, 25.0, 45.0, 45.0, 32.016]);
        close6(trace.steps[5].duration, 25.0f64.hypot(20.0) / 10.0);
        close6(trace.totals().total_time, 20.0 / 10_000.0 * 60.0 + (25.0 + 45.0 + 45.0 + 25.0f64.hypot(20.0)) / 10.0);
        // An arc too small for the tool on its inside stops the run there.
        let text = "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 G03 X0 Y6 I0 J3\nN5 G40 G01 X0 Y20\nN6 M30\n";
        let trace = run_text(text);
        let fatal: Vec<&str> = trace.findings.iter().filter(|f| f.fatal).map(|f| text[f.range].trim_end()).collect();
        assert_eq!(fatal, ["N4 G03 X0 Y6 I0 J3"]);
    }

    #[test]
    fn mirroring_reverses_axes_arcs_and_the_compensation_side() {
        let trace = run_text("%1\nN1 G35 X0\nN2 G01 X10 Y5 F600\nN3 G02 X20 Y5 I5 J0\nN4 G34\nN5 G01 X0 Y0\nN6 M30\n");
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let ends: Vec<(f64, f64)> =
            trace.steps.iter().map(|step| (trace.axis(&step.end, b'X'), trace.axis(&step.end, b'Y'))).collect();
        assert_eq!(ends[..5], [(0.0, 0.0), (-10.0, 5.0), (-20.0, 5.0), (-20.0, 5.0), (0.0, 0.0)]);
        // The clockwise half circle over the top turns counter-clockwise
        // about the mirrored centre, still over the top.
        assert_eq!(trace.steps[2].path, Path::Arc { plane: (b'X', b'Y'), centre: [-15.0, 5.0], clockwise: false });
        close6(trace.steps[2].length, PI * 5.0);
        // Compensation G41 on the mirrored contour runs on the right: the
        // tool-centre path is the mirror image, with the same lengths.
        let text = "%1\nN10 G35 X0\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 Y50\nN6 G40 X70 Y70\nN7 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert_eq!(lengths(&trace)[1..7], [0.0, 20.0, 25.0, 45.0, 45.0, 32.016]);
    }

    #[test]
    fn scale_multiplies_the_programmed_lengths() {
        let trace = run_text("%1\nN1 G36 X2\nN2 G01 X10 F600\nN3 G36 X1 Y4\nN4 G91 X8\nN5 G36\nN6 X1\nN7 M30\n");
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
        assert_eq!(x[..6], [0.0, 20.0, 20.0, 22.0, 22.0, 23.0]);
        assert_eq!(timing(&trace)[1], (2.0, 20.0));
        // A scale of 0 stops the run at its G36.
        let text = "%1\nN1 G36 X1 Y0\nN2 G01 X10 F600\nN3 M30\n";
        let trace = run_text(text);
        let fatal: Vec<&str> = trace.findings.iter().filter(|f| f.fatal).map(|f| &text[f.range]).collect();
        assert_eq!(fatal, ["G36"]);
        assert_eq!(trace.steps.len(), 0);
    }

    #[test]
    fn the_independent_offset_adds_to_the_zero_offset() {
        let trace = run_text("%1\nN1 G37 X10 Y-5\nN2 G00 X1 Y1\nN3 G37\nN4 G00 X1 Y1\nN5 M30\n");
        let machine = |index: usize| {
            let end = trace.machine_end(index);
            (trace.axis(&end, b'X'), trace.axis(&end, b'Y'))
        };
        // The tool stays at the machine zero when G37 comes: its program
        // position moves the other way.
        assert_eq!(
            [machine(0), machine(1), machine(2), machine(3)],
            [(0.0, 0.0), (11.0, -4.0), (11.0, -4.0), (1.0, 1.0)]
        );
        assert_eq!(trace.axis(&trace.start_of(1), b'X'), -10.0);
        assert_eq!(lengths(&trace)[..4], [0.0, 137f64.sqrt(), 0.0, 125f64.sqrt()].map(round3));
    }

    #[test]
    fn a_planar_transformation_turns_the_real_axes() {
        // The real system turned 90° and shifted by (10, 0): the program
        // runs in fictive coordinates, the axes move in real ones.
        let machine = MachineConfig { rapid_rates: [(b'X', 5_000)].into(), ..MachineConfig::default() };
        let text =
            "%1\nN1 G38 X10 Y0 I90\nN2 G38\nN3\nN4 G00 X10 Y10\nN5 G01 X20 F600\nN6 G38 I0\nN7\nN8 G01 X0 Y0\nN9 M30\n";
        let trace = run(text, &NoFiles, &machine, 100);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let at = |values: Axes| (round3(trace.axis(&values, b'X')), round3(trace.axis(&values, b'Y')));
        // Activated at the machine zero, the tool is at fictive (10, 0).
        assert_eq!(at(trace.steps[2].end), (10.0, 0.0));
        assert_eq!(at(trace.machine_end(2)), (0.0, 0.0));
        // Fictive Y is real X, which rapids at half the rate.
        assert_eq!(at(trace.machine_end(3)), (10.0, 0.0));
        assert_eq!(timing(&trace)[3], (0.12, 10.0));
        assert_eq!(at(trace.machine_end(4)), (10.0, -10.0));
        // Cancelled, the program takes the real position again.
        assert_eq!(at(trace.steps[6].end), (10.0, -10.0));
        assert_eq!(lengths(&trace)[..8], [0.0, 0.0, 0.0, 10.0, 10.0, 0.0, 0.0, 200f64.sqrt()].map(round3));
    }

    #[test]
    fn the_spatial_transformation_and_what_the_control_refuses() {
        let text = "%1\nN1 G31 X0 Y0 Z0 I0 J0 K9000 E100\nN2 G31\nN3\nN4 G01 X10 F600\nN5 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let end = trace.machine_end(3);
        let real = [b'X', b'Y', b'Z'].map(|axis| round3(trace.axis(&end, axis)));
        assert_eq!(real, [0.0, -10.0, 0.0]);
        // Activating without parameters goes on without it; setting them
        // while active stops the run.
        let text = "%1\nN1 G39\nN2 G39 X0 Y0 I30\nN3 G39\nN4 G39 X1 Y1 I30\nN5 M30\n";
        let trace = run_text(text);
        let findings: Vec<(&str, bool)> = trace.findings.iter().map(|f| (text[f.range].trim_end(), f.fatal)).collect();
        assert_eq!(findings, [("G39", false), ("G39", true)]);
        assert_eq!(&text[trace.findings[1].range.start().into()..][..2], "G3");
        assert!(trace.findings[1].message.contains("cannot change while it is active"));
    }

    #[test]
    fn operation_51_messages_are_kept_with_their_block() {
        use crate::arith::{Message, MessageDisplay};
        let trace = run_text("%1\nN1 G00 X10\nN2 R30=12.5 R5=51073053 G26\nN3 R5=51073050 G26\nN4 M30\n");
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let shown: Vec<(usize, Message)> = trace.messages.iter().map(|m| (m.step, m.message)).collect();
        let message = |value, display| Message { code: 7, parameter: 30, value, display };
        assert_eq!(
            shown,
            [
                (1, message(Some(12_500), MessageDisplay::Seconds(5))),
                (2, message(Some(12_500), MessageDisplay::Cancel))
            ]
        );
    }

    #[test]
    fn operation_49_reads_the_block_registers() {
        // S into R26 (F800), the motion code into R20 (G01), the spindle's
        // M code into R21 (M04), T into R22 and D into R23; dwells show them.
        let text = "%1\nN1 S800 M04 T3 D2\nN2 R5=49550026 G26\nN3 G01 X10 FR26\nN4 R5=49520020 R6=49510221 R7=49560022 R8=49580023 G29\nN5 G00 X0\nN6 GR20 X10\nN7 G04 QR21\nN8 G04 QR22\nN9 G04 QR23\nN10 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let times: Vec<f64> = timing(&trace).iter().map(|&(duration, _)| duration).collect();
        assert_eq!(times[2], 0.75);
        assert_eq!((trace.steps[5].motion, times[5]), (Motion::Feed, 0.75));
        assert_eq!(times[6..9], [0.04, 0.03, 0.02]);
    }

    #[test]
    fn g23_i_selects_the_dynamic_set_and_steps_tell_which_lines_may_merge() {
        let trace = run_text(
            "%1\nN1 G23 I2 G01 X10 F600\nN2 X20\nN3 G23 I1 X30\nN4 G23 I7 X40\nN5 X40.003\nN6 X41 S500\nN7 G91 X1\nN8 G90 G00 X0\nN9 M30\n",
        );
        let sets: Vec<u8> = trace.steps.iter().map(|step| step.dynamic_set).collect();
        assert_eq!(sets, [2, 2, 1, 1, 1, 1, 1, 1, 1]);
        let mergeable: Vec<bool> = trace.steps.iter().map(|step| step.mergeable).collect();
        assert_eq!(mergeable, [false, true, true, true, true, false, false, false, false]);
        let messages: Vec<&str> = trace.findings.iter().map(|finding| finding.message.as_str()).collect();
        assert_eq!(messages, ["G23 I7: the dynamic sets are I1 to I4: the set in force stays"]);
    }

    #[test]
    fn incremental_moves_add_to_the_position() {
        let trace = run_text("%1\nN1 G91 G01 X10 Y10 F600\nN2 X10\nN3 G90 X0\nN4 M30\n");
        let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
        assert_eq!(x, [10.0, 20.0, 0.0, 0.0]);
    }

    #[test]
    fn arcs_run_the_way_their_code_turns() {
        let r = 10.0;
        // From (10,0) about the origin to (0,10): a quarter counter-clockwise,
        // three quarters clockwise; back to the start is a full circle.
        let trace = run_text(
            "%1\nN1 G00 X10 Y0\nN2 G03 X0 Y10 I-10 F600\nN3 G00 X10 Y0\nN4 G02 X0 Y10 I-10\nN5 G00 X10 Y0\nN6 G02 X10 Y0 I-10\nN7 M30\n",
        );
        let lengths: Vec<f64> = trace.steps.iter().map(|step| step.length).collect();
        close(lengths[1], PI * r / 2.0);
        close(lengths[3], 3.0 * PI * r / 2.0);
        close(lengths[5], 2.0 * PI * r);
        close(trace.steps[5].duration, 2.0 * PI * r / 600.0 * 60.0);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn in_the_zx_plane_i_measures_along_z() {
        // The manual's example 7b: from Z500 to Z100 about Z300, radius 200.
        let trace = run_text("%1\nN1 G00 X100 Z500\nN2 G03 G90 X100.0 Z100.0 I-200.0 F1000\nN3 M30\n");
        close(trace.steps[1].length, PI * 200.0);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn a_helix_adds_its_lead() {
        let trace = run_text("%1\nN1 G00 X10 Y0 Z0\nN2 G03 X10 Y0 Z5 I-10 F600\nN3 M30\n");
        close(trace.steps[1].length, ((2.0 * PI * 10.0f64).powi(2) + 25.0).sqrt());
    }

    #[test]
    fn bad_arcs_and_missing_feed_are_reported_where_they_are() {
        let text = "%1\nN1 G01 X10\nN2 G02 X5\nN3 G02 X20 Y0 I3 F100\nN4 M30\n";
        let trace = run_text(text);
        let found: Vec<(&str, &str, bool)> = trace
            .findings
            .iter()
            .map(|f| (&text[f.range], f.message.split(':').next().unwrap_or(""), f.fatal))
            .collect();
        assert_eq!(
            found,
            [
                ("N1 G01 X10\n", "no feed F programmed before this motion", false),
                (
                    "N2 G02 X5\n",
                    "an arc needs both coordinates of its plane, even when the end point equals the start",
                    false
                ),
                ("N3 G02 X20 Y0 I3 F100\n", "the end point does not lie on the circle", true),
            ]
        );
        // The control stops with error 7.56 before the arc runs.
        assert_eq!(lines_run(text, &trace), ["N1 G01 X10", "N2 G02 X5"]);
        assert!(trace.steps.iter().all(|step| step.duration == 0.0));
    }

    #[test]
    fn machine_constant_55_widens_the_arc_end_tolerance() {
        // The end point lies 3 µm outside the circle of radius 10.
        let text = "%1\nN1 G00 X10 Y0\nN2 G02 X-10.003 Y0 I-10 F100\nN3 M30\n";
        let stopped = run_text(text);
        assert_eq!(stopped.findings.iter().filter(|f| f.fatal).count(), 1, "{:?}", stopped.findings);
        assert_eq!(stopped.steps.len(), 1);
        let machine = MachineConfig { constants: [(55, 5)].into(), ..MachineConfig::default() };
        let trace = run(text, &NoFiles, &machine, 100);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert_eq!(trace.steps.len(), 3);
    }

    #[test]
    fn a_block_with_motion_and_g04_moves_then_dwells() {
        // 15 mm at F100 take 9 s, then 300 × 10 ms.
        let text = "%1\nN1 G00 X0 Y0 Z5\nN2 G01 Z-10 F100 G04 Q300\nN3 G00 Z5\nN4 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let motions: Vec<(String, Motion)> =
            trace.steps.iter().map(|step| (text[step.range].trim_end().to_owned(), step.motion)).collect();
        let n2 = "N2 G01 Z-10 F100 G04 Q300".to_owned();
        assert_eq!(motions[1..3], [(n2.clone(), Motion::Feed), (n2, Motion::Dwell)]);
        assert_eq!(timing(&trace)[1..4], [(9.0, 15.0), (3.0, 0.0), (0.09, 15.0)]);
        assert_eq!(trace.axis(&trace.steps[2].end, b'Z'), -10.0);
        // The manual's G82 of the cycle file drills, then dwells at the
        // bottom (R29 = 250: 2.5 s).
        let body = "\"$PC\nN1 G79 L82\nN2 G00 G90 ZR30 FR26 SR27\nN3 G01 ZR31 G04 QR29\nN4 G00 ZR32\nN5 G70\n*\n";
        let machine = MachineConfig { cycle_file: Some("PC.NCP".to_owned()), ..MachineConfig::default() };
        let text =
            "%1\nN1 R26=100 R27=1000 R29=250 R30=2. R31=-10. R32=5. M03\nN2 G00 X10 Y10 Z5\nN3 G82 X20\nN4 G80 M30\n";
        let trace = run(text, &Library(body), &machine, 1000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let body_steps: Vec<(Motion, f64, f64)> = trace
            .steps
            .iter()
            .filter(|step| step.source == 1)
            .map(|step| (step.motion, round3(step.duration), trace.axis(&step.end, b'Z')))
            .collect();
        assert_eq!(
            body_steps,
            [
                (Motion::Rapid, 0.018, 2.0),
                (Motion::Feed, 7.2, -10.0),
                (Motion::Dwell, 2.5, -10.0),
                (Motion::Rapid, 0.09, 5.0),
                (Motion::None, 0.0, 5.0),
            ]
        );
        // The manual's G86 pecks R28 deeper each time and dwells there.
        let body = "\"$PC\nN1 G79 L86\nN3 FR26 SR27\n   G27 R5=07280028\n       R6=16313034\nN4 GR34 L100\nN10 G00 G90 ZR30\n    G26 R5=00300024\nN20 G27 R5=02242824\n        R6=15312423\nN30 GR23 L60\nN40 G01  ZR24 G04 QR29\nN50 G73 L20 Q9998\nN60 ZR31\nN70 G70 G00 ZR32\n*\n";
        let text = "%1\nN1 R26=100 R27=1000 R28=3. R29=50 R30=2. R31=-10. R32=5. M03\nN2 G00 X10 Y10 Z5\nN3 G86 X20\nN4 G80 M30\n";
        let trace = run(text, &Library(body), &machine, 1000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let pecks: Vec<(Motion, f64)> = trace
            .steps
            .iter()
            .filter(|step| matches!(step.motion, Motion::Feed | Motion::Dwell))
            .map(|step| (step.motion, trace.axis(&step.end, b'Z')))
            .collect();
        let (feed, dwell) = (Motion::Feed, Motion::Dwell);
        let expected = [(feed, -1.0), (dwell, -1.0), (feed, -4.0), (dwell, -4.0), (feed, -7.0), (dwell, -7.0)];
        // The last peck reaches R31, where N60's feed ends too.
        assert_eq!(pecks[..6], expected);
        assert_eq!(pecks[6..], [(feed, -10.0), (dwell, -10.0), (feed, -10.0)]);
    }

    #[test]
    fn g58_and_g59_hold_in_their_own_block_and_g92_writes_their_row() {
        let text = "%1\nN1 G55 G92 X10.\nN2 G58 G92 X100.\nN3 G59 G92 X200.\nN4 G00 X0\nN5 G58 X0\nN6 X0\nN7 G59 X0\nN8 X0\nN9 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let machine_x: Vec<f64> = (3..8).map(|step| trace.axis(&trace.machine_end(step), b'X')).collect();
        assert_eq!(machine_x, [10.0, 100.0, 10.0, 200.0, 10.0]);
    }

    #[test]
    fn a_helix_drives_its_lead_axis_by_the_turns_of_the_arc() {
        use std::f64::consts::TAU;
        // The manual's helix: lead 1.05 mm on Z, a full circle of radius
        // 100 run 21 times (Q20), then a half circle; after G98 an arc
        // leaves Z alone.
        let text = "%1\nN5 X0 Y0 Z0 G00\nN10 Z1.05 G10\nN50 G09 G02 X0 Y0 I100 G73 L50 Q20 F1000\nN60 X200. Y0 I100\nN70 G98\nN75 G02 X200 Y0 I-100\nN80 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let z: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'Z')).collect();
        // The lead block does not move.
        assert_eq!(z[..3], [0.0, 0.0, 1.05]);
        assert_eq!(z[21..], [21.0, 22.05, 22.575, 22.575, 22.575, 22.575]);
        let turn = (TAU * 100.0).hypot(1.05);
        let half = (TAU / 2.0 * 100.0).hypot(0.525);
        close6(trace.steps[2].length, turn);
        close6(trace.steps[23].length, half);
        close6(trace.steps[25].length, TAU * 100.0);
        let length = 21.0 * turn + half + TAU * 100.0;
        close6(trace.totals().length(Motion::Feed), length);
        close6(trace.totals().time(Motion::Feed), length / 1000.0 * 60.0);
        assert_eq!(trace.axis(&trace.steps[23].end, b'X'), 200.0);
    }

    #[test]
    fn m37_runs_the_feed_at_a_hundredth_until_m36() {
        let text = "%1\nN1 G01 X100 F1000\nN2 M37\nN3 X200\nN4 G00 X0\nN5 G95 S500 G01 X10 F200\nN6 M36\nN7 G94 X110 F1000\nN8 M37 S500 G33 Z-15. F1.5\nN9 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        // 100 mm at 10 mm/min; the rapid is not a feed; 200 µm/rev at S500
        // is 100 mm/min, 1 mm/min under M37; after M36 the feed is F again.
        let feeds: Vec<Option<f64>> = trace.steps.iter().map(|step| step.feed).collect();
        assert_eq!(feeds[..7], [Some(1000.0), None, Some(10.0), None, Some(1.0), None, Some(1000.0)]);
        let times: Vec<f64> = timing(&trace).iter().map(|&(duration, _)| duration).collect();
        assert_eq!(times[..7], [6.0, 0.0, 600.0, 1.2, 600.0, 0.0, 6.0]);
        // A thread's F is its lead: 15 mm at 1.5 mm/rev and S500.
        close6(trace.steps[7].duration, (0.02 + 0.001) * 60.0);
        // The built-in cycles feed under it too: 12 mm at F100 / 100.
        let trace = run_text(&DRILLING.replace("M03", "M03 M37"));
        close(trace.totals().time(Motion::Feed), 2.0 * 12.0 / 1.0 * 60.0);
    }

    /// The fatal findings of a run: where (the text) and what.
    fn stops<'t>(text: &'t str, trace: &'t Trace) -> Vec<(&'t str, &'t str)> {
        trace.findings.iter().filter(|f| f.fatal).map(|f| (&text[f.range], f.message.as_str())).collect()
    }

    #[test]
    fn a_value_the_control_refuses_stops_the_run_in_the_checkers_words() {
        let overflow = "the parameter holds 0.123 (123 as digits, 3 decades) but `{}` takes at most 2: the control stops with \"an R of more than 2 decades cannot be substituted\"";
        // The manual's example: three decades into G's two.
        let text = "%1\nN10 R10=123\nN20 GR10\nN30 G00 X10\nN40 M30\n";
        let trace = run_text(text);
        assert_eq!(stops(text, &trace), [("R10", overflow.replace("{}", "G").as_str())]);
        assert_eq!(trace.findings.len(), 1, "{:?}", trace.findings);
        assert_eq!(lines_run(text, &trace), ["N10 R10=123"]);
        // In a subprogram.
        let text = "%1\nN10 R10=123\nN20 G71 L5\nN30 M30\nN40 G79 L5\nN50 MR10\nN60 G70\n";
        let trace = run_text(text);
        assert_eq!(stops(text, &trace), [("R10", overflow.replace("{}", "M").as_str())]);
        for (text, at, message) in [
            ("%1\nN1 G01 X10 F-100\nN2 M30\n", "-100", "`F` takes only unsigned values; remove the sign"),
            (
                "%1\nN1 G26 R5=99010203\nN2 M30\n",
                "99010203",
                "`99010203` is outside the parameter range -69999.999 to 69999.999",
            ),
            (
                "%1\nN1 R10=-100\nN2 G01 X10 FR10\nN3 M30\n",
                "R10",
                "the parameter holds -0.100, but `F` takes only unsigned values",
            ),
            (
                "%1\nN10 G1 X99999999999999999999 F100\nN20 M30\n",
                "99999999999999999999",
                "`X99999999999999999999` has 20 digits before the point; the format of `X` allows 5",
            ),
            ("%1\nN1 R96=5\nN2 M30\n", "96", "R96: the control has parameters R0 to R95"),
            ("%1\nN1 G01 XR100 F100\nN2 M30\n", "100", "R100: the control has parameters R0 to R95"),
            (
                "%1\nN1 G92 D1 R0=5.\nN2 &0031 D1\nN3 M30\n",
                "0031",
                "`&0031`: each digit assigns one axis's length correction and must be 0 (off), 1 (add) or 2 (subtract)",
            ),
            (
                "%1\nN1 G92 D1 R0=5.\nN2 R10=13\nN3 &R10 D1\nN4 M30\n",
                "R10",
                "the parameter holds 0.013 (read as `&13`): each `&` digit must be 0, 1 or 2",
            ),
        ] {
            let trace = run_text(text);
            assert_eq!(stops(text, &trace), [(at, message)], "{text}");
            assert!(trace.steps.iter().all(|step| step.motion == Motion::None), "{text}");
        }
    }

    #[test]
    fn a_move_beyond_the_axis_range_or_the_travel_limits_stops_the_run() {
        // G91 X1000 repeated: the 70th would reach X70000.
        let text = "%1\nN1 G91 G00 X1000\nN2 G73 L1 Q999\nN3 M30\n";
        let trace = run(text, &NoFiles, &MachineConfig::default(), 10_000);
        let message = "X would reach 70000.000, outside the range of `X`: -69999.999 to 69999.999: the control stops";
        assert_eq!(stops(text, &trace), [("N1 G91 G00 X1000\n", message)]);
        assert_eq!(trace.steps.len(), 2 * 69);
        assert_eq!(trace.axis(&trace.end(), b'X'), 69_000.0);
        // Under diameter programming the range holds the diameter.
        let lathe = MachineConfig { diameter_axis: Some(b'X'), ..MachineConfig::default() };
        let text = "%1\nN1 G74 G91 G00 X1000\nN2 G73 L1 Q999\nN3 M30\n";
        let trace = run(text, &NoFiles, &lathe, 10_000);
        assert_eq!(stops(text, &trace), [("N1 G74 G91 G00 X1000\n", message)]);
        assert_eq!(trace.axis(&trace.end(), b'X'), 34_500.0);
        // Travel limits are machine coordinates: G54 puts X250 at 450.
        let mut machine = MachineConfig {
            limits: [
                (b'X', TravelLimits { min: None, max: Some(500_000) }),
                (b'Z', TravelLimits { min: Some(-5_000), max: None }),
            ]
            .into(),
            ..MachineConfig::default()
        };
        (machine.offsets, _) = OffsetTable::parse("$POS\nG54: X=200.0\n", &machine.axes);
        let text = "%1\nN1 G54 G00 X250\nN2 X300\nN3 X350\nN4 M30\n";
        let trace = run(text, &NoFiles, &machine, 100);
        let message = "X would reach 550.000 in machine coordinates, beyond its travel limit 500.000 (`limits` of the machine): the control stops at the software limit switch";
        assert_eq!(stops(text, &trace), [("N3 X350\n", message)]);
        assert_eq!(trace.steps.len(), 2);
        // An arc's side: G03 from X290 (490 on the machine) about I0 J10
        // reaches 500; G02 between the same ends reaches 480.
        machine.limits.insert(b'X', TravelLimits { min: None, max: Some(495_000) });
        let text = "%1\nN1 G54 G00 X290 Y0\nN2 G03 X290 Y20 I0 J10 F100\nN3 M30\n";
        let trace = run(text, &NoFiles, &machine, 100);
        let message = "the arc's side: X would reach 500.000 in machine coordinates, beyond its travel limit 495.000 (`limits` of the machine): the control stops at the software limit switch";
        assert_eq!(stops(text, &trace), [("N2 G03 X290 Y20 I0 J10 F100\n", message)]);
        let trace = run(&text.replace("G03", "G02"), &NoFiles, &machine, 100);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        // A built-in cycle's moves too: G81 drills to Z-10.
        let trace = run(DRILLING, &NoFiles, &machine, 100);
        let message = "the fixed cycle G81: Z would reach -10.000 in machine coordinates, beyond its travel limit -5.000 (`limits` of the machine): the control stops at the software limit switch";
        assert_eq!(stops(DRILLING, &trace), [("N3 G81 X20\n", message)]);
    }

    #[test]
    fn dwell_is_q_times_ten_milliseconds() {
        let trace = run_text("%1\nN1 G04 Q150\nN2 M30\n");
        assert_eq!(trace.steps[0].motion, Motion::Dwell);
        close(trace.totals().time(Motion::Dwell), 1.5);
    }

    #[test]
    fn a_block_moves_with_the_parameters_from_before_its_assignments() {
        // R1=20000 is 20 mm (thousandths); the block that assigns 50 mm
        // still moves with 20.
        let trace = run_text("%1\nN1 R1=20000\nN2 G01 XR1 F1200\nN3 R1=50000 G01 X-R1\nN4 XR1\nN5 M30\n");
        let x: Vec<f64> = trace.steps.iter().map(|step| trace.axis(&step.end, b'X')).collect();
        assert_eq!(x, [0.0, 20.0, -20.0, 50.0, 50.0]);
        close(trace.steps[1].duration, 1.0);
    }

    /// The block lines each step ran, in order.
    fn lines_run(text: &str, trace: &Trace) -> Vec<String> {
        trace.steps.iter().map(|step| text[step.range].trim_end().to_owned()).collect()
    }

    #[test]
    fn a_subprogram_runs_q_times_and_returns_after_the_call() {
        let text = "%1\nN1 G71 L7 Q2 F600\nN2 G00 X0\nN3 M30\nN10 G79 L7\nN11 G91 G01 X10\nN12 G90 G70\n*\n";
        let trace = run_text(text);
        assert_eq!(
            lines_run(text, &trace),
            [
                "N1 G71 L7 Q2 F600",
                "N11 G91 G01 X10",
                "N12 G90 G70",
                "N11 G91 G01 X10",
                "N12 G90 G70",
                "N2 G00 X0",
                "N3 M30"
            ]
        );
        // The subprogram's modal G01 and F carry on after it.
        close(trace.totals().time(Motion::Feed), 2.0);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn a_macrocycle_file_runs_q_times_with_its_own_jumps() {
        // The macro drills R21 holes R20 apart: its jump back to N20 is
        // found in its own file, though the program has an N20 too.
        let program = "%1\nN10 R20=10. R21=3. G91 F600\nN20 G72 L9001 Q2\nN30 M30\n";
        let macro_text = "N1 G79 L9001\nN2 R22=0 R24=1.\nN20 G01 XR20\nN30 R5=1222422 R6=17222123 G27\nN40 GR23 L20 Q9999\nN50 G70\n";
        let trace = run(program, &Library(macro_text), &MachineConfig::default(), 1000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert_eq!(trace.files, [Called::Macrocycle(9001)]);
        // Two calls, three holes each.
        let moves: Vec<usize> = trace.steps.iter().filter(|s| s.motion == Motion::Feed).map(|s| s.source).collect();
        assert_eq!(moves, [1; 6]);
        assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 60.0);

        let trace = run(program, &NoFiles, &MachineConfig::default(), 1000);
        let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
        assert_eq!(messages, ["there is no macrocycle file L9001 to call"]);
        let unended = Library("N1 G79 L9001\nN2 G00 X1\n");
        let trace = run(program, &unended, &MachineConfig::default(), 1000);
        let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
        assert_eq!(messages, ["the macrocycle file ends without G70"]);
    }

    #[test]
    fn a_jump_with_q_runs_the_section_q_plus_one_times() {
        // The manual's example: N26…N54 with `G73 L26 Q3` runs four times.
        let text = "%1\nN25 G91 F600\nN26 G01 X1\nN54 G73 L26 Q3\nN55 M30\n";
        let trace = run_text(text);
        assert_eq!(trace.steps.iter().filter(|step| &text[step.range] == "N26 G01 X1\n").count(), 4);
        assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 4.0);
        // Nested in a subprogram called twice, the count starts again.
        let text = "%1\nN1 G71 L1 Q2 G91 F600\nN2 M30\nN3 G79 L1\nN4 G01 X1\nN5 G73 L4 Q1\nN6 G70\n";
        assert_eq!(run_text(text).end_position()[usize::from(b'X' - b'A')], 4.0);
    }

    #[test]
    fn a_long_program_runs_alike_taken_from_the_index_pass_or_lowered_again() {
        // Several batches from the index pass, then a jump back (which waits
        // for the whole index), a call into a subprogram after the end, and
        // comments, which the plain reading keeps.
        let mut text = String::from("%1\nN1 G91 G01 F600\n");
        for n in 2..3000 {
            text.push_str(&format!("N{n} X1 \"STEP\"\n"));
        }
        text.push_str("N3000 G73 L2 Q1\nN3001 G71 L7 Q2\nN3002 M30\nN3003 G79 L7\nN3004 Y1\nN3005 G70\n");
        let trace = run(&text, &NoFiles, &MachineConfig::default(), 100_000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        assert_eq!(trace.steps.len(), 1 + 2 * 2999 + 1 + 2 * 2 + 1);
        let end = trace.end_position();
        assert_eq!((end[usize::from(b'X' - b'A')], end[usize::from(b'Y' - b'A')]), (2.0 * 2998.0, 2.0));
    }

    #[test]
    fn dwell_takes_q_and_the_call_runs_once() {
        let text = "%1\nN1 G04 G71 L5 Q200\nN2 M30\nN3 G79 L5\nN4 G01 X1 F60\nN5 G70\n";
        let trace = run_text(text);
        close(trace.totals().time(Motion::Dwell), 2.0);
        close(trace.totals().time(Motion::Feed), 1.0);
    }

    #[test]
    fn endless_loops_and_missing_targets_stop_the_run_where_they_are() {
        let text = "%1\nN1 G71 L1\nN2 M30\nN3 G79 L1\nN4 G71 L1\nN5 G70\n";
        let trace = run_text(text);
        let fatal: Vec<(&str, &str)> =
            trace.findings.iter().filter(|f| f.fatal).map(|f| (text[f.range].trim_end(), f.message.as_str())).collect();
        assert_eq!(fatal, [("N4 G71 L1", "calls nest deeper than 64: runaway recursion?")]);

        let text = "%1\nN1 G73 L1 Q9999\nN2 M30\n";
        let trace = run(text, &NoFiles, &MachineConfig::default(), 500);
        assert_eq!(trace.steps.len(), 500);
        assert!(trace.findings[0].message.starts_with("stopped after 500 blocks"), "{:?}", trace.findings);

        for (text, message) in [
            ("%1\nN1 G71 L9\nN2 M30\n", "there is no subprogram L9 (G79 L9) in this file"),
            ("%1\nN1 G73 L5\nN2 M30\nN3 G79 L1\nN5 G70\n", "no block N5 in this program unit to jump to"),
            ("%1\nN1 X1\nN3 G79 L1\nN5 G70\n", "the main body runs into a subprogram: it has no M02 or M30 before it"),
        ] {
            let trace = run_text(text);
            assert_eq!(trace.findings.last().map(|f| f.message.as_str()), Some(message), "{text}");
        }
    }

    #[test]
    fn arithmetic_runs_after_the_motion_and_conditional_codes_jump_on_73() {
        // R10 counts the passes: op 01 adds R11 (1.000) to it, op 17 writes
        // 73 into R20 while R10 < R12 (3.000), so `GR20` jumps back twice
        // and is G78 (no jump) the third time.
        let text =
            "%1\nN1 R10=0 R11=1. R12=3. G91 F600\nN2 G01 X1\nN3 G27 R5=1101110 R6=17101220\nN4 GR20 L2 Q9999\nN5 M30\n";
        let trace = run_text(text);
        assert_eq!(trace.steps.iter().filter(|step| &text[step.range] == "N2 G01 X1\n").count(), 3);
        assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 3.0);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        // Op 26 reads the programmed position of axis 1 (X) after the
        // block's motion: 12.5 mm, raw 12500.
        let trace = run_text("%1\nN1 G00 X12.5 R5=26010010 G26\nN2 G01 YR10 F600\nN3 M30\n");
        assert_eq!(trace.end_position()[usize::from(b'Y' - b'A')], 12.5);
        // Op 49 reads a block register (table 4), which the run does not
        // model: the word that uses the value is named and left out.
        let text = "%1\nN1 R5=49410110 G26\nN2 G01 XR10 F100\nN3 M30\n";
        let trace = run_text(text);
        let found: Vec<(&str, bool)> = trace.findings.iter().map(|f| (&text[f.range], f.fatal)).collect();
        assert_eq!(found, [("XR10", false)]);
        assert!(trace.findings[0].message.starts_with("R10 holds a value the executor does not know"));
    }

    #[test]
    fn an_arithmetic_error_stops_the_run_at_its_function() {
        // Op 04 divides R1 by R2, which is zero.
        let text = "%1\nN1 R1=1. R2=0 R5=4010203 G26\nN2 G00 X1\nN3 M30\n";
        let trace = run_text(text);
        let found: Vec<(&str, &str, bool)> =
            trace.findings.iter().map(|f| (&text[f.range], f.message.as_str(), f.fatal)).collect();
        assert_eq!(found, [("G26", "parameter arithmetic failed: division by zero", true)]);
        assert_eq!(trace.steps.len(), 1);
    }

    #[test]
    fn speed_and_dwell_read_a_parameter_as_its_digits() {
        // R27=300 is S300 and R29=250 a dwell of 250 × 10 ms (03 §1.6);
        // G95 F1. is 1 mm/rev, 300 mm/min at S300.
        let trace = run_text("%1\nN1 R27=300 R29=250\nN2 SR27 G95 G01 X1 F1.\nN3 G04 QR29\nN4 M30\n");
        assert_eq!(trace.steps[1].feed, Some(300.0));
        close(trace.steps[1].duration, 0.2);
        close(trace.totals().time(Motion::Dwell), 2.5);
    }

    #[test]
    fn the_program_ends_at_m30_and_unmodelled_work_is_named_once() {
        let trace = run_text("%1\nN1 G08 X1 F100\nN2 G08 X2\nN3 M30\nN4 G00 X500\n");
        assert_eq!(trace.steps.len(), 3);
        let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
        assert_eq!(messages, ["the executor does not run G08 yet: the time leaves them out"]);
    }

    #[test]
    fn a_rapid_move_lasts_as_long_as_its_slowest_axis() {
        let machine = MachineConfig { rapid_rates: [(b'Z', 5_000)].into(), ..MachineConfig::default() };
        let trace = run("%1\nN1 G00 X100 Z40\nN2 X0 Z0 Y200\nN3 M30\n", &NoFiles, &machine, 100);
        // N1: X 100 mm at 10000 mm/min is 0.6 s, Z 40 mm at 5000 mm/min 0.48 s;
        // N2: Y 200 mm at 10000 mm/min is 1.2 s.
        close(trace.steps[0].duration, 0.6);
        close(trace.steps[1].duration, 1.2);
        let trace = run("%1\nN1 G00 X50 Z40\nN2 M30\n", &NoFiles, &machine, 100);
        close(trace.steps[0].duration, 0.48);
    }
}
