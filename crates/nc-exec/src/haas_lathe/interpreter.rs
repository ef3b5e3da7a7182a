//! The Haas lathe interpreter: the modal state, motion and time of the
//! file's first program, block by block, in the order the control runs
//! them.
//!
//! What runs:
//! - Motion: G00 (the slowest axis at its own rapid rate, lathe manual
//!   §5.8 (001:543-547)), G01, arcs G02/G03 by R (negative for more than
//!   180°) or by I/K (I a radius, both incremental from the start), G02
//!   turning clockwise seen with +Z to the right and +X up (lathe manual
//!   §5.8 (001:591-668)). X and U are diameters, Z and W lengths; U and W
//!   count from the last position and mix with X and Z in one block
//!   (lathe manual §5.4 (001:480-555)).
//! - Feed and spindle: F per revolution (G99) or per minute (G98), S in
//!   rpm (G97) or m/min of cutting speed (G96), the speed limit G50 S,
//!   the spindle M03/M04/M05, dwell G04 P (ms without a decimal point,
//!   seconds with one, lathe manual §5.3 (001:55-71)), exact stop G09 and
//!   G61/G64.
//! - The canned cycles as moves of their block ([`super::cycles`],
//!   [`super::roughing`]): thread cutting G32; the box cycles G90, G92,
//!   G94, modal, repeated by each block that moves; G70–G73 over the P..Q
//!   contour, the run going on after the Q block once a roughing cycle has
//!   run (lathe manual §6.9 item 8, inferred there) and after the block of
//!   G70; G74–G76; the drilling and tapping cycles G81–G89, G184 at every
//!   block that moves while one is in force, until G80, G00 or G01.
//! - Macro statements through [`super::eval`]: assignments, `IF … GOTO`,
//!   `IF … THEN`, `GOTO`, `WHILE … DOn` … `ENDn`; the step budget bounds
//!   the loops.
//! - M00/M01 stops, M02/M30 end the run; T changes the tool; other M
//!   functions are counted.
//!
//! The modal state is the catalogue's: every group starts at its default
//! (G01, G18, G21, G40, G54, G64, G80, G97, G99, M05, …) and a modal code
//! replaces its group's.
//!
//! Everything else is reported once per kind as not run yet and moves
//! nothing, so that a total never silently leaves work out: live-tool
//! tapping G95, tool-nose radius compensation G41/G42 (in a cycle's
//! contour too), M97/M98/M99, G65, G28/G29, G53, work offsets, G52, inch
//! units G20, corner chamfers and angles on G01 (and in the contour of
//! G70 and G73; the roughing of G71 and G72 ignores them).
//!
//! Assumptions the manual does not settle:
//! - A step's X is the radius, as CNC8x6 keeps it under diameter
//!   programming ([`Trace::diameter_axis`] is X): the program's X50. is 25
//!   in the geometry, lengths and times.
//! - Arcs lie in the plane (Z, X), so that clockwise in it is clockwise
//!   with +Z to the right and +X up.
//! - Under G96 the rpm is 1000·Vc/(π·D), at most the G50 limit, and
//!   follows the diameter along a line (the time is its integral); along an
//!   arc it is the one at the mean diameter. The limit holds under G97 too.
//!   The machine's own spindle maximum is not modelled.
//! - F is the lead of G32, G92 and G76 under G98 as under G99 (the manual:
//!   "F = feed per revolution = thread pitch", §6.8 (001:1490)).
//! - A cycle changes no modal state but its own (the box cycles' target,
//!   the drilling words) and the spindle G84/G184 switch on; the modes of
//!   the contour's blocks stay with them.
//! - G64, the default, joins blocks continuously; G09 and G61 stop exactly.
//! - A computed dwell P (`P#1`) counts in ms, as a literal without a point.
//! - A word whose variable is vacant is left out (Fanuc convention).
//! - Block delete `/` is off: the blocks run.
//! - `GOTO n` goes to the first block numbered n in the program.
//! - T is recorded as written (`T101`: tool 1, offset 1).

use std::f64::consts::TAU;

use ncc_syntax::{Dialect, Parse, TextRange};

use super::{
    eval::{EvalError, MacroValue, Variables},
    lower::{Expr, ExprKind, HaasBlock, Statement, Value, Word, block_nodes},
    modes::Modes,
    program::{Contour, Program, ProgramModel},
};
use crate::{
    arc::{CircleArc, OffCircle, circle_through},
    known::Known,
    machine::MachineConfig,
    trace::{Finding, Motion, Path, PathMode, Position, RunRule, Step, StepSink, Stop, Trace, round3, slot},
    transform::{Frame, over_axes},
};

/// The catalogue's groups the interpreter reads.
const MOTION: &str = "G1";
const DRILLING: &str = "G9";
const FEED_MODE: &str = "G10";
const SPEED_MODE: &str = "G12S";
const EXACT_STOP: &str = "G13";
const SPINDLE: &str = "M2";

/// Runs the first program of `text` on `machine` for at most `budget`
/// blocks, handing the steps to `sink` when there is one. The run starts
/// from the beginning every time: it takes no checkpoints.
pub(crate) fn run_into(text: &str, machine: &MachineConfig, budget: usize, sink: Option<&mut dyn StepSink>) -> Trace {
    let parse = Parse::new(text, Dialect::HaasLathe);
    let (ranges, blocks): (Vec<TextRange>, Vec<HaasBlock>) =
        block_nodes(parse.green()).map(|(range, block)| (range, HaasBlock::lower(block))).unzip();
    let model = ProgramModel::new(&blocks);
    let mut interpreter = Interpreter::new(machine, &blocks, &ranges);
    interpreter.contours = model.contours().cloned().collect();
    if let Some(program) = model.programs.first() {
        interpreter.run(program, model.programs.len() > 1, budget);
    }
    let frames = vec![Frame::default()];
    let mut steps = interpreter.steps;
    if let Some(sink) = sink {
        sink.references(&frames, &[], &[]);
        sink.steps(&mut steps);
    }
    Trace {
        axes: machine.step_axes().to_vec(),
        diameter_axis: Some(b'X'),
        frames,
        reset_frame: Frame::default(),
        tool_centre: Vec::new(),
        compensated: Vec::new(),
        messages: Vec::new(),
        steps,
        findings: interpreter.findings,
        tools: interpreter.tools,
        files: Vec::new(),
        blocks_run: interpreter.executed,
    }
}

/// Which block runs after one.
enum Flow {
    Next,
    Jump(usize),
    End,
}

/// A block's move, before it becomes a step.
struct Moved {
    motion: Motion,
    path: Path,
    length: f64,
    duration: f64,
    feed: Option<f64>,
}

const STILL: Moved = Moved { motion: Motion::None, path: Path::Straight, length: 0.0, duration: 0.0, feed: None };

struct Interpreter<'a> {
    machine: &'a MachineConfig,
    blocks: &'a [HaasBlock],
    ranges: &'a [TextRange],
    modes: Modes,
    variables: Variables,
    /// Program coordinates, X as a radius.
    position: Position,
    /// F as written: mm/rev or mm/min by the feed mode.
    feed: Option<f64>,
    /// S as written: rpm under G97, m/min under G96.
    speed: f64,
    /// G50 S.
    speed_limit: Option<f64>,
    steps: Vec<Step>,
    findings: Vec<Finding>,
    tools: Vec<u32>,
    executed: usize,
    /// Keys of what was reported once.
    reported: Vec<String>,
    /// A finding the control stops on was made.
    stopped: bool,
    /// The contours of the cycles G70–G73.
    contours: Vec<Contour>,
    cycles: canned::CycleState,
}

impl<'a> Interpreter<'a> {
    fn new(machine: &'a MachineConfig, blocks: &'a [HaasBlock], ranges: &'a [TextRange]) -> Self {
        Interpreter {
            machine,
            blocks,
            ranges,
            modes: Modes::at_reset(Dialect::HaasLathe.catalogue()),
            variables: Variables::at_power_on(),
            position: [0.0; 26],
            feed: None,
            speed: 0.0,
            speed_limit: None,
            steps: Vec::new(),
            findings: Vec::new(),
            tools: Vec::new(),
            executed: 0,
            reported: Vec::new(),
            stopped: false,
            contours: Vec::new(),
            cycles: canned::CycleState::default(),
        }
    }

    fn run(&mut self, program: &Program, more_programs: bool, budget: usize) {
        let mut at = program.blocks.start;
        while program.blocks.contains(&at) {
            if self.executed >= budget {
                let message = format!("the run went past its budget of {budget} blocks");
                self.finding(RunRule::StepBudget, self.ranges[at], &message);
                return;
            }
            self.executed += 1;
            let flow = self.block(at, program);
            if self.stopped {
                return;
            }
            at = match flow {
                Flow::Next => at + 1,
                Flow::Jump(target) => target,
                Flow::End => return,
            };
        }
        if more_programs && at == program.blocks.end {
            let range = self.ranges[at];
            self.finding(RunRule::RunsIntoSubprogram, range, "the program runs into the next one without M30 or M02");
        }
    }

    /// Runs block `at`: its codes, motion, then its macro statement.
    fn block(&mut self, at: usize, program: &Program) -> Flow {
        let block = &self.blocks[at];
        let range = self.ranges[at];
        if block.words.is_empty() && block.statements.is_empty() && block.corners.is_empty() {
            return Flow::Next;
        }
        let mut flow = Flow::Next;
        let (mut dwell, mut exact_stop, mut still, mut cycle) = (false, false, false, None);
        for code in block.codes(b'G') {
            self.modes.set('G', code);
            match code {
                0..=3 | 32 | 80 | 90 | 92 | 94 => self.cycles.drilling = Default::default(),
                18 | 21 | 40 | 50 | 61 | 64 | 96..=100 => {}
                4 => dwell = true,
                9 => exact_stop = true,
                20 => self.not_run("inch units G20 (the run reads mm)", range),
                41 | 42 => self.not_run("tool-nose radius compensation G41/G42", range),
                54..=59 | 110..=129 => {
                    self.not_run("work offsets G54–G59, G110–G129 (positions stay in program coordinates)", range)
                }
                81..=89 | 184 => {}
                95 => self.not_run("live-tool rigid tapping G95", range),
                101 => self.not_run("mirror image G101", range),
                28 | 29 => {
                    still = true;
                    self.not_run("reference point returns G28/G29", range);
                }
                53 => {
                    still = true;
                    self.not_run("moves in machine coordinates G53", range);
                }
                65 => {
                    still = true;
                    self.not_run("macro calls G65", range);
                }
                70..=76 => {
                    cycle = Some(code);
                    if (71..=73).contains(&code) {
                        flow = self.after_contour(at).map_or(Flow::Next, Flow::Jump);
                    }
                }
                _ => {
                    still = true;
                    self.not_run(&format!("G{code}"), range);
                }
            }
        }
        let (mut stop, mut m_functions, mut end) = (None, 0u8, false);
        for code in block.codes(b'M') {
            self.modes.set('M', code);
            match code {
                0 => stop = Some(Stop::Program),
                1 => stop = Some(Stop::Optional),
                2 | 30 => end = true,
                3..=5 => {}
                97..=99 => self.not_run("subprogram calls and returns M97/M98/M99", range),
                _ => m_functions = m_functions.saturating_add(1),
            }
        }
        if let Some(feed) = block.word(b'F').and_then(|word| self.number(word, range)) {
            self.feed = Some(feed);
        }
        if let Some(speed) = block.word(b'S').and_then(|word| self.number(word, range)) {
            if block.has_code(b'G', 50) {
                self.speed_limit = Some(speed);
            } else {
                self.speed = speed;
            }
        }
        let tool = block.word(b'T').and_then(|word| self.number(word, range));
        if let Some(tool) = tool.map(|tool| tool as u32)
            && !self.tools.contains(&tool)
        {
            self.tools.push(tool);
        }
        let moved = if dwell {
            self.dwell(block, range)
        } else if let Some(code) = cycle {
            self.canned(code, at, block, range)
        } else if still {
            STILL
        } else {
            self.motion(block, range)
        };
        if self.stopped {
            return Flow::End;
        }
        for statement in &block.statements {
            flow = self.statement(statement, range, at, program);
            if self.stopped {
                return Flow::End;
            }
        }
        let exact = exact_stop || self.modes.get(EXACT_STOP) == Some(61);
        let step = Step {
            source: 0,
            range,
            motion: moved.motion,
            path: moved.path,
            duration: moved.duration,
            length: moved.length,
            feed: moved.feed,
            end: over_axes(&self.position, self.machine.step_axes()),
            frame: 0,
            stop,
            path_mode: if exact { PathMode::ExactStop } else { PathMode::Continuous },
            m_functions,
            tool_change: tool.is_some(),
            dynamic_set: 1,
            mergeable: false,
        };
        // A cycle's moves before its last, which is the block's own.
        for (Moved { motion, path, length, duration, feed }, end, stop) in std::mem::take(&mut self.cycles.pending) {
            let (m_functions, tool_change) = (0, false);
            let moved =
                Step { motion, path, duration, length, feed, end, stop, m_functions, tool_change, ..step.clone() };
            self.steps.push(moved);
        }
        self.steps.push(step);
        if end { Flow::End } else { flow }
    }

    /// The block after the Q block of the roughing cycle in block `cycle`.
    fn after_contour(&self, cycle: usize) -> Option<usize> {
        self.contours.iter().find(|contour| contour.cycle == cycle).map(|contour| contour.blocks.end() + 1)
    }

    fn dwell(&mut self, block: &HaasBlock, range: TextRange) -> Moved {
        match block.word(b'P').and_then(|word| self.seconds(word, range)) {
            Some(duration) => Moved { motion: Motion::Dwell, duration, ..STILL },
            None => STILL,
        }
    }

    /// A dwell's P in seconds: ms without a decimal point, seconds with one
    /// (lathe manual §5.3 (001:55-71)).
    fn seconds(&mut self, word: &Word, range: TextRange) -> Option<f64> {
        let seconds_written = matches!(&word.value, Some(Value::Literal(decimal)) if decimal.has_point());
        let value = self.number(word, range)?;
        Some(if seconds_written { value } else { value / 1000.0 })
    }

    /// The block's move to its end point in the motion mode in force.
    fn motion(&mut self, block: &HaasBlock, range: TextRange) -> Moved {
        let start = self.position;
        let Some(end) = self.end_point(block, range, &start) else { return STILL };
        if let Some(code) = self.modes.get(DRILLING).filter(|&code| code != 80) {
            // The drilling cycle in force runs at the position instead.
            return self.drilling(code, block, range, &end);
        }
        let motion = self.modes.get(MOTION);
        if let Some(code @ (32 | 90 | 92 | 94)) = motion {
            return self.modal_cycle(code, block, range, &end);
        }
        self.unrun_corners(block, range, motion);
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let (from, to) = ([start[z], start[x]], [end[z], end[x]]);
        let (path, length) = match motion {
            Some(code @ (2 | 3)) => {
                let Some(arc) = self.arc(block, range, from, to, code == 3) else { return STILL };
                let path = Path::Arc { plane: (b'Z', b'X'), centre: arc.centre, clockwise: arc.sweep < 0.0 };
                (path, arc.length())
            }
            _ => (Path::Straight, (to[0] - from[0]).hypot(to[1] - from[1])),
        };
        self.position = end;
        if motion == Some(0) {
            return Moved { motion: Motion::Rapid, path, length, duration: self.rapid_seconds(from, to), feed: None };
        }
        self.feed_move(range, from, to, path, length)
    }

    /// Reports the corner words of a G01 block, which the run leaves out.
    fn unrun_corners(&mut self, block: &HaasBlock, range: TextRange, motion: Option<u32>) {
        if motion == Some(1) && (!block.corners.is_empty() || "IKRA".bytes().any(|l| block.word(l).is_some())) {
            self.not_run("corner chamfers, roundings and angles on G01 (the line runs to its end point)", range);
        }
    }

    /// Where the block's X, U, Z and W words lead from `start`; `None` when
    /// it has none.
    fn end_point(&mut self, block: &HaasBlock, range: TextRange, start: &Position) -> Option<Position> {
        let mut end = *start;
        let mut moves = false;
        for word in &block.words {
            let (axis, incremental) = match word.letter {
                b'X' => (b'X', false),
                b'U' => (b'X', true),
                b'Z' => (b'Z', false),
                b'W' => (b'Z', true),
                _ => continue,
            };
            let Some(value) = self.number(word, range) else { continue };
            // X and U are diameters; the control counts in µm of them.
            let written = if axis == b'X' { 2.0 } else { 1.0 };
            let at = &mut end[slot(axis)];
            *at = round3(if incremental { *at * written + value } else { value }) / written;
            moves = true;
        }
        moves.then_some(end)
    }

    /// Seconds of a rapid move from `from` to `to` (Z, X radius): the
    /// slowest axis at its own rate.
    fn rapid_seconds(&self, from: [f64; 2], to: [f64; 2]) -> f64 {
        let minutes = [(b'X', to[1] - from[1]), (b'Z', to[0] - from[0])]
            .map(|(axis, delta)| delta.abs() / f64::from(self.machine.axis_rapid_rate(axis)))
            .into_iter()
            .fold(0.0, f64::max);
        minutes * 60.0
    }

    /// The arc from `from` to `to` in the plane (Z, X), radii on X; `None`
    /// after reporting an end point off its circle.
    fn arc(
        &mut self,
        block: &HaasBlock,
        range: TextRange,
        from: [f64; 2],
        to: [f64; 2],
        ccw: bool,
    ) -> Option<CircleArc> {
        let tolerance = self.machine.arc_tolerance();
        let centre = match block.word(b'R').and_then(|word| self.number(word, range)) {
            Some(radius) => match centre_by_radius(from, to, radius, ccw, tolerance) {
                Some(centre) => centre,
                None => {
                    let message = format!("no arc of radius {} mm joins the start and the end point", radius.abs());
                    self.finding(RunRule::ArcOffCircle, range, &message);
                    return None;
                }
            },
            None => {
                let mut offset = |letter| block.word(letter).and_then(|word| self.number(word, range)).unwrap_or(0.0);
                let (k, i) = (offset(b'K'), offset(b'I'));
                [from[0] + k, from[1] + i]
            }
        };
        match circle_through(from, to, centre, ccw, tolerance) {
            Ok(arc) => Some(arc),
            Err(OffCircle { start_radius, end_radius }) => {
                let message = format!(
                    "the end point does not lie on the circle: {} mm from the centre, the start {} mm, more than the tolerance {tolerance} mm apart",
                    round3(end_radius),
                    round3(start_radius)
                );
                self.finding(RunRule::ArcOffCircle, range, &message);
                None
            }
        }
    }

    /// A feed move of `length` mm from `from` to `to` (Z, X radius) along
    /// `path`.
    fn feed_move(&mut self, range: TextRange, from: [f64; 2], to: [f64; 2], path: Path, length: f64) -> Moved {
        let minutes = self.feed_minutes(range, from, to, length, path == Path::Straight);
        let (duration, feed) = minutes.map_or((0.0, None), |minutes| (minutes * 60.0, Some(length / minutes)));
        Moved { motion: Motion::Feed, path, length, duration, feed }
    }

    /// Minutes of a feed move of `length` mm from `from` to `to` (Z, X
    /// radius), along a line or an arc; `None` after reporting why the axes
    /// cannot move. Under G96 the rpm follows the radius up to the G50
    /// limit: exactly along a line, at the mean radius along an arc.
    fn feed_minutes(&mut self, range: TextRange, from: [f64; 2], to: [f64; 2], length: f64, line: bool) -> Option<f64> {
        let Some(feed) = self.feed.filter(|&feed| feed > 0.0) else {
            self.finding(
                RunRule::MotionWithoutFeed,
                range,
                "no feed F programmed before this motion: G01–G03 need one",
            );
            return None;
        };
        if self.modes.get(FEED_MODE) == Some(98) {
            return Some(length / feed);
        }
        let rpm = self.spindle_rpm(range, (from[1] + to[1]) / 2.0)?;
        if line && self.modes.get(SPEED_MODE) == Some(96) {
            let limit = self.speed_limit.unwrap_or(f64::INFINITY);
            return Some(turning_minutes(length, [from[1], to[1]], 1000.0 * self.speed / TAU, limit) / feed);
        }
        Some(length / (feed * rpm))
    }

    /// The spindle's rpm at `radius`: S under G97, the cutting speed S
    /// (m/min) over the circumference under G96, at most the G50 limit;
    /// `None` after reporting a spindle that does not turn.
    fn spindle_rpm(&mut self, range: TextRange, radius: f64) -> Option<f64> {
        let spindle_on = matches!(self.modes.get(SPINDLE), Some(3 | 4));
        let limit = self.speed_limit.unwrap_or(f64::INFINITY);
        let rpm = match self.modes.get(SPEED_MODE) {
            _ if !spindle_on => 0.0,
            Some(96) => (1000.0 * self.speed / (TAU * radius.abs())).min(limit),
            _ => self.speed.min(limit),
        };
        if !rpm.is_finite() {
            self.not_run("constant cutting speed G96 at the spindle's centre without a G50 limit", range);
            return None;
        }
        if rpm <= 0.0 {
            let message =
                "feed per revolution (G99) or a thread with the spindle stopped or at S0: the axes cannot move";
            self.finding(RunRule::MotionWithoutFeed, range, message);
            return None;
        }
        Some(rpm)
    }

    fn statement(&mut self, statement: &Statement, range: TextRange, at: usize, program: &Program) -> Flow {
        match statement {
            Statement::Assign { target, value, .. } => {
                if let Err(error) = self.variables.assign(target, value) {
                    self.eval_failed(error, range);
                }
                Flow::Next
            }
            Statement::If { condition, then, .. } => match (self.condition(condition, range), then) {
                (true, Some(then)) => self.statement(then, range, at, program),
                _ => Flow::Next,
            },
            Statement::Goto { target, .. } => self.goto(target, range, program),
            Statement::LoopStart { condition, .. } => {
                let Some(end) = program.loop_end(at) else {
                    self.finding(RunRule::CallTargetMissing, range, "no END with the loop's number after its DO");
                    return Flow::End;
                };
                // `DOn` without WHILE loops for ever.
                let runs = condition.as_ref().is_none_or(|condition| self.condition(condition, range));
                if runs { Flow::Next } else { Flow::Jump(end + 1) }
            }
            Statement::LoopEnd { .. } => match program.loop_start(at) {
                Some(start) => Flow::Jump(start),
                None => {
                    self.finding(RunRule::CallTargetMissing, range, "no DO with the loop's number before its END");
                    Flow::End
                }
            },
        }
    }

    fn goto(&mut self, target: &Expr, range: TextRange, program: &Program) -> Flow {
        let number = match self.variables.eval(target) {
            Ok(Known::Is(MacroValue::Number(value))) if value >= 0.0 => value.round() as u64,
            Ok(Known::Unknown) => {
                self.unknown(range);
                return Flow::End;
            }
            Ok(_) => {
                self.finding(RunRule::CallTargetMissing, range, "GOTO names no block number");
                return Flow::End;
            }
            Err(error) => {
                self.eval_failed(error, range);
                return Flow::End;
            }
        };
        match program.block_numbers.get(&number).and_then(|blocks| blocks.first()) {
            Some(&block) => Flow::Jump(block),
            None => {
                self.finding(
                    RunRule::CallTargetMissing,
                    range,
                    &format!("no block N{number} in this program to go to"),
                );
                Flow::End
            }
        }
    }

    /// A condition's truth; an unknown one is reported and taken as false.
    fn condition(&mut self, condition: &Expr, range: TextRange) -> bool {
        match self.variables.condition(condition) {
            Ok(Known::Is(truth)) => truth,
            Ok(Known::Unknown) => {
                self.unknown(range);
                false
            }
            Err(error) => {
                self.eval_failed(error, range);
                false
            }
        }
    }

    /// A word's value; `None` when it has none (vacant, unknown, or an
    /// error reported).
    fn number(&mut self, word: &Word, range: TextRange) -> Option<f64> {
        let (negative, value) = match word.value.as_ref()? {
            Value::Literal(decimal) => return Some(decimal.to_f64()),
            Value::Variable { negative, index } => {
                let variable = Expr { kind: ExprKind::Variable(Box::new(index.clone())), range: index.range };
                (*negative, self.variables.eval(&variable))
            }
            Value::Bracket { negative, expr } => (*negative, self.variables.eval(expr)),
        };
        match value {
            Ok(Known::Is(MacroValue::Number(value))) => Some(if negative { -value } else { value }),
            Ok(Known::Is(MacroValue::Vacant)) => None,
            Ok(Known::Unknown) => {
                self.unknown(range);
                None
            }
            Err(error) => {
                self.eval_failed(error, range);
                None
            }
        }
    }

    fn unknown(&mut self, range: TextRange) {
        let message = "a variable whose value the run does not know (system variables, the kept commons #500–#699): what uses it is left out";
        self.report_once(RunRule::ParameterUnknown, "unknown variable", range, message);
    }

    fn eval_failed(&mut self, error: EvalError, range: TextRange) {
        let message = match error {
            EvalError::DivisionByZero { .. } => "a division by zero".to_owned(),
            EvalError::OutOfDomain { function, .. } => format!("{function:?} of a value outside its domain"),
            EvalError::NoSuchVariable { number, .. } => format!("there is no macro variable #{number}"),
            EvalError::VacantVariableNumber { .. } => "a variable number from a vacant variable".to_owned(),
            EvalError::ReadOnlyVariable { number, .. } => format!("#{number} cannot be written"),
            EvalError::Malformed { .. } => "a malformed expression".to_owned(),
        };
        self.finding(RunRule::ArithmeticFailed, range, &format!("{message}: the control stops"));
    }

    fn not_run(&mut self, what: &str, range: TextRange) {
        let message = format!("the executor does not run {what} yet: the time leaves them out");
        self.report_once(RunRule::NotRunYet, what, range, &message);
    }

    fn report_once(&mut self, rule: RunRule, key: &str, range: TextRange, message: &str) {
        if !self.reported.iter().any(|done| done == key) {
            self.reported.push(key.to_owned());
            self.finding(rule, range, message);
        }
    }

    fn finding(&mut self, rule: RunRule, range: TextRange, message: &str) {
        self.stopped |= rule.stops();
        self.findings.push(Finding { rule, source: 0, range, message: message.to_owned() });
    }
}

/// Minutes of a line `length` mm long from radius `radii[0]` to `radii[1]`
/// at 1 mm per revolution, the spindle at min(`k`/|r|, `limit`) rpm (G96):
/// the integral of max(|r|/k, 1/limit) along the line, the radius changing
/// linearly.
fn turning_minutes(length: f64, [from, to]: [f64; 2], k: f64, limit: f64) -> f64 {
    // The radius under which the limit holds.
    let clamp = k / limit;
    let per_mm = |r: f64| (r.abs() / k).max(1.0 / limit);
    // The integral of `per_mm` from 0 to r.
    let integral = |r: f64| {
        let a = r.abs();
        let part = if a <= clamp { a / limit } else { clamp / limit + (a * a - clamp * clamp) / (2.0 * k) };
        part.copysign(r)
    };
    if (to - from).abs() < 1e-9 {
        length * per_mm(from)
    } else {
        length * (integral(to) - integral(from)) / (to - from)
    }
}

/// The centre of the arc of `radius` from `from` to `to`: on the side that
/// makes it at most a half circle, the other side for a negative radius
/// (lathe manual §5.8 (001:658-660)). `None` when the ends lie farther
/// apart than the diameter beyond `tolerance`.
fn centre_by_radius(from: [f64; 2], to: [f64; 2], radius: f64, ccw: bool, tolerance: f64) -> Option<[f64; 2]> {
    let chord = [to[0] - from[0], to[1] - from[1]];
    let half = chord[0].hypot(chord[1]) / 2.0;
    if half == 0.0 || half > radius.abs() + tolerance {
        return None;
    }
    let height = (radius * radius - half * half).max(0.0).sqrt();
    // The centre of a short counter-clockwise arc lies left of the chord.
    let side = if ccw == (radius > 0.0) { 1.0 } else { -1.0 };
    let left = [-chord[1] / (2.0 * half), chord[0] / (2.0 * half)];
    let middle = [(from[0] + to[0]) / 2.0, (from[1] + to[1]) / 2.0];
    Some([middle[0] + side * height * left[0], middle[1] + side * height * left[1]])
}

mod canned;
#[cfg(test)]
mod tests;
