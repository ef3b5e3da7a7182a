//! How a run hands on what it makes: the sink that takes the steps, the
//! checkpoints a run can resume from, and the files it reads.

use std::{
    any::Any,
    hash::{DefaultHasher, Hash, Hasher},
    ops::{ControlFlow, Range},
    sync::mpsc::{self, Receiver},
};

use ncc_syntax::{TextRange, TextSize};

use crate::{compensation::ToolElement, transform::Frame};

use super::*;

/// How many blocks a run executes at most before it stops: a jump loop
/// that never ends or runaway recursion stops here with a finding.
pub const DEFAULT_STEP_BUDGET: usize = 10_000_000;

/// How deep subprogram calls nest before the run stops.
pub(crate) const MAX_CALL_DEPTH: usize = 64;

/// What a run needs from where it runs: the files a program uses besides
/// its own, and someone to tell how far it got.
pub trait Environment {
    /// The text of the file `called`.
    fn file(&self, called: &Called) -> Option<String>;
    /// Called every [`PROGRESS_INTERVAL`] blocks with the number run so far.
    fn progress(&self, _blocks_run: usize) {}
    /// Whether whoever asked for the run no longer wants it (the editor's
    /// text changed again): asked every [`ABANDON_INTERVAL`] blocks read or
    /// run, and the run ends there, its trace incomplete.
    fn abandoned(&self) -> bool {
        false
    }
}

/// About as many blocks as a program of CAM output with this text has, or
/// more: memory reserved and never used costs nothing, growing costs copies.
pub fn expected_blocks(text: &str) -> usize {
    text.len() / 24
}

/// How often a run reports its progress, in blocks.
pub const PROGRESS_INTERVAL: usize = 1 << 16;

/// How often a run asks whether it is still wanted, in blocks: a
/// fraction of a millisecond.
pub const ABANDON_INTERVAL: usize = 1 << 10;

/// Reports the run's progress to `files` and asks whether it is abandoned,
/// each at its interval, after `blocks_run` blocks: whether the run goes
/// on. Every interpreter asks before each block it runs.
pub(crate) fn goes_on(files: &dyn Environment, blocks_run: usize) -> bool {
    if blocks_run.is_multiple_of(PROGRESS_INTERVAL) {
        files.progress(blocks_run);
    }
    !(blocks_run.is_multiple_of(ABANDON_INTERVAL) && files.abandoned())
}

/// The program alone: no other files.
#[derive(Debug, Clone, Copy)]
pub struct NoFiles;

impl Environment for NoFiles {
    fn file(&self, _called: &Called) -> Option<String> {
        None
    }
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
    /// The interpreter's state, of the machine's control.
    pub(crate) state: Box<dyn State>,
    /// The next block, and where it starts.
    pub(crate) block: usize,
    pub(crate) offset: TextSize,
    /// Blocks run before it, for the step budget.
    pub(crate) executed: usize,
}

/// What a control's interpreter keeps in a [`Checkpoint`] to run on from.
pub(crate) trait Resumable: Clone + Send + Sync + 'static {
    /// Steps made before it.
    fn steps(&self) -> usize;
    fn set_steps(&mut self, steps: usize);
    /// See [`Checkpoint::same_course`].
    fn same_course(&self, other: &Self) -> bool;
}

/// A [`Resumable`] of any control, as a checkpoint holds it.
pub(crate) trait State: Any + Send + Sync {
    fn boxed_clone(&self) -> Box<dyn State>;
    fn steps(&self) -> usize;
    fn set_steps(&mut self, steps: usize);
    /// False for another control's state.
    fn same_course(&self, other: &dyn State) -> bool;
}

impl<R: Resumable> State for R {
    fn boxed_clone(&self) -> Box<dyn State> {
        Box::new(self.clone())
    }

    fn steps(&self) -> usize {
        Resumable::steps(self)
    }

    fn set_steps(&mut self, steps: usize) {
        Resumable::set_steps(self, steps);
    }

    fn same_course(&self, other: &dyn State) -> bool {
        (other as &dyn Any).downcast_ref::<R>().is_some_and(|other| Resumable::same_course(self, other))
    }
}

impl Clone for Box<dyn State> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}

impl fmt::Debug for Checkpoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
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

    /// Blocks the run executed before it.
    pub fn blocks_run(&self) -> usize {
        self.executed
    }

    /// The interpreter's state, when it is `R` (the control's).
    pub(crate) fn state<R: Resumable>(&self) -> Option<&R> {
        (&*self.state as &dyn Any).downcast_ref::<R>()
    }

    /// Steps the run made before it.
    pub fn steps(&self) -> usize {
        self.state.steps()
    }

    /// Whether a run from here goes on as one from `other` does over the
    /// same text after their offsets: the same modes, position,
    /// parameters, tables and frames; the blocks and steps before them and
    /// what was reported may differ.
    pub fn same_course(&self, other: &Checkpoint) -> bool {
        self.state.same_course(&*other.state)
    }

    /// This checkpoint in a text where its block starts `text` bytes
    /// later, after `blocks` more blocks and `steps` more steps.
    pub fn shifted(&self, text: i64, blocks: i64, steps: i64) -> Checkpoint {
        let mut shifted = self.clone();
        shifted.offset = shift_offset(self.offset, text);
        shifted.block = shift_count(self.block, blocks);
        shifted.executed = shift_count(self.executed, blocks);
        shifted.state.set_steps(shift_count(self.state.steps(), steps));
        shifted
    }
}

/// `before` with `part` folded in: what a checkpoint's run may read of
/// the text before it.
pub(crate) fn fold(before: u64, part: impl Hash) -> u64 {
    let mut hasher = DefaultHasher::new();
    (before, part).hash(&mut hasher);
    hasher.finish()
}

/// `spans` sorted and joined where they meet or overlap: the blocks before
/// which a run takes no checkpoint, for [`covers`].
pub(crate) fn merged(mut spans: Vec<Range<usize>>) -> Vec<Range<usize>> {
    spans.sort_by_key(|span| span.start);
    let mut merged: Vec<Range<usize>> = Vec::with_capacity(spans.len());
    for span in spans {
        match merged.last_mut() {
            Some(last) if span.start <= last.end => last.end = last.end.max(span.end),
            _ => merged.push(span),
        }
    }
    merged
}

/// Whether one of the sorted, disjoint `spans` holds `block`.
pub(crate) fn covers(spans: &[Range<usize>], block: usize) -> bool {
    let after = spans.partition_point(|span| span.end <= block);
    spans.get(after).is_some_and(|span| span.start <= block)
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

/// Steps gathered for a sink on another thread, in batches it hands back
/// emptied: memory used again costs less than new memory.
pub(crate) struct Batches {
    pub(crate) batch: Vec<Step>,
    pub(crate) sender: mpsc::SyncSender<Vec<Step>>,
    pub(crate) emptied: Receiver<Vec<Step>>,
}

impl Batches {
    /// Sends the gathered batch on, with an emptied one in its place.
    pub(crate) fn send(&mut self) {
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
pub(crate) const DELIVERY_BATCH: usize = 1024;

/// The steps of a run not handed on yet: `steps[0]` is the run's step
/// `delivered`. Radius compensation may still change the last few.
#[derive(Debug, Clone, Default)]
pub(crate) struct Undelivered {
    pub(crate) steps: Vec<Step>,
    pub(crate) delivered: usize,
}

impl Undelivered {
    /// The index in the run of the step to come.
    pub(crate) fn next(&self) -> usize {
        self.delivered + self.steps.len()
    }

    pub(crate) fn push(&mut self, step: Step) {
        self.steps.push(step);
    }

    /// Step `index` of the run, not handed on yet.
    pub(crate) fn get(&self, index: usize) -> &Step {
        &self.steps[index - self.delivered]
    }

    pub(crate) fn get_mut(&mut self, index: usize) -> &mut Step {
        &mut self.steps[index - self.delivered]
    }

    /// Hands `sink` the steps before the run's step `open`, the first one
    /// compensation may still change (all of them without one), after
    /// what they refer to: the run's `frames` and `compensated` spans, and
    /// the pieces of its tool-centre path that belong to them, in path
    /// order. Of `tool_centre`, the pieces of the steps handed on before
    /// come first, sorted; the others come in the order compensation fixed
    /// them, and are sorted here.
    pub(crate) fn deliver(
        &mut self,
        sink: &mut dyn StepSink,
        open: Option<usize>,
        frames: &[Frame],
        compensated: &[Compensated],
        tool_centre: &mut [ToolElement],
    ) {
        let open = open.map_or(self.steps.len(), |open| open - self.delivered);
        let first = tool_centre.partition_point(|piece| piece.block < self.delivered);
        self.delivered += open;
        let fresh = &mut tool_centre[first..];
        fresh.sort_by_key(|piece| piece.block);
        let fixed = first + fresh.partition_point(|piece| piece.block < self.delivered);
        sink.references(frames, compensated, &tool_centre[first..fixed]);
        if open == self.steps.len() {
            sink.steps(&mut self.steps);
        } else {
            self.steps.drain(..open).for_each(|step| sink.step(step));
        }
    }
}

#[cfg(test)]
impl StepSink for Vec<Step> {
    fn step(&mut self, step: Step) {
        self.push(step);
    }
}

/// Takes steps until it has `room` of them, then is closed.
#[cfg(test)]
pub(crate) struct Closing {
    pub(crate) taken: usize,
    pub(crate) room: usize,
}

#[cfg(test)]
impl StepSink for Closing {
    fn step(&mut self, _step: Step) {
        self.taken += 1;
    }

    fn closed(&self) -> bool {
        self.taken >= self.room
    }
}

/// The steps of a run after its first `before`, and a checkpoint
/// every `every` blocks (none for 0).
#[cfg(test)]
#[derive(Default)]
pub(crate) struct Checkpoints {
    pub(crate) before: usize,
    pub(crate) steps: Vec<Step>,
    pub(crate) taken: Vec<Checkpoint>,
    pub(crate) every: usize,
}

#[cfg(test)]
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
