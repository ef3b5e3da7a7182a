//! The CNC8x9 envelope velocity: speed planning up to 500 blocks ahead
//! with a linear (trapezoidal) or parabolic (jerk-limited) speed profile
//! (04 §1.9, §1.10), as a streaming planner of its own.
//!
//! Every junction between two moves gets a cap from the criteria of the
//! manual: a lower programmed speed, the arc limits, the minimum block
//! duration of 4 ms, the accuracy criterion (R384) and the dynamic
//! criterion (R385), or a stop the caller decides (G00, G98/G24, a block
//! without motion, R39, axes beyond the third). Over the window of planned
//! moves a backward pass keeps every junction within what the moves after
//! it can still stop from (the window's end stops), and a forward pass
//! within what the moves before it can reach. A ramp over several blocks is
//! one section, reached from the cap where it starts (04 §1.10: the control
//! "groups the blocks into sections"), so short blocks run at the
//! programmed speed once the look-ahead covers the ramps.
//!
//! [`Envelope::of`] reads the machine; [`Planner`] takes the moves one at a
//! time and hands them back planned, in order, holding at most the
//! look-ahead depth.

use std::collections::VecDeque;

use crate::{ramp::Ramp, trace::shift_count};

/// A move's speed through it, in mm/min: at its start, its highest, and at
/// its end; with its duration in seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Profile {
    pub entry: f64,
    pub peak: f64,
    pub exit: f64,
    pub duration: f64,
}

/// The control plans at most this many blocks ahead (04 §1.9).
pub const MAX_DEPTH: usize = 500;
/// The default geometric criterion on arcs: chords within 1 µm of the
/// circle per tick (04 §1.11); R232, which may change it, is not decoded.
const CHORD_ERROR: f64 = 0.001;
/// Speeds (mm/s) are kept within these so that every duration is finite.
const SPEED_RANGE: (f64, f64) = (1e-6, 1e9);
/// The parabolic ramp P as a jerk: J = P / 32.768 mm/s³ reproduces both of
/// the manual's A7.1 formulas, T = 1.478·sqrt(F/P) and A < sqrt(Fmax·P/1966)
/// (04 §1.10).
pub(crate) const P_PER_JERK: f64 = 32.768;

/// How speed changes: linearly (R338 decade 2 = 1) or parabolically, with
/// limited jerk (decade 2 = 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileKind {
    Linear,
    Parabolic,
}

/// One dynamic set (R406–R429), or the constants that stand for it when the
/// sets are off: R236, R384, R385.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicSet {
    pub ramp: Ramp,
    /// Accuracy criterion Lm in mm (R384/R409 decades 1–4 are µm); 0 is off.
    pub accuracy: f64,
    /// Dynamic (overload) criterion am in mm/s² (R385/R410 decades 1–7); 0 is off.
    pub overload: f64,
    /// Highest centrifugal acceleration on arcs in mm/s² (R411 new method,
    /// entered ×10); 0 is none.
    pub centrifugal: f64,
}

/// The envelope velocity of a machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    pub profile: ProfileKind,
    /// Moves planned at a time, the current one included (1 to 500).
    pub depth: usize,
    /// The interpolator tick Ts in seconds.
    pub tick: f64,
    /// The shortest block duration (s): a move runs at most at length / it.
    pub min_duration: f64,
    /// R382 in mm: a shorter feed move runs from a stop to a stop; 0 is off.
    pub short_block: f64,
    /// R383 in mm: a shorter mergeable move joins its neighbour; 0 is off.
    pub merge_below: f64,
    /// R395 in seconds: when a move does not rise above its junction speeds.
    pub hold_time: f64,
    /// Sets 1 to 4 (G23 I1 … I4).
    pub sets: [DynamicSet; 4],
    /// Ramps of rapid moves: R237, or the set R430–R432.
    pub rapid: Ramp,
    /// Ramps of feed moves outside continuity: R52.
    pub basic: Ramp,
}

/// What a move is to the planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MoveKind {
    /// G01/G02/G03.
    Feed,
    /// G00: stops at both ends.
    Rapid,
    /// G33: runs at its speed without ramps, from a stop to a stop.
    Thread,
    /// A dwell or a block without motion, with its own duration (s).
    Still { duration: f64 },
}

/// A move as the planner sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvelopeMove {
    /// Path length in mm.
    pub length: f64,
    /// The programmed speed in mm/s (the feed, or the rapid traverse).
    pub speed: f64,
    pub kind: MoveKind,
    /// Unit motion directions over the first three axes at the start and
    /// the end.
    pub start_direction: [f64; 3],
    pub end_direction: [f64; 3],
    /// The radius (mm) of an arc.
    pub arc_radius: Option<f64>,
    /// The junction before the move is a stop, as the caller decides: G98 or
    /// G24, a corner not below R39, axes beyond the third, a block without
    /// motion. Rapid moves, threads and still blocks stop anyway.
    pub stop_before: bool,
    /// G23 is in force: the move ramps with the continuity acceleration
    /// (R236 or its set), otherwise with R52.
    pub continuity: bool,
    /// The dynamic set, G23 I1 … I4; others are set 1.
    pub set: u8,
    /// A G01 line without technology functions, F or G91, which R383 may
    /// merge into the move before it (04 §1.9.4).
    pub mergeable: bool,
}

/// Why the speed at a junction (or through a move) is below the programmed
/// speed, as the planner knows it: the velocity model says it in the
/// control's terms, with the machine constants and the CNC8x6 stop rules
/// (`velocity::Reason`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Limit {
    /// The caller's stop, a rapid move, thread or still block at the
    /// junction, or the program's start.
    Stop,
    /// A block shorter than R382 runs from a stop to a stop.
    ShortBlock,
    /// A lower programmed speed.
    Feed,
    /// The accuracy criterion R384 at a corner of `angle` degrees.
    Accuracy {
        angle: f64,
    },
    /// The dynamic criterion R385 at a corner of `angle` degrees.
    Overload {
        angle: f64,
    },
    /// An arc: its centrifugal acceleration, or the chord error per tick.
    Centrifugal {
        radius: f64,
    },
    ChordError {
        radius: f64,
    },
    /// A move must take at least the minimum block duration (4 ms).
    MinDuration,
    /// The look-ahead ends: the last move planned must be able to stop.
    WindowEnd,
    /// The program ends.
    End,
    /// The speed is still rising after an earlier drop.
    Ramp,
}

/// A planned move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Planned {
    /// Speeds in mm/min, duration in s.
    pub profile: Profile,
    /// Why the speed at the move's end is below the lower programmed speed
    /// of it and the next move.
    pub exit_limit: Option<Limit>,
    /// Why the move runs below its programmed speed throughout.
    pub cruise_limit: Option<Limit>,
}

/// The streaming planner: [`Planner::push`] each move, then
/// [`Planner::finish`].
#[derive(Debug, Clone)]
pub struct Planner {
    envelope: Envelope,
    window: VecDeque<Slot>,
    /// The stream index of the next move pushed.
    next_index: usize,
    /// Where the last move pushed ends, in mm along the path.
    end: f64,
    tail: Option<Tail>,
    /// The speed the last move handed back ends at: where the next starts.
    entry: f64,
    finished: bool,
}

/// The speed envelope from a junction: the highest speed a ramp of `ramp`
/// reaches from `speed` at `at` (mm along the path), either way.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Anchor {
    speed: f64,
    at: f64,
    ramp: Ramp,
    limit: Limit,
}

/// A move in the window, with its junction before it.
#[derive(Debug, Clone, Copy)]
struct Slot {
    index: usize,
    kind: MoveKind,
    start: f64,
    length: f64,
    programmed: f64,
    cruise: f64,
    cruise_limit: Limit,
    ramp: Ramp,
    /// The cap at the junction before, from the criteria, and why.
    cap: f64,
    cap_limit: Limit,
    /// The backward pass: the highest speed at the junction from which the
    /// moves after it can stop, and where that comes from.
    back: f64,
    back_anchor: Anchor,
    /// The planned speed at the junction, why, and the forward envelope
    /// through the move.
    speed: f64,
    limit: Limit,
    forward: Anchor,
}

/// What the next junction needs of the last move pushed.
#[derive(Debug, Clone, Copy)]
struct Tail {
    direction: [f64; 3],
    cruise: f64,
    cruise_limit: Limit,
    /// Stops after it: not a feed move, or shorter than R382.
    stops: Option<Limit>,
}

impl Planner {
    /// The planner of a stream with `by` more moves before the ones it
    /// holds.
    pub fn shift_indices(&mut self, by: i64) {
        self.next_index = shift_count(self.next_index, by);
        self.window.iter_mut().for_each(|slot| slot.index = shift_count(slot.index, by));
    }
}

/// A section's ramps, besides a move's own ([`Ramp::change`]: the
/// manual's S-curve, 04 §1.10).
impl Ramp {
    /// The highest speed reached from `from` over `distance` mm (or the
    /// highest from which `from` is reached), starting without acceleration:
    /// the jerk raises it to A, then A holds. This is a section's ramp over
    /// several blocks; its rounding into the next speed is left to the
    /// moves' profiles.
    fn reach(&self, from: f64, distance: f64) -> f64 {
        self.section(from, distance).1
    }

    /// Seconds and the speed at `distance` mm along the section's ramp from
    /// `from` (see [`Ramp::reach`]). Under a jerk limit a slower start gains
    /// more over a short distance (the acceleration has longer to build), so
    /// a speed cap of `from` also allows the ramp from rest: the higher of
    /// the two keeps the envelope rising with its cap, which the planning
    /// passes rely on.
    fn section(&self, from: f64, distance: f64) -> (f64, f64) {
        let own = self.ramp_from(from, distance);
        if from > 0.0 && self.jerk_limited() {
            let rest = self.ramp_from(0.0, distance);
            if rest.1 > own.1 {
                return rest;
            }
        }
        own
    }

    fn ramp_from(&self, from: f64, distance: f64) -> (f64, f64) {
        if !self.limited() {
            return (0.0, f64::INFINITY);
        }
        let (a, j, v) = (self.acceleration, self.jerk, from);
        if distance <= 0.0 {
            return (0.0, from);
        }
        if !self.jerk_limited() {
            let speed = (v * v + 2.0 * a * distance).sqrt();
            return ((speed - v) / a, speed);
        }
        let knee = a / j;
        let knee_distance = v * knee + j * knee * knee * knee / 6.0;
        if distance <= knee_distance {
            // v·t + J·t³/6 = distance: Newton from above converges
            // monotonically on this convex cubic.
            let mut t = (6.0 * distance / j).cbrt();
            if v > 0.0 {
                t = t.min(distance / v);
            }
            for _ in 0..64 {
                let step = (j * t * t * t / 6.0 + v * t - distance) / (j * t * t / 2.0 + v);
                if !step.is_finite() || step <= t * 1e-15 {
                    break;
                }
                t -= step;
            }
            (t, v + j * t * t / 2.0)
        } else {
            let knee_speed = v + a * knee / 2.0;
            let speed = (knee_speed * knee_speed + 2.0 * a * (distance - knee_distance)).sqrt();
            (knee + (speed - knee_speed) / a, speed)
        }
    }
}

impl Anchor {
    fn speed_at(&self, position: f64) -> f64 {
        let distance = (position - self.at).abs();
        // At the anchor itself even one without ramps (a stop at a block
        // without motion) has its own speed.
        if distance == 0.0 { self.speed } else { self.ramp.reach(self.speed, distance) }
    }
}

/// A number that is finite and at least zero.
fn length_of(value: f64) -> f64 {
    if value.is_finite() { value.max(0.0) } else { 0.0 }
}

fn speed_of(value: f64) -> f64 {
    if value.is_nan() { SPEED_RANGE.0 } else { value.clamp(SPEED_RANGE.0, SPEED_RANGE.1) }
}

/// The angle in radians between two directions; 0 when one is unknown.
fn angle_between(before: [f64; 3], after: [f64; 3]) -> f64 {
    let norm = |v: [f64; 3]| v.iter().map(|c| c * c).sum::<f64>().sqrt();
    let norms = norm(before) * norm(after);
    if !(norms.is_finite() && norms > 0.0) {
        return 0.0;
    }
    let dot: f64 = before.iter().zip(after).map(|(a, b)| a * b).sum();
    (dot / norms).clamp(-1.0, 1.0).acos()
}

/// The corner criteria at a junction turning by `angle` radians: the
/// accuracy criterion vm = Lm / (Ts·tan(α/2)) (04 §1.9.1) and the dynamic
/// criterion vm = am·Ts / (2·sin(α/2)) (04 §1.9.2), in mm/s, with the one
/// that limits. R385's block-length correction (decade 8) is left out: the
/// manual gives no formula, and R385 is tuned at the reference length.
fn corner_cap(set: &DynamicSet, tick: f64, angle: f64) -> (f64, Limit) {
    let half = angle / 2.0;
    let degrees = angle.to_degrees();
    let mut cap = (f64::INFINITY, Limit::Feed);
    if set.accuracy > 0.0 && half.tan() > 0.0 {
        cap = (set.accuracy / (tick * half.tan()), Limit::Accuracy { angle: degrees });
    }
    if set.overload > 0.0 && half.sin() > 0.0 {
        let overload = set.overload * tick / (2.0 * half.sin());
        if overload < cap.0 {
            cap = (overload, Limit::Overload { angle: degrees });
        }
    }
    cap
}

impl Planner {
    pub fn new(envelope: Envelope) -> Planner {
        let depth = envelope.depth.clamp(1, MAX_DEPTH);
        Planner {
            envelope: Envelope { depth, ..envelope },
            window: VecDeque::with_capacity(depth),
            next_index: 0,
            end: 0.0,
            tail: None,
            entry: 0.0,
            finished: false,
        }
    }

    /// How many moves the planner holds (never more than the depth).
    #[cfg(test)]
    fn held(&self) -> usize {
        self.window.len()
    }

    /// Plans `mv` as the next move of the stream. When the window is full,
    /// the oldest move is planned for good and handed back with its index.
    pub fn push(&mut self, mv: EnvelopeMove) -> Option<(usize, Planned)> {
        let emitted = if self.window.len() >= self.envelope.depth { self.emit() } else { None };
        let slot = self.slot(&mv);
        self.end = slot.start + slot.length;
        self.window.push_back(slot);
        self.plan();
        emitted
    }

    /// Ends the stream: the remaining moves, planned to stop at the end.
    pub fn finish(mut self) -> impl Iterator<Item = (usize, Planned)> {
        self.finished = true;
        std::iter::from_fn(move || self.emit())
    }

    /// The move as a slot, with the cap of the junction before it.
    fn slot(&mut self, mv: &EnvelopeMove) -> Slot {
        let envelope = &self.envelope;
        let set = &envelope.sets[usize::from(mv.set.clamp(1, 4) - 1)];
        let mut length = length_of(mv.length);
        let programmed = speed_of(mv.speed);
        let (mut cruise, mut cruise_limit) = (programmed, Limit::Feed);
        let mut lower = |speed: f64, limit: Limit| {
            if speed < cruise {
                (cruise, cruise_limit) = (speed, limit);
            }
        };
        let feed = mv.kind == MoveKind::Feed;
        let merged = feed
            && mv.mergeable
            && !mv.stop_before
            && length < envelope.merge_below
            && self.tail.is_some_and(|tail| tail.stops.is_none());
        let (ramp, stops) = match mv.kind {
            MoveKind::Feed => {
                let ramp = if mv.continuity { set.ramp } else { envelope.basic };
                // A merged block is part of its neighbour: no limits of its own.
                if !merged && length > 0.0 {
                    lower(length / envelope.min_duration, Limit::MinDuration);
                    if let Some(radius) = mv.arc_radius.filter(|r| r.is_finite() && *r > 0.0) {
                        lower((8.0 * radius * CHORD_ERROR).sqrt() / envelope.tick, Limit::ChordError { radius });
                        if set.centrifugal > 0.0 {
                            lower((set.centrifugal * radius).sqrt(), Limit::Centrifugal { radius });
                        }
                    }
                }
                let short = !merged && length < envelope.short_block;
                (ramp, short.then_some(Limit::ShortBlock))
            }
            MoveKind::Rapid => (envelope.rapid, Some(Limit::Stop)),
            MoveKind::Thread => (Ramp::NONE, Some(Limit::Stop)),
            MoveKind::Still { .. } => {
                length = 0.0;
                cruise = 0.0;
                (Ramp::NONE, Some(Limit::Stop))
            }
        };
        let (cap, cap_limit) = match self.tail {
            None => (0.0, Limit::Stop),
            Some(_) if mv.stop_before => (0.0, Limit::Stop),
            Some(tail) => match tail.stops.or(stops) {
                Some(limit) => (0.0, limit),
                None => {
                    let mut cap =
                        if tail.cruise < cruise { (tail.cruise, tail.cruise_limit) } else { (cruise, cruise_limit) };
                    if !merged {
                        let corner = corner_cap(set, envelope.tick, angle_between(tail.direction, mv.start_direction));
                        if corner.0 < cap.0 {
                            cap = corner;
                        }
                    }
                    cap
                }
            },
        };
        let direction = match self.tail {
            Some(tail) if merged => tail.direction,
            _ => mv.end_direction,
        };
        self.tail = Some(Tail { direction, cruise, cruise_limit, stops });
        let index = self.next_index;
        self.next_index += 1;
        let start = self.end;
        // The window's first move starts where the one handed back ended.
        let anchor = Anchor { speed: self.entry, at: start, ramp, limit: cap_limit };
        Slot {
            index,
            kind: mv.kind,
            start,
            length,
            programmed,
            cruise,
            cruise_limit,
            ramp,
            cap,
            cap_limit,
            back: cap,
            back_anchor: anchor,
            speed: self.entry.min(cap),
            limit: cap_limit,
            forward: Anchor { speed: self.entry.min(cap), ..anchor },
        }
    }

    /// The backward pass from the window's end, which stops at the first
    /// junction it does not change, then the forward pass over the
    /// junctions it changed.
    fn plan(&mut self) {
        let last = self.window.len() - 1;
        let mut next = Anchor { speed: 0.0, at: self.end, ramp: self.window[last].ramp, limit: Limit::WindowEnd };
        let mut changed = last;
        for i in (0..=last).rev() {
            let slot = &mut self.window[i];
            // A ramp of other dynamics starts a section at the junction after.
            let through = if next.ramp == slot.ramp {
                next
            } else {
                let end = slot.start + slot.length;
                Anchor { speed: next.speed_at(end), at: end, ramp: slot.ramp, ..next }
            };
            let reach = through.speed_at(slot.start);
            let (back, anchor) = if slot.cap <= reach {
                (slot.cap, Anchor { speed: slot.cap, at: slot.start, ramp: slot.ramp, limit: slot.cap_limit })
            } else {
                (reach, through)
            };
            if i < last && back <= slot.back {
                break;
            }
            (slot.back, slot.back_anchor, next, changed) = (back, anchor, anchor, i);
        }
        // The first move's entry is fixed: the move before it is handed back.
        for j in changed.max(1)..=last {
            let forward = self.window[j - 1].forward;
            let slot = &mut self.window[j];
            let reach = forward.speed_at(slot.start);
            if reach < slot.back {
                slot.speed = reach;
                slot.limit = Limit::Ramp;
                slot.forward = if forward.ramp == slot.ramp {
                    forward
                } else {
                    Anchor { speed: reach, at: slot.start, ramp: slot.ramp, limit: Limit::Ramp }
                };
            } else {
                slot.speed = slot.back;
                slot.limit = slot.back_anchor.limit;
                slot.forward = Anchor { speed: slot.back, at: slot.start, ramp: slot.ramp, limit: slot.limit };
            }
        }
    }

    /// Hands back the window's first move.
    fn emit(&mut self) -> Option<(usize, Planned)> {
        let slot = self.window.pop_front()?;
        let end = if self.finished { Limit::End } else { Limit::WindowEnd };
        let end_of_move = slot.start + slot.length;
        let through = match self.window.front() {
            Some(next) if next.back_anchor.ramp == slot.ramp => next.back_anchor,
            Some(next) => Anchor { speed: next.back, at: end_of_move, ramp: slot.ramp, limit: next.limit },
            None => Anchor { speed: 0.0, at: end_of_move, ramp: slot.ramp, limit: Limit::End },
        };
        let (exit, limit, reference) = match self.window.front() {
            Some(next) if matches!(next.kind, MoveKind::Feed | MoveKind::Rapid) => {
                (next.speed, next.limit, slot.programmed.min(next.programmed))
            }
            Some(next) => (next.speed, next.limit, slot.programmed),
            None => (0.0, end, slot.programmed),
        };
        let limit = if limit == Limit::WindowEnd { end } else { limit };
        self.entry = exit;
        let profile = self.profile(&slot, &through, slot.speed, exit);
        let moving = matches!(slot.kind, MoveKind::Feed | MoveKind::Rapid);
        let planned = Planned {
            profile,
            exit_limit: (moving && exit < reference * (1.0 - 1e-9)).then_some(limit),
            cruise_limit: (moving && slot.cruise < slot.programmed).then_some(slot.cruise_limit),
        };
        Some((slot.index, planned))
    }

    /// The move's profile from `entry` to `exit` (mm/s); `through` is the
    /// backward pass's envelope through it.
    fn profile(&self, slot: &Slot, through: &Anchor, entry: f64, exit: f64) -> Profile {
        let per_minute = |speed: f64| speed * 60.0;
        let (peak, duration) = match slot.kind {
            MoveKind::Still { duration } => return Profile { duration: length_of(duration), ..Profile::default() },
            // Without ramps a thread runs at its speed from end to end.
            MoveKind::Thread => {
                let speed = per_minute(slot.cruise);
                let duration = slot.length / slot.cruise;
                return Profile { entry: speed, peak: speed, exit: speed, duration };
            }
            MoveKind::Feed | MoveKind::Rapid => self.run(slot, through, entry, exit),
        };
        Profile { entry: per_minute(entry), peak: per_minute(peak), exit: per_minute(exit), duration }
    }

    /// The peak speed and the seconds of a move from `entry` to `exit`: up to
    /// at most its cruise speed and down again within its length, unless
    /// R395 keeps it at its junction speeds.
    fn run(&self, slot: &Slot, through: &Anchor, entry: f64, exit: f64) -> (f64, f64) {
        let (ramp, length) = (&slot.ramp, slot.length);
        let low = entry.max(exit);
        let cruise = slot.cruise.max(low);
        if !ramp.limited() {
            return (cruise, length / cruise);
        }
        let distance = |peak: f64| ramp.span(entry, peak, exit).1;
        let time = |peak: f64| ramp.duration(entry, peak, exit, length);
        if distance(low) > length * (1.0 + 1e-9) + 1e-12 {
            return section(slot, through, cruise);
        }
        let peak = if distance(cruise) <= length { cruise } else { ramp.peak(entry, exit, length, cruise).max(low) };
        let rise = time(peak);
        // R395: rising within the move is not worth it when the move at its
        // junction speeds is short (linear, 04 §1.9.3) or gains little
        // against the rise (parabolic, 04 §1.10).
        if peak > low && low > 0.0 {
            let held = time(low);
            let worth = match self.envelope.profile {
                ProfileKind::Linear => held,
                ProfileKind::Parabolic => held - rise,
            };
            if worth < self.envelope.hold_time {
                return (low, held);
            }
        }
        (peak, rise)
    }
}

/// The peak speed and the seconds of a move within a section's ramps over
/// several blocks: up the forward envelope, at most at its cruise speed,
/// and down the backward one (`through`), where they cross.
fn section(slot: &Slot, through: &Anchor, cruise: f64) -> (f64, f64) {
    let (up, down) = (&slot.forward, through);
    let (start, end) = (slot.start, slot.start + slot.length);
    let rising = |s: f64| up.ramp.section(up.speed, s - up.at);
    let falling = |s: f64| down.ramp.section(down.speed, down.at - s);
    // The last point in [from, to] where `below` holds, by bisection.
    let last = |from: f64, to: f64, below: &dyn Fn(f64) -> bool| {
        if below(to) {
            return to;
        }
        let (mut low, mut high) = (from, to);
        for _ in 0..100 {
            let middle = (low + high) / 2.0;
            if below(middle) {
                low = middle
            } else {
                high = middle
            }
            if high - low <= high.abs().max(1.0) * 1e-14 {
                break;
            }
        }
        low
    };
    let cross = last(start, end, &|s| rising(s).1 <= falling(s).1);
    let top = rising(cross).1.min(falling(cross).1);
    let (climb, descent) = if top > cruise {
        (last(start, cross, &|s| rising(s).1 <= cruise), end - last(cross, end, &|s| falling(s).1 > cruise))
    } else {
        (cross, end - cross)
    };
    let descent_start = end - descent;
    let entry_exit = (slot.speed, rising(end).1.min(falling(end).1));
    let time = (rising(climb).0 - rising(start).0).abs()
        + (descent_start - climb).max(0.0) / cruise
        + (falling(descent_start).0 - falling(end).0).abs();
    let peak = top.min(cruise).max(entry_exit.0).max(entry_exit.1);
    // Near a stop the two ramps from a cap can disagree: the mean speed.
    if time.is_finite() && time > 0.0 {
        (peak, time)
    } else {
        (peak, 2.0 * slot.length / (entry_exit.0 + entry_exit.1))
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::{Envelope, EnvelopeMove, Limit, MoveKind, Planned, Planner, ProfileKind, corner_cap};
    use crate::{
        cnc8x6::dynamics,
        machine::MachineConfig,
        run::{NoFiles, run},
        velocity::time,
    };

    /// A machine with these constants (raw values) besides the defaults:
    /// R52 = 1000, R236 = 400 and R237 = 1000 mm/s², Ts = 2 ms.
    fn machine(constants: &[(u32, i64)]) -> MachineConfig {
        let mut machine = MachineConfig::default();
        machine.constants.extend(constants.iter().copied());
        machine
    }

    fn linear() -> Envelope {
        dynamics::envelope(&machine(&[(338, 10)])).unwrap()
    }

    fn parabolic() -> Envelope {
        dynamics::envelope(&machine(&[(338, 20)])).unwrap()
    }

    const X: [f64; 3] = [1.0, 0.0, 0.0];

    /// A G23 line of `length` mm at `speed` mm/s in `direction`.
    fn line(length: f64, speed: f64, direction: [f64; 3]) -> EnvelopeMove {
        EnvelopeMove {
            length,
            speed,
            kind: MoveKind::Feed,
            start_direction: direction,
            end_direction: direction,
            arc_radius: None,
            stop_before: false,
            continuity: true,
            set: 1,
            mergeable: false,
        }
    }

    /// Plans `moves` and checks that every index comes back once, in order.
    fn plan(envelope: Envelope, moves: &[EnvelopeMove]) -> Vec<Planned> {
        let mut planner = Planner::new(envelope);
        let mut planned: Vec<(usize, Planned)> = moves.iter().filter_map(|&mv| planner.push(mv)).collect();
        planned.extend(planner.finish());
        assert!(planned.iter().map(|&(index, _)| index).eq(0..moves.len()));
        planned.into_iter().map(|(_, planned)| planned).collect()
    }

    fn total(planned: &[Planned]) -> f64 {
        planned.iter().map(|p| p.profile.duration).sum()
    }

    fn close(actual: f64, expected: f64) {
        assert!((actual - expected).abs() <= expected.abs() * 1e-3, "{actual} != {expected} within 0.1%");
    }

    #[test]
    fn the_envelope_follows_r338_and_reads_the_sets() {
        assert_eq!(dynamics::envelope(&MachineConfig::default()), None);
        let envelope = linear();
        assert_eq!((envelope.profile, envelope.depth, envelope.tick), (ProfileKind::Linear, 500, 0.002));
        let set = envelope.sets[0];
        assert_eq!((set.ramp.acceleration, set.ramp.jerk), (400.0, f64::INFINITY));
        assert_eq!((set.accuracy, set.overload, envelope.hold_time), (0.008, 10_000.0, 0.5));
        // Parabolic with the sets on: set 2 has its own A and falls back to
        // set 1 for P; rapid moves take R430–R432. R411 with decade 8 = 1
        // is the centrifugal acceleration ×10.
        let sets = [(338, 20), (406, 1), (407, 10_000), (408, 800), (411, 10_004_000), (412, 1), (414, 300)];
        let envelope = dynamics::envelope(&machine(&[&sets[..], &[(430, 1), (432, 2000)]].concat())).unwrap();
        let jerk = 10_000.0 / 32.768;
        assert_eq!((envelope.sets[0].ramp.acceleration, envelope.sets[0].ramp.jerk), (800.0, jerk));
        assert_eq!((envelope.sets[1].ramp.acceleration, envelope.sets[1].ramp.jerk), (300.0, jerk));
        assert_eq!(envelope.sets[0].centrifugal, 400.0);
        assert_eq!((envelope.rapid.acceleration, envelope.rapid.jerk), (2000.0, jerk));
    }

    #[test]
    fn one_long_line_is_a_trapezoid() {
        // 100 mm at 100 mm/s with R236 = 400 mm/s²: 12.5 mm of ramp at each end.
        let planned = plan(linear(), &[line(100.0, 100.0, X)]);
        let profile = planned[0].profile;
        assert_eq!((profile.entry, profile.peak, profile.exit), (0.0, 6000.0, 0.0));
        close(profile.duration, 2.0 * 100.0 / 400.0 + (100.0 - 100.0 * 100.0 / 400.0) / 100.0);
        assert_eq!(planned[0].exit_limit, Some(Limit::End));
    }

    #[test]
    fn one_long_line_is_an_s_curve() {
        // P = 50000 (J = P/32.768) and A = 400: 200 mm/s is above A²/J, so
        // the ramps have their linear part: t = v/A + A/J + L/v.
        let (a, j, v, length) = (400.0, 50_000.0 / 32.768, 200.0, 200.0);
        let planned = plan(parabolic(), &[line(length, v, X)]);
        assert_eq!(planned[0].profile.peak, v * 60.0);
        close(planned[0].profile.duration, v / a + a / j + length / v);
    }

    #[test]
    fn a_short_move_does_not_reach_its_speed() {
        // Trapezoid: a triangle up to sqrt(A·L).
        let short = plan(linear(), &[line(1.0, 100.0, X)])[0].profile;
        close(short.peak, (400.0f64 * 1.0).sqrt() * 60.0);
        close(short.duration, 2.0 * 20.0 / 400.0);
        let (a, j): (f64, f64) = (400.0, 50_000.0 / 32.768);
        // S-curve without reaching A: two parabolas to the peak and two back,
        // L = 2·v^1.5/sqrt(J).
        let peak = (1.0 * j.sqrt() / 2.0f64).powf(2.0 / 3.0);
        assert!(peak < a * a / j);
        let short = plan(parabolic(), &[line(1.0, 200.0, X)])[0].profile;
        close(short.peak, peak * 60.0);
        close(short.duration, 4.0 * (peak / j).sqrt());
        // S-curve reaching A but not the speed: L = v·(v/A + A/J).
        let length = 100.0;
        let peak = (-a / j + ((a / j) * (a / j) + 4.0 * length / a).sqrt()) * a / 2.0;
        assert!(peak > a * a / j && peak < 200.0);
        let short = plan(parabolic(), &[line(length, 200.0, X)])[0].profile;
        close(short.peak, peak * 60.0);
        close(short.duration, 2.0 * (peak / a + a / j));
    }

    #[test]
    fn a_collinear_chain_of_short_blocks_runs_at_the_feed() {
        // 100 blocks of 1 mm at 100 mm/s: the look-ahead ramps over many
        // blocks, as one 100 mm line would.
        let chain = vec![line(1.0, 100.0, X); 100];
        let planned = plan(linear(), &chain);
        close(total(&planned), 2.0 * 100.0 / 400.0 + (100.0 - 100.0 * 100.0 / 400.0) / 100.0);
        assert_eq!(planned[50].profile.entry, 6000.0);
        // Below the feed only while rising from the start or braking for the end.
        let limits = |p: &Planned| p.exit_limit.is_none_or(|limit| matches!(limit, Limit::Ramp | Limit::End));
        assert!(planned.iter().all(limits));
        // The CNC8x6 model stops at every 10 ms block (60 ms is its shortest).
        let program: String = (1..=100).map(|x| format!("N{x} X{x}\n")).collect();
        let machine = MachineConfig::default();
        let trace = run(&format!("%1\nN101 G23 G01 F6000\n{program}M30\n"), &NoFiles, &machine, 1000);
        let cnc8x6 = time(&trace, &dynamics::dynamics(&machine)).total_time();
        assert!(cnc8x6 > 3.0 * total(&planned), "{cnc8x6}");
        // Parabolic: the sections' ramps over several blocks come within 2%
        // of one 100 mm S-curve (1.5% faster: a section's ramp is not
        // rounded into the feed).
        let (a, j): (f64, f64) = (400.0, 50_000.0 / 32.768);
        let planned = plan(parabolic(), &chain);
        let one_line = 100.0 / a + a / j + 100.0 / 100.0;
        let ratio = total(&planned) / one_line;
        assert!((0.98..1.0).contains(&ratio), "{ratio}");
        assert_eq!(planned[50].profile.entry, 6000.0);
    }

    #[test]
    fn a_corner_runs_at_the_accuracy_criterion() {
        // 45°: Lm / (Ts·tan 22.5°) with 8 µm and 2 ms is 9.66 mm/s, below
        // the dynamic criterion's 10000·Ts / (2·sin 22.5°) = 26.1 mm/s.
        let turned = [45f64.to_radians().cos(), 45f64.to_radians().sin(), 0.0];
        let planned = plan(linear(), &[line(50.0, 100.0, X), line(50.0, 100.0, turned)]);
        let speed = 0.008 / (0.002 * 22.5f64.to_radians().tan());
        close(planned[0].profile.exit, speed * 60.0);
        close(planned[1].profile.entry, speed * 60.0);
        let Some(Limit::Accuracy { angle }) = planned[0].exit_limit else { panic!("{:?}", planned[0]) };
        close(angle, 45.0);
        let ramps = |from: f64| (100.0 - from) / 400.0 + (100.0 - from) * (100.0 + from) / 2.0 / 400.0 / -100.0;
        close(total(&planned), 2.0 * (ramps(0.0) + ramps(speed) + 50.0 / 100.0));
        // With a higher accuracy limit the dynamic criterion takes over.
        let (cap, limit) = corner_cap(&linear().sets[0], 0.002, 45f64.to_radians());
        let loose = corner_cap(&super::DynamicSet { accuracy: 0.05, ..linear().sets[0] }, 0.002, 45f64.to_radians());
        assert_eq!(limit, Limit::Accuracy { angle: 45.0 });
        assert!(matches!(loose.1, Limit::Overload { .. }) && loose.0 > cap);
        close(loose.0, 10_000.0 * 0.002 / (2.0 * 22.5f64.to_radians().sin()));
    }

    #[test]
    fn the_window_end_forces_a_stop() {
        // Three blocks ahead: the 100 mm line must be able to stop within the
        // two 1 mm blocks after it, sqrt(2·400·2) = 40 mm/s.
        let moves = [line(100.0, 100.0, X), line(1.0, 100.0, X), line(1.0, 100.0, X), line(100.0, 100.0, X)];
        let shallow = plan(Envelope { depth: 3, ..linear() }, &moves);
        close(shallow[0].profile.exit, 40.0 * 60.0);
        assert_eq!(shallow[0].exit_limit, Some(Limit::WindowEnd));
        let deep = plan(linear(), &moves);
        assert_eq!((deep[0].profile.exit, deep[0].exit_limit), (6000.0, None));
        assert!(total(&shallow) > total(&deep));
    }

    #[test]
    fn a_million_moves_in_bounded_memory() {
        let mut planner = Planner::new(Envelope { depth: 50, ..linear() });
        let (mut emitted, mut most) = (0usize, 0usize);
        for i in 0..1_000_000 {
            // Every tenth block turns a little: caps now and then.
            let direction = if i % 10 == 0 { [0.99, 0.141, 0.0] } else { X };
            if let Some((index, _)) = planner.push(line(10.0, 100.0, direction)) {
                assert_eq!(index, emitted);
                emitted += 1;
            }
            most = most.max(planner.held());
        }
        assert_eq!(most, 50);
        assert_eq!(emitted + planner.finish().count(), 1_000_000);
    }

    #[test]
    fn stops_short_blocks_and_merged_blocks() {
        // A rapid move and the caller's stop both stop; a 2 µm block merged
        // by R383 does not hold the chain to 2 µm / 4 ms.
        let rapid = EnvelopeMove { kind: MoveKind::Rapid, ..line(10.0, 150.0, X) };
        let stopped = EnvelopeMove { stop_before: true, ..line(10.0, 100.0, X) };
        let planned = plan(linear(), &[line(10.0, 100.0, X), rapid, stopped]);
        assert_eq!(planned.iter().map(|p| p.profile.exit).collect::<Vec<_>>(), [0.0, 0.0, 0.0]);
        assert_eq!(planned[0].exit_limit, Some(Limit::Stop));
        let tiny = EnvelopeMove { mergeable: true, ..line(0.002, 100.0, X) };
        let planned = plan(linear(), &[line(50.0, 100.0, X), tiny, line(50.0, 100.0, X)]);
        assert_eq!(planned[0].profile.exit, 6000.0);
        let unmerged = plan(linear(), &[line(50.0, 100.0, X), line(0.002, 100.0, X), line(50.0, 100.0, X)]);
        close(unmerged[0].profile.exit, 0.002 / 0.004 * 60.0);
        assert_eq!(unmerged[1].cruise_limit, Some(Limit::MinDuration));
        // R382: a block shorter than 1 mm stops at both ends.
        let short = Envelope { short_block: 1.0, ..linear() };
        let planned = plan(short, &[line(50.0, 100.0, X), line(0.5, 100.0, X), line(50.0, 100.0, X)]);
        assert_eq!((planned[0].profile.exit, planned[1].profile.exit), (0.0, 0.0));
        assert_eq!(planned[0].exit_limit, Some(Limit::ShortBlock));
    }

    #[test]
    fn arcs_run_at_their_limits() {
        // Radius 1 mm: a 1 µm chord per 2 ms tick allows sqrt(8·r·e)/Ts.
        let arc = EnvelopeMove { arc_radius: Some(1.0), ..line(10.0, 100.0, X) };
        let planned = plan(linear(), &[arc]);
        let limit = (8.0f64 * 0.001).sqrt() / 0.002;
        close(planned[0].profile.peak, limit * 60.0);
        assert_eq!(planned[0].cruise_limit, Some(Limit::ChordError { radius: 1.0 }));
    }

    #[test]
    fn degenerate_dynamics_never_panic() {
        // No acceleration (no ramps), a tick of zero (every corner stops),
        // and extreme ramps: finite durations all the same.
        let mut flat = linear();
        flat.sets[0].ramp.acceleration = 0.0;
        flat.basic.acceleration = f64::NAN;
        flat.tick = 0.0;
        let turned = [0.0, 1.0, 0.0];
        let moves = [line(10.0, 100.0, X), line(0.0, 100.0, turned), line(f64::INFINITY, f64::NAN, X)];
        for envelope in [
            flat,
            Envelope {
                sets: [super::DynamicSet {
                    ramp: super::Ramp { acceleration: 1e300, jerk: 1e-300 },
                    ..parabolic().sets[0]
                }; 4],
                ..parabolic()
            },
        ] {
            let planned = plan(envelope, &moves);
            assert!(planned.iter().all(|p| p.profile.duration.is_finite() && p.profile.duration >= 0.0), "{planned:?}");
        }
        // Without ramps a move runs at its speed throughout.
        let mut flat = linear();
        flat.sets[0].ramp.acceleration = 0.0;
        close(plan(flat, &[line(10.0, 100.0, X)])[0].profile.duration, 0.1);
    }

    fn moves() -> impl Strategy<Value = Vec<EnvelopeMove>> {
        let direction = (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y, z)| {
            let norm = (x * x + y * y + z * z).sqrt();
            if norm > 1e-3 { [x / norm, y / norm, z / norm] } else { X }
        });
        let kind = prop_oneof![
            6 => Just(MoveKind::Feed),
            1 => Just(MoveKind::Rapid),
            1 => Just(MoveKind::Thread),
            1 => (0.0..2.0f64).prop_map(|duration| MoveKind::Still { duration: duration + 1e-3 }),
        ];
        let one = (1e-4..500.0f64, 1e-2..2000.0f64, kind, direction.clone(), direction, any::<bool>(), 1..=4u8)
            .prop_map(|(length, speed, kind, start, end, stop_before, set)| EnvelopeMove {
                length,
                speed,
                kind,
                start_direction: start,
                end_direction: end,
                arc_radius: (set == 2).then_some(length),
                stop_before: stop_before && set == 3,
                continuity: set != 4,
                set,
                mergeable: set == 1,
            });
        prop::collection::vec(one, 1..60)
    }

    proptest! {
        #[test]
        fn durations_are_finite_and_speeds_within_the_caps(
            moves in moves(),
            parabolic_profile in any::<bool>(),
            depth in 1..20usize,
        ) {
            let envelope = if parabolic_profile { parabolic() } else { linear() };
            let planned = plan(Envelope { depth, ..envelope }, &moves);
            for (i, (mv, p)) in moves.iter().zip(&planned).enumerate() {
                let profile = p.profile;
                prop_assert!(profile.duration.is_finite() && profile.duration > 0.0, "{i}: {profile:?}");
                let cap = mv.speed * 60.0 * (1.0 + 1e-9);
                prop_assert!(profile.entry <= cap && profile.exit <= cap && profile.peak <= cap, "{i}: {p:?}");
                let peak = profile.peak * (1.0 + 1e-9);
                prop_assert!(profile.entry <= peak && profile.exit <= peak, "{i}: {p:?}");
                if let Some(next) = planned.get(i + 1) {
                    let next_move = &moves[i + 1];
                    // A thread shows its own speed at both ends; it starts and ends at a stop.
                    let speed = |kind, speed| if kind == MoveKind::Thread { 0.0 } else { speed };
                    let exit = speed(mv.kind, profile.exit);
                    prop_assert_eq!(exit, speed(next_move.kind, next.profile.entry));
                    if next_move.stop_before || mv.kind != MoveKind::Feed || next_move.kind != MoveKind::Feed {
                        prop_assert_eq!(exit, 0.0);
                    } else if !next_move.mergeable || next_move.length >= 0.005 {
                        let angle = super::angle_between(mv.end_direction, next_move.start_direction);
                        let set = &envelope.sets[usize::from(next_move.set) - 1];
                        let corner = corner_cap(set, envelope.tick, angle).0 * 60.0;
                        prop_assert!(profile.exit <= corner * (1.0 + 1e-9), "{i}: {p:?} above {corner}");
                    }
                }
            }
        }
    }
}
