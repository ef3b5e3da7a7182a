//! Tool-nose radius compensation G41/G42/G40 (lathe manual §7.1
//! (001:808-1064)): the nose-radius centre runs on the equidistant of the
//! programmed contour, on its left under G41 and its right under G42
//! (looking along the motion, +Z to the right and +X up), built by the
//! project's compensation ([`crate::compensation`]) in the plane (Z, X
//! radius) and run by its shared driver ([`crate::compensation_driver`]).
//! The radius and the tip code come from the tool offset that T selects
//! (`Txxyy`: offset `yy`, 001:825-826).
//!
//! The start and the cancel follow the manual's rules: the first move after
//! G41/G42 starts the compensation and must be a line (G00/G01); after it
//! the nose centre stands on the normal at the next element's start
//! (001:960-963); before the cancel it stands on the normal at the last
//! element's end, and the first move after G40, a line, brings the tip
//! back onto the programmed point (001:964-966, 1043-1047). A start or a
//! cancel on an arc stops the run, as the manual allows only lines there.
//!
//! The control positions the imaginary tool tip (001:879-951): the trace's
//! tool-centre path ([`Trace::tool_centre`](crate::trace::Trace)) is the
//! nose centre's shifted by the vector from the centre to the tip that the
//! tip code gives, and the steps' ends stay the programmed points. Each
//! piece takes the time of its length at the programmed move's mean feed,
//! or at rapid.
//!
//! Assumptions the manual does not settle:
//! - The tip codes are Haas's (External: the figure of 001:906-944 is
//!   lost, OQ-16): from the nose centre to the tip, 1 is X+ Z+, 2 X+ Z−,
//!   3 X− Z−, 4 X− Z+, 5 Z+, 6 X+, 7 Z−, 8 X−, each by the nose radius; 0
//!   and 9 (and no code) are the centre itself.
//! - An outside corner that turns by up to 90° joins at the equidistants'
//!   intersection (Fanuc's offset mode, External); a sharper one goes round
//!   the corner on an arc of the nose radius, where Fanuc goes round on
//!   lines, longer by less than the radius.
//! - G40's I and K, the direction to leave along (001:1058-1064, inferred
//!   there), do not change the path: the cancel ends on the programmed
//!   point all the same.
//! - A radius of 0, the default, leaves the path as programmed.
//! - The radius and tip hold from the start to the cancel: a T between them
//!   changes them at the next start.
//! - G41 after G42 (or the reverse) without G40 keeps the side of the start.
//! - G28, G29 and G53 run without compensation: their first move cancels it
//!   and the next move after them starts it again (Fanuc takes the offset
//!   off at the reference point, External). A move in another frame (G53,
//!   a new work offset or G52) ends it where it is.
//! - The feed along a compensated arc holds at the tool, not at the
//!   contour.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Point2, Vector2};

use super::{Interpreter, Point};
use crate::{
    compensation::{CompensationError, Settings, Side},
    compensation_driver::{PlaneMove, Refusal, Start},
    trace::RunRule,
};

/// The catalogue's group of G40/G41/G42.
const NOSE: &str = "G7";

/// How the equidistants meet (see the module's assumptions).
const SETTINGS: Settings = Settings {
    // A right angle, the lathe's usual corner, meets at the intersection
    // whatever its rounding.
    limit_angle: FRAC_PI_2 + 1e-6,
    insert_arcs: true,
    continuity_limit: 0.0,
    contact_feed: false,
};

impl Interpreter<'_> {
    /// The side G41 or G42 puts the tool on; `None` under G40.
    pub(super) fn nose_side(&self) -> Option<Side> {
        match self.modes.get(NOSE) {
            Some(41) => Some(Side::Left),
            Some(42) => Some(Side::Right),
            _ => None,
        }
    }

    /// Follows step `index`, which moved from `from` to `to` (Z, X radius),
    /// with compensation on `side` (`None`: G40 or a move that runs
    /// without), through the shared driver, one move late as the control's
    /// look-ahead fixes the tool path.
    pub(super) fn compensate(&mut self, index: usize, from: Point, to: Point, side: Option<Side>) {
        let step = self.steps.get(index);
        let (range, frame) = (step.range, step.frame);
        let start = side.map(|side| {
            let entry = self.machine.tools.entry(self.offset);
            let radius = f64::from(entry.radius) / 1000.0;
            // The driver moves the nose centre's path by this to the tip.
            let shift = tip_vector(entry.tip, radius);
            Start { side, radius, settings: SETTINGS, shift }
        });
        let moved = PlaneMove { step: index, from: point(from), to: point(to), plane: (b'Z', b'X'), frame };
        let message = match self.compensation.follow(&mut self.steps, &self.machine, moved, start) {
            Ok(()) => return,
            Err(Refusal::StartNotLine) => "tool-nose radius compensation starts on an arc or a thread: the first move after G41 or G42 must be a line, G00 or G01 (lathe manual §7.1 (001:960-961))".to_owned(),
            Err(Refusal::CancelNotLine) => "tool-nose radius compensation ends on an arc or a thread: the first move after G40 must be a line, G00 or G01 (lathe manual §7.1 (001:965, 1043-1044))".to_owned(),
            Err(Refusal::Failed(error)) => return self.compensation_failed(&error),
        };
        self.finding(RunRule::CompensationFailed, range, &message);
    }

    /// Ends compensation still in force where the run ends: the nose
    /// centre stays on the normal at the last programmed point.
    pub(super) fn end_compensation(&mut self) {
        self.compensation.end(&mut self.steps, &self.machine);
    }

    fn compensation_failed(&mut self, error: &CompensationError) {
        let range = self.steps.get(error.block()).range;
        let message = match *error {
            CompensationError::NoIntersection { .. } => {
                "the nose-centre paths of this move and the one before do not meet: the control stops".to_owned()
            }
            CompensationError::ArcTooSmall { arc_radius, tool_radius, .. } => format!(
                "the nose radius {tool_radius} mm is not smaller than the radius {arc_radius} mm of this arc, on whose inside the tool runs: the nose-centre path vanishes"
            ),
        };
        self.finding(RunRule::CompensationFailed, range, &message);
    }
}

fn point([z, x]: Point) -> Point2<f64> {
    Point2::new(z, x)
}

/// From the nose-radius centre to the imaginary tip of a nose of `radius`
/// with tip code `tip`, in (Z, X radius).
fn tip_vector(tip: Option<u8>, radius: f64) -> Vector2<f64> {
    let (x, z) = match tip {
        Some(1) => (1.0, 1.0),
        Some(2) => (1.0, -1.0),
        Some(3) => (-1.0, -1.0),
        Some(4) => (-1.0, 1.0),
        Some(5) => (0.0, 1.0),
        Some(6) => (1.0, 0.0),
        Some(7) => (0.0, -1.0),
        Some(8) => (-1.0, 0.0),
        _ => (0.0, 0.0),
    };
    Vector2::new(z, x) * radius
}
