//! Built-in fixed cycles: what G81–G89 do when the machine names no `$PC`
//! cycle file, written from the step descriptions of the supplied files
//! (milling `PCYKLYDG.NCP`, 03 §2.1; lathe `PEVNECY4/5/6.NCP`, 03 §2.3).
//!
//! [`expand`] turns one run of a cycle into its moves ([`CycleStep`], with
//! absolute end positions) for the runner to time as steps. It is pure: it
//! reads the parameters and the modal state it is given and changes nothing.
//!
//! # How the runner calls it (03 §1.4)
//! - G81–G89 (or `GRxx` giving 81–89) makes that cycle active and G80
//!   cancels it. The active cycle runs in its own block and in every
//!   following block, with motion or without, but not in the G80 block.
//! - It runs after the block's parameter assignments (a block may declare
//!   the cycle's parameters, I5) and after its own motion, from the position
//!   the block reached, before the block's closing M functions.
//! - Afterwards the tool stays where the last step left it ([`Cycle::end`]).
//!   Everything else is as before the cycle (I6, I7): the motion group,
//!   G90/G91, G94/G95, F, S, the spindle's direction, and the parameters.
//!   The steps carry their own feed and speed, so the runner times them
//!   without taking their F, S or spindle changes into its modal state. The
//!   control restores a spindle the cycle reversed or stopped (G84, G87) at
//!   the start of the next block, which is where a spindle model would charge
//!   the time. The built-ins keep their working values to themselves (the
//!   files use R0–R48 and the restore undoes it), so parameters need nothing.
//!
//! # Units (03 §1.6)
//! Parameters hold raw thousandths: lengths are µm (`R30=5.` is 5 mm, `R30=5`
//! is 5 µm), the feed R26 is mm/min under G94 and µm/rev under G95 (a thread
//! lead too), the speed R27 of the milling cycles rpm, the dwell R29 units of
//! 10 ms, and counts (R23, R27 of the roughing cycles, R29 of the threads) are
//! the raw number (`R27=0.002` and `R27=2` are both two passes). Positions
//! are mm; a lathe's X is in the programming mode (diameter or radius) as the
//! block programmed it, and so are its X-size parameters.
//!
//! # Readings (each the project's decision)
//! - The geometry is computed in raw thousandths, products and quotients
//!   rounded to a thousandth (halves away from zero) as the files' real
//!   arithmetic does, so positions match the files' (03 Appendix B).
//! - Loops end where the files' jumps end: `G73 … Q9998` runs a section at
//!   most 9999 times (Q9999: 10000). A cycle that needs more is an error
//!   rather than a hole left half drilled.
//! - Milling and lathe G83 program no G90: under G91 their Z words are
//!   incremental, as the files' are (03 §2.1.3).
//! - Milling G86 with an increment beyond the depth goes to RB at rapid: no
//!   G01 ran before that block (03 §2.1.6).
//! - Lathe G82 ends with the start point's X and Z swapped, as its file does
//!   (03 §2.3.2, §7.4): the digest says to run the code as written.
//! - Lathe G84/G85 cut every thread as metric and ignore R20 (the file
//!   overwrites it, §7.8); lathe G86 takes its lengths as written, diameter
//!   or not (§7.7); lathe G83 ignores R27 (§7.5).
//! - An M function of a cycle's block comes before the block's motion
//!   (§7.9); G84's M49 (feed override blocked) is left out, it takes no time.
//! - A move to where the tool already is, and a dwell of 0, are left out.

use std::fmt;

use crate::{
    cnc8x6::arith::{MAX_RAW, Parameters, Raw},
    trace::Position,
};

const X: usize = (b'X' - b'A') as usize;
const Y: usize = (b'Y' - b'A') as usize;
const Z: usize = (b'Z' - b'A') as usize;

/// The most moves one run of a cycle may make: a net under the loop limits.
pub const MAX_STEPS: usize = 100_000;

/// The deep-drilling cycles re-approach 1 mm before the last depth
/// (`R24=1.000`, 03 §2.1.3).
const CLEARANCE: Raw = 1000;

/// Which cycles G81–G89 name: the machine's cycle file decides (03 §1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum CycleKind {
    /// Drilling in Z (`PCYKLYDG.NCP`).
    #[default]
    Milling,
    /// Roughing, drilling, threads and chamfers in X/Z (`PEVNECY4/5/6.NCP`).
    Lathe,
}

impl CycleKind {
    /// The kind of a machine's cycle file: `PEVNECY` and a digit is a lathe
    /// file; anything else, or no file, is milling (`PEVNECYK.NCP` is the
    /// older milling file, 03 §1.2).
    pub fn of(cycle_file: Option<&str>) -> CycleKind {
        let name = cycle_file.map_or("", |path| path.rsplit(['/', '\\']).next().unwrap_or(path)).as_bytes();
        match name.get(..8) {
            Some([prefix @ .., digit]) if prefix.eq_ignore_ascii_case(b"PEVNECY") && digit.is_ascii_digit() => {
                CycleKind::Lathe
            }
            _ => CycleKind::Milling,
        }
    }
}

impl fmt::Display for CycleKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CycleKind::Milling => "milling",
            CycleKind::Lathe => "lathe",
        })
    }
}

/// The spindle's state, M group 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Spindle {
    /// M3.
    Clockwise,
    /// M4.
    CounterClockwise,
    /// M5, the priority block's state.
    #[default]
    Stopped,
    /// M19, oriented stop.
    Oriented,
}

impl Spindle {
    /// The M code.
    pub fn code(self) -> u8 {
        match self {
            Spindle::Clockwise => 3,
            Spindle::CounterClockwise => 4,
            Spindle::Stopped => 5,
            Spindle::Oriented => 19,
        }
    }
}

/// What one run of a cycle needs: the call, the parameters and the modal
/// state at the call.
#[derive(Debug, Clone, Copy)]
pub struct CycleInput<'a> {
    /// The cycle, 81–89.
    pub number: u32,
    pub kind: CycleKind,
    /// R0–R95 as the block left them, its own assignments included.
    pub params: &'a Parameters,
    /// The programmed position the block reached, mm: milling cycles drill
    /// at its X and Y, lathe cycles start from its X and Z.
    pub position: Position,
    /// G91 at the call: the G83 cycles program no G90 (03 §2.1.3, §2.3.3).
    pub incremental: bool,
    /// G95 at the call: R26 is then µm/rev (milling G84 programs G94).
    pub per_revolution: bool,
    /// S at the call, rpm: the lathe cycles program none (the milling ones
    /// take R27).
    pub speed: f64,
    /// The spindle at the call: milling G84 reverses it, G87 restarts it.
    pub spindle: Spindle,
    /// Lathe X values are diameters (`PEVNECY4/5`, G74): the alternating
    /// thread infeed halves its depth for the flank shift.
    pub diameter: bool,
}

/// A feed as the cycle programs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FeedSpec {
    /// G94: mm/min.
    PerMinute(f64),
    /// G95: mm per revolution at `speed` rpm (above 0).
    PerRevolution { per_rev: f64, speed: f64 },
}

impl FeedSpec {
    /// The path feed in mm/min.
    pub fn mm_per_min(self) -> f64 {
        match self {
            FeedSpec::PerMinute(feed) => feed,
            FeedSpec::PerRevolution { per_rev, speed } => per_rev * speed,
        }
    }
}

/// A thread pass's G33 words.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thread {
    /// F: mm per revolution (R26).
    pub lead: f64,
    /// The spindle speed it is cut at, rpm (above 0).
    pub speed: f64,
    /// I: the start's angle from the spindle's zero pulse, degrees (R27).
    pub start_angle: f64,
    /// J: the run-out length in mm (lathe G85, R22). The end point includes
    /// it; the angle comes from machine constant 8 or R04 (01 §6.8.3), which
    /// the runner's thread model reads.
    pub run_out: Option<f64>,
}

/// One move or action of a cycle, in order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CycleStep {
    /// G00 to an absolute position.
    Rapid { to: Position },
    /// G01 to an absolute position.
    Feed { to: Position, feed: FeedSpec },
    /// G33 to an absolute position; waits for the spindle's zero pulse first.
    Thread { to: Position, thread: Thread },
    /// G04.
    Dwell { seconds: f64 },
    /// A new spindle state (M3/M4/M5/M19) or speed (S), or both.
    Spindle { state: Option<Spindle>, speed: Option<f64> },
}

impl CycleStep {
    /// Where a move ends.
    pub fn to(&self) -> Option<&Position> {
        match self {
            CycleStep::Rapid { to } | CycleStep::Feed { to, .. } | CycleStep::Thread { to, .. } => Some(to),
            CycleStep::Dwell { .. } | CycleStep::Spindle { .. } => None,
        }
    }

    /// The path feed of a feed or thread move, mm/min.
    pub fn feed_rate(&self) -> Option<f64> {
        match self {
            CycleStep::Feed { feed, .. } => Some(feed.mm_per_min()),
            CycleStep::Thread { thread, .. } => Some(thread.lead * thread.speed),
            _ => None,
        }
    }
}

/// One run of a cycle. It prints one line per step, with the axes each move
/// changes (the form of 03 Appendix B).
#[derive(Debug, Clone, PartialEq)]
pub struct Cycle {
    /// Where the cycle started.
    pub start: Position,
    pub steps: Vec<CycleStep>,
}

impl Cycle {
    /// Where the tool is after the cycle: the runner's position from then on.
    pub fn end(&self) -> Position {
        self.steps.iter().rev().find_map(CycleStep::to).copied().unwrap_or(self.start)
    }
}

impl fmt::Display for Cycle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut at = self.start;
        for step in &self.steps {
            match step {
                CycleStep::Rapid { to } => {
                    f.write_str("G00")?;
                    axes(f, &at, to)?;
                }
                CycleStep::Feed { to, feed } => {
                    f.write_str("G01")?;
                    axes(f, &at, to)?;
                    match *feed {
                        FeedSpec::PerMinute(feed) => write!(f, " F{} mm/min", Short(feed))?,
                        FeedSpec::PerRevolution { per_rev, speed } => {
                            write!(f, " F{} mm/rev S{}", Short(per_rev), Short(speed))?
                        }
                    }
                }
                CycleStep::Thread { to, thread } => {
                    f.write_str("G33")?;
                    axes(f, &at, to)?;
                    write!(f, " F{} mm/rev S{}", Short(thread.lead), Short(thread.speed))?;
                    if thread.start_angle != 0.0 {
                        write!(f, " I{}", Short(thread.start_angle))?;
                    }
                    if let Some(run_out) = thread.run_out {
                        write!(f, " J{}", Short(run_out))?;
                    }
                }
                CycleStep::Dwell { seconds } => write!(f, "G04 {} s", Short(*seconds))?,
                CycleStep::Spindle { state, speed } => {
                    let state = state.map(|state| format!("M{}", state.code()));
                    let speed = speed.map(|speed| format!("S{}", Short(speed)));
                    f.write_str(&[state, speed].into_iter().flatten().collect::<Vec<_>>().join(" "))?;
                }
            }
            writeln!(f)?;
            if let Some(to) = step.to() {
                at = *to;
            }
        }
        Ok(())
    }
}

/// The axes a move changes, as ` Z-50.000`.
fn axes(f: &mut fmt::Formatter<'_>, from: &Position, to: &Position) -> fmt::Result {
    for (letter, (a, b)) in (b'A'..).zip(from.iter().zip(to)) {
        if a != b {
            write!(f, " {}{b:.3}", char::from(letter))?;
        }
    }
    Ok(())
}

/// A number with up to three decimals and no trailing zeros.
struct Short(f64);

impl fmt::Display for Short {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = format!("{:.3}", self.0);
        f.write_str(text.trim_end_matches('0').trim_end_matches('.'))
    }
}

/// Why a cycle cannot run. The runner reports it at the block.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CycleError {
    /// The cycle file of this kind has no such cycle (lathe G88, G89).
    NotDefined { number: u32, kind: CycleKind },
    /// A parameter the cycle reads is not known.
    Unknown { parameter: u8 },
    /// A parameter holds a value the cycle cannot work with.
    Invalid { parameter: u8, value: Raw, why: &'static str },
    /// The cycle would repeat a section more often than the file's jump allows.
    TooManyPasses { passes: Raw, limit: Raw },
    /// More than [`MAX_STEPS`] moves.
    TooManySteps,
    /// Milling G84 reverses the spindle, which is not turning.
    SpindleNotTurning,
    /// Feed per revolution or a thread with the spindle at S0.
    NoSpindleSpeed,
    /// The start position lies outside what a parameter can hold.
    PositionOutOfRange { axis: char },
}

impl fmt::Display for CycleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CycleError::NotDefined { number, kind } => {
                write!(f, "the {kind} cycle file has no G{number}")?;
                if *kind == CycleKind::Lathe {
                    f.write_str(" (the lathe cycles are G81–G87)")?;
                }
                Ok(())
            }
            CycleError::Unknown { parameter } => write!(f, "the cycle needs R{parameter:02}, whose value is not known"),
            CycleError::Invalid { parameter, value, why } => {
                write!(f, "R{parameter:02} = {:.3}: {why}", *value as f64 / 1000.0)
            }
            CycleError::TooManyPasses { passes, limit } => write!(
                f,
                "the cycle would repeat a section {passes} times; the supplied cycle's jump stops after {limit}"
            ),
            CycleError::TooManySteps => write!(f, "the cycle would make more than {MAX_STEPS} moves"),
            CycleError::SpindleNotTurning => {
                f.write_str("G84 reverses the spindle at the hole's bottom: it needs M3 or M4 before the call")
            }
            CycleError::NoSpindleSpeed => {
                f.write_str("feed per revolution or a thread with spindle speed S0: the axes cannot move")
            }
            CycleError::PositionOutOfRange { axis } => {
                write!(f, "the {axis} position is outside ±69999.999 mm, which the cycle's parameters cannot hold")
            }
        }
    }
}

impl std::error::Error for CycleError {}

/// The moves of one run of cycle `input.number`.
pub fn expand(input: &CycleInput<'_>) -> Result<Cycle, CycleError> {
    for axis in [X, Y, Z] {
        // NaN is out of range too.
        if !(-mm(MAX_RAW)..=mm(MAX_RAW)).contains(&input.position[axis]) {
            return Err(CycleError::PositionOutOfRange { axis: char::from(b'A' + axis as u8) });
        }
    }
    let mut cycle = Builder { input, at: input.position, steps: Vec::new() };
    match (input.kind, input.number) {
        (CycleKind::Milling, number @ (81 | 82 | 85)) => cycle.drilling(number)?,
        (CycleKind::Milling, 83) | (CycleKind::Lathe, 83) => cycle.deep_drilling()?,
        (CycleKind::Milling, 84) => cycle.tapping()?,
        (CycleKind::Milling, 86) => cycle.chip_breaking()?,
        (CycleKind::Milling, 87) => cycle.jump_off()?,
        // The user's slots, empty in the supplied file (03 §2.1.8).
        (CycleKind::Milling, 88 | 89) => {}
        (CycleKind::Lathe, 81) => cycle.roughing(false)?,
        (CycleKind::Lathe, 82) => cycle.roughing(true)?,
        (CycleKind::Lathe, 84) => cycle.cylindrical_thread(false)?,
        (CycleKind::Lathe, 85) => cycle.cylindrical_thread(true)?,
        (CycleKind::Lathe, 86) => cycle.chamfer()?,
        (CycleKind::Lathe, 87) => cycle.taper_thread()?,
        (kind, number) => return Err(CycleError::NotDefined { number, kind }),
    }
    Ok(Cycle { start: input.position, steps: cycle.steps })
}

/// Collects the steps, following the position.
struct Builder<'i, 'p> {
    input: &'i CycleInput<'p>,
    at: Position,
    steps: Vec<CycleStep>,
}

/// The values a lathe thread cycle derives before its passes (03 §2.3.4).
struct ThreadPlan {
    /// The start point.
    x0: Raw,
    z0: Raw,
    /// The first chip's depth, signed as R30, and the X it cuts at.
    chip: Raw,
    first: Raw,
    /// The quotient by which each chip is smaller than the one before (R28).
    quotient: Raw,
    /// Roughing passes: R29 − 1.
    passes: Raw,
    /// The thread's final X and its end in Z.
    x_end: Raw,
    z_end: Raw,
    thread: Thread,
}

impl Builder<'_, '_> {
    /// The value of R`parameter`, within the ±69999.999 a parameter holds.
    fn raw(&self, parameter: u8) -> Result<Raw, CycleError> {
        let value = self.input.params.get(usize::from(parameter)).ok_or(CycleError::Unknown { parameter })?;
        if value.abs() > MAX_RAW {
            return Err(CycleError::Invalid { parameter, value, why: "a parameter holds at most ±69999.999" });
        }
        Ok(value)
    }

    /// The value of R`parameter` if `valid` accepts it.
    fn check(&self, parameter: u8, valid: impl Fn(Raw) -> bool, why: &'static str) -> Result<Raw, CycleError> {
        let value = self.raw(parameter)?;
        if valid(value) { Ok(value) } else { Err(CycleError::Invalid { parameter, value, why }) }
    }

    /// The feed R26 (`FR26`) in the given mode.
    fn feed_spec(&self, per_revolution: bool, speed: f64) -> Result<FeedSpec, CycleError> {
        let feed = self.check(26, |feed| feed > 0, "the feed must be above 0")?;
        if !per_revolution {
            return Ok(FeedSpec::PerMinute(feed as f64));
        }
        if speed <= 0.0 {
            return Err(CycleError::NoSpindleSpeed);
        }
        Ok(FeedSpec::PerRevolution { per_rev: mm(feed), speed })
    }

    /// The feed R26 in the mode and at the speed of the call (the lathe
    /// cycles set neither).
    fn modal_feed(&self) -> Result<FeedSpec, CycleError> {
        self.feed_spec(self.input.per_revolution, self.input.speed)
    }

    /// The speed R27 (`SR27`) of the milling cycles, rpm.
    fn milling_speed(&self) -> Result<f64, CycleError> {
        let speed = self.check(27, |s| (0..=9999).contains(&s), "the spindle speed must lie between 0 and 9999 rpm")?;
        Ok(speed as f64)
    }

    /// The dwell R29 (`QR29`) in seconds.
    fn dwell_time(&self) -> Result<f64, CycleError> {
        let units = self.check(29, |q| (0..=9999).contains(&q), "the dwell must lie between 0 and 9999 (× 10 ms)")?;
        Ok(units as f64 / 100.0)
    }

    /// Where `axis` is now, raw.
    fn now(&self, axis: usize) -> Raw {
        (self.at[axis] * 1000.0).round() as Raw
    }

    /// The target of a Z word: absolute, or added under G91.
    fn z_word(&self, value: Raw) -> Raw {
        if self.input.incremental { self.now(Z) + value } else { value }
    }

    fn push(&mut self, step: CycleStep) -> Result<(), CycleError> {
        if self.steps.len() >= MAX_STEPS {
            return Err(CycleError::TooManySteps);
        }
        if let Some(to) = step.to() {
            self.at = *to;
        }
        self.steps.push(step);
        Ok(())
    }

    /// A move's end: the position now with `axes` set (raw, absolute), or
    /// `None` where that is where the tool already is.
    fn target(&self, axes: &[(usize, Raw)]) -> Option<Position> {
        let mut to = self.at;
        for &(axis, value) in axes {
            to[axis] = mm(value);
        }
        (to != self.at).then_some(to)
    }

    fn rapid(&mut self, axes: &[(usize, Raw)]) -> Result<(), CycleError> {
        match self.target(axes) {
            Some(to) => self.push(CycleStep::Rapid { to }),
            None => Ok(()),
        }
    }

    fn feed(&mut self, axes: &[(usize, Raw)], feed: FeedSpec) -> Result<(), CycleError> {
        match self.target(axes) {
            Some(to) => self.push(CycleStep::Feed { to, feed }),
            None => Ok(()),
        }
    }

    fn thread(&mut self, axes: &[(usize, Raw)], thread: Thread) -> Result<(), CycleError> {
        match self.target(axes) {
            Some(to) => self.push(CycleStep::Thread { to, thread }),
            None => Ok(()),
        }
    }

    fn dwell(&mut self, seconds: f64) -> Result<(), CycleError> {
        if seconds > 0.0 { self.push(CycleStep::Dwell { seconds }) } else { Ok(()) }
    }

    fn spindle(&mut self, state: Option<Spindle>, speed: Option<f64>) -> Result<(), CycleError> {
        self.push(CycleStep::Spindle { state, speed })
    }

    /// Milling G81, G82, G85 (03 §2.1.1, §2.1.2, §2.1.5): rapid to RA, feed
    /// to RB (G82: dwell R29; G85: feed back to RA), rapid to RC.
    fn drilling(&mut self, number: u32) -> Result<(), CycleError> {
        let speed = self.milling_speed()?;
        let feed = self.feed_spec(self.input.per_revolution, speed)?;
        let (ra, rb, rc) = (self.raw(30)?, self.raw(31)?, self.raw(32)?);
        let dwell = if number == 82 { self.dwell_time()? } else { 0.0 };
        self.spindle(None, Some(speed))?;
        self.rapid(&[(Z, ra)])?;
        self.feed(&[(Z, rb)], feed)?;
        self.dwell(dwell)?;
        if number == 85 {
            self.feed(&[(Z, ra)], feed)?;
        }
        self.rapid(&[(Z, rc)])
    }

    /// Milling G84 (03 §2.1.4): rapid to RA, feed to RB under G94, reverse
    /// the spindle, feed back to RA, rapid to RC.
    fn tapping(&mut self) -> Result<(), CycleError> {
        let speed = self.milling_speed()?;
        // The cycle programs G94 itself: R26 is mm/min whatever the call's mode.
        let feed = self.feed_spec(false, speed)?;
        let reverse = match self.input.spindle {
            Spindle::Clockwise => Spindle::CounterClockwise,
            Spindle::CounterClockwise => Spindle::Clockwise,
            Spindle::Stopped | Spindle::Oriented => return Err(CycleError::SpindleNotTurning),
        };
        let (ra, rb, rc) = (self.raw(30)?, self.raw(31)?, self.raw(32)?);
        self.spindle(None, Some(speed))?;
        self.rapid(&[(Z, ra)])?;
        self.feed(&[(Z, rb)], feed)?;
        self.spindle(Some(reverse), None)?;
        self.feed(&[(Z, ra)], feed)?;
        self.rapid(&[(Z, rc)])
    }

    /// G83, milling and lathe (03 §2.1.3, §2.3.3): pecks of R28 from RA
    /// toward RB, each fed from 1 mm before the last depth and followed by a
    /// rapid back to RA. The milling cycle takes |R28| and retracts to RC
    /// after the last peck; the lathe one takes R28 as written, ends at RA
    /// and programs no S.
    fn deep_drilling(&mut self) -> Result<(), CycleError> {
        let milling = self.input.kind == CycleKind::Milling;
        let (ra, rb) = (self.raw(30)?, self.raw(31)?);
        let feed = if milling {
            let speed = self.milling_speed()?;
            self.spindle(None, Some(speed))?;
            self.feed_spec(self.input.per_revolution, speed)?
        } else {
            self.modal_feed()?
        };
        let last_retract = if milling { self.raw(32)? } else { ra };
        // A hole of depth 0 ends before the first move.
        if ra == rb {
            return Ok(());
        }
        let increment = if milling {
            self.check(28, |q| q != 0, "the increment must not be 0: the pecks would never reach RB")?.abs()
        } else {
            self.check(28, |q| q > 0, "the increment must be above 0: the lathe cycle takes it as written")?
        };
        let sign = if rb > ra { 1 } else { -1 };
        let depth_total = (rb - ra).abs();
        check_runs((depth_total + increment - 1) / increment, 9998)?;
        let (mut depth, mut approach, mut retract) = (ra, ra, ra);
        // Until the depth reaches RB (a sign-free "RB ≥ depth" of the −Z branch).
        while (rb - depth) * sign > 0 {
            self.rapid(&[(Z, self.z_word(approach))])?;
            depth += sign * increment;
            if (rb - depth) * sign <= 0 {
                depth = rb;
                retract = last_retract;
            }
            self.feed(&[(Z, self.z_word(depth))], feed)?;
            self.rapid(&[(Z, self.z_word(retract))])?;
            approach = depth - sign * CLEARANCE;
        }
        Ok(())
    }

    /// Milling G86 (03 §2.1.6): rapid to RA, then feeds of |R28| toward RB,
    /// each followed by the dwell R29, a last feed to RB without dwell and a
    /// rapid to RC. RB ≥ RA drills toward +Z.
    fn chip_breaking(&mut self) -> Result<(), CycleError> {
        let speed = self.milling_speed()?;
        let feed = self.feed_spec(self.input.per_revolution, speed)?;
        let increment =
            self.check(28, |q| q != 0, "the increment must not be 0: the steps would never reach RB")?.abs();
        let dwell = self.dwell_time()?;
        let (ra, rb, rc) = (self.raw(30)?, self.raw(31)?, self.raw(32)?);
        let sign = if rb >= ra { 1 } else { -1 };
        check_runs((rb - ra).abs() / increment, 9998)?;
        self.spindle(None, Some(speed))?;
        self.rapid(&[(Z, ra)])?;
        let (mut depth, mut fed) = (ra, false);
        loop {
            depth += sign * increment;
            if (rb - depth) * sign < 0 {
                break;
            }
            self.feed(&[(Z, depth)], feed)?;
            self.dwell(dwell)?;
            fed = true;
        }
        // `ZR31` runs in the modal motion: G00 of the approach when no step
        // fitted into the depth.
        if fed {
            self.feed(&[(Z, rb)], feed)?;
        } else {
            self.rapid(&[(Z, rb)])?;
        }
        self.rapid(&[(Z, rc)])
    }

    /// Milling G87 (03 §2.1.7): rapid to RA, orient the spindle, jump off
    /// by R28 in Y, rapid to the plane RD (R29) and back onto the hole's
    /// axis, restart the spindle as it turned at the call at S R27, feed to
    /// RB, orient, jump off, rapid to RC and back onto the axis.
    fn jump_off(&mut self) -> Result<(), CycleError> {
        let speed = self.milling_speed()?;
        let feed = self.feed_spec(self.input.per_revolution, speed)?;
        let (jump, rd) = (self.raw(28)?, self.raw(29)?);
        let (ra, rb, rc) = (self.raw(30)?, self.raw(31)?, self.raw(32)?);
        let y = self.now(Y);
        self.rapid(&[(Z, ra)])?;
        self.spindle(Some(Spindle::Oriented), None)?;
        self.rapid(&[(Y, y + jump)])?;
        self.rapid(&[(Z, rd)])?;
        self.rapid(&[(Y, y)])?;
        self.spindle(Some(self.input.spindle), Some(speed))?;
        self.feed(&[(Z, rb)], feed)?;
        self.spindle(Some(Spindle::Oriented), None)?;
        self.rapid(&[(Y, y + jump)])?;
        self.rapid(&[(Z, rc)])?;
        self.rapid(&[(Y, y)])
    }

    /// Lathe G81 and G82 (03 §2.3.1, §2.3.2). G81 takes chips of R28 in X
    /// (the infeed axis) and cuts along Z; G82 takes them in Z and cuts
    /// along X. Per chip: in to the chip (G81 rapid, G82 feed), cut to the
    /// end shortened by R29 more each chip, back out to the last chip's
    /// size, rapid back to the start along the cut axis. Then one last chip
    /// at the final size, or R27 finishing passes along the final contour.
    fn roughing(&mut self, transverse: bool) -> Result<(), CycleError> {
        // Infeed axis, cut axis, and the parameters of each: offset of the
        // start from the start point (R24/R25), size of the region (R30/R31).
        let (infeed, cut, infeed_offset, cut_offset, infeed_size, cut_size) =
            if transverse { (Z, X, 25, 24, 31, 30) } else { (X, Z, 24, 25, 30, 31) };
        let feed = self.modal_feed()?;
        let thickness = self.check(
            28,
            |t| t > 0,
            "the chip thickness must be above 0 (the cycle gives it the region's direction itself)",
        )?;
        let region = self.check(infeed_size, |r| r != 0, "the roughing region must not be empty")?;
        let length = self.check(cut_size, |r| r != 0, "the roughing length must not be 0")?;
        let shortening = self.raw(29)?;
        let finishing = self.raw(27)?;
        let (infeed_home, cut_home) = (self.now(infeed), self.now(cut));
        let infeed_start = infeed_home + self.raw(infeed_offset)?;
        let infeed_end = infeed_start + region;
        let cut_end = cut_home + self.raw(cut_offset)? + length;
        let step = region.signum() * thickness;
        // The first chip is always cut; the next while it lies strictly
        // before the final size.
        let chips = ((region.abs() + thickness - 1) / thickness - 1).max(1);
        let q = if transverse { 9999 } else { 9998 };
        check_runs(chips, q)?;
        let (mut previous, mut at, mut cut_to) = (infeed_home, infeed_start + step, cut_end);
        for _ in 0..chips {
            self.roughing_infeed(transverse, infeed, at, feed)?;
            cut_to += shortening;
            self.feed(&[(cut, cut_to)], feed)?;
            self.feed(&[(infeed, previous)], feed)?;
            self.rapid(&[(cut, cut_home)])?;
            previous = at;
            at += step;
        }
        if finishing == 0 {
            self.roughing_infeed(transverse, infeed, infeed_end, feed)?;
            self.feed(&[(cut, cut_to + shortening)], feed)?;
            self.feed(&[(infeed, infeed_home)], feed)?;
            // G82's file returns X to the start point's Z (03 §2.3.2).
            self.rapid(&[(cut, if transverse { infeed_home } else { cut_home })])?;
            return Ok(());
        }
        // The counter R47 = R27 counts down and repeats while above 0.
        let passes = finishing.max(1);
        check_runs(passes, q)?;
        // The finishing cut ends where the shortening reaches the final size:
        // R29 · |size| / R28 before the end.
        let finish = cut_end + div(mul(shortening, region.abs()), thickness);
        // G82's file swaps the start point's X and Z in the last two moves.
        let (infeed_back, cut_back) = if transverse { (cut_home, infeed_home) } else { (infeed_home, cut_home) };
        for _ in 0..passes {
            self.roughing_infeed(transverse, infeed, infeed_end, feed)?;
            self.feed(&[(cut, finish)], feed)?;
            // The face: to the part's surface and the end at once.
            self.feed(&[(infeed, infeed_start), (cut, cut_end)], feed)?;
            self.feed(&[(infeed, infeed_back)], feed)?;
            self.rapid(&[(cut, cut_back)])?;
        }
        Ok(())
    }

    /// The move in to a chip: G81 at rapid, G82 at feed.
    fn roughing_infeed(&mut self, transverse: bool, axis: usize, to: Raw, feed: FeedSpec) -> Result<(), CycleError> {
        if transverse { self.feed(&[(axis, to)], feed) } else { self.rapid(&[(axis, to)]) }
    }

    /// What the lathe thread cycles derive first (03 §2.3.4): the first chip
    /// |R30| / (1 + k + … + k^(n−1)) with k = R28 and n = R29 chips, signed
    /// as R30; X starts at X0 + R24 and ends R30 further; Z ends at
    /// Z0 + R25 + R31.
    fn thread_plan(&self, run_out: Option<f64>) -> Result<ThreadPlan, CycleError> {
        let lead = self.check(26, |lead| lead > 0, "the thread lead must be above 0")?;
        if self.input.speed <= 0.0 {
            return Err(CycleError::NoSpindleSpeed);
        }
        let quotient = self.check(28, |k| 0 < k && k < 1000, "the chip quotient must lie between 0 and 1")?;
        let chips = self.check(29, |n| n >= 2, "a thread needs at least 2 chips")?;
        // The roughing passes repeat with `G73 L50 QR10`, R10 = R29 − 2 ≤ 9999.
        check_runs(chips - 1, 9999)?;
        let depth = self.raw(30)?;
        let k = quotient as f64 / 1000.0;
        // Op 28's sum, rounded as a real result; at least 1 for 0 < k < 1.
        let sum = ((k.powi(chips as i32) - 1.0) / (k - 1.0) * 1000.0).round() as Raw;
        let chip = div(depth.abs(), sum) * if depth < 0 { -1 } else { 1 };
        let (x0, z0) = (self.now(X), self.now(Z));
        let x_start = x0 + self.raw(24)?;
        Ok(ThreadPlan {
            x0,
            z0,
            chip,
            first: x_start + chip,
            quotient,
            passes: chips - 1,
            x_end: x_start + depth,
            z_end: z0 + self.raw(25)? + self.raw(31)?,
            thread: Thread { lead: mm(lead), speed: self.input.speed, start_angle: mm(self.raw(27)?), run_out },
        })
    }

    /// Lathe G84 and G85 (03 §2.3.4, §2.3.5): R29 − 1 roughing passes, radial
    /// (R21 = 0) or alternating between the flanks, then R23 + 1 passes at
    /// the final X. G85 cuts each pass with the run-out R22.
    fn cylindrical_thread(&mut self, run_out: bool) -> Result<(), CycleError> {
        let run_out =
            if run_out { Some(mm(self.check(22, |j| j > 0, "the run-out length must be above 0")?)) } else { None };
        let plan = self.thread_plan(run_out)?;
        // R39 = R23 counts down after each final pass; the pass repeats while R39 ≥ 0.
        let final_passes = (self.raw(23)? + 1).max(1);
        if self.raw(21)? == 0 {
            self.radial_passes(&plan, 0)?;
        } else {
            self.alternating_passes(&plan)?;
        }
        self.final_passes(&plan, final_passes, 0)
    }

    /// Lathe G87 (03 §2.3.7): as G84 with radial infeed, each pass rising by
    /// R22 in X along the thread; max(1, R23) final passes.
    fn taper_thread(&mut self) -> Result<(), CycleError> {
        let plan = self.thread_plan(None)?;
        let rise = self.raw(22)?;
        // G87 repeats while R39 > 0 where G84 tests R39 ≥ 0.
        let final_passes = self.raw(23)?.max(1);
        self.radial_passes(&plan, rise)?;
        self.final_passes(&plan, final_passes, rise)
    }

    /// The roughing passes with radial infeed: each chip R28 times the one before.
    fn radial_passes(&mut self, plan: &ThreadPlan, rise: Raw) -> Result<(), CycleError> {
        let (mut x, mut chip) = (plan.first, plan.chip);
        for _ in 0..plan.passes {
            self.thread_pass(plan, x, rise)?;
            chip = mul(chip, plan.quotient);
            x += chip;
        }
        Ok(())
    }

    /// The passes at the thread's final X.
    fn final_passes(&mut self, plan: &ThreadPlan, passes: Raw, rise: Raw) -> Result<(), CycleError> {
        check_runs(passes, 9998)?;
        for _ in 0..passes {
            self.thread_pass(plan, plan.x_end, rise)?;
        }
        Ok(())
    }

    /// One radial pass at `x`: in, along the thread (rising by `rise`), out
    /// to the start X, back to the start Z.
    fn thread_pass(&mut self, plan: &ThreadPlan, x: Raw, rise: Raw) -> Result<(), CycleError> {
        self.rapid(&[(X, x)])?;
        self.thread(&[(X, x + rise), (Z, plan.z_end)], plan.thread)?;
        self.rapid(&[(X, plan.x0)])?;
        self.rapid(&[(Z, plan.z0)])
    }

    /// The alternating infeed of G84/G85 (03 §2.3.4): each depth is cut
    /// twice, started P − R19 before and after Z0, P the metric flank shift
    /// tan 30° · (0.6134 · lead − radial depth), as the file computes it:
    /// (34 · lead − |55.426 · T|) / 96. After R29 − R21 depths (at least one)
    /// the passes are single, radial and at Z0.
    fn alternating_passes(&mut self, plan: &ThreadPlan) -> Result<(), CycleError> {
        let lead = self.raw(26)?;
        let mut allowance = self.raw(19)?;
        let mut counter = plan.passes + 1 - self.raw(21)?;
        let constant = mul(34_000, lead);
        // Anything but 0: the file's R20=69999.999 makes the first depth
        // compute the shift, and a shift of 0 is never computed again.
        let mut shift = MAX_RAW;
        let mut alternate = true;
        let (mut x, mut chip, mut depth) = (plan.first, plan.chip, plan.chip);
        for _ in 0..plan.passes {
            if shift != 0 {
                // Diameter files halve the depth with a binary shift (R32 = −1),
                // which rounds down.
                let radial = if self.input.diameter { depth >> 1 } else { depth };
                shift = div(constant - mul(55_426, radial).abs(), 96_000);
            }
            let offset = shift - allowance;
            self.rapid(&[(X, x), (Z, plan.z0 - offset)])?;
            self.thread(&[(Z, plan.z_end)], plan.thread)?;
            self.rapid(&[(X, plan.x0)])?;
            self.rapid(&[(Z, plan.z0)])?;
            if alternate {
                self.rapid(&[(X, x), (Z, plan.z0 + offset)])?;
                self.thread(&[(Z, plan.z_end)], plan.thread)?;
                self.rapid(&[(X, plan.x0)])?;
            }
            chip = mul(chip, plan.quotient);
            depth += chip;
            x += chip;
            counter -= 1;
            if counter <= 0 && alternate {
                (alternate, shift, allowance) = (false, 0, 0);
            }
            self.rapid(&[(Z, plan.z0)])?;
        }
        Ok(())
    }

    /// Lathe G86 (03 §2.3.6): passes parallel to the chamfer |R30| × |R31| at
    /// the corner start + (R24, R25), each an incremental triangle from the
    /// start point: rapid out in X, feed back in X while moving in Z, rapid
    /// back in Z. The depth grows by |R28| per pass up to |R30|, which is cut
    /// last; only R24 and R25 give directions.
    fn chamfer(&mut self) -> Result<(), CycleError> {
        let feed = self.modal_feed()?;
        let (offset_x, offset_z) = (self.raw(24)?, self.raw(25)?);
        let thickness = self.check(28, |t| t != 0, "the chip thickness must not be 0")?.abs();
        let length_x = self.check(30, |d| d != 0, "the chamfer's X length must not be 0")?.abs();
        let length_z = self.check(31, |d| d != 0, "the chamfer's Z length must not be 0")?.abs();
        check_runs(length_x / thickness, 9998)?;
        let sign_x = if offset_x < 0 { -1 } else { 1 };
        let sign_z = if offset_z < 0 { -1 } else { 1 };
        let (offset_x, offset_z) = (offset_x.abs(), offset_z.abs());
        // A = Zp·Dx/Dz + Xp and B = Xp·Dz/Dx + Zp: the chamfer's line, extended
        // to the start point's lines.
        let reach_x = div(mul(offset_z, length_x), length_z) + offset_x;
        let reach_z = div(mul(offset_x, length_z), length_x) + offset_z;
        let (x0, z0) = (self.now(X), self.now(Z));
        let (mut depth, mut last) = (thickness, false);
        loop {
            let depth_z = div(mul(depth, length_z), length_x);
            let (dx, dz) = (sign_x * (reach_x + depth), sign_z * (reach_z + depth_z));
            self.rapid(&[(X, x0 + dx)])?;
            self.feed(&[(X, x0), (Z, z0 + dz)], feed)?;
            self.rapid(&[(Z, z0)])?;
            if last {
                return Ok(());
            }
            depth += thickness;
            if depth > length_x {
                (depth, last) = (length_x, true);
            }
        }
    }
}

/// The files loop with `G73 … Q9998` (or Q9999): a section runs at most
/// Q + 1 times.
fn check_runs(runs: Raw, q: Raw) -> Result<(), CycleError> {
    if runs > q + 1 { Err(CycleError::TooManyPasses { passes: runs, limit: q + 1 }) } else { Ok(()) }
}

/// Raw thousandths in mm.
fn mm(raw: Raw) -> f64 {
    raw as f64 / 1000.0
}

/// a · b as real arithmetic computes it: rounded to a thousandth.
fn mul(a: Raw, b: Raw) -> Raw {
    round_div(i128::from(a) * i128::from(b), 1000)
}

/// a / b as real arithmetic computes it; b ≠ 0.
fn div(a: Raw, b: Raw) -> Raw {
    round_div(i128::from(a) * 1000, i128::from(b))
}

/// n / d rounded to the nearest integer, halves away from zero. The callers'
/// operands are at most ±69999.999 times a few thousand passes, far inside
/// an i64.
fn round_div(n: i128, d: i128) -> Raw {
    let (q, r) = (n / d, n % d);
    let q = if 2 * r.abs() >= d.abs() { q + n.signum() * d.signum() } else { q };
    q as Raw
}

#[cfg(test)]
mod tests;
