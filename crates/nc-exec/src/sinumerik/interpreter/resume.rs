//! Checkpoints of a run (the interpreter's documentation says where it takes
//! them): the state a checkpoint keeps, what it compares, and resuming from it.

use std::{
    collections::{HashMap, HashSet},
    ops::Range,
    sync::Arc,
};

use super::{At, Interpreter, State, files};
use crate::{
    machine::MachineConfig,
    sinumerik::{
        dynamics::PathControl,
        eval::Store,
        frames::ProgrammableFrame,
        lower::Call,
        modes::Modes,
        program::{SinumerikModel, Unbalanced},
    },
    trace::{Called, Checkpoint, Position, Resumable, fold, merged},
};

/// The run between two blocks of the main program outside calls, which a
/// [`Checkpoint`] keeps: the modal state, position, feed, spindle, tool and
/// its data, path modes, frame, variables, MCALL and written files.
#[derive(Clone)]
pub(super) struct Resumed {
    machine: Arc<MachineConfig>,
    modes: Modes,
    position: Position,
    feed: Option<f64>,
    speed: f64,
    tool: u32,
    edge: u32,
    tool_data: HashMap<(String, i64, i64), f64>,
    path: PathControl,
    frame: ProgrammableFrame,
    frames: usize,
    files: files::Files,
    reported: HashSet<String>,
    store: Store,
    modal_call: Option<Call>,
    /// What the run after the checkpoint may read of the text before it,
    /// besides the blocks it ran with a step, which a run revisiting them
    /// shows in its steps: the labels and block numbers, which jumps and
    /// REPEAT look up, and the text of the blocks it went past or ran
    /// without a step.
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
            position,
            feed,
            speed,
            tool,
            edge,
            tool_data,
            path,
            frame,
            frames,
            files,
            reported,
            store,
            modal_call,
            before,
            steps: _,
        } = self;
        **machine == *other.machine
            && *modes == other.modes
            && *position == other.position
            && *feed == other.feed
            && *speed == other.speed
            && *tool == other.tool
            && *edge == other.edge
            && *tool_data == other.tool_data
            && *path == other.path
            && *frame == other.frame
            && *frames == other.frames
            && *files == other.files
            && *reported == other.reported
            && *store == other.store
            && *modal_call == other.modal_call
            && *before == other.before
    }
}

/// The blocks of `model` before which a run takes no checkpoint: those
/// after a structure's start up to its end, and all after a start never
/// closed. An end after such a checkpoint could pair with a start before
/// it, so that the text before it would decide the run after it; a
/// one-line `IF … GOTO` that an ENDIF pairs with is among the structures.
/// Sorted and apart.
pub(super) fn inside_structures(model: &SinumerikModel) -> Vec<Range<usize>> {
    let matched = model.structures.iter().map(|s| s.start + 1..s.end + 1);
    let unclosed = model.unmatched.iter().filter(|u| u.problem == Unbalanced::NotClosed);
    merged(matched.chain(unclosed.map(|u| u.block + 1..usize::MAX)).collect())
}

/// The global user data definition files (Siemens's `_N_SGUD_DEF`,
/// `_N_MGUD_DEF`, `_N_UGUD_DEF`, `_N_GUD4_DEF` … `_N_GUD9_DEF`).
pub(super) fn global_data_files() -> impl Iterator<Item = Called> {
    let names = ["SGUD", "MGUD", "UGUD", "GUD4", "GUD5", "GUD6", "GUD7", "GUD8", "GUD9"];
    names.into_iter().map(|name| Called::ControlFile(format!("_N_{name}_DEF")))
}

impl Interpreter<'_> {
    /// Goes past the blocks of the main file from the furthest one run to
    /// `block`, which a jump or a structure left early has skipped.
    pub(super) fn pass_to(&mut self, block: usize) {
        let unit = Arc::clone(&self.units[0]);
        for skipped in self.reached..block {
            let (block, range) = (&unit.block(skipped), unit.ranges[skipped]);
            let label = block.label.as_ref().map(|label| label.name.as_str());
            let text = if block.statements.is_empty() { "" } else { &self.text[range] };
            self.before = fold(self.before, (2u8, label, block.number.and_then(|n| n.value), text));
        }
        self.reached = self.reached.max(block);
    }

    /// The state to resume from before the next block, every step before
    /// it handed on.
    pub(super) fn resumed(&self) -> Resumed {
        // Every field named, so that a new one must be placed here.
        let Interpreter {
            machine,
            files: _,
            text: _,
            units: _,
            // None read: a checkpoint is taken only before the first.
            called: _,
            store,
            state,
            // None under way at a checkpoint.
            calls: _,
            modal_call,
            // None pending at a checkpoint.
            spline: _,
            // None in force at a checkpoint; its path is reported by the
            // run up to the checkpoint.
            compensation: _,
            steps,
            executed: _,
            reached: _,
            before,
        } = self;
        let State {
            machine: _,
            modes,
            position,
            feed,
            speed,
            tool,
            edge,
            tool_data,
            // A resumed run lists the tools it selects itself.
            tools: _,
            path,
            frame,
            frames,
            files,
            findings: _,
            reported,
            source: _,
            block_start: _,
            stopped: _,
        } = state;
        Resumed {
            machine: Arc::clone(machine),
            modes: modes.clone(),
            position: *position,
            feed: *feed,
            speed: *speed,
            tool: *tool,
            edge: *edge,
            tool_data: tool_data.clone(),
            path: path.clone(),
            frame: frame.clone(),
            frames: *frames,
            files: files.clone(),
            reported: reported.clone(),
            store: store.clone(),
            modal_call: modal_call.clone(),
            before: *before,
            steps: steps.next(),
        }
    }

    /// Goes on from `checkpoint`, a checkpoint of a run of this program on
    /// this machine: where it resumes; `None`, to run from the start, for a
    /// checkpoint of another control or machine, of a block this text does
    /// not have there, or where the global user data a run from the start
    /// reads is there now.
    pub(super) fn resume(&mut self, checkpoint: &Checkpoint) -> Option<At> {
        let resumed = checkpoint.state::<Resumed>()?;
        let block = checkpoint.block;
        let here = self.units[0].ranges.get(block).is_some_and(|range| range.start() == checkpoint.offset);
        if !here || *resumed.machine != **self.machine {
            return None;
        }
        // The checkpoint's run read none.
        if global_data_files().any(|called| self.files.file(&called).is_some()) {
            return None;
        }
        let Resumed {
            machine: _,
            modes,
            position,
            feed,
            speed,
            tool,
            edge,
            tool_data,
            path,
            frame,
            frames,
            files,
            reported,
            store,
            modal_call,
            before,
            steps,
        } = resumed.clone();
        let state = &mut self.state;
        (state.modes, state.position, state.feed, state.speed) = (modes, position, feed, speed);
        (state.tool, state.edge, state.tool_data, state.path) = (tool, edge, tool_data, path);
        (state.frame, state.frames, state.files, state.reported) = (frame, frames, files, reported);
        (self.store, self.modal_call, self.before, self.steps.delivered) = (store, modal_call, before, steps);
        (self.executed, self.reached) = (checkpoint.executed, block);
        Some(At { source: 0, block })
    }
}
