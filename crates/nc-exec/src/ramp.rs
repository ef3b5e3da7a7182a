//! How fast a path speed may change: a ramp of limited acceleration A and,
//! where the control limits it, jerk J (the classic S-curve), as both
//! velocity planners use it.
//!
//! Every ramp starts and ends without acceleration, so a change of speed
//! by Δv = |v1 − v0| is symmetric in time and its distance is the mean
//! speed times its time, s = (v0 + v1)/2 · t:
//!
//! * linear (J infinite): t = Δv/A;
//! * S-curve that does not reach A (Δv ≤ A²/J): the jerk raises the
//!   acceleration for sqrt(Δv/J) to sqrt(Δv·J) and lowers it as long
//!   (a triangular acceleration profile): t = 2·sqrt(Δv/J);
//! * S-curve that reaches A (Δv > A²/J): A/J to raise it, Δv/A − A/J at
//!   A, A/J to lower it (a trapezoidal one): t = Δv/A + A/J.
//!
//! A move from rest to rest is a ramp up, a cruise and a ramp down: the
//! seven phases of the S-curve (three each way around the cruise). Both
//! times tend to Δv/A as J grows, and neither is shorter than it.
//!
//! The inverse, the speed a ramp reaches within a distance, has closed
//! forms from rest (s = v·sqrt(v/J), so v = (s²·J)^⅓ up to s = A³/J²;
//! s = v/2 · (v/A + A/J), so v = (sqrt(A⁴/J² + 8·A·s) − A²/J)/2 beyond),
//! but from another speed the triangular case is a cubic; the distance
//! rises with the speed, so [`Ramp::reachable`] and [`Ramp::peak`] find
//! it by bisection under a jerk limit, and keep the linear closed forms
//! without one.

/// How fast speed may change: acceleration in mm/s² and jerk in mm/s³. An
/// infinite jerk is the linear profile; an acceleration that is not a
/// positive finite number means no ramps at all (threads, and a machine
/// whose configuration gives zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ramp {
    pub acceleration: f64,
    pub jerk: f64,
}

/// Halvings of a bisection: far more than a double's 52 bits need from
/// any bracket, so it ends by its tolerance first.
const BISECTIONS: usize = 100;

impl Ramp {
    /// No ramps: speed changes at once.
    pub const NONE: Ramp = Ramp { acceleration: f64::INFINITY, jerk: f64::INFINITY };

    /// Linear ramps of `acceleration`, under the jerk limit `jerk` where
    /// it is some.
    pub fn new(acceleration: f64, jerk: Option<f64>) -> Ramp {
        Ramp { acceleration, jerk: jerk.unwrap_or(f64::INFINITY) }
    }

    pub fn limited(&self) -> bool {
        self.acceleration.is_finite() && self.acceleration > 0.0
    }

    pub fn jerk_limited(&self) -> bool {
        self.jerk.is_finite() && self.jerk > 0.0
    }

    /// Seconds and mm to change speed between `from` and `to`, starting
    /// and ending without acceleration (see the module doc).
    pub fn change(&self, from: f64, to: f64) -> (f64, f64) {
        if !self.limited() {
            return (0.0, 0.0);
        }
        let (a, j, dv) = (self.acceleration, self.jerk, (to - from).abs());
        let time = if !self.jerk_limited() {
            dv / a
        } else if dv <= a * a / j {
            2.0 * (dv / j).sqrt()
        } else {
            dv / a + a / j
        };
        (time, (from + to) / 2.0 * time)
    }

    /// Seconds and mm to rise from `entry` to `peak` and fall to `exit`.
    pub fn span(&self, entry: f64, peak: f64, exit: f64) -> (f64, f64) {
        let (up, down) = (self.change(entry, peak), self.change(peak, exit));
        (up.0 + down.0, up.1 + down.1)
    }

    /// Seconds over `length` mm from `entry` up to `peak`, at `peak`, and
    /// down to `exit`; the ramps alone where they take the whole length.
    pub fn duration(&self, entry: f64, peak: f64, exit: f64, length: f64) -> f64 {
        let (ramps, distance) = self.span(entry, peak, exit);
        if peak > 0.0 { ramps + (length - distance).max(0.0) / peak } else { ramps }
    }

    /// The highest speed, at most `cruise`, that a move of `length` mm
    /// entered at `entry` reaches and still leaves at `exit`: at least the
    /// higher of the two, which the caller keeps within reach.
    pub fn peak(&self, entry: f64, exit: f64, length: f64, cruise: f64) -> f64 {
        if !self.limited() {
            return cruise;
        }
        if !self.jerk_limited() {
            let a = self.acceleration;
            return ((2.0 * a * length + entry * entry + exit * exit) / 2.0).sqrt().min(cruise);
        }
        let fits = |peak: f64| self.span(entry, peak, exit).1 <= length;
        highest(entry.max(exit), cruise, fits)
    }

    /// The highest speed a ramp reaches from `from` within `distance` mm,
    /// which is also the highest from which it gets back to `from` there.
    pub fn reachable(&self, from: f64, distance: f64) -> f64 {
        if !self.limited() {
            return f64::INFINITY;
        }
        let a = self.acceleration;
        let linear = (from * from + 2.0 * a * distance).sqrt();
        if !self.jerk_limited() {
            return linear;
        }
        // A jerk limit only lengthens the ramp: the linear speed bounds it.
        highest(from, linear, |speed| self.change(from, speed).1 <= distance)
    }
}

/// The highest speed in [`low`, `high`] that `fits`, which holds up to
/// some speed and not beyond; `low` where none does, or where the bracket
/// is empty or not a number, so that degenerate input never panics.
fn highest(low: f64, high: f64, fits: impl Fn(f64) -> bool) -> f64 {
    if high.partial_cmp(&low) != Some(std::cmp::Ordering::Greater) {
        return low;
    }
    if fits(high) {
        return high;
    }
    let (mut below, mut above) = (low, high);
    for _ in 0..BISECTIONS {
        let middle = (below + above) / 2.0;
        if fits(middle) {
            below = middle
        } else {
            above = middle
        }
        if above - below <= above * 1e-13 {
            break;
        }
    }
    below
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::Ramp;

    fn close(actual: f64, expected: f64) {
        assert!((actual - expected).abs() <= expected.abs() * 1e-9 + 1e-12, "{actual} != {expected}");
    }

    /// A move of `length` mm at most at `feed` from rest to rest.
    fn rest_to_rest(ramp: &Ramp, length: f64, feed: f64) -> f64 {
        ramp.duration(0.0, ramp.peak(0.0, 0.0, length, feed), 0.0, length)
    }

    #[test]
    fn a_change_of_speed_takes_the_s_curves_time_over_the_mean_speed() {
        let ramp = Ramp::new(1000.0, Some(20_000.0));
        // A²/J = 50 mm/s: below it a triangle of acceleration, above a trapezoid.
        close(ramp.change(10.0, 40.0).0, 2.0 * (30.0f64 / 20_000.0).sqrt());
        close(ramp.change(100.0, 0.0).0, 100.0 / 1000.0 + 1000.0 / 20_000.0);
        close(ramp.change(100.0, 0.0).1, 50.0 * (0.1 + 0.05));
        let linear = Ramp::new(1000.0, None);
        assert_eq!(linear.change(100.0, 0.0), (0.1, 5.0));
    }

    #[test]
    fn the_speed_reachable_from_rest_takes_the_closed_forms() {
        let (a, j) = (1000.0, 20_000.0);
        let ramp = Ramp::new(a, Some(j));
        // Up to A³/J² = 2.5 mm the acceleration stays below A: v = (s²J)^⅓.
        close(ramp.reachable(0.0, 1.0), (j * 1.0f64).cbrt());
        let beyond = |s: f64| ((a.powi(4) / (j * j) + 8.0 * a * s).sqrt() - a * a / j) / 2.0;
        close(ramp.reachable(0.0, 8.0), beyond(8.0));
        close(ramp.reachable(0.0, 2.5), a * a / j);
        // From a speed, the ramp to the speed reached covers the distance.
        let speed = ramp.reachable(30.0, 4.0);
        close(ramp.change(30.0, speed).1, 4.0);
        assert_eq!(Ramp::new(a, None).reachable(30.0, 4.0), (900.0f64 + 8000.0).sqrt());
    }

    #[test]
    fn the_peak_of_a_short_move_leaves_room_for_both_ramps() {
        let ramp = Ramp::new(400.0, Some(4000.0));
        let (entry, exit, length) = (20.0, 5.0, 3.0);
        let peak = ramp.peak(entry, exit, length, 1000.0);
        close(ramp.change(entry, peak).1 + ramp.change(peak, exit).1, length);
        // Long enough for the cruise: the cruise speed.
        assert_eq!(ramp.peak(entry, exit, 100.0, 50.0), 50.0);
        // Entered too fast to reach anything higher: the higher end.
        assert_eq!(ramp.peak(80.0, 0.0, 0.001, 100.0), 80.0);
    }

    #[test]
    fn degenerate_ramps_never_panic_and_a_huge_jerk_is_linear() {
        let linear = Ramp::new(1000.0, None);
        for jerk in [0.0, -5.0, f64::NAN, f64::INFINITY] {
            let ramp = Ramp::new(1000.0, Some(jerk));
            assert!(!ramp.jerk_limited());
            assert_eq!(rest_to_rest(&ramp, 10.0, 50.0), rest_to_rest(&linear, 10.0, 50.0));
        }
        let huge = Ramp::new(1000.0, Some(1e300));
        close(rest_to_rest(&huge, 10.0, 50.0), rest_to_rest(&linear, 10.0, 50.0));
        let tiny = Ramp::new(1000.0, Some(1e-300));
        assert!(rest_to_rest(&tiny, 10.0, 50.0).is_finite());
        let ramp = Ramp::new(1000.0, Some(20_000.0));
        assert_eq!(ramp.reachable(0.0, 0.0), 0.0);
        assert_eq!(ramp.reachable(7.0, 0.0), 7.0);
        assert_eq!(ramp.peak(0.0, 0.0, 0.0, 50.0), 0.0);
        assert_eq!(rest_to_rest(&ramp, 0.0, 50.0), 0.0);
        assert_eq!(rest_to_rest(&ramp, 10.0, 0.0), 0.0);
        // No acceleration limit: no ramps.
        assert_eq!(Ramp::new(0.0, Some(20_000.0)).reachable(0.0, 1.0), f64::INFINITY);
        assert_eq!(Ramp::NONE.peak(0.0, 0.0, 1.0, 50.0), 50.0);
    }

    proptest! {
        /// A jerk limit only lengthens a move, and less the larger it is,
        /// down to the linear ramps' time.
        #[test]
        fn a_jerk_limit_costs_time_that_vanishes_as_it_grows(
            length in 0.01f64..500.0,
            feed in 1.0f64..500.0,
            acceleration in 50.0f64..5000.0,
            jerk in 100.0f64..100_000.0,
        ) {
            let linear = rest_to_rest(&Ramp::new(acceleration, None), length, feed);
            let mut before = f64::INFINITY;
            for factor in [1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8] {
                let time = rest_to_rest(&Ramp::new(acceleration, Some(jerk * factor)), length, feed);
                prop_assert!(time >= linear * (1.0 - 1e-12), "{time} < {linear}");
                prop_assert!(time <= before * (1.0 + 1e-12), "{time} > {before}");
                before = time;
            }
            prop_assert!((before - linear).abs() <= linear * 1e-3, "{before} vs {linear}");
        }
    }
}
