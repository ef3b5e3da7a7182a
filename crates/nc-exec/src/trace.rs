//! What a run produces: the steps, the findings and the trace that holds
//! them, and how a run hands them on ([`sink`]). Every control's
//! interpreter writes this vocabulary.

mod rules;
mod sink;

pub use self::{rules::RunRule, sink::*};
pub use crate::axes::{Axes, MAX_AXES, Position};
pub(crate) use crate::axes::{round3, slot};

use std::{fmt, ops::Range};

use ncc_syntax::TextRange;

use crate::{
    compensation::ToolElement,
    transform::{self, Frame},
};

/// What a block did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// No motion, no time.
    None,
    Rapid,
    Feed,
    Dwell,
}

/// What a run adds up to.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Totals {
    /// Seconds from the program's start to its end.
    pub total_time: f64,
    /// The same at the programmed feeds: the steps' own durations.
    pub programmed_time: f64,
    /// Seconds and mm by [`Motion`].
    pub(super) time: [f64; 4],
    pub(super) length: [f64; 4],
    /// M00 and M01 stops.
    pub program_stops: usize,
    pub optional_stops: usize,
}

impl Totals {
    /// Seconds spent in blocks of one kind.
    pub fn time(&self, motion: Motion) -> f64 {
        self.time[motion as usize]
    }

    /// Path length in mm of blocks of one kind.
    pub fn length(&self, motion: Motion) -> f64 {
        self.length[motion as usize]
    }

    /// These totals of a run whose part up to a point summed to `from`,
    /// after that part changed to sum to `to`.
    pub fn moved(&self, from: &Totals, to: &Totals) -> Totals {
        let shift = |value: f64, from: f64, to: f64| value - from + to;
        let count = |value: usize, from: usize, to: usize| (value + to).saturating_sub(from);
        Totals {
            total_time: shift(self.total_time, from.total_time, to.total_time),
            programmed_time: shift(self.programmed_time, from.programmed_time, to.programmed_time),
            time: std::array::from_fn(|i| shift(self.time[i], from.time[i], to.time[i])),
            length: std::array::from_fn(|i| shift(self.length[i], from.length[i], to.length[i])),
            program_stops: count(self.program_stops, from.program_stops, to.program_stops),
            optional_stops: count(self.optional_stops, from.optional_stops, to.optional_stops),
        }
    }

    /// Counts `step`, which took `duration` seconds.
    pub fn add(&mut self, step: &Step, duration: f64) {
        self.total_time += duration;
        self.programmed_time += step.duration;
        self.time[step.motion as usize] += duration;
        self.length[step.motion as usize] += step.length;
        match step.stop {
            Some(Stop::Program) => self.program_stops += 1,
            Some(Stop::Optional) => self.optional_stops += 1,
            None => {}
        }
    }
}

/// One block as it ran.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The file the block is in: 0 for the program, k for the k-th other
    /// file the run read ([`Trace::files`]).
    pub source: usize,
    /// The block's text range.
    pub range: TextRange,
    pub motion: Motion,
    /// The shape of the move.
    pub path: Path,
    pub duration: f64,
    /// Path length in mm.
    pub length: f64,
    /// The path feed in mm/min (`None` for rapid and non-motion blocks).
    pub feed: Option<f64>,
    /// The programmed position at the step's end, over the machine's axes
    /// ([`Trace::axes`]); it starts where the step before it ended.
    pub end: Axes,
    /// How program coordinates became machine ones in the step:
    /// `Trace::frames[frame]` (the zero offset, G37, the length correction
    /// and the transformations G38/G39/G31).
    pub frame: usize,
    /// The program stops after the block (M00, M01) until the operator
    /// starts it again; the run does not count the wait.
    pub stop: Option<Stop>,
    /// How the path passes into the block from the one before it.
    pub path_mode: PathMode,
    /// M functions the block runs besides program stops, ends and the tool
    /// change, and whether it changes the tool (M06); each takes the
    /// machine's time for it.
    pub m_functions: u8,
    pub tool_change: bool,
    /// The control's set of dynamics in force, from 1 (CNC8x6: the
    /// envelope velocity's `G23 I1` … `I4`, 1 after reset).
    pub dynamic_set: u8,
    /// A line the control may merge into the move before it (CNC8x6: a
    /// G01 line without M, S, T, D or F and not under G91, which machine
    /// constant R383 merges, 04 §1.9.4).
    pub mergeable: bool,
    /// The control limits the jerk of the move's ramps to its policy's
    /// (the velocity model's `Dynamics::jerk`; Sinumerik: SOFT against
    /// BRISK), so that a program switches block by block.
    pub jerk_limited: bool,
    /// The spindle's commanded speed in rpm (negative under M04, 0 where
    /// it stands or the control's model does not follow it) as the step
    /// starts and as it ends; they differ on a cut under constant cutting
    /// speed, where it follows the diameter. Single precision is ample
    /// for rpm and keeps the steps of a long run small.
    pub spindle: [f32; 2],
    /// How far (mm) the path may leave the corner where this move is
    /// joined to the one before (Haas lathe: G187); infinite where the
    /// control bounds the corner speed by no tolerance.
    pub corner_tolerance: f32,
}

/// How the path passes from one block into the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathMode {
    /// The axes stop, and the next block is prepared only then: a pause
    /// (CNC8x6: G98, the basic state, and the group's other codes G05–G10).
    Stop,
    /// An exact stop: the axes stop and wait for the in-position window
    /// (CNC8x6: G24, tight joining).
    ExactStop,
    /// A continuous path: the blocks join without a stop where the control
    /// allows (CNC8x6: G23, manual or recognised as R97 says).
    Continuous,
}

/// A message operation 51 shows the operator; the program does not wait
/// for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OperatorMessage {
    /// The step of the block that showed it.
    pub step: usize,
    pub message: Message,
}

/// A message the program shows the operator: a numbered text with one
/// parameter's value in it (CNC8x6: operation 51, `51MMPPTD`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Message {
    /// Which message text (CNC8x6: 1–99, decades 6–5; where the texts are
    /// defined is not described in the manual).
    pub code: u8,
    /// The parameter shown where the text has a lone `$`.
    pub parameter: u8,
    /// Its raw value when the message was shown; the display does not
    /// update it.
    pub value: Option<i64>,
    pub display: MessageDisplay,
}

/// How long a message stays on screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MessageDisplay {
    /// Removes the message.
    Cancel,
    /// Until cancelled.
    Permanent,
    /// For the duration of one block.
    OneBlock,
    /// For some seconds.
    Seconds(u8),
}

/// Steps that ran under radius compensation: their ends are the
/// programmed contour, the tool ran on [`Trace::tool_centre`].
#[derive(Debug, Clone, PartialEq)]
pub struct Compensated {
    pub steps: Range<usize>,
    /// The plane's axes, the order of the tool-centre path's coordinates.
    pub plane: (u8, u8),
}

/// The shape of a move from its start to its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Path {
    Straight,
    /// An arc (a helix when other axes move too) in the plane of two axes
    /// (letters), turning about `centre` (absolute, in the plane's order).
    Arc {
        plane: (u8, u8),
        centre: [f64; 2],
        clockwise: bool,
    },
    /// A thread: `lead` mm per revolution at `speed` rpm.
    Thread {
        lead: f64,
        speed: f64,
    },
}

/// A program stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// M00: always.
    Program,
    /// M01: when the operator has selected AUT-M01.
    Optional,
}

/// A problem found while running, at a text range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    pub rule: RunRule,
    /// The file, as in [`Step::source`].
    pub source: usize,
    pub range: TextRange,
    pub message: String,
}

impl Finding {
    /// The run stopped here (an error the control stops on).
    pub fn stops(&self) -> bool {
        self.rule.stops()
    }
}

/// A whole run.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// The machine's axes, the order of [`Step::end`].
    pub axes: Vec<u8>,
    /// The machine's diameter axis: positions on it are radii, whether the
    /// program wrote diameters (G74) or radii (G75).
    pub diameter_axis: Option<u8>,
    /// From program to machine coordinates, per [`Step::frame`].
    pub frames: Vec<Frame>,
    /// The frame of the priority block: the zero offset G53 of the machine's
    /// tables as the run started.
    pub reset_frame: Frame,
    /// The tool-centre path of radius compensation, piece by piece in the
    /// order of their steps (`block` is the step's index).
    pub tool_centre: Vec<ToolElement>,
    pub compensated: Vec<Compensated>,
    /// The technologist's messages of operation 51, in the order shown.
    pub messages: Vec<OperatorMessage>,
    pub steps: Vec<Step>,
    pub findings: Vec<Finding>,
    /// Tools called with T, in order of first use.
    pub tools: Vec<Tool>,
    /// The files the run read besides the program: source k is
    /// `files[k - 1]`.
    pub files: Vec<Called>,
    /// Blocks the run executed, the ones before a checkpoint it resumed
    /// from included (the step budget counts them).
    pub blocks_run: usize,
    /// The files the program wrote (Sinumerik: WRITE), with their final
    /// text, for whoever runs it to keep where it chooses.
    pub written: Vec<WrittenFile>,
}

/// A tool as a program selects it: by its number (`T5`), or by its name
/// on a Sinumerik with tool management (`T="DRILL_8"`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Tool {
    Number(u32),
    Name(String),
}

impl fmt::Display for Tool {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tool::Number(number) => write!(f, "T{number}"),
            Tool::Name(name) => write!(f, "T=\"{name}\""),
        }
    }
}

/// A file a run wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WrittenFile {
    /// As the program named it, in upper case: the control's path
    /// (`/_N_MPF_DIR/_N_VACKA_DIR/_N_GEOMETRIE_VACKA_SPF`) or a bare name.
    pub path: String,
    pub text: String,
}

impl Trace {
    /// Time and length by kind of block, and the program stops, in one
    /// pass over the steps (a long run's steps are hundreds of megabytes).
    pub fn totals(&self) -> Totals {
        self.totals_with(self.steps.iter().map(|step| step.duration))
    }

    /// Like [`Trace::totals`], with the steps taking `durations` (those of
    /// the velocity model).
    pub fn totals_with(&self, durations: impl Iterator<Item = f64>) -> Totals {
        let mut totals = Totals::default();
        for (step, duration) in self.steps.iter().zip(durations) {
            totals.add(step, duration);
        }
        totals
    }

    /// The programmed position at the end, over the machine's axes.
    pub fn end(&self) -> Axes {
        self.steps.last().map_or([0.0; MAX_AXES], |step| step.end)
    }

    /// The programmed position at the end, by letter.
    pub fn end_position(&self) -> Position {
        self.position(&self.end())
    }

    /// Where step `index` starts in machine coordinates: where the one
    /// before it ended, or the machine zero.
    pub fn machine_start(&self, index: usize) -> Axes {
        index.checked_sub(1).map_or([0.0; MAX_AXES], |before| self.machine_end(before))
    }

    /// Where step `index` starts in the program coordinates it runs in.
    pub fn start_of(&self, index: usize) -> Axes {
        self.frames[self.steps[index].frame].to_program(&self.machine_start(index), &self.axes)
    }

    /// Axis values as a position by letter.
    pub fn position(&self, values: &Axes) -> Position {
        transform::by_letter(values, &self.axes)
    }

    /// Step `index`'s end in machine coordinates.
    pub fn machine_end(&self, index: usize) -> Axes {
        let step = &self.steps[index];
        self.frames[step.frame].to_machine(&step.end, &self.axes)
    }

    /// The value of axis `letter` in `values`, 0 for a letter the machine
    /// does not have.
    pub fn axis(&self, values: &Axes, letter: u8) -> f64 {
        self.axes.iter().position(|&axis| axis == letter).map_or(0.0, |i| values[i])
    }
}

/// A file a run reads besides the program, as the program or the machine
/// names it; the [`Environment`] finds it by the dialect's rule.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Called {
    /// By number (CNC8x6: the macrocycle file `L<number>`).
    Number(u32),
    /// By name (CNC8x6: the machine's fixed-cycle file).
    Name(String),
    /// A program by its number (Haas lathe: `M98 P1234` or `G65 P1234`
    /// calls program `O1234`, in a file named after it, `O1234` or
    /// `O01234` with or without an extension).
    Program(u32),
    /// A program by the control's name for its file (Sinumerik:
    /// `_N_PROFIL_SPF`, in a file `PROFIL.SPF` or `_N_PROFIL_SPF` beside
    /// the program, any case).
    ControlFile(String),
    /// A program the run wrote itself ([`Trace::written`]), by its path.
    Written(String),
}
