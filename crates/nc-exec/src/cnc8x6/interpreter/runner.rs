//! The interpreter: the modal state, motion and time of each block.

use nalgebra::{Point2, Vector2};
use ncc_catalog::{AddressRole, Catalogue, Dialect};
use ncc_syntax::TextRange;
use smallvec::SmallVec;

use crate::{
    arc::{OffCircle, circle_through},
    cnc8x6::arcs,
    cnc8x6::arith::{self, BlockArithmetic, Parameters, Raw},
    cnc8x6::cycles::{self, CycleError, CycleInput, CycleKind, CycleStep, Spindle},
    cnc8x6::dynamics,
    cnc8x6::formats::{self, PlainLiterals},
    cnc8x6::lower::{BlockData, Value, Word},
    cnc8x6::modes::{Group, Modes},
    cnc8x6::program_flow::{self, BlockFlow, block_flow},
    compensation::{CompensationError, Compensator, Element, Settings, Side, ToolElement},
    machine::MachineConfig,
    machine::{OffsetTable, ToolTable},
    transform::{self, Frame, Kind, Recalculation, Refused, Transformation, Transformations},
};

use super::support::*;
use crate::trace::*;

/// What runs after a block: its own flow, or first a fixed cycle's body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Flow {
    Block(BlockFlow),
    /// A fixed cycle's body in the cycle file, after the block's motion;
    /// then the block's own flow.
    Cycle {
        number: u32,
        then: BlockFlow,
    },
}

/// The control's state while a program runs.
#[derive(Clone)]
pub(super) struct Runner {
    catalogue: &'static Catalogue,
    /// The file of the block being run.
    pub(super) source: usize,
    pub(super) machine: std::sync::Arc<MachineConfig>,
    pub(super) modes: Modes,
    /// F as programmed; its unit follows the feed mode in force.
    pub(super) feed: Option<ProgrammedFeed>,
    /// S as programmed: rpm, or the cutting speed under constant cutting
    /// speed (0.1 m/min, or m/min as machine constant 329 selects).
    pub(super) speed: f64,
    /// A fixed cycle's body of the cycle file is running: cycles do not
    /// start in it.
    pub(super) in_cycle: bool,
    /// Radius compensation in force, and its machine constants.
    pub(super) compensator: Option<Compensator>,
    pub(super) compensation: Settings,
    /// Messages of operation 51, with the step of their block.
    pub(super) messages: Vec<OperatorMessage>,
    /// The tool-centre path so far, and the steps compensation ran over.
    pub(super) tool_centre: Vec<ToolElement>,
    pub(super) compensated: Vec<Compensated>,
    /// Machine constant 329 decade 3: G96/G97 swapped (1, 3), S in m/min
    /// (2, 3); read once, as every block asks.
    css_setting: u8,
    /// Machine constant 329 decade 7: the length-compensation mode (0 = A).
    length_setting: u8,
    /// What the address of each machine axis holds (±69999.999), in the
    /// order of the axes, as bounds of the positions (radii on a diameter
    /// axis) with half a µm to spare, outside and under diameter
    /// programming G74; worked out once, as every move asks.
    axis_bounds: [[(f64, f64); MAX_AXES]; 2],
    /// The literals each address A–Z plainly takes, as every word asks.
    plain_literals: [PlainLiterals; 26],
    /// The machine's planes, as every arc and compensated block asks.
    planes: arcs::Planes,
    /// The zero-offset and correction tables, as the program changes them.
    pub(super) offsets: OffsetTable,
    pub(super) corrections: ToolTable,
    /// The envelope velocity's dynamic set, `G23 I1` … `I4`.
    pub(super) dynamic_set: u8,
    /// The zero offset the block writes, which holds in it alone when it
    /// is G58 or G59.
    block_offset: Option<u8>,
    /// The helix's axis and its travel per turn in mm, from G10.
    helix_lead: Option<(u8, f64)>,
    /// The correction entry D and the length-compensation digits `&`.
    pub(super) correction: u8,
    length_digits: u32,
    /// The length correction in force, by letter.
    length_shift: Position,
    /// Mirroring, scale and offset G35–G37, and the transformations
    /// G38/G39/G31.
    pub(super) recalculation: Recalculation,
    pub(super) transformations: Transformations,
    /// Diameter programming G74 (G75: radius): the machine's diameter axis
    /// is written as a diameter, and runs as a radius.
    pub(super) diameter: bool,
    /// The frames the steps ran in; the last is in force.
    pub(super) frames: Vec<Frame>,
    /// The speed limit of constant cutting speed set by `G76 S`, in rpm.
    pub(super) speed_limit: Option<f64>,
    /// The spindle speed constant cutting speed reached last, which S
    /// takes when it ends (01 §6.9.1).
    speed_reached: Option<f64>,
    pub(super) position: Position,
    pub(super) params: Parameters,
    /// The steps not handed on yet.
    pub(super) steps: Undelivered,
    pub(super) findings: Vec<Finding>,
    /// T in force, and every T in order of first use.
    pub(super) tool: Option<u32>,
    pub(super) tools: Vec<Tool>,
    /// Kinds of work already reported as not run.
    pub(super) reported: Vec<String>,
}

impl Runner {
    pub(super) fn new(machine: std::sync::Arc<MachineConfig>) -> Self {
        // The priority block: G01 G17 G90 G94 F0 S0 M05 ….
        Runner {
            catalogue: Dialect::Cnc8x6.catalogue(),
            source: 0,
            modes: Modes::reset(),
            feed: None,
            speed: 0.0,
            speed_limit: None,
            speed_reached: None,
            in_cycle: false,
            css_setting: machine.decade(329, 3),
            length_setting: machine.decade(329, 7),
            axis_bounds: [false, true].map(|diameter| {
                std::array::from_fn(|index| {
                    let Some(&axis) = machine.axes.get(index) else { return (f64::NEG_INFINITY, f64::INFINITY) };
                    let per_unit = if diameter && machine.diameter_axis == Some(axis) { 2.0 } else { 1.0 };
                    match Dialect::Cnc8x6.catalogue().address_of(axis).and_then(|address| address.bounds) {
                        // Exact: halving and doubling lose no bits.
                        Some((min, max)) => ((min - HALF_MICROMETRE) / per_unit, (max + HALF_MICROMETRE) / per_unit),
                        None => (f64::NEG_INFINITY, f64::INFINITY),
                    }
                })
            }),
            plain_literals: std::array::from_fn(|index| {
                PlainLiterals::of(Dialect::Cnc8x6.catalogue().address_of(b'A' + index as u8))
            }),
            planes: arcs::Planes::of(&machine),
            compensator: None,
            compensation: Settings::of(&machine),
            tool_centre: Vec::new(),
            compensated: Vec::new(),
            messages: Vec::new(),
            offsets: machine.offsets.clone(),
            corrections: machine.tools.clone(),
            dynamic_set: 1,
            block_offset: None,
            helix_lead: None,
            correction: 0,
            length_digits: 0,
            length_shift: [0.0; 26],
            recalculation: Recalculation::default(),
            transformations: Transformations::default(),
            diameter: machine.diameter_axis.is_some(),
            frames: vec![Frame::default()],
            position: [0.0; 26],
            params: Parameters::zeroed(),
            steps: Undelivered::default(),
            findings: Vec::new(),
            tool: None,
            tools: Vec::new(),
            reported: Vec::new(),
            machine,
        }
    }

    /// A copy to go on from, without what the run reported so far.
    pub(super) fn for_checkpoint(&self) -> Runner {
        let mut copy = self.clone();
        copy.findings.clear();
        copy.messages.clear();
        copy.tool_centre.clear();
        copy.compensated.clear();
        copy.tools.clear();
        copy
    }

    /// See [`Checkpoint::same_course`].
    pub(super) fn same_course(&self, other: &Runner) -> bool {
        // Every field named, so that a new one must be placed here.
        let Runner {
            catalogue: _,
            source,
            machine,
            modes,
            feed,
            speed,
            in_cycle,
            compensator,
            compensation: _,
            messages: _,
            tool_centre: _,
            compensated: _,
            css_setting: _,
            length_setting: _,
            axis_bounds: _,
            plain_literals: _,
            planes: _,
            offsets,
            corrections,
            dynamic_set,
            // Set anew by every block before it is read.
            block_offset: _,
            helix_lead,
            correction,
            length_digits,
            length_shift,
            recalculation,
            transformations,
            diameter,
            frames,
            speed_limit,
            speed_reached,
            position,
            params,
            steps,
            findings: _,
            tool,
            tools: _,
            reported,
        } = self;
        *source == other.source
            && **machine == *other.machine
            && *modes == other.modes
            && *feed == other.feed
            && *speed == other.speed
            && *in_cycle == other.in_cycle
            && compensator.is_none()
            && other.compensator.is_none()
            && *offsets == other.offsets
            && *corrections == other.corrections
            && *dynamic_set == other.dynamic_set
            && *helix_lead == other.helix_lead
            && *correction == other.correction
            && *length_digits == other.length_digits
            && *length_shift == other.length_shift
            && *recalculation == other.recalculation
            && *transformations == other.transformations
            && *diameter == other.diameter
            && *frames == other.frames
            && *speed_limit == other.speed_limit
            && *speed_reached == other.speed_reached
            && *position == other.position
            && *params == other.params
            && steps.steps.is_empty()
            && other.steps.steps.is_empty()
            && *tool == other.tool
            && *reported == other.reported
    }

    pub(super) fn block(&mut self, block: &BlockData, range: TextRange) -> Flow {
        let at = |local: TextRange| local + range.start();
        let codes: SmallVec<[(u8, u32, TextRange); 8]> = block
            .words
            .iter()
            .filter(|word| matches!(word.letter, b'G' | b'M'))
            .filter_map(|word| Some((word.letter, self.integer(word)?, at(word.range))))
            .collect();
        let has = |letter: u8, number: u32| codes.iter().any(|&(l, n, _)| l == letter && n == number);
        if let Some((refused, message)) = self.refused_value(block, &codes) {
            self.finding(RunRule::ValueRefused, at(refused), &message);
            return Flow::Block(BlockFlow::End);
        }
        for word in &block.words {
            if let Some(Value::Parameter { index: Some(index), .. }) = word.value
                && (index as usize) < arith::PARAMETER_COUNT
                && self.params.get(index as usize).is_none()
            {
                let message = format!(
                    "R{index} holds a value the executor does not know (read from a table or register it does not model yet): words that use it are left out"
                );
                self.report_once(RunRule::ParameterUnknown, &format!("R{index}"), at(word.range), &message);
            }
        }
        let css_before = self.feed_mode().css;
        for &(letter, number, code_range) in &codes {
            self.modes.set(letter, number);
            match (letter, number) {
                // Modes the run reads where they matter; block joining
                // changes nothing before the velocity model.
                (b'G', 0..=4 | 33 | 17..=19 | 23 | 24 | 40..=42 | 53..=59 | 76 | 78 | 80..=93 | 94..=98)
                | (b'M', _) => {}
                // Program flow, which the caller follows, and the
                // arithmetic, which runs after the motion.
                (b'G', 26..=29 | 70..=73 | 79) => {}
                // The helix G09 and its lead G10, which the motion reads.
                (b'G', 9 | 10) => {}
                // Transformations, which the block is about.
                (b'G', 31 | 34..=39) => {}
                // Group G10 also holds the block's own G04/G92/G93, so the
                // programming mode is kept apart from it.
                (b'G', 74) => self.diameter = true,
                (b'G', 75) => self.diameter = false,
                _ => self.not_run(&format!("G{number:02}"), code_range),
            }
        }
        // Technology functions (M, S, T, D) and F keep R383 from merging
        // the block (04 §1.9.4).
        let mut technology = false;
        let mut writes_speed = false;
        let mut axes: SmallVec<[&Word; 8]> = SmallVec::new();
        for word in &block.words {
            let role = self.catalogue.role_of(word.letter);
            technology |= word.letter == b'M'
                || matches!(
                    role,
                    Some(AddressRole::Feed | AddressRole::Speed | AddressRole::Tool | AddressRole::Offset)
                );
            writes_speed |= role == Some(AddressRole::Speed);
            match role {
                Some(AddressRole::Axis) => axes.push(word),
                Some(AddressRole::Feed) => self.feed = self.programmed_feed(word),
                Some(AddressRole::Speed) => match self.count(word) {
                    // `G76 S` limits the speed of constant cutting speed.
                    Some(limit) if has(b'G', 76) => self.speed_limit = Some(limit),
                    Some(speed) => self.speed = speed,
                    None => {}
                },
                Some(AddressRole::Tool) => {
                    if let Some(tool) = self.integer(word) {
                        self.tool = Some(tool);
                        if !self.tools.contains(&Tool::Number(tool)) {
                            self.tools.push(Tool::Number(tool));
                        }
                    }
                }
                Some(AddressRole::Offset) => {
                    if let Some(entry) = self.integer(word).and_then(|entry| u8::try_from(entry).ok()) {
                        self.correction = entry;
                    }
                }
                Some(AddressRole::LengthCompensation) => {
                    if let Some(digits) = self.integer(word) {
                        self.length_digits = digits;
                    }
                }
                _ => {}
            }
        }
        // When constant cutting speed ends, S keeps the speed it reached.
        if css_before && !self.feed_mode().css && !writes_speed {
            self.speed = self.speed_reached.take().unwrap_or(self.speed);
        }
        // A block of group 11 names its axes as the function's parameters:
        // it does not move (03 §3).
        if let Some(&(_, code, code_range)) = codes.iter().find(|&&(l, n, _)| l == b'G' && matches!(n, 31 | 34..=39)) {
            if let Err((message, fatal)) = self.transform(code, &axes, block) {
                let rule = if fatal { RunRule::TransformationRefused } else { RunRule::TransformationIgnored };
                self.finding(rule, code_range, &message);
                if fatal {
                    return Flow::Block(BlockFlow::End);
                }
            }
            axes.clear();
        }
        // The helix lead block `N10 Z1.05 G10` names the axis the helix
        // drives and its travel per turn: it does not move (02 §4).
        if has(b'G', 10) {
            if let Some(word) = axes.first() {
                self.helix_lead = self.number(word).map(|lead| (word.letter, lead));
            }
            axes.clear();
        }
        // G58 and G59 hold in their own block only (01 §5.5).
        self.block_offset = codes
            .iter()
            .find(|&&(letter, number, _)| Group::of(letter, number) == Some(Group::ZERO_OFFSET))
            .and_then(|&(_, number, _)| u8::try_from(number).ok());
        // A new zero offset holds from this block; a new length correction
        // from its first block of linear or rapid motion (02 §1.18.2).
        let motion = self.modes.get(Group::MOTION);
        // `G23 I1` … `I4` selects the envelope velocity's dynamic set (04
        // §2.2); in an arc block I is the centre.
        if has(b'G', 23)
            && !matches!(motion, Some(2 | 3))
            && let Some((set, word)) = block.word(b'I').and_then(|word| Some((self.integer(word)?, word)))
        {
            match u8::try_from(set) {
                Ok(set @ 1..=4) => self.dynamic_set = set,
                _ => self.finding(
                    RunRule::DynamicSetOutOfRange,
                    at(word.range),
                    &format!("G23 I{set}: the dynamic sets are I1 to I4: the set in force stays"),
                ),
            }
        }
        let shifts_length = !axes.is_empty() && matches!(motion, Some(0 | 1));
        self.shift_frame(shifts_length);
        let start = self.position;
        let writes_table = has(b'G', 92) || has(b'G', 93);
        // G04 Q dwells in 10 ms steps (02 §2.1), after the block's motion:
        // the cycles' `G01 ZR31 G04 QR29` drill, then dwell (03 §1).
        let dwell = has(b'G', 4).then(|| Moved {
            motion: Motion::Dwell,
            length: 0.0,
            duration: block.word(b'Q').and_then(|q| self.count(q)).unwrap_or(0.0) * 0.01,
            feed: None,
            path: Path::Straight,
        });
        let still = Moved { motion: Motion::None, length: 0.0, duration: 0.0, feed: None, path: Path::Straight };
        let (moved, dwell) = if writes_table {
            // G92/G93 write the table and move nothing (01 §5.6, §5.7).
            self.write_table(block, has(b'G', 93));
            (still, None)
        } else if axes.is_empty() {
            (dwell.unwrap_or(still), None)
        } else {
            let mut end = self.position;
            for word in &axes {
                if let Some(value) = self.number(word) {
                    let value = self.recalculation.apply(word.letter, value);
                    let written = self.written_per_unit(word.letter);
                    let slot = &mut end[usize::from(word.letter - b'A')];
                    // The control counts positions in whole µm, of the
                    // diameter on a diameter axis.
                    *slot = round3(if self.incremental() { *slot * written + value } else { value }) / written;
                }
            }
            self.position = end;
            let Some(moved) = self.moved(&Move { block, range, axes: &axes, start, end }) else {
                return Flow::Block(BlockFlow::End);
            };
            if let Some(message) = self.unreachable(&self.position) {
                self.finding(RunRule::BeyondAxisRange, range, &message);
                return Flow::Block(BlockFlow::End);
            }
            (moved, dwell)
        };
        let stop = if has(b'M', 0) {
            Some(Stop::Program)
        } else if has(b'M', 1) {
            Some(Stop::Optional)
        } else {
            None
        };
        let path = moved.path;
        let m_functions = codes.iter().filter(|&&(letter, code, _)| letter == b'M' && !matches!(code, 0..=2 | 6 | 30));
        let functions = Functions {
            m_functions: u8::try_from(m_functions.count()).unwrap_or(u8::MAX),
            tool_change: has(b'M', 6),
            mergeable: moved.motion == Motion::Feed && motion == Some(1) && !technology && !self.incremental(),
        };
        let end = self.position;
        self.record(range, &end, moved, stop.filter(|_| dwell.is_none()), functions);
        if let Err(error) = self.compensate(start, path) {
            let range = self.steps.get(error.block()).range;
            self.finding(RunRule::CompensationFailed, range, &format!("radius compensation: {error}"));
            return Flow::Block(BlockFlow::End);
        }
        if let Some(dwell) = dwell {
            self.record(range, &end, dwell, stop, Functions::default());
        }
        // Assignments and arithmetic take effect after the block's motion.
        arith::assign(block, &mut self.params);
        let mut machine = ProgramMachine {
            machine: &self.machine,
            position: &self.position,
            frame: &self.frames[self.frames.len() - 1],
            offsets: &mut self.offsets,
            corrections: &mut self.corrections,
            messages: &mut self.messages,
            step: self.steps.next() - 1,
            registers: Registers {
                modes: &self.modes,
                speed: self.speed,
                tool: self.tool,
                correction: self.correction,
            },
        };
        match arith::compute(block, &mut self.params, &mut machine, &self.machine) {
            BlockArithmetic::None | BlockArithmetic::Ran { result: Ok(()), .. } => {}
            BlockArithmetic::UnknownWord => {
                let message =
                    "a control word in R5–R8 has no value: it was computed from a value the executor does not know";
                self.finding(RunRule::ControlWordUnknown, range, message);
                return Flow::Block(BlockFlow::End);
            }
            BlockArithmetic::Ran { function, result: Err(error), .. } => {
                self.finding(RunRule::ArithmeticFailed, at(function), &format!("parameter arithmetic failed: {error}"));
                return Flow::Block(BlockFlow::End);
            }
        }
        // The active fixed cycle runs after the block's motion, in every
        // block until G80 (03 §1.4), but not inside its own body.
        let cycle = self.modes.get(Group::CYCLE).filter(|&number| (81..=89).contains(&number));
        if let Some(number) = cycle.filter(|_| !self.in_cycle) {
            if self.machine.cycle_file.is_some() {
                return Flow::Cycle { number, then: self.flow_of(block, has) };
            }
            if !self.built_in_cycle_or_stop(number, range) {
                return Flow::Block(BlockFlow::End);
            }
        }
        Flow::Block(self.flow_of(block, has))
    }

    /// The first value of the block the control refuses, with its range in
    /// the block: a literal or an assignment outside its address's format,
    /// or a parameter whose value the address cannot take (02 §3.6: the
    /// control checks them only as the block runs). `codes` are the
    /// block's G and M codes.
    fn refused_value(&self, block: &BlockData, codes: &[(u8, u32, TextRange)]) -> Option<(TextRange, String)> {
        let motion = codes
            .iter()
            .rev()
            .find(|&&(letter, number, _)| Group::modal_of(letter, number) == Some(Group::MOTION))
            .map_or(self.modes.get(Group::MOTION), |&(_, number, _)| Some(number));
        let thread = motion == Some(33);
        let machine = &*self.machine;
        for word in &block.words {
            if let Some(Value::Literal(decimal)) = &word.value
                && let Some(plain) = self.plain_literals.get(usize::from(word.letter.wrapping_sub(b'A')))
                && plain.take(decimal)
            {
                continue;
            }
            if let Some(Value::Parameter { index: Some(index), index_range, .. }) = &word.value
                && let Some(fault) = formats::parameter_number_fault(*index)
            {
                return Some((*index_range, fault.message));
            }
            let Some(address) = self.catalogue.address_of(word.letter) else { continue };
            let fault = match word.value.as_ref() {
                Some(Value::Literal(decimal)) => formats::literal_fault(address, decimal, machine),
                Some(value) => {
                    self.raw(value).and_then(|raw| formats::substitution_fault(address, raw, thread, machine))
                }
                None => None,
            };
            if let Some(fault) = fault {
                return Some((word.value_range.unwrap_or(word.range), fault.message));
            }
        }
        block.assignments.iter().find_map(|assignment| {
            if let Some(fault) = assignment.index.and_then(formats::parameter_number_fault) {
                return Some((assignment.index_range, fault.message));
            }
            let Some(Value::Literal(value)) = &assignment.value else { return None };
            let letter = self.catalogue.letter_with_role(AddressRole::Parameter)?;
            let fault = formats::assignment_fault(self.catalogue.address_of(letter)?, value)?;
            Some((assignment.value_range.unwrap_or(assignment.range), fault.message))
        })
    }

    /// What follows the block once its work is done ([`block_flow`]).
    fn flow_of(&self, block: &BlockData, has: impl Fn(u8, u32) -> bool) -> BlockFlow {
        block_flow(block, has, |word| self.integer(word))
    }

    /// Runs a block of group 11 with its axis words `axes`; the error says
    /// why the control refuses it, and whether it stops the program there.
    pub(super) fn transform(&mut self, code: u32, axes: &[&Word], block: &BlockData) -> Result<(), (String, bool)> {
        let values: Vec<(u8, f64)> = axes.iter().filter_map(|w| Some((w.letter, self.number(w)?))).collect();
        let Some(kind) = Kind::of(code) else {
            match code {
                34 => self.recalculation = Recalculation::default(),
                35 => self.recalculation.mirror(axes.iter().map(|word| word.letter)),
                36 => {
                    let factors: Vec<f64> = values.iter().map(|&(_, value)| value).collect();
                    self.recalculation.set_scale(&factors).ok_or_else(|| {
                        ("G36 with a scale of 0 or a zero denominator: the control refuses it".to_owned(), true)
                    })?;
                }
                _ => self.recalculation.set_shift(values),
            }
            return Ok(());
        };
        let refused = |refused: Refused| {
            let fatal = refused != Refused::NotSet;
            let then = if fatal { "the control stops" } else { "the run goes on without it" };
            (format!("G{code}: {refused}: {then}"), fatal)
        };
        let angle = |letter: u8| block.word(letter).and_then(|word| self.number(word));
        if axes.is_empty() {
            // Alone it activates; with `I0` it cancels (000:6701–6740).
            return match angle(b'I') {
                None => self.transformations.activate(kind).map_err(refused),
                Some(0.0) => {
                    self.transformations.deactivate(kind);
                    Ok(())
                }
                Some(_) => Err((format!("G{code} with I but no axes neither sets, activates nor cancels it"), true)),
            };
        }
        // E divides the angles, for finer steps than 0.001° (000:6674–6678).
        let divisor = block.word(b'E').and_then(|word| self.number(word)).unwrap_or(1.0);
        if divisor <= 0.0 {
            return Err((format!("G{code}: the angle divisor E must be positive"), true));
        }
        let letters: &[u8] = if kind == Kind::Spatial { b"IJK" } else { b"I" };
        let mut angles = [0.0; 3];
        for (angle_of, &letter) in angles.iter_mut().zip(letters) {
            *angle_of = angle(letter).ok_or_else(|| {
                (format!("G{code} sets its parameters with {}: it is missing", char::from(letter)), true)
            })? / divisor;
        }
        self.transformations.set(kind, Transformation::new(&values, angles)).map_err(refused)
    }

    /// Takes the zero offset in force, G37, the length correction when
    /// `with_length` (a block of linear or rapid motion) and the active
    /// transformations into the frame from program to machine coordinates.
    /// The tool stays where it is, so its program position moves.
    fn shift_frame(&mut self, with_length: bool) {
        if with_length {
            self.length_shift = self.length_correction();
        }
        let axes = &self.machine.axes;
        let frame = self.frame_in_force();
        let current = self.frame();
        if frame == *current {
            return;
        }
        let position = self.machine_axes(&self.position);
        let program: Axes = if frame.transformations == current.transformations {
            // A translation alone moves the program position exactly.
            std::array::from_fn(|i| position[i] - (frame.translation[i] - current.translation[i]))
        } else {
            // The control recomputes the position in whole µm (000:6248–6252).
            frame.to_program(&current.to_machine(&position, axes), axes).map(round3)
        };
        for (&axis, value) in axes.iter().zip(program) {
            self.position[slot(axis)] = value;
        }
        self.frames.push(frame);
    }

    /// The frame the zero offset, G37, the length correction and the
    /// transformations in force make.
    pub(super) fn frame_in_force(&self) -> Frame {
        let offset = self.offsets.offset(self.zero_offset_row());
        let mut translation = [0.0; MAX_AXES];
        for ((value, &axis), &offset) in translation.iter_mut().zip(&self.machine.axes).zip(&offset) {
            let letter = slot(axis);
            *value = self.length_shift[letter] + f64::from(offset) / 1000.0 + self.recalculation.shift[letter];
        }
        Frame { translation, transformations: self.transformations.active() }
    }

    /// The frame the tool's program position is in.
    pub(super) fn frame(&self) -> &Frame {
        &self.frames[self.frames.len() - 1]
    }

    /// The length correction `&` and `D` select: mode A (machine constant
    /// 329 decade 7 = 0) adds (1) or subtracts (2) entry D's length per
    /// digit of `&` for axes 1–4; otherwise D alone applies the entry's
    /// lengths to every axis (mode B; mode C's switch is read as B).
    fn length_correction(&self) -> Position {
        let mut shift = [0.0; 26];
        if self.correction == 0 {
            return shift;
        }
        let entry = self.corrections.entry(self.correction);
        let mode_a = self.length_setting == 0;
        for (index, (&axis, &length)) in self.machine.axes.iter().zip(&entry.lengths).enumerate() {
            let sign = if mode_a {
                // `&k1k2k3k4`, right-aligned: k1 is the thousands digit.
                let digit = (index < 4).then(|| self.length_digits / 10u32.pow(3 - index as u32) % 10);
                match digit {
                    Some(1) => 1.0,
                    Some(2) => -1.0,
                    _ => 0.0,
                }
            } else {
                1.0
            };
            shift[slot(axis)] = sign * f64::from(length) / 1000.0;
        }
        shift
    }

    /// G92 writes the programmed values into the zero-offset row of the
    /// block's G5 code (or the one in force), or with D the R0–R4 of the
    /// block into that correction entry; G93 sets the row so that the
    /// programmed values become the tool's position (01 §5.6–5.7, 02 §1.4).
    pub(super) fn write_table(&mut self, block: &BlockData, relative_to_tool: bool) {
        if !relative_to_tool
            && block.words.iter().any(|w| self.catalogue.role_of(w.letter) == Some(AddressRole::Offset))
        {
            let mut entry = self.corrections.entry(self.correction);
            for assignment in &block.assignments {
                let (Some(index), Some(Value::Literal(value))) = (assignment.index, &assignment.value) else {
                    continue;
                };
                let Some(raw) = arith::literal_raw(value).and_then(|raw| i32::try_from(raw).ok()) else { continue };
                // R0 is the radius (column 1), R1–R4 the lengths of axes 1–4.
                if index <= 4
                    && let Some(datum) = datum(&mut entry, index as usize + 1)
                {
                    *datum = raw;
                }
            }
            self.corrections.entries.insert(self.correction, entry);
            return;
        }
        let row = self.zero_offset_row();
        let mut values = self.offsets.offset(row);
        for word in block.words.iter().filter(|w| self.catalogue.role_of(w.letter) == Some(AddressRole::Axis)) {
            let (Some(index), Some(value)) =
                (self.machine.axes.iter().position(|&axis| axis == word.letter), self.number(word))
            else {
                continue;
            };
            let value = (value * 1000.0).round() as i32;
            values[index] = if relative_to_tool {
                let at = (self.position[slot(word.letter)] * 1000.0).round() as i32;
                values[index] + at - value
            } else {
                value
            };
        }
        self.offsets.rows.insert(row, values);
    }

    /// Follows the last step with radius compensation G41/G42 (02 §1.6–1.9):
    /// starts it on a line, passes each move in the plane to the
    /// [`Compensator`], cancels it on G40, and puts the tool-centre path's
    /// length and time on the steps it belongs to, one block late as the
    /// control's look-ahead fixes them.
    fn compensate(&mut self, start: Position, path: Path) -> Result<(), CompensationError> {
        let index = self.steps.next() - 1;
        let code = self.modes.get(Group::PLANE).unwrap_or_default();
        let Some([first, second]) = self.planes.compensation(code) else {
            if self.modes.get(Group::COMPENSATION).is_some_and(|code| code != 40) {
                let range = self.steps.get(index).range;
                let message = format!(
                    "radius compensation in the plane of G{code}, which this machine does not have (machine constants R340, R341): the run leaves the compensation out"
                );
                self.report_once(RunRule::NotRunYet, "compensation plane", range, &message);
            }
            return Ok(());
        };
        let plane = (first, second);
        // Mirrored in one axis of the plane, the tool changes side.
        let flipped = self.recalculation.flips(plane);
        let side = match self.modes.get(Group::COMPENSATION) {
            Some(41) => Some(if flipped { Side::Right } else { Side::Left }),
            Some(42) => Some(if flipped { Side::Left } else { Side::Right }),
            _ => None,
        };
        let (a, b) = (slot(plane.0), slot(plane.1));
        let point = |position: &Position| Point2::new(position[a], position[b]);
        let (from, to) = (point(&start), point(&self.position));
        let moves_in_plane = from != to || matches!(path, Path::Arc { .. });
        let linear = matches!(self.steps.get(index).motion, Motion::Rapid | Motion::Feed) && path == Path::Straight;
        let pieces = match (self.compensator.take(), side) {
            (None, Some(side)) if moves_in_plane && linear => {
                let radius = f64::from(self.corrections.entry(self.correction).radius) / 1000.0;
                self.compensator = Some(Compensator::start(self.compensation, side, radius, index, from, to));
                self.compensated.push(Compensated { steps: index..index + 1, plane });
                return Ok(());
            }
            (Some(compensator), None) if moves_in_plane => compensator.cancel(index, to),
            (Some(mut compensator), _) => {
                let element = match path {
                    Path::Arc { centre, clockwise, .. } => {
                        Element::Arc { from, to, centre: Point2::new(centre[0], centre[1]), clockwise }
                    }
                    _ => Element::Line { from, to },
                };
                let pushed = if moves_in_plane { compensator.push(index, element) } else { Ok(Vec::new()) };
                // Kept on an error too, so that the run's end fixes the
                // element before the block the control stops at.
                self.compensator = Some(compensator);
                pushed?
            }
            (None, _) => return Ok(()),
        };
        // Compensation was in force when the block came.
        if let Some(compensated) = self.compensated.last_mut() {
            compensated.steps.end = index + 1;
        }
        self.charge(pieces);
        Ok(())
    }

    /// Ends radius compensation still in force where the run ends: the
    /// tool centre stays on the normal at the last programmed point
    /// ([`Compensator::finish`]), and the last element's length and time
    /// are those of its path there.
    pub(super) fn finish_compensation(&mut self) {
        if let Some(compensator) = self.compensator.take() {
            self.charge(vec![compensator.finish()]);
        }
    }

    /// Puts the length and time of the tool-centre path's `pieces` on the
    /// steps they belong to, in place of the programmed ones.
    fn charge(&mut self, pieces: Vec<ToolElement>) {
        let Some(&Compensated { plane, .. }) = self.compensated.last() else { return };
        let (a, b) = (slot(plane.0), slot(plane.1));
        for piece in pieces {
            let length = piece.path.length();
            let step = self.steps.get(piece.block);
            let duration = match (step.motion, step.feed) {
                (Motion::Feed, Some(feed)) => length / (feed * piece.feed_scale) * 60.0,
                _ => {
                    let in_plane = |point: Point2<f64>| {
                        let mut position = [0.0; 26];
                        (position[a], position[b]) = (point.x, point.y);
                        position
                    };
                    self.rapid_seconds(&in_plane(piece.path.start()), &in_plane(piece.path.end()))
                }
            };
            // Pieces come in the order of their blocks, a block's over
            // one or two calls (its corner, then its contour): its first
            // one replaces the programmed length and time.
            let first = self.tool_centre.last().is_none_or(|last| last.block != piece.block);
            let step = self.steps.get_mut(piece.block);
            if first {
                (step.length, step.duration) = (0.0, 0.0);
            }
            step.length += length;
            step.duration += duration;
            self.tool_centre.push(piece);
        }
    }

    /// Adds a step of the block at `range` that ends at `end`. Its start
    /// time follows from the durations when the run ends.
    /// Records a step; `functions` are its M functions and tool change.
    fn record(&mut self, range: TextRange, end: &Position, moved: Moved, stop: Option<Stop>, functions: Functions) {
        let Functions { m_functions, tool_change, mergeable } = functions;
        let Moved { motion, length, duration, feed, path } = moved;
        let (source, end, frame) = (self.source, self.machine_axes(end), self.frames.len() - 1);
        debug_assert!(
            [length, duration, feed.unwrap_or(0.0)].iter().chain(&end).all(|value| value.is_finite()),
            "no NaN or infinity leaves the executor: {end:?} {length} {duration} {feed:?}"
        );
        let path_mode = dynamics::path_mode(self.modes.get(Group::JOINING));
        let step = Step {
            source,
            range,
            motion,
            path,
            duration,
            length,
            feed,
            end,
            frame,
            stop,
            path_mode,
            m_functions,
            tool_change,
            dynamic_set: self.dynamic_set,
            mergeable,
            // The CNC8x6 model follows no spindle run-up and no jerk limit
            // (the envelope's sets have their own), and joins corners by
            // R39, not by a tolerance.
            jerk_limited: false,
            spindle: [0.0; 2],
            corner_tolerance: f32::INFINITY,
        };
        self.steps.push(step);
    }

    /// Hands `sink` the steps no later block can change: all at the `end`,
    /// else those before the first one radius compensation may still fix.
    pub(super) fn deliver(&mut self, sink: &mut dyn StepSink, end: bool) {
        let open = self.compensator.as_ref().filter(|_| !end).map(Compensator::open_block);
        self.steps.deliver(sink, open, &self.frames, &self.compensated, &mut self.tool_centre);
    }

    /// A position by letter over the machine's axes, as steps keep it.
    fn machine_axes(&self, position: &Position) -> Axes {
        transform::over_axes(position, &self.machine.axes)
    }

    /// The row of the zero-offset table in force (G53–G59): the block's
    /// own, else the modal one.
    fn zero_offset_row(&self) -> u8 {
        self.block_offset
            .or_else(|| self.modes.get(Group::ZERO_OFFSET).and_then(|code| u8::try_from(code).ok()))
            .unwrap_or(53)
    }

    /// Runs a built-in cycle; `false` after reporting why it cannot run.
    pub(super) fn built_in_cycle_or_stop(&mut self, number: u32, range: TextRange) -> bool {
        let result = self.built_in_cycle(number, range);
        if let Err(message) = &result {
            self.finding(RunRule::CycleFailed, range, message);
        }
        result.is_ok()
    }

    /// How many units the program writes per mm the axis `letter` moves:
    /// 2 on the diameter axis under diameter programming, else 1.
    fn written_per_unit(&self, letter: u8) -> f64 {
        if self.diameter && self.machine.diameter_axis == Some(letter) { 2.0 } else { 1.0 }
    }

    /// Runs one pass of a built-in fixed cycle from where the block ended
    /// and times its moves as steps of the block. Its F, S and spindle
    /// changes stay inside it (03 §1.4 I6). The error says why the
    /// control stops.
    fn built_in_cycle(&mut self, number: u32, range: TextRange) -> Result<(), String> {
        let spindle = match self.modes.get(Group::SPINDLE) {
            Some(3) => Spindle::Clockwise,
            Some(4) => Spindle::CounterClockwise,
            Some(19) => Spindle::Oriented,
            _ => Spindle::Stopped,
        };
        // The cycles compute in the values as written (diameters under G74).
        let written = self.machine.diameter_axis.map(|axis| (slot(axis), self.written_per_unit(axis)));
        let scaled = |position: &Position, by: fn(f64, f64) -> f64| {
            let mut position = *position;
            if let Some((slot, factor)) = written {
                position[slot] = by(position[slot], factor);
            }
            position
        };
        let input = CycleInput {
            number,
            kind: CycleKind::of(self.machine.cycle_file.as_deref()),
            params: &self.params,
            position: scaled(&self.position, |value, factor| value * factor),
            incremental: self.incremental(),
            per_revolution: self.feed_mode().per_revolution,
            speed: self.speed,
            spindle,
            diameter: self.diameter,
        };
        let cycle = cycles::expand(&input)
            .map_err(|error: CycleError| format!("the fixed cycle G{number} cannot run: {error}"))?;
        let physical = |position: &Position| scaled(position, |value, factor| value / factor);
        let mut at = physical(&cycle.start);
        for step in &cycle.steps {
            let to = step.to().map_or(at, physical);
            if let Some(message) = self.unreachable(&to) {
                return Err(format!("the fixed cycle G{number}: {message}"));
            }
            let length = distance(&at, &to);
            let (motion, duration, feed, path) = match *step {
                CycleStep::Rapid { .. } => (Motion::Rapid, self.rapid_seconds(&at, &to), None, Path::Straight),
                CycleStep::Feed { .. } => {
                    let rate = step.feed_rate().map(|rate| rate * self.feed_factor()).filter(|&rate| rate > 0.0);
                    (Motion::Feed, rate.map_or(0.0, |rate| length / rate * 60.0), rate, Path::Straight)
                }
                CycleStep::Thread { thread, .. } => {
                    let minutes = thread_minutes(length, thread.lead, thread.speed);
                    let path = Path::Thread { lead: thread.lead, speed: thread.speed };
                    (Motion::Feed, minutes * 60.0, Some(length / minutes), path)
                }
                CycleStep::Dwell { seconds } => (Motion::Dwell, seconds, None, Path::Straight),
                CycleStep::Spindle { .. } => continue,
            };
            self.record(range, &to, Moved { motion, length, duration, feed, path }, None, Functions::default());
            at = to;
        }
        self.position = physical(&cycle.end());
        Ok(())
    }

    /// Seconds a rapid move takes: every real axis runs at its own rate,
    /// and the slowest to arrive sets the time.
    fn rapid_seconds(&self, start: &Position, end: &Position) -> f64 {
        let mut delta: Position = std::array::from_fn(|slot| end[slot] - start[slot]);
        self.frame().real_displacement(&mut delta);
        let minutes = (b'A'..=b'Z')
            .map(|letter| delta[slot(letter)].abs() / f64::from(self.machine.axis_rapid_rate(letter)))
            .fold(0.0, f64::max);
        minutes * 60.0
    }

    /// What a cycle of the cycle file keeps of the state before it: all of
    /// it, restored when the cycle's body returns (03 §1.4 I6).
    pub(super) fn snapshot(&self) -> Snapshot {
        Snapshot {
            modes: self.modes,
            feed: self.feed,
            speed: self.speed,
            speed_limit: self.speed_limit,
            diameter: self.diameter,
            params: self.params.clone(),
        }
    }

    /// Back to the state before a cycle, where the cycle left the tool.
    pub(super) fn restore(&mut self, snapshot: Snapshot) {
        Snapshot {
            modes: self.modes,
            feed: self.feed,
            speed: self.speed,
            speed_limit: self.speed_limit,
            diameter: self.diameter,
            params: self.params,
        } = snapshot;
        self.in_cycle = false;
    }

    pub(super) fn finding(&mut self, rule: RunRule, range: TextRange, message: &str) {
        self.findings.push(Finding { rule, source: self.source, range, message: message.to_owned() });
    }

    /// Length, duration and feed of a block's move; `None` after
    /// reporting an error the control stops on.
    pub(super) fn moved(&mut self, step: &Move<'_>) -> Option<Moved> {
        let (range, start, end) = (step.range, step.start, step.end);
        let straight = distance(&start, &end);
        let motion = self.modes.get(Group::MOTION);
        let moved = |motion, length, duration, feed, path| Some(Moved { motion, length, duration, feed, path });
        if motion == Some(0) {
            return moved(Motion::Rapid, straight, self.rapid_seconds(&start, &end), None, Path::Straight);
        }
        let arc = match motion {
            Some(2 | 3) => match self.arc(step, motion == Some(3)) {
                Ok(Some(arc)) => Some(arc),
                Ok(None) => return moved(Motion::Feed, straight, 0.0, None, Path::Straight),
                Err(()) => return None,
            },
            _ => None,
        };
        // The arc's sides may reach beyond a limit its ends keep within.
        if let Some(message) = arc.iter().flat_map(|arc| arc.sides(&end)).find_map(|side| self.unreachable(&side)) {
            self.finding(RunRule::BeyondAxisRange, range, &format!("the arc's side: {message}"));
            return None;
        }
        let length = arc.as_ref().map_or(straight, Arc::length);
        let mode = self.feed_mode();
        // A thread's F is its lead, which M37 leaves alone.
        let feed = match motion {
            Some(33) => self.feed.map(|feed| feed.value(true)),
            _ => self.feed.map(|feed| feed.value(mode.per_revolution) * self.feed_factor()),
        };
        // Minutes, and the path feed in mm/min (the average where it varies).
        let timed = |minutes: f64| (minutes, length / minutes);
        let minutes = match (feed.filter(|&feed| feed > 0.0), mode) {
            (Some(lead), _) if motion == Some(33) => {
                (self.speed > 0.0).then(|| timed(thread_minutes(length, lead, self.speed)))
            }
            (Some(feed), FeedMode { per_revolution: false, .. }) => Some((length / feed, feed)),
            (Some(feed), FeedMode { per_revolution: true, css: false }) => {
                let rate = feed * self.speed;
                (rate > 0.0).then(|| (length / rate, rate))
            }
            (Some(feed), FeedMode { per_revolution: true, css: true }) => {
                self.css_minutes(step, arc.as_ref(), length, feed).map(timed)
            }
            (None, _) => None,
        };
        let path = match (&arc, feed) {
            (Some(arc), _) => Path::Arc {
                plane: (arc.plane.0 as u8 + b'A', arc.plane.1 as u8 + b'A'),
                centre: [arc.centre.x, arc.centre.y],
                clockwise: arc.sweep < 0.0,
            },
            (None, Some(lead)) if motion == Some(33) => Path::Thread { lead, speed: self.speed },
            _ => Path::Straight,
        };
        match minutes {
            Some((minutes, rate)) => moved(Motion::Feed, length, minutes * 60.0, Some(rate), path),
            None => {
                let why = match mode {
                    _ if feed.is_none_or(|feed| feed <= 0.0) => {
                        "no feed F programmed before this motion: G01–G03 need one"
                    }
                    _ if motion == Some(33) => "a thread (G33) with spindle speed S0: the axes cannot move",
                    FeedMode { css: true, .. } => {
                        "feed per revolution under constant cutting speed with cutting speed S0: the axes cannot move"
                    }
                    _ => "feed per revolution (G95) with spindle speed S0: the axes cannot move",
                };
                self.finding(RunRule::MotionWithoutFeed, range, why);
                moved(Motion::Feed, length, 0.0, None, path)
            }
        }
    }

    /// Feed units and constant cutting speed from group G6, with the swap
    /// of G96/G97 that machine constant 329 decade 3 selects (01 §6.9).
    fn feed_mode(&self) -> FeedMode {
        let swapped = matches!(self.css_setting, 1 | 3);
        match self.modes.get(Group::FEED_UNITS) {
            Some(95) => FeedMode { per_revolution: true, css: false },
            Some(96) => FeedMode { per_revolution: swapped, css: true },
            Some(97) => FeedMode { per_revolution: !swapped, css: true },
            _ => FeedMode { per_revolution: false, css: false },
        }
    }

    /// What the feed is multiplied by: M37 reduces it 1 : 100, M36 (the
    /// reset state) runs it as programmed (01 §6.6).
    fn feed_factor(&self) -> f64 {
        if self.modes.get(Group::FEED_REDUCTION) == Some(37) { 0.01 } else { 1.0 }
    }

    /// Why the control cannot move to `position` (program coordinates in
    /// the frame in force): an axis beyond what its address holds, or
    /// beyond its travel limits in machine coordinates, where the
    /// software limit switches work (03 §3.2).
    pub(super) fn unreachable(&self, position: &Position) -> Option<String> {
        let axes = &self.machine.axes;
        let bounds = &self.axis_bounds[usize::from(self.diameter)];
        let beyond =
            axes.iter().zip(bounds).find(|&(&axis, &(low, high))| !(low..=high).contains(&position[slot(axis)]));
        if let Some((&axis, _)) = beyond {
            let letter = char::from(axis);
            // On a diameter axis the program holds the diameter.
            let written = position[slot(axis)] * self.written_per_unit(axis);
            let (min, max) = self.catalogue.address_of(axis).and_then(|address| address.bounds).unwrap_or_default();
            return Some(format!(
                "{letter} would reach {written:.3}, outside the range of `{letter}`: {min:.3} to {max:.3}: the control stops"
            ));
        }
        if self.machine.limits.is_empty() {
            return None;
        }
        let machine = self.frame().to_machine(&self.machine_axes(position), axes);
        for (&axis, &real) in axes.iter().zip(&machine) {
            let letter = char::from(axis);
            let limits = self.machine.limits.get(&axis).copied().unwrap_or_default();
            if let Some(limit) = limits.passed_by(round3(real)) {
                return Some(format!(
                    "{letter} would reach {real:.3} in machine coordinates, beyond its travel limit {limit:.3} (`limits` of the machine): the control stops at the software limit switch"
                ));
            }
        }
        None
    }

    pub(super) fn incremental(&self) -> bool {
        self.modes.get(Group::DIMENSIONS) == Some(91)
    }

    /// Minutes a move takes with feed per revolution under constant cutting
    /// speed: the spindle turns at v / (2π r), r the distance of the
    /// controlling coordinate from the spindle axis, up to the `G76` limit
    /// (else 9999 rpm, the largest S); `None` when the cutting speed is 0.
    fn css_minutes(&mut self, step: &Move<'_>, arc: Option<&Arc>, length: f64, feed: f64) -> Option<f64> {
        // S in 0.1 m/min, or in m/min (decade 3 = 2 or 3); as mm/min.
        let per_unit = if matches!(self.css_setting, 2 | 3) { 1000.0 } else { 100.0 };
        let cutting_speed = self.speed * per_unit;
        if cutting_speed <= 0.0 {
            return None;
        }
        let limit = self.speed_limit.unwrap_or(MAX_SPINDLE_SPEED).min(MAX_SPINDLE_SPEED);
        // Machine constant 67 names the controlling coordinate by a code
        // the manual does not give; the run reads 1–6 as the axis number
        // and takes axis 1 otherwise.
        let axis = usize::try_from(self.machine.constant(67)).ok().filter(|n| (1..=6).contains(n)).unwrap_or(1);
        let letter = self.machine.axes.get(axis - 1).or(self.machine.axes.first()).copied().unwrap_or(b'X');
        let slot = slot(letter);
        let coordinate = |t: f64| {
            let straight = step.start[slot] + t * (step.end[slot] - step.start[slot]);
            arc.and_then(|arc| arc.coordinate(slot, t)).unwrap_or(straight)
        };
        let rpm = |t: f64| (cutting_speed / (std::f64::consts::TAU * coordinate(t).abs())).min(limit);
        self.speed_reached = Some(rpm(1.0));
        // Composite Simpson over the move: smooth except where the limit
        // sets in, where 512 intervals keep the error far below a µs.
        const INTERVALS: usize = 512;
        let h = 1.0 / INTERVALS as f64;
        let per_mm = |t: f64| 1.0 / (feed * rpm(t));
        let sum: f64 = (0..=INTERVALS)
            .map(|i| {
                let weight = if i == 0 || i == INTERVALS {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                weight * per_mm(i as f64 * h)
            })
            .sum();
        Some(length * sum * h / 3.0)
    }

    /// The arc of a G02/G03 block, or `None` after reporting why the block
    /// is not one; the error after reporting an end point the control
    /// stops on. Under a helix the axis of its lead turns with the arc.
    pub(super) fn arc(&mut self, step: &Move<'_>, counter_clockwise: bool) -> Result<Option<Arc>, ()> {
        let Move { block, range, axes, start, end } = *step;
        let helix = self.helix_lead.filter(|_| self.modes.get(Group::JOINING) == Some(9));
        // Under a helix a word for its axis is not a coordinate of the arc.
        let mut letters: Vec<u8> = axes
            .iter()
            .map(|word| word.letter)
            .filter(|&letter| helix.is_none_or(|(axis, _)| axis != letter))
            .collect();
        letters.dedup();
        if letters.len() < 2 {
            let message = "an arc needs both coordinates of its plane, even when the end point equals the start";
            self.finding(RunRule::ArcPlaneIncomplete, range, message);
            return Ok(None);
        }
        // The machine's interpolation plane of the two axes: I measures
        // along its first axis. A pair the machine has no plane of runs in
        // the order written.
        let [first, second] = self.planes.arc(letters[0], letters[1]).unwrap_or([letters[0], letters[1]]);
        let (a, b) = (usize::from(first - b'A'), usize::from(second - b'A'));
        // I and J are recalculated as the axes they measure along, and an
        // arc mirrored in one of its axes turns the other way.
        let centre_offset = |letter: u8, axis: u8| {
            let value = block.word(letter).and_then(|word| self.number(word)).unwrap_or(0.0);
            self.recalculation.apply(axis, value)
        };
        let counter_clockwise = counter_clockwise != self.recalculation.flips((first, second));
        let (from, to) = ([start[a], start[b]], [end[a], end[b]]);
        let mut offsets = [centre_offset(b'I', first), centre_offset(b'J', second)];
        // The preprocessor's refinement E of I or J, in thousandths of a µm;
        // the checker reports one the control cannot apply.
        let refinement = block.word(b'E').and_then(|word| self.number(word)).map(|mm| (mm * 1000.0).round() as i64);
        if let Some(Ok(arcs::Refinement { word, amount })) = refinement.map(arcs::refinement) {
            offsets[word] += self.recalculation.apply([first, second][word], amount as f64 / 1e6);
        }
        let centre = [from[0] + offsets[0], from[1] + offsets[1]];
        let tolerance = self.machine.arc_tolerance();
        let circle = match circle_through(from, to, centre, counter_clockwise, tolerance) {
            Ok(circle) => circle,
            Err(OffCircle { start_radius, end_radius }) => {
                let message = format!(
                    "the end point does not lie on the circle: {} mm from the centre, the start {} mm, more than the tolerance {tolerance} mm apart: the control stops with error 7.56",
                    round3(end_radius),
                    round3(start_radius)
                );
                self.finding(RunRule::ArcOffCircle, range, &message);
                return Err(());
            }
        };
        let sweep = circle.sweep;
        // A third axis written in the block moves along with the arc; the
        // helix's axis travels its lead per full turn, whichever way the
        // arc turns (02 §4).
        let mut lead: f64 =
            letters[2..].iter().map(|&l| (end[usize::from(l - b'A')] - start[usize::from(l - b'A')]).powi(2)).sum();
        if let Some((axis, per_turn)) = helix.filter(|&(axis, _)| axis != first && axis != second) {
            let travel = per_turn * sweep.abs() / std::f64::consts::TAU;
            self.position[slot(axis)] = round3(start[slot(axis)] + travel);
            lead += (self.position[slot(axis)] - start[slot(axis)]).powi(2);
        }
        let (centre, radius, start_angle) = (Vector2::from(circle.centre), circle.radius, circle.start_angle);
        Ok(Some(Arc { plane: (a, b), centre, radius, start_angle, sweep, lead: lead.sqrt() }))
    }

    /// F as written: a literal, or a parameter's raw value read as digits
    /// without a point (`R26=0.200` is F200, 03 §1.6).
    fn programmed_feed(&self, word: &Word) -> Option<ProgrammedFeed> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => Some(ProgrammedFeed { value: decimal.to_f64(), point: decimal.has_point() }),
            value => self.raw(value).map(|raw| ProgrammedFeed { value: raw as f64, point: false }),
        }
    }

    /// A dimensional word's value: the literal as written (mm), or a
    /// parameter's raw thousandths.
    pub(super) fn number(&self, word: &Word) -> Option<f64> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => Some(decimal.to_f64()),
            value => self.raw(value).map(|raw| raw as f64 / 1000.0),
        }
    }

    /// A dimensionless quantity (S in rpm, Q in 10 ms): the literal as
    /// written, or a parameter's raw digits (`R27=300` and `R27=0.300` are
    /// both S300, 03 §1.6).
    pub(super) fn count(&self, word: &Word) -> Option<f64> {
        match word.value.as_ref()? {
            Value::Literal(decimal) => Some(decimal.to_f64()),
            value => self.raw(value).map(|raw| raw as f64),
        }
    }

    /// A dimensionless word's whole number (codes, T): the literal, or a
    /// parameter's raw digits.
    fn integer(&self, word: &Word) -> Option<u32> {
        program_flow::integer(word, &self.params)
    }

    /// The raw value a parameter reference reads, sign applied.
    pub(super) fn raw(&self, value: &Value) -> Option<Raw> {
        arith::reference(value, &self.params)
    }

    fn not_run(&mut self, what: &str, range: TextRange) {
        let message = format!("the executor does not run {what} yet: the time leaves them out");
        self.report_once(RunRule::NotRunYet, what, range, &message);
    }

    /// Reports a problem of kind `key` at its first place only.
    pub(super) fn report_once(&mut self, rule: RunRule, key: &str, range: TextRange, message: &str) {
        if !self.reported.iter().any(|done| done == key) {
            self.reported.push(key.to_owned());
            self.finding(rule, range, message);
        }
    }
}
