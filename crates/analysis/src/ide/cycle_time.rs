//! The predicted cycle time of a program, block by block.
//!
//! The program runs on the executor (`nc_exec::run`) with the workspace's
//! macrocycle files and cycle file (Haas: program files), and the velocity
//! model times the
//! steps. Each block of the file gets the time of all its executions; the
//! steps of other files (a macrocycle, a cycle body) are charged to the
//! block of this file that ran last before them: the call.
//!
//! The run needs no database: [`RunInput`] takes what it reads from a
//! snapshot, so a long run never holds one (an edit would wait for it).

use std::{fmt::Write as _, ops::ControlFlow, path::Path, sync::Arc};

use nc_exec::{
    run::{
        Called, Checkpoint, Environment, LoweredProgram, Motion, Step, Totals, resume_lowered_into, shift_count,
        shift_offset, shift_range,
    },
    velocity::{self, Break, Stated, Timer, TimerState, TimingSink},
};
use ncc_syntax::{BlockParser, Dialect, SyntaxNode, TextRange, TextSize, ast::AstNode};
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

pub use self::block_times::BlockTimes;
use crate::{
    InlayHint, InlayHintKind, MachineConfig,
    cnc8x6::model::{self, FileKind},
    db::{Db, Settings, SourceFile},
    dialect,
    ide::{
        common_ends::{common_prefix, common_suffix},
        symbols::content_end,
    },
};

/// What the cycle-time inlay hints show.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum CycleTimeHints {
    /// Each block's own time.
    #[default]
    PerBlock,
    /// The time since the program's start at each block's end.
    Cumulative,
    /// None (the speed-break markers stay off too).
    Off,
}

/// A program's predicted run, per block of the file and in total. Owned
/// and self-contained, so that a later estimate can start from it.
#[derive(Debug, Clone, Default)]
pub struct Estimate {
    /// The blocks of the file that ran, in the order they are written.
    pub blocks: BlockTimes,
    pub totals: CycleTotals,
    /// Why the run stopped before the program's end, if it did.
    pub stopped: Option<String>,
    /// The part of the text this estimate's run went through; the rest is
    /// a previous estimate's.
    pub rerun: std::ops::Range<TextSize>,
    /// Where a later estimate may go on from, in text order, and what the
    /// run read.
    checkpoints: Vec<Stored>,
    /// What `totals` shows, as a later estimate moves it.
    sums: Sums,
    /// Blocks the run executed, and the most it could.
    blocks_run: usize,
    budget: usize,
    text: Arc<String>,
    files: WorkspaceFiles,
    /// The machine it ran on (a run without checkpoints has it only here).
    machine: Arc<MachineConfig>,
}

/// One block of the file as it ran.
#[derive(Debug, PartialEq)]
pub struct BlockTime {
    pub range: TextRange,
    /// Seconds since the program's start when its first execution starts
    /// and ends (with the files it calls).
    pub start: f64,
    pub end: f64,
    /// Seconds of all its executions, with the steps of the files it calls.
    pub total: f64,
    pub executions: usize,
    /// Its own motion in its last execution.
    pub profile: velocity::Profile,
    /// The speed breaks at it, one per reason.
    pub breaks: SmallVec<[BreakAt; 1]>,
}

/// Every estimate after an edit copies the blocks it keeps: their breaks
/// as bytes.
impl Clone for BlockTime {
    fn clone(&self) -> BlockTime {
        BlockTime { breaks: SmallVec::from_slice(&self.breaks), ..*self }
    }
}

/// The drops of the path speed at a block for one reason, over all its
/// executions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BreakAt {
    /// Displayed, the reason in the control's terms; `code()`, its short
    /// name.
    pub reason: Stated,
    /// mm/min before the drop and at it, in the last execution.
    pub before: f64,
    pub at: f64,
    /// Seconds lost against a smooth join, over all executions.
    pub lost: f64,
    pub count: usize,
}

/// The whole program.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CycleTotals {
    pub total: f64,
    pub cutting: f64,
    pub rapid: f64,
    pub dwell: f64,
    pub breaks: usize,
    /// Seconds all breaks cost against smooth joins.
    pub lost: f64,
}

/// What a run of a file reads from the workspace, taken from a snapshot.
#[derive(Debug, Clone)]
pub struct RunInput {
    pub text: Arc<String>,
    pub machine: MachineConfig,
    pub files: WorkspaceFiles,
    /// The text's blocks as the analysis lowered them, which the run reads
    /// instead of lowering the text again.
    pub lowered: Option<LoweredProgram>,
}

/// The macrocycle files and possible cycle files of a workspace, or its
/// Haas program files, as the editor has them (unsaved edits too): what
/// the inline times and the plot of an open program run with.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WorkspaceFiles {
    /// Path and text by number.
    macrocycles: FxHashMap<u32, (String, Arc<String>)>,
    /// Haas program files named after their number (`O01234.nc`): path and
    /// text by number.
    programs: FxHashMap<u32, (String, Arc<String>)>,
    /// The number the running program's own file is named after, whose
    /// text is the run's: kept apart, so that an edit of the program leaves
    /// the files as they were and its estimate resumes.
    own_program: Option<u32>,
    /// The files named as the machine's cycle file, by their name without
    /// directory and extension, with their path.
    by_stem: Vec<(String, String, Arc<String>)>,
    /// Sinumerik: the other files of the workspace, which a program calls
    /// by the control's name (`_N_PROFIL_SPF` is `PROFIL.SPF`): path and
    /// text.
    control_files: Vec<(String, Arc<String>)>,
}

impl WorkspaceFiles {
    /// The path and text of the macrocycle file `L<number>`.
    pub fn macrocycle_file(&self, number: u32) -> Option<(&str, &str)> {
        self.macrocycles.get(&number).map(|(path, text)| (path.as_str(), text.as_str()))
    }

    /// The path and text of the Haas program file of `number`.
    pub fn program_file(&self, number: u32) -> Option<(&str, &str)> {
        self.programs.get(&number).map(|(path, text)| (path.as_str(), text.as_str()))
    }

    /// The path and text of the cycle file the machine names `name`.
    pub fn cycle_file_named(&self, name: &str) -> Option<(&str, &str)> {
        let stem = model::file_stem(name);
        let found = self.by_stem.iter().find(|(s, _, _)| s.eq_ignore_ascii_case(stem));
        found.map(|(_, path, text)| (path.as_str(), text.as_str()))
    }

    /// The path and text of the Sinumerik file the control names `name`
    /// (`_N_PROFIL_SPF`).
    pub fn control_file(&self, name: &str) -> Option<(&str, &str)> {
        let found = self.control_files.iter().find(|(path, _)| ncc_catalog::is_control_file(Path::new(path), name));
        found.map(|(path, text)| (path.as_str(), text.as_str()))
    }
}

impl Environment for WorkspaceFiles {
    fn file(&self, called: &Called) -> Option<String> {
        let found = match called {
            &Called::Number(number) => self.macrocycle_file(number),
            Called::Name(name) => self.cycle_file_named(name),
            &Called::Program(number) => self.program_file(number),
            Called::ControlFile(name) => self.control_file(name),
            Called::Written(_) => None,
        };
        found.map(|(_, text)| text.to_owned())
    }
}

/// What a run of `file` needs; `None` for macrocycle and cycle files,
/// which run only when a program calls them, and for a program the
/// executor does not run (no time rather than a wrong one).
pub(crate) fn run_input(db: &dyn Db, file: SourceFile) -> Option<RunInput> {
    let settings = Settings::get(db);
    if !nc_exec::run::interprets(*settings.dialect(db)) || model::file_kind(db, file) != FileKind::Program {
        return None;
    }
    let mut files = WorkspaceFiles::default();
    for (&number, found) in model::macrocycles(db) {
        if let Some(first) = found.first() {
            files.macrocycles.insert(number, (first.path(db).clone(), first.text(db).clone()));
        }
    }
    let machine = &settings.config(db).machine;
    if *settings.dialect(db) == Dialect::HaasLathe {
        for &other in settings.files(db) {
            let Some(number) = ncc_catalog::program_file_number(Path::new(other.path(db))) else { continue };
            if files.own_program == Some(number) || files.programs.contains_key(&number) {
                continue;
            }
            if other == file {
                files.own_program = Some(number);
            } else {
                files.programs.insert(number, (other.path(db).clone(), other.text(db).clone()));
            }
        }
    }
    if *settings.dialect(db) == Dialect::Sinumerik {
        let others = settings.files(db).iter().filter(|&&other| other != file);
        files.control_files = others.map(|other| (other.path(db).clone(), other.text(db).clone())).collect();
    }
    // Only the cycle file the machine names: an edit of another program
    // leaves this one's estimate as it is.
    if let Some(cycle_file) = machine.cycle_file.as_deref().map(model::file_stem) {
        for &other in settings.files(db) {
            let stem = model::file_stem(other.path(db));
            if other != file && stem.eq_ignore_ascii_case(cycle_file) {
                files.by_stem.push((stem.to_owned(), other.path(db).clone(), other.text(db).clone()));
            }
        }
    }
    let lowered = dialect::lowered_program(db, file);
    Some(RunInput { text: file.text(db).clone(), machine: machine.clone(), files, lowered })
}

/// Where the program's total is shown: the `%` header, or the first block.
pub(crate) fn program_head(db: &dyn Db, file: SourceFile) -> Option<TextRange> {
    let tree = file.parse(db).tree();
    match tree.header() {
        Some(header) => Some(header.syntax().text_range()),
        None => tree.blocks().next().map(|block| block.syntax().text_range()),
    }
}

impl RunInput {
    /// The estimate of this input; `previous`, an estimate of an earlier
    /// text of the same file, lets the run resume where the texts part.
    /// `None` when `abandoned` came true meanwhile (a newer text waits):
    /// the run asks it every few hundred blocks and gives up.
    pub fn estimate(
        &self,
        previous: Option<&Estimate>,
        budget: usize,
        abandoned: &dyn Fn() -> bool,
    ) -> Option<Estimate> {
        let watched = Watched { files: &self.files, abandoned };
        let program = (&self.text, self.lowered.as_ref());
        let estimate = estimate_in(previous, program, &self.files, &watched, &self.machine, budget);
        (!abandoned()).then_some(estimate)
    }
}

/// The workspace's files as a run reads them, and whether the run is
/// still wanted.
struct Watched<'a> {
    files: &'a WorkspaceFiles,
    abandoned: &'a dyn Fn() -> bool,
}

impl Environment for Watched<'_> {
    fn file(&self, called: &Called) -> Option<String> {
        self.files.file(called)
    }

    fn abandoned(&self) -> bool {
        (self.abandoned)()
    }
}

impl Estimate {
    /// Whether this estimate is the one of `input`: the same text, files
    /// and machine.
    pub fn holds_for(&self, input: &RunInput) -> bool {
        self.text == input.text && self.files == input.files && *self.machine == input.machine
    }
}

/// Blocks between two checkpoints of a run going block after block: an
/// edit reruns about this many blocks when the run comes back to the
/// course it took before.
const CHECKPOINT_INTERVAL: usize = 1000;

/// The one way to an estimate. With `previous`, the estimate of an earlier
/// text on the same machine and files, the run resumes from the last
/// checkpoint before the first changed byte, and stops at the first
/// checkpoint after the last one where it takes the course it took before:
/// the rest is the previous estimate's, moved.
pub fn estimate(
    previous: Option<&Estimate>,
    text: &Arc<String>,
    files: &WorkspaceFiles,
    machine: &MachineConfig,
    budget: usize,
) -> Estimate {
    estimate_in(previous, (text, None), files, files, machine, budget)
}

/// [`estimate`], the run reading the files through `environment`.
fn estimate_in(
    previous: Option<&Estimate>,
    (text, lowered): (&Arc<String>, Option<&LoweredProgram>),
    files: &WorkspaceFiles,
    environment: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
) -> Estimate {
    let environment = &WithOwnProgram { environment, number: files.own_program, text };
    let dynamics = nc_exec::run::dynamics(machine);
    let axes = machine.step_axes();
    let change = previous.and_then(|previous| Change::between(previous, text, files, machine, budget));
    let resumed = change.as_ref().and_then(|change| {
        let previous = change.previous;
        // Strictly before: the block before a checkpoint may end where it
        // does because of the byte after it.
        let index = previous.checkpoints.partition_point(|stored| stored.run.offset() < change.start);
        Some((index.checked_sub(1)?, previous))
    });
    let rerun_from = resumed.map_or(TextSize::default(), |(index, previous)| previous.checkpoints[index].run.offset());
    let mut charges = Charges::new(change);
    // The model times the steps as they come: the run keeps none. It runs
    // on the run's thread, leaving the other core to the editor's requests.
    let trace = match resumed {
        Some((index, previous)) => {
            let stored = &previous.checkpoints[index];
            charges.resume(previous, index);
            let mut timer = Timer::resume(axes, &dynamics, stored.model.clone(), charges);
            let checkpoint = Some(&stored.run);
            let trace = resume_lowered_into(checkpoint, text, lowered, environment, machine, budget, &mut timer);
            charges = timer.finish();
            trace
        }
        None => {
            let mut timer = Timer::new(axes, &dynamics, charges);
            let trace = resume_lowered_into(None, text, lowered, environment, machine, budget, &mut timer);
            charges = timer.finish();
            trace
        }
    };
    let stopped = trace.findings.iter().find(|finding| finding.stops()).map(|finding| finding.message.clone());
    let mut estimate = charges.into_estimate(text, files, machine, stopped, (trace.blocks_run, budget));
    estimate.rerun.start = rerun_from;
    estimate
}

/// The workspace's files, and the running program's own file as its
/// current text.
struct WithOwnProgram<'a> {
    environment: &'a dyn Environment,
    number: Option<u32>,
    text: &'a str,
}

impl Environment for WithOwnProgram<'_> {
    fn file(&self, called: &Called) -> Option<String> {
        match called {
            &Called::Program(number) if Some(number) == self.number => Some(self.text.to_owned()),
            _ => self.environment.file(called),
        }
    }

    fn abandoned(&self) -> bool {
        self.environment.abandoned()
    }
}

/// How a text differs from the text of a previous estimate: one changed
/// range, and the rest alike.
struct Change<'a> {
    previous: &'a Estimate,
    /// The changed range starts at `start` in both texts and ends `end`
    /// bytes before the new text's end.
    start: TextSize,
    end: TextSize,
    /// The new text's length minus the old one's.
    shift: i64,
    /// The step budget of the new run.
    budget: usize,
}

impl<'a> Change<'a> {
    /// `None` when the machine changed. When the files changed, the change
    /// reaches to the text's end: the program calls them only after its
    /// checkpoints, and everything after may differ.
    fn between(
        previous: &'a Estimate,
        text: &str,
        files: &WorkspaceFiles,
        machine: &MachineConfig,
        budget: usize,
    ) -> Option<Change<'a>> {
        if *previous.machine != *machine {
            return None;
        }
        let (old, new) = (previous.text.as_bytes(), text.as_bytes());
        let common = common_prefix(old, new);
        // After the common start, so that the two do not overlap.
        let common_end = common_suffix(&old[common..], &new[common..]);
        let offset = |at: usize| TextSize::try_from(at).ok();
        let end = if previous.files == *files { new.len() - common_end } else { new.len() };
        let shift = new.len() as i64 - old.len() as i64;
        Some(Change { previous, start: offset(common)?, end: offset(end)?, shift, budget })
    }
}

/// A checkpoint of the run, the model's state and the charges there.
#[derive(Debug, Clone)]
struct Stored {
    run: Checkpoint,
    model: TimerState,
    charges: Mark,
}

/// The charges at a checkpoint.
#[derive(Debug, Clone)]
struct Mark {
    /// Blocks charged so far; the last one may be charged more (its
    /// steps may wait in the model).
    blocks: usize,
    last: Option<BlockTime>,
    sums: Sums,
}

/// What a run adds up to: the executor's totals, the breaks and what they
/// cost.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    totals: Totals,
    breaks: usize,
    lost: f64,
}

impl Sums {
    /// These sums of a run whose part up to a checkpoint summed to `from`,
    /// after that part changed to sum to `to`.
    fn moved(&self, from: &Sums, to: &Sums) -> Sums {
        Sums {
            totals: self.totals.moved(&from.totals, &to.totals),
            breaks: (self.breaks + to.breaks).saturating_sub(from.breaks),
            lost: self.lost - from.lost + to.lost,
        }
    }

    fn cycle_totals(&self) -> CycleTotals {
        let totals = &self.totals;
        CycleTotals {
            total: totals.total_time,
            cutting: totals.time(Motion::Feed),
            rapid: totals.time(Motion::Rapid),
            dwell: totals.time(Motion::Dwell),
            breaks: self.breaks,
            lost: self.lost,
        }
    }
}

impl Stored {
    /// This checkpoint in the new text of a run that took the course of
    /// `from` at `to`.
    fn moved(&self, from: &Stored, to: &Stored, shift: i64) -> Stored {
        let blocks = to.charges.blocks as i64 - from.charges.blocks as i64;
        let steps = to.run.steps() as i64 - from.run.steps() as i64;
        let run_blocks = to.run.block() as i64 - from.run.block() as i64;
        let (from, to) = (&from.charges.sums, &to.charges.sums);
        let clock = to.totals.total_time - from.totals.total_time;
        Stored {
            run: self.run.shifted(shift, run_blocks, steps),
            model: self.model.shifted(shift, steps),
            charges: Mark {
                blocks: shift_count(self.charges.blocks, blocks),
                last: self.charges.last.as_ref().map(|last| last.moved(shift, clock)),
                sums: self.charges.sums.moved(from, to),
            },
        }
    }
}

impl BlockTime {
    /// The block in a text where it starts `shift` bytes later, its runs
    /// `clock` seconds later.
    fn moved(&self, shift: i64, clock: f64) -> BlockTime {
        BlockTime {
            range: shift_range(self.range, shift),
            start: self.start + clock,
            end: self.end + clock,
            ..self.clone()
        }
    }

    /// The block as charged so far, without when it ran.
    fn charged(&self, shift: i64) -> BlockTime {
        BlockTime { start: 0.0, end: 0.0, ..self.moved(shift, 0.0) }
    }
}

/// Every step charged to a block of the file as the model times it, and
/// the sums; the checkpoints of the run.
struct Charges<'a> {
    /// The blocks a resumed run starts with, shared with the previous
    /// estimate: a step of one of them (a jump back before the checkpoint)
    /// copies them into `blocks`.
    kept: BlockTimes,
    /// The blocks after `kept`; a block's index counts `kept`'s too.
    blocks: Vec<BlockTime>,
    /// Whether `blocks` are in text order, else where each one is.
    in_order: bool,
    index_of: FxHashMap<TextSize, usize>,
    /// The block of the last step of this file: steps of other files are
    /// its, and a new execution starts when another block's step comes.
    current: Option<usize>,
    sums: Sums,
    /// The checkpoints of the run that no block before them ran after:
    /// a block that runs again drops those after its start, which no
    /// longer have the final charges of the blocks before them.
    checkpoints: Vec<Stored>,
    change: Option<Change<'a>>,
    /// The previous estimate's checkpoint where the run took its course
    /// again, once it has.
    rejoined: Option<usize>,
}

impl<'a> Charges<'a> {
    fn new(change: Option<Change<'a>>) -> Charges<'a> {
        Charges {
            kept: BlockTimes::default(),
            blocks: Vec::new(),
            in_order: true,
            index_of: FxHashMap::default(),
            current: None,
            sums: Sums::default(),
            checkpoints: Vec::new(),
            change,
            rejoined: None,
        }
    }

    /// Starts from checkpoint `index` of `previous`: its blocks before it
    /// and their sums, and its checkpoints before it.
    fn resume(&mut self, previous: &Estimate, index: usize) {
        let mark = &previous.checkpoints[index].charges;
        self.kept = previous.blocks.prefix(mark.blocks.saturating_sub(1));
        self.blocks.extend(mark.last.clone());
        self.current = self.len().checked_sub(1);
        self.sums = mark.sums;
        self.checkpoints = previous.checkpoints[..index].to_vec();
    }

    /// The number of blocks charged.
    fn len(&self) -> usize {
        self.kept.len() + self.blocks.len()
    }

    /// The block at `index`, which is past `kept`.
    fn block_mut(&mut self, index: usize) -> &mut BlockTime {
        &mut self.blocks[index - self.kept.len()]
    }

    /// The block a step is charged to: its own in this file, found or
    /// added, else the block that ran last.
    fn block_of(&mut self, step: &Step) -> Option<usize> {
        if step.source != 0 {
            return self.current;
        }
        let start = step.range.start();
        if self.kept.last().is_some_and(|last| start <= last.range.start()) {
            // A jump back before the checkpoint the run resumed from.
            let after = std::mem::take(&mut self.blocks);
            self.blocks = std::mem::take(&mut self.kept).to_vec();
            self.blocks.extend(after);
            if !self.in_order {
                self.index_of = self.index_all();
            }
        }
        if self.in_order {
            // While blocks come in text order, their place finds them.
            let found = self.blocks.binary_search_by_key(&start, |block| block.range.start());
            let kept = self.kept.len();
            match found {
                Ok(index) => return Some(kept + index),
                Err(place) if place == self.blocks.len() => return Some(self.add_block(step)),
                Err(_) => {
                    self.in_order = false;
                    self.index_of = self.index_all();
                }
            }
        }
        if let Some(&index) = self.index_of.get(&start) {
            return Some(index);
        }
        let index = self.add_block(step);
        self.index_of.insert(start, index);
        Some(index)
    }

    /// Where each block of `blocks` is, by its start.
    fn index_all(&self) -> FxHashMap<TextSize, usize> {
        let kept = self.kept.len();
        self.blocks.iter().enumerate().map(|(i, block)| (block.range.start(), kept + i)).collect()
    }

    fn add_block(&mut self, step: &Step) -> usize {
        self.blocks.push(BlockTime {
            range: step.range,
            start: self.sums.totals.total_time,
            end: self.sums.totals.total_time,
            total: 0.0,
            executions: 0,
            profile: velocity::Profile::default(),
            breaks: SmallVec::new(),
        });
        self.len() - 1
    }

    fn mark(&self) -> Mark {
        let last = self.blocks.last().cloned().or_else(|| self.kept.last());
        Mark { blocks: self.len(), last, sums: self.sums }
    }

    /// The previous estimate's checkpoint at `offset`, when the text after
    /// it is alike and the run there may take its course again.
    fn counterpart(&self, offset: TextSize) -> Option<usize> {
        let change = self.change.as_ref()?;
        if offset < change.end {
            return None;
        }
        let old = shift_offset(offset, -change.shift);
        let checkpoints = &change.previous.checkpoints;
        let index = checkpoints.partition_point(|stored| stored.run.offset() < old);
        checkpoints.get(index).filter(|stored| stored.run.offset() == old).map(|_| index)
    }

    fn into_estimate(
        mut self,
        text: &Arc<String>,
        files: &WorkspaceFiles,
        machine: &MachineConfig,
        mut stopped: Option<String>,
        (mut blocks_run, budget): (usize, usize),
    ) -> Estimate {
        let mut sums = self.sums;
        let mut rerun_end = TextSize::of(text.as_str());
        let mut after = BlockTimes::default();
        // The rejoining checkpoint is the run's last.
        let rejoined = self.rejoined.zip(self.checkpoints.last().cloned());
        if let (Some((index, to)), Some(change)) = (rejoined, &self.change) {
            // The model's last steps were timed as the end of the program:
            // the previous estimate has them, and all after them.
            let previous = change.previous;
            let (from, to) = (&previous.checkpoints[index], &to);
            rerun_end = to.run.offset();
            let clock = to.charges.sums.totals.total_time - from.charges.sums.totals.total_time;
            let kept = to.charges.blocks.saturating_sub(1);
            self.blocks.truncate(kept.saturating_sub(self.kept.len()));
            self.kept = self.kept.prefix(kept);
            let first_old = from.charges.blocks.saturating_sub(1);
            after = previous.blocks.slice(first_old..previous.blocks.len()).moved(change.shift, clock);
            let later = previous.checkpoints[index + 1..].iter().map(|stored| stored.moved(from, to, change.shift));
            self.checkpoints.extend(later.collect::<Vec<_>>());
            sums = previous.sums.moved(&from.charges.sums, &to.charges.sums);
            stopped.clone_from(&previous.stopped);
            blocks_run = previous.blocks_run - from.run.blocks_run() + to.run.blocks_run();
        }
        if !self.in_order {
            self.blocks.sort_by_key(|block| block.range.start());
        }
        let mut blocks = self.kept;
        blocks.push_owned(self.blocks);
        blocks.append(after);
        Estimate {
            blocks,
            totals: sums.cycle_totals(),
            sums,
            stopped,
            rerun: TextSize::default()..rerun_end,
            checkpoints: self.checkpoints,
            blocks_run,
            budget,
            // A copy: while the estimate shares the file's text, the next
            // edit must copy it to change it, on the thread edits wait for.
            text: Arc::new(String::clone(text)),
            files: files.clone(),
            machine: Arc::new(machine.clone()),
        }
    }
}

impl TimingSink for Charges<'_> {
    fn speed_break(&mut self, step: &Step, speed_break: Break) {
        self.sums.breaks += 1;
        self.sums.lost += speed_break.lost;
        let Some(index) = self.block_of(step) else { return };
        let block = self.block_mut(index);
        let code = speed_break.reason.code();
        match block.breaks.iter_mut().find(|known| known.reason.code() == code) {
            Some(known) => {
                known.reason = speed_break.reason;
                (known.before, known.at) = (speed_break.before, speed_break.at);
                known.lost += speed_break.lost;
                known.count += 1;
            }
            None => block.breaks.push(BreakAt {
                reason: speed_break.reason,
                before: speed_break.before,
                at: speed_break.at,
                lost: speed_break.lost,
                count: 1,
            }),
        }
    }

    fn timed(&mut self, step: &Step, profile: velocity::Profile) {
        let start = self.sums.totals.total_time;
        self.sums.totals.add(step, profile.duration);
        let index = self.block_of(step);
        if step.source == 0
            && let Some(own) = index
        {
            let (continued, rejoined) = (self.current == index, self.rejoined.is_some());
            let block = self.block_mut(own);
            let mut runs_again = None;
            if continued {
                block.profile.peak = block.profile.peak.max(profile.peak);
                block.profile.exit = profile.exit;
                block.profile.duration += profile.duration;
            } else {
                block.executions += 1;
                block.profile = profile;
                // After the rejoining checkpoint the steps are the previous
                // estimate's, which kept it.
                if block.executions > 1 && !rejoined {
                    runs_again = Some(block.range.start());
                }
            }
            if let Some(start) = runs_again {
                let kept = self.checkpoints.partition_point(|stored| stored.run.offset() <= start);
                self.checkpoints.truncate(kept);
            }
            self.current = index;
        }
        if let Some(index) = index {
            let block = self.block_mut(index);
            block.total += profile.duration;
            if block.executions == 1 {
                block.end = start + profile.duration;
            }
        }
    }

    fn checkpoint_wanted(&mut self, block: usize, offset: TextSize) -> bool {
        block.is_multiple_of(CHECKPOINT_INTERVAL) || self.counterpart(offset).is_some()
    }

    fn checkpoint(&mut self, run: Checkpoint, model: TimerState) -> ControlFlow<()> {
        let counterpart = self.counterpart(run.offset());
        let stored = Stored { run, model, charges: self.mark() };
        let rejoins = counterpart.zip(self.change.as_ref()).is_some_and(|(index, change)| {
            let old = &change.previous.checkpoints[index];
            let charged = |mark: &Mark, shift| mark.last.as_ref().map(|last| last.charged(shift));
            // The previous run did not stop for the budget, and the blocks
            // it ran after its checkpoint still fit in it: an error it
            // stopped at, the run stops at again.
            let previous = change.previous;
            let blocks_run = previous.blocks_run - old.run.blocks_run() + stored.run.blocks_run();
            previous.budget == change.budget
                && previous.blocks_run <= change.budget
                && blocks_run <= change.budget
                && stored.run.same_course(&old.run)
                && stored.model.same_course(&old.model, change.shift)
                && charged(&stored.charges, 0) == charged(&old.charges, change.shift)
        });
        self.checkpoints.push(stored);
        if rejoins {
            self.rejoined = counterpart;
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    }
}

impl Estimate {
    /// The block whose range holds `offset` (its end included).
    pub fn block_at(&self, offset: TextSize) -> Option<BlockTime> {
        let after = self.blocks.partition_point(|block| block.range.start() <= offset);
        self.blocks.get(after.checked_sub(1)?).filter(|block| block.range.contains_inclusive(offset))
    }

    /// The hints in `range` (everywhere without one), at the end of the
    /// last line of each block that holds program text: its time, and a
    /// marker per reason the speed drops there. Offsets are in the text
    /// the estimate ran on.
    pub fn inlay_hints(&self, range: Option<TextRange>, mode: CycleTimeHints) -> Vec<InlayHint> {
        if mode == CycleTimeHints::Off {
            return Vec::new();
        }
        let first = range.map_or(0, |range| self.blocks.partition_point(|block| block.range.end() < range.start()));
        let mut hints = Vec::new();
        let mut blocks = BlockParser::new(&self.text);
        for block in self.blocks.iter_from(first) {
            if range.is_some_and(|range| block.range.start() > range.end()) {
                break;
            }
            if block.total <= 0.0 {
                continue;
            }
            let offset = match self.machine.control {
                Dialect::Cnc8x6 => hint_offset(&mut blocks, block.range),
                // One line is one block.
                Dialect::HaasLathe | Dialect::Sinumerik => line_end(&self.text, block.range),
            };
            // A block that ends where the range starts has its hints on
            // the line before.
            if range.is_some_and(|range| !range.contains_inclusive(offset)) {
                continue;
            }
            let label = match mode {
                CycleTimeHints::Cumulative => format!("Σ {}", short_time(block.end)),
                _ => short_time(block.total),
            };
            hints.push(InlayHint { offset, label, kind: InlayHintKind::BlockTime, tooltip: Some(block.summary()) });
            for speed_break in &block.breaks {
                let times = if speed_break.count > 1 { format!(" ×{}", speed_break.count) } else { String::new() };
                hints.push(InlayHint {
                    offset,
                    label: format!("▼ {}{times} −{}", speed_break.reason.code(), short_time(speed_break.lost)),
                    kind: InlayHintKind::SpeedBreak,
                    tooltip: Some(speed_break.explanation()),
                });
            }
        }
        hints
    }

    /// The program's total in one line, for the top of the file.
    pub fn headline(&self) -> String {
        let t = &self.totals;
        let mut line = format!(
            "Cycle time {} · cutting {} · rapid {}",
            short_time(t.total),
            short_time(t.cutting),
            short_time(t.rapid)
        );
        if t.dwell > 0.0 {
            let _ = write!(line, " · dwell {}", short_time(t.dwell));
        }
        match t.breaks {
            0 => {}
            1 => {
                let _ = write!(line, " · 1 break costs {}", short_time(t.lost));
            }
            n => {
                let _ = write!(line, " · {n} breaks cost {}", short_time(t.lost));
            }
        }
        if self.stopped.is_some() {
            line.push_str(" · the run stopped early");
        }
        line
    }

    /// Markdown about the block at `offset`: when it runs, how long, and
    /// its speed; `None` for a block that did not run.
    pub fn hover(&self, offset: TextSize) -> Option<String> {
        let block = self.block_at(offset)?;
        let mut text = format!("**Predicted time:** {}", block.summary());
        let p = &block.profile;
        if p.peak > 0.0 {
            let last = if block.executions > 1 { " (last run)" } else { "" };
            let _ = write!(
                text,
                "\n\n**Speed{last}:** entry {:.0} → peak {:.0} → exit {:.0} mm/min over {}",
                p.entry,
                p.peak,
                p.exit,
                short_time(p.duration)
            );
        }
        for speed_break in &block.breaks {
            let _ = write!(text, "\n\n{}", speed_break.explanation());
        }
        Some(text)
    }
}

impl BlockTime {
    /// `takes 420 ms, starts at 1:02.3 (3 runs)`.
    fn summary(&self) -> String {
        let runs = if self.executions > 1 { format!(" in {} runs", self.executions) } else { String::new() };
        format!("takes {}{runs}, starts at {}", short_time(self.total), short_time(self.start))
    }
}

impl BreakAt {
    /// The reason in the control's terms, the speeds and the cost.
    fn explanation(&self) -> String {
        let times = if self.count > 1 { format!(" ({} runs)", self.count) } else { String::new() };
        format!(
            "**Speed drops** ({}): {}. {:.0} → {:.0} mm/min; {} lost against a smooth join{times}.",
            self.reason.code(),
            self.reason,
            self.before,
            self.at,
            short_time(self.lost)
        )
    }
}

/// Where the hints of the block at `range` go: the end of its last line
/// that holds program text. A block runs up to the next block number, so
/// the comment lines after its words are its own; hints after them would
/// stand lines below the block.
fn hint_offset(blocks: &mut BlockParser<'_>, range: TextRange) -> TextSize {
    let block = blocks.block_at(range.start().into());
    block.map_or(range.end(), |(_, block)| range.start() + content_end(&SyntaxNode::new_root(block)))
}

/// The end of the first line of the block at `range`, before its line
/// break.
fn line_end(text: &str, range: TextRange) -> TextSize {
    let line = text.get(usize::from(range.start())..usize::from(range.end())).unwrap_or_default();
    let content = line.find(['\r', '\n']).unwrap_or(line.len());
    range.start() + TextSize::new(content as u32)
}

/// Hours, minutes and seconds of a non-negative time.
fn hms(seconds: f64) -> (f64, f64, f64) {
    let whole = seconds.max(0.0);
    let hours = (whole / 3600.0).floor();
    let minutes = ((whole - hours * 3600.0) / 60.0).floor();
    (hours, minutes, whole - hours * 3600.0 - minutes * 60.0)
}

/// `h:mm:ss.sss`, for reports.
pub fn clock(seconds: f64) -> String {
    // Whole milliseconds first, so that 59.9999 s is `0:01:00.000`.
    let ms = (seconds.max(0.0) * 1000.0).round() as u64;
    format!("{}:{:02}:{:02}.{:03}", ms / 3_600_000, ms / 60_000 % 60, ms / 1000 % 60, ms % 1000)
}

/// A short time for the editor: `0 s`, `0.4 ms`, `420 ms`, `4.25 s`,
/// `1:23.4`, `1:02:03.4`.
pub fn short_time(seconds: f64) -> String {
    let seconds = seconds.max(0.0);
    if seconds == 0.0 {
        return "0 s".to_owned();
    }
    if seconds < 0.01 {
        return format!("{:.1} ms", seconds * 1000.0);
    }
    if seconds < 0.9995 {
        return format!("{:.0} ms", seconds * 1000.0);
    }
    if seconds < 59.995 {
        return format!("{seconds:.2} s");
    }
    // Rounded first, so that 59.97 s is not `0:60.0`.
    let (hours, minutes, seconds) = hms((seconds * 10.0).round() / 10.0);
    if hours > 0.0 { format!("{hours}:{minutes:02}:{seconds:04.1}") } else { format!("{minutes}:{seconds:04.1}") }
}

mod block_times;
#[cfg(test)]
mod tests;
