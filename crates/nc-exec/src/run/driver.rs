//! The run driver: running a program to a trace or into a sink, on a thread
//! of its own or this one, with checkpoints to resume from.

use std::{
    borrow::Cow,
    ops::ControlFlow,
    sync::mpsc::{self, Receiver},
    thread::Scope,
};

use ncc_syntax::{TextRange, TextSize};

use crate::{
    cnc8x6::lower::BlockData,
    cnc8x6::program_flow::{BlockFlow, JumpCounts},
    compensation::ToolElement,
    machine::MachineConfig,
    transform::Frame,
};

use super::{index::*, rules::RunRule, runner::*, trace::*};

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
    pub(super) runner: Box<Runner>,
    /// The next block, and where it starts.
    pub(super) block: usize,
    pub(super) offset: TextSize,
    /// Blocks run before it, for the step budget.
    pub(super) executed: usize,
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
pub(super) struct Batches {
    pub(super) batch: Vec<Step>,
    pub(super) sender: mpsc::SyncSender<Vec<Step>>,
    emptied: Receiver<Vec<Step>>,
}

impl Batches {
    /// Sends the gathered batch on, with an emptied one in its place.
    pub(super) fn send(&mut self) {
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
pub(super) const DELIVERY_BATCH: usize = 1024;

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
            runner.finding(
                RunRule::RunsIntoSubprogram,
                range,
                "the main body runs into a subprogram: it has no M02 or M30 before it",
            );
            break;
        }
        executed += usize::from(resume.is_none());
        if executed % PROGRESS_INTERVAL == 0 {
            files.progress(executed);
        }
        if executed > budget {
            let message = format!("stopped after {budget} blocks: a jump loop that never ends or runaway calls?");
            runner.finding(RunRule::StepBudget, range, &message);
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
                        runner.report_once(
                            RunRule::CycleFileMissing,
                            &why,
                            range,
                            &format!("{why}: the built-in cycle runs instead"),
                        );
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
                        let message = format!("calls nest deeper than {MAX_CALL_DEPTH}: runaway recursion?");
                        runner.finding(RunRule::CallDepth, range, &message);
                        break;
                    }
                    None if is_macrocycle => {
                        let message = format!("there is no macrocycle file L{label} to call");
                        runner.finding(RunRule::CallTargetMissing, range, &message);
                        break;
                    }
                    None => {
                        let message = format!("there is no subprogram L{label} (G79 L{label}) in this file");
                        runner.finding(RunRule::CallTargetMissing, range, &message);
                        break;
                    }
                }
            }
            Flow::Block(BlockFlow::Jump { label, times }) => match index.complete().units.jump_target(at, label) {
                Some(target) if jumps.jumps(at, times) => target,
                Some(_) => next,
                None => {
                    let message = format!("no block N{label} in this program unit to jump to");
                    runner.finding(RunRule::CallTargetMissing, range, &message);
                    break;
                }
            },
        };
        // Only another file's blocks can end without a way back.
        let leaves_file = |index: &mut Index<'_, '_>| index.complete().block(at).is_none_or(|(_, file)| file != source);
        if source != 0 && passes_on && leaves_file(&mut index) {
            runner.finding(RunRule::MacrocycleWithoutReturn, range, "the macrocycle file ends without G70");
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
