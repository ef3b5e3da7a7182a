//! BSPLINE (digest §3.2): while group 1 is BSPLINE, each block's end
//! point is a control point, with its weight PW, the knot interval PL from
//! the point before, and the degree SD (3 when not programmed; the last
//! SD of the curve holds). When the mode ends (another code of group 1, a
//! return, the program's end) the curve is built with
//! [`Spline::programmed`] from the position before the first BSPLINE
//! block, and each block's step becomes the straight pieces of the curve
//! within [`CHORD_TOLERANCE`] of it that belong to its knot interval, the
//! pieces joined end to end: the first with the block's path mode and
//! functions, the others continuous, the last with the block's stop. A block of the curve without a piece (its
//! point repeats the one before) ends where the curve is; so does any
//! block run while the curve was open.

use ncc_syntax::TextRange;

use super::{Interpreter, Moved, Words};
use crate::{
    spline::{ControlPoint, Spline, SplineError},
    trace::{Axes, Finding, MAX_AXES, Motion, Path, PathMode, Position, RunRule, Step},
    transform::over_axes,
};

/// How far the straight pieces may stray from the curve, in mm: 1 µm,
/// the grid positions lie on.
pub(super) const CHORD_TOLERANCE: f64 = 0.001;

/// A curve whose control points are being programmed.
pub(super) struct Pending {
    /// The position before its first point.
    start: Axes,
    points: Vec<Point>,
    degree: Option<usize>,
}

/// One control point: the step of its block, the point and the path feed
/// in mm/min at its block.
struct Point {
    step: usize,
    control: ControlPoint<MAX_AXES>,
    rate: Option<f64>,
}

impl Pending {
    /// The first step the curve may still change.
    pub(super) fn first_step(&self) -> usize {
        self.points.first().map_or(usize::MAX, |point| point.step)
    }
}

impl Interpreter<'_> {
    /// A block's control point from `start` to `end`: its step stands in
    /// for the pieces of the curve until the curve is built.
    pub(super) fn spline_point(&mut self, words: &Words, range: TextRange, start: &Position, end: &Position) -> Moved {
        let degree = match words.degree {
            Some(degree) if (1.0..=5.0).contains(&degree) && degree.fract() == 0.0 => Some(degree as usize),
            Some(_) => {
                self.state.finding(RunRule::ValueRefused, range, "SD, the spline's degree, is a whole number 1 to 5");
                return super::STILL;
            }
            None => None,
        };
        let axes = self.state.machine.step_axes();
        let pending = self.spline.get_or_insert_with(|| Pending {
            start: over_axes(start, axes),
            points: Vec::new(),
            degree: None,
        });
        pending.degree = degree.or(pending.degree);
        let control = ControlPoint {
            position: over_axes(end, axes),
            weight: words.weight,
            interval: words.interval.map(|length| self.length(length)),
        };
        let rate = self.feed_rate(range);
        let step = self.steps.next();
        if let Some(pending) = self.spline.as_mut() {
            pending.points.push(Point { step, control, rate });
        }
        Moved { motion: Motion::Feed, path: Path::Straight, length: 0.0, duration: 0.0, feed: rate }
    }

    /// Builds the open curve, if any, into its blocks' steps.
    pub(super) fn end_spline(&mut self) {
        let Some(pending) = self.spline.take() else { return };
        let controls: Vec<ControlPoint<MAX_AXES>> = pending.points.iter().map(|point| point.control).collect();
        let curve = match Spline::programmed(pending.start, &controls, pending.degree) {
            Ok(curve) => curve,
            Err(error) => return self.spline_failed(&pending, error),
        };
        let parameters = point_parameters(&pending.start, &controls);
        let polyline = curve.polyline(CHORD_TOLERANCE);
        // The pieces of each point's knot interval.
        let mut pieces: Vec<Vec<(Axes, f64)>> = vec![Vec::new(); pending.points.len()];
        let mut point = 0;
        for pair in polyline.windows(2) {
            let (from, to) = (pair[0], pair[1]);
            while point + 1 < parameters.len() && to.parameter > parameters[point] + 1e-9 {
                point += 1;
            }
            let length = from.position.iter().zip(&to.position).map(|(a, b)| (b - a).powi(2)).sum::<f64>().sqrt();
            pieces[point].push((to.position, length));
        }
        let first = pending.first_step() - self.steps.delivered;
        let tail: Vec<Step> = self.steps.steps.drain(first..).collect();
        let mut at = pending.start;
        let mut replaced = Vec::with_capacity(tail.len() + polyline.len());
        for (offset, step) in tail.into_iter().enumerate() {
            let index = pending.points.iter().position(|point| point.step == first + self.steps.delivered + offset);
            let Some(index) = index.filter(|&index| !pieces[index].is_empty()) else {
                replaced.push(Step { end: at, ..step });
                continue;
            };
            let rate = pending.points[index].rate;
            let last = pieces[index].len() - 1;
            for (piece, &(end, length)) in pieces[index].iter().enumerate() {
                let duration = rate.map_or(0.0, |rate| length / rate * 60.0);
                let mut made = Step { end, length, duration, feed: rate, ..step.clone() };
                // Inside its block the curve runs on: only the block's
                // first piece joins as the block's mode says, and the last
                // stops where the block does.
                if piece > 0 {
                    (made.path_mode, made.m_functions, made.tool_change) = (PathMode::Continuous, 0, false);
                }
                if piece < last {
                    made.stop = None;
                }
                replaced.push(made);
                at = end;
            }
        }
        self.steps.steps.extend(replaced);
    }

    fn spline_failed(&mut self, pending: &Pending, error: SplineError) {
        let (point, message) = match error {
            SplineError::Weight { point, weight } => (point, format!("PW={weight}: a point's weight is above 0")),
            SplineError::Interval { point, length } => (point, format!("PL={length}: a knot interval is above 0")),
            SplineError::Position { point } => (point, "a control point too far off for the spline".to_owned()),
            other => (0, format!("the spline cannot be built: {other:?}")),
        };
        let step = pending.points.get(point).map_or(pending.first_step(), |point| point.step);
        let Some(step) = self.steps.steps.get(step.wrapping_sub(self.steps.delivered)) else { return };
        let finding = Finding { rule: RunRule::ValueRefused, source: step.source, range: step.range, message };
        self.state.stopped = true;
        self.state.findings.push(finding);
    }
}

/// The curve parameter at each programmed point, as
/// [`Spline::programmed`] spaces them: PL, or the distance from the
/// point before; a point at the point before adds none.
fn point_parameters(start: &Axes, controls: &[ControlPoint<MAX_AXES>]) -> Vec<f64> {
    let mut before = *start;
    let mut total = 0.0;
    controls
        .iter()
        .map(|control| {
            let chord = before.iter().zip(&control.position).map(|(a, b)| (b - a).powi(2)).sum::<f64>().sqrt();
            let scale = before.iter().chain(&control.position).fold(1.0f64, |m, x| m.max(x.abs()));
            if chord > 1e-9 * scale {
                total += control.interval.unwrap_or(chord);
                before = control.position;
            }
            total
        })
        .collect()
}
