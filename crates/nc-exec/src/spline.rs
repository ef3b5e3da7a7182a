//! Rational B-spline (NURBS) curves over any number of axes: points,
//! first and second derivatives, curvature, arc length, polylines within a
//! chord tolerance and the highest curvature of each knot span, for the
//! tool path, the plot and the velocity model (v ≤ sqrt(a/κ)).
//!
//! [`Spline::new`] takes a curve as the mathematics writes it (degree,
//! control points, weights, knot vector). [`Spline::programmed`] builds it
//! the way a control that programs the control points block by block does
//! (Sinumerik's BSPLINE with SD, PW and PL), from the start position, the
//! programmed points and the requested degree; it knows no syntax, so the
//! dialect reads the words and reports the errors with their blocks.
//!
//! The formulas are standard NURBS theory (Piegl & Tiller, *The NURBS
//! Book*, 1997): Cox–de Boor basis functions and their derivatives (A2.2,
//! A2.3), rational derivatives from the homogeneous ones, κ = |C″ ⊥ C′| /
//! |C′|². How a programmed curve is built:
//!
//! - The curve starts at the start position (the current one) and ends at
//!   the last programmed point: the knot vector is clamped (the first and
//!   last degree + 1 knots equal). Siemens documents that the programmed
//!   points are control points the curve passes near, not the knot
//!   vector; clamping is the standard convention that makes the curve
//!   begin and end at its end points (assumption).
//! - Degree: SD, 3 when not programmed (Siemens documentation). With fewer
//!   points than degree + 1 the degree is lowered to the points less one,
//!   the highest a clamped curve through them can have (assumption): two
//!   points make a line, three a parabola.
//! - Weights: PW, 1 when not programmed (Siemens documentation); the start
//!   point has weight 1. A weight must be positive: Siemens allows PW=0,
//!   but a clamped end of weight 0 has no position, so it is refused
//!   everywhere ([`SplineError::Weight`]).
//! - Knot spacing: Siemens documents that the control computes it unless
//!   PL gives the parameter interval lengths, in path units, and not how.
//!   Here a point's PL is the interval from the point before to it, and a
//!   point without PL takes its distance from the point before (chord
//!   length, the usual choice; assumption). The inner knots are the
//!   averages of degree successive point parameters (Piegl & Tiller eq.
//!   9.8, their choice for curves fitted through points), the count a
//!   clamped curve needs whatever the degree: equal intervals h give inner
//!   knots h apart and end spans (degree + 1)·h/2 long. The parameter runs
//!   in path units from 0 to the sum of the intervals.
//! - A point at the position of the point before it adds no motion and is
//!   dropped, its weight (when programmed) replacing the earlier one's
//!   (assumption): programs that repeat the start position as the first
//!   control point then make the same curve as those that do not, instead
//!   of one that stands still at its start with a cusp of infinite
//!   curvature there.

use nalgebra::SVector;
use smallvec::{SmallVec, smallvec};

/// Room for the basis functions of degree 3 without allocating; higher
/// degrees spill to the heap.
type Basis<T> = SmallVec<[T; 4]>;

/// The Gauss–Legendre nodes on [−1, 1] and their weights, five points:
/// exact for polynomials up to degree 9.
const GAUSS_LEGENDRE: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_08),
    (0.906_179_845_938_664, 0.236_926_885_056_189_08),
];

/// The relative error the arc length aims at.
const LENGTH_TOLERANCE: f64 = 1e-13;

/// How deep the length and polyline subdivisions may halve an interval.
const MAX_DEPTH: u32 = 48;

/// How many halvings the length of a span may take, and its polyline: a
/// bound on the work whatever the curve (a rounding-noisy speed never
/// converges), far beyond what smooth spans need.
const LENGTH_HALVINGS: u32 = 1 << 12;
const POLYLINE_HALVINGS: u32 = 1 << 14;

/// The smallest chord tolerance a polyline takes, in path units (a
/// nanometre in millimetres): a smaller or non-positive one would ask for
/// points without end.
pub const MIN_CHORD_TOLERANCE: f64 = 1e-6;

/// Points closer than this, relative to their size (at least 1), are one
/// position.
const COINCIDENT: f64 = 1e-9;

/// One programmed control point of a spline: its position and its weight
/// and parameter interval when programmed (PW, PL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlPoint<const D: usize> {
    pub position: [f64; D],
    pub weight: Option<f64>,
    /// The length of the parameter interval from the point before to this
    /// one, in path units.
    pub interval: Option<f64>,
}

impl<const D: usize> ControlPoint<D> {
    /// A point without weight or interval.
    pub fn at(position: [f64; D]) -> Self {
        ControlPoint { position, weight: None, interval: None }
    }
}

/// Why a spline cannot be built. Indexes count the points given: for
/// [`Spline::programmed`], the programmed ones (not the start).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SplineError {
    /// Degree 0 joins no points by a path.
    ZeroDegree,
    /// A curve of a degree needs at least degree + 1 points.
    TooFewPoints { points: usize, degree: usize },
    /// The start position has a coordinate that is not a finite number.
    Start,
    /// A point has a coordinate that is not a finite number, or lies too
    /// far from the point before for a distance in floating point.
    Position { point: usize },
    /// A weight is not a positive finite number.
    Weight { point: usize, weight: f64 },
    /// A parameter interval is not a positive finite number, or the
    /// intervals add up beyond the floating-point range.
    Interval { point: usize, length: f64 },
    /// There are not as many weights as points.
    WeightCount { points: usize, weights: usize },
    /// The knot vector does not have points + degree + 1 finite knots in
    /// order, spanning a parameter range of some length.
    Knots,
}

/// A rational B-spline curve in `D` axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline<const D: usize> {
    degree: usize,
    points: Vec<SVector<f64, D>>,
    weights: Vec<f64>,
    knots: Vec<f64>,
}

/// The position and the first two derivatives of a curve at a parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Derivatives<const D: usize> {
    pub point: [f64; D],
    pub first: [f64; D],
    pub second: [f64; D],
}

/// A point of a polyline and the curve parameter it lies at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint<const D: usize> {
    pub parameter: f64,
    pub position: [f64; D],
}

/// One knot span of a curve, where it is one polynomial (or rational)
/// piece: its parameter range, its length and its highest curvature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub start: f64,
    pub end: f64,
    pub length: f64,
    /// The highest curvature (1/path unit), infinite at a cusp where the
    /// curve stops and turns.
    pub max_curvature: f64,
    /// The parameter where the curvature is highest.
    pub at: f64,
}

impl<const D: usize> Spline<D> {
    /// The curve of `degree` over `points`, with `weights` and `knots`
    /// (points + degree + 1 of them), with at least degree + 1 points.
    /// Degree 0 is a curve only of a single point.
    pub fn new(degree: usize, points: &[[f64; D]], weights: &[f64], knots: &[f64]) -> Result<Self, SplineError> {
        if degree == 0 && points.len() != 1 {
            return Err(SplineError::ZeroDegree);
        }
        if points.len() <= degree {
            return Err(SplineError::TooFewPoints { points: points.len(), degree });
        }
        if weights.len() != points.len() {
            return Err(SplineError::WeightCount { points: points.len(), weights: weights.len() });
        }
        if let Some(point) = points.iter().position(|point| !point.iter().all(|x| x.is_finite())) {
            return Err(SplineError::Position { point });
        }
        if let Some(point) = weights.iter().position(|&weight| !positive_finite(weight)) {
            return Err(SplineError::Weight { point, weight: weights[point] });
        }
        let last = points.len();
        let in_order = knots.windows(2).all(|pair| pair[0] <= pair[1]);
        if knots.len() != points.len() + degree + 1
            || !in_order
            || !knots.iter().all(|knot| knot.is_finite())
            || (points.len() > 1 && knots[degree] >= knots[last])
        {
            return Err(SplineError::Knots);
        }
        Ok(Spline {
            degree,
            points: points.iter().map(|&point| SVector::from(point)).collect(),
            weights: weights.to_vec(),
            knots: knots.to_vec(),
        })
    }

    /// The curve a control builds from the start position and the
    /// programmed control points with the degree programmed (SD), as the
    /// module's documentation describes.
    pub fn programmed(
        start: [f64; D],
        programmed: &[ControlPoint<D>],
        degree: Option<usize>,
    ) -> Result<Self, SplineError> {
        if degree == Some(0) {
            return Err(SplineError::ZeroDegree);
        }
        if !start.iter().all(|x| x.is_finite()) {
            return Err(SplineError::Start);
        }
        let mut points = vec![SVector::from(start)];
        let mut weights = vec![1.0];
        let mut intervals = Vec::new();
        let mut total = 0.0;
        for (index, control) in programmed.iter().enumerate() {
            if !control.position.iter().all(|x| x.is_finite()) {
                return Err(SplineError::Position { point: index });
            }
            let weight = control.weight.unwrap_or(1.0);
            if !positive_finite(weight) {
                return Err(SplineError::Weight { point: index, weight });
            }
            if let Some(length) = control.interval.filter(|&length| !positive_finite(length)) {
                return Err(SplineError::Interval { point: index, length });
            }
            let position = SVector::from(control.position);
            let before = points[points.len() - 1];
            let chord = (position - before).norm();
            if !chord.is_finite() {
                return Err(SplineError::Position { point: index });
            }
            if chord <= COINCIDENT * position.amax().max(before.amax()).max(1.0) {
                if control.weight.is_some() {
                    *weights.last_mut().expect("the start is a point") = weight;
                }
                continue;
            }
            let interval = control.interval.unwrap_or(chord);
            total += interval;
            if !total.is_finite() {
                return Err(SplineError::Interval { point: index, length: interval });
            }
            points.push(position);
            weights.push(weight);
            intervals.push(interval);
        }
        let degree = degree.unwrap_or(3).min(points.len() - 1);
        let knots = averaged_knots(&intervals, degree);
        Ok(Spline { degree, points, weights, knots })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    pub fn control_points(&self) -> impl ExactSizeIterator<Item = [f64; D]> + '_ {
        self.points.iter().map(|&point| point.into())
    }

    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The parameter range of the curve, from its start to its end.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.points.len()])
    }

    /// The point at parameter `u` (clamped to the domain).
    pub fn point(&self, u: f64) -> [f64; D] {
        self.evaluate(u, 0)[0].into()
    }

    /// The point and its first and second derivatives at `u`.
    pub fn derivatives(&self, u: f64) -> Derivatives<D> {
        let [point, first, second] = self.evaluate(u, 2);
        Derivatives { point: point.into(), first: first.into(), second: second.into() }
    }

    /// The curvature at `u`: infinite where the curve stops (its derivative
    /// vanishes) while still bending, as at a cusp.
    pub fn curvature(&self, u: f64) -> f64 {
        let [_, first, second] = self.evaluate(u, 2);
        curvature_of(&first, &second)
    }

    /// The length of the whole curve.
    pub fn length(&self) -> f64 {
        let (start, end) = self.domain();
        self.length_between(start, end)
    }

    /// The length of the curve between two parameters (clamped to the
    /// domain; negative when `to` comes before `from`). Each knot span is
    /// integrated on its own by adaptive Gauss–Legendre quadrature, since
    /// the speed is smooth only inside a span.
    pub fn length_between(&self, from: f64, to: f64) -> f64 {
        let (low, high) = (self.clamp(from.min(to)), self.clamp(from.max(to)));
        let sign = if to < from { -1.0 } else { 1.0 };
        let speed = |u: f64| self.evaluate(u, 1)[1].norm();
        let mut length = 0.0;
        for (start, end) in self.span_ranges() {
            let (a, b) = (start.max(low), end.min(high));
            if a < b {
                length += integrate(&speed, a, b);
            }
        }
        sign * length
    }

    /// Points along the curve, from its start to its end, such that the
    /// curve stays within `chord_tolerance` of the segments between them
    /// (checked at the quarters of each segment, with a margin, halving
    /// until it holds, up to 16 384 times a span).
    /// Every knot is a point, so a polyline of degree 1 is its control
    /// points. The tolerance is at least [`MIN_CHORD_TOLERANCE`].
    pub fn polyline(&self, chord_tolerance: f64) -> Vec<PathPoint<D>> {
        let tolerance = if chord_tolerance >= MIN_CHORD_TOLERANCE { chord_tolerance } else { MIN_CHORD_TOLERANCE };
        let (start, _) = self.domain();
        let mut points = vec![self.path_point(start)];
        for (a, b) in self.span_ranges() {
            let (from, to) = (self.path_point(a), self.path_point(b));
            let mut budget = POLYLINE_HALVINGS;
            self.refine(from, to, tolerance, MAX_DEPTH, &mut budget, &mut points);
        }
        points
    }

    /// The knot spans of the curve with their lengths and highest
    /// curvatures.
    pub fn spans(&self) -> Vec<Span> {
        self.span_ranges()
            .map(|(start, end)| {
                let (at, max_curvature) = self.max_curvature_in(start, end);
                Span { start, end, length: self.length_between(start, end), max_curvature, at }
            })
            .collect()
    }

    fn clamp(&self, u: f64) -> f64 {
        let (start, end) = self.domain();
        if u.is_nan() { start } else { u.clamp(start, end) }
    }

    /// The parameter ranges of the knot spans that have a length.
    fn span_ranges(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        let spans = &self.knots[self.degree..=self.points.len()];
        spans.windows(2).filter(|pair| pair[0] < pair[1]).map(|pair| (pair[0], pair[1]))
    }

    /// The index k of the knot span holding `u`: knots[k] ≤ u < knots[k+1]
    /// with knots[k] < knots[k+1], the last such span at the domain's end.
    fn span_index(&self, u: f64) -> usize {
        let last = self.points.len() - 1;
        let mut k = self.knots.partition_point(|&knot| knot <= u).saturating_sub(1).clamp(self.degree, last);
        while k > self.degree && self.knots[k] >= self.knots[k + 1] {
            k -= 1;
        }
        k
    }

    /// The point and its derivatives up to `order` (at most 2) at `u`,
    /// from the homogeneous curve (w·P, w).
    fn evaluate(&self, u: f64, order: usize) -> [SVector<f64, D>; 3] {
        let mut result = [SVector::zeros(); 3];
        if self.points.len() == 1 {
            result[0] = self.points[0];
            return result;
        }
        let u = self.clamp(u);
        let span = self.span_index(u);
        let basis = basis_derivatives(&self.knots, self.degree, span, u, order);
        let mut numerator = [SVector::<f64, D>::zeros(); 3];
        let mut denominator = [0.0; 3];
        for (j, derivatives) in basis.iter().enumerate() {
            let i = span - self.degree + j;
            for k in 0..=order {
                let weighted = derivatives[k] * self.weights[i];
                numerator[k] += self.points[i] * weighted;
                denominator[k] += weighted;
            }
        }
        // C = A/w, C′ = (A′ − w′C)/w, C″ = (A″ − 2w′C′ − w″C)/w.
        let w = denominator[0];
        result[0] = numerator[0] / w;
        result[1] = (numerator[1] - result[0] * denominator[1]) / w;
        result[2] = (numerator[2] - result[1] * (2.0 * denominator[1]) - result[0] * denominator[2]) / w;
        result
    }

    fn path_point(&self, parameter: f64) -> PathPoint<D> {
        PathPoint { parameter, position: self.point(parameter) }
    }

    /// Pushes the points after `from` up to `to` that keep the curve
    /// within `tolerance` of the polyline.
    fn refine(
        &self,
        from: PathPoint<D>,
        to: PathPoint<D>,
        tolerance: f64,
        depth: u32,
        budget: &mut u32,
        points: &mut Vec<PathPoint<D>>,
    ) {
        let (a, b) = (SVector::from(from.position), SVector::from(to.position));
        let width = to.parameter - from.parameter;
        let middle = self.path_point(from.parameter + width / 2.0);
        let deviation = [0.25, 0.5, 0.75]
            .map(|fraction| {
                let position =
                    if fraction == 0.5 { middle.position } else { self.point(from.parameter + width * fraction) };
                distance_to_segment(&SVector::from(position), &a, &b)
            })
            .into_iter()
            .fold(0.0, f64::max);
        // Between the quarters a cubic strays up to a tenth farther than
        // at them; a margin of a fifth covers that.
        let flat = deviation <= 0.8 * tolerance;
        // Not finite: the coordinates overflow, and halving cannot help.
        if depth == 0 || *budget == 0 || flat || !deviation.is_finite() {
            points.push(to);
            return;
        }
        *budget -= 1;
        self.refine(from, middle, tolerance, depth - 1, budget, points);
        self.refine(middle, to, tolerance, depth - 1, budget, points);
    }

    /// The highest curvature in [start, end] and where it is: the best of
    /// samples spaced for the span's degree, refined by golden-section
    /// search between the samples around it.
    fn max_curvature_in(&self, start: f64, end: f64) -> (f64, f64) {
        let samples = 4 * (self.degree + 1);
        let step = (end - start) / samples as f64;
        let at = |i: usize| if i == samples { end } else { start + step * i as f64 };
        let (best, best_curvature) = (0..=samples)
            .map(|i| (i, self.curvature(at(i))))
            .fold((0, f64::NEG_INFINITY), |best, sample| if sample.1 > best.1 { sample } else { best });
        if best_curvature.is_infinite() || best_curvature.is_nan() {
            return (at(best), best_curvature);
        }
        let (mut low, mut high) = (at(best.saturating_sub(1)), at((best + 1).min(samples)));
        let ratio = (5f64.sqrt() - 1.0) / 2.0;
        let (mut left, mut right) = (high - ratio * (high - low), low + ratio * (high - low));
        let (mut left_curvature, mut right_curvature) = (self.curvature(left), self.curvature(right));
        // Each step keeps 0.618 of the bracket: 40 leave 5e-9 of it.
        for _ in 0..40 {
            if left_curvature >= right_curvature {
                (high, right, right_curvature) = (right, left, left_curvature);
                left = high - ratio * (high - low);
                left_curvature = self.curvature(left);
            } else {
                (low, left, left_curvature) = (left, right, right_curvature);
                right = low + ratio * (high - low);
                right_curvature = self.curvature(right);
            }
        }
        [(left, left_curvature), (right, right_curvature), (at(best), best_curvature)]
            .into_iter()
            .fold((start, f64::NEG_INFINITY), |best, sample| if sample.1 > best.1 { sample } else { best })
    }
}

fn positive_finite(value: f64) -> bool {
    value.is_finite() && value > 0.0
}

/// The clamped knot vector for points `intervals.len() + 1` apart by
/// `intervals` and `degree`: the inner knots average `degree` successive
/// point parameters (Piegl & Tiller eq. 9.8).
fn averaged_knots(intervals: &[f64], degree: usize) -> Vec<f64> {
    let mut parameters = vec![0.0];
    for interval in intervals {
        parameters.push(parameters[parameters.len() - 1] + interval);
    }
    let n = intervals.len();
    let end = parameters[n];
    let mut knots = vec![0.0; degree + 1];
    for j in 1..=n.saturating_sub(degree) {
        knots.push(parameters[j..j + degree].iter().sum::<f64>() / degree as f64);
    }
    // A single point: degree 0 over a range of length 0.
    knots.extend(std::iter::repeat_n(end, degree + 1));
    knots
}

/// The non-zero basis functions N_{span−p..span, p} at `u` and their
/// derivatives up to `order` (Piegl & Tiller A2.3): entry j holds
/// [N, N′, N″] of basis function span − p + j. The span has a length, so
/// every knot difference divided by is positive.
fn basis_derivatives(knots: &[f64], p: usize, span: usize, u: f64, order: usize) -> Basis<[f64; 3]> {
    let order = order.min(p);
    // ndu[j][r]: basis functions of degree j above the diagonal, knot
    // differences below it.
    let mut ndu: Basis<Basis<f64>> = smallvec![smallvec![0.0; p + 1]; p + 1];
    let mut left: Basis<f64> = smallvec![0.0; p + 1];
    let mut right: Basis<f64> = smallvec![0.0; p + 1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut result: Basis<[f64; 3]> = (0..=p).map(|j| [ndu[j][p], 0.0, 0.0]).collect();
    let mut a: [Basis<f64>; 2] = [smallvec![0.0; p + 1], smallvec![0.0; p + 1]];
    for (r, derivatives) in result.iter_mut().enumerate() {
        let (mut s1, mut s2) = (0, 1);
        a[0][0] = 1.0;
        for k in 1..=order {
            let mut d = 0.0;
            let pk = p - k;
            if r >= k {
                let rk = r - k;
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                d = a[s2][0] * ndu[rk][pk];
            }
            let j1 = if r + 1 >= k { 1 } else { k - r };
            let j2 = if r <= pk + 1 { k - 1 } else { p - r };
            for j in j1..=j2 {
                let rkj = r + j - k;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rkj];
                d += a[s2][j] * ndu[rkj][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            derivatives[k] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    // The k-th derivatives carry the factor p!/(p−k)!.
    let mut factor = p as f64;
    for k in 1..=order {
        for derivatives in &mut result {
            derivatives[k] *= factor;
        }
        factor *= (p - k) as f64;
    }
    result
}

/// |C″ ⊥ C′| / |C′|²: the part of the second derivative across the
/// tangent, which is stable where the two are nearly parallel (unlike the
/// cross product's |C′|²|C″|² − (C′·C″)²) and holds in any number of axes.
fn curvature_of<const D: usize>(first: &SVector<f64, D>, second: &SVector<f64, D>) -> f64 {
    let speed_squared = first.norm_squared();
    let scale = second.norm();
    if speed_squared <= f64::MIN_POSITIVE {
        return if scale == 0.0 { 0.0 } else { f64::INFINITY };
    }
    let across = second - first * (second.dot(first) / speed_squared);
    across.norm() / speed_squared
}

fn distance_to_segment<const D: usize>(point: &SVector<f64, D>, a: &SVector<f64, D>, b: &SVector<f64, D>) -> f64 {
    let along = b - a;
    let length_squared = along.norm_squared();
    let t = if length_squared > 0.0 { ((point - a).dot(&along) / length_squared).clamp(0.0, 1.0) } else { 0.0 };
    (point - (a + along * t)).norm()
}

/// The integral of `f` over [a, b] by five-point Gauss–Legendre, halving
/// the interval where the halves disagree with the whole by more than the
/// tolerance, within [`MAX_DEPTH`] and [`LENGTH_HALVINGS`].
fn integrate(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let whole = gauss_legendre(f, a, b);
    let mut budget = LENGTH_HALVINGS;
    halve(f, a, b, whole, LENGTH_TOLERANCE * whole.abs(), MAX_DEPTH, &mut budget)
}

fn halve(f: &impl Fn(f64) -> f64, a: f64, b: f64, whole: f64, tolerance: f64, depth: u32, budget: &mut u32) -> f64 {
    let middle = (a + b) / 2.0;
    let (left, right) = (gauss_legendre(f, a, middle), gauss_legendre(f, middle, b));
    let both = left + right;
    // Rounding bounds what the halves can agree to.
    let tolerance = tolerance.max(8.0 * f64::EPSILON * both.abs());
    if depth == 0 || *budget == 0 || !both.is_finite() || (both - whole).abs() <= tolerance {
        return both;
    }
    *budget -= 1;
    halve(f, a, middle, left, tolerance / 2.0, depth - 1, budget)
        + halve(f, middle, b, right, tolerance / 2.0, depth - 1, budget)
}

fn gauss_legendre(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (centre, half) = ((a + b) / 2.0, (b - a) / 2.0);
    half * GAUSS_LEGENDRE.iter().map(|&(node, weight)| weight * f(centre + half * node)).sum::<f64>()
}

#[cfg(test)]
mod tests;
