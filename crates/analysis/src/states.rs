//! The state before a block of the main body, from checkpoints kept across
//! edits.
//!
//! Walking a 100,000-block program up to the cursor takes a good part of a
//! second; hover has a millisecond. So the walk leaves a checkpoint (modal
//! state and parameters) every [`STRIDE`] blocks of the main body, and a
//! question walks from the nearest one. An edit keeps the checkpoints that
//! depend only on blocks before the first changed one: those before it
//! whose walk entered no subprogram at or after it (a subprogram's ranges
//! move with the edit). The checkpoints hold the tree they were taken on,
//! so comparing blocks by identity is exact.

use std::{
    collections::hash_map::Entry,
    sync::{Arc, Mutex},
};

use ncc_syntax::{Dialect, SyntaxKind};
use rowan::GreenNode;
use rustc_hash::FxHashMap;

use crate::{
    Config,
    db::{Db, Settings, SourceFile},
    flow::{ModalState, ParamState, Walk},
    model::{self, Program},
};

/// Blocks between checkpoints: walking this many costs well under a
/// millisecond, and 100,000 blocks keep under 3 MB of checkpoints.
const STRIDE: usize = 128;

/// Checkpoints of every file, shared by the database and its snapshots.
#[derive(Default)]
pub struct StateCache {
    files: Mutex<FxHashMap<SourceFile, Checkpoints>>,
}

impl std::fmt::Debug for StateCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StateCache").finish_non_exhaustive()
    }
}

impl StateCache {
    /// Forgets a file's checkpoints.
    pub(crate) fn forget(&self, file: SourceFile) {
        self.files.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).remove(&file);
    }
}

struct Checkpoints {
    root: GreenNode,
    context: Context,
    /// Sorted by block index.
    points: Vec<Checkpoint>,
}

/// What the walk depends on besides the file's blocks.
struct Context {
    dialect: Dialect,
    config: Config,
    /// Number and closedness of every unit: calls resolve by number.
    units: Vec<(Option<u32>, bool)>,
    /// The macrocycle files' texts, kept alive so identity is exact.
    macrocycles: Vec<Arc<String>>,
}

impl Context {
    fn of(db: &dyn Db, program: &Program) -> Context {
        let settings = Settings::get(db);
        let mut macrocycles: Vec<(u32, Arc<String>)> = model::macrocycles(db)
            .iter()
            .flat_map(|(&number, files)| files.iter().map(move |&file| (number, file.text(db).clone())))
            .collect();
        macrocycles.sort_by_key(|(number, _)| *number);
        Context {
            dialect: *settings.dialect(db),
            config: settings.config(db).clone(),
            units: program.units.iter().map(|unit| (unit.number, unit.closed)).collect(),
            macrocycles: macrocycles.into_iter().map(|(_, text)| text).collect(),
        }
    }

    fn same_as(&self, other: &Context) -> bool {
        self.dialect == other.dialect
            && self.config == other.config
            && self.units == other.units
            && self.macrocycles.len() == other.macrocycles.len()
            && self.macrocycles.iter().zip(&other.macrocycles).all(|(a, b)| Arc::ptr_eq(a, b))
    }
}

struct Checkpoint {
    /// The state is the one before this block.
    index: usize,
    state: ModalState,
    params: ParamState,
    /// The end of the last block of any subprogram the walk entered before
    /// this point (0: none).
    called_end: usize,
}

/// The index of the first block that differs between two trees.
fn first_changed_block(old: &GreenNode, new: &GreenNode) -> usize {
    fn blocks(root: &GreenNode) -> impl Iterator<Item = *const rowan::GreenNodeData> + '_ {
        root.children()
            .filter_map(|child| child.into_node())
            .filter(|node| node.kind() == SyntaxKind::BLOCK.into())
            .map(|node| node as *const rowan::GreenNodeData)
    }
    blocks(old)
        .zip(blocks(new))
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| blocks(old).count().min(blocks(new).count()))
}

/// The state before block `index` when it belongs to the main body
/// (`None` otherwise: other blocks are reached from several places).
pub(crate) fn main_state_before(db: &dyn Db, file: SourceFile, index: usize) -> Option<(ModalState, ParamState)> {
    let program = model::program(db, file);
    if !program.has_main() || !program.units[0].blocks.contains(&index) {
        return None;
    }
    let root = file.parse(db).green().clone();
    let context = Context::of(db, program);
    let cache = db.state_cache();
    let mut files = cache.files.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let checkpoints = match files.entry(file) {
        Entry::Vacant(entry) => entry.insert(Checkpoints { root, context, points: Vec::new() }),
        Entry::Occupied(entry) => {
            let checkpoints = entry.into_mut();
            if !checkpoints.context.same_as(&context) {
                checkpoints.points.clear();
            } else if !std::ptr::eq::<rowan::GreenNodeData>(&*checkpoints.root, &*root) {
                // Identity, not `!=`: rowan compares green trees deeply.
                let changed = first_changed_block(&checkpoints.root, &root);
                checkpoints.points.retain(|point| point.index <= changed && point.called_end <= changed);
            }
            checkpoints.root = root;
            checkpoints.context = context;
            checkpoints
        }
    };
    let points = &mut checkpoints.points;
    let (from, mut state, mut params, called_before) = match points.partition_point(|p| p.index <= index) {
        0 => (0, ModalState::reset(Settings::get(db).dialect(db).catalogue()), ParamState::program_start(), 0),
        after => {
            let point = &points[after - 1];
            (point.index, point.state.clone(), point.params.clone(), point.called_end)
        }
    };
    let mut walk = Walk::new(db, file, program, Vec::new());
    walk.stack.push(0);
    for block in from..index {
        (state, params) = walk.step(block, &state, &params);
        let next = block + 1;
        if next.is_multiple_of(STRIDE) {
            let called_end = walk.called_end().max(called_before);
            let at = points.partition_point(|p| p.index < next);
            if points.get(at).is_none_or(|p| p.index != next) {
                let point = Checkpoint { index: next, state: state.clone(), params: params.clone(), called_end };
                points.insert(at, point);
            }
        }
    }
    Some((state, params))
}
