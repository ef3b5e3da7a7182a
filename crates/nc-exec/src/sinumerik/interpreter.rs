//! The Sinumerik interpreter: the modal state, variables, control flow,
//! calls, motion and time of a program, block by block, in the order the
//! control runs them.
//!
//! What runs:
//! - Values and variables through [`super::eval`]: global user data from
//!   the GUD definition files beside the program (`UGUD.DEF`, …),
//!   assignments, DEF, `G[n]=k`, and a word `NAME=…` whose name is a
//!   defined variable and no axis of the machine (a formal parameter `C`
//!   of `PROC PROFIL (REAL C, …)`) assigns it.
//! - Control structures by [`SinumerikModel`]: IF/ELSE/ENDIF, WHILE,
//!   FOR (`FOR v = a TO b`, inclusive, step 1, the end evaluated at every
//!   pass), REPEAT/UNTIL, LOOP/ENDLOOP, CASE … OF … DEFAULT, and
//!   GOTO/GOTOF/GOTOB/GOTOC/GOTOS with a label, block number or computed
//!   target (`GOTOF "N"<<R3`: a string `N<digits>` names a block number,
//!   any other a label, searched in the jump's direction). Structures keep
//!   no stack: an ENDFOR always steps its FOR's variable and an ENDWHILE
//!   always goes back to its WHILE, so a jump out of a structure leaves it
//!   and a jump into a body (the cam cycle's `GOTOB COUNTER`, 004:5091,
//!   5145-5165) runs on from there as the loop (assumption; the step budget
//!   ends any run that does not end).
//! - Calls (module `calls`): programs by name (`PROFIL`,
//!   `_N_GEOMETRIE_VACKA_SPF`, `L140`, `PCALL path`, `CALL "name"`), found
//!   first among the files the run wrote, then by the [`Environment`] as
//!   `_N_NAME_MPF` before `_N_NAME_SPF` (004:1454-1462), their PROC
//!   parameters bound by value or `VAR` by reference (omitted ones zero,
//!   004:1480), `$P_SUBPAR`, `P` repetitions, SAVE (the caller's modal G
//!   codes come back), RET and M17 (and M2/M30 in a subprogram, Siemens
//!   documentation) return, MCALL after every block with a path motion,
//!   `REPEAT label [label] P=n` sections; 16 program levels at most
//!   (004:1464), the main program being the first.
//! - Motion: G0 (each axis at its rapid rate, the slowest deciding; the
//!   dogleg of 004:841-847 is timed so but drawn straight), G1, G2/G3 by
//!   centre I/J/K (incremental from the start unless `=AC(…)`), radius CR
//!   (negative above 180°) or opening angle AR with a centre or an end
//!   point, in the plane of G17/G18/G19 (a helix when the third axis
//!   moves); G90/G91 and `AC()`/`IC()` per word; G70/G700 inch and
//!   G71/G710 mm (G700 and G710 take the feed in the same unit); F in
//!   mm/min (G94) or mm per revolution (G95, at S); BSPLINE (module
//!   `bspline`).
//! - S, M3/M4/M5, T (a number, or `T="name"`), M6, G4 dwell (F seconds
//!   or S spindle revolutions, in a block of its own), M0/M1 stops, M2/M30
//!   end; MSG evaluates its text, which the trace has no place for.
//! - Each step's path mode, corner tolerance and jerk limit from the
//!   velocity policy's [`PathControl`] (G60/G9, G64, G641 with ADIS and
//!   ADISPOS, G642–G645 with CTOL, SOFT/BRISK, M17 and M30 ending the
//!   continuous path), kept in step with the groups of the modal state.
//! - The programmable frame ([`ProgrammableFrame`], module
//!   `frames_and_cycles`: TRANS, ATRANS, ROT,
//!   AROT, SCALE, ASCALE, MIRROR, AMIRROR, and CYCLE800's swivel): steps
//!   are in base coordinates, the frame's image of the program's; a frame
//!   change leaves the tool where it is. An arc stays an arc where the
//!   frame keeps its plane (its centre moved, its sense turned over by a
//!   mirror); where the frame makes it an ellipse or turns it out of the
//!   plane it runs straight, reported as not run.
//! - The drilling cycles CYCLE81–CYCLE89 and CYCLE840 ([`super::cycles`]) as
//!   moves of the block that calls them, at the tool's position in the
//!   plane, under MCALL after every block with a path motion.
//! - Inverse-time feed G93 on lines and arcs: each block takes 1/F
//!   minutes, whatever its length (Siemens documentation); the F in force
//!   counts for every block until the next F.
//! - WRITE, READ, DELETE and ISFILE on the run's own files (module
//!   `files`).
//! - Tool radius compensation G41/G42/G40 (module `radius`) with the
//!   radius of the edge D of tool T: the tool-centre path in the trace.
//!
//! Reported once each as not run, moving nothing: the control's other
//! cycles (CYCLE832, …), axes the machine does
//! not have and orientation words, transformations (TRAORI),
//! inverse-time feed G93 on a spline, synchronous
//! actions and what [`super::eval`] does not model. System variables the run has no
//! value for read 0 with a finding once per name.
//!
//! A block makes a step when it has a word the machine acts on (an axis,
//! a code, F, S, T, M, …), moves, dwells or stops; one that only
//! computes, branches or calls makes none: the control prepares it ahead,
//! and the path does not wait for it (assumption; the seed warns that
//! slow preparation can starve a fast path, 004:2537-2557, which the run
//! does not model).
//!
//! Assumptions besides those above: a program run by itself whose first
//! line is a PROC has its parameters, `VAR` ones too, as variables of
//! their type at zero, as if called with all left out; block skip is off;
//! the settable frames G54 … are zero; a subprogram that reaches its end
//! without M17 or RET returns; a main program ends at its end without a
//! finding; `$AC_TIME` (the time since the block started) is 0 where a
//! program reads it, and the run has no clock (`$A_YEAR` … read 0,
//! reported once); `$AA_IM`, `$AA_IW` are the programmed position; a named
//! tool has no number (`$P_TOOLNO` is 0) and is listed in the trace's
//! tools by its name.
//!
//! A run into a sink takes the checkpoints the sink asks for before blocks
//! of the main program that it has not gone past yet, so that every step
//! before a checkpoint is of a block before it: outside calls and program
//! sections, before the first file the run reads (a program, or the global
//! user data), without radius compensation or a spline in force; and
//! resumes from them. Not inside a control structure, nor after a start
//! that is never closed: an end after the checkpoint that pairs with a
//! start before it would let the text before the checkpoint decide the run
//! after it. A checkpoint's course includes the labels and block numbers
//! before it, which jumps back and REPEAT look up, and the text of the
//! blocks it went past without running them or ran without a step, which a
//! later jump back may run (a block run again that makes a step shows in
//! its steps).

use std::{
    collections::{HashMap, HashSet},
    ops::Deref,
    sync::Arc,
};

use ncc_catalog::{AddressRole, Code, Dialect, KeywordKind};
use ncc_syntax::{Parse, TextRange, TextSize};

use super::{
    dynamics::PathControl,
    eval::{Context, ErrorKind, Eval, EvalError, Store, Value},
    frames::ProgrammableFrame,
    lower::{
        Call, Command, Dimension, Expr, Place, PlaceKind, SinumerikBlock, StatementKind, Word, WordValue, block_nodes,
        is_axis,
    },
    program::{SinumerikModel, StructureKind},
};
use crate::{
    arc::{OffCircle, centre_by_radius, circle_through},
    compensation_driver::Driver,
    lowered::Lowered,
    machine::MachineConfig,
    trace::{
        ABANDON_INTERVAL, Called, Checkpoint, DELIVERY_BATCH, Environment, Finding, Motion, Path, Position, RunRule,
        Step, StepSink, Stop, Tool, Trace, Undelivered, covers, fold, goes_on, slot,
    },
    transform::{Frame, over_axes},
};

mod bspline;
mod calls;
mod files;
mod flow;
mod frames_and_cycles;
mod radius;
mod resume;

use resume::{global_data_files, inside_structures};

use super::modes::{
    INCH, Modes,
    groups::{ACCELERATION, DIMENSIONS, FEED_MODE, MOTION, PATH_MODE, PLANE, SPINDLE, TOOL_RADIUS, UNITS},
};

/// Inverse-time feed: F is 1/minutes of each block.
const INVERSE_TIME: &str = "G93";

/// The axes the programmable frame maps, in its order.
const XYZ: [u8; 3] = [b'X', b'Y', b'Z'];

/// The frame a Sinumerik run starts in: none, the settable frames being
/// zero.
pub(crate) fn reset_frame(_machine: &MachineConfig) -> Frame {
    Frame::default()
}

/// Runs `text` on `machine` for at most `budget` blocks, reading the
/// programs it calls through `files`, handing the steps to `sink` as they
/// are final when there is one, from its start or from `checkpoint`.
pub(crate) fn run_in(
    text: &str,
    lowered: Option<&Arc<Unit>>,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
    mut sink: Option<&mut dyn StepSink>,
    checkpoint: Option<&Checkpoint>,
) -> Trace {
    let shared = Arc::new(machine.clone());
    let unit = lowered.cloned().unwrap_or_else(|| Arc::new(Unit::read(text, files)));
    let mut interpreter = Interpreter::new(&shared, files, text, unit);
    let start = checkpoint.and_then(|checkpoint| interpreter.resume(checkpoint));
    interpreter.run(budget, start, sink.as_deref_mut());
    interpreter.end_compensation();
    if let Some(sink) = sink {
        interpreter.deliver(sink, true);
    }
    let Interpreter { steps, state, called, executed, compensation, .. } = interpreter;
    let (tool_centre, compensated) = compensation.into_parts();
    Trace {
        axes: machine.step_axes().to_vec(),
        diameter_axis: machine.diameter_axis,
        frames: vec![reset_frame(machine)],
        reset_frame: reset_frame(machine),
        tool_centre,
        compensated,
        messages: Vec::new(),
        steps: steps.steps,
        findings: state.findings,
        tools: state.tools,
        files: called,
        blocks_run: executed,
        written: state.files.into_written(),
    }
}

/// One file of a run, lowered: the program's (source 0), or one a call
/// read. The editor's analysis keeps the program's between edits and hands
/// it to the run of the same text.
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    pub blocks: Lowered<SinumerikBlock>,
    pub model: SinumerikModel,
}

/// A unit is its blocks, with the program model beside them.
impl Deref for Unit {
    type Target = Lowered<SinumerikBlock>;

    fn deref(&self) -> &Lowered<SinumerikBlock> {
        &self.blocks
    }
}

impl Unit {
    /// The file `text`, lowered; cut short when `files` says the run is
    /// abandoned, which ends at its next look.
    fn read(text: &str, files: &dyn Environment) -> Unit {
        let parse = Parse::new(text, Dialect::Sinumerik);
        let (ranges, blocks): (Vec<TextRange>, Vec<SinumerikBlock>) = block_nodes(parse.green())
            .enumerate()
            .take_while(|(index, _)| !(index.is_multiple_of(ABANDON_INTERVAL) && files.abandoned()))
            .map(|(_, (range, block))| (range, SinumerikBlock::lower(block)))
            .unzip();
        let model = SinumerikModel::new(&blocks);
        Unit { blocks: Lowered::whole(blocks, ranges), model }
    }
}

/// A block of a run: its file (as [`Step::source`]) and index there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct At {
    source: usize,
    block: usize,
}

/// Which block runs after one.
enum Flow {
    Next,
    /// A block of the same file.
    Jump(usize),
    /// Into a call, or back from one.
    Go(At),
    /// Back from the program being run: `RET`, `M17`.
    Return,
    /// M2 or M30: the end of a main program, a return from a subprogram.
    End,
    /// The run stops (an error).
    Stop,
}

/// The words of a block, their values read.
#[derive(Debug, Default)]
struct Words {
    /// Axis letters with their values and dimensions.
    axes: Vec<(u8, f64, Option<Dimension>)>,
    /// I, J, K.
    centre: [Option<(f64, Option<Dimension>)>; 3],
    radius: Option<f64>,
    opening: Option<f64>,
    feed: Option<f64>,
    speed: Option<f64>,
    tool: Option<Value>,
    /// D: the tool's cutting edge.
    edge: Option<f64>,
    m: Vec<u32>,
    /// The codes written, in order (G numbers and words like `SOFT`).
    codes: Vec<&'static Code>,
    /// ADIS, ADISPOS and CTOL in mm, for the path modes.
    path: Vec<(&'static str, f64)>,
    degree: Option<f64>,
    weight: Option<f64>,
    interval: Option<f64>,
    auxiliary: u8,
}

impl Words {
    /// Whether the block wrote no word the machine acts on.
    fn is_empty(&self) -> bool {
        let Words {
            axes,
            centre,
            radius,
            opening,
            feed,
            speed,
            tool,
            // D only picks the edge whose radius compensation takes: the
            // machine sees nothing of it until a move.
            edge: _,
            m,
            codes,
            path,
            degree,
            weight,
            interval,
            auxiliary,
        } = self;
        axes.is_empty()
            && centre.iter().all(Option::is_none)
            && [radius, opening, feed, speed, degree, weight, interval].iter().all(|word| word.is_none())
            && path.is_empty()
            && tool.is_none()
            && m.is_empty()
            && codes.is_empty()
            && *auxiliary == 0
    }
}

/// A block's move, before it becomes a step.
#[derive(Clone, PartialEq)]
struct Moved {
    motion: Motion,
    path: Path,
    length: f64,
    duration: f64,
    feed: Option<f64>,
}

const STILL: Moved = Moved { motion: Motion::None, path: Path::Straight, length: 0.0, duration: 0.0, feed: None };

/// What the expressions see of the run, and what it reports: the modal
/// state, position, feed and spindle, the files, the findings.
struct State<'a> {
    machine: &'a MachineConfig,
    modes: Modes,
    /// Program coordinates in mm.
    position: Position,
    /// F as written, in mm/min or mm/rev by the feed mode (inch under
    /// G700).
    feed: Option<f64>,
    /// S in rpm.
    speed: f64,
    /// The tool T selected last: a number, or 0 for a named one.
    tool: u32,
    /// The cutting edge D selected last (0: none).
    edge: u32,
    /// Tool data the program wrote: `$TC_DP<n>[t,d]` by name, tool and
    /// edge.
    tool_data: HashMap<(String, i64, i64), f64>,
    tools: Vec<Tool>,
    /// The path modes G60, G64x, SOFT, BRISK with ADIS, ADISPOS and CTOL,
    /// kept in step with the groups of `modes` as each step is recorded.
    path: PathControl,
    /// The programmable frame: program coordinates to base ones (the
    /// settable frame's, which are zero).
    frame: ProgrammableFrame,
    /// How often the frame changed: radius compensation does not go
    /// across a change.
    frames: usize,
    files: files::Files,
    findings: Vec<Finding>,
    /// Keys of what was reported once.
    reported: HashSet<String>,
    /// The file and the start of the block being run: expressions and
    /// statements have ranges inside their block.
    source: usize,
    block_start: TextSize,
    stopped: bool,
}

impl State<'_> {
    /// A position in program coordinates in base ones, through the
    /// programmable frame (X, Y and Z; other axes as they are).
    fn to_base(&self, position: &Position) -> Position {
        self.frame_xyz(position, |frame, point| frame.to_base(point))
    }

    fn to_program(&self, position: &Position) -> Position {
        self.frame_xyz(position, |frame, point| frame.to_program(point))
    }

    fn frame_xyz(&self, position: &Position, map: impl Fn(&ProgrammableFrame, [f64; 3]) -> [f64; 3]) -> Position {
        if self.frame.is_identity() {
            return *position;
        }
        let mut mapped = *position;
        let xyz = XYZ.map(|letter| position[slot(letter)]);
        for (letter, value) in XYZ.into_iter().zip(map(&self.frame, xyz)) {
            mapped[slot(letter)] = value;
        }
        mapped
    }

    /// A finding at `range`, inside the block being run.
    fn finding(&mut self, rule: RunRule, range: TextRange, message: &str) {
        self.stopped |= rule.stops();
        let range = range + self.block_start;
        self.findings.push(Finding { rule, source: self.source, range, message: message.to_owned() });
    }

    fn report_once(&mut self, rule: RunRule, key: &str, range: TextRange, message: &str) {
        if self.reported.insert(key.to_owned()) {
            self.finding(rule, range, message);
        }
    }

    fn not_run(&mut self, what: &str, range: TextRange) {
        let message = format!("the executor does not run {what} yet: the time leaves it out");
        self.report_once(RunRule::NotRunYet, what, range, &message);
    }

    /// The key of tool data `name[indices]` the run keeps: `$TC_DP<n>[t,d]`.
    fn tool_data_key(name: &str, indices: &[Value], range: TextRange) -> Option<(String, i64, i64)> {
        let [tool, edge] = indices else { return None };
        let key = (name.to_owned(), tool.int(range).ok()?, edge.int(range).ok()?);
        name.starts_with("$TC_DP").then_some(key)
    }

    /// The value of axis `name` in program coordinates.
    fn axis_value(&self, name: &str) -> Option<f64> {
        let &[letter] = name.as_bytes() else { return None };
        self.machine.axes.contains(&letter).then(|| self.position[slot(letter)])
    }
}

impl Context for State<'_> {
    fn system(&mut self, name: &str, indices: &[Value], range: TextRange) -> Result<Value, EvalError> {
        let index = |at: usize| indices.get(at).and_then(|value| value.int(range).ok());
        let value = match name {
            "$P_F" => Value::Real(self.feed.unwrap_or(0.0)),
            "$P_S" => Value::Real(self.speed),
            "$P_SDIR" => Value::Int(self.modes.get(SPINDLE).and_then(|code| code[1..].parse().ok()).unwrap_or(5)),
            "$AC_MSNUM" => Value::Int(1),
            "$P_GG" => {
                let group = index(0).map(|group| format!("G{group}"));
                let code = group.and_then(|group| self.modes.code(&group));
                Value::Int(code.and_then(|code| code.index).map_or(0, i64::from))
            }
            "$AA_IM" | "$AA_IW" => match indices.first() {
                Some(Value::Axis(axis) | Value::Str(axis)) => match self.axis_value(axis) {
                    Some(value) => Value::Real(value),
                    None => return Err(failed(range, format!("the machine has no axis {axis}"))),
                },
                _ => return Err(failed(range, format!("{name} needs an axis: {name}[X]"))),
            },
            "$P_TOOLNO" | "$P_TOOLP" => Value::Int(i64::from(self.tool)),
            "$P_ISTEST" => Value::Bool(false),
            "$AC_TIME" => Value::Real(0.0),
            _ if let Some(value) =
                Self::tool_data_key(name, indices, range).and_then(|key| self.tool_data.get(&key)) =>
            {
                Value::Real(*value)
            }
            "$MN_MM_NUM_R_PARAM" | "$MC_MM_NUM_R_PARAM" => {
                Value::Int(i64::from(Dialect::Sinumerik.catalogue().parameters.count))
            }
            "$A_YEAR" | "$A_MONTH" | "$A_DAY" | "$A_HOUR" | "$A_MINUTE" | "$A_SECOND" => {
                let message = "the run has no clock: the date and time variables ($A_YEAR … $A_SECOND) read 0";
                self.report_once(RunRule::ParameterUnknown, "clock", range, message);
                Value::Int(0)
            }
            _ => {
                let message = format!("the run has no value for the system variable {name}: it reads 0");
                self.report_once(RunRule::ParameterUnknown, name, range, &message);
                Value::Int(0)
            }
        };
        Ok(value)
    }

    fn write_system(&mut self, name: &str, indices: &[Value], value: Value, range: TextRange) -> Result<(), EvalError> {
        match Self::tool_data_key(name, indices, range) {
            Some(key) => {
                self.tool_data.insert(key, value.number(range)?);
            }
            None => self.not_run(&format!("writes of the system variable {name}"), range),
        }
        Ok(())
    }

    fn set_group(&mut self, group: i64, index: i64, range: TextRange) -> Result<(), EvalError> {
        let code = u32::try_from(index)
            .ok()
            .and_then(|index| Dialect::Sinumerik.catalogue().code_at(&format!("G{group}"), index));
        match code {
            Some(code) => {
                self.modes.set(code);
                Ok(())
            }
            None => Err(failed(range, format!("G group {group} has no code {index} the executor knows"))),
        }
    }

    fn is_file(&self, path: &str) -> bool {
        self.files.exists(path)
    }

    fn undefined_array(&mut self, name: &str, range: TextRange) {
        let message = format!(
            "{name} is not defined in the program (a GUD whose definition is not in the project): taken as a REAL array of 100 elements a dimension"
        );
        self.report_once(RunRule::ParameterUnknown, name, range, &message);
    }
}

fn failed(range: TextRange, message: String) -> EvalError {
    EvalError { kind: ErrorKind::Failed, message, range }
}

struct Interpreter<'a> {
    machine: &'a Arc<MachineConfig>,
    files: &'a dyn Environment,
    /// The program's text.
    text: &'a str,
    units: Vec<Arc<Unit>>,
    /// The files read besides the program, source k being `called[k - 1]`.
    called: Vec<Called>,
    store: Store,
    state: State<'a>,
    calls: Vec<calls::Frame>,
    /// MCALL's program and arguments.
    modal_call: Option<Call>,
    spline: Option<bspline::Pending>,
    /// Radius compensation, and the tool-centre path it made.
    compensation: Driver,
    steps: Undelivered,
    executed: usize,
    /// One past the furthest block of the main file run, and what a run
    /// after it may read of the text before it ([`Resumed::before`]).
    reached: usize,
    before: u64,
}

impl<'a> Interpreter<'a> {
    fn new(machine: &'a Arc<MachineConfig>, files: &'a dyn Environment, text: &'a str, unit: Arc<Unit>) -> Self {
        let state = State {
            machine,
            modes: Modes::at_reset(),
            position: [0.0; 26],
            feed: None,
            speed: 0.0,
            tool: 0,
            edge: 1,
            tool_data: HashMap::new(),
            tools: Vec::new(),
            path: PathControl::default(),
            frame: ProgrammableFrame::default(),
            frames: 0,
            files: files::Files::default(),
            findings: Vec::new(),
            reported: HashSet::new(),
            source: 0,
            block_start: TextSize::default(),
            stopped: false,
        };
        Interpreter {
            machine,
            files,
            text,
            units: vec![unit],
            called: Vec::new(),
            store: Store::new(),
            state,
            calls: Vec::new(),
            modal_call: None,
            spline: None,
            compensation: Driver::default(),
            steps: Undelivered::default(),
            executed: 0,
            reached: 0,
            before: 0,
        }
    }

    fn eval(&mut self) -> Eval<'_> {
        Eval { store: &mut self.store, context: &mut self.state }
    }

    /// Declares the global user data of the definition files the
    /// environment has ([`global_data_files`]): their DEF lines.
    fn define_globals(&mut self) {
        for called in global_data_files() {
            let Some(text) = self.files.file(&called) else { continue };
            let source = self.unit_of(called, &text);
            let unit = Arc::clone(&self.units[source]);
            self.state.source = source;
            for (block, range) in unit.iter().zip(&unit.ranges) {
                self.state.block_start = range.start();
                for statement in &block.statements {
                    if let StatementKind::Def(def) = &statement.kind {
                        for declared in &def.names {
                            let result = self.eval().define(&def.ty, declared, true);
                            self.check(result);
                        }
                    }
                }
            }
        }
    }

    /// Runs the program for at most `budget` blocks, from its first block
    /// or from `start`; hands `sink` the steps as they are final and the
    /// checkpoints it asks for.
    fn run(&mut self, budget: usize, start: Option<At>, mut sink: Option<&mut (dyn StepSink + '_)>) {
        if start.is_none() {
            self.define_globals();
            self.bind_own_parameters();
        }
        let mut at = start.unwrap_or(At { source: 0, block: 0 });
        let inside = inside_structures(&self.units[0].model);
        loop {
            let unit = Arc::clone(&self.units[at.source]);
            self.state.source = at.source;
            if at.block >= unit.count() {
                // The end of the file: a subprogram returns, the main
                // program ends.
                match self.return_from() {
                    Some(back) => {
                        at = back;
                        continue;
                    }
                    None => break,
                }
            }
            self.state.block_start = unit.ranges[at.block].start();
            // A block of the main file the run has not gone past yet.
            let fresh = at.source == 0 && at.block >= self.reached;
            if fresh {
                self.pass_to(at.block);
            }
            if let Some(sink) = sink.as_deref_mut()
                && fresh
                && self.calls.is_empty()
                && self.called.is_empty()
                && !self.compensation.is_active()
                && self.spline.is_none()
                && !covers(&inside, at.block)
                && sink.checkpoint_wanted(at.block, unit.ranges[at.block].start())
            {
                self.deliver(sink, false);
                let offset = unit.ranges[at.block].start();
                let checkpoint =
                    Checkpoint { state: Box::new(self.resumed()), block: at.block, offset, executed: self.executed };
                if sink.checkpoint(checkpoint).is_break() {
                    return;
                }
            }
            if fresh {
                let block = &unit.block(at.block);
                let label = block.label.as_ref().map(|label| label.name.as_str());
                self.before = fold(self.before, (0u8, label, block.number.and_then(|n| n.value)));
                self.reached = at.block + 1;
            }
            if self.executed >= budget {
                let message = format!("the run went past its budget of {budget} blocks");
                let range = TextRange::up_to(unit.block(at.block).len);
                self.state.finding(RunRule::StepBudget, range, &message);
                break;
            }
            self.executed += 1;
            if !goes_on(self.files, self.executed) {
                break;
            }
            let made = self.steps.next();
            let flow = self.block(at, &unit);
            if fresh && self.steps.next() == made && !unit.block(at.block).statements.is_empty() {
                // A jump back may run it again without a step to show it.
                self.before = fold(self.before, (1u8, &self.text[unit.ranges[at.block]]));
            }
            if self.state.stopped {
                break;
            }
            let next = match flow {
                Flow::Next => Some(At { block: at.block + 1, ..at }),
                Flow::Jump(block) => Some(At { block, ..at }),
                Flow::Go(to) => Some(to),
                Flow::Return | Flow::End => self.return_from(),
                Flow::Stop => None,
            };
            let Some(next) = next else { break };
            at = self.section_end(at, next);
            if let Some(sink) = sink.as_deref_mut()
                && self.steps.steps.len() >= DELIVERY_BATCH
            {
                self.deliver(sink, false);
                if sink.closed() {
                    return;
                }
            }
        }
        // A curve the run stopped in still ends where its points lead.
        self.end_spline();
    }

    /// Hands `sink` the steps no later block can change: all at the
    /// `end`, else those before an open spline's or the first one radius
    /// compensation may still change.
    fn deliver(&mut self, sink: &mut dyn StepSink, end: bool) {
        let spline = self.spline.as_ref().map(bspline::Pending::first_step);
        let open = [spline, self.compensation.open_step()].into_iter().flatten().min().filter(|_| !end);
        let Driver { tool_centre, compensated, .. } = &mut self.compensation;
        self.steps.deliver(sink, open, &[reset_frame(self.state.machine)], compensated, tool_centre);
    }

    /// Runs the block at `at` of `unit`: its statements in order, then its
    /// codes and motion, then its call, jump or end.
    fn block(&mut self, at: At, unit: &Unit) -> Flow {
        let block = &unit.block(at.block);
        if block.statements.is_empty() {
            return Flow::Next;
        }
        let whole = TextRange::up_to(block.len);
        let mut words = Words::default();
        let mut flow = Flow::Next;
        let mut call = None;
        for statement in &block.statements {
            let range = statement.range;
            match &statement.kind {
                StatementKind::Word(word) => self.word(word, &mut words),
                StatementKind::Assign { target, value }
                    if target.kind == PlaceKind::User
                        && !self.store.is_defined(&target.name)
                        && Dialect::Sinumerik.catalogue().keyword(&target.name).is_some() =>
                {
                    self.state.not_run(&target.name, range);
                }
                StatementKind::Assign { target, value } => {
                    let result = self.eval().assign(target, value, range);
                    self.check(result);
                }
                StatementKind::Def(def) => {
                    for declared in &def.names {
                        let result = self.eval().define(&def.ty, declared, def.scope.is_some());
                        self.check(result);
                    }
                }
                StatementKind::Command(command) => self.command(command, &mut words, range),
                StatementKind::Call(called) => call = Some((called.clone(), range)),
                StatementKind::ModalCall(modal) => {
                    self.modal_call = modal.clone();
                }
                StatementKind::Return { arguments } => {
                    if !arguments.is_empty() {
                        self.state.not_run("RET with a return target", range);
                    }
                    flow = Flow::Return;
                }
                StatementKind::Proc(_) | StatementKind::Extern(_) => {}
                StatementKind::Define { .. } => self.state.not_run("DEFINE … AS macros", range),
                StatementKind::SyncAction { .. } => self.state.not_run("synchronous actions", range),
                StatementKind::Jump(jump) => flow = self.jump(at.block, jump, unit),
                StatementKind::If { condition, jump } => {
                    let holds = self.truth(condition);
                    flow = match (holds, jump) {
                        (None, _) => Flow::Stop,
                        (Some(true), Some(jump)) => self.jump(at.block, jump, unit),
                        (Some(false), Some(_)) | (Some(true), None) => Flow::Next,
                        (Some(false), None) => self.structure_exit(at.block, StructureKind::If, unit, range),
                    };
                }
                StatementKind::Else => flow = self.structure_exit(at.block, StructureKind::If, unit, range),
                StatementKind::While(condition) => {
                    flow = match self.truth(condition) {
                        None => Flow::Stop,
                        Some(true) => Flow::Next,
                        Some(false) => self.structure_exit(at.block, StructureKind::While, unit, range),
                    };
                }
                StatementKind::EndWhile => flow = self.structure_back(at.block, StructureKind::While, unit, range, 0),
                StatementKind::For { variable, start, end } => {
                    let result = self.eval().assign(variable, start, range);
                    flow = match self.check(result).and_then(|()| self.for_continues(variable, end)) {
                        None => Flow::Stop,
                        Some(true) => Flow::Next,
                        Some(false) => self.structure_exit(at.block, StructureKind::For, unit, range),
                    };
                }
                StatementKind::EndFor => flow = self.end_for(at.block, unit, range),
                StatementKind::Repeat | StatementKind::Loop | StatementKind::EndIf => {}
                StatementKind::Until(condition) => {
                    flow = match self.truth(condition) {
                        None => Flow::Stop,
                        Some(true) => Flow::Next,
                        Some(false) => self.structure_back(at.block, StructureKind::Repeat, unit, range, 1),
                    };
                }
                StatementKind::EndLoop => flow = self.structure_back(at.block, StructureKind::Loop, unit, range, 1),
                StatementKind::RepeatSection { start, end, count } => {
                    flow = self.repeat_section(at, unit, start, end.as_deref(), count.as_deref(), range);
                }
                StatementKind::Case { selector, arms } => flow = self.case(at.block, selector, arms, unit),
            }
            if self.state.stopped {
                return Flow::Stop;
            }
            if !matches!(flow, Flow::Next) {
                break;
            }
        }
        let start = self.state.to_base(&self.state.position);
        let (moved, stop, end, facts) = self.codes_and_motion(&words, whole);
        if self.state.stopped {
            return Flow::Stop;
        }
        // A block that only computes, branches or calls is prepared ahead:
        // the machine sees nothing of it.
        if !words.is_empty() || moved.motion != Motion::None || stop.is_some() {
            self.record(at, whole, moved.clone(), facts, stop);
            // A spline's steps stand in for its curve until it is built.
            if self.spline.is_none() {
                self.compensate(&start, whole);
                if self.state.stopped {
                    return Flow::Stop;
                }
            }
        }
        if end {
            self.end_spline();
            self.state.path.subprogram_end();
            return Flow::End;
        }
        if words.m.contains(&17) {
            self.end_spline();
            self.state.path.subprogram_end();
            return Flow::Return;
        }
        if let Some((called, range)) = call {
            return self.call(at, &called, range);
        }
        if matches!(flow, Flow::Next)
            && matches!(moved.motion, Motion::Rapid | Motion::Feed)
            && let Some(modal) = self.modal_call.clone()
            && !self.calls.iter().any(|frame| frame.modal)
        {
            return self.modal(at, &modal, whole);
        }
        flow
    }

    /// Reports an evaluation's error; `Some` when there was none.
    fn check<T>(&mut self, result: Result<T, EvalError>) -> Option<T> {
        match result {
            Ok(value) => Some(value),
            Err(error) => {
                self.eval_failed(error);
                None
            }
        }
    }

    fn eval_failed(&mut self, error: EvalError) {
        match error.kind {
            ErrorKind::Failed => {
                let message = format!("{}: the control stops", error.message);
                self.state.finding(RunRule::ArithmeticFailed, error.range, &message);
            }
            ErrorKind::NotModelled => self.state.not_run(&error.message, error.range),
        }
    }

    /// A condition's truth; `None` after reporting why it has none.
    fn truth(&mut self, condition: &Expr) -> Option<bool> {
        let result = self.eval().truth(condition);
        let truth = self.check(result);
        if truth.is_none() && !self.state.stopped {
            // Not modelled: the run cannot tell which way it goes.
            let message = "a condition the run cannot evaluate: it cannot tell which way the program goes";
            self.state.finding(RunRule::ControlWordUnknown, condition.range, message);
        }
        truth
    }

    /// A word's number and dimension; `None` when it has none (reported).
    fn word_number(&mut self, word: &Word) -> Option<(f64, Option<Dimension>)> {
        match word.value.as_ref() {
            Some(WordValue::Literal(number)) => Some((number.value(), None)),
            Some(WordValue::Expr { expr, dimension }) => {
                let result = self.eval().number(expr);
                self.check(result).map(|value| (value, *dimension))
            }
            None => None,
        }
    }

    /// Reads a word into `words`, or assigns it when its address is a
    /// variable's name.
    fn word(&mut self, word: &Word, words: &mut Words) {
        let catalogue = Dialect::Sinumerik.catalogue();
        let address = word.address.as_str();
        let machine_axis = matches!(address.as_bytes(), &[letter] if self.state.machine.axes.contains(&letter));
        if let Some(WordValue::Expr { expr, dimension: None }) = &word.value
            && !machine_axis
            && self.store.is_defined(address)
        {
            let target = Place { kind: PlaceKind::User, name: address.to_owned(), indices: Vec::new() };
            let result = self.eval().assign(&target, expr, word.range);
            self.check(result);
            return;
        }
        if address == "T" {
            if let Some(WordValue::Expr { expr, .. }) = &word.value {
                let result = self.eval().value(expr);
                words.tool = self.check(result);
            } else if let Some((value, _)) = self.word_number(word) {
                words.tool = Some(Value::Real(value));
            }
            return;
        }
        let Some(role) = catalogue.address(address).map(|a| a.role) else {
            // A bare letter is an address the catalogue has.
            let what = if is_axis(address) {
                format!("axis {address} (the machine has none)")
            } else {
                format!("the address {address}")
            };
            self.state.not_run(&what, word.range);
            return;
        };
        let Some((value, dimension)) = self.word_number(word) else { return };
        let whole = || (value >= 0.0 && value.fract() == 0.0 && value < f64::from(u32::MAX)).then_some(value as u32);
        match (role, address) {
            (AddressRole::Function, "G") => match whole().and_then(|number| catalogue.code('G', number)) {
                Some(code) => words.codes.push(code),
                None => self.state.not_run(&format!("G{value}"), word.range),
            },
            (AddressRole::Function, _) => match whole() {
                Some(number) => words.m.push(number),
                None => self.state.not_run(&format!("M{value}"), word.range),
            },
            (AddressRole::Axis, _) => match address.as_bytes() {
                &[letter] if self.state.machine.axes.contains(&letter) => words.axes.push((letter, value, dimension)),
                _ => self.state.not_run(&format!("axis {address} (the machine has none)"), word.range),
            },
            (AddressRole::Interpolation, "I" | "J" | "K") => {
                words.centre[usize::from(address.as_bytes()[0] - b'I')] = Some((value, dimension));
            }
            (AddressRole::Interpolation, "CR") => words.radius = Some(value),
            (AddressRole::Interpolation, "AR") => words.opening = Some(value),
            (AddressRole::Feed, _) => words.feed = Some(value),
            (AddressRole::Speed, _) => words.speed = Some(value),
            (AddressRole::Tolerance, "ADIS") => words.path.push(("ADIS", value)),
            (AddressRole::Tolerance, "ADISPOS") => words.path.push(("ADISPOS", value)),
            (AddressRole::Tolerance, "CTOL") => words.path.push(("CTOL", value)),
            (AddressRole::Spline, "SD") => words.degree = Some(value),
            (AddressRole::Spline, "PW") => words.weight = Some(value),
            (AddressRole::Spline, "PL") => words.interval = Some(value),
            (AddressRole::Auxiliary, _) => words.auxiliary = words.auxiliary.saturating_add(1),
            (AddressRole::Offset, "D") => words.edge = Some(value),
            // Other offsets select lengths the run does not model; the
            // count belongs to a call, tolerances of orientation to what
            // is reported below.
            (AddressRole::Offset | AddressRole::Count | AddressRole::Tolerance, _) => {}
            (AddressRole::Orientation, _) => self.state.not_run("tool orientation (A2, A3, LEAD, …)", word.range),
            _ => self.state.not_run(&format!("the address {address}"), word.range),
        }
    }

    /// A code or keyword written as a name.
    fn command(&mut self, command: &Command, words: &mut Words, range: TextRange) {
        let catalogue = Dialect::Sinumerik.catalogue();
        if let Some(code) = catalogue.word_code(&command.name) {
            if code.group.as_deref() == Some("G3") {
                self.frame(command, range);
            } else {
                words.codes.push(code);
            }
            return;
        }
        match catalogue.keyword(&command.name).map(|keyword| keyword.kind) {
            Some(KeywordKind::Transformation) if command.name.ends_with("OF") => {}
            Some(KeywordKind::Transformation) => {
                self.state.not_run(&format!("the transformation {}", command.name), range);
            }
            Some(KeywordKind::Statement) => {}
            _ => self.state.not_run(&command.name, range),
        }
    }

    /// The block's codes, feed, spindle, tool and motion: its move, its
    /// stop, whether it ends the program, and what its step records.
    fn codes_and_motion(&mut self, words: &Words, range: TextRange) -> (Moved, Option<Stop>, bool, Facts) {
        let mut facts = Facts::default();
        let mut dwell = false;
        for &code in &words.codes {
            match code.code.as_str() {
                "G4" => dwell = true,
                "G9" => facts.exact = true,
                "G74" | "G75" => self.state.not_run("reference point approach G74/G75", range),
                _ => {}
            }
            let ends_spline = code.group.as_deref() == Some(MOTION) && code.code != "BSPLINE";
            if ends_spline {
                self.end_spline();
            }
            self.state.modes.set(code);
        }
        let mut stop = None;
        let mut end = false;
        for &m in &words.m {
            match m {
                0 => stop = Some(Stop::Program),
                1 => stop = Some(Stop::Optional),
                2 | 30 => end = true,
                17 => {}
                6 => facts.tool_change = true,
                3..=5 => {
                    if let Some(code) = Dialect::Sinumerik.catalogue().code('M', m) {
                        self.state.modes.set(code);
                    }
                }
                _ => facts.m_functions = facts.m_functions.saturating_add(1),
            }
        }
        facts.m_functions = facts.m_functions.saturating_add(words.auxiliary);
        for &(address, value) in &words.path {
            if let Err(error) = self.state.path.address(address, self.length(value)) {
                self.state.finding(RunRule::ValueRefused, range, &error.to_string());
            }
        }
        if let Some(tool) = &words.tool {
            self.select_tool(tool);
            // The control's default edge of a new tool.
            self.state.edge = 1;
        }
        if let Some(edge) = words.edge {
            self.state.edge = if edge >= 0.0 && edge.fract() == 0.0 { edge as u32 } else { 0 };
        }
        if dwell {
            return (self.dwell(words, range), stop, end, facts);
        }
        if let Some(feed) = words.feed {
            self.state.feed = Some(feed);
        }
        if let Some(speed) = words.speed {
            self.state.speed = speed;
        }
        let moved = self.motion(words, range);
        (moved, stop, end, facts)
    }

    /// The spindle's commanded rpm, negative under M4, 0 when it stands.
    fn signed_rpm(&self) -> f64 {
        match self.state.modes.get(SPINDLE) {
            Some("M3") => self.state.speed,
            Some("M4") => -self.state.speed,
            _ => 0.0,
        }
    }

    fn select_tool(&mut self, tool: &Value) {
        let selected = match tool {
            Value::Str(name) => Some(Tool::Name(name.to_string())),
            number => number.int(TextRange::default()).ok().and_then(|n| u32::try_from(n).ok()).map(Tool::Number),
        };
        self.state.tool = match selected {
            Some(Tool::Number(number)) => number,
            _ => 0,
        };
        if let Some(tool) = selected.filter(|tool| *tool != Tool::Number(0))
            && !self.state.tools.contains(&tool)
        {
            self.state.tools.push(tool);
        }
    }

    /// G4: F seconds, or S revolutions of the spindle.
    fn dwell(&mut self, words: &Words, range: TextRange) -> Moved {
        let duration = match (words.feed, words.speed) {
            (Some(seconds), _) => seconds,
            (None, Some(revolutions)) if self.state.speed > 0.0 => revolutions * 60.0 / self.state.speed,
            (None, Some(_)) => {
                let message = "a dwell of spindle revolutions with the spindle at S0: it never ends";
                self.state.finding(RunRule::MotionWithoutFeed, range, message);
                0.0
            }
            (None, None) => {
                self.state.finding(RunRule::ValueRefused, range, "G4 needs its time: F seconds or S revolutions");
                0.0
            }
        };
        Moved { motion: Motion::Dwell, duration: duration.max(0.0), ..STILL }
    }

    /// A length as written, in mm: inch under G70 and G700.
    fn length(&self, value: f64) -> f64 {
        value * self.state.modes.mm_per_unit().unwrap_or(1.0)
    }

    /// Where the block's axis words lead; `None` when it has none.
    fn end_point(&self, words: &Words) -> Option<Position> {
        if words.axes.is_empty() {
            return None;
        }
        let incremental = self.state.modes.is(DIMENSIONS, "G91");
        let mut end = self.state.position;
        for &(letter, value, dimension) in &words.axes {
            let value = if is_linear(letter) { self.length(value) } else { value };
            let relative = dimension.map_or(incremental, |d| d == Dimension::Incremental);
            let at = &mut end[slot(letter)];
            *at = if relative { *at + value } else { value };
        }
        Some(end)
    }

    /// The block's move in the motion mode in force.
    fn motion(&mut self, words: &Words, range: TextRange) -> Moved {
        let start = self.state.position;
        let arc_by_angle = words.opening.is_some() && words.centre.iter().any(Option::is_some);
        let end = match self.end_point(words) {
            Some(end) => end,
            None if arc_by_angle && matches!(self.state.modes.get(MOTION), Some("G2" | "G3")) => start,
            None => return STILL,
        };
        if self.beyond_turns(&end, range) {
            return STILL;
        }
        let motion = self.state.modes.get(MOTION).unwrap_or("G1");
        if motion == "BSPLINE" {
            self.end_compensation();
            self.state.position = end;
            // A frame is affine: the curve of the mapped control points is
            // the mapped curve.
            let (start, end) = (self.state.to_base(&start), self.state.to_base(&end));
            return self.spline_point(words, range, &start, &end);
        }
        // `G[1]=…` left the spline without a code of the block.
        self.end_spline();
        let (path, end) = match motion {
            "G0" | "G1" => (Path::Straight, end),
            "G2" | "G3" => match self.arc(words, range, &start, end, motion == "G3") {
                Some((path, end)) => (self.arc_in_base(path, &start, range), end),
                None => return STILL,
            },
            other => {
                self.state.not_run(&format!("the motion {other}"), range);
                return STILL;
            }
        };
        self.state.position = end;
        let (start, end) = (self.state.to_base(&start), self.state.to_base(&end));
        let length = path_length(&path, &start, &end, self.state.machine.arc_tolerance());
        if motion == "G0" {
            return self.rapid(&start, &end, length);
        }
        self.feed_move(range, path, length)
    }

    /// Whether a rotary axis would leave its travel limits (`limits`, in
    /// degrees): its cables allow only so many turns one way, and then it
    /// must be unwound (004:936-938). Rotary axes are not in the frames, so
    /// their program positions are the machine's; the linear axes' limits
    /// would need the work offsets, which the run takes as zero.
    fn beyond_turns(&mut self, end: &Position, range: TextRange) -> bool {
        let machine = self.state.machine;
        for &axis in machine.axes.iter().filter(|&&axis| !is_linear(axis)) {
            let degrees = end[slot(axis)];
            let Some(limit) = machine.limits.get(&axis).and_then(|limits| limits.passed_by(degrees)) else { continue };
            let letter = char::from(axis);
            let message = format!(
                "{letter} would reach {degrees:.3}° ({:.2} turns), beyond its travel limit {limit}° ({:.2} turns): a rotary axis turns only so far one way before it must be unwound (004:936-938); the control stops",
                degrees / 360.0,
                limit / 360.0
            );
            self.state.finding(RunRule::BeyondAxisRange, range, &message);
            return true;
        }
        false
    }

    /// A rapid move between base positions: each axis at its own rate, the
    /// slowest deciding.
    fn rapid(&self, start: &Position, end: &Position, length: f64) -> Moved {
        let machine = self.state.machine;
        let minutes = machine
            .axes
            .iter()
            .map(|&axis| (end[slot(axis)] - start[slot(axis)]).abs() / f64::from(machine.axis_rapid_rate(axis)))
            .fold(0.0, f64::max);
        Moved { motion: Motion::Rapid, path: Path::Straight, length, duration: minutes * 60.0, feed: None }
    }

    /// A feed move of `length` mm along `path`.
    fn feed_move(&mut self, range: TextRange, path: Path, length: f64) -> Moved {
        let minutes = if self.state.modes.is(FEED_MODE, INVERSE_TIME) {
            self.inverse_time(range)
        } else {
            self.feed_rate(range).map(|rate| length / rate)
        };
        let (duration, feed) = match minutes {
            Some(minutes) => {
                (minutes * 60.0, Some(length / minutes).filter(|f| f.is_finite()).or(self.feed_rate_quiet()))
            }
            None => (0.0, None),
        };
        Moved { motion: Motion::Feed, path, length, duration, feed }
    }

    /// Under G93 a block takes 1/F minutes, whatever its length (Siemens
    /// documentation); `None` after reporting a missing F.
    fn inverse_time(&mut self, range: TextRange) -> Option<f64> {
        let minutes = self.state.feed.filter(|&feed| feed > 0.0).map(|feed| 1.0 / feed);
        if minutes.is_none() {
            let message =
                "inverse-time feed (G93) with no F: the block's time 1/F is not given, so the axes cannot move";
            self.state.finding(RunRule::MotionWithoutFeed, range, message);
        }
        minutes
    }

    /// The path feed in mm/min; `None` after reporting why the axes cannot
    /// move.
    fn feed_rate(&mut self, range: TextRange) -> Option<f64> {
        if self.state.modes.is(FEED_MODE, INVERSE_TIME) {
            // A spline's points share its curve: what 1/F of each is, the
            // run does not divide.
            self.state.not_run("inverse-time feed G93 on a spline or cycle", range);
            return None;
        }
        let rate = self.feed_rate_quiet();
        if rate.is_none() {
            let message = match self.state.modes.get(FEED_MODE) {
                Some("G95") => "feed per revolution (G95) with no F or the spindle stopped: the axes cannot move",
                _ => "no feed F programmed before this motion: G1, G2, G3 and splines need one",
            };
            self.state.finding(RunRule::MotionWithoutFeed, range, message);
        }
        rate
    }

    fn feed_rate_quiet(&self) -> Option<f64> {
        let feed = self.state.feed.filter(|&feed| feed > 0.0)?;
        let feed = if self.state.modes.is(UNITS, "G700") { feed * INCH } else { feed };
        let spindle_on = matches!(self.state.modes.get(SPINDLE), Some("M3" | "M4"));
        match self.state.modes.get(FEED_MODE) {
            Some("G95") => (spindle_on && self.state.speed > 0.0).then_some(feed * self.state.speed),
            Some(INVERSE_TIME) => None,
            _ => Some(feed),
        }
    }

    /// The arc of G2 (`ccw` false) or G3 from `start` to `end` in the
    /// plane in force: its path and end; `None` after reporting.
    fn arc(
        &mut self,
        words: &Words,
        range: TextRange,
        start: &Position,
        mut end: Position,
        ccw: bool,
    ) -> Option<(Path, Position)> {
        let [a, b, _] = self.plane().axes().map(|axis| XYZ[axis]);
        let from = [start[slot(a)], start[slot(b)]];
        let centre_word = |letter: u8| words.centre[usize::from(letter - b'X')];
        let centre = match (centre_word(a), centre_word(b)) {
            (None, None) => None,
            (i, j) => {
                let absolute = |word: Option<(f64, Option<Dimension>)>, at: f64| match word {
                    Some((value, Some(Dimension::Absolute))) => self.length(value),
                    Some((value, _)) => at + self.length(value),
                    None => at,
                };
                Some([absolute(i, from[0]), absolute(j, from[1])])
            }
        };
        let tolerance = self.state.machine.arc_tolerance();
        let to_point = |end: &Position| [end[slot(a)], end[slot(b)]];
        let centre = match (centre, words.radius, words.opening) {
            (Some(centre), _, Some(angle)) if words.axes.is_empty() => {
                // The end lies the opening angle round the centre.
                let turn = if ccw { angle } else { -angle }.to_radians();
                let (sin, cos) = turn.sin_cos();
                let (dx, dy) = (from[0] - centre[0], from[1] - centre[1]);
                end[slot(a)] = centre[0] + dx * cos - dy * sin;
                end[slot(b)] = centre[1] + dx * sin + dy * cos;
                centre
            }
            (Some(centre), _, _) => centre,
            (None, radius, opening) => {
                let to = to_point(&end);
                let radius = match (radius, opening) {
                    (Some(radius), _) => Some(self.length(radius)),
                    (None, Some(angle)) if angle > 0.0 && angle < 360.0 => {
                        let half = (to[0] - from[0]).hypot(to[1] - from[1]) / 2.0;
                        let radius = half / (angle / 2.0).to_radians().sin();
                        Some(if angle > 180.0 { -radius } else { radius })
                    }
                    _ => None,
                };
                let Some(radius) = radius else {
                    let message = "a circle needs its centre (I, J, K), radius CR or opening angle AR";
                    self.state.finding(RunRule::ArcOffCircle, range, message);
                    return None;
                };
                match centre_by_radius(from, to, radius, ccw, tolerance) {
                    Some(centre) => centre,
                    None => {
                        let message = format!("no arc of radius {} mm joins the start and the end point", radius.abs());
                        self.state.finding(RunRule::ArcOffCircle, range, &message);
                        return None;
                    }
                }
            }
        };
        if let Err(OffCircle { start_radius, end_radius }) =
            circle_through(from, to_point(&end), centre, ccw, tolerance)
        {
            let message = format!(
                "the end point does not lie on the circle: {end_radius:.3} mm from the centre, the start {start_radius:.3} mm, more than the tolerance {tolerance} mm apart"
            );
            self.state.finding(RunRule::ArcOffCircle, range, &message);
            return None;
        }
        let path = Path::Arc { plane: (a, b), centre, clockwise: !ccw };
        Some((path, end))
    }

    /// Adds the block's step.
    fn record(&mut self, at: At, range: TextRange, moved: Moved, facts: Facts, stop: Option<Stop>) {
        let modes = &self.state.modes;
        // `G[10]=…` and SAVE change the groups without a code of the block:
        // the path modes follow the groups.
        for group in [PATH_MODE, ACCELERATION] {
            if let Some(code) = modes.get(group) {
                self.state.path.code(code);
            }
        }
        let path = self.state.path.step(facts.exact, moved.motion == Motion::Rapid);
        let rpm = self.signed_rpm() as f32;
        let step = Step {
            source: at.source,
            range: range + self.state.block_start,
            motion: moved.motion,
            path: moved.path,
            duration: moved.duration,
            length: moved.length,
            feed: moved.feed,
            end: over_axes(&self.state.to_base(&self.state.position), self.state.machine.step_axes()),
            frame: 0,
            stop,
            path_mode: path.path_mode,
            m_functions: facts.m_functions,
            tool_change: facts.tool_change,
            dynamic_set: 1,
            mergeable: false,
            jerk_limited: path.jerk_limited,
            spindle: [rpm; 2],
            corner_tolerance: path.corner_tolerance,
        };
        self.steps.push(step);
    }
}

/// What a block's step records besides its move.
#[derive(Debug, Default)]
struct Facts {
    /// G9.
    exact: bool,
    m_functions: u8,
    tool_change: bool,
}

/// Whether `axis` is a linear axis, whose values are lengths.
fn is_linear(axis: u8) -> bool {
    matches!(axis, b'X' | b'Y' | b'Z' | b'U' | b'V' | b'W')
}

/// The length of a straight move over the linear axes.
/// The length of `path` from `start` to `end` (base coordinates): a
/// helix's is its arc's and its rise's.
fn path_length(path: &Path, start: &Position, end: &Position, tolerance: f64) -> f64 {
    let Path::Arc { plane: (a, b), centre, clockwise } = *path else { return distance(start, end) };
    let normal = XYZ.into_iter().find(|&letter| letter != a && letter != b).unwrap_or(b'Z');
    let point = |position: &Position| [position[slot(a)], position[slot(b)]];
    let rise = end[slot(normal)] - start[slot(normal)];
    match circle_through(point(start), point(end), centre, !clockwise, tolerance) {
        Ok(arc) => arc.length().hypot(rise),
        Err(_) => distance(start, end),
    }
}

fn distance(from: &Position, to: &Position) -> f64 {
    b"XYZUVW".iter().map(|&axis| (to[slot(axis)] - from[slot(axis)]).powi(2)).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests;
