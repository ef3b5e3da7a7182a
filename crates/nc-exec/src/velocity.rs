//! The velocity model: how fast a control really runs a trace's moves,
//! where the path speed must drop, and what each drop costs. It reads no
//! machine constant and names no code: a control's policy gives it the
//! [`Dynamics`] (for CNC8x6, `cnc8x6::dynamics`) and the [`Terms`] its
//! reasons are told in.
//!
//! Every move ramps linearly (trapezoids), or, where the control limits
//! the jerk ([`Dynamics::jerk`]) and the step asks for it
//! ([`Step::jerk_limited`]), along S-curves: the acceleration rises and
//! falls at the jerk limit, so that a change of speed by Δv takes
//! 2·sqrt(Δv/J) where it stays below the acceleration A (Δv ≤ A²/J) and
//! Δv/A + A/J where it reaches it, over the mean speed times that time
//! (the closed forms are in `ramp`). Every ramp the model computes takes
//! the move's profile: the time and distance to change speed, the speed a
//! move can still stop from within itself, the peak a short move reaches
//! (found by bisection under a jerk limit, where the distance is no longer
//! a quadratic in the speed) and so the profile a step reports. A rest to
//! rest move of length L at feed F with F > A²/J takes F/A + A/J + L/F
//! when it reaches F; with no jerk limit, F/A + L/F.
//!
//! A junction between two moves is smooth or a stop ([`stop_reason`]):
//!
//! * smooth only between two working-feed moves where the second is
//!   programmed for a continuous path and the control joins such moves
//!   ([`Joining`]): whenever programmed, or automatically only where the
//!   angle between the motion directions is below the tolerance angle and
//!   neither move runs axes beyond the first three; and both moves last at
//!   least the minimum duration for joining at their programmed speed;
//! * a stop otherwise: the move before ramps to zero, then waits for the
//!   in-position window or, where blocks are not joined at all, pauses for
//!   the next block to be prepared.
//!
//! A smooth junction runs at the lower of the two speeds, and the control
//! looks one block ahead: the move after a junction must be able to stop
//! within itself from the junction speed. Where the control bounds corners
//! by a tolerance ([`Step::corner_tolerance`]), a joined corner runs at
//! most at [`corner_speed`]: the speed of the arc that blends it within
//! the tolerance at the continuous-path acceleration (the envelope planner
//! has its own accuracy criterion instead). Arcs run at most at the speed
//! whose chord per interpolator tick stays within the chord error of the
//! circle. Ramps take the continuous-path acceleration under continuity,
//! the feed acceleration for other working feed and the rapid acceleration
//! for rapid moves; threads run without ramps. A control with a longer
//! look-ahead plans with [`Dynamics::envelope`] instead.
//!
//! The spindle ([`Step::spindle`]) changes its speed at the spindle
//! acceleration while the steps run: from the rpm it has reached towards
//! the one the step commands. A cut (a feed move or a thread) with the
//! spindle commanded to turn waits at its start until the spindle has
//! reached the cut's starting rpm, so that rapid moves, dwells and other
//! blocks before it hide the change; the wait adds to the cut's time and
//! is a break of its own ([`Reason::Spindle`]). Along a cut the spindle is
//! taken to follow the rpm the cut commands (under constant cutting speed,
//! the diameter's), however fast that changes.

use std::{collections::VecDeque, ops::ControlFlow};

use ncc_syntax::TextSize;

pub use crate::envelope::Profile;
use crate::{
    envelope::{Envelope, EnvelopeMove, Limit, MoveKind, Planned, Planner},
    machine::MachineConfig,
    ramp::Ramp,
    trace::{Axes, Checkpoint, MAX_AXES, Motion, Path, PathMode, Step, StepSink, Trace, shift_count, shift_range},
};

/// The spatial angle in degrees between the motion directions (unit
/// vectors over the first three axes) at a junction, which the control
/// compares with R39.
pub fn junction_angle(before: [f64; 3], after: [f64; 3]) -> f64 {
    before.iter().zip(after).map(|(a, b)| a * b).sum::<f64>().clamp(-1.0, 1.0).acos().to_degrees()
}

/// The highest speed (mm/s) at which a path turning from `before` into
/// `after` (unit directions) stays within `tolerance` mm of the corner with
/// `acceleration` (mm/s²). The path blends the corner with the arc tangent
/// to both moves whose middle lies `tolerance` from the corner: for a turn
/// of θ its radius is r = ε·cos(θ/2) / (1 − cos(θ/2)), which runs at most
/// at v = sqrt(a·r). Unbounded where the path runs straight on or the
/// tolerance is infinite; zero at a reversal.
pub fn corner_speed(before: [f64; 3], after: [f64; 3], tolerance: f64, acceleration: f64) -> f64 {
    let cosine: f64 = before.iter().zip(after).map(|(a, b)| a * b).sum();
    // cos(θ/2) from cos θ.
    let half = ((1.0 + cosine.clamp(-1.0, 1.0)) / 2.0).sqrt();
    if !tolerance.is_finite() || half >= 1.0 - 1e-12 {
        return f64::INFINITY;
    }
    (acceleration * tolerance * half / (1.0 - half)).sqrt()
}

/// Which moves programmed for a continuous path the control joins.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Joining {
    /// None: every junction is a stop.
    Off,
    /// Every junction into a move programmed for it.
    Programmed,
    /// Those, where the path turns by less than the tolerance angle and
    /// neither move runs axes beyond the first three.
    Automatic,
}

/// What the model reads from the machine, as the control's policy gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct Dynamics {
    pub joining: Joining,
    /// The tolerance angle in degrees, and its cosine, which junctions
    /// compare with.
    pub tolerance_angle: f64,
    pub(crate) tolerance_cosine: f64,
    /// Ramps in mm/s²: working feed, working feed on a continuous path, and
    /// rapid.
    pub feed_acceleration: f64,
    pub continuity_acceleration: f64,
    pub rapid_acceleration: f64,
    /// The machine's own waits and the times of its functions.
    pub times: MachineTimes,
    /// The shortest moves (s) that a continuous path, and an exact stop
    /// without a pause, join.
    pub min_continuity: f64,
    pub min_tight_joining: f64,
    /// The interpolator tick (s) and the largest distance (mm) of a chord
    /// from its circle, which bound the speed on arcs.
    pub tick: f64,
    pub chord_error: f64,
    /// How fast the spindle changes its speed, in rpm/s; infinite where it
    /// is taken to follow at once.
    pub spindle_acceleration: f64,
    /// The jerk limit of the ramps in mm/s³ for the steps that ask for it
    /// ([`Step::jerk_limited`]); `None` ramps linearly (no jerk limit).
    /// The envelope planner takes its ramps from its own sets instead.
    pub jerk: Option<f64>,
    /// A look-ahead planner over many moves, for controls that have one: it
    /// plans the moves instead of the one-block look-ahead.
    pub envelope: Option<Envelope>,
    /// How the control tells the reasons of its breaks.
    pub terms: &'static Terms,
}

/// The times every control's policy reads alike from the machine
/// description, in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineTimes {
    /// Between blocks that are not joined at all, and for the in-position
    /// window after a stop otherwise.
    pub block_pause: f64,
    pub settle_time: f64,
    /// What an M function and a tool change take.
    pub m_function_time: f64,
    pub tool_change_time: f64,
}

impl MachineTimes {
    pub fn of(machine: &MachineConfig) -> MachineTimes {
        let seconds = |ms: u32| f64::from(ms) / 1000.0;
        MachineTimes {
            block_pause: seconds(machine.block_pause_ms),
            settle_time: seconds(machine.settle_time_ms),
            m_function_time: seconds(machine.m_function_ms),
            tool_change_time: seconds(machine.tool_change_ms),
        }
    }
}

/// The figures a control's policy assumes where the machine description
/// gives none, for [`Dynamics::joined_within_tolerance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Assumed {
    /// Feed and rapid ramps, mm/s².
    pub acceleration: f64,
    /// rpm/s.
    pub spindle_acceleration: f64,
    /// The interpolator tick (s) and chord error (mm) that bound arcs.
    pub tick: f64,
    pub chord_error: f64,
    /// mm/s³ where the control limits the jerk.
    pub jerk: Option<f64>,
}

impl Dynamics {
    /// The policy of a control that joins every junction its program's
    /// modes join and bounds each corner's speed by the step's corner
    /// tolerance, with the ramps of the machine description, else
    /// `assumed`.
    pub fn joined_within_tolerance(machine: &MachineConfig, assumed: Assumed, terms: &'static Terms) -> Dynamics {
        let configured = |value: Option<u32>, assumed| value.map_or(assumed, f64::from);
        let feed_acceleration = configured(machine.feed_acceleration, assumed.acceleration);
        Dynamics {
            joining: Joining::Programmed,
            tolerance_angle: 180.0,
            tolerance_cosine: -1.0,
            feed_acceleration,
            continuity_acceleration: feed_acceleration,
            rapid_acceleration: configured(machine.rapid_acceleration, assumed.acceleration),
            times: MachineTimes::of(machine),
            min_continuity: 0.0,
            min_tight_joining: 0.0,
            tick: assumed.tick,
            chord_error: assumed.chord_error,
            spindle_acceleration: configured(machine.spindle_acceleration, assumed.spindle_acceleration),
            jerk: assumed.jerk,
            envelope: None,
            terms,
        }
    }

    /// `reason`, to be told in the control's terms.
    pub fn state(&self, reason: Reason) -> Stated {
        Stated { reason, terms: self.terms }
    }

    /// Why a move of `duration` s at its programmed speed is too short to
    /// be joined on a continuous path.
    #[inline]
    pub fn too_short_to_join(&self, duration: f64) -> Option<Reason> {
        (duration < self.min_continuity).then_some(Reason::ShortBlock { duration, limit: self.min_continuity })
    }

    /// Why automatic joining stops where the path turns from `before` into
    /// `after` (unit directions over the first three axes).
    #[inline]
    pub fn corner(&self, before: [f64; 3], after: [f64; 3]) -> Option<Reason> {
        if self.joining != Joining::Automatic {
            return None;
        }
        let cosine: f64 = before.iter().zip(&after).map(|(a, b)| a * b).sum();
        // Not below the tolerance: the arc cosine only near and past it.
        if cosine > self.tolerance_cosine + 1e-9 {
            return None;
        }
        let angle = junction_angle(before, after);
        (angle >= self.tolerance_angle).then_some(Reason::Corner { angle, limit: self.tolerance_angle })
    }

    /// Why automatic joining stops at a move that runs axes beyond the
    /// first three.
    #[inline]
    pub fn beyond_three_axes(&self, beyond: bool) -> Option<Reason> {
        (self.joining == Joining::Automatic && beyond).then_some(Reason::BeyondThreeAxes)
    }

    /// Why the junction into a feed move programmed with `path_mode` is a
    /// stop, whatever the moves' geometry.
    #[inline]
    pub fn entered(&self, path_mode: PathMode) -> Option<Reason> {
        match path_mode {
            PathMode::Stop => Some(Reason::Unjoined),
            PathMode::ExactStop => Some(Reason::ExactStop),
            PathMode::Continuous if self.joining == Joining::Off => Some(Reason::JoiningOff),
            PathMode::Continuous => None,
        }
    }

    /// Whether an exact-stop move of `duration` s at its programmed speed is
    /// too short for the control to prepare the next block while it runs,
    /// so that it pauses after it.
    pub fn too_short_to_prepare(&self, duration: f64) -> bool {
        duration < self.min_tight_joining
    }

    /// The distance (mm) a move ramping with `acceleration` needs to stop
    /// from `speed` (mm/s).
    pub fn braking_distance(speed: f64, acceleration: f64) -> f64 {
        speed * speed / (2.0 * acceleration)
    }
}

impl Reason {
    /// A short name for scripts, for the reasons every control names alike;
    /// a control's [`Terms`] name the others.
    pub fn neutral_code(&self) -> &'static str {
        match self {
            Reason::Unjoined => "unjoined",
            Reason::ExactStop => "exact-stop",
            Reason::JoiningOff => "continuity-off",
            Reason::Corner { .. } => "corner",
            Reason::Rapid => "rapid",
            Reason::Thread => "thread",
            Reason::NonMotion => "non-motion",
            Reason::ShortBlock { .. } => "short-block",
            Reason::BeyondThreeAxes => "beyond-three-axes",
            Reason::LookAhead => "look-ahead",
            Reason::ArcLimit { .. } => "arc-limit",
            Reason::Accuracy { .. } => "accuracy",
            Reason::Overload { .. } => "overload",
            Reason::Centrifugal { .. } => "centrifugal",
            Reason::WindowEnd { .. } => "window-end",
            Reason::ContinuityLength { .. } => "continuity-length",
            Reason::Spindle { .. } => "spindle",
        }
    }
}

/// How a control names the reasons of its breaks, in its own words.
pub struct Terms {
    /// A short name for scripts.
    pub code: fn(&Reason) -> &'static str,
    /// A sentence for people.
    pub describe: fn(&Reason, &mut std::fmt::Formatter<'_>) -> std::fmt::Result,
}

impl std::fmt::Debug for Terms {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Terms")
    }
}

/// One control's terms are one static.
impl PartialEq for Terms {
    fn eq(&self, other: &Terms) -> bool {
        std::ptr::eq(self, other)
    }
}

/// A reason with the terms of the control that gave it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stated {
    pub reason: Reason,
    terms: &'static Terms,
}

impl Stated {
    pub fn code(&self) -> &'static str {
        (self.terms.code)(&self.reason)
    }

    pub fn avoidable(&self) -> bool {
        self.reason.avoidable()
    }
}

impl std::fmt::Display for Stated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        (self.terms.describe)(&self.reason, f)
    }
}

/// Why the path speed drops below the programmed feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reason {
    /// The move is programmed to be joined to none: the one before ramps to
    /// a stop and the control pauses.
    Unjoined,
    /// An exact stop: the move before ramps to a stop and waits for the
    /// in-position window.
    ExactStop,
    /// A continuous path is programmed, but the control joins no moves.
    JoiningOff,
    /// The angle between the motion directions (degrees) is not below the
    /// tolerance angle.
    Corner {
        angle: f64,
        limit: f64,
    },
    /// A rapid move at the junction.
    Rapid,
    /// A thread at the junction: it runs without ramps, from a stop.
    Thread,
    /// A block without motion (or a dwell) between two moves.
    NonMotion,
    /// A move shorter (s) than the minimum duration for smooth joining.
    ShortBlock {
        duration: f64,
        limit: f64,
    },
    /// Automatic recognition works for the first three axes only.
    BeyondThreeAxes,
    /// One block of look-ahead: the next move must be able to stop within
    /// itself, so the junction runs slower.
    LookAhead,
    /// An arc runs at most at the speed its chord error allows.
    ArcLimit {
        radius: f64,
    },
    /// Planned look-ahead: a corner of `angle` degrees, limited by the
    /// accuracy criterion or the dynamic criterion.
    Accuracy {
        angle: f64,
    },
    Overload {
        angle: f64,
    },
    /// Planned look-ahead: the centrifugal acceleration on an arc.
    Centrifugal {
        radius: f64,
    },
    /// Planned look-ahead: the window of `blocks` ends, and the last block
    /// planned must be able to stop.
    WindowEnd {
        blocks: usize,
    },
    /// Planned look-ahead: a block shorter than `limit` mm breaks the path.
    ContinuityLength {
        limit: f64,
    },
    /// A cut waits at rest for the spindle to get from `from` to `to` rpm.
    Spindle {
        from: f64,
        to: f64,
    },
}

impl Reason {
    /// Whether the program could avoid the drop; rapid moves and threads
    /// always start and end at rest.
    pub fn avoidable(&self) -> bool {
        !matches!(self, Reason::Rapid | Reason::Thread)
    }
}

/// A place where the speed drops: at the end of `step` (or, for an arc
/// limit, through it; for a wait for the spindle, at its start).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Break {
    pub step: usize,
    pub reason: Stated,
    /// mm/min before the drop and at it.
    pub before: f64,
    pub at: f64,
    /// Seconds the drop costs against a smooth join at the programmed feed.
    pub lost: f64,
}

impl Break {
    /// Whether the drop is where its step starts rather than where it ends.
    pub fn at_start(&self) -> bool {
        matches!(self.reason.reason, Reason::Spindle { .. })
    }
}

/// The model's timing of a whole trace.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timing {
    /// One per step of the trace.
    pub profiles: Vec<Profile>,
    pub breaks: Vec<Break>,
}

impl Timing {
    pub fn total_time(&self) -> f64 {
        self.profiles.iter().map(|profile| profile.duration).sum()
    }

    /// When each step starts, in seconds since the program started.
    pub fn start_times(&self) -> impl Iterator<Item = f64> + '_ {
        self.profiles.iter().scan(0.0, |time, profile| {
            let start = *time;
            *time += profile.duration;
            Some(start)
        })
    }
}

/// A move as the model sees it, speeds in mm/s.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Move {
    length: f64,
    /// The programmed speed, and the speed the move may run at.
    programmed: f64,
    cruise: f64,
    ramp: Ramp,
    /// Runs without ramps (threads).
    no_ramps: bool,
    kind: Kind,
    path_mode: PathMode,
    beyond_three_axes: bool,
    /// Unit directions at the start and at the end, over the first three axes.
    start_direction: [f64; 3],
    end_direction: [f64; 3],
    arc_radius: Option<f64>,
    /// The tolerance (mm) of the corner into this move.
    corner_tolerance: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Feed,
    Rapid,
    Thread,
    /// A dwell or a block without motion: its own time, no speed.
    Still,
}

/// Takes what the model finds, step by step in order.
pub trait TimingSink {
    /// A break at the step [`TimingSink::timed`] takes next.
    fn speed_break(&mut self, step: &Step, speed_break: Break);
    /// The next step and its profile.
    fn timed(&mut self, step: &Step, profile: Profile);

    /// See [`StepSink::checkpoint_wanted`].
    fn checkpoint_wanted(&mut self, _block: usize, _offset: TextSize) -> bool {
        false
    }

    /// A checkpoint of the run with the model's state there, which
    /// [`Timer::resume`] goes on from; see [`StepSink::checkpoint`].
    fn checkpoint(&mut self, _run: Checkpoint, _model: TimerState) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

impl TimingSink for Timing {
    fn speed_break(&mut self, _step: &Step, speed_break: Break) {
        self.breaks.push(speed_break);
    }

    fn timed(&mut self, _step: &Step, profile: Profile) {
        self.profiles.push(profile);
    }
}

/// Times every step of `trace` with the velocity model of `dynamics`.
pub fn time(trace: &Trace, dynamics: &Dynamics) -> Timing {
    let count = trace.steps.len();
    // Breaks can come at every step: reserved room never touched costs
    // nothing, growing copies.
    let timing = Timing { profiles: Vec::with_capacity(count), breaks: Vec::with_capacity(count) };
    let mut timer = Timer::new(&trace.axes, dynamics, timing);
    for step in &trace.steps {
        timer.push(step.clone());
    }
    timer.finish()
}

/// The model run over steps as they come: the CNC8x6 model holds three at
/// a time (the step before the junction being decided waits for the speed
/// its successor ends at, which the lost time of a break needs), the
/// envelope velocity its look-ahead window.
#[derive(Debug)]
pub struct Timer<'a, S> {
    axes: &'a [u8],
    dynamics: &'a Dynamics,
    sink: S,
    /// Steps pushed so far, and where the last one ended.
    count: usize,
    end: Axes,
    model: Model,
    spindle: Spindle,
}

/// The spindle as the model follows it: `elapsed` s after it had `from`
/// rpm, ramping at the spindle acceleration towards `target`; at rest once
/// it is there (`from` is `target`). `step` is the next step to time.
#[derive(Debug, Default, Clone, PartialEq)]
struct Spindle {
    from: f64,
    target: f64,
    elapsed: f64,
    step: usize,
}

impl Spindle {
    /// The rpm it has reached.
    fn rpm(&self, acceleration: f64) -> f64 {
        let gap = self.target - self.from;
        if self.elapsed >= gap.abs() / acceleration {
            self.target
        } else {
            self.from + (self.elapsed * acceleration).copysign(gap)
        }
    }

    /// Ramps from where it is towards `rpm`.
    fn command(&mut self, rpm: f64, acceleration: f64) {
        if rpm != self.target {
            *self = Spindle { from: self.rpm(acceleration), target: rpm, elapsed: 0.0, step: self.step };
        }
    }

    /// Follows `step`, which takes `duration` s once it runs, and hands
    /// back how long it waits first for the spindle and from what rpm.
    fn pass(&mut self, step: &Step, duration: f64, acceleration: f64) -> (f64, f64) {
        let [start, end] = step.spindle.map(f64::from);
        let cuts = matches!(kind_of(step), Kind::Feed | Kind::Thread);
        let (from, wait) = if cuts {
            self.command(start, acceleration);
            let reached = self.rpm(acceleration);
            let wait = if start == 0.0 { 0.0 } else { (start - reached).abs() / acceleration };
            (reached, wait)
        } else {
            self.command(end, acceleration);
            (self.rpm(acceleration), 0.0)
        };
        self.elapsed += wait + duration;
        // Along a cut the spindle follows; at its target it is at rest, which
        // keeps the state the same however long ago it got there.
        if (cuts && start != end) || self.rpm(acceleration) == self.target {
            *self = Spindle { from: end, target: end, elapsed: 0.0, step: self.step };
        }
        self.step += 1;
        (wait, from)
    }
}

/// A sink that adds the spindle's waits to the cuts' times, as breaks.
struct Waiting<'s, S> {
    spindle: &'s mut Spindle,
    sink: &'s mut S,
    dynamics: &'s Dynamics,
}

impl<S: TimingSink> TimingSink for Waiting<'_, S> {
    fn speed_break(&mut self, step: &Step, speed_break: Break) {
        self.sink.speed_break(step, speed_break);
    }

    fn timed(&mut self, step: &Step, mut profile: Profile) {
        let index = self.spindle.step;
        let (wait, from) = self.spindle.pass(step, profile.duration, self.dynamics.spindle_acceleration);
        if wait > 0.0 {
            let reason = self.dynamics.state(Reason::Spindle { from, to: f64::from(step.spindle[0]) });
            let before = step.feed.unwrap_or(0.0);
            self.sink.speed_break(step, Break { step: index, reason, before, at: 0.0, lost: wait });
            profile.duration += wait;
        }
        self.sink.timed(step, profile);
    }
}

#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant, reason = "one per run, never moved while it runs")]
enum Model {
    OneBlock(OneBlock),
    Envelope(Planning),
}

/// The CNC8x6 one-block look-ahead.
#[derive(Debug, Default, Clone, PartialEq)]
struct OneBlock {
    /// The last step pushed, whose exit the next step decides, and the
    /// speed it enters at.
    current: Option<(Step, Move)>,
    entry: f64,
    /// The step before it.
    waiting: Option<Timed>,
}

impl<'a, S: TimingSink> Timer<'a, S> {
    /// A timer for steps over the machine's `axes` ([`Trace::axes`]).
    pub fn new(axes: &'a [u8], dynamics: &'a Dynamics, sink: S) -> Self {
        let model = match &dynamics.envelope {
            Some(envelope) => Model::Envelope(Planning::new(envelope.clone())),
            None => Model::OneBlock(OneBlock::default()),
        };
        Timer { axes, dynamics, sink, count: 0, end: [0.0; MAX_AXES], model, spindle: Spindle::default() }
    }

    /// Takes the next step of the run.
    pub fn push(&mut self, step: Step) {
        let dynamics = self.dynamics;
        let next = move_of(&step, &self.end, self.axes, dynamics);
        self.end = step.end;
        self.count += 1;
        let sink = &mut Waiting { spindle: &mut self.spindle, sink: &mut self.sink, dynamics };
        match &mut self.model {
            Model::OneBlock(model) => model.push(self.count - 1, step, next, dynamics, sink),
            Model::Envelope(planning) => planning.push(step, next, dynamics, sink),
        }
    }

    /// Times the last steps, which end at rest, and hands back the sink.
    pub fn finish(mut self) -> S {
        let dynamics = self.dynamics;
        let sink = &mut Waiting { spindle: &mut self.spindle, sink: &mut self.sink, dynamics };
        match self.model {
            Model::OneBlock(model) => model.finish(self.count, dynamics, sink),
            Model::Envelope(planning) => planning.finish(dynamics, sink),
        }
        self.sink
    }
}

impl OneBlock {
    fn push(&mut self, index: usize, step: Step, next: Move, dynamics: &Dynamics, sink: &mut impl TimingSink) {
        let Some((this_step, this)) = self.current.replace((step, next)) else {
            return;
        };
        let entry = self.entry;
        let (exit, stop, corner) = match stop_reason(&this, &next, dynamics) {
            Some(reason) => (0.0, Some(reason), None),
            // One block of look-ahead: the next move must be able to stop
            // within itself, the corner keep its tolerance; and this move
            // must reach the speed.
            None => {
                let speed = this.cruise.min(next.cruise).min(stopping_speed(&next, 0.0));
                let (before, after) = (this.end_direction, next.start_direction);
                let corner = corner_speed(before, after, next.corner_tolerance, dynamics.continuity_acceleration);
                let limited = (corner < speed).then(|| Reason::Accuracy { angle: junction_angle(before, after) });
                (speed.min(corner).min(stopping_speed(&this, entry)), None, limited)
            }
        };
        if let Some(before) = self.waiting.take() {
            before.finish(Some(&this), exit, dynamics, sink);
        }
        self.waiting = Some(Timed { index: index - 1, step: this_step, this, entry, exit, stop, corner });
        self.entry = exit;
    }

    fn finish(mut self, count: usize, dynamics: &Dynamics, sink: &mut impl TimingSink) {
        if let Some((step, this)) = self.current.take() {
            if let Some(before) = self.waiting.take() {
                before.finish(Some(&this), 0.0, dynamics, sink);
            }
            let last = Timed { index: count - 1, step, this, entry: self.entry, exit: 0.0, stop: None, corner: None };
            last.finish(None, 0.0, dynamics, sink);
        }
    }
}

/// The CNC8x9 envelope velocity: the planner's window, the steps in it,
/// and the last step planned, which waits for its successor's time.
#[derive(Debug, Clone)]
struct Planning {
    planner: Planner,
    steps: PlannedSteps,
}

#[derive(Debug, Default, Clone)]
struct PlannedSteps {
    /// The steps in the window, each with why the junction before it stops.
    window: VecDeque<(Step, Move, Option<Reason>)>,
    previous: Option<Move>,
    held: Option<Held>,
}

/// A planned step whose exit break waits for the time its successor loses
/// to the same drop.
#[derive(Debug, Clone)]
struct Held {
    step: Step,
    profile: Profile,
    exit: Option<Break>,
    through: Option<Break>,
}

impl Planning {
    fn new(envelope: Envelope) -> Planning {
        Planning { planner: Planner::new(envelope), steps: PlannedSteps::default() }
    }

    fn push(&mut self, step: Step, this: Move, dynamics: &Dynamics, sink: &mut impl TimingSink) {
        let steps = &mut self.steps;
        let stop = steps.previous.and_then(|previous| stop_reason(&previous, &this, dynamics));
        // The planner caps short blocks by their duration itself.
        let stop_before = stop.is_some_and(|reason| !matches!(reason, Reason::ShortBlock { .. }));
        let planned = EnvelopeMove {
            length: this.length,
            speed: this.programmed,
            kind: match this.kind {
                Kind::Feed => MoveKind::Feed,
                Kind::Rapid => MoveKind::Rapid,
                Kind::Thread => MoveKind::Thread,
                Kind::Still => MoveKind::Still { duration: step.duration },
            },
            start_direction: this.start_direction,
            end_direction: this.end_direction,
            arc_radius: this.arc_radius,
            stop_before,
            continuity: this.path_mode == PathMode::Continuous && dynamics.joining != Joining::Off,
            set: step.dynamic_set,
            mergeable: step.mergeable,
        };
        steps.previous = Some(this);
        steps.window.push_back((step, this, stop.filter(|_| stop_before)));
        if let Some((index, planned)) = self.planner.push(planned) {
            steps.planned(index, planned, dynamics, sink);
        }
    }

    fn finish(self, dynamics: &Dynamics, sink: &mut impl TimingSink) {
        let Planning { planner, mut steps } = self;
        for (index, planned) in planner.finish() {
            steps.planned(index, planned, dynamics, sink);
        }
        if let Some(held) = steps.held.take() {
            held.hand_on(sink);
        }
    }
}

/// A limit the planner found, in the control's terms: at the junction
/// after `this`, with the move after it and the stop the CNC8x6 rules make
/// there, or through `this` without them. `None` for what is no drop.
fn reason_of(limit: Limit, this: &Move, next: Option<(&Move, Option<Reason>)>, dynamics: &Dynamics) -> Option<Reason> {
    let envelope = dynamics.envelope.as_ref();
    Some(match limit {
        Limit::Stop => next?.1.unwrap_or(Reason::NonMotion),
        Limit::ShortBlock => Reason::ContinuityLength { limit: envelope.map_or(0.0, |e| e.short_block) },
        Limit::Accuracy { angle } => Reason::Accuracy { angle },
        Limit::Overload { angle } => Reason::Overload { angle },
        Limit::Centrifugal { radius } => Reason::Centrifugal { radius },
        Limit::ChordError { radius } => Reason::ArcLimit { radius },
        Limit::MinDuration => {
            let duration = this.length / this.programmed;
            let shorter = next.map_or(duration, |(next, _)| duration.min(next.length / next.programmed));
            Reason::ShortBlock { duration: shorter, limit: dynamics.min_continuity }
        }
        Limit::WindowEnd => Reason::WindowEnd { blocks: envelope.map_or(0, |e| e.depth) },
        Limit::Feed | Limit::End | Limit::Ramp => return None,
    })
}

impl PlannedSteps {
    /// Hands on the step before the one planned, now that the time this one
    /// loses to the drop between them is known.
    fn planned(&mut self, index: usize, planned: Planned, dynamics: &Dynamics, sink: &mut impl TimingSink) {
        let Some((step, this, _)) = self.window.pop_front() else { return };
        let next = self.window.front();
        let mut profile = planned.profile;
        profile.duration += extra_time(&step, dynamics);
        let pause = match next {
            Some((_, next, Some(_))) if this.kind != Kind::Still => pause_after(&this, next, dynamics),
            _ => 0.0,
        };
        profile.duration += pause;
        let moving = this.kind != Kind::Still && this.length > 0.0;
        // Against the move at its programmed speed from end to end.
        let deficit = if moving { (planned.profile.duration - this.length / this.programmed).max(0.0) } else { 0.0 };
        let through = planned.cruise_limit.filter(|_| moving).and_then(|limit| {
            let reason = reason_of(limit, &this, None, dynamics)?;
            let cruise = profile.peak / 60.0;
            let lost = (this.length / cruise - this.length / this.programmed).clamp(0.0, deficit);
            Some(Break {
                step: index,
                reason: dynamics.state(reason),
                before: this.programmed * 60.0,
                at: profile.peak,
                lost,
            })
        });
        let exit = next.filter(|_| moving).zip(planned.exit_limit).and_then(|((_, next, stop), limit)| {
            let reason = reason_of(limit, &this, Some((next, *stop)), dynamics)?;
            let before = if next.kind == Kind::Still { this.programmed } else { this.programmed.min(next.programmed) };
            Some(Break {
                step: index,
                reason: dynamics.state(reason),
                before: before * 60.0,
                at: profile.exit,
                lost: pause,
            })
        });
        // What the move loses besides a limit through it goes to the drops
        // at its ends, as the square of each end's shortfall weighs (a
        // linear ramp from v loses (feed − v)² / (2 a feed)); a ramp from
        // the program's start or a still block is no drop's.
        let remaining = deficit - through.map_or(0.0, |through| through.lost);
        let shortfall = |speed: f64| (this.programmed - speed / 60.0).max(0.0).powi(2);
        let (at_entry, at_exit) = (shortfall(profile.entry), shortfall(profile.exit));
        let share = |part: f64| if at_entry + at_exit > 0.0 { remaining * part / (at_entry + at_exit) } else { 0.0 };
        let (to_entry, to_exit) = (share(at_entry), share(at_exit));
        if let Some(mut held) = self.held.take() {
            if let Some(drop) = &mut held.exit {
                drop.lost += to_entry;
            }
            held.hand_on(sink);
        }
        let exit = exit.map(|drop| Break { lost: drop.lost + to_exit, ..drop });
        self.held = Some(Held { step, profile, exit, through });
    }
}

impl Held {
    fn hand_on(self, sink: &mut impl TimingSink) {
        for speed_break in self.exit.into_iter().chain(self.through) {
            sink.speed_break(&self.step, speed_break);
        }
        sink.timed(&self.step, self.profile);
    }
}

impl<S: TimingSink> StepSink for Timer<'_, S> {
    fn step(&mut self, step: Step) {
        self.push(step);
    }

    fn checkpoint_wanted(&mut self, block: usize, offset: TextSize) -> bool {
        self.sink.checkpoint_wanted(block, offset)
    }

    fn checkpoint(&mut self, checkpoint: Checkpoint) -> ControlFlow<()> {
        let state =
            TimerState { count: self.count, end: self.end, model: self.model.clone(), spindle: self.spindle.clone() };
        self.sink.checkpoint(checkpoint, state)
    }
}

/// The model between two steps: the steps it holds (the CNC8x6 model two,
/// the envelope velocity its look-ahead window), and how many came before.
#[derive(Debug, Clone)]
pub struct TimerState {
    count: usize,
    end: Axes,
    model: Model,
    spindle: Spindle,
}

impl TimerState {
    /// This state in a text where its steps' blocks start `text` bytes
    /// later, after `steps` more steps.
    pub fn shifted(&self, text: i64, steps: i64) -> TimerState {
        let mut shifted = self.clone();
        shifted.count = shift_count(self.count, steps);
        shifted.spindle.step = shift_count(self.spindle.step, steps);
        let move_step = |step: &mut Step| step.range = shift_range(step.range, text);
        match &mut shifted.model {
            Model::OneBlock(model) => {
                if let Some((step, _)) = &mut model.current {
                    move_step(step);
                }
                if let Some(waiting) = &mut model.waiting {
                    move_step(&mut waiting.step);
                    waiting.index = shift_count(waiting.index, steps);
                }
            }
            Model::Envelope(planning) => {
                planning.planner.shift_indices(steps);
                planning.steps.window.iter_mut().for_each(|(step, _, _)| move_step(step));
                if let Some(held) = &mut planning.steps.held {
                    move_step(&mut held.step);
                    for speed_break in held.exit.iter_mut().chain(&mut held.through) {
                        speed_break.step = shift_count(speed_break.step, steps);
                    }
                }
            }
        }
        shifted
    }

    /// Whether the model goes on from here as from `other`, whose steps'
    /// blocks start `text` bytes earlier. Only the CNC8x6 model tells: the
    /// envelope velocity's window holds positions along the whole path,
    /// which an edit before it moves.
    pub fn same_course(&self, other: &TimerState, text: i64) -> bool {
        let steps = self.count as i64 - other.count as i64;
        let other = other.shifted(text, steps);
        match (&self.model, &other.model) {
            (Model::OneBlock(this), Model::OneBlock(that)) => {
                self.end == other.end && this == that && self.spindle == other.spindle
            }
            _ => false,
        }
    }
}

impl<'a, S: TimingSink> Timer<'a, S> {
    /// A timer that goes on from `state`, taken at a checkpoint of a run
    /// on the same machine.
    pub fn resume(axes: &'a [u8], dynamics: &'a Dynamics, state: TimerState, sink: S) -> Self {
        let TimerState { count, end, model, spindle } = state;
        Timer { axes, dynamics, sink, count, end, model, spindle }
    }
}

/// A move with the speeds it enters and leaves at.
#[derive(Debug, Clone, PartialEq)]
struct Timed {
    index: usize,
    step: Step,
    this: Move,
    entry: f64,
    exit: f64,
    /// Why it ends in a stop, or why its smooth exit is limited by the
    /// corner's tolerance.
    stop: Option<Reason>,
    corner: Option<Reason>,
}

impl Timed {
    /// Hands on the move's breaks and profile; `next` is the move after it,
    /// and `after` where that one ends.
    fn finish(self, next: Option<&Move>, after: f64, dynamics: &Dynamics, sink: &mut impl TimingSink) {
        let Timed { index, step, this, entry, exit, stop, corner } = self;
        let mut profile = profile(&this, entry, exit, step.duration);
        profile.duration += extra_time(&step, dynamics);
        match (stop, next) {
            (Some(reason), Some(next)) if this.kind != Kind::Still => {
                let pause = pause_after(&this, next, dynamics);
                profile.duration += pause;
                let (before, lost) = if next.kind == Kind::Still {
                    // Without the still block the move would go on at its speed.
                    let before = this.cruise.min(stopping_speed(&this, entry));
                    (before, run_time(&this, entry, 0.0) - run_time(&this, entry, before))
                } else {
                    let before = this.cruise.min(next.cruise);
                    (before, lost_time(&this, next, entry, exit, before, after))
                };
                let lost = lost.max(0.0) + pause;
                sink.speed_break(
                    &step,
                    Break { step: index, reason: dynamics.state(reason), before: before * 60.0, at: 0.0, lost },
                );
            }
            (None, Some(next)) if this.kind == Kind::Feed => {
                // Below what the move reaches on its own only when the next
                // one could not stop from it; still ramping up is no drop.
                let before = this.cruise.min(next.cruise).min(stopping_speed(&this, entry));
                if exit < before * (1.0 - 1e-9) {
                    let lost = lost_time(&this, next, entry, exit, before, after);
                    let reason = dynamics.state(corner.unwrap_or(Reason::LookAhead));
                    sink.speed_break(
                        &step,
                        Break { step: index, reason, before: before * 60.0, at: exit * 60.0, lost },
                    );
                }
            }
            _ => {}
        }
        if let Some(radius) = this.arc_radius.filter(|_| this.cruise < this.programmed * (1.0 - 1e-9)) {
            let lost = this.length / this.cruise - this.length / this.programmed;
            let reason = dynamics.state(Reason::ArcLimit { radius });
            let (before, at) = (this.programmed * 60.0, this.cruise * 60.0);
            sink.speed_break(&step, Break { step: index, reason, before, at, lost });
        }
        sink.timed(&step, profile);
    }
}

/// Seconds the step's M functions and tool change add.
fn extra_time(step: &Step, dynamics: &Dynamics) -> f64 {
    let times = &dynamics.times;
    f64::from(step.m_functions) * times.m_function_time + if step.tool_change { times.tool_change_time } else { 0.0 }
}

/// The step as a move: its speeds, acceleration and directions.
fn move_of(step: &Step, start: &Axes, axes: &[u8], dynamics: &Dynamics) -> Move {
    let kind = kind_of(step);
    // The speed the trace timed the move at: the feed, or the rapid of its slowest axis.
    let programmed = if step.duration > 0.0 { step.length / step.duration } else { 0.0 };
    let mut chord = [0.0; 3];
    for (i, value) in chord.iter_mut().enumerate() {
        *value = step.end[i] - start[i];
    }
    let (mut start_direction, mut end_direction) = (unit(chord), unit(chord));
    let mut arc_radius = None;
    let mut cruise = programmed;
    if let Path::Arc { plane, centre, clockwise } = step.path {
        let slot = |letter: u8| axes.iter().position(|&axis| axis == letter);
        if let (Some(u), Some(v)) = (slot(plane.0), slot(plane.1)) {
            let tangent = |point: &[f64; MAX_AXES]| {
                let (du, dv) = (point[u] - centre[0], point[v] - centre[1]);
                // Counter-clockwise turns the radius a quarter left.
                let (tu, tv) = if clockwise { (dv, -du) } else { (-dv, du) };
                let mut direction = [0.0; 3];
                if u < 3 {
                    direction[u] = tu;
                }
                if v < 3 {
                    direction[v] = tv;
                }
                unit(direction)
            };
            start_direction = tangent(start);
            end_direction = tangent(&step.end);
            let radius = (step.end[u] - centre[0]).hypot(step.end[v] - centre[1]);
            if radius > 0.0 && kind == Kind::Feed {
                let limit = (8.0 * radius * dynamics.chord_error).sqrt() / dynamics.tick;
                if limit < cruise {
                    cruise = limit;
                }
                arc_radius = Some(radius);
            }
        }
    }
    let acceleration = match (kind, step.path_mode) {
        (Kind::Rapid, _) => dynamics.rapid_acceleration,
        (Kind::Feed, PathMode::Continuous) if dynamics.joining != Joining::Off => dynamics.continuity_acceleration,
        _ => dynamics.feed_acceleration,
    };
    let ramp = Ramp::new(acceleration, dynamics.jerk.filter(|_| step.jerk_limited));
    let beyond_three_axes = (3..MAX_AXES).any(|i| (step.end[i] - start[i]).abs() > 0.0);
    Move {
        length: step.length,
        programmed,
        cruise,
        ramp,
        no_ramps: kind == Kind::Thread || !ramp.limited(),
        kind,
        path_mode: step.path_mode,
        beyond_three_axes,
        start_direction,
        end_direction,
        arc_radius,
        corner_tolerance: f64::from(step.corner_tolerance),
    }
}

/// What the model makes of a step.
fn kind_of(step: &Step) -> Kind {
    match (step.motion, step.path) {
        _ if step.length <= 0.0 || step.duration <= 0.0 => Kind::Still,
        (Motion::Feed, Path::Thread { .. }) => Kind::Thread,
        (Motion::Feed, _) => Kind::Feed,
        (Motion::Rapid, _) => Kind::Rapid,
        _ => Kind::Still,
    }
}

fn unit(vector: [f64; 3]) -> [f64; 3] {
    let norm = vector.iter().map(|c| c * c).sum::<f64>().sqrt();
    if norm > 0.0 { vector.map(|c| c / norm) } else { vector }
}

/// Why the junction from `this` into `next` is a stop, or `None` when it
/// is smooth; the first reason in the order the control asks, each asked of
/// [`Dynamics`], as the checker asks them.
fn stop_reason(this: &Move, next: &Move, dynamics: &Dynamics) -> Option<Reason> {
    for side in [this, next] {
        match side.kind {
            Kind::Still => return Some(Reason::NonMotion),
            Kind::Rapid => return Some(Reason::Rapid),
            Kind::Thread => return Some(Reason::Thread),
            Kind::Feed => {}
        }
    }
    dynamics
        .entered(next.path_mode)
        .or_else(|| dynamics.beyond_three_axes(this.beyond_three_axes || next.beyond_three_axes))
        .or_else(|| dynamics.corner(this.end_direction, next.start_direction))
        .or_else(|| dynamics.too_short_to_join(this.length / this.programmed))
        .or_else(|| dynamics.too_short_to_join(next.length / next.programmed))
}

/// The highest speed at which `this` can be entered (from `entry`'s side:
/// the speed it can still reach or stop from) within its length.
fn stopping_speed(this: &Move, from: f64) -> f64 {
    if this.no_ramps { f64::INFINITY } else { this.ramp.reachable(from, this.length) }
}

/// The wait after `this` stops before `next` starts: the in-position
/// window, or under G98 the pause for the next block to be prepared; a G24
/// block too short to send the next one while it runs pauses as well.
fn pause_after(this: &Move, next: &Move, dynamics: &Dynamics) -> f64 {
    let too_short_to_prepare =
        this.path_mode == PathMode::ExactStop && dynamics.too_short_to_prepare(this.length / this.programmed);
    let times = &dynamics.times;
    if next.path_mode == PathMode::Stop || too_short_to_prepare { times.block_pause } else { times.settle_time }
}

/// The move's trapezoid from `entry` to `exit` (mm/s); `fallback` is the
/// trace's own time for blocks without motion.
fn profile(this: &Move, entry: f64, exit: f64, fallback: f64) -> Profile {
    if this.kind == Kind::Still || this.length <= 0.0 {
        return Profile { duration: fallback, ..Profile::default() };
    }
    // Without ramps the move runs at its speed from end to end.
    let (entry, exit) = if this.no_ramps { (this.cruise, this.cruise) } else { (entry, exit) };
    let per_minute = |speed: f64| speed * 60.0;
    Profile {
        entry: per_minute(entry),
        peak: per_minute(peak_speed(this, entry, exit)),
        exit: per_minute(exit),
        duration: run_time(this, entry, exit),
    }
}

/// The highest speed of `this` between `entry` and `exit` (mm/s): its
/// cruise speed, or the top of the ramps when it is too short for it.
fn peak_speed(this: &Move, entry: f64, exit: f64) -> f64 {
    if this.no_ramps {
        return this.cruise;
    }
    this.ramp.peak(entry, exit, this.length, this.cruise)
}

/// Seconds to run `this` from `entry` to `exit` (mm/s), at most at its
/// cruise speed.
fn run_time(this: &Move, entry: f64, exit: f64) -> f64 {
    if this.no_ramps {
        return this.length / this.cruise;
    }
    if this.ramp.jerk_limited() {
        return this.ramp.duration(entry, peak_speed(this, entry, exit), exit, this.length);
    }
    // Linear ramps: the trapezoid or, too short for the cruise, the triangle.
    let (a, length, cruise) = (this.ramp.acceleration, this.length, this.cruise);
    let ramps = (cruise * cruise - entry * entry + cruise * cruise - exit * exit) / (2.0 * a);
    if ramps <= length {
        (cruise - entry) / a + (cruise - exit) / a + (length - ramps) / cruise
    } else {
        let peak = peak_speed(this, entry, exit);
        (peak - entry) / a + (peak - exit) / a
    }
}

/// What a drop to `exit` between `this` and `next` costs against joining
/// them at `smooth` (mm/s), `after` being where `next` ends either way.
fn lost_time(this: &Move, next: &Move, entry: f64, exit: f64, smooth: f64, after: f64) -> f64 {
    let actual = run_time(this, entry, exit) + run_time(next, exit, after);
    let smooth = smooth.min(stopping_speed(this, entry)).min(stopping_speed(next, after));
    let ideal = run_time(this, entry, smooth) + run_time(next, smooth, after);
    (actual - ideal).max(0.0)
}

#[cfg(test)]
mod tests;
