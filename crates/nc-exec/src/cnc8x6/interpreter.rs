//! The CNC8x6 interpreter, which the run driver (`run`) runs: the modal
//! state, motion and time of a program, block by block, in the order the
//! control runs them.
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
//! - Feed and spindle: the modal machine of every group ([`Modes`](crate::cnc8x6::modes::Modes)), F
//!   with its decimal-point rules per minute or per revolution and M37's
//!   1 : 100, S, constant cutting speed G96/G97 with the G76 limit, dwell
//!   (G04 Q, in 10 ms, after the block's motion).
//! - Parameters: assignments and arithmetic G26–G29 take effect after the
//!   block's motion, which reads the values from before them.
//! - Fixed cycles G81–G89 after the block's motion until G80: the bodies of
//!   the machine's cycle file with the state restored afterwards, or the
//!   built-in cycles ([`crate::cnc8x6::cycles`]).
//!
//! - Offsets: zero offsets G53–G59 with G92/G93, length corrections D/&,
//!   and radius compensation G41/G42 ([`crate::compensation`]).
//!
//! - Coordinates: diameter programming G74/G75 on the machine's diameter
//!   axis (positions are radii), the recalculations G34–G37 and the
//!   transformations G38/G39/G31 ([`crate::transform`]).
//!
//! Where the control stops on an error, the run stops with a fatal
//! [`Finding`]: a value its address cannot take ([`crate::cnc8x6::formats`]), a
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

mod index;
mod runner;
mod support;

use std::{borrow::Cow, thread::Scope};

use crate::{
    cnc8x6::lower::BlockData,
    cnc8x6::program_flow::{BlockFlow, JumpCounts},
    machine::MachineConfig,
    trace::{
        Called, Checkpoint, DELIVERY_BATCH, Environment, MAX_CALL_DEPTH, Resumable, RunRule, StepSink, Trace,
        expected_blocks, goes_on,
    },
    transform::Frame,
};

use self::{index::*, runner::*};

/// The frame of the priority block on `machine`.
pub(crate) fn reset_frame(machine: &MachineConfig) -> Frame {
    Runner::new(std::sync::Arc::new(machine.clone())).frame_in_force()
}

impl Resumable for Runner {
    fn steps(&self) -> usize {
        self.steps.delivered
    }

    fn set_steps(&mut self, steps: usize) {
        self.steps.delivered = steps;
    }

    fn same_course(&self, other: &Runner) -> bool {
        Runner::same_course(self, other)
    }
}

pub(crate) fn run_in<'a, 's>(
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
    let resumed = checkpoint.and_then(|checkpoint| {
        let runner = checkpoint.state::<Runner>()?;
        (*runner.machine == *machine).then_some((runner, checkpoint))
    });
    let (mut runner, mut index, mut at, mut executed) = match resumed {
        Some((runner, checkpoint)) => (
            runner.clone(),
            Index::start(scope, text, Some((checkpoint.offset, checkpoint.block))),
            checkpoint.block,
            checkpoint.executed,
        ),
        _ => (fresh, Index::start(scope, text, None), 0, 0),
    };
    // Most programs run each block about once.
    runner.steps.steps.reserve(if sink.is_some() { DELIVERY_BATCH } else { expected_blocks(text) });
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
                Checkpoint { state: Box::new(runner.for_checkpoint()), block: at, offset: range.start(), executed };
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
        if !goes_on(files, executed) {
            break;
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
                    let file = Called::Name(name.to_owned());
                    let text = files.file(&file)?;
                    called.push(file);
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
                        let file = Called::Number(label);
                        let start = files.file(&file).and_then(|text| {
                            called.push(file);
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
            && runner.steps.steps.len() >= DELIVERY_BATCH
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
        steps: runner.steps.steps,
        findings: runner.findings,
        tools: runner.tools,
        files: called,
        blocks_run: executed,
        written: Vec::new(),
    }
}

#[cfg(test)]
mod tests;
