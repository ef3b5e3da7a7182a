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
    run::{Called, Checkpoint, Environment, Motion, Step, Totals, shift_count, shift_offset, shift_range},
    velocity::{self, Break, Stated, Timer, TimerState, TimingSink},
};
use ncc_syntax::{BlockParser, Dialect, SyntaxNode, TextRange, TextSize, ast::AstNode};
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use crate::{
    InlayHint, InlayHintKind, MachineConfig,
    cnc8x6::model::{self, FileKind},
    db::{Db, Settings, SourceFile},
    ide::symbols::content_end,
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
    pub blocks: Vec<BlockTime>,
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
    revisited: Option<TextSize>,
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
            if let Some(number) = ncc_catalog::program_file_number(Path::new(other.path(db))) {
                files.programs.entry(number).or_insert_with(|| (other.path(db).clone(), other.text(db).clone()));
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
    Some(RunInput { text: file.text(db).clone(), machine: machine.clone(), files })
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
        let estimate = estimate_in(previous, &self.text, &self.files, &watched, &self.machine, budget);
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
    estimate_in(previous, text, files, files, machine, budget)
}

/// [`estimate`], the run reading the files through `environment`.
fn estimate_in(
    previous: Option<&Estimate>,
    text: &Arc<String>,
    files: &WorkspaceFiles,
    environment: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
) -> Estimate {
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
            let trace = nc_exec::run::resume_into(Some(&stored.run), text, environment, machine, budget, &mut timer);
            charges = timer.finish();
            trace
        }
        None => {
            let mut timer = Timer::new(axes, &dynamics, charges);
            let trace = nc_exec::run::run_into(text, environment, machine, budget, &mut timer);
            charges = timer.finish();
            trace
        }
    };
    let stopped = trace.findings.iter().find(|finding| finding.stops()).map(|finding| finding.message.clone());
    let mut estimate = charges.into_estimate(text, files, machine, stopped, (trace.blocks_run, budget));
    estimate.rerun.start = rerun_from;
    estimate
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

/// Bytes compared a run at a time, with `memcmp`, before byte by byte.
const COMPARED_RUN: usize = 4096;

/// How many bytes `a` and `b` start with alike.
fn common_prefix(a: &[u8], b: &[u8]) -> usize {
    let len = a.len().min(b.len());
    let mut at = 0;
    while at + COMPARED_RUN <= len && a[at..at + COMPARED_RUN] == b[at..at + COMPARED_RUN] {
        at += COMPARED_RUN;
    }
    at + a[at..len].iter().zip(&b[at..len]).take_while(|(x, y)| x == y).count()
}

/// How many bytes `a` and `b` end with alike.
fn common_suffix(a: &[u8], b: &[u8]) -> usize {
    let len = a.len().min(b.len());
    let (a, b) = (&a[a.len() - len..], &b[b.len() - len..]);
    let mut alike = 0;
    while alike + COMPARED_RUN <= len
        && a[len - alike - COMPARED_RUN..len - alike] == b[len - alike - COMPARED_RUN..len - alike]
    {
        alike += COMPARED_RUN;
    }
    alike + a[..len - alike].iter().rev().zip(b[..len - alike].iter().rev()).take_while(|(x, y)| x == y).count()
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
    blocks: Vec<BlockTime>,
    /// Whether `blocks` are in text order, else where each one is.
    in_order: bool,
    index_of: FxHashMap<TextSize, usize>,
    /// The block of the last step of this file: steps of other files are
    /// its, and a new execution starts when another block's step comes.
    current: Option<usize>,
    sums: Sums,
    checkpoints: Vec<Stored>,
    /// The first block in the text that ran again after other blocks (a
    /// jump back): a checkpoint after its start no longer has the final
    /// charges of the blocks before it.
    revisited: Option<TextSize>,
    change: Option<Change<'a>>,
    /// The previous estimate's checkpoint where the run took its course
    /// again, once it has.
    rejoined: Option<usize>,
}

impl<'a> Charges<'a> {
    fn new(change: Option<Change<'a>>) -> Charges<'a> {
        Charges {
            blocks: Vec::new(),
            in_order: true,
            index_of: FxHashMap::default(),
            current: None,
            sums: Sums::default(),
            checkpoints: Vec::new(),
            revisited: None,
            change,
            rejoined: None,
        }
    }

    /// Starts from checkpoint `index` of `previous`: its blocks before it
    /// and their sums, and its checkpoints before it.
    fn resume(&mut self, previous: &Estimate, index: usize) {
        let mark = &previous.checkpoints[index].charges;
        let charged = mark.blocks.saturating_sub(1);
        self.blocks = previous.blocks[..charged].to_vec();
        self.blocks.extend(mark.last.clone());
        self.current = self.blocks.len().checked_sub(1);
        self.sums = mark.sums;
        self.checkpoints = previous.checkpoints[..index].to_vec();
    }

    /// The block a step is charged to: its own in this file, found or
    /// added, else the block that ran last.
    fn block_of(&mut self, step: &Step) -> Option<usize> {
        if step.source != 0 {
            return self.current;
        }
        let start = step.range.start();
        if self.in_order {
            // While blocks come in text order, their place finds them.
            let found = self.blocks.binary_search_by_key(&start, |block| block.range.start());
            match found {
                Ok(index) => return Some(index),
                Err(place) if place == self.blocks.len() => return Some(self.add_block(step)),
                Err(_) => {
                    self.in_order = false;
                    self.index_of = self.blocks.iter().enumerate().map(|(i, block)| (block.range.start(), i)).collect();
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
        self.blocks.len() - 1
    }

    fn mark(&self) -> Mark {
        Mark { blocks: self.blocks.len(), last: self.blocks.last().cloned(), sums: self.sums }
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
            self.blocks.truncate(kept);
            let first_old = from.charges.blocks.saturating_sub(1);
            self.blocks.extend(previous.blocks[first_old..].iter().map(|block| block.moved(change.shift, clock)));
            let later = previous.checkpoints[index + 1..].iter().map(|stored| stored.moved(from, to, change.shift));
            self.checkpoints.extend(later.collect::<Vec<_>>());
            sums = previous.sums.moved(&from.charges.sums, &to.charges.sums);
            stopped.clone_from(&previous.stopped);
            blocks_run = previous.blocks_run - from.run.blocks_run() + to.run.blocks_run();
            // The run before the checkpoint went block after block.
            self.revisited = previous.revisited.map(|first| shift_offset(first, change.shift));
        }
        let revisited = self.revisited;
        self.checkpoints.retain(|stored| revisited.is_none_or(|first| stored.run.offset() <= first));
        if !self.in_order {
            self.blocks.sort_by_key(|block| block.range.start());
        }
        Estimate {
            blocks: self.blocks,
            totals: sums.cycle_totals(),
            sums,
            stopped,
            rerun: TextSize::default()..rerun_end,
            checkpoints: self.checkpoints,
            revisited,
            blocks_run,
            budget,
            text: text.clone(),
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
        let block = &mut self.blocks[index];
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
            let block = &mut self.blocks[own];
            if self.current == index {
                block.profile.peak = block.profile.peak.max(profile.peak);
                block.profile.exit = profile.exit;
                block.profile.duration += profile.duration;
            } else {
                block.executions += 1;
                block.profile = profile;
                if block.executions > 1 {
                    let start = block.range.start();
                    self.revisited = Some(self.revisited.map_or(start, |first| first.min(start)));
                }
            }
            self.current = index;
        }
        if let Some(block) = index.map(|index| &mut self.blocks[index]) {
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
    pub fn block_at(&self, offset: TextSize) -> Option<&BlockTime> {
        let after = self.blocks.partition_point(|block| block.range.start() <= offset);
        self.blocks[..after].last().filter(|block| block.range.contains_inclusive(offset))
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
        for block in &self.blocks[first..] {
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

#[cfg(test)]
mod tests {
    use expect_test::{Expect, expect};

    use super::*;
    use crate::{AnalysisHost, Config};

    /// The estimate of `program` in a workspace that also holds `others`
    /// (path, text).
    fn estimated(program: &str, others: &[(&str, &str)]) -> Estimate {
        let mut host = AnalysisHost::new(Config::default());
        let file = host.add_file("/p/PROGRAM.NCP", program);
        for (path, text) in others {
            host.add_file(*path, *text);
        }
        let input = host.analysis().run_input(file).expect("a program");
        input.estimate(None, nc_exec::run::DEFAULT_STEP_BUDGET, &|| false).expect("never abandoned")
    }

    /// One line per block: its first line, when it starts, its time, its
    /// runs, its speed profile and breaks, in ms and mm/min.
    fn render(program: &str, estimate: &Estimate) -> String {
        let ms = |s: f64| format!("{:.1}", s * 1000.0);
        let mut out = String::new();
        for block in &estimate.blocks {
            let text = program[block.range].lines().next().unwrap_or_default();
            let p = &block.profile;
            let _ = write!(
                out,
                "{text:<24} start {:>7} end {:>7} total {:>7} ×{} speed {:.0}/{:.0}/{:.0} in {}",
                ms(block.start),
                ms(block.end),
                ms(block.total),
                block.executions,
                p.entry,
                p.peak,
                p.exit,
                ms(p.duration)
            );
            for b in &block.breaks {
                let _ = write!(out, " | {} ×{} {:.0}→{:.0} −{}", b.reason.code(), b.count, b.before, b.at, ms(b.lost));
            }
            out.push('\n');
        }
        let t = &estimate.totals;
        let _ = writeln!(
            out,
            "total {} cutting {} rapid {} dwell {} breaks {} lost {}",
            ms(t.total),
            ms(t.cutting),
            ms(t.rapid),
            ms(t.dwell),
            t.breaks,
            ms(t.lost)
        );
        out
    }

    fn check(program: &str, others: &[(&str, &str)], expect: Expect) -> Estimate {
        let estimate = estimated(program, others);
        expect.assert_eq(&render(program, &estimate));
        estimate
    }

    /// The velocity model's own timing of the program alone.
    fn model_total(program: &str) -> f64 {
        let machine = MachineConfig::default();
        let trace = nc_exec::run::run(program, &nc_exec::run::NoFiles, &machine, 1000);
        velocity::time(&trace, &nc_exec::run::dynamics(&machine)).total_time()
    }

    #[test]
    fn a_corner_stops_the_path_and_costs_its_ramps() {
        let program = "%1\nN10 G23 G01 X10 F600\nN20 Y10\nN30 X20\nN40 M30\n*\n";
        let estimate = check(
            program,
            &[],
            expect![[r#"
                N10 G23 G01 X10 F600     start     0.0 end  1035.0 total  1035.0 ×1 speed 0/600/0 in 1035.0 | corner ×1 600→0 −35.0
                N20 Y10                  start  1035.0 end  2070.0 total  1035.0 ×1 speed 0/600/0 in 1035.0 | corner ×1 600→0 −35.0
                N30 X20                  start  2070.0 end  3105.0 total  1035.0 ×1 speed 0/600/0 in 1035.0 | non-motion ×1 600→0 −22.5
                N40 M30                  start  3105.0 end  3105.0 total     0.0 ×1 speed 0/0/0 in 0.0
                total 3105.0 cutting 3105.0 rapid 0.0 dwell 0.0 breaks 3 lost 92.5
            "#]],
        );
        assert_eq!(estimate.totals.total, model_total(program));
        let sum: f64 = estimate.blocks.iter().map(|block| block.total).sum();
        assert!((sum - estimate.totals.total).abs() < 1e-9, "{sum} vs {}", estimate.totals.total);
    }

    #[test]
    fn a_subprogram_called_three_times_is_charged_each_run() {
        let program = "%1\nN1 G23 G01 F600 G71 L1 Q3\nN2 M30\nN3 G79 L1\nN4 G91 X10\nN5 G70\n*\n";
        let estimate = check(
            program,
            &[],
            expect![[r#"
                N1 G23 G01 F600 G71 L1 Q3 start     0.0 end     0.0 total     0.0 ×1 speed 0/0/0 in 0.0
                N2 M30                   start  3105.0 end  3105.0 total     0.0 ×1 speed 0/0/0 in 0.0
                N4 G91 X10               start     0.0 end  1035.0 total  3105.0 ×3 speed 0/600/0 in 1035.0 | non-motion ×3 600→0 −67.5
                N5 G70                   start  1035.0 end  1035.0 total     0.0 ×3 speed 0/0/0 in 0.0
                total 3105.0 cutting 3105.0 rapid 0.0 dwell 0.0 breaks 3 lost 67.5
            "#]],
        );
        assert_eq!(estimate.totals.total, model_total(program));
    }

    #[test]
    fn a_macrocycle_is_charged_to_the_calling_block() {
        let program = "%1\nN10 G91 G01 F600\nN20 G72 L9001 Q2\nN30 G90 X0\nN40 M30\n*\n";
        let macrocycle = "N1 G79 L9001\nN2 G01 X10\nN3 Y5\nN4 G70\n*\n";
        let estimate = check(
            program,
            &[("/p/L9001", macrocycle)],
            expect![[r#"
                N10 G91 G01 F600         start     0.0 end     0.0 total     0.0 ×1 speed 0/0/0 in 0.0
                N20 G72 L9001 Q2         start     0.0 end  3120.0 total  3120.0 ×1 speed 0/0/0 in 0.0 | g98 ×2 600→0 −60.0 | non-motion ×2 600→0 −50.0
                N30 G90 X0               start  3120.0 end  5150.0 total  2030.0 ×1 speed 0/600/0 in 2030.0 | non-motion ×1 600→0 −25.0
                N40 M30                  start  5150.0 end  5150.0 total     0.0 ×1 speed 0/0/0 in 0.0
                total 5150.0 cutting 5150.0 rapid 0.0 dwell 0.0 breaks 5 lost 135.0
            "#]],
        );
        // Everything the macrocycle did is in N20.
        let call = &estimate.blocks[1];
        let rest: f64 = estimate.blocks.iter().filter(|block| block.range != call.range).map(|b| b.total).sum();
        assert!((call.total + rest - estimate.totals.total).abs() < 1e-9);
        assert!(call.total > 3.0, "two runs of 15 mm at 10 mm/s and their ramps: {}", call.total);
    }

    #[test]
    fn hints_hover_and_headline_show_the_times() {
        let program = "%1\nN10 G23 G01 X10 F600\nN20 Y10 \"SIDE\"\nN30 M30\n*\n";
        let estimate = estimated(program, &[]);
        let hints: Vec<String> = estimate
            .inlay_hints(None, CycleTimeHints::PerBlock)
            .iter()
            .map(|hint| {
                format!("{}: {}", &program[..usize::from(hint.offset)].rsplit('\n').next().unwrap(), hint.label)
            })
            .collect();
        expect![[r#"
            [
                "N10 G23 G01 X10 F600: 1.03 s",
                "N10 G23 G01 X10 F600: ▼ corner −35 ms",
                "N20 Y10 \"SIDE\": 1.03 s",
                "N20 Y10 \"SIDE\": ▼ non-motion −22 ms",
            ]
        "#]]
        .assert_debug_eq(&hints);
        let cumulative: Vec<String> = estimate
            .inlay_hints(None, CycleTimeHints::Cumulative)
            .into_iter()
            .filter(|hint| hint.kind == InlayHintKind::BlockTime)
            .map(|hint| hint.label)
            .collect();
        expect![[r#"
            [
                "Σ 1.03 s",
                "Σ 2.07 s",
            ]
        "#]]
        .assert_debug_eq(&cumulative);
        assert!(estimate.inlay_hints(None, CycleTimeHints::Off).is_empty());
        // Only the hints in the range: the line of N20, not N10's before it.
        let n20 = TextSize::from(program.find("N20").unwrap() as u32);
        let line = TextRange::new(n20, TextSize::from(program.find("\nN30").unwrap() as u32));
        let ranged: Vec<String> =
            estimate.inlay_hints(Some(line), CycleTimeHints::PerBlock).into_iter().map(|h| h.label).collect();
        assert_eq!(ranged, ["1.03 s", "▼ non-motion −22 ms"]);
        expect![[r#"
            **Predicted time:** takes 1.03 s, starts at 1.03 s

            **Speed:** entry 0 → peak 600 → exit 0 mm/min over 1.03 s

            **Speed drops** (non-motion): a block without motion between moves. 600 → 0 mm/min; 22 ms lost against a smooth join."#]].assert_eq(&estimate.hover(n20 + TextSize::from(5)).unwrap());
        expect!["Cycle time 2.07 s · cutting 2.07 s · rapid 0 s · 2 breaks cost 57 ms"].assert_eq(&estimate.headline());
        assert_eq!(estimate.hover(TextSize::from(0)), None, "the header is no block");
    }

    #[test]
    fn a_blocks_hints_end_its_last_line_of_program_text_not_the_comment_lines_after_it() {
        let program = "%1\nN10 R11=5.\nN20 G01 X10\nY10 F600 \"SIDE\"  \n\"NEXT\"\nN30 / G00 ZR11\n\"LIFT\"\n  \"CLEAR\"\n\nN40 M30\n*\n";
        let estimate = estimated(program, &[]);
        // Each line with its hints in brackets where they stand.
        let mut shown = program.to_owned();
        for hint in estimate.inlay_hints(None, CycleTimeHints::PerBlock).iter().rev() {
            shown.insert_str(usize::from(hint.offset), &format!("[{}]", hint.label));
        }
        expect![[r#"
            %1
            N10 R11=5.
            N20 G01 X10
            Y10 F600 "SIDE"[1.44 s][▼ rapid −34 ms]  
            "NEXT"
            N30 / G00 ZR11[161 ms][▼ rapid −61 ms]
            "LIFT"
              "CLEAR"

            N40 M30
            *
        "#]]
        .assert_eq(&shown);
    }

    /// A CAM-like program of `blocks` moves: absolute contours with
    /// corners, rapids, a dwell now and then.
    fn long_program(blocks: usize) -> String {
        let mut text = String::from("%1\nN1 G54 G90 G00 X0 Y0 Z5 M03 S8000\nN2 G01 Z-1 F1200\n");
        for i in 0..blocks {
            let (x, y) = ((i % 97) as f64 * 0.7, (i / 97) as f64 * 1.3 + (i % 5) as f64 * 0.2);
            let block = match i % 50 {
                17 => "G04 Q10".to_owned(),
                31 => format!("G00 X{x:.3} Y{y:.3}"),
                32 => format!("G01 X{x:.3} Y{y:.3} F900"),
                _ => format!("X{x:.3} Y{y:.3}"),
            };
            text.push_str(&format!("N{} {block}\n", i + 3));
        }
        text.push_str("N99999 G00 Z5 M30\n");
        text
    }

    fn estimate_of(text: &str, previous: Option<&Estimate>) -> Estimate {
        let machine = MachineConfig::default();
        estimate(previous, &Arc::new(text.to_owned()), &WorkspaceFiles::default(), &machine, 1_000_000)
    }

    /// The estimates agree on every block and total, to rounding.
    fn assert_alike(resumed: &Estimate, whole: &Estimate) {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()));
        assert_eq!(resumed.blocks.len(), whole.blocks.len());
        for (r, w) in resumed.blocks.iter().zip(&whole.blocks) {
            assert_eq!((r.range, r.executions, &r.profile), (w.range, w.executions, &w.profile));
            assert!(close(r.start, w.start) && close(r.end, w.end) && close(r.total, w.total), "{r:?} vs {w:?}");
            assert_eq!(r.breaks.len(), w.breaks.len(), "{r:?} vs {w:?}");
            for (r, w) in r.breaks.iter().zip(&w.breaks) {
                assert_eq!((r.reason.code(), r.count), (w.reason.code(), w.count));
                assert!(close(r.lost, w.lost));
            }
        }
        let (r, w) = (&resumed.totals, &whole.totals);
        assert_eq!(r.breaks, w.breaks);
        for (a, b) in
            [(r.total, w.total), (r.cutting, w.cutting), (r.rapid, w.rapid), (r.dwell, w.dwell), (r.lost, w.lost)]
        {
            assert!(close(a, b), "{r:?} vs {w:?}");
        }
        assert_eq!(resumed.stopped, whole.stopped);
    }

    #[test]
    fn an_edit_reruns_from_the_checkpoint_before_it_to_where_the_run_takes_its_course_again() {
        let text = long_program(5000);
        let first = estimate_of(&text, None);
        assert_eq!(first.rerun, TextSize::default()..TextSize::of(text.as_str()));
        assert!(first.checkpoints.len() >= 5, "{} checkpoints", first.checkpoints.len());
        // A digit typed into an absolute coordinate in the middle.
        let at = text.find("N2503 X").expect("the block") + "N2503 X".len();
        let edited = format!("{}7{}", &text[..at], &text[at..]);
        let resumed = estimate_of(&edited, Some(&first));
        let whole = estimate_of(&edited, None);
        assert_alike(&resumed, &whole);
        assert!(resumed.totals.total > first.totals.total, "the move got longer");
        // From the checkpoint at block 2000 (N2001) to the one at block 3000.
        let rerun = usize::from(resumed.rerun.start)..usize::from(resumed.rerun.end);
        assert!(edited[rerun.clone()].starts_with("N2001 ") && edited[rerun.end..].starts_with("N3001 "), "{rerun:?}");
        // Edited again, from the resumed estimate: its checkpoints hold.
        let at = edited.find("N4321 X").expect("the block") + "N4321 X".len();
        let again = format!("{}{}", &edited[..at], &edited[at + 1..]);
        let resumed = estimate_of(&again, Some(&resumed));
        assert_alike(&resumed, &estimate_of(&again, None));
        assert!(resumed.rerun.end < TextSize::of(again.as_str()));
    }

    #[test]
    fn checkpoints_after_the_first_block_a_jump_goes_back_to_are_not_used() {
        // N1000 … N2502 run twice: a checkpoint after N1000 does not have
        // their final charges.
        let text = long_program(2500).replace("N99999 G00", "N99998 G73 L1000 Q1\nN99999 G00");
        let first = estimate_of(&text, None);
        let n1000 = TextSize::of(&text[..text.find("N1000 ").expect("the block")]);
        assert!(first.checkpoints.iter().all(|stored| stored.run.offset() <= n1000));
        for (edit, at) in [("", "N2000 X"), ("7", "N2000 X"), ("7", "N900 X")] {
            let at = text.find(at).expect("the block") + 7;
            let edited = format!("{}{edit}{}", &text[..at], &text[at..]);
            let resumed = estimate_of(&edited, Some(&first));
            assert_alike(&resumed, &estimate_of(&edited, None));
            assert!(resumed.blocks.iter().any(|block| block.executions == 2));
        }
    }

    #[test]
    fn a_block_more_in_a_program_that_fills_the_step_budget_stops_the_run() {
        let machine = MachineConfig::default();
        let files = WorkspaceFiles::default();
        let text = Arc::new(long_program(2500));
        let budget = estimate(None, &text, &files, &machine, 1_000_000).blocks_run;
        let first = estimate(None, &text, &files, &machine, budget);
        assert_eq!(first.stopped, None);
        let at = text.find("N1503 ").expect("the block");
        let edited = Arc::new(format!("{}N5 X1 Y1\n{}", &text[..at], &text[at..]));
        let resumed = estimate(Some(&first), &edited, &files, &machine, budget);
        let whole = estimate(None, &edited, &files, &machine, budget);
        assert!(whole.stopped.is_some());
        assert_alike(&resumed, &whole);
    }

    #[test]
    fn an_edit_that_changes_everything_after_it_reruns_to_the_end() {
        let text = long_program(3000);
        let first = estimate_of(&text, None);
        let edited = text.replacen("N1500 ", "N1500 G91 ", 1);
        let resumed = estimate_of(&edited, Some(&first));
        assert_eq!(resumed.rerun.end, TextSize::of(edited.as_str()));
        assert!(resumed.rerun.start > TextSize::default());
        assert_alike(&resumed, &estimate_of(&edited, None));
    }

    #[test]
    fn under_the_envelope_velocity_an_edit_reruns_from_the_checkpoint_before_it_to_the_end() {
        let machine = MachineConfig { constants: [(338, 20)].into(), ..MachineConfig::default() };
        let files = WorkspaceFiles::default();
        let text = Arc::new(long_program(3000));
        let first = estimate(None, &text, &files, &machine, 1_000_000);
        let at = text.find("N1503 X").expect("the block") + "N1503 X".len();
        let edited = Arc::new(format!("{}7{}", &text[..at], &text[at..]));
        let resumed = estimate(Some(&first), &edited, &files, &machine, 1_000_000);
        assert!(edited[usize::from(resumed.rerun.start)..].starts_with("N1001 "));
        assert_eq!(resumed.rerun.end, TextSize::of(edited.as_str()));
        assert_alike(&resumed, &estimate(None, &edited, &files, &machine, 1_000_000));
    }

    #[test]
    fn a_changed_macrocycle_file_reruns_from_the_last_checkpoint() {
        let text = long_program(2500).replace("N99999 G00 Z5 M30", "N99998 G72 L9001\nN99999 G00 Z5 M30");
        let files = |x: &str| WorkspaceFiles {
            macrocycles: [(
                9001,
                ("L9001".to_owned(), Arc::new(format!("N1 G79 L9001\nN2 G91 G01 X{x}\nN3 G90 G70\n*\n"))),
            )]
            .into_iter()
            .collect(),
            by_stem: Vec::new(),
            programs: FxHashMap::default(),
            control_files: Vec::new(),
        };
        let machine = MachineConfig::default();
        let text = Arc::new(text);
        let first = estimate(None, &text, &files("10"), &machine, 1_000_000);
        assert!(first.holds_for(&RunInput { text: text.clone(), machine: machine.clone(), files: files("10") }));
        let changed = files("30");
        assert!(!first.holds_for(&RunInput { text: text.clone(), machine: machine.clone(), files: changed.clone() }));
        let resumed = estimate(Some(&first), &text, &changed, &machine, 1_000_000);
        assert!(resumed.rerun.start > TextSize::default());
        assert_alike(&resumed, &estimate(None, &text, &changed, &machine, 1_000_000));
        // 20 mm more at the last feed, 900 mm/min.
        let longer = resumed.totals.total - first.totals.total;
        assert!((longer - 20.0 / 15.0).abs() < 0.05, "{longer}");
    }

    /// A Haas program's M98 runs the program file named after the number
    /// in the workspace, as the editor has it.
    #[test]
    fn a_haas_program_runs_the_program_files_of_the_workspace() {
        let mut host = AnalysisHost::in_dialect(Dialect::HaasLathe, Config::default());
        let file = host.add_file("/p/main.nc", "O1\nM98 P1000\nM30\n");
        host.add_file("/p/O01000.nc", "O1000\nG98 G01 W-10. F600.\nM99\n");
        host.add_file("/p/other.nc", "O2\nM30\n");
        let input = host.analysis().run_input(file).expect("a program");
        assert_eq!(input.files.program_file(1000).map(|(path, _)| path), Some("/p/O01000.nc"));
        assert_eq!(input.files.program_file(2), None, "found by its file's name only");
        // 10 mm at 600 mm/min, with the ramps.
        let total = input.estimate(None, 1000, &|| false).expect("never abandoned").totals.total;
        assert!(total >= 1.0, "{total}");
    }

    /// An estimate asked for a text typed on meanwhile is given up.
    #[test]
    fn an_abandoned_estimate_is_none() {
        let mut host = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
        let file = host.add_file("/p/MAIN.MPF", "G1 X10 F100\nM30\n");
        let input = host.analysis().run_input(file).expect("a program");
        assert!(input.estimate(None, 1000, &|| true).is_none());
        assert!(input.estimate(None, 1000, &|| false).is_some_and(|estimate| estimate.totals.total > 0.0));
    }

    /// In a dialect whose lines are blocks, a block's hints stand at the
    /// end of its own line, not after the lines below it.
    #[test]
    fn hints_of_a_line_dialect_stand_on_the_blocks_line() {
        let machine = MachineConfig::of_control(Dialect::Sinumerik);
        let text = Arc::new("G0 X10 Z2 ; in\nR1=5\nG1 X20 F600\nM30\n".to_owned());
        let estimate = estimate(None, &text, &WorkspaceFiles::default(), &machine, 1000);
        let lines: Vec<&str> = estimate
            .inlay_hints(None, CycleTimeHints::PerBlock)
            .iter()
            .filter(|hint| hint.kind == InlayHintKind::BlockTime)
            .map(|hint| text[..usize::from(hint.offset)].lines().last().unwrap_or_default())
            .collect();
        assert_eq!(lines, ["G0 X10 Z2 ; in", "G1 X20 F600"]);
    }

    /// A Haas lathe estimate knows its input: an edit of another file
    /// does not run it again.
    #[test]
    fn a_haas_estimate_holds_for_its_input() {
        let machine = MachineConfig::of_control(Dialect::HaasLathe);
        let text = Arc::new("O1\nG98 G01 X20. Z-10. F100.\nM30\n".to_owned());
        let files = WorkspaceFiles::default();
        let first = estimate(None, &text, &files, &machine, 1000);
        assert_eq!(first.checkpoints.iter().map(|stored| stored.run.block()).collect::<Vec<_>>(), [0]);
        // 5 mm of radius and 10 mm of Z at 100 mm/min, with the ramps.
        assert!(first.totals.total > 125.0f64.sqrt() / 100.0 * 60.0, "{}", first.totals.total);
        assert!(first.holds_for(&RunInput { text: text.clone(), machine: machine.clone(), files: files.clone() }));
        let milling = MachineConfig::default();
        assert!(!first.holds_for(&RunInput { text: text.clone(), machine: milling, files }));
    }

    /// A long Haas lathe program: moves from CAM, a dwell now and then, and
    /// a local subprogram after its end that edits may call.
    fn long_haas_program(blocks: usize) -> String {
        let mut text = String::from("O1\nG54 G18 G97 G98 G00 X0 Z5. M03 S1000\n#100 = 1.\nG01 Z0 F1200.\n");
        for i in 0..blocks {
            let (x, z) = ((i % 97) as f64 * 0.7, -((i / 97) as f64 * 1.3 + (i % 5) as f64 * 0.2));
            let block = match i % 250 {
                17 => "G04 P10".to_owned(),
                31 => format!("G00 X{x:.3} Z{z:.3}"),
                32 => format!("G01 X{x:.3} Z{z:.3} F900."),
                _ => format!("X{x:.3} Z{z:.3}"),
            };
            text.push_str(&format!("N{} {block}\n", i + 3));
        }
        text.push_str("N99999 G00 X100. M30\nN90000 G01 W-0.5\nW0.5\nM99\n");
        text
    }

    fn haas_estimate_of(text: &str, previous: Option<&Estimate>) -> Estimate {
        let machine = MachineConfig::of_control(Dialect::HaasLathe);
        estimate(previous, &Arc::new(text.to_owned()), &WorkspaceFiles::default(), &machine, 1_000_000)
    }

    #[test]
    fn a_haas_run_takes_no_checkpoints_after_calling_a_subprogram_written_after_the_main_program() {
        let text = long_haas_program(5000).replace("N1503 ", "M97 P90000\nN1503 ");
        let first = haas_estimate_of(&text, None);
        let call = TextSize::of(&text[..text.find("M97 P90000").expect("the call")]);
        let blocks: Vec<usize> = first.checkpoints.iter().map(|stored| stored.run.block()).collect();
        assert!(first.checkpoints.iter().all(|stored| stored.run.offset() < call), "{blocks:?}");
        assert_eq!(blocks, [0, 1000]);
        let at = text.find("N2503 X").expect("the block") + "N2503 X".len();
        let edited = format!("{}7{}", &text[..at], &text[at..]);
        let resumed = haas_estimate_of(&edited, Some(&first));
        assert_alike(&resumed, &haas_estimate_of(&edited, None));
        assert!(edited[usize::from(resumed.rerun.start)..].starts_with("N999 "));
    }

    #[test]
    fn an_edit_of_a_haas_program_reruns_from_the_checkpoint_before_it_to_where_the_run_takes_its_course_again() {
        let text = long_haas_program(5000);
        let first = haas_estimate_of(&text, None);
        assert_eq!(first.stopped, None);
        assert!(first.checkpoints.len() >= 5, "{} checkpoints", first.checkpoints.len());
        // A digit typed into an absolute coordinate in the middle.
        let at = text.find("N2503 X").expect("the block") + "N2503 X".len();
        let edited = format!("{}7{}", &text[..at], &text[at..]);
        let resumed = haas_estimate_of(&edited, Some(&first));
        let whole = haas_estimate_of(&edited, None);
        assert_alike(&resumed, &whole);
        assert!(resumed.totals.total > first.totals.total, "the move got longer");
        // From the checkpoint at block 2000 (N1999) to the one at block 3000.
        let rerun = usize::from(resumed.rerun.start)..usize::from(resumed.rerun.end);
        assert!(edited[rerun.clone()].starts_with("N1999 ") && edited[rerun.end..].starts_with("N2999 "), "{rerun:?}");
        // Edited again, from the resumed estimate: its checkpoints hold.
        let at = edited.find("N4321 X").expect("the block") + "N4321 X".len();
        let again = format!("{}{}", &edited[..at], &edited[at + 1..]);
        let resumed = haas_estimate_of(&again, Some(&resumed));
        assert_alike(&resumed, &haas_estimate_of(&again, None));
        assert!(resumed.rerun.end < TextSize::of(again.as_str()));
    }

    proptest::proptest! {
        /// The run-at-a-time comparisons count what byte by byte does.
        #[test]
        fn common_starts_and_ends_are_counted_exactly(
            shared in proptest::collection::vec(0u8..3, 0..9000),
            a in proptest::collection::vec(0u8..3, 0..30),
            b in proptest::collection::vec(0u8..3, 0..30),
            tail in proptest::collection::vec(0u8..3, 0..9000),
        ) {
            let left: Vec<u8> = [&shared[..], &a, &tail].concat();
            let right: Vec<u8> = [&shared[..], &b, &tail].concat();
            let prefix = left.iter().zip(&right).take_while(|(x, y)| x == y).count();
            let suffix = left.iter().rev().zip(right.iter().rev()).take_while(|(x, y)| x == y).count();
            proptest::prop_assert_eq!(common_prefix(&left, &right), prefix);
            proptest::prop_assert_eq!(common_suffix(&left, &right), suffix);
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(12))]

        /// Resumed estimates equal whole runs, edit after edit: digits
        /// typed or deleted, blocks inserted or removed, a jump back or
        /// forward inserted, a jump to no block (the run stops there).
        #[test]
        fn resumed_estimates_equal_whole_runs(
            edits in proptest::collection::vec((0.0f64..1.0, 0u8..6), 1..4),
        ) {
            let later = ["N6 G73 L1000 Q1\n", "N7 G73 L77777 Q1\n"];
            assert_edits_resume_as_whole_runs(long_program(2500), &edits, "N5 G01 X1 Y1 F2000\n", &later, estimate_of);
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(12))]

        /// Resumed estimates of a Haas lathe program equal whole runs, edit
        /// after edit: digits typed or deleted, blocks inserted or removed,
        /// a jump back or forward once, a jump to no block (the run stops
        /// there), a call, a block numbered like a jump's target.
        #[test]
        fn resumed_haas_estimates_equal_whole_runs(
            edits in proptest::collection::vec((0.0f64..1.0, 0u8..8), 1..4),
        ) {
            let later = ["#1 = #1 + 1\nIF [#1 LT 2] GOTO 1000\n", "GOTO 77777\n", "M97 P90000\n", "N1000 G01 X2.\n"];
            let first = "N5 G01 X1. Z1. F2000.\n";
            assert_edits_resume_as_whole_runs(long_haas_program(2500), &edits, first, &later, haas_estimate_of);
        }
    }

    /// Applies `edits` to `text` one by one, at a place (a fraction of the
    /// text) of a kind: a digit typed into (0) or deleted from (1) an X
    /// word, the block `first` inserted anywhere (2), a block of `later`
    /// (3 on) inserted after the first line, else a line removed; after
    /// each, the estimate resumed from the last equals a whole run's.
    fn assert_edits_resume_as_whole_runs(
        mut text: String,
        edits: &[(f64, u8)],
        first: &str,
        later: &[&str],
        estimate_of: fn(&str, Option<&Estimate>) -> Estimate,
    ) {
        let mut previous = estimate_of(&text, None);
        for &(place, kind) in edits {
            let line_start = text[..(place * text.len() as f64) as usize].rfind('\n').map_or(0, |i| i + 1);
            let line_end = text[line_start..].find('\n').map_or(text.len(), |i| line_start + i + 1);
            let word = text[line_start..line_end].find(" X").map(|i| line_start + i + 2);
            let block = usize::from(kind).checked_sub(3).and_then(|i| later.get(i));
            match (kind, word, block) {
                (0, Some(at), _) => text.insert(at, '3'),
                (1, Some(at), _) => {
                    text.remove(at);
                }
                (2, _, _) => text.insert_str(line_start, first),
                (_, _, Some(block)) if line_start > 0 => text.insert_str(line_start, block),
                _ if line_start > 0 && line_end < text.len() => text.replace_range(line_start..line_end, ""),
                _ => {}
            }
            let resumed = estimate_of(&text, Some(&previous));
            assert_alike(&resumed, &estimate_of(&text, None));
            previous = resumed;
        }
    }

    #[test]
    fn times_read_short() {
        let shown: Vec<String> =
            [0.0, 0.0004, 0.0123, 0.42, 0.9996, 4.254, 59.97, 83.44, 3723.4].map(short_time).to_vec();
        expect![[r#"
            [
                "0 s",
                "0.4 ms",
                "12 ms",
                "420 ms",
                "1.00 s",
                "4.25 s",
                "59.97 s",
                "1:23.4",
                "1:02:03.4",
            ]
        "#]]
        .assert_debug_eq(&shown);
        assert_eq!(clock(3723.4), "1:02:03.400");
        // Rounded to the millisecond before it is split: never `:60.000`.
        assert_eq!(clock(119_999.999_9), "33:20:00.000");
        assert_eq!(clock(59.9996), "0:01:00.000");
    }
}
