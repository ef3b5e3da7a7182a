use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};

use proptest::prelude::*;

use super::{ControlPoint, MIN_CHORD_TOLERANCE, PathPoint, Spline, SplineError};

fn distance<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

fn polyline_length<const D: usize>(points: &[PathPoint<D>]) -> f64 {
    points.windows(2).map(|pair| distance(pair[0].position, pair[1].position)).sum()
}

/// The length of the curve sampled at `count` even parameter steps.
fn brute_length<const D: usize>(spline: &Spline<D>, count: usize) -> f64 {
    let (start, end) = spline.domain();
    let points: Vec<_> = (0..=count)
        .map(|i| PathPoint { parameter: 0.0, position: spline.point(start + (end - start) * i as f64 / count as f64) })
        .collect();
    polyline_length(&points)
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn quarter_circle(radius: f64) -> Spline<2> {
    Spline::programmed(
        [radius, 0.0],
        &[
            ControlPoint { position: [radius, radius], weight: Some(FRAC_1_SQRT_2), interval: None },
            ControlPoint::at([0.0, radius]),
        ],
        Some(2),
    )
    .unwrap()
}

#[test]
fn degree_one_is_the_polyline_of_its_points() {
    let points = [[0.0, 0.0, 0.0], [3.0, 4.0, 0.0], [3.0, 4.0, 12.0], [-1.0, 1.0, 12.0]];
    let programmed: Vec<_> = points[1..].iter().map(|&point| ControlPoint::at(point)).collect();
    let spline = Spline::programmed(points[0], &programmed, Some(1)).unwrap();
    assert_eq!(spline.degree(), 1);
    // Chord-length knots: the parameter is the distance along the path.
    assert_eq!(spline.knots(), [0.0, 0.0, 5.0, 17.0, 22.0, 22.0]);
    assert!((spline.length() - 22.0).abs() < 1e-12);
    let polyline: Vec<_> = spline.polyline(0.001).iter().map(|point| point.position).collect();
    assert_eq!(polyline, points);
    assert_eq!(spline.point(11.0), [3.0, 4.0, 6.0]);
    assert!(spline.spans().iter().all(|span| span.max_curvature == 0.0));
}

#[test]
fn rational_quadratic_with_weights_one_half_root_two_one_is_a_quarter_circle() {
    for radius in [0.5, 10.0, 250.0] {
        let spline = quarter_circle(radius);
        assert!(relative(spline.length(), FRAC_PI_2 * radius) < 1e-9, "length {} at r={radius}", spline.length());
        let (start, end) = spline.domain();
        for i in 0..=50 {
            let u = start + (end - start) * f64::from(i) / 50.0;
            let point = spline.point(u);
            assert!((distance(point, [0.0, 0.0]) - radius).abs() < 1e-9 * radius);
            assert!(relative(spline.curvature(u), 1.0 / radius) < 1e-9, "curvature at {u}");
        }
        let spans = spline.spans();
        assert_eq!(spans.len(), 1);
        assert!(relative(spans[0].max_curvature, 1.0 / radius) < 1e-9);
        assert!(relative(spans[0].length, FRAC_PI_2 * radius) < 1e-9);
    }
}

#[test]
fn cubic_over_collinear_points_is_the_straight_line_between_its_ends() {
    let direction = [1.0, 2.0, -2.0];
    let along = |t: f64| direction.map(|x| x * t);
    let programmed = [0.5, 2.0, 2.5, 4.0, 7.0].map(|t| ControlPoint::at(along(t)));
    let spline = Spline::programmed([0.0; 3], &programmed, None).unwrap();
    assert_eq!(spline.degree(), 3);
    assert!(relative(spline.length(), 21.0) < 1e-12);
    let (start, end) = spline.domain();
    for i in 0..=40 {
        let u = start + (end - start) * f64::from(i) / 40.0;
        let point = spline.point(u);
        let t = point[0];
        assert!(distance(point, along(t)) < 1e-12);
        assert!(spline.curvature(u) < 1e-12);
    }
    assert_eq!(spline.polyline(1e-4).len(), spline.spans().len() + 1);
}

#[test]
fn uniform_cubic_length_agrees_with_a_fine_polyline() {
    let points = [[0.0, 0.0], [10.0, 25.0], [30.0, -5.0], [45.0, 40.0], [60.0, 10.0], [62.0, -20.0], [90.0, 0.0]];
    let knots = [0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0, 4.0, 4.0];
    let spline = Spline::new(3, &points, &[1.0; 7], &knots).unwrap();
    let brute = brute_length(&spline, 200_000);
    assert!(relative(spline.length(), brute) < 1e-4, "{} against {brute}", spline.length());
    assert_eq!(spline.point(0.0), points[0]);
    assert_eq!(spline.point(4.0), points[6]);
    let spans = spline.spans();
    assert_eq!(spans.len(), 4);
    assert!(relative(spans.iter().map(|span| span.length).sum(), spline.length()) < 1e-12);
}

#[test]
fn equal_intervals_make_evenly_spaced_inner_knots() {
    let programmed = [[1.0, 1.0], [2.0, 0.0], [3.0, 3.0], [4.0, 0.0], [5.0, 1.0], [6.0, 0.0]]
        .map(|position| ControlPoint { position, weight: None, interval: Some(2.0) });
    let spline = Spline::programmed([0.0, 0.0], &programmed, None).unwrap();
    assert_eq!(spline.knots(), [0.0, 0.0, 0.0, 0.0, 4.0, 6.0, 8.0, 12.0, 12.0, 12.0, 12.0]);
}

#[test]
fn maximum_curvature_of_a_span_is_found_between_samples() {
    // The parabola y = x²/8 from x = −4 to 10: its quadratic Bézier has
    // the end tangents' crossing as middle point; curvature 1/4 at the
    // vertex, at a parameter no sample falls on, lower elsewhere.
    let spline =
        Spline::programmed([-4.0, 2.0], &[ControlPoint::at([3.0, -5.0]), ControlPoint::at([10.0, 12.5])], None)
            .unwrap();
    assert_eq!(spline.degree(), 2);
    let span = spline.spans()[0];
    assert!(relative(span.max_curvature, 1.0 / 4.0) < 1e-9, "{}", span.max_curvature);
    assert!(distance(spline.point(span.at), [0.0, 0.0]) < 1e-4);
}

#[test]
fn polyline_stays_within_its_chord_tolerance() {
    let programmed = [[10.0, 25.0, 1.0], [30.0, -5.0, 2.0], [45.0, 40.0, 0.0], [60.0, 10.0, -3.0], [90.0, 0.0, 0.0]]
        .map(ControlPoint::at);
    let spline = Spline::programmed([0.0; 3], &programmed, None).unwrap();
    for tolerance in [0.1, 0.01, 0.001] {
        let polyline = spline.polyline(tolerance);
        assert_eq!(polyline.first().map(|point| point.position), Some([0.0; 3]));
        assert_eq!(polyline.last().map(|point| point.position), Some([90.0, 0.0, 0.0]));
        assert!(polyline.windows(2).all(|pair| pair[0].parameter < pair[1].parameter));
        let worst = worst_deviation(&spline, &polyline);
        assert!(worst <= tolerance, "deviation {worst} over tolerance {tolerance}");
    }
}

/// The farthest the curve strays from the polyline, sampled between its
/// points.
fn worst_deviation(spline: &Spline<3>, polyline: &[PathPoint<3>]) -> f64 {
    let mut worst: f64 = 0.0;
    for pair in polyline.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for i in 1..20 {
            let u = a.parameter + (b.parameter - a.parameter) * f64::from(i) / 20.0;
            worst = worst.max(segment_distance(spline.point(u), a.position, b.position));
        }
    }
    worst
}

fn segment_distance(point: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let along: Vec<f64> = (0..3).map(|i| b[i] - a[i]).collect();
    let squared: f64 = along.iter().map(|x| x * x).sum();
    let t = ((0..3).map(|i| (point[i] - a[i]) * along[i]).sum::<f64>() / squared).clamp(0.0, 1.0);
    distance(point, [0, 1, 2].map(|i| a[i] + along[i] * t))
}

#[test]
fn fewer_points_than_the_degree_needs_lower_it() {
    let line = Spline::programmed([0.0, 0.0], &[ControlPoint::at([3.0, 4.0])], Some(3)).unwrap();
    assert_eq!(line.degree(), 1);
    assert!(relative(line.length(), 5.0) < 1e-12);
    let parabola =
        Spline::programmed([0.0, 0.0], &[ControlPoint::at([1.0, 1.0]), ControlPoint::at([2.0, 0.0])], None).unwrap();
    assert_eq!(parabola.degree(), 2);
    let still = Spline::programmed([1.0, 2.0], &[], None).unwrap();
    assert_eq!((still.degree(), still.length(), still.spans().len()), (0, 0.0, 0));
    assert_eq!(still.polyline(0.01).len(), 1);
    assert_eq!(still.point(5.0), [1.0, 2.0]);
}

#[test]
fn repeating_the_start_position_makes_the_same_curve() {
    let points = [[5.0, 5.0, -4.0], [10.0, 0.0, -4.0], [15.0, 5.0, -4.0], [20.0, 0.0, -4.0]].map(ControlPoint::at);
    let start = [0.0, 0.0, -4.0];
    let without = Spline::programmed(start, &points, None).unwrap();
    let repeated: Vec<_> = std::iter::once(ControlPoint::at(start)).chain(points).collect();
    assert_eq!(Spline::programmed(start, &repeated, None), Ok(without.clone()));
    // Its weight is the start's.
    let weighted: Vec<_> =
        std::iter::once(ControlPoint { position: start, weight: Some(2.0), interval: None }).chain(points).collect();
    assert_eq!(Spline::programmed(start, &weighted, None).unwrap().weights()[0], 2.0);
    // A repeat without a weight keeps the one programmed before.
    let heavy = ControlPoint { weight: Some(3.0), ..points[0] };
    let twice = Spline::programmed(start, &[heavy, points[0], points[1]], None).unwrap();
    assert_eq!(twice.weights(), [1.0, 3.0, 1.0]);
    assert!(without.spans().iter().all(|span| span.max_curvature.is_finite()));
}

#[test]
fn weights_pull_the_curve_towards_their_point() {
    let with = |weight| {
        let programmed = [
            ControlPoint::at([10.0, 0.0]),
            ControlPoint { position: [20.0, 20.0], weight: Some(weight), interval: None },
            ControlPoint::at([30.0, 0.0]),
            ControlPoint::at([40.0, 0.0]),
        ];
        let spline = Spline::programmed([0.0, 0.0], &programmed, None).unwrap();
        (0..=100).map(|i| spline.point(spline.domain().1 * f64::from(i) / 100.0)[1]).fold(0.0, f64::max)
    };
    assert!(with(0.5) < with(1.0) && with(1.0) < with(3.0));
}

#[test]
fn bad_data_is_an_error_naming_its_point() {
    let at = ControlPoint::at([1.0, 1.0]);
    let weighted = |weight| ControlPoint { weight: Some(weight), ..ControlPoint::at([2.0, 0.0]) };
    let interval = |length| ControlPoint { interval: Some(length), ..ControlPoint::at([2.0, 0.0]) };
    let build = |points: &[ControlPoint<2>]| Spline::programmed([0.0, 0.0], points, None);
    assert_eq!(build(&[at, weighted(0.0)]), Err(SplineError::Weight { point: 1, weight: 0.0 }));
    assert_eq!(build(&[at, weighted(-1.0)]), Err(SplineError::Weight { point: 1, weight: -1.0 }));
    assert!(matches!(build(&[weighted(f64::NAN)]), Err(SplineError::Weight { point: 0, .. })));
    assert_eq!(build(&[at, interval(0.0)]), Err(SplineError::Interval { point: 1, length: 0.0 }));
    assert_eq!(
        build(&[ControlPoint { interval: Some(f64::MAX), ..at }, interval(f64::MAX)]),
        Err(SplineError::Interval { point: 1, length: f64::MAX })
    );
    assert_eq!(build(&[at, ControlPoint::at([f64::NAN, 0.0])]), Err(SplineError::Position { point: 1 }));
    assert_eq!(Spline::programmed([f64::INFINITY, 0.0], &[at], None), Err(SplineError::Start));
    assert_eq!(build(&[ControlPoint::at([f64::MAX, 0.0]), at]), Err(SplineError::Position { point: 0 }));
    assert_eq!(Spline::programmed([0.0, 0.0], &[at], Some(0)), Err(SplineError::ZeroDegree));

    let points = [[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]];
    assert_eq!(Spline::new(2, &points, &[1.0; 3], &[0.0, 0.0, 0.0, 1.0, 1.0]), Err(SplineError::Knots));
    assert_eq!(Spline::new(2, &points, &[1.0; 3], &[0.0, 0.0, 1.0, 0.5, 1.0, 1.0]), Err(SplineError::Knots));
    assert_eq!(Spline::new(2, &points, &[1.0; 3], &[0.0; 6]), Err(SplineError::Knots));
    assert_eq!(Spline::new(3, &points, &[1.0; 3], &[0.0; 7]), Err(SplineError::TooFewPoints { points: 3, degree: 3 }));
    assert_eq!(
        Spline::new(1, &points, &[1.0; 2], &[0.0, 0.0, 1.0, 2.0, 2.0]),
        Err(SplineError::WeightCount { points: 3, weights: 2 })
    );
}

#[test]
fn a_reversal_is_a_cusp_of_infinite_curvature() {
    // Out and back along a line: the curve stops where it turns.
    let spline =
        Spline::new(2, &[[0.0, 0.0], [2.0, 0.0], [0.0, 0.0]], &[1.0; 3], &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]).unwrap();
    assert_eq!(spline.curvature(0.5), f64::INFINITY);
    assert_eq!(spline.spans()[0].max_curvature, f64::INFINITY);
    assert!(relative(spline.length(), 2.0) < 1e-9);
}

#[test]
fn parameters_outside_the_domain_are_clamped() {
    let spline = quarter_circle(1.0);
    let (start, end) = spline.domain();
    assert_eq!(spline.point(start - 5.0), spline.point(start));
    assert_eq!(spline.point(end + 5.0), spline.point(end));
    assert_eq!(spline.point(f64::NAN), spline.point(start));
    assert!(relative(spline.length_between(end, start), -spline.length()) < 1e-12);
}

fn control_points() -> impl Strategy<Value = Vec<ControlPoint<3>>> {
    let point = (prop::array::uniform3(-100.0..100.0f64), 0.1..3.0f64, prop::option::of(0.5..50.0f64))
        .prop_map(|(position, weight, interval)| ControlPoint { position, weight: Some(weight), interval });
    prop::collection::vec(point, 1..10)
}

fn any_number() -> impl Strategy<Value = f64> {
    prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(0.0), Just(1e300), Just(-1e-300), -1e6..1e6f64, any::<f64>(),]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_splines_are_longer_than_their_chord_and_their_polylines(
        start in prop::array::uniform3(-100.0..100.0f64),
        programmed in control_points(),
        degree in 1..5usize,
    ) {
        let spline = Spline::programmed(start, &programmed, Some(degree)).unwrap();
        let length = spline.length();
        let (first, last) = spline.domain();
        let chord = distance(spline.point(first), spline.point(last));
        prop_assert!(length >= chord * (1.0 - 1e-12), "{length} shorter than its chord {chord}");
        let coarse = length - polyline_length(&spline.polyline(0.1));
        let fine = length - polyline_length(&spline.polyline(0.001));
        prop_assert!(coarse >= -1e-9 * length && fine >= -1e-9 * length, "a polyline longer than {length}");
        prop_assert!(fine <= coarse + 1e-9 * length, "the finer polyline is shorter: {fine} over {coarse}");
        prop_assert!(fine <= 1e-4 * length.max(1.0), "the fine polyline is {fine} short of {length}");
        let deviation = worst_deviation(&spline, &spline.polyline(0.01));
        prop_assert!(deviation <= 0.01, "deviation {deviation}");
    }

    #[test]
    fn any_numbers_build_a_spline_or_an_error_and_never_panic(
        start in prop::array::uniform3(any_number()),
        programmed in prop::collection::vec(
            (prop::array::uniform3(any_number()), prop::option::of(any_number()), prop::option::of(any_number())),
            0..8,
        ),
        degree in prop::option::of(0..8usize),
        parameter in any_number(),
    ) {
        let programmed: Vec<_> = programmed
            .into_iter()
            .map(|(position, weight, interval)| ControlPoint { position, weight, interval })
            .collect();
        if let Ok(spline) = Spline::programmed(start, &programmed, degree) {
            spline.point(parameter);
            spline.curvature(parameter);
            spline.spans();
            prop_assert!(spline.length() >= 0.0);
            let (start, end) = spline.domain();
            for polyline in [spline.polyline(parameter), spline.polyline(MIN_CHORD_TOLERANCE * 1e6)] {
                prop_assert_eq!(polyline.first().map(|point| point.parameter), Some(start));
                prop_assert_eq!(polyline.last().map(|point| point.parameter), Some(end));
            }
        }
    }
}

#[test]
fn work_is_bounded_where_no_tolerance_can_be_met() {
    // Far from the origin, rounding leaves the speed noisy and a chord
    // tolerance of a nanometre out of reach on a kilometre-wide curve.
    let far = [[1e15, 0.0], [1e15 + 1.0, 1.0], [1e15 + 2.0, 0.0], [1e15 + 3.0, 1.0]];
    let noisy = Spline::new(3, &far, &[1.0; 4], &[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]).unwrap();
    assert!(noisy.length().is_finite());
    let wide =
        Spline::programmed([0.0, 0.0], &[ControlPoint::at([1e6, 1e6]), ControlPoint::at([2e6, 0.0])], None).unwrap();
    let polyline = wide.polyline(0.0);
    assert!(polyline.len() <= (1 << 14) + 2, "{} points", polyline.len());
    assert_eq!(polyline.last().map(|point| point.position), Some([2e6, 0.0]));
}
