//! The walk's state before a block, from checkpoints kept across edits.
//!
//! Walking a 100,000-block program takes tens of milliseconds; hover has
//! one. So the walk of each program leaves a checkpoint (where it stands
//! between two blocks, [`Resume`]) about every [`STRIDE`] blocks, and a
//! question walks from the nearest one.
//!
//! A checkpoint is *linked* when its state is the one the walk from the
//! previous checkpoint reaches. An edit that leaves the walk's plan as it
//! was (the programs, where jumps and loops join, the contours) unlinks
//! the checkpoints whose walk from the previous one crosses the edit, or
//! runs a contour the edit meets; any other edit drops them all. Those
//! that only linked ones precede hold. A question walks from the one
//! before each unlinked checkpoint before it to that checkpoint and links
//! it again when the state there is the same (otherwise its state is
//! replaced, and the next one unlinked), then from the nearest one: a
//! walk across each edit, not from the program's start. The walks take
//! no lock: a question takes it to copy the checkpoints it needs and to
//! store what it learnt, unless another stored something meanwhile.
//! [`prepare`], in idle time, does the same for the whole file.

use std::{
    collections::{BTreeSet, hash_map::Entry},
    ops::{ControlFlow, Range, RangeInclusive},
    sync::Mutex,
};

use rowan::GreenNode;
use rustc_hash::FxHashMap;

use crate::{
    changed::changed_blocks,
    db::{Db, DialectCache, SourceFile},
    haas_lathe::{
        model::{FileModel, file_model},
        walk::{Resume, State, Visit, joins, program_start, walk_from},
    },
    interactive::between_blocks,
};

/// Blocks between checkpoints: walking this many costs a few tens of
/// microseconds.
pub(crate) const STRIDE: usize = 64;

/// Checkpoints of every file, shared by the database and its snapshots.
#[derive(Default)]
struct StateCache {
    files: Mutex<FxHashMap<SourceFile, Checkpoints>>,
}

impl std::fmt::Debug for StateCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StateCache").finish_non_exhaustive()
    }
}

impl DialectCache for StateCache {
    fn forget(&self, file: SourceFile) {
        lock(&self.files).remove(&file);
    }
}

fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The checkpoints of the database's files.
fn state_cache(db: &dyn Db) -> &StateCache {
    let cache: &dyn std::any::Any = &**db.dialect_cache().get_or_init(|| Box::<StateCache>::default());
    cache.downcast_ref().expect("a database keeps the cache of its one dialect")
}

/// What the walk depends on besides the blocks it runs.
#[derive(Debug, Clone, PartialEq)]
struct Plan {
    /// Each program's blocks and the state it starts in.
    programs: Vec<(Range<usize>, State)>,
    /// Each program's blocks where the walk forgets the state.
    joins: Vec<BTreeSet<usize>>,
    /// Each contour's cycle and blocks.
    contours: Vec<(usize, RangeInclusive<usize>)>,
}

impl Plan {
    /// Where the walk of `program` starts.
    fn start(&self, program: usize) -> Option<Resume> {
        let (blocks, state) = self.programs.get(program)?;
        Some(Resume { at: blocks.start, state: state.clone() })
    }
}

/// The file's plan, once per edit: questions and the preparation share it.
#[salsa::tracked(returns(ref))]
fn walk_plan(db: &dyn Db, file: SourceFile) -> Plan {
    let model = file_model(db, file);
    let programs = &model.model.programs;
    Plan {
        programs: (0..programs.len())
            .map(|index| (programs[index].blocks.clone(), program_start(model, index)))
            .collect(),
        joins: programs.iter().map(|program| joins(model, program)).collect(),
        contours: model.model.contours().map(|contour| (contour.cycle, contour.blocks.clone())).collect(),
    }
}

#[derive(Debug, Clone)]
struct Checkpoint {
    resume: Resume,
    /// Whether the state is the one the walk from the previous checkpoint
    /// (or from the program's start) reaches in the current tree.
    linked: bool,
}

struct Checkpoints {
    root: GreenNode,
    plan: Plan,
    /// Each program's, sorted by block, the first at its start (empty
    /// until the program is walked).
    programs: Vec<Vec<Checkpoint>>,
    /// Counts the changes of `programs`: a walk's result is stored only
    /// over the checkpoints it started from.
    version: u64,
}

impl Checkpoints {
    fn new(root: GreenNode, plan: Plan) -> Checkpoints {
        let programs = vec![Vec::new(); plan.programs.len()];
        Checkpoints { root, plan, programs, version: 0 }
    }

    /// Carries the checkpoints over to the file's current tree and plan.
    fn update(&mut self, root: GreenNode, plan: &Plan) {
        if *plan != self.plan {
            *self = Checkpoints::new(root, plan.clone());
            return;
        }
        // Identity, not `!=`: rowan compares green trees deeply.
        if std::ptr::eq::<rowan::GreenNodeData>(&*self.root, &*root) {
            return;
        }
        let changed = changed_blocks(&self.root, &root);
        self.root = root;
        self.version += 1;
        // The same plan has the same blocks: an edit replaced blocks one
        // for one.
        let edited = changed.new;
        let meets = |blocks: &RangeInclusive<usize>| *blocks.start() < edited.end && edited.start <= *blocks.end();
        // The cycles whose contours the edit meets.
        let cycles: Vec<usize> =
            self.plan.contours.iter().filter(|(_, blocks)| meets(blocks)).map(|(cycle, _)| *cycle).collect();
        for points in &mut self.programs {
            for i in 1..points.len() {
                let walked = points[i - 1].resume.at..points[i].resume.at;
                let crossed = walked.start < edited.end && edited.start < walked.end;
                if crossed || cycles.iter().any(|cycle| walked.contains(cycle)) {
                    points[i].linked = false;
                }
            }
        }
    }
}

/// The checkpoints of `file`, carried over to its current tree.
fn checkpoints<'a>(
    files: &'a mut FxHashMap<SourceFile, Checkpoints>,
    db: &dyn Db,
    file: SourceFile,
    plan: &Plan,
) -> &'a mut Checkpoints {
    let root = file.parse(db).green().clone();
    match files.entry(file) {
        Entry::Vacant(entry) => entry.insert(Checkpoints::new(root, plan.clone())),
        Entry::Occupied(entry) => {
            let checkpoints = entry.into_mut();
            checkpoints.update(root, plan);
            checkpoints
        }
    }
}

/// Walks program `program` from a checkpoint up to block `last`, showing
/// `visit` each block it runs: from the nearest one at or before block
/// `first` that holds, after linking those before it.
pub(crate) fn walk_between(
    db: &dyn Db,
    file: SourceFile,
    program: usize,
    first: usize,
    last: usize,
    visit: &mut dyn FnMut(&Visit<'_>),
) {
    let model = file_model(db, file);
    let plan = walk_plan(db, file);
    let Some(program_start_point) = plan.start(program) else { return };
    let (version, mut points) = {
        let mut files = lock(&state_cache(db).files);
        let checkpoints = checkpoints(&mut files, db, file, plan);
        let points = &checkpoints.programs[program];
        // And the one after: linking the last may unlink it.
        let needed = (points.partition_point(|point| point.resume.at <= first) + 1).min(points.len());
        (checkpoints.version, points[..needed].to_vec())
    };
    let copied = points.len();
    let (nearest, changed) = link(db, model, program, &mut points, first);
    let start = nearest.map_or(program_start_point, |nearest| points[nearest].resume.clone());
    if changed {
        store(db, file, program, version, points, copied);
    }
    walk_from(model, program, start, last, visit, &mut |_| ControlFlow::Continue(()));
}

/// Links every program's checkpoints (walking a program without any from
/// its start, leaving them), so that a question anywhere walks little.
pub(crate) fn prepare(db: &dyn Db, file: SourceFile) {
    let model = file_model(db, file);
    let plan = walk_plan(db, file);
    for program in 0..plan.programs.len() {
        let (version, mut points) = {
            let mut files = lock(&state_cache(db).files);
            let checkpoints = checkpoints(&mut files, db, file, plan);
            (checkpoints.version, checkpoints.programs[program].clone())
        };
        let copied = points.len();
        let changed = match plan.start(program) {
            Some(start) if points.is_empty() => {
                points = walked(db, model, program, start);
                true
            }
            _ => link(db, model, program, &mut points, usize::MAX).1,
        };
        if changed {
            store(db, file, program, version, points, copied);
        }
    }
}

/// Stores `points`, what became of the first `replaced` checkpoints of
/// `program` in the checkpoints of `version`, unless they changed since.
fn store(db: &dyn Db, file: SourceFile, program: usize, version: u64, points: Vec<Checkpoint>, replaced: usize) {
    let mut files = lock(&state_cache(db).files);
    let Some(checkpoints) = files.get_mut(&file).filter(|checkpoints| checkpoints.version == version) else { return };
    checkpoints.programs[program].splice(..replaced, points);
    checkpoints.version += 1;
}

/// The checkpoints of a walk of `program` from `start`, its start, to its
/// end.
fn walked(db: &dyn Db, model: &FileModel, program: usize, start: Resume) -> Vec<Checkpoint> {
    let mut points = vec![Checkpoint { resume: start.clone(), linked: true }];
    let mut since = 0;
    walk_from(model, program, start, usize::MAX, &mut |_| between_blocks(db), &mut |here| {
        since += 1;
        if since >= STRIDE {
            since = 0;
            points.push(Checkpoint { resume: here.clone(), linked: true });
        }
        ControlFlow::Continue(())
    });
    points
}

/// Links the unlinked checkpoints of `points` at or before block `first`:
/// walks from the one before each (which holds) to it, and links it when
/// the walk reaches its state there, or gives it that state and unlinks
/// the next; a checkpoint the walk no longer stands at goes. Returns the
/// index of the last checkpoint at or before `first`, which then holds,
/// and whether any checkpoint changed.
fn link(
    db: &dyn Db,
    model: &FileModel,
    program: usize,
    points: &mut Vec<Checkpoint>,
    first: usize,
) -> (Option<usize>, bool) {
    let mut changed = false;
    loop {
        let trusted = points.iter().position(|point| !point.linked).unwrap_or(points.len());
        if points.get(trusted).is_none_or(|point| point.resume.at > first) {
            return (points[..trusted].partition_point(|point| point.resume.at <= first).checked_sub(1), changed);
        }
        changed = true;
        // The first checkpoint is the program's start, always linked.
        let from = points[trusted - 1].resume.clone();
        let target = points[trusted].resume.at;
        let mut reached = None;
        let cancel = &mut |_: &Visit<'_>| between_blocks(db);
        walk_from(model, program, from, usize::MAX, cancel, &mut |here| {
            if here.at < target {
                return ControlFlow::Continue(());
            }
            reached = Some(here.clone());
            ControlFlow::Break(())
        });
        match reached.filter(|here| here.at == target) {
            Some(here) => {
                if here.state != points[trusted].resume.state {
                    points[trusted].resume = here;
                    if let Some(next) = points.get_mut(trusted + 1) {
                        next.linked = false;
                    }
                }
                points[trusted].linked = true;
            }
            None => {
                points.remove(trusted);
                if let Some(next) = points.get_mut(trusted) {
                    next.linked = false;
                }
            }
        }
    }
}
