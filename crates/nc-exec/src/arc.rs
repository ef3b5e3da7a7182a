//! Circular arcs in a plane, built from their ends and centre: the one
//! construction the executor and the checker share.

use std::f64::consts::TAU;

/// An arc of a circle in a plane, in millimetres and radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleArc {
    pub centre: [f64; 2],
    pub radius: f64,
    /// The angle of the start point seen from the centre.
    pub start_angle: f64,
    /// The angle swept: positive counter-clockwise; a full turn when the
    /// ends coincide.
    pub sweep: f64,
}

/// An end point off its circle: the distances of both ends from the centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OffCircle {
    pub start_radius: f64,
    pub end_radius: f64,
}

/// The arc from `start` to `end` around `centre`, turning counter-clockwise
/// or clockwise; an error when the end lies farther than `tolerance` from
/// the circle the start is on.
pub fn circle_through(
    start: [f64; 2],
    end: [f64; 2],
    centre: [f64; 2],
    counter_clockwise: bool,
    tolerance: f64,
) -> Result<CircleArc, OffCircle> {
    let distance = |point: [f64; 2]| (point[0] - centre[0]).hypot(point[1] - centre[1]);
    let (radius, end_radius) = (distance(start), distance(end));
    if (radius - end_radius).abs() > tolerance {
        return Err(OffCircle { start_radius: radius, end_radius });
    }
    let angle_of = |point: [f64; 2]| (point[1] - centre[1]).atan2(point[0] - centre[0]);
    let start_angle = angle_of(start);
    let mut sweep = angle_of(end) - start_angle;
    if counter_clockwise && sweep <= 0.0 {
        sweep += TAU;
    } else if !counter_clockwise && sweep >= 0.0 {
        sweep -= TAU;
    }
    Ok(CircleArc { centre, radius, start_angle, sweep })
}

impl CircleArc {
    /// The length along the circle.
    pub fn length(&self) -> f64 {
        self.radius * self.sweep.abs()
    }
}

/// The centre of the arc of `radius` from `from` to `to`: on the side that
/// makes it at most a half circle, the other side for a negative radius
/// (Haas lathe manual §5.8 (001:658-660); Sinumerik's CR alike). `None` when the ends lie farther
/// apart than the diameter beyond `tolerance`.
pub fn centre_by_radius(from: [f64; 2], to: [f64; 2], radius: f64, ccw: bool, tolerance: f64) -> Option<[f64; 2]> {
    let chord = [to[0] - from[0], to[1] - from[1]];
    let half = chord[0].hypot(chord[1]) / 2.0;
    if half == 0.0 || half > radius.abs() + tolerance {
        return None;
    }
    let height = (radius * radius - half * half).max(0.0).sqrt();
    // The centre of a short counter-clockwise arc lies left of the chord.
    let side = if ccw == (radius > 0.0) { 1.0 } else { -1.0 };
    let left = [-chord[1] / (2.0 * half), chord[0] / (2.0 * half)];
    let middle = [(from[0] + to[0]) / 2.0, (from[1] + to[1]) / 2.0];
    Some([middle[0] + side * height * left[0], middle[1] + side * height * left[1]])
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    use super::{OffCircle, circle_through};

    #[test]
    fn sweeps_follow_the_direction_and_coinciding_ends_are_a_full_turn() {
        let sweep = |start, end, centre, ccw| circle_through(start, end, centre, ccw, 0.001).unwrap().sweep;
        assert!((sweep([10.0, 0.0], [0.0, 10.0], [0.0, 0.0], true) - FRAC_PI_2).abs() < 1e-12);
        assert!((sweep([10.0, 0.0], [0.0, 10.0], [0.0, 0.0], false) + 3.0 * FRAC_PI_2).abs() < 1e-12);
        assert!((sweep([0.0, 0.0], [20.0, 0.0], [10.0, 0.0], false) + PI).abs() < 1e-12);
        assert_eq!(sweep([5.0, 0.0], [5.0, 0.0], [0.0, 0.0], true), TAU);
        assert_eq!(sweep([5.0, 0.0], [5.0, 0.0], [0.0, 0.0], false), -TAU);
    }

    #[test]
    fn an_end_off_the_circle_beyond_the_tolerance_is_refused() {
        assert_eq!(
            circle_through([0.0, 0.0], [20.0, 0.0], [5.0, 0.0], true, 0.001),
            Err(OffCircle { start_radius: 5.0, end_radius: 15.0 })
        );
        assert!(circle_through([0.0, 0.0], [10.0005, 0.0], [5.0, 0.0], true, 0.001).is_ok());
    }
}
