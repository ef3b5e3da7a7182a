//! Path dynamics: continuity modes G23/G24, block durations, junctions.
//!
//! Continuity (G23) is governed by machine constant R97 decade 1: 0 off,
//! 1 manual (a junction is smooth when the block entered is a G23 feed
//! block), 2 automatic recognition (the control also compares the junction
//! angle with R39). When the configuration does not give R97, the rules that
//! depend on it say nothing. Whether a junction stops is the velocity
//! model's decision ([`velocity::Dynamics`], from the same machine through
//! `cnc8x6::dynamics`): these rules ask it over what the walk knows, so the
//! checker and the cycle time cannot disagree. Durations are taken at the
//! programmed feed. Path lengths come from the known end positions; [`Arc`]
//! gives the length and tangents of a G02/G03 block.

use nc_exec::{
    arc::circle_through,
    cnc8x6::arcs,
    cnc8x6::dynamics::{self as policy, path_mode},
    known::Known,
    velocity::{self, Joining, Reason},
};
use ncc_catalog::{AddressRole, Dialect};
use ncc_syntax::{Decimal, TextRange, TextSize};

use crate::{
    Config, Diagnostic,
    cnc8x6::checks::motion,
    cnc8x6::flow::{FlowCheck, ModalState, Visit},
    diagnostic::declare_rules,
    lower::{BlockData, Value, Word},
};

declare_rules! {
    INVALID_DYNAMIC_SET = "D901", "invalid-dynamic-set", Warning, "G23 I selecting a dynamic set other than 1 to 4, or in an arc block where I is the circle centre.";
    CONTINUITY_MODE_DISABLED = "D902", "continuity-mode-disabled", Info, "G23 while machine constant R97 switches continuity control off.";
    RAPID_BREAKS_CONTINUITY = "D903", "rapid-breaks-continuity", Info, "A rapid G00 move between G23 feed blocks, which stops the axes.";
    NON_MOTION_BLOCK_BREAKS_CONTINUITY = "D904", "non-motion-block-breaks-continuity", Info, "A block without motion between G23 feed blocks, which stops the axes.";
    CONTINUITY_BREAK_MANUAL_MODE = "D905", "continuity-break-manual-mode", Info, "With manual continuity, a motion block after G23 blocks that is not itself a G23 block.";
    CONTINUITY_WITH_EXTRA_AXES = "D906", "continuity-with-extra-axes", Info, "With automatic continuity, a G23 block that moves an axis beyond the first three.";
    BLOCK_TOO_SHORT_FOR_CONTINUITY = "D907", "block-too-short-for-continuity", Warning, "A G23 block shorter in time than the minimum for smooth joining.";
    BLOCK_TOO_SHORT_FOR_TIGHT_JOINING = "D908", "block-too-short-for-tight-joining", Info, "A G24 block shorter in time than the minimum for tight joining.";
    CONTINUITY_BREAK_TOO_SHORT_TO_BRAKE = "D909", "continuity-break-too-short-to-brake", Warning, "The last G23 block before continuity ends, shorter than the braking distance from its feed.";
    JUNCTION_ANGLE_STOP = "D910", "junction-angle-stop", Info, "With automatic continuity, a junction whose angle is not below R39, where the axes stop.";
    MISSING_CONTINUITY_MODE = "D911", "missing-continuity-mode", Info, "Many short feed blocks in a row without continuity, G23 not programmed before them.";
    SHORT_BLOCK_NOT_MERGED = "D912", "short-block-not-merged", Info, "A G23 block shorter than R383 that the control cannot merge into its neighbour.";
    BLOCK_SHORTER_THAN_R382 = "D913", "block-shorter-than-r382", Info, "A G23 block shorter than R382, where the control breaks continuity.";
}

/// How many short feed blocks in a row without continuity are "many": a
/// contour divided that finely spends its time ramping down and up.
const MANY_SHORT_BLOCKS: usize = 20;
/// The dynamic sets `G23 I1` … `G23 I4` (machine constants R406–R429).
const DYNAMIC_SETS: std::ops::RangeInclusive<i128> = 1..=4;
/// The rotary axis letters (degrees), whose moves have no path length.
const ROTARY_AXES: [u8; 3] = [b'A', b'B', b'C'];

/// How the control joins blocks under G23, when the configuration gives
/// R97: the velocity model would assume it.
fn joining(config: &Config) -> Option<Joining> {
    policy::joining(config.machine.known_decade(97, 1)?)
}

/// A length limit in mm from a machine constant (R382, R383): `None` when
/// unknown, zero, or negative (a minus sign blocks the limit).
fn length_limit(config: &Config, number: u32) -> Option<f64> {
    config.machine.known_constant(number).filter(|&raw| raw > 0).map(|raw| raw as f64 / 1000.0)
}

/// The path feed in mm/min, when its unit is known: F per minute (G94,
/// G96), with a decimal point in m/min, reduced 1:100 by M37.
fn feed_mm_per_min(state: &ModalState) -> Option<f64> {
    let setting = state.feed.known()??;
    if !matches!(state.g(6)?, Some(94 | 96)) {
        return None;
    }
    let factor = match state.m(4)? {
        Some(36) => 1.0,
        Some(37) => 0.01,
        _ => return None,
    };
    let feed = feed_number(setting.value) * factor;
    (feed.is_finite() && feed > 0.0).then_some(feed)
}

/// F as mm/min (or µm/rev): a decimal point means m/min (mm/rev).
fn feed_number(value: Decimal) -> f64 {
    if value.has_point() { value.to_f64() * 1000.0 } else { value.to_f64() }
}

/// How long a path takes at a feed (mm/min), in s.
fn duration(length: f64, feed: f64) -> f64 {
    length / feed * 60.0
}

type Vector = [f64; 3];

/// A block's programmed path, in millimetres.
struct Path {
    length: f64,
    /// Unit tangents at the start and at the end, in the machine's first
    /// three axes (those automatic continuity compares); `None` when
    /// unknown or when the path does not move them.
    start: Option<Vector>,
    end: Option<Vector>,
}

/// A circular arc in the plane of two axes, in millimetres.
pub(crate) struct Arc {
    pub radius: f64,
    /// Angle of the start point seen from the centre, radians.
    pub start_angle: f64,
    /// Swept angle, radians: positive counter-clockwise (G03), negative
    /// clockwise (G02); a full circle when start and end coincide.
    pub sweep: f64,
}

impl Arc {
    /// The arc of a G02 (`clockwise`) or G03 block from `start` to `end`,
    /// with the centre `offset` from the start (I, J are always
    /// incremental); `None` when the end lies farther than `tolerance` (the
    /// machine's, R55) off the circle, which the control stops on.
    pub fn through(start: [f64; 2], end: [f64; 2], offset: [f64; 2], clockwise: bool, tolerance: f64) -> Option<Arc> {
        let centre = [start[0] + offset[0], start[1] + offset[1]];
        let circle = circle_through(start, end, centre, !clockwise, tolerance).ok()?;
        (circle.radius > 0.0).then_some(Arc {
            radius: circle.radius,
            start_angle: circle.start_angle,
            sweep: circle.sweep,
        })
    }

    pub fn length(&self) -> f64 {
        self.radius * self.sweep.abs()
    }

    /// The unit direction of motion at angle `angle` on the arc.
    pub fn tangent_at(&self, angle: f64) -> [f64; 2] {
        let direction = self.sweep.signum();
        [-angle.sin() * direction, angle.cos() * direction]
    }

    pub fn start_tangent(&self) -> [f64; 2] {
        self.tangent_at(self.start_angle)
    }

    pub fn end_tangent(&self) -> [f64; 2] {
        self.tangent_at(self.start_angle + self.sweep)
    }
}

/// How X positions map to path lengths: halved under diameter programming
/// (G74). Without G74/G75 a machine with a diameter axis starts in diameter
/// programming, and one with a Y axis is taken as a mill, which programs X
/// as a coordinate; on another lathe the scale is then unknown.
fn x_scale(visit: &Visit<'_>) -> Option<f64> {
    let machine = &visit.config.machine;
    match visit.after.g(10) {
        Some(Some(74)) => Some(0.5),
        Some(_) => Some(1.0),
        None if machine.diameter_axis.is_some() => Some(0.5),
        None => machine.is_axis(b'Y').then_some(1.0),
    }
}

fn axis_words<'a>(visit: &'a Visit<'_>) -> impl Iterator<Item = &'a Word> {
    let catalogue = Dialect::Cnc8x6.catalogue();
    visit.block.words.iter().filter(move |w| catalogue.role_of(w.letter) == Some(AddressRole::Axis))
}

/// Whether axis `letter` is known to move in the block.
fn axis_moves(visit: &Visit<'_>, letter: u8) -> bool {
    matches!((visit.before.position(letter), visit.after.position(letter)), (Some(from), Some(to)) if from != to)
}

/// The slot of `letter` among the machine's first three axes.
fn direction_slot(config: &Config, letter: u8) -> Option<usize> {
    config.machine.axes.iter().take(3).position(|&axis| axis == letter)
}

fn unit(vector: Vector) -> Option<Vector> {
    let norm = vector.iter().map(|c| c * c).sum::<f64>().sqrt();
    (norm > 0.0).then(|| vector.map(|c| c / norm))
}

/// The path of a moving block when every position it needs is known.
fn path(visit: &Visit<'_>) -> Option<Path> {
    if !motion::moves(visit) {
        return None;
    }
    let scale = x_scale(visit);
    match visit.after.g(0)?? {
        0 | 1 => line(visit, scale),
        code @ (2 | 3) => arc_path(visit, scale?, code == 2),
        _ => None,
    }
}

fn line(visit: &Visit<'_>, scale: Option<f64>) -> Option<Path> {
    let mut squares = 0.0;
    let mut direction = [0.0; 3];
    let mut direction_known = true;
    for word in axis_words(visit) {
        let (from, to) = (visit.before.position(word.letter)?, visit.after.position(word.letter)?);
        if from == to {
            continue;
        }
        if ROTARY_AXES.contains(&word.letter) {
            return None;
        }
        // An unknown diameter scale makes X at most as long as written,
        // which is enough for lengths but not for directions.
        let axis_scale = if word.letter == b'X' { scale } else { Some(1.0) };
        direction_known &= axis_scale.is_some();
        let delta = (to - from) as f64 / 1000.0 * axis_scale.unwrap_or(1.0);
        squares += delta * delta;
        if let Some(slot) = direction_slot(visit.config, word.letter) {
            direction[slot] = delta;
        }
    }
    let direction = if direction_known { unit(direction) } else { None };
    (squares > 0.0).then(|| Path { length: squares.sqrt(), start: direction, end: direction })
}

/// The path of a G02/G03 block in the plane of its two axis words.
fn arc_path(visit: &Visit<'_>, scale: f64, clockwise: bool) -> Option<Path> {
    let mut letters: Vec<u8> = axis_words(visit).map(|w| w.letter).collect();
    letters.dedup();
    let [one, other] = letters[..] else { return None };
    let plane = arcs::arc_plane(&visit.config.machine, one, other)?;
    let point = |state: &ModalState| -> Option<[f64; 2]> {
        let mut point = [0.0; 2];
        for (slot, &letter) in plane.iter().enumerate() {
            let axis_scale = if letter == b'X' { scale } else { 1.0 };
            point[slot] = state.position(letter)? as f64 / 1000.0 * axis_scale;
        }
        Some(point)
    };
    let offset = [centre_offset(visit, b'I')?, centre_offset(visit, b'J')?];
    let tolerance = visit.config.machine.arc_tolerance();
    let arc = Arc::through(point(visit.before)?, point(visit.after)?, offset, clockwise, tolerance)?;
    let in_space = |tangent: [f64; 2]| -> Option<Vector> {
        let mut vector = [0.0; 3];
        for (slot, &letter) in plane.iter().enumerate() {
            vector[direction_slot(visit.config, letter)?] = tangent[slot];
        }
        Some(vector)
    };
    Some(Path { length: arc.length(), start: in_space(arc.start_tangent()), end: in_space(arc.end_tangent()) })
}

/// The circle-centre distance under I or J in mm (0 when not written).
fn centre_offset(visit: &Visit<'_>, letter: u8) -> Option<f64> {
    let Some(index) = visit.block.words.iter().position(|w| w.letter == letter) else { return Some(0.0) };
    micrometres(visit, index).map(|value| value as f64 / 1000.0)
}

/// A dimensional word's value in thousandths (µm), literal or substituted.
fn micrometres(visit: &Visit<'_>, index: usize) -> Option<i128> {
    match (&visit.block.words.get(index)?.value, visit.substitutions.get(index)?) {
        (Some(Value::Literal(value)), _) => value.scaled(3),
        (Some(Value::Parameter { .. }), Some(substitution)) => Some(i128::from(substitution.raw)),
        _ => None,
    }
}

/// The block's coordinates: from its first axis word to its last.
fn coordinates(visit: &Visit<'_>) -> Option<TextRange> {
    let first = axis_words(visit).next()?;
    let last = axis_words(visit).last()?;
    Some(visit.range(first.range.cover(last.range)))
}

/// The first thing written in a block: a word, an assignment or its number.
fn head(visit: &Visit<'_>) -> TextRange {
    let block = visit.block;
    let range = block
        .body_words()
        .next()
        .map(|w| w.range)
        .or_else(|| block.assignments.first().map(|a| a.range))
        .or_else(|| block.number.map(|n| n.range))
        .unwrap_or_default();
    visit.range(range)
}

/// The feed in the message, and where it was programmed when that was in
/// an earlier block.
fn with_feed_origin(diagnostic: Diagnostic, visit: &Visit<'_>) -> Diagnostic {
    let block = TextRange::at(visit.offset, visit.block.len);
    match visit.after.feed {
        Known::Is(Some(setting)) if !block.contains_range(setting.range) => {
            diagnostic.with_related(None, setting.range, "the feed is programmed here")
        }
        _ => diagnostic,
    }
}

/// A word as written, for messages (`M08`).
fn written(word: &Word) -> String {
    match &word.value {
        Some(Value::Literal(value)) => format!("{}{value}", char::from(word.letter)),
        _ => char::from(word.letter).to_string(),
    }
}

fn mm(value: f64) -> String {
    format!("{value:.3} mm")
}

/// The last block joined under G23, from which continuity may carry on.
struct SmoothBlock {
    feed: Option<f64>,
    length: Option<f64>,
    end: Option<Vector>,
    range: TextRange,
    /// The path is known to run into it without a stop.
    entered_moving: bool,
}

/// A block that stops the axes while G23 stays active.
struct Interruption {
    rapid: bool,
    range: TextRange,
}

#[derive(Default)]
pub(crate) struct Dynamics {
    /// The velocity model's parameters for the machine, with R97 as the
    /// configuration gives it.
    model: Option<velocity::Dynamics>,
    smooth: Option<SmoothBlock>,
    /// The first interruption since `smooth`.
    interruption: Option<Interruption>,
    /// Short feed blocks in a row without continuity, from the first one.
    short_run: usize,
    short_run_start: Option<TextRange>,
    /// The advice to program G23 is given once per program.
    continuity_advised: bool,
    g23_seen: bool,
    disabled_reported: bool,
}

impl FlowCheck for Dynamics {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        // A line with nothing but a comment is no block for the control.
        if visit.block.words.is_empty() && visit.block.assignments.is_empty() {
            return;
        }
        check_dynamic_set(visit, out);
        let joining = joining(visit.config);
        if let Some(range) = visit.code_range(b'G', 23) {
            self.g23_seen = true;
            // Once: the setting belongs to the machine, not to the block.
            if joining == Some(Joining::Off) && !self.disabled_reported {
                self.disabled_reported = true;
                out.push(Diagnostic::new(
                    &CONTINUITY_MODE_DISABLED,
                    range,
                    "G23 has no effect: machine constant R97 decade 1 is 0, which switches continuity control off; set R97 to 1 (manual) or 2 (automatic recognition), or leave G23 out",
                ));
            }
        }
        // Calls, jumps and subprogram boundaries lead to the blocks the walk
        // visits next; they are not blocks the axes wait for.
        let catalogue = Dialect::Cnc8x6.catalogue();
        let transfer = visit.codes.iter().any(|&(letter, number, _)| {
            letter == b'G' && catalogue.group_of('G', number).is_some_and(|g| g.id == "G7")
        });
        if transfer {
            return;
        }
        let model = self.model.take().unwrap_or_else(|| {
            let mut model = policy::dynamics(&visit.config.machine);
            model.joining = joining.unwrap_or(model.joining);
            model
        });
        let path = path(visit);
        let feed = feed_mm_per_min(visit.after);
        let feed_move = motion::moves(visit) && matches!(visit.after.g(0), Some(Some(1..=3)));
        self.check_without_continuity(visit, &model, feed_move, path.as_ref(), feed, out);
        if feed_move && visit.after.g(2) == Some(Some(24)) {
            check_tight_joining(visit, &model, path.as_ref(), feed, out);
        }
        if joining.is_some_and(|joining| joining != Joining::Off) {
            self.continuity(visit, &model, feed_move, path, feed, out);
        } else {
            self.smooth = None;
            self.interruption = None;
        }
        self.model = Some(model);
    }

    fn end_of_unit(&mut self, _state: &ModalState, _last: Option<(TextSize, &BlockData)>, _out: &mut Vec<Diagnostic>) {
        // The next block walked may belong to another run of the program.
        self.smooth = None;
        self.interruption = None;
        self.short_run = 0;
    }
}

/// `G23 I<n>`: the dynamic set, 1 to 4, and not in an arc block.
fn check_dynamic_set(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    if !visit.has_code(b'G', 23) {
        return;
    }
    let Some((index, word)) = visit.block.words.iter().enumerate().find(|(_, w)| w.letter == b'I') else { return };
    let range = visit.range(word.range);
    // An arc written in the block, or a modal one the block moves along.
    let arc = [2, 3].into_iter().find(|&code| visit.has_code(b'G', code)).or_else(|| match visit.after.g(0) {
        Some(Some(code @ (2 | 3))) if motion::moves(visit) => Some(code),
        _ => None,
    });
    if let Some(arc) = arc {
        out.push(Diagnostic::new(
            &INVALID_DYNAMIC_SET,
            range,
            format!(
                "in a G{arc:02} block I is the circle centre, so it is unclear whether this I selects a dynamic set of G23; write `G23 I<set>` in a block of its own"
            ),
        ));
        return;
    }
    let Some(value) = micrometres(visit, index) else { return };
    let set = (value % 1000 == 0).then_some(value / 1000).filter(|set| DYNAMIC_SETS.contains(set));
    if set.is_none() {
        out.push(Diagnostic::new(
            &INVALID_DYNAMIC_SET,
            range,
            format!(
                "G23 I selects dynamic set 1 to 4 (machine constants R406–R429), but I is {}; write I1, I2, I3 or I4",
                value as f64 / 1000.0
            ),
        ));
    }
}

/// G24 joins blocks tightly only when each lasts the minimum time.
fn check_tight_joining(
    visit: &Visit<'_>,
    model: &velocity::Dynamics,
    path: Option<&Path>,
    feed: Option<f64>,
    out: &mut Vec<Diagnostic>,
) {
    let (Some(path), Some(feed), Some(range)) = (path, feed, coordinates(visit)) else { return };
    let duration = duration(path.length, feed);
    if model.too_short_to_prepare(duration) {
        let diagnostic = Diagnostic::new(
            &BLOCK_TOO_SHORT_FOR_TIGHT_JOINING,
            range,
            format!(
                "this G24 move of {} takes {} at {feed:.0} mm/min, but tight joining needs blocks of at least {}, so the control may not join it tightly; lengthen the block or lower the feed",
                mm(path.length),
                ms(duration),
                ms(model.min_tight_joining)
            ),
        );
        out.push(with_feed_origin(diagnostic, visit));
    }
}

/// Seconds as whole milliseconds.
fn ms(seconds: f64) -> String {
    format!("{:.0} ms", seconds * 1000.0)
}

impl Dynamics {
    /// Runs of short feed blocks under G98 (the reset state) while G23 has
    /// not been programmed.
    fn check_without_continuity(
        &mut self,
        visit: &Visit<'_>,
        model: &velocity::Dynamics,
        feed_move: bool,
        path: Option<&Path>,
        feed: Option<f64>,
        out: &mut Vec<Diagnostic>,
    ) {
        let short = feed_move
            && !self.g23_seen
            && !self.continuity_advised
            && visit.after.g(2) == Some(Some(98))
            && matches!((path, feed), (Some(path), Some(feed)) if model.too_short_to_join(duration(path.length, feed)).is_some());
        if !short {
            self.short_run = 0;
            return;
        }
        if self.short_run == 0 {
            self.short_run_start = coordinates(visit);
        }
        self.short_run += 1;
        if self.short_run == MANY_SHORT_BLOCKS
            && let Some(range) = self.short_run_start
        {
            self.continuity_advised = true;
            out.push(Diagnostic::new(
                &MISSING_CONTINUITY_MODE,
                range,
                format!(
                    "{MANY_SHORT_BLOCKS} or more feed blocks in a row from here last less than {} each and run without continuity (G98, the state after reset): the axes ramp down to a stop at the end of every one; program G23 at the start of the program so that the control can join them (machine constant R97 selects how)",
                    ms(model.min_continuity)
                ),
            ));
        }
    }

    /// Junctions and block durations under G23.
    fn continuity(
        &mut self,
        visit: &Visit<'_>,
        model: &velocity::Dynamics,
        feed_move: bool,
        path: Option<Path>,
        feed: Option<f64>,
        out: &mut Vec<Diagnostic>,
    ) {
        let g23 = visit.after.g(2) == Some(Some(23));
        let moves = motion::moves(visit);
        if feed_move && g23 {
            let entered_moving = self.smooth_block(visit, model, path.as_ref(), feed, out);
            let range = coordinates(visit).unwrap_or_else(|| head(visit));
            self.smooth = Some(SmoothBlock {
                feed,
                length: path.as_ref().map(|p| p.length),
                end: path.and_then(|p| p.end),
                range,
                entered_moving,
            });
            self.interruption = None;
            return;
        }
        if g23 {
            let stops = if !moves {
                Some(false)
            } else if visit.after.g(0) == Some(Some(0)) {
                Some(true)
            } else {
                None
            };
            match stops {
                Some(rapid) => {
                    if self.smooth.is_some() && self.interruption.is_none() {
                        let range = if rapid { visit.code_range(b'G', 0) } else { None };
                        self.interruption = Some(Interruption { rapid, range: range.unwrap_or_else(|| head(visit)) });
                    }
                }
                // A thread or an unknown motion: nothing to prove.
                None => {
                    self.smooth = None;
                    self.interruption = None;
                }
            }
            return;
        }
        let interrupted = self.interruption.take().is_some();
        let previous = self.smooth.take().filter(|_| !interrupted);
        let ends = visit.before.g(2) == Some(Some(23)) && visit.after.g(2).is_some() && moves;
        if let Some(previous) = previous.filter(|_| ends) {
            continuity_ends(visit, model, &previous, out);
        }
    }

    /// A G23 feed block: the junction into it and its own length. Whether
    /// the path is known to run into it without a stop.
    fn smooth_block(
        &mut self,
        visit: &Visit<'_>,
        model: &velocity::Dynamics,
        path: Option<&Path>,
        feed: Option<f64>,
        out: &mut Vec<Diagnostic>,
    ) -> bool {
        let mut entered_moving = false;
        match (&self.smooth, self.interruption.take()) {
            (Some(previous), Some(interruption)) => {
                let diagnostic = if interruption.rapid {
                    Diagnostic::new(
                        &RAPID_BREAKS_CONTINUITY,
                        interruption.range,
                        "rapid G00 between G23 feed blocks is never joined smoothly: the axes stop before and after it; if the path should run on, move at feed (G01)",
                    )
                } else {
                    Diagnostic::new(
                        &NON_MOTION_BLOCK_BREAKS_CONTINUITY,
                        interruption.range,
                        "a block without motion between G23 feed blocks breaks continuity: the axes stop at the end of the previous block; write these words in a motion block instead",
                    )
                };
                out.push(diagnostic.with_related(None, previous.range, "the smooth path before it ends here"));
            }
            (Some(previous), None) => {
                let corner = check_junction_angle(visit, model, previous, path, out);
                let durations = [previous.length.zip(previous.feed), path.map(|p| p.length).zip(feed)];
                let long_enough = durations.iter().all(|known| {
                    known.is_some_and(|(length, feed)| model.too_short_to_join(duration(length, feed)).is_none())
                });
                entered_moving = corner == Some(false) && long_enough;
            }
            (None, _) => {}
        }
        if check_extra_axes(visit, model, out) {
            entered_moving = false;
        }
        if let Some(path) = path {
            check_short_smooth_block(visit, model, path, feed, out);
        }
        entered_moving
    }
}

/// A moving block that leaves G23 right after a smooth block.
fn continuity_ends(visit: &Visit<'_>, model: &velocity::Dynamics, previous: &SmoothBlock, out: &mut Vec<Diagnostic>) {
    let Some(Some(code)) = visit.after.g(2) else { return };
    let Some(code_range) = visit.code_range(b'G', code) else { return };
    let stop = model.entered(path_mode(Some(code)));
    if model.joining == Joining::Programmed && stop.is_some() {
        out.push(
            Diagnostic::new(
                &CONTINUITY_BREAK_MANUAL_MODE,
                code_range,
                format!(
                    "with manual continuity (R97 = 1) only G23 feed blocks are entered smoothly: the axes stop before this G{code} block; keep G23 here if the path should run on"
                ),
            )
            .with_related(None, previous.range, "the last smooth block"),
        );
    }
    // The stop comes before this block, so the last smooth block must brake
    // within itself; the control looks one block ahead only, and slows the
    // path down before that block when it is too short (000:7014-7025).
    let (Some(length), Some(feed), Some(acceleration)) =
        (previous.length, previous.feed, continuity_acceleration(visit.config))
    else {
        return;
    };
    let braking = velocity::Dynamics::braking_distance(feed / 60.0, acceleration);
    if stop.is_some() && previous.entered_moving && length < braking {
        out.push(
            Diagnostic::new(
                &CONTINUITY_BREAK_TOO_SHORT_TO_BRAKE,
                previous.range,
                format!(
                    "continuity ends at the G{code} block after this one, so the axes must stop within this G23 block of {}; stopping from {feed:.0} mm/min takes {} at {acceleration:.0} mm/s²: the path slows down before it reaches the feed, and the control, which looks only one block ahead, cannot brake any earlier; end continuity after a longer block or lower the feed",
                    mm(length),
                    mm(braking)
                ),
            )
            .with_related(None, code_range, format!("continuity ends with G{code} here")),
        );
    }
}

/// The acceleration under continuity in mm/s²: R236, or R52 when R236 is 0.
fn continuity_acceleration(config: &Config) -> Option<f64> {
    let positive = |number| config.machine.known_constant(number).filter(|&raw| raw > 0);
    match config.machine.known_constant(236)? {
        0 => positive(52),
        raw => Some(raw).filter(|&raw| raw > 0),
    }
    .map(|raw| raw as f64)
}

/// Automatic continuity stops where the tangents turn by R39 or more.
/// Whether it does, when the tangents are known.
fn check_junction_angle(
    visit: &Visit<'_>,
    model: &velocity::Dynamics,
    previous: &SmoothBlock,
    path: Option<&Path>,
    out: &mut Vec<Diagnostic>,
) -> Option<bool> {
    let (before, after) = (previous.end?, path?.start?);
    let Some(Reason::Corner { angle, limit }) = model.corner(before, after) else { return Some(false) };
    if let Some(range) = coordinates(visit) {
        out.push(
            Diagnostic::new(
                &JUNCTION_ANGLE_STOP,
                range,
                format!(
                    "the path turns by {angle:.1}° into this block, not less than the tolerance angle R39 ({limit:.3}°): automatic continuity stops the axes at the end of the previous block and starts again; round the corner if the path should run on"
                ),
            )
            .with_related(None, previous.range, "the previous block ends here"),
        );
    }
    Some(true)
}

/// Automatic recognition covers the machine's first three axes only.
/// Whether the block moves another.
fn check_extra_axes(visit: &Visit<'_>, model: &velocity::Dynamics, out: &mut Vec<Diagnostic>) -> bool {
    let axes = &visit.config.machine.axes;
    let first_three = axes.get(..3).unwrap_or(axes);
    let extra = axis_words(visit).find(|w| !first_three.contains(&w.letter) && axis_moves(visit, w.letter));
    let Some(word) = extra.filter(|_| model.beyond_three_axes(true).is_some()) else { return false };
    let first_three: Vec<String> = first_three.iter().map(|&a| char::from(a).to_string()).collect();
    out.push(Diagnostic::new(
        &CONTINUITY_WITH_EXTRA_AXES,
        visit.range(word.range),
        format!(
            "automatic continuity recognition (R97 = 2) covers only the first three axes ({}): this G23 block also moves {}, so it may not be joined smoothly",
            first_three.join(", "),
            char::from(word.letter)
        ),
    ));
    true
}

/// Short G23 blocks: merged (R383), breaking continuity (R382), or too
/// short in time to be joined.
fn check_short_smooth_block(
    visit: &Visit<'_>,
    model: &velocity::Dynamics,
    path: &Path,
    feed: Option<f64>,
    out: &mut Vec<Diagnostic>,
) {
    let Some(range) = coordinates(visit) else { return };
    let config = visit.config;
    if let Some(merge_limit) = length_limit(config, 383).filter(|&limit| path.length < limit) {
        match merge_obstacle(visit) {
            // Merged into its neighbour: the block no longer exists.
            Some(None) => return,
            Some(Some((obstacle, why))) => out.push(Diagnostic::new(
                &SHORT_BLOCK_NOT_MERGED,
                obstacle,
                format!(
                    "this G23 block of {} is shorter than R383 ({}), but the control merges such blocks into their neighbour only when they are linear without technology functions, feed change or G91; {why}, so it stays a block of its own and slows the motion",
                    mm(path.length),
                    mm(merge_limit)
                ),
            )),
            None => return,
        }
    }
    if let Some(limit) = length_limit(config, 382).filter(|&limit| path.length < limit) {
        out.push(Diagnostic::new(
            &BLOCK_SHORTER_THAN_R382,
            range,
            format!(
                "this G23 block of {} is shorter than R382 ({}): the control breaks continuity here and the axes slow down",
                mm(path.length),
                mm(limit)
            ),
        ));
        return;
    }
    let Some(feed) = feed else { return };
    if let Some(Reason::ShortBlock { duration, limit }) = model.too_short_to_join(duration(path.length, feed)) {
        let diagnostic = Diagnostic::new(
            &BLOCK_TOO_SHORT_FOR_CONTINUITY,
            range,
            format!(
                "this G23 move of {} takes {} at {feed:.0} mm/min, but blocks are joined smoothly only when they last at least {}: the axes slow down here; combine it with its neighbours or lower the feed",
                mm(path.length),
                ms(duration),
                ms(limit)
            ),
        );
        out.push(with_feed_origin(diagnostic, visit));
    }
}

/// What keeps a short block from being merged: `Some(None)` when nothing
/// does, `None` when that is not known.
fn merge_obstacle(visit: &Visit<'_>) -> Option<Option<(TextRange, String)>> {
    let coordinates = coordinates(visit)?;
    if let Some(Some(arc @ (2 | 3))) = visit.after.g(0) {
        let range = visit.code_range(b'G', arc).unwrap_or(coordinates);
        return Some(Some((range, format!("this one is an arc (G{arc:02})"))));
    }
    if visit.after.g(9)? == Some(91) {
        let range = visit.code_range(b'G', 91).unwrap_or(coordinates);
        return Some(Some((range, "this one is programmed incrementally (G91)".to_owned())));
    }
    if let Some(word) = visit.block.word(b'F') {
        let changes = match (visit.before.feed.known()?, visit.after.feed.known()?) {
            (Some(before), Some(after)) => feed_number(before.value) != feed_number(after.value),
            (None, _) => true,
            (_, None) => return None,
        };
        if changes {
            return Some(Some((visit.range(word.range), "this one changes the feed".to_owned())));
        }
    }
    let catalogue = Dialect::Cnc8x6.catalogue();
    let technology = visit.block.body_words().find(|w| {
        w.letter == b'M'
            || matches!(
                catalogue.role_of(w.letter),
                Some(AddressRole::Speed | AddressRole::Tool | AddressRole::Auxiliary)
            )
    });
    if let Some(word) = technology {
        return Some(Some((
            visit.range(word.range),
            format!("this one programs the technology function {}", written(word)),
        )));
    }
    Some(None)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::Arc;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn arc_length_follows_the_direction() {
        // From (0,0) around (10,0) to (20,0): half a circle either way.
        let ccw = Arc::through([0.0, 0.0], [20.0, 0.0], [10.0, 0.0], false, 0.001).unwrap();
        assert!(close(ccw.length(), 10.0 * PI));
        // A quarter one way is three quarters the other.
        let quarter = Arc::through([10.0, 0.0], [0.0, 10.0], [-10.0, 0.0], false, 0.001).unwrap();
        assert!(close(quarter.length(), 5.0 * PI));
        let three_quarters = Arc::through([10.0, 0.0], [0.0, 10.0], [-10.0, 0.0], true, 0.001).unwrap();
        assert!(close(three_quarters.length(), 15.0 * PI));
    }

    #[test]
    fn arc_to_its_start_is_a_full_circle() {
        for clockwise in [false, true] {
            let full = Arc::through([5.0, 0.0], [5.0, 0.0], [-5.0, 0.0], clockwise, 0.001).unwrap();
            assert!(close(full.length(), 10.0 * PI));
        }
    }

    #[test]
    fn arc_tangents_point_along_the_motion() {
        // Counter-clockwise from below the centre: leaves along +X, ends along +Y.
        let arc = Arc::through([0.0, 0.0], [10.0, 10.0], [0.0, 10.0], false, 0.001).unwrap();
        let [sx, sy] = arc.start_tangent();
        let [ex, ey] = arc.end_tangent();
        assert!(close(sx, 1.0) && close(sy, 0.0));
        assert!(close(ex, 0.0) && close(ey, 1.0));
        // Clockwise from above the centre: leaves along +X, ends along -Y.
        let arc = Arc::through([0.0, 10.0], [10.0, 0.0], [0.0, -10.0], true, 0.001).unwrap();
        let [ex, ey] = arc.end_tangent();
        assert!(close(arc.start_tangent()[0], 1.0) && close(ex, 0.0) && close(ey, -1.0));
    }

    #[test]
    fn end_off_the_circle_has_no_arc() {
        assert!(Arc::through([0.0, 0.0], [25.0, 0.0], [10.0, 0.0], false, 0.001).is_none());
        assert!(Arc::through([0.0, 0.0], [0.0, 0.0], [0.0, 0.0], false, 0.001).is_none());
    }
}
