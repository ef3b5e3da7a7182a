//! Running a program: the driver that runs it on its machine by the
//! interpreter of the machine's control (CNC8x6:
//! [`crate::cnc8x6::interpreter`], Haas lathe:
//! [`crate::haas_lathe::interpreter`]; Sinumerik has none yet, see
//! [`not_run`]), to a trace or into a sink, on a thread
//! of its own or this one, with checkpoints to resume from; the control's
//! velocity policy that times the steps; and the trace's vocabulary
//! ([`crate::trace`]), which the interpreters write.

use std::{sync::mpsc, thread::Scope};

use ncc_catalog::Dialect;
use ncc_syntax::{TextRange, TextSize};

use crate::{cnc8x6, haas_lathe, machine::MachineConfig, transform::Frame, velocity::Dynamics};

pub use crate::trace::*;

/// Runs the program `text` from its first block to its end on `machine`,
/// in the language of the machine's control, following calls of
/// subprograms and other files, cycles and jumps, for at most `budget`
/// blocks. Files are read from `files` when first needed, and the run
/// reports its progress there.
pub fn run(text: &str, files: &dyn Environment, machine: &MachineConfig, budget: usize) -> Trace {
    std::thread::scope(|scope| run_in(scope, text, files, machine, budget, None, None))
}

/// The frame in which a run on `machine` starts ([`Trace::reset_frame`]):
/// CNC8x6, the zero offset G53 of its tables after the priority block;
/// Haas lathe, the work offset G54; Sinumerik, which does not run yet, none.
pub fn reset_frame(machine: &MachineConfig) -> Frame {
    match machine.control {
        Dialect::Cnc8x6 => cnc8x6::interpreter::reset_frame(machine),
        Dialect::HaasLathe => haas_lathe::interpreter::reset_frame(machine),
        Dialect::Sinumerik => Frame::default(),
    }
}

/// Whether the executor has an interpreter for `control`'s programs: a
/// run of any other makes no step, and its only finding says so.
pub fn interprets(control: Dialect) -> bool {
    match control {
        Dialect::Cnc8x6 => true,
        Dialect::HaasLathe => true,
        Dialect::Sinumerik => false,
    }
}

/// The velocity model's parameters on `machine`: its control's policy, read
/// from its machine description.
pub fn dynamics(machine: &MachineConfig) -> Dynamics {
    match machine.control {
        Dialect::Cnc8x6 => cnc8x6::dynamics::dynamics(machine),
        Dialect::HaasLathe => haas_lathe::dynamics::dynamics(machine),
        // Sinumerik has no policy yet, and its runs make no step to time:
        // the Haas policy, read from the same machine description, stands in.
        Dialect::Sinumerik => haas_lathe::dynamics::dynamics(machine),
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

/// Runs `text` in the language of the machine's control.
fn run_in<'a, 's>(
    scope: &'s Scope<'s, 'a>,
    text: &'a str,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    sink: Option<&mut dyn StepSink>,
    checkpoint: Option<&Checkpoint>,
) -> Trace {
    match machine.control {
        Dialect::Cnc8x6 => cnc8x6::interpreter::run_in(scope, text, files, machine, budget, sink, checkpoint),
        Dialect::HaasLathe => haas_lathe::interpreter::run_in(text, files, machine, budget, sink, checkpoint),
        Dialect::Sinumerik => not_run(text, machine),
    }
}

/// The run of a program in a language the executor has no interpreter for
/// yet (Sinumerik): no step, and one finding at the first line with text
/// that says so, so that no time is given for it rather than a wrong one.
fn not_run(text: &str, machine: &MachineConfig) -> Trace {
    let start = text.len() - text.trim_start().len();
    let end = text[start..].find(['\r', '\n']).map_or(text.len(), |length| start + length);
    let range = TextRange::new(TextSize::new(start as u32), TextSize::new(end as u32));
    let message = format!("the executor does not run {} programs yet", machine.control.title());
    Trace {
        axes: machine.step_axes().to_vec(),
        diameter_axis: machine.diameter_axis,
        frames: Vec::new(),
        reset_frame: reset_frame(machine),
        tool_centre: Vec::new(),
        compensated: Vec::new(),
        messages: Vec::new(),
        steps: Vec::new(),
        findings: vec![Finding { rule: RunRule::NotRunYet, source: 0, range, message }],
        tools: Vec::new(),
        files: Vec::new(),
        blocks_run: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Sinumerik program makes no step: its one finding, at its first
    /// line with text, says the executor does not run it yet.
    #[test]
    fn a_program_without_an_interpreter_runs_to_one_finding() {
        let machine = MachineConfig::of_control(Dialect::Sinumerik);
        assert_eq!(machine.axes, b"XYZ");
        let text = "\n  N10 G0 X10 Y20\r\nM30\n";
        let trace = run(text, &NoFiles, &machine, DEFAULT_STEP_BUDGET);
        assert!(trace.steps.is_empty() && trace.blocks_run == 0);
        let [finding] = trace.findings.as_slice() else { panic!("{:?}", trace.findings) };
        assert_eq!(finding.rule, RunRule::NotRunYet);
        assert_eq!(&text[finding.range], "N10 G0 X10 Y20");
        assert_eq!(finding.message, "the executor does not run Siemens Sinumerik programs yet");
        assert!(!interprets(Dialect::Sinumerik) && interprets(Dialect::HaasLathe));
        let empty = run("", &NoFiles, &machine, DEFAULT_STEP_BUDGET);
        assert_eq!(empty.findings[0].range, TextRange::default());
    }
}
