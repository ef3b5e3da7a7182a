//! The state before a block of the main body, from checkpoints kept across
//! edits.
//!
//! Walking a 100,000-block program up to the cursor takes about 0.2 s;
//! hover has a millisecond. So the walk leaves a checkpoint (modal
//! state and parameters) about every [`STRIDE`] blocks of the main body,
//! and a question walks from the nearest one.
//!
//! An edit replaces a run of blocks ([`changed_blocks`]): the checkpoints
//! before it stay, those inside it go, those after it move with the blocks,
//! and the text ranges in their states move with the text. A checkpoint is
//! *linked* when its state is the one the walk from the previous checkpoint
//! reaches; an edit between the two (in the main body, or in a subprogram
//! the walk between them entered) unlinks it. A question that needs an
//! unlinked checkpoint walks to it and compares: the same state links it
//! again, and so vouches for the linked ones after it. A one-character edit
//! thus costs a walk across it, not a walk to the end of the file.

use std::{
    collections::hash_map::Entry,
    ops::Range,
    sync::{
        Arc, Mutex,
        atomic::{AtomicUsize, Ordering},
    },
};

use ncc_syntax::{Dialect, TextRange, TextSize};
use rowan::GreenNode;
use rustc_hash::FxHashMap;

use nc_exec::known::Known;

use crate::{
    Config,
    changed::{Changed, changed_blocks},
    cnc8x6::flow::{Course, ModalState, ParamState, Walk},
    cnc8x6::model::{self, Program},
    db::{Db, DialectCache, Settings, SourceFile},
    interactive,
};

/// Blocks between checkpoints: walking this many costs well under a
/// millisecond, and 100,000 blocks keep under 3 MB of checkpoints.
const STRIDE: usize = 128;

/// Checkpoints of every file, shared by the database and its snapshots.
#[derive(Default)]
struct StateCache {
    files: Mutex<FxHashMap<SourceFile, Checkpoints>>,
    /// Questions waiting for `files`: [`prepare`] lets go for them.
    waiting: AtomicUsize,
}

impl std::fmt::Debug for StateCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StateCache").finish_non_exhaustive()
    }
}

impl DialectCache for StateCache {
    fn forget(&self, file: SourceFile) {
        self.files.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).remove(&file);
    }
}

/// The checkpoints of the database's files.
fn state_cache(db: &dyn Db) -> &StateCache {
    let cache: &dyn std::any::Any = &**db.dialect_cache().get_or_init(|| Box::<StateCache>::default());
    cache.downcast_ref().expect("a database keeps the cache of its one dialect")
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
    /// The blocks of every unit, which move with edits.
    blocks: Vec<Range<usize>>,
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
            blocks: program.units.iter().map(|unit| unit.blocks.clone()).collect(),
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

    /// Whether every unit the change does not meet has the same blocks in
    /// `new`: a unit can also grow or shrink by an edit beside it (a `G70`
    /// after its last one), and a walk that entered it is then unchecked.
    fn units_follow(&self, new: &Context, changed: &Changed) -> bool {
        self.blocks.iter().zip(&new.blocks).all(|(old, new)| changed.blocks(old).is_none_or(|moved| moved == *new))
    }
}

/// What the walk of the main body carries from block to block.
#[derive(Clone, PartialEq, Eq)]
struct Carried {
    state: (ModalState, ParamState),
    course: Course,
    /// Blocks run again so far, against the walk's budget.
    repeated: usize,
}

struct Checkpoint {
    /// The state is the one before this block, which the walk reaches here
    /// the first time, having run no block after it yet: so the first time
    /// it reaches any later block is after this checkpoint.
    index: usize,
    /// Boxed, so that inserting a checkpoint moves little.
    state: Box<Carried>,
    /// Where the last text range in `state` ends: an edit after it moves
    /// none of them.
    reach: TextSize,
    /// The hull of the blocks of the subprograms the walk from the previous
    /// checkpoint entered.
    entered: Option<Range<usize>>,
    /// Whether `state` is the one the walk from the previous checkpoint (or
    /// from the program start) reaches in the current tree.
    linked: bool,
}

impl Checkpoint {
    fn new(index: usize, state: Carried, entered: Option<Range<usize>>) -> Checkpoint {
        let mut point = Checkpoint { index, state: Box::new(state), reach: TextSize::from(0), entered, linked: true };
        point.reach = point.ranges().map(|range| range.end()).max().unwrap_or_default();
        point
    }

    /// The text ranges in the state.
    fn ranges(&mut self) -> impl Iterator<Item = &mut TextRange> {
        let (state, params) = &mut self.state.state;
        let settings = state.settings_mut().into_iter().filter_map(|setting| match setting {
            Known::Is(Some(setting)) => Some(&mut setting.range),
            _ => None,
        });
        settings.chain(params.origins.iter_mut().flatten().map(|origin| &mut origin.range))
    }

    /// Moves the state's text ranges with the text and its jump counts
    /// with their blocks; `false` if one lies in the change.
    fn move_ranges(&mut self, changed: &Changed) -> bool {
        if !self.state.course.move_blocks(|block| changed.blocks(&(block..block + 1)).map(|moved| moved.start)) {
            return false;
        }
        if self.reach <= changed.old_text.start() {
            return true;
        }
        let mut reach = TextSize::from(0);
        let moved = self.ranges().all(|range| match changed.range(*range) {
            Some(moved) => {
                *range = moved;
                reach = reach.max(moved.end());
                true
            }
            None => false,
        });
        self.reach = reach;
        moved
    }
}

impl Checkpoints {
    /// Carries the checkpoints over to the file's current tree and context.
    fn update(&mut self, root: GreenNode, context: Context) {
        if !self.context.same_as(&context) {
            self.points.clear();
        } else if !std::ptr::eq::<rowan::GreenNodeData>(&*self.root, &*root) {
            // Identity, not `!=`: rowan compares green trees deeply.
            let changed = changed_blocks(&self.root, &root);
            if self.context.units_follow(&context, &changed) {
                self.carry_over(&changed);
            } else {
                self.points.clear();
            }
        }
        self.root = root;
        self.context = context;
    }

    /// Keeps the checkpoints outside the change, moved with it, and unlinks
    /// those whose walk from the previous one crosses it.
    fn carry_over(&mut self, changed: &Changed) {
        // The old index of the previous checkpoint, whether it went, and the
        // new index of the last one kept.
        let (mut previous, mut dropped, mut kept) = (0, false, None);
        self.points.retain_mut(|point| {
            let across = previous <= changed.old.start && changed.old.start < point.index;
            let entered = point.entered.as_ref().map(|hull| changed.blocks(hull));
            let unlinked = std::mem::take(&mut dropped) || across || entered.as_ref().is_some_and(Option::is_none);
            previous = point.index;
            match changed.position(point.index) {
                // Deleted blocks can bring two checkpoints together: the
                // later one goes.
                Some(index) if kept != Some(index) && point.move_ranges(changed) => {
                    kept = Some(index);
                    point.index = index;
                    point.entered = entered.flatten();
                    point.linked &= !unlinked;
                    true
                }
                _ => {
                    dropped = true;
                    false
                }
            }
        });
    }

    /// The state before block `index` of the main body, the first time the
    /// walk reaches it (`None`: it does not before it has run a block after
    /// it), and how many blocks the walk to it took.
    fn state_before(
        &mut self,
        db: &dyn Db,
        file: SourceFile,
        program: &Program,
        index: usize,
        waiting: Option<&AtomicUsize>,
    ) -> (Option<(ModalState, ParamState)>, usize) {
        let points = &mut self.points;
        // Start at the last checkpoint before the question that only linked
        // ones precede.
        let trusted = points.iter().position(|p| !p.linked).unwrap_or(points.len());
        // `at`: the first checkpoint after `block`.
        let mut at = points[..trusted].partition_point(|p| p.index <= index);
        let (mut block, mut carried) = match at.checked_sub(1) {
            Some(start) => (points[start].index, (*points[start].state).clone()),
            None => {
                let state = (ModalState::reset(), ParamState::program_start());
                (0, Carried { state, course: Course::default(), repeated: 0 })
            }
        };
        // An unlinked checkpoint just after the question is checked as well:
        // the edit the question follows left it there, and unchecked ones
        // would pile up for a later question further down.
        let end = points[at..]
            .iter()
            .find(|p| p.index > index)
            .filter(|p| !p.linked && p.index - index <= 2 * STRIDE)
            .map_or(index, |p| p.index);
        let mut walk = Walk::new(db, file, program, Vec::new());
        walk.stack.push(0);
        walk.repeated = carried.repeated;
        // `unrun`: the first block after every block run so far. Loops run
        // blocks before it again; a block at or after it runs the first time.
        let (mut unrun, mut last, mut walked, mut answer) = (block, block, 0, None);
        loop {
            let first_time = block >= unrun;
            if first_time {
                // Checkpoints the walk passed without reaching them are no
                // longer on its way.
                while points.get(at).is_some_and(|p| p.index < block) {
                    points.remove(at);
                    if let Some(next) = points.get_mut(at) {
                        next.linked = false;
                    }
                }
            }
            if first_time && points.get(at).is_some_and(|p| p.index == block) {
                let entered = walk.take_entered();
                let point = &mut points[at];
                if !point.linked {
                    if *point.state == carried {
                        point.linked = true;
                        point.entered = entered;
                    } else {
                        *point = Checkpoint::new(block, carried.clone(), entered);
                        // The ones linked to it followed the old state.
                        if let Some(next) = points.get_mut(at + 1) {
                            next.linked = false;
                        }
                    }
                }
                // The checkpoints linked to this one hold the states the walk
                // would reach: go on from the last one up to the question.
                let run = points[at + 1..].iter().position(|p| !p.linked).map_or(points.len(), |n| at + 1 + n);
                let jump = at + points[at..run].partition_point(|p| p.index <= index).saturating_sub(1);
                if jump > at {
                    block = points[jump].index;
                    carried = (*points[jump].state).clone();
                    walk.repeated = carried.repeated;
                    unrun = block;
                }
                at = jump + 1;
                last = block;
            }
            if first_time && block == index {
                answer = Some(carried.state.clone());
            }
            // The walk reached the last block it had to, or passed it: a
            // block it passed is reached later, if at all, by a loop.
            if first_time && block >= end {
                if block > end && points.get(at.wrapping_sub(1)).is_none_or(|p| p.index != block) {
                    points.insert(at, Checkpoint::new(block, carried, walk.take_entered()));
                }
                return (answer, walked);
            }
            let Some(next) = walk.step(block, &mut carried.course, &mut carried.state.0, &mut carried.state.1) else {
                return (answer, walked);
            };
            carried.repeated = walk.repeated;
            unrun = unrun.max(block + 1);
            block = next;
            walked += 1;
            if block < unrun {
                continue;
            }
            // A new checkpoint every STRIDE blocks, but not right before one.
            let following = points.get(at).map_or(usize::MAX, |p| p.index);
            if block - last >= STRIDE && following.saturating_sub(block) >= STRIDE / 2 {
                points.insert(at, Checkpoint::new(block, carried.clone(), walk.take_entered()));
                at += 1;
                last = block;
            }
            // Preparing for questions must not keep one waiting: let go,
            // leaving a checkpoint here to go on from, unless it would crowd
            // those around it (over a session of edits and questions they
            // would pile up); the next step then walks from the last one.
            if waiting.is_some_and(|waiting| waiting.load(Ordering::Relaxed) > 0) && block < end {
                if block - last >= STRIDE / 2 && following - block >= STRIDE / 2 {
                    points.insert(at, Checkpoint::new(block, carried, walk.take_entered()));
                }
                return (None, walked);
            }
        }
    }
}

/// The most blocks one step of [`prepare`] walks: a question waiting for
/// the checkpoints waits about a millisecond.
const SLICE: usize = 4 * STRIDE;

/// Walks the main body to its end, a slice at a time: checks the
/// checkpoints an edit unlinked and leaves new ones, so that a later
/// question anywhere walks little. After an edit that left the state after
/// it unchanged, this walks only across the edit.
pub(crate) fn prepare(db: &dyn Db, file: SourceFile) {
    let program = model::program(db, file);
    let Some(last) = program.has_main().then(|| program.units[0].blocks.end.checked_sub(1)).flatten() else {
        return;
    };
    // The first step carries the checkpoints over to the current tree.
    walk_to(db, file, 0, Asker::Preparation);
    let mut progress = None;
    loop {
        let (target, now) = {
            let files = state_cache(db).files.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            let points = files.get(&file).map_or(&[][..], |checkpoints| checkpoints.points.as_slice());
            let unlinked = points.iter().find(|point| !point.linked).map(|point| point.index);
            let from = points.last().map_or(0, |point| point.index);
            // Where the checkpoints stand: a step that changed nothing (the
            // program ended before the target, or a question came inside
            // a loop, where no checkpoint goes) ends the preparation.
            let now = Some((unlinked, from, points.len()));
            match unlinked {
                Some(unlinked) => (unlinked, now),
                None if from + STRIDE > last => return,
                None => ((from + SLICE).min(last), now),
            }
        };
        if now == progress {
            return;
        }
        progress = now;
        walk_to(db, file, target, Asker::Preparation);
    }
}

/// The state before block `index` when it belongs to the main body
/// (`None` otherwise: other blocks are reached from several places).
/// (`None` also when the walk does not reach it before it has run a block
/// after it: a jump passed it, and a loop may come back to it).
pub(crate) fn main_state_before(db: &dyn Db, file: SourceFile, index: usize) -> Option<(ModalState, ParamState)> {
    main_state_and_walk(db, file, index).and_then(|(state, _)| state)
}

/// [`main_state_before`], and how many blocks it walked (`None`: not in
/// the main body).
pub(crate) fn main_state_and_walk(
    db: &dyn Db,
    file: SourceFile,
    index: usize,
) -> Option<(Option<(ModalState, ParamState)>, usize)> {
    walk_to(db, file, index, Asker::Question)
}

/// Who walks: a question, or [`prepare`], which gives way to questions.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Asker {
    Question,
    Preparation,
}

/// Counts a question as waiting while it lives.
struct Waiting<'a>(&'a AtomicUsize);

impl Drop for Waiting<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

fn walk_to(
    db: &dyn Db,
    file: SourceFile,
    index: usize,
    asker: Asker,
) -> Option<(Option<(ModalState, ParamState)>, usize)> {
    let program = model::program(db, file);
    if !program.has_main() || !program.units[0].blocks.contains(&index) {
        return None;
    }
    let root = file.parse(db).green().clone();
    let context = Context::of(db, program);
    let cache = state_cache(db);
    let _waiting = (asker == Asker::Question).then(|| {
        cache.waiting.fetch_add(1, Ordering::Relaxed);
        Waiting(&cache.waiting)
    });
    let mut files = cache.files.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let checkpoints = match files.entry(file) {
        Entry::Vacant(entry) => entry.insert(Checkpoints { root, context, points: Vec::new() }),
        Entry::Occupied(entry) => {
            let checkpoints = entry.into_mut();
            checkpoints.update(root, context);
            checkpoints
        }
    };
    let waiting = (asker == Asker::Preparation).then_some(&cache.waiting);
    // Under the lock a question waits for: it lets go for questions itself.
    Some(interactive::without_giving_way(|| checkpoints.state_before(db, file, program, index, waiting)))
}

#[cfg(test)]
mod tests {
    use ncc_syntax::{Dialect, Parse, ast::AstNode};

    use std::sync::atomic::Ordering;

    use super::{Asker, STRIDE, changed_blocks, main_state_and_walk, main_state_before, state_cache, walk_to};
    use crate::{AnalysisHost, Config, TextEdit, TextRange, TextSize, cnc8x6::flow::walked_states};

    /// What [`changed_blocks`] promises, whatever the tree's shape: the
    /// blocks before and after the change are the same nodes, the text
    /// ranges are those of the blocks between, and a small edit makes a
    /// small change.
    #[test]
    fn changed_blocks_bound_what_an_edit_replaced() {
        let short = "%1 \"C\"\nN1 G90\nN2 X1.\nN3 X2.\nN4 X3.\nN5 M30\n*\n".to_owned();
        let edits = [("X2.", "X22."), ("N3 X2.\n", ""), ("N3 ", "N3 G91\nN33 "), ("\nN5", "\n\nN5"), ("M30", "M3")];
        check_changed_blocks(&short, &edits);
        // Many runs: edits in the middle, next to where runs end, and at the
        // ends of the program.
        let long: String = std::iter::once("%1\n".to_owned())
            .chain((1..=3000).map(|n| format!("N{n} X{}.\n", n % 97)))
            .chain(["N9999 M30\n*\n".to_owned()])
            .collect();
        let parse = Parse::new(&long, Dialect::Cnc8x6);
        let run_ends: Vec<String> =
            parse.syntax_node().children().filter_map(|run| run.last_child()).map(|block| block.to_string()).collect();
        assert!(run_ends.len() > 3, "{} runs", run_ends.len());
        let mut edits: Vec<(&str, &str)> =
            vec![("N1 X1.", "N1 X11."), ("N1500 ", "N1500 G91\nN1501 "), ("N9999 ", "N9999 G4\n")];
        for end in &run_ends[1..3] {
            edits.push((end.as_str(), ""));
            edits.push((end.as_str(), "N7777 Y1.\n"));
        }
        check_changed_blocks(&long, &edits);
    }

    fn check_changed_blocks(text: &str, edits: &[(&str, &str)]) {
        let old = Parse::new(text, Dialect::Cnc8x6);
        let blocks = |parse: &Parse| -> Vec<(rowan::GreenNode, TextRange)> {
            let blocks = parse.tree().blocks().map(|block| block.syntax().clone());
            blocks.map(|node| (node.green().to_owned(), node.text_range())).collect()
        };
        let span =
            |blocks: &[(rowan::GreenNode, TextRange)]| blocks.iter().map(|(_, range)| *range).reduce(|a, b| a.cover(b));
        let same = |a: &[(rowan::GreenNode, TextRange)], b: &[(rowan::GreenNode, TextRange)]| {
            a.len() == b.len()
                && a.iter().zip(b).all(|((a, _), (b, _))| std::ptr::eq::<rowan::GreenNodeData>(&**a, &**b))
        };
        let unchanged = changed_blocks(old.green(), old.green());
        let count = blocks(&old).len();
        assert_eq!((unchanged.old, unchanged.new), (count..count, count..count));

        for &(find, replace) in edits {
            let at = TextSize::from(text.find(find).unwrap() as u32);
            let edit = TextEdit::replace(TextRange::at(at, TextSize::of(find)), replace);
            let mut new_text = text.to_owned();
            edit.apply(&mut new_text);
            let new = old.reparse(&edit, &new_text);
            let changed = changed_blocks(old.green(), new.green());
            let (a, b) = (blocks(&old), blocks(&new));
            assert_eq!(changed.old.start, changed.new.start, "`{find}`");
            assert!(changed.old.len() <= 3 && changed.new.len() <= 3, "`{find}`: {changed:?}");
            assert!(same(&a[..changed.old.start], &b[..changed.new.start]), "`{find}`: {changed:?}");
            assert!(same(&a[changed.old.end..], &b[changed.new.end..]), "`{find}`: {changed:?}");
            if let Some(span) = span(&a[changed.old.clone()]) {
                assert_eq!(changed.old_text, span, "`{find}`");
            }
            if let Some(span) = span(&b[changed.new.clone()]) {
                assert_eq!(changed.new_text, span, "`{find}`");
            }
            assert_eq!(changed.old_text.start(), changed.new_text.start(), "`{find}`");
        }
    }

    /// A typed digit far before the question costs the walk across the
    /// edit and from the checkpoint before the question, not the walk from
    /// the start. (That the answers equal a fresh walk is tested at length
    /// in `tests/incremental.rs`.)
    #[test]
    fn a_question_after_an_edit_walks_across_the_edit_only() {
        let mut text = String::from("%1 \"WALK\"\nN1 G90 F100\n");
        for n in 2..=5000 {
            text.push_str(&format!("N{n} G01 X{n}. Y-{n}.\n"));
        }
        text.push_str("N9999 M30\n*\n");
        let mut host = AnalysisHost::new(Config::default());
        let file = host.add_file("main.NCP", text.as_str());
        let far = 4900;
        assert_eq!(main_state_and_walk(host.db(), file, far).map(|(_, walked)| walked), Some(far));

        let at = text.find("N101 G01 X1").unwrap() + "N101 G01 X1".len();
        let edit = TextEdit::replace(TextRange::empty(TextSize::from(at as u32)), "7");
        host.apply_edit(file, &edit);
        edit.apply(&mut text);
        let (state, walked) = main_state_and_walk(host.db(), file, far).unwrap();
        assert!(walked <= 3 * STRIDE, "walked {walked} blocks");

        let mut fresh = AnalysisHost::new(Config::default());
        let fresh_file = fresh.add_file("main.NCP", text.as_str());
        assert_eq!(state, main_state_before(fresh.db(), fresh_file, far));
    }

    /// With jumps and loops the checkpoints still give the state the
    /// checker's walk reaches a main-body block in the first time, before
    /// and after edits that move the jumps' counts; a block the walk passes
    /// without running it is left to the whole walk.
    #[test]
    fn checkpoints_follow_jumps_as_the_walk_does() {
        let mut text = String::from("%1 \"JUMPS\"\nN1 G90 G01 F100 R1=0 R2=0\n");
        for n in 2..=700 {
            let extra = match n % 150 {
                // Forward over four blocks, once: the count stays until the
                // loop below comes back to it.
                10 => format!(" G73 L{}", n + 5),
                12 => " R2=7.".to_owned(),
                // R1 counts the runs of a loop back over the jump.
                40 => " G26 R5=-41010001".to_owned(),
                60 => format!(" G73 L{} Q2", n - 55),
                // A jump whose condition (R3) is unknown.
                90 => format!(" GR3 L{}", n + 20),
                100 => " R4=1.".to_owned(),
                _ => String::new(),
            };
            text.push_str(&format!("N{n} X{n}. YR2{extra}\n"));
        }
        text.push_str("N9999 M30\n*\n");
        let mut host = AnalysisHost::new(Config::default());
        let file = host.add_file("main.NCP", text.as_str());
        let edits = [("N7 X7.", "N7 X7.\nN8000 X1."), ("N160 X160. YR2 G73 L165", "N160 X160. YR2 G73 L164")];
        for edit in [None].into_iter().chain(edits.map(Some)) {
            if let Some((find, replace)) = edit {
                let at = TextSize::from(text.find(find).unwrap() as u32);
                let edit = TextEdit::replace(TextRange::at(at, TextSize::of(find)), replace);
                host.apply_edit(file, &edit);
                edit.apply(&mut text);
            }
            host.analysis().prepare_states(file);
            let db = host.db();
            let blocks = crate::cnc8x6::model::program(db, file).units[0].blocks.clone();
            let (mut passed, mut counted) = (0, false);
            for index in blocks.step_by(13) {
                let walked = walked_states(db, file, index);
                match main_state_before(db, file, index) {
                    Some(state) => {
                        counted |= state.1.values.get(1).is_some_and(|runs| runs > 1);
                        assert_eq!(Some(&state), walked.first(), "block {index} after {edit:?}");
                    }
                    None => passed += 1,
                }
            }
            assert!(passed > 0 && counted, "{passed} blocks passed; the loop counted: {counted}");
        }
    }

    /// A preparation that gives way to a question again and again, after
    /// every edit of a long session, leaves no more checkpoints than its
    /// stride allows: they would pile up over the session otherwise.
    #[test]
    fn preparations_giving_way_to_questions_keep_their_checkpoints_apart() {
        let blocks = 3000;
        let mut text = String::from("%1 \"YIELD\"\nN1 G90 F100\n");
        for n in 2..=blocks {
            text.push_str(&format!("N{n} G01 X{n}. Y-{n}.\n"));
        }
        text.push_str("N9999 M30\n*\n");
        let mut host = AnalysisHost::new(Config::default());
        let file = host.add_file("main.NCP", text.as_str());
        host.analysis().prepare_states(file);
        let points = |host: &AnalysisHost| -> Vec<usize> {
            let files = state_cache(host.db()).files.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            files[&file].points.iter().map(|point| point.index).collect()
        };
        let regular = points(&host).len();
        for n in (7..blocks).step_by(37) {
            let at = text.find(&format!("N{n} G01 X")).unwrap() + format!("N{n} G01 X").len();
            let edit = TextEdit::replace(TextRange::empty(TextSize::from(at as u32)), "1");
            host.apply_edit(file, &edit);
            edit.apply(&mut text);
            // A question waits all along: each step walks a block and lets go.
            let waiting = &state_cache(host.db()).waiting;
            waiting.fetch_add(1, Ordering::Relaxed);
            for _ in 0..20 {
                walk_to(host.db(), file, blocks - 1, Asker::Preparation);
            }
            waiting.fetch_sub(1, Ordering::Relaxed);
            host.analysis().prepare_states(file);
        }
        let after = points(&host);
        assert!(after.windows(2).all(|pair| pair[1] - pair[0] >= STRIDE / 2), "{after:?}");
        assert!(after.len() <= 2 * regular, "{} checkpoints, {regular} after the first preparation", after.len());
    }
}
