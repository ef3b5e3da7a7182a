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
//! runs a contour the edit meets; any other edit drops them all. A
//! question walks from the last checkpoint before it that only linked ones
//! precede, and changes nothing: the lock is taken for the lookup only.
//! [`prepare`], in idle time, walks from there across the edit and links
//! the checkpoints again where the walk reaches the same state.

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
    fn of(file: &FileModel) -> Plan {
        let programs = &file.model.programs;
        Plan {
            programs: (0..programs.len())
                .map(|index| (programs[index].blocks.clone(), program_start(file, index)))
                .collect(),
            joins: programs.iter().map(|program| joins(file, program)).collect(),
            contours: file.model.contours().map(|contour| (contour.cycle, contour.blocks.clone())).collect(),
        }
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
}

impl Checkpoints {
    fn new(root: GreenNode, plan: Plan) -> Checkpoints {
        let programs = vec![Vec::new(); plan.programs.len()];
        Checkpoints { root, plan, programs }
    }

    /// Carries the checkpoints over to the file's current tree and plan.
    fn update(&mut self, root: GreenNode, plan: Plan) {
        if plan != self.plan {
            *self = Checkpoints::new(root, plan);
            return;
        }
        // Identity, not `!=`: rowan compares green trees deeply.
        if std::ptr::eq::<rowan::GreenNodeData>(&*self.root, &*root) {
            return;
        }
        let changed = changed_blocks(&self.root, &root);
        self.root = root;
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

    /// Where a walk to block `first` of `program` can start: the last
    /// checkpoint at or before it that only linked ones precede.
    fn start(&self, program: usize, first: usize) -> Option<&Checkpoint> {
        let points = self.programs.get(program)?;
        let trusted = points.iter().position(|point| !point.linked).unwrap_or(points.len());
        let nearest = points[..trusted].partition_point(|point| point.resume.at <= first);
        nearest.checked_sub(1).map(|index| &points[index])
    }
}

/// The checkpoints of `file`, carried over to its current tree.
fn checkpoints<'a>(
    files: &'a mut FxHashMap<SourceFile, Checkpoints>,
    db: &dyn Db,
    file: SourceFile,
    plan: Plan,
) -> &'a mut Checkpoints {
    let root = file.parse(db).green().clone();
    match files.entry(file) {
        Entry::Vacant(entry) => entry.insert(Checkpoints::new(root, plan)),
        Entry::Occupied(entry) => {
            let checkpoints = entry.into_mut();
            checkpoints.update(root, plan);
            checkpoints
        }
    }
}

/// Walks program `program` from a checkpoint up to block `last`, showing
/// `visit` each block it runs: from the last one at or before block
/// `first`, else from the program's start.
pub(crate) fn walk_between(
    db: &dyn Db,
    file: SourceFile,
    program: usize,
    first: usize,
    last: usize,
    visit: &mut dyn FnMut(&Visit<'_>),
) {
    let model = file_model(db, file);
    let plan = Plan::of(model);
    let start = {
        let mut files = lock(&state_cache(db).files);
        checkpoints(&mut files, db, file, plan).start(program, first).map(|point| point.resume.clone())
    };
    let Some(start) = start.or_else(|| {
        let program_blocks = &model.model.programs.get(program)?.blocks;
        Some(Resume { at: program_blocks.start, state: program_start(model, program) })
    }) else {
        return;
    };
    walk_from(model, program, start, last, visit, &mut |_| ControlFlow::Continue(()));
}

/// Walks every program whose checkpoints an edit unlinked (or that has
/// none) from its last trusted one, leaving checkpoints, until the walk
/// reaches the state of an unlinked one after which all are linked. The
/// lock is held only to read where to start and to store what was found.
pub(crate) fn prepare(db: &dyn Db, file: SourceFile) {
    let model = file_model(db, file);
    let plan = Plan::of(model);
    for program in 0..model.model.programs.len() {
        let (root, old) = {
            let mut files = lock(&state_cache(db).files);
            let checkpoints = checkpoints(&mut files, db, file, plan.clone());
            (checkpoints.root.clone(), checkpoints.programs[program].clone())
        };
        let Some(walked) = walk_across(db, model, program, &old) else { continue };
        let mut files = lock(&state_cache(db).files);
        let Some(checkpoints) = files.get_mut(&file) else { return };
        // An edit came meanwhile: its question or preparation walks again.
        if !std::ptr::eq::<rowan::GreenNodeData>(&*checkpoints.root, &*root) || checkpoints.plan != plan {
            return;
        }
        checkpoints.programs[program] = walked;
    }
}

/// The checkpoints of `program` after a walk from the last trusted one of
/// `old` (its start when none) across the unlinked ones; `None` when all
/// are linked.
fn walk_across(db: &dyn Db, model: &FileModel, program: usize, old: &[Checkpoint]) -> Option<Vec<Checkpoint>> {
    let unlinked = old.iter().position(|point| !point.linked);
    if !old.is_empty() && unlinked.is_none() {
        return None;
    }
    let kept = unlinked.unwrap_or(0);
    let mut points: Vec<Checkpoint> = old[..kept].to_vec();
    let start = match points.last() {
        Some(point) => point.resume.clone(),
        None => {
            let resume =
                Resume { at: model.model.programs[program].blocks.start, state: program_start(model, program) };
            points.push(Checkpoint { resume: resume.clone(), linked: true });
            resume
        }
    };
    // The old checkpoints after the last unlinked one are linked: reaching
    // the state of one at or after it, the walk may stop there.
    let last_unlinked = old.iter().rposition(|point| !point.linked).unwrap_or(0);
    let mut rest = None;
    let mut since = 0;
    walk_from(model, program, start, usize::MAX, &mut |_| db.unwind_if_revision_cancelled(), &mut |here| {
        let old_here = old.binary_search_by_key(&here.at, |point| point.resume.at);
        if let Ok(index) = old_here
            && index >= last_unlinked
            && old[index].resume.state == here.state
        {
            rest = Some(index);
            return ControlFlow::Break(());
        }
        since += 1;
        if since >= STRIDE {
            since = 0;
            points.push(Checkpoint { resume: here.clone(), linked: true });
        }
        ControlFlow::Continue(())
    });
    if let Some(index) = rest {
        points.extend(old[index..].iter().cloned().map(|point| Checkpoint { linked: true, ..point }));
    }
    Some(points)
}
