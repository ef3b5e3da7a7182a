//! Running a CNC8x6 program: the modal state, motion and time, block by
//! block, in the order the control runs them.
//!
//! What runs so far: the program's flow (subprogram calls G71 L Q with
//! their repetitions, jumps G73 L Q that run a section Q+1 times, G04 taking
//! Q from a call in its block, M02/M30, a step budget against endless
//! loops), rapid and linear motion (G00, G01), arcs and helices
//! (G02, G03) with the centre from I/J/K and the plane from the two axes
//! written (01 §6.4), absolute and incremental dimensions (G90, G91), feed
//! per minute and per revolution with the decimal-point rules of F (G94,
//! G95), the spindle speed S, dwell (G04 Q, in 10 ms), parameter
//! assignments and references (a block's motion uses the values from before
//! its own assignments). A block's time is its path
//! length over its feed (G00: the longest axis travel over the machine's
//! rapid rate), plus dwells; ramps and block joining are the velocity
//! model's business.
//!
//! Everything else the control does is reported once per kind as not run
//! yet (macrocycles, parameter arithmetic, offsets, compensation, fixed
//! cycles, transformations, threads), so that a total never silently leaves
//! something out.

use nalgebra::Vector2;
use ncc_catalog::{AddressRole, Catalogue, Dialect};
use ncc_syntax::{Parse, TextRange, ast::AstNode};

use crate::{
    arith::{self, Parameters, Raw},
    lower::{BlockData, Value, Word},
    machine::MachineConfig,
};

/// Axes by letter (index = letter − `A`); positions in mm (degrees for
/// rotary axes).
pub type Position = [f64; 26];

/// What a block did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// No motion, no time.
    None,
    Rapid,
    Feed,
    Dwell,
}

/// One block as it ran.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The block's text range.
    pub range: TextRange,
    pub motion: Motion,
    /// Seconds since the program started, when the block starts.
    pub start_time: f64,
    pub duration: f64,
    /// Path length in mm.
    pub length: f64,
    /// The path feed in mm/min (`None` for rapid and non-motion blocks).
    pub feed: Option<f64>,
    /// Programmed positions at the block's start and end (program and
    /// machine coordinates coincide until zero offsets run).
    pub start: Position,
    pub end: Position,
}

/// A problem found while running, at a text range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    pub range: TextRange,
    pub message: String,
    /// The run stopped here (an error the control stops on).
    pub fatal: bool,
}

/// A whole run.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    pub steps: Vec<Step>,
    pub findings: Vec<Finding>,
    /// Tools called with T, in order of first use.
    pub tools: Vec<u32>,
}

impl Trace {
    /// Total seconds.
    pub fn total_time(&self) -> f64 {
        self.steps.last().map_or(0.0, |step| step.start_time + step.duration)
    }

    /// Seconds spent in blocks of one kind.
    pub fn time_in(&self, motion: Motion) -> f64 {
        self.steps.iter().filter(|step| step.motion == motion).map(|step| step.duration).sum()
    }

    /// Path length in mm of blocks of one kind.
    pub fn length_in(&self, motion: Motion) -> f64 {
        self.steps.iter().filter(|step| step.motion == motion).map(|step| step.length).sum()
    }

    /// The programmed position at the end.
    pub fn end_position(&self) -> Position {
        self.steps.last().map_or([0.0; 26], |step| step.end)
    }
}

/// How many blocks a run executes at most before it stops: a jump loop
/// that never ends or runaway recursion stops here with a finding.
pub const DEFAULT_STEP_BUDGET: usize = 10_000_000;

/// How deep subprogram calls nest before the run stops.
const MAX_CALL_DEPTH: usize = 64;

/// Runs a CNC8x6 program from its first block to M02/M30 on `machine`,
/// following subprogram calls and jumps, for at most `budget` blocks.
/// Parameters start at zero.
pub fn run(parse: &Parse, machine: &MachineConfig, budget: usize) -> Trace {
    let blocks: Vec<(TextRange, BlockData)> = parse
        .tree()
        .blocks()
        .map(|block| (block.syntax().text_range(), BlockData::lower(block.syntax().green())))
        .collect();
    let units = Units::of(&blocks);
    let mut runner = Runner::new(machine);
    // Calls being run: where to return, how many runs remain, where the
    // subprogram starts.
    let mut calls: Vec<Call> = Vec::new();
    // Jumps taken so far from each jump block, until its count runs out.
    let mut jumps: std::collections::HashMap<usize, u32> = Default::default();
    let mut at = 0;
    let mut executed = 0;
    while let Some((range, block)) = blocks.get(at) {
        let range = *range;
        if units.starts_subprogram(at) && calls.is_empty() {
            runner.finding(range, "the main body runs into a subprogram: it has no M02 or M30 before it", false);
            break;
        }
        executed += 1;
        if executed > budget {
            let message = format!("stopped after {budget} blocks: a jump loop that never ends or runaway calls?");
            runner.finding(range, &message, true);
            break;
        }
        let next = at + 1;
        at = match runner.block(block, range) {
            Flow::End => break,
            Flow::Next => next,
            Flow::Return => match calls.last_mut() {
                Some(call) if call.remaining > 1 => {
                    call.remaining -= 1;
                    call.start
                }
                Some(_) => calls.pop().map_or(next, |call| call.back),
                None => next,
            },
            Flow::Call { label, times } => match units.subprogram(label) {
                Some(start) if calls.len() < MAX_CALL_DEPTH => {
                    calls.push(Call { back: next, remaining: times, start });
                    start
                }
                Some(_) => {
                    runner.finding(
                        range,
                        &format!("calls nest deeper than {MAX_CALL_DEPTH}: runaway recursion?"),
                        true,
                    );
                    break;
                }
                None => {
                    runner.finding(
                        range,
                        &format!("there is no subprogram L{label} (G79 L{label}) in this file"),
                        true,
                    );
                    break;
                }
            },
            Flow::Jump { label, times } => match units.jump_target(at, label) {
                Some(target) => {
                    let taken = jumps.entry(at).or_default();
                    if *taken < times {
                        *taken += 1;
                        target
                    } else {
                        // The count starts again when the section is reached anew.
                        jumps.remove(&at);
                        next
                    }
                }
                None => {
                    runner.finding(range, &format!("no block N{label} in this program unit to jump to"), true);
                    break;
                }
            },
        };
    }
    Trace { steps: runner.steps, findings: runner.findings, tools: runner.tools }
}

/// A subprogram call being run.
struct Call {
    /// The block after the call.
    back: usize,
    /// Runs left, this one included.
    remaining: u32,
    /// The subprogram's first block after its `G79`.
    start: usize,
}

/// Where the subprograms start, and the block numbers of each unit.
struct Units {
    /// Subprogram starts (`G79 L`): the block index and the label.
    starts: Vec<(usize, u32)>,
    /// The unit of each block (0: the main body, then each subprogram).
    unit_of: Vec<usize>,
    /// Block numbers with their block, sorted.
    numbers: Vec<(u64, usize)>,
}

impl Units {
    fn of(blocks: &[(TextRange, BlockData)]) -> Units {
        let label = |block: &BlockData| match block.word(b'L')?.value.as_ref()? {
            Value::Literal(decimal) => whole_number(decimal),
            Value::Parameter { .. } => None,
        };
        let (mut starts, mut unit_of, mut unit) = (Vec::new(), Vec::with_capacity(blocks.len()), 0);
        for (index, (_, block)) in blocks.iter().enumerate() {
            if block.has_code(b'G', 79) {
                unit += 1;
                starts.extend(label(block).map(|label| (index, label)));
            }
            unit_of.push(unit);
        }
        let mut numbers: Vec<(u64, usize)> =
            blocks.iter().enumerate().filter_map(|(index, (_, block))| Some((block.number?.value?, index))).collect();
        numbers.sort_unstable();
        Units { starts, unit_of, numbers }
    }

    fn starts_subprogram(&self, index: usize) -> bool {
        self.starts.iter().any(|&(at, _)| at == index)
    }

    /// The first block of subprogram `label`, after its `G79`.
    fn subprogram(&self, label: u32) -> Option<usize> {
        self.starts.iter().find(|&&(_, l)| l == label).map(|&(at, _)| at + 1)
    }

    /// The block numbered `label` in the unit of block `from`.
    fn jump_target(&self, from: usize, label: u32) -> Option<usize> {
        let (unit, label) = (self.unit_of[from], u64::from(label));
        let first = self.numbers.partition_point(|&(number, _)| number < label);
        self.numbers[first..]
            .iter()
            .take_while(|&&(number, _)| number == label)
            .map(|&(_, at)| at)
            .find(|&at| self.unit_of[at] == unit)
    }
}

/// What runs after a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Flow {
    Next,
    End,
    /// `G70`: back from a subprogram.
    Return,
    /// `G71 L`: run subprogram `label` `times` times.
    Call {
        label: u32,
        times: u32,
    },
    /// `G73 L Q`: jump to block N`label`, `times` times in all.
    Jump {
        label: u32,
        times: u32,
    },
}

/// The control's state while a program runs.
struct Runner<'a> {
    catalogue: &'static Catalogue,
    machine: &'a MachineConfig,
    /// G00–G03.
    motion: u32,
    incremental: bool,
    per_revolution: bool,
    /// F as programmed: mm/min (per minute) or mm/rev (per revolution).
    feed: Option<f64>,
    /// S in rpm.
    speed: f64,
    position: Position,
    params: Parameters,
    time: f64,
    steps: Vec<Step>,
    findings: Vec<Finding>,
    tools: Vec<u32>,
    /// Kinds of work already reported as not run.
    reported: Vec<String>,
}

/// Tolerance of the arc end point's distance from the centre (1 µm, 01 §6.4).
const ARC_TOLERANCE: f64 = 0.001;

impl<'a> Runner<'a> {
    fn new(machine: &'a MachineConfig) -> Self {
        Runner {
            catalogue: Dialect::Cnc8x6.catalogue(),
            machine,
            // The priority block: G01 G90 G94 F0 S0.
            motion: 1,
            incremental: false,
            per_revolution: false,
            feed: None,
            speed: 0.0,
            position: [0.0; 26],
            params: Parameters::zeroed(),
            time: 0.0,
            steps: Vec::new(),
            findings: Vec::new(),
            tools: Vec::new(),
            reported: Vec::new(),
        }
    }

    fn block(&mut self, block: &BlockData, range: TextRange) -> Flow {
        let at = |local: TextRange| local + range.start();
        let codes: Vec<(u8, u32, TextRange)> = block
            .words
            .iter()
            .filter(|word| matches!(word.letter, b'G' | b'M'))
            .filter_map(|word| Some((word.letter, self.integer(word)?, at(word.range))))
            .collect();
        let has = |letter: u8, number: u32| codes.iter().any(|&(l, n, _)| l == letter && n == number);
        for &(letter, number, code_range) in &codes {
            match (letter, number) {
                (b'G', 0..=3) => self.motion = number,
                (b'G', 90) => self.incremental = false,
                (b'G', 91) => self.incremental = true,
                (b'G', 94) => self.per_revolution = false,
                (b'G', 95) => self.per_revolution = true,
                // Planes, block joining, cancelling and the priority
                // codes change nothing the executor models yet.
                (b'G', 4 | 17..=19 | 23 | 24 | 40 | 53 | 78 | 80 | 98) | (b'M', _) => {}
                // Program flow, which the caller follows.
                (b'G', 70 | 71 | 73 | 79) => {}
                (b'G', 26..=29) => self.not_run("parameter arithmetic (G26–G29)", code_range),
                (b'G', 72) => self.not_run("macrocycle calls (G72)", code_range),
                (b'G', 41 | 42) => self.not_run("radius compensation (G41/G42)", code_range),
                (b'G', 33) => self.not_run("thread cutting (G33)", code_range),
                (b'G', 81..=89) => self.not_run("fixed cycles (G81–G89)", code_range),
                (b'G', 54..=59 | 92 | 93) => self.not_run("zero offsets (G54–G59, G92, G93)", code_range),
                (b'G', 31 | 34..=39) => self.not_run("transformations (G31, G34–G39)", code_range),
                (b'G', 96 | 97) => self.not_run("constant cutting speed (G96/G97)", code_range),
                _ => self.not_run(&format!("G{number:02}"), code_range),
            }
        }
        for word in &block.words {
            match self.catalogue.role_of(word.letter) {
                Some(AddressRole::Feed) => self.feed = self.feed_value(word),
                Some(AddressRole::Speed) => {
                    if let Some(speed) = self.number(word) {
                        self.speed = speed;
                    }
                }
                Some(AddressRole::Tool) => {
                    if let Some(tool) = self.integer(word)
                        && !self.tools.contains(&tool)
                    {
                        self.tools.push(tool);
                    }
                }
                _ => {}
            }
        }
        let start = self.position;
        let axes: Vec<&Word> =
            block.words.iter().filter(|w| self.catalogue.role_of(w.letter) == Some(AddressRole::Axis)).collect();
        let (motion, length, duration, feed) = if has(b'G', 4) {
            let dwell = block.word(b'Q').and_then(|q| self.number(q)).unwrap_or(0.0) * 0.01;
            (Motion::Dwell, 0.0, dwell, None)
        } else if axes.is_empty() {
            (Motion::None, 0.0, 0.0, None)
        } else {
            let mut end = self.position;
            for word in &axes {
                if let Some(value) = self.number(word) {
                    let slot = &mut end[usize::from(word.letter - b'A')];
                    *slot = if self.incremental { *slot + value } else { value };
                }
            }
            self.position = end;
            self.moved(&Move { block, range, axes: &axes, start, end })
        };
        self.steps.push(Step {
            range,
            motion,
            start_time: self.time,
            duration,
            length,
            feed,
            start,
            end: self.position,
        });
        self.time += duration;
        // Assignments take effect after the block's motion.
        for assignment in &block.assignments {
            let (Some(index), Some(value)) = (assignment.index, &assignment.value) else { continue };
            let raw = match value {
                Value::Literal(decimal) => arith::literal_raw(decimal),
                Value::Parameter { .. } => self.raw(value),
            };
            self.params.set(index as usize, raw);
        }
        if has(b'M', 2) || has(b'M', 30) {
            return Flow::End;
        }
        // The call or jump comes at the end of the block; with G04, Q is
        // the dwell and the call runs once (01 §4.8).
        let label = block.word(b'L').and_then(|word| self.integer(word));
        let count = block.word(b'Q').filter(|_| !has(b'G', 4)).and_then(|word| self.integer(word));
        match label {
            Some(label) if has(b'G', 71) => Flow::Call { label, times: count.unwrap_or(1).max(1) },
            Some(label) if has(b'G', 73) => Flow::Jump { label, times: count.unwrap_or(1) },
            _ if has(b'G', 70) => Flow::Return,
            _ => Flow::Next,
        }
    }

    fn finding(&mut self, range: TextRange, message: &str, fatal: bool) {
        self.findings.push(Finding { range, message: message.to_owned(), fatal });
    }

    /// Length, duration and feed of a block's move.
    fn moved(&mut self, step: &Move<'_>) -> (Motion, f64, f64, Option<f64>) {
        let (range, start, end) = (step.range, step.start, step.end);
        let travel = |i: usize| end[i] - start[i];
        let straight = (0..26).map(|i| travel(i).powi(2)).sum::<f64>().sqrt();
        if self.motion == 0 {
            // Every axis runs at its own rate: the slowest one to arrive sets the time.
            let minutes = (b'A'..=b'Z')
                .map(|letter| {
                    travel(usize::from(letter - b'A')).abs() / f64::from(self.machine.axis_rapid_rate(letter))
                })
                .fold(0.0, f64::max);
            return (Motion::Rapid, straight, minutes * 60.0, None);
        }
        let length = match self.motion {
            2 | 3 => match self.arc_length(step) {
                Some(length) => length,
                None => return (Motion::Feed, straight, 0.0, None),
            },
            _ => straight,
        };
        let feed = match (self.feed, self.per_revolution) {
            (Some(feed), true) => Some(feed * self.speed),
            (feed, false) => feed,
            (None, true) => None,
        };
        match feed.filter(|&feed| feed > 0.0) {
            Some(feed) => (Motion::Feed, length, length / feed * 60.0, Some(feed)),
            None => {
                let why = if self.per_revolution && self.feed.is_some() {
                    "feed per revolution (G95) with spindle speed S0: the axes cannot move"
                } else {
                    "no feed F programmed before this motion: G01–G03 need one"
                };
                self.finding(range, why, false);
                (Motion::Feed, length, 0.0, None)
            }
        }
    }

    /// The length of an arc (with a helix's lead along a third axis), or
    /// `None` after reporting why the block is not an arc.
    fn arc_length(&mut self, step: &Move<'_>) -> Option<f64> {
        let Move { block, range, axes, start, end } = *step;
        let mut letters: Vec<u8> = axes.iter().map(|word| word.letter).collect();
        letters.dedup();
        if letters.len() < 2 {
            let message = "an arc needs both coordinates of its plane, even when the end point equals the start";
            self.finding(range, message, false);
            return None;
        }
        // The plane's first axis is the one I measures along: X of XY, Y of
        // YZ, Z of ZX (01 §6.4).
        let (first, second) = plane(letters[0], letters[1]);
        let (a, b) = (usize::from(first - b'A'), usize::from(second - b'A'));
        let centre_offset = |letter: u8| block.word(letter).and_then(|word| self.number(word)).unwrap_or(0.0);
        let from = Vector2::new(start[a], start[b]);
        let to = Vector2::new(end[a], end[b]);
        let centre = from + Vector2::new(centre_offset(b'I'), centre_offset(b'J'));
        let (radius, end_radius) = ((from - centre).norm(), (to - centre).norm());
        if (radius - end_radius).abs() > ARC_TOLERANCE {
            let message = format!(
                "the end point does not lie on the circle: {} mm from the centre, the start {} mm (error 7.56)",
                round3(end_radius),
                round3(radius)
            );
            self.finding(range, &message, false);
            return None;
        }
        let angle_of = |point: Vector2<f64>| (point.y - centre.y).atan2(point.x - centre.x);
        let counter_clockwise = self.motion == 3;
        let mut sweep = angle_of(to) - angle_of(from);
        if counter_clockwise && sweep <= 0.0 {
            sweep += std::f64::consts::TAU;
        } else if !counter_clockwise && sweep >= 0.0 {
            sweep -= std::f64::consts::TAU;
        }
        let arc = radius * sweep.abs();
        // A third axis written in the block moves along with the arc.
        let lead: f64 =
            letters[2..].iter().map(|&l| (end[usize::from(l - b'A')] - start[usize::from(l - b'A')]).powi(2)).sum();
        Some((arc * arc + lead).sqrt())
    }

    /// F in mm/min (per minute) or mm/rev (per revolution): without a
    /// decimal point mm/min or µm/rev, with one m/min or mm/rev (01 §6.6);
    /// from a parameter, its raw value as the digits written.
    fn feed_value(&self, word: &Word) -> Option<f64> {
        match &word.value {
            Some(Value::Literal(decimal)) => {
                let value = decimal.to_f64();
                Some(match (decimal.has_point(), self.per_revolution) {
                    (false, false) | (true, true) => value,
                    (true, false) => value * 1000.0,
                    (false, true) => value / 1000.0,
                })
            }
            value => self.raw(value.as_ref()?).map(|raw| raw as f64 / if self.per_revolution { 1000.0 } else { 1.0 }),
        }
    }

    /// A dimensional word's value: the literal as written (mm), or a
    /// parameter's raw thousandths.
    fn number(&self, word: &Word) -> Option<f64> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => Some(decimal.to_f64()),
            value => self.raw(value).map(|raw| raw as f64 / 1000.0),
        }
    }

    /// A dimensionless word's whole number (codes, T): the literal, or a
    /// parameter's raw digits.
    fn integer(&self, word: &Word) -> Option<u32> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => whole_number(decimal),
            value => u32::try_from(self.raw(value)?).ok(),
        }
    }

    /// The raw value a parameter reference reads, sign applied.
    fn raw(&self, value: &Value) -> Option<Raw> {
        match value {
            Value::Parameter { negative, index: Some(index), .. } => {
                let raw = self.params.get(*index as usize)?;
                Some(if *negative { -raw } else { raw })
            }
            _ => None,
        }
    }

    fn not_run(&mut self, what: &str, range: TextRange) {
        if !self.reported.iter().any(|done| done == what) {
            self.reported.push(what.to_owned());
            self.finding(range, &format!("the executor does not run {what} yet: the time leaves them out"), false);
        }
    }
}

/// A block's move from `start` to `end`, by the axis words `axes`.
#[derive(Clone, Copy)]
struct Move<'b> {
    block: &'b BlockData,
    range: TextRange,
    axes: &'b [&'b Word],
    start: Position,
    end: Position,
}

/// The plane of two axes in the order I/J measure along them.
fn plane(one: u8, other: u8) -> (u8, u8) {
    match (one, other) {
        (b'X', b'Z') | (b'Z', b'X') => (b'Z', b'X'),
        (b'Z', b'Y') => (b'Y', b'Z'),
        (b'Y', b'X') => (b'X', b'Y'),
        pair => pair,
    }
}

/// A dimensionless literal (a code, L, Q, T): written without a point.
fn whole_number(decimal: &ncc_syntax::Decimal) -> Option<u32> {
    if decimal.has_point() { None } else { u32::try_from(decimal.scaled(0)?).ok() }
}

fn round3(value: f64) -> f64 {
    (value * 1000.0).round() / 1000.0
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use ncc_syntax::{Dialect, Parse};

    use super::{Motion, Trace, run};
    use crate::machine::MachineConfig;

    fn run_text(text: &str) -> Trace {
        run(&Parse::new(text, Dialect::Cnc8x6), &MachineConfig::default(), 1000)
    }

    /// Durations (s) and lengths (mm) of the blocks, rounded to a
    /// microsecond and a micrometre.
    fn timing(trace: &Trace) -> Vec<(f64, f64)> {
        let round = |v: f64| (v * 1e6).round() / 1e6;
        trace.steps.iter().map(|step| (round(step.duration), round(step.length))).collect()
    }

    fn close(actual: f64, expected: f64) {
        assert!((actual - expected).abs() < 1e-9, "{actual} != {expected}");
    }

    #[test]
    fn rapid_and_linear_moves_take_length_over_rate() {
        let trace = run_text("%1\nN1 G00 X100 Y0\nN2 G01 X100 Y100 F600\nN3 X0 Y100 F1.2\nN4 M30\n");
        // Rapid: the longest axis travel over 10,000 mm/min; F600 is mm/min;
        // F1.2 (with a point) is m/min.
        assert_eq!(timing(&trace), [(0.6, 100.0), (10.0, 100.0), (5.0, 100.0), (0.0, 0.0)]);
        assert_eq!(trace.steps[1].feed, Some(600.0));
        assert_eq!(trace.steps[2].feed, Some(1200.0));
        close(trace.total_time(), 15.6);
        close(trace.time_in(Motion::Rapid), 0.6);
        close(trace.length_in(Motion::Feed), 200.0);
        let end = trace.end_position();
        assert_eq!([b'X', b'Y', b'Z'].map(|axis| end[usize::from(axis - b'A')]), [0.0, 100.0, 0.0]);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn feed_per_revolution_follows_the_spindle() {
        // F200 under G95 is 200 µm/rev, F0.5 is 0.5 mm/rev; at S500 that is
        // 100 and 250 mm/min.
        let trace = run_text("%1\nN1 G95 S500 G01 X10 F200\nN2 X20 F0.5\nN3 M30\n");
        assert_eq!(timing(&trace)[..2], [(6.0, 10.0), (2.4, 10.0)]);
        assert_eq!(trace.steps[1].feed, Some(250.0));
    }

    #[test]
    fn incremental_moves_add_to_the_position() {
        let trace = run_text("%1\nN1 G91 G01 X10 Y10 F600\nN2 X10\nN3 G90 X0\nN4 M30\n");
        let x: Vec<f64> = trace.steps.iter().map(|step| step.end[usize::from(b'X' - b'A')]).collect();
        assert_eq!(x, [10.0, 20.0, 0.0, 0.0]);
    }

    #[test]
    fn arcs_run_the_way_their_code_turns() {
        let r = 10.0;
        // From (10,0) about the origin to (0,10): a quarter counter-clockwise,
        // three quarters clockwise; back to the start is a full circle.
        let trace = run_text(
            "%1\nN1 G00 X10 Y0\nN2 G03 X0 Y10 I-10 F600\nN3 G00 X10 Y0\nN4 G02 X0 Y10 I-10\nN5 G00 X10 Y0\nN6 G02 X10 Y0 I-10\nN7 M30\n",
        );
        let lengths: Vec<f64> = trace.steps.iter().map(|step| step.length).collect();
        close(lengths[1], PI * r / 2.0);
        close(lengths[3], 3.0 * PI * r / 2.0);
        close(lengths[5], 2.0 * PI * r);
        close(trace.steps[5].duration, 2.0 * PI * r / 600.0 * 60.0);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn in_the_zx_plane_i_measures_along_z() {
        // The manual's example 7b: from Z500 to Z100 about Z300, radius 200.
        let trace = run_text("%1\nN1 G00 X100 Z500\nN2 G03 G90 X100.0 Z100.0 I-200.0 F1000\nN3 M30\n");
        close(trace.steps[1].length, PI * 200.0);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn a_helix_adds_its_lead() {
        let trace = run_text("%1\nN1 G00 X10 Y0 Z0\nN2 G03 X10 Y0 Z5 I-10 F600\nN3 M30\n");
        close(trace.steps[1].length, ((2.0 * PI * 10.0f64).powi(2) + 25.0).sqrt());
    }

    #[test]
    fn bad_arcs_and_missing_feed_are_reported_where_they_are() {
        let text = "%1\nN1 G01 X10\nN2 G02 X20 Y0 I3 F100\nN3 G02 X5\nN4 M30\n";
        let trace = run_text(text);
        let found: Vec<(&str, &str)> =
            trace.findings.iter().map(|f| (&text[f.range], f.message.split(':').next().unwrap_or(""))).collect();
        assert_eq!(
            found,
            [
                ("N1 G01 X10\n", "no feed F programmed before this motion"),
                ("N2 G02 X20 Y0 I3 F100\n", "the end point does not lie on the circle"),
                ("N3 G02 X5\n", "an arc needs both coordinates of its plane, even when the end point equals the start"),
            ]
        );
        assert!(trace.steps[..3].iter().all(|step| step.duration == 0.0));
    }

    #[test]
    fn dwell_is_q_times_ten_milliseconds() {
        let trace = run_text("%1\nN1 G04 Q150\nN2 M30\n");
        assert_eq!(trace.steps[0].motion, Motion::Dwell);
        close(trace.time_in(Motion::Dwell), 1.5);
    }

    #[test]
    fn a_block_moves_with_the_parameters_from_before_its_assignments() {
        // R1=20000 is 20 mm (thousandths); the block that assigns 50 mm
        // still moves with 20.
        let trace = run_text("%1\nN1 R1=20000\nN2 G01 XR1 F1200\nN3 R1=50000 G01 X-R1\nN4 XR1\nN5 M30\n");
        let x: Vec<f64> = trace.steps.iter().map(|step| step.end[usize::from(b'X' - b'A')]).collect();
        assert_eq!(x, [0.0, 20.0, -20.0, 50.0, 50.0]);
        close(trace.steps[1].duration, 1.0);
    }

    /// The block lines each step ran, in order.
    fn lines_run(text: &str, trace: &Trace) -> Vec<String> {
        trace.steps.iter().map(|step| text[step.range].trim_end().to_owned()).collect()
    }

    #[test]
    fn a_subprogram_runs_q_times_and_returns_after_the_call() {
        let text = "%1\nN1 G71 L7 Q2 F600\nN2 G00 X0\nN3 M30\nN10 G79 L7\nN11 G91 G01 X10\nN12 G90 G70\n*\n";
        let trace = run_text(text);
        assert_eq!(
            lines_run(text, &trace),
            [
                "N1 G71 L7 Q2 F600",
                "N11 G91 G01 X10",
                "N12 G90 G70",
                "N11 G91 G01 X10",
                "N12 G90 G70",
                "N2 G00 X0",
                "N3 M30"
            ]
        );
        // The subprogram's modal G01 and F carry on after it.
        close(trace.time_in(Motion::Feed), 2.0);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    }

    #[test]
    fn a_jump_with_q_runs_the_section_q_plus_one_times() {
        // The manual's example: N26…N54 with `G73 L26 Q3` runs four times.
        let text = "%1\nN25 G91 F600\nN26 G01 X1\nN54 G73 L26 Q3\nN55 M30\n";
        let trace = run_text(text);
        assert_eq!(trace.steps.iter().filter(|step| &text[step.range] == "N26 G01 X1\n").count(), 4);
        assert_eq!(trace.end_position()[usize::from(b'X' - b'A')], 4.0);
        // Nested in a subprogram called twice, the count starts again.
        let text = "%1\nN1 G71 L1 Q2 G91 F600\nN2 M30\nN3 G79 L1\nN4 G01 X1\nN5 G73 L4 Q1\nN6 G70\n";
        assert_eq!(run_text(text).end_position()[usize::from(b'X' - b'A')], 4.0);
    }

    #[test]
    fn dwell_takes_q_and_the_call_runs_once() {
        let text = "%1\nN1 G04 G71 L5 Q200\nN2 M30\nN3 G79 L5\nN4 G01 X1 F60\nN5 G70\n";
        let trace = run_text(text);
        close(trace.time_in(Motion::Dwell), 2.0);
        close(trace.time_in(Motion::Feed), 1.0);
    }

    #[test]
    fn endless_loops_and_missing_targets_stop_the_run_where_they_are() {
        let text = "%1\nN1 G71 L1\nN2 M30\nN3 G79 L1\nN4 G71 L1\nN5 G70\n";
        let trace = run_text(text);
        let fatal: Vec<(&str, &str)> =
            trace.findings.iter().filter(|f| f.fatal).map(|f| (text[f.range].trim_end(), f.message.as_str())).collect();
        assert_eq!(fatal, [("N4 G71 L1", "calls nest deeper than 64: runaway recursion?")]);

        let text = "%1\nN1 G73 L1 Q9999\nN2 M30\n";
        let trace = run(&Parse::new(text, Dialect::Cnc8x6), &MachineConfig::default(), 500);
        assert_eq!(trace.steps.len(), 500);
        assert!(trace.findings[0].message.starts_with("stopped after 500 blocks"), "{:?}", trace.findings);

        for (text, message) in [
            ("%1\nN1 G71 L9\nN2 M30\n", "there is no subprogram L9 (G79 L9) in this file"),
            ("%1\nN1 G73 L5\nN2 M30\nN3 G79 L1\nN5 G70\n", "no block N5 in this program unit to jump to"),
            ("%1\nN1 X1\nN3 G79 L1\nN5 G70\n", "the main body runs into a subprogram: it has no M02 or M30 before it"),
        ] {
            let trace = run_text(text);
            assert_eq!(trace.findings.last().map(|f| f.message.as_str()), Some(message), "{text}");
        }
    }

    #[test]
    fn the_program_ends_at_m30_and_unmodelled_work_is_named_once() {
        let trace = run_text("%1\nN1 G41 X1 F100\nN2 G42 X2\nN3 M30\nN4 G00 X500\n");
        assert_eq!(trace.steps.len(), 3);
        let messages: Vec<&str> = trace.findings.iter().map(|f| f.message.as_str()).collect();
        assert_eq!(messages, ["the executor does not run radius compensation (G41/G42) yet: the time leaves them out"]);
    }

    #[test]
    fn a_rapid_move_lasts_as_long_as_its_slowest_axis() {
        let machine = MachineConfig { rapid_rates: [(b'Z', 5_000)].into(), ..MachineConfig::default() };
        let trace = run(&Parse::new("%1\nN1 G00 X100 Z40\nN2 X0 Z0 Y200\nN3 M30\n", Dialect::Cnc8x6), &machine, 100);
        // N1: X 100 mm at 10000 mm/min is 0.6 s, Z 40 mm at 5000 mm/min 0.48 s;
        // N2: Y 200 mm at 10000 mm/min is 1.2 s.
        close(trace.steps[0].duration, 0.6);
        close(trace.steps[1].duration, 1.2);
        let trace = run(&Parse::new("%1\nN1 G00 X50 Z40\nN2 M30\n", Dialect::Cnc8x6), &machine, 100);
        close(trace.steps[0].duration, 0.48);
    }
}
