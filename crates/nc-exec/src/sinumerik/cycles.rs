//! Sinumerik's drilling cycles CYCLE81–CYCLE89 and CYCLE840 as moves, and
//! the swivel cycle CYCLE800 as a frame.
//!
//! ```text
//! let hole = Hole { position: [10.0, 20.0, 50.0], plane: Plane::XY, feed: 300.0, spindle: 1000.0 };
//! let moves = drilling("CYCLE81", &[Some(10.0), Some(0.0), Some(2.0), Some(-20.0)], &hole)?;
//! // [Rapid([10, 20, 2]), Feed { to: [10, 20, -20], feed: 300 }, Rapid([10, 20, 10])]
//! let swivel = swivel(&[Some(0.0), None, Some(0.0), Some(57.0), …, Some(45.0), …])?;
//! swivel.apply_to(&mut frame);
//! ```
//!
//! Which argument sits where comes from the catalogue's cycle entries
//! (`data/sinumerik/cycles.toml`); arguments after the ones it lists (later
//! software versions add some) are not read. The thesis uses only
//! CYCLE800 and explains none of the cycles' arguments (004:3298-3302), so
//! what the cycles do is Siemens documentation recalled (the classic
//! 840D cycles), and these readings are the project's:
//! - an omitted argument is zero, as for any procedure (004:1480-1484);
//! - the hole is drilled at the tool's position in the plane, along the
//!   tool axis (Z under G17, Y under G18, X under G19) towards its
//!   negative side; RTP, RFP and DP are positions on that axis. The tool
//!   first goes at rapid to the reference plane plus the safety distance
//!   and ends at rapid on the retraction plane;
//! - the final depth is DP when the call writes it, else RFP − DPR (the
//!   catalogue's reading); FDEP and FDPR of CYCLE83 likewise. A depth not
//!   below RFP, a retraction plane below RFP and a negative SDIS are
//!   refused, naming the argument;
//! - CYCLE83 (deep hole): the first step goes to FDEP at F·FRF (FRF 0 is
//!   1), each following one is DAM shorter, but not shorter than DAM,
//!   until DP; without a first depth one step drills to DP. VARI=0 breaks
//!   the chip by going back 1 mm at the feed after each step; VARI=1
//!   removes it by going out at rapid to the reference plane plus the
//!   safety distance, dwelling DTS there, and coming back at rapid to an
//!   anticipation distance above the depth reached (0.6 mm up to 30 mm of
//!   depth, else 1/50 of it, at most 7 mm). DTB dwells at the final depth;
//! - CYCLE84 (rigid tapping): the spindle stops oriented at POSS, the tap
//!   goes in at the pitch (MPIT, a metric thread size, else PIT; a negative
//!   one cuts left-handed) at SST (0: the speed in force), dwells DTB and
//!   comes out with the spindle reversed at SST1 (0: SST) to the reference
//!   plane plus the safety distance; SDAC (3, 4, 5) sets the spindle after
//!   the cycle at the speed in force;
//! - CYCLE85 feeds in at FFR, dwells DTB and out at RFF; CYCLE89 the same at
//!   F; CYCLE86 feeds in at F, dwells, stops the spindle oriented at POSS,
//!   lifts off by RPA, RPO (in the plane) and RPAP (along the tool axis) at
//!   rapid, goes out at rapid, back over the hole and restarts the spindle
//!   in SDIR; CYCLE87 and CYCLE88 feed in (CYCLE88 dwells), stop the
//!   spindle and the program, and after the operator's start go out at
//!   rapid and restart the spindle in SDIR. CYCLE86–CYCLE88 also start the
//!   spindle in SDIR before they drill;
//! - CYCLE840 (tapping in a compensating chuck) taps along AXN's axis (0:
//!   the plane's tool axis): with an encoder (ENC=0) at the pitch as
//!   CYCLE84 does, at the spindle speed in force; without (ENC=1) at the
//!   feed F, reversing the spindle at the bottom. The return turns as SDR
//!   says (0: reversed), and SDAC sets the spindle after it;
//!
//! CYCLE800 ([`swivel`]) turns the working plane: it translates to the
//! reference point (_X0, _Y0, _Z0), turns by _A, _B, _C and translates to
//! the zero point after the turn (_X1, _Y1, _Z1). Its modes (Siemens
//! documentation recalled): _ST's units digit 0 makes a new swivel, 1 adds
//! to the one in force; _MODE's two high bits choose axis by axis (0) or
//! solid angles (64: about Z by _A, then about the turned Y by _B), and
//! axis by axis its low bits name the axes in order, two bits each from
//! the lowest (1 X, 2 Y, 3 Z: 57 is X, Y, Z; 0 is taken as 57).
//! Projection angles (128) and direct rotary positions (192) need the
//! machine's kinematics and are refused. The retraction before the swivel
//! (_FR, _FR_I), the swivel data record (_TC), the direction (_DIR) and the
//! display (_DMODE) do not change the frame and are not read. A new swivel
//! with no turn and no offsets clears the frame.

use std::fmt;

use ncc_catalog::{CycleArgument, Dialect};

use super::frames::{FrameKind, Plane, ProgrammableFrame};

/// Where and how a drilling cycle starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hole {
    /// The tool's position, X, Y and Z in program coordinates: the hole's
    /// centre in the plane.
    pub position: [f64; 3],
    pub plane: Plane,
    /// The feed F in force, mm/min.
    pub feed: f64,
    /// The spindle speed in force, rpm, negative under M4.
    pub spindle: f64,
}

/// One move or action of a cycle; points are X, Y, Z in program
/// coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CycleMove {
    Rapid([f64; 3]),
    /// At `feed` mm/min.
    Feed {
        to: [f64; 3],
        feed: f64,
    },
    /// Synchronised with the spindle at `lead` mm per revolution and `rpm`
    /// (negative: M4).
    Tap {
        to: [f64; 3],
        lead: f64,
        rpm: f64,
    },
    /// Seconds.
    Dwell(f64),
    Spindle(SpindleAction),
    /// The program stops until the operator starts it again (M0).
    ProgramStop,
}

/// What a cycle does to the spindle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpindleAction {
    /// Turns at `rpm`, negative under M4.
    Turn(f64),
    Stop,
    /// Stops at the angle in degrees (SPOS).
    Orient(f64),
}

/// Why a cycle call is refused: the argument at fault (its index in the
/// call and its name) where one is.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleError {
    pub cycle: String,
    pub argument: Option<(usize, &'static str)>,
    pub problem: String,
}

impl fmt::Display for CycleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.argument {
            Some((_, name)) => write!(f, "{} {name}: {}", self.cycle, self.problem),
            None => write!(f, "{}: {}", self.cycle, self.problem),
        }
    }
}

impl std::error::Error for CycleError {}

/// The most steps of CYCLE83, against a first depth or degression too
/// small for the hole.
pub const MAX_PECKS: usize = 10_000;

/// How far CYCLE83 goes back to break the chip (VARI=0), mm.
const CHIP_BREAK: f64 = 1.0;

/// A call's arguments by the catalogue's names.
struct Arguments<'a> {
    cycle: &'static str,
    names: &'static [CycleArgument],
    values: &'a [Option<f64>],
}

impl<'a> Arguments<'a> {
    fn of(name: &str, values: &'a [Option<f64>]) -> Result<Arguments<'a>, CycleError> {
        let cycle = Dialect::Sinumerik.catalogue().cycles_for(name).next().ok_or_else(|| CycleError {
            cycle: name.to_ascii_uppercase(),
            argument: None,
            problem: "is not a cycle of the catalogue".into(),
        })?;
        let arguments = Arguments { cycle: &cycle.code, names: &cycle.arguments, values };
        for (argument, value) in arguments.names.iter().zip(values) {
            if value.is_some_and(|value| !value.is_finite()) {
                return arguments.refuse(&argument.name, "has no finite value");
            }
        }
        Ok(arguments)
    }

    fn index(&self, name: &str) -> Option<(usize, &'static str)> {
        self.names.iter().enumerate().find(|(_, argument)| argument.name == name).map(|(i, a)| (i, a.name.as_str()))
    }

    /// The value written for `name`, `None` where omitted.
    fn written(&self, name: &str) -> Option<f64> {
        self.index(name).and_then(|(index, _)| self.values.get(index).copied().flatten())
    }

    /// The value of `name`, zero where omitted.
    fn value(&self, name: &str) -> f64 {
        self.written(name).unwrap_or(0.0)
    }

    fn error(&self, name: &str, problem: impl Into<String>) -> CycleError {
        CycleError { cycle: self.cycle.to_owned(), argument: self.index(name), problem: problem.into() }
    }

    fn refuse<T>(&self, name: &str, problem: impl Into<String>) -> Result<T, CycleError> {
        Err(self.error(name, problem))
    }

    /// An absolute depth, else the reference plane less a relative one.
    fn depth(&self, absolute: &str, relative: &str, reference: f64) -> Option<(f64, &'static str)> {
        match (self.written(absolute), self.written(relative)) {
            (Some(depth), _) => Some((depth, self.index(absolute)?.1)),
            (None, Some(below)) => Some((reference - below, self.index(relative)?.1)),
            (None, None) => None,
        }
    }

    /// A spindle direction argument: 3 (M3) or 4 (M4) as the sign of `rpm`.
    fn direction(&self, name: &str, rpm: f64) -> Result<f64, CycleError> {
        match self.value(name) {
            3.0 => Ok(rpm.abs()),
            4.0 => Ok(-rpm.abs()),
            other => self.refuse(name, format!("is {other}, not 3 (M3) or 4 (M4)")),
        }
    }
}

/// The planes of a hole along the tool axis.
struct Planes {
    retraction: f64,
    /// The reference plane plus the safety distance.
    safety: f64,
    reference: f64,
    depth: f64,
}

impl Planes {
    fn of(arguments: &Arguments<'_>) -> Result<Planes, CycleError> {
        let (retraction, reference, safety) = (arguments.value("RTP"), arguments.value("RFP"), arguments.value("SDIS"));
        if safety < 0.0 {
            return arguments
                .refuse("SDIS", format!("{safety} is negative: the safety distance is written without sign"));
        }
        if retraction < reference {
            return arguments.refuse("RTP", format!("{retraction} lies below the reference plane RFP {reference}"));
        }
        let Some((depth, name)) = arguments.depth("DP", "DPR", reference) else {
            return arguments.refuse("DP", "no final depth: the call writes neither DP nor DPR");
        };
        if depth >= reference {
            return arguments
                .refuse(name, format!("the final depth {depth} is not below the reference plane RFP {reference}"));
        }
        Ok(Planes { retraction, safety: reference + safety, reference, depth })
    }
}

/// What a drilling cycle does, by its moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Drilling {
    /// CYCLE81, CYCLE82: in at the feed (and a dwell).
    Drill,
    /// CYCLE83.
    DeepHole,
    /// CYCLE84, rigid.
    Tap,
    /// CYCLE840, in a compensating chuck.
    FloatingTap,
    /// CYCLE85: in and out at feeds of its own.
    Bore,
    /// CYCLE86: out at rapid, lifted off the wall.
    BoreLiftingOff,
    /// CYCLE87, CYCLE88: the operator takes the tool out.
    BoreForTheOperator,
    /// CYCLE89: in and out at the feed.
    BoreAtTheFeed,
}

impl Drilling {
    fn of(code: &str) -> Option<Drilling> {
        Some(match code {
            "CYCLE81" | "CYCLE82" => Drilling::Drill,
            "CYCLE83" => Drilling::DeepHole,
            "CYCLE84" => Drilling::Tap,
            "CYCLE840" => Drilling::FloatingTap,
            "CYCLE85" => Drilling::Bore,
            "CYCLE86" => Drilling::BoreLiftingOff,
            "CYCLE87" | "CYCLE88" => Drilling::BoreForTheOperator,
            "CYCLE89" => Drilling::BoreAtTheFeed,
            _ => return None,
        })
    }
}

/// The moves of the drilling cycle `name` (CYCLE81–CYCLE89, CYCLE840) called with
/// `arguments` at `hole`.
pub fn drilling(name: &str, arguments: &[Option<f64>], hole: &Hole) -> Result<Vec<CycleMove>, CycleError> {
    let arguments = Arguments::of(name, arguments)?;
    let Some(kind) = Drilling::of(arguments.cycle) else {
        return Err(CycleError {
            cycle: arguments.cycle.to_owned(),
            argument: None,
            problem: "is not a drilling cycle".into(),
        });
    };
    let planes = Planes::of(&arguments)?;
    let axis = match kind {
        Drilling::FloatingTap => match arguments.value("AXN") {
            0.0 => hole.plane.axes()[2],
            axis @ (1.0 | 2.0 | 3.0) => axis as usize - 1,
            other => return arguments.refuse("AXN", format!("is {other}, not 1, 2 or 3 (X, Y, Z) or 0 (the plane's)")),
        },
        _ => hole.plane.axes()[2],
    };
    let at = |height: f64| {
        let mut point = hole.position;
        point[axis] = height;
        point
    };
    let feed = || match hole.feed > 0.0 {
        true => Ok(hole.feed),
        false => Err(CycleError {
            cycle: arguments.cycle.to_owned(),
            argument: None,
            problem: "needs a feed F above 0".into(),
        }),
    };
    let mut moves = vec![CycleMove::Rapid(at(planes.safety))];
    let (bottom, top) = (at(planes.depth), at(planes.safety));
    match kind {
        Drilling::Drill => {
            moves.push(CycleMove::Feed { to: bottom, feed: feed()? });
            dwell(&arguments, "DTB", &mut moves)?;
        }
        Drilling::DeepHole => deep_hole(&arguments, &planes, feed()?, &at, &mut moves)?,
        Drilling::Tap => {
            let lead = pitch(&arguments)?;
            let rpm = |name: &str, or: f64| match arguments.value(name) {
                0.0 => or,
                rpm => rpm.abs(),
            };
            let into = rpm("SST", hole.spindle.abs()) * lead.signum();
            if into == 0.0 {
                return arguments.refuse("SST", "no spindle speed: SST is 0 and no speed is in force");
            }
            let out = -rpm("SST1", into.abs()) * lead.signum();
            moves.push(CycleMove::Spindle(SpindleAction::Orient(arguments.value("POSS"))));
            moves.push(CycleMove::Tap { to: bottom, lead: lead.abs(), rpm: into });
            dwell(&arguments, "DTB", &mut moves)?;
            moves.push(CycleMove::Tap { to: top, lead: lead.abs(), rpm: out });
        }
        Drilling::FloatingTap => {
            let (into, moving) = match arguments.value("ENC") {
                0.0 => {
                    let lead = pitch(&arguments)?;
                    (hole.spindle.abs() * lead.signum(), Some(lead.abs()))
                }
                1.0 => (hole.spindle, None),
                other => return arguments.refuse("ENC", format!("is {other}, not 0 (with an encoder) or 1 (without)")),
            };
            if into == 0.0 {
                return Err(CycleError {
                    cycle: arguments.cycle.to_owned(),
                    argument: None,
                    problem: "needs the spindle turning".into(),
                });
            }
            let out = match arguments.value("SDR") {
                0.0 => -into,
                3.0 | 4.0 => arguments.direction("SDR", into)?,
                other => return arguments.refuse("SDR", format!("is {other}, not 0 (reversed), 3 (M3) or 4 (M4)")),
            };
            match moving {
                Some(lead) => {
                    moves.push(CycleMove::Tap { to: bottom, lead, rpm: into });
                    dwell(&arguments, "DTB", &mut moves)?;
                    moves.push(CycleMove::Tap { to: top, lead, rpm: out });
                }
                None => {
                    let feed = feed()?;
                    moves.push(CycleMove::Feed { to: bottom, feed });
                    dwell(&arguments, "DTB", &mut moves)?;
                    moves.extend([CycleMove::Spindle(SpindleAction::Turn(out)), CycleMove::Feed { to: top, feed }]);
                }
            }
        }
        Drilling::Bore => {
            let rate = |name| match arguments.value(name) {
                rate if rate > 0.0 => Ok(rate),
                rate => arguments.refuse(name, format!("{rate} is not a feed above 0")),
            };
            let (inward, outward) = (rate("FFR")?, rate("RFF")?);
            moves.push(CycleMove::Feed { to: bottom, feed: inward });
            dwell(&arguments, "DTB", &mut moves)?;
            moves.push(CycleMove::Feed { to: top, feed: outward });
        }
        Drilling::BoreLiftingOff => {
            let turn = arguments.direction("SDIR", hole.spindle)?;
            moves.insert(0, CycleMove::Spindle(SpindleAction::Turn(turn)));
            moves.push(CycleMove::Feed { to: bottom, feed: feed()? });
            dwell(&arguments, "DTB", &mut moves)?;
            moves.push(CycleMove::Spindle(SpindleAction::Orient(arguments.value("POSS"))));
            let [abscissa, ordinate, _] = hole.plane.axes();
            let mut lifted = bottom;
            lifted[abscissa] += arguments.value("RPA");
            lifted[ordinate] += arguments.value("RPO");
            lifted[axis] += arguments.value("RPAP");
            moves.push(CycleMove::Rapid(lifted));
            lifted[axis] = planes.retraction;
            moves.push(CycleMove::Rapid(lifted));
            moves.push(CycleMove::Rapid(at(planes.retraction)));
            moves.push(CycleMove::Spindle(SpindleAction::Turn(turn)));
            return Ok(moves);
        }
        Drilling::BoreForTheOperator => {
            let turn = arguments.direction("SDIR", hole.spindle)?;
            moves.insert(0, CycleMove::Spindle(SpindleAction::Turn(turn)));
            moves.push(CycleMove::Feed { to: bottom, feed: feed()? });
            dwell(&arguments, "DTB", &mut moves)?;
            moves.extend([CycleMove::Spindle(SpindleAction::Stop), CycleMove::ProgramStop]);
            moves.extend([CycleMove::Rapid(at(planes.retraction)), CycleMove::Spindle(SpindleAction::Turn(turn))]);
            return Ok(moves);
        }
        Drilling::BoreAtTheFeed => {
            let feed = feed()?;
            moves.push(CycleMove::Feed { to: bottom, feed });
            dwell(&arguments, "DTB", &mut moves)?;
            moves.push(CycleMove::Feed { to: top, feed });
        }
    }
    moves.push(CycleMove::Rapid(at(planes.retraction)));
    if matches!(kind, Drilling::Tap | Drilling::FloatingTap) {
        let after = match arguments.value("SDAC") {
            3.0 => SpindleAction::Turn(hole.spindle.abs()),
            4.0 => SpindleAction::Turn(-hole.spindle.abs()),
            5.0 => SpindleAction::Stop,
            other => return arguments.refuse("SDAC", format!("is {other}, not 3 (M3), 4 (M4) or 5 (M5)")),
        };
        moves.push(CycleMove::Spindle(after));
    }
    Ok(moves)
}

/// CYCLE83's steps from the reference plane plus the safety distance down
/// to the final depth, each followed by its chip breaking or removal.
fn deep_hole(
    arguments: &Arguments<'_>,
    planes: &Planes,
    feed: f64,
    at: &dyn Fn(f64) -> [f64; 3],
    moves: &mut Vec<CycleMove>,
) -> Result<(), CycleError> {
    let degression = arguments.value("DAM");
    if degression < 0.0 {
        return arguments.refuse("DAM", format!("{degression} is negative: the degression is written without sign"));
    }
    let factor = match arguments.value("FRF") {
        0.0 => 1.0,
        factor if (0.001..=1.0).contains(&factor) => factor,
        factor => return arguments.refuse("FRF", format!("{factor} is not a feed factor from 0.001 to 1")),
    };
    let removal = match arguments.value("VARI") {
        0.0 => false,
        1.0 => true,
        other => return arguments.refuse("VARI", format!("is {other}, not 0 (chip breaking) or 1 (chip removal)")),
    };
    let first = match arguments.depth("FDEP", "FDPR", planes.reference) {
        Some((first, name)) if first >= planes.reference => {
            return arguments.refuse(
                name,
                format!("the first depth {first} is not below the reference plane RFP {}", planes.reference),
            );
        }
        Some((first, _)) => first.max(planes.depth),
        None => planes.depth,
    };
    let total = planes.reference - planes.depth;
    let anticipation = if total <= 30.0 { 0.6 } else { (total / 50.0).min(7.0) };
    let mut step = planes.reference - first;
    let mut reached = first;
    moves.push(CycleMove::Feed { to: at(first), feed: feed * factor });
    for _ in 1..MAX_PECKS {
        if reached <= planes.depth {
            dwell(arguments, "DTB", moves)?;
            return Ok(());
        }
        if removal {
            moves.push(CycleMove::Rapid(at(planes.safety)));
            dwell(arguments, "DTS", moves)?;
            moves.push(CycleMove::Rapid(at(reached + anticipation)));
        } else {
            moves.push(CycleMove::Feed { to: at(reached + CHIP_BREAK), feed });
        }
        if degression > 0.0 {
            step = (step - degression).max(degression);
        }
        reached = (reached - step).max(planes.depth);
        moves.push(CycleMove::Feed { to: at(reached), feed });
    }
    let name = if arguments.written("FDEP").is_some() { "FDEP" } else { "FDPR" };
    arguments.refuse(name, format!("the steps would drill the hole in more than {MAX_PECKS}"))
}

/// The dwell of the argument `name` in seconds, where it is not zero.
fn dwell(arguments: &Arguments<'_>, name: &str, moves: &mut Vec<CycleMove>) -> Result<(), CycleError> {
    match arguments.value(name) {
        seconds if seconds < 0.0 => arguments.refuse(name, format!("{seconds} is not a dwell in seconds")),
        0.0 => Ok(()),
        seconds => {
            moves.push(CycleMove::Dwell(seconds));
            Ok(())
        }
    }
}

/// The ISO metric coarse pitches of M3 to M48 (ISO 261), which MPIT names.
const METRIC_PITCHES: [(f64, f64); 21] = [
    (3.0, 0.5),
    (4.0, 0.7),
    (5.0, 0.8),
    (6.0, 1.0),
    (8.0, 1.25),
    (10.0, 1.5),
    (12.0, 1.75),
    (14.0, 2.0),
    (16.0, 2.0),
    (18.0, 2.5),
    (20.0, 2.5),
    (22.0, 2.5),
    (24.0, 3.0),
    (27.0, 3.0),
    (30.0, 3.5),
    (33.0, 3.5),
    (36.0, 4.0),
    (39.0, 4.0),
    (42.0, 4.5),
    (45.0, 4.5),
    (48.0, 5.0),
];

/// CYCLE84's pitch in mm with the thread's hand as its sign: MPIT's size
/// where written, else PIT.
fn pitch(arguments: &Arguments<'_>) -> Result<f64, CycleError> {
    match (arguments.value("MPIT"), arguments.value("PIT")) {
        (0.0, 0.0) => arguments.refuse("PIT", "no pitch: the call writes neither MPIT nor PIT"),
        (0.0, pitch) => Ok(pitch),
        (size, _) => match METRIC_PITCHES.iter().find(|(nominal, _)| *nominal == size.abs()) {
            Some((_, pitch)) => Ok(pitch * size.signum()),
            None => arguments.refuse("MPIT", format!("{size} is not a metric thread size M3 to M48")),
        },
    }
}

/// A swivel of the working plane, as CYCLE800 programs it.
#[derive(Debug, Clone, PartialEq)]
pub struct Swivel {
    /// Adds to the frame in force, rather than replacing it.
    pub additive: bool,
    /// The reference point the turn is about, X, Y, Z.
    pub reference: [f64; 3],
    /// The turns in order: the axis (0 = X) and the angle in degrees, each
    /// about the axis as the turns before left it.
    pub turns: Vec<(usize, f64)>,
    /// The zero point after the turn, in the turned axes.
    pub zero: [f64; 3],
}

impl Swivel {
    /// Puts the swivel into `frame`: replacing it, or on top of it.
    pub fn apply_to(&self, frame: &mut ProgrammableFrame) {
        if !self.additive {
            *frame = ProgrammableFrame::default();
        }
        frame.compose(FrameKind::Translation, self.reference.map(Some));
        for &(axis, angle) in &self.turns {
            let mut values = [None; 3];
            values[axis] = Some(angle);
            frame.compose(FrameKind::Rotation, values);
        }
        frame.compose(FrameKind::Translation, self.zero.map(Some));
    }
}

/// The swivel CYCLE800 programs with `arguments` (the swivel data record
/// _TC, a string, is not read: `None` will do).
pub fn swivel(arguments: &[Option<f64>]) -> Result<Swivel, CycleError> {
    let arguments = Arguments::of("CYCLE800", arguments)?;
    let additive = match arguments.value("_ST") % 10.0 {
        0.0 => false,
        1.0 => true,
        _ => return arguments.refuse("_ST", "must end in 0 (a new swivel) or 1 (an additive one)"),
    };
    let mode = match arguments.value("_MODE") {
        0.0 => 57,
        mode if mode.fract() == 0.0 && (0.0..256.0).contains(&mode) => mode as u32,
        mode => return arguments.refuse("_MODE", format!("{mode} is not a mode from 0 to 255")),
    };
    let angles = ["_A", "_B", "_C"].map(|name| arguments.value(name));
    let turns = match mode & 0xC0 {
        0x00 => {
            let axes: Vec<u32> = (0..3).map(|turn| (mode >> (2 * turn)) & 3).collect();
            if axes.contains(&0) || (1..=3).any(|axis| axes.iter().filter(|&&a| a == axis).count() > 1) {
                return arguments
                    .refuse("_MODE", format!("{mode} does not name each of X, Y and Z once in its low bits"));
            }
            axes.iter().zip(angles).map(|(&axis, angle)| (axis as usize - 1, angle)).collect()
        }
        0x40 => vec![(2, angles[0]), (1, angles[1])],
        _ => {
            return arguments.refuse(
                "_MODE",
                format!("{mode}: projection angles and direct rotary positions need the machine's kinematics"),
            );
        }
    };
    let point = |names: [&str; 3]| names.map(|name| arguments.value(name));
    Ok(Swivel { additive, reference: point(["_X0", "_Y0", "_Z0"]), turns, zero: point(["_X1", "_Y1", "_Z1"]) })
}

#[cfg(test)]
mod tests;
