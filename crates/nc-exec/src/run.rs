//! Running a program: the driver that runs it on its machine by the
//! interpreter of the machine's control (CNC8x6:
//! [`crate::cnc8x6::interpreter`], Haas lathe:
//! [`crate::haas_lathe::interpreter`], Sinumerik:
//! `crate::sinumerik::interpreter`), to a trace or into a sink, on a thread
//! of its own or this one, with checkpoints to resume from; the control's
//! velocity policy that times the steps; and the trace's vocabulary
//! ([`crate::trace`]), which the interpreters write.

use std::{
    sync::{Arc, mpsc},
    thread::Scope,
};

use ncc_catalog::Dialect;

use crate::{cnc8x6, haas_lathe, machine::MachineConfig, sinumerik, transform::Frame, velocity::Dynamics};

pub use crate::trace::*;

/// Runs the program `text` from its first block to its end on `machine`,
/// in the language of the machine's control, following calls of
/// subprograms and other files, cycles and jumps, for at most `budget`
/// blocks. Files are read from `files` when first needed, and the run
/// reports its progress there.
pub fn run(text: &str, files: &dyn Environment, machine: &MachineConfig, budget: usize) -> Trace {
    std::thread::scope(|scope| run_in(scope, Program { text, lowered: None }, files, machine, budget, None, None))
}

/// The frame in which a run on `machine` starts ([`Trace::reset_frame`]):
/// CNC8x6, the zero offset G53 of its tables after the priority block;
/// Haas lathe, the work offset G54; Sinumerik, none (its settable frames
/// are zero).
pub fn reset_frame(machine: &MachineConfig) -> Frame {
    match machine.control {
        Dialect::Cnc8x6 => cnc8x6::interpreter::reset_frame(machine),
        Dialect::HaasLathe => haas_lathe::interpreter::reset_frame(machine),
        Dialect::Sinumerik => sinumerik::interpreter::reset_frame(machine),
    }
}

/// Whether the executor has an interpreter for `control`'s programs: a
/// run of any other makes no step, and its only finding says so.
pub fn interprets(control: Dialect) -> bool {
    match control {
        Dialect::Cnc8x6 => true,
        Dialect::HaasLathe => true,
        Dialect::Sinumerik => true,
    }
}

/// The velocity model's parameters on `machine`: its control's policy, read
/// from its machine description.
pub fn dynamics(machine: &MachineConfig) -> Dynamics {
    match machine.control {
        Dialect::Cnc8x6 => cnc8x6::dynamics::dynamics(machine),
        Dialect::HaasLathe => haas_lathe::dynamics::dynamics(machine),
        Dialect::Sinumerik => sinumerik::dynamics::dynamics(machine),
    }
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
    resume_into(None, text, files, machine, budget, sink)
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
    resume_lowered_into(checkpoint, text, None, files, machine, budget, sink)
}

/// A program's blocks as its control's interpreter reads them, lowered by
/// whoever asks for the run (the editor's analysis keeps them between
/// edits), so that the run does not lower the whole text again.
#[derive(Debug, Clone)]
pub enum LoweredProgram {
    HaasLathe(Arc<haas_lathe::interpreter::Unit>),
    Sinumerik(Arc<sinumerik::Unit>),
}

/// Like [`resume_into`], reading the program's blocks from `lowered`, the
/// blocks of `text`, when it has those of the machine's control.
pub fn resume_lowered_into(
    checkpoint: Option<&Checkpoint>,
    text: &str,
    lowered: Option<&LoweredProgram>,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    sink: &mut dyn StepSink,
) -> Trace {
    let program = Program { text, lowered };
    std::thread::scope(|scope| run_in(scope, program, files, machine, budget, Some(sink), checkpoint))
}

/// The program a run runs: its text, and its blocks if already lowered.
#[derive(Clone, Copy)]
struct Program<'a> {
    text: &'a str,
    lowered: Option<&'a LoweredProgram>,
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
        let program = Program { text, lowered: None };
        let trace = run_in(scope, program, files, machine, budget, Some(&mut handing), None);
        let Batches { batch, sender, .. } = handing;
        // The sink's thread ends when the last batch is in and the channel
        // closes.
        let _ = sender.send(batch);
        drop(sender);
        (trace, beside.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
    })
}

/// Runs `program` in the language of the machine's control.
fn run_in<'a, 's>(
    scope: &'s Scope<'s, 'a>,
    Program { text, lowered }: Program<'a>,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    sink: Option<&mut dyn StepSink>,
    checkpoint: Option<&Checkpoint>,
) -> Trace {
    match machine.control {
        Dialect::Cnc8x6 => cnc8x6::interpreter::run_in(scope, text, files, machine, budget, sink, checkpoint),
        Dialect::HaasLathe => {
            let lowered = lowered.and_then(|lowered| match lowered {
                LoweredProgram::HaasLathe(unit) => Some(unit),
                LoweredProgram::Sinumerik(_) => None,
            });
            haas_lathe::interpreter::run_in(text, lowered, files, machine, budget, sink, checkpoint)
        }
        Dialect::Sinumerik => {
            let lowered = lowered.and_then(|lowered| match lowered {
                LoweredProgram::Sinumerik(unit) => Some(unit),
                LoweredProgram::HaasLathe(_) => None,
            });
            sinumerik::interpreter::run_in(text, lowered, files, machine, budget, sink, checkpoint)
        }
    }
}
