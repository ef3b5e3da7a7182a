//! Tool radius compensation G41/G42/G40 in a run: the tool centre runs on
//! the equidistant of the programmed contour in the working plane (G17 X/Y,
//! G18 Z/X, G19 Y/Z), on its left under G41 and its right under G42,
//! looking along the motion (digest §1.9 names the group and the reason;
//! the rest is Siemens documentation recalled, or assumption). The project's
//! compensation builds the path ([`crate::compensation`]) and its shared
//! driver runs it ([`crate::compensation_driver`]): the first move after
//! G41/G42 starts it and the first move after G40 cancels it, each a line
//! (G0 or G1; an arc there stops the run, as Siemens allows only lines), the
//! start ending on the normal at the next element's start and the cancel
//! leaving from the normal at the last element's end for the programmed
//! point. Each step's time is that of its pieces of the tool-centre path in
//! the plane.
//!
//! The radius is that of the tool's cutting edge: T selects the tool, D the
//! edge (D1 after a T without D, the control's default edge; D0 none). It
//! is `$TC_DP6[t,d]` when the program wrote it, else the machine
//! configuration's tool offset `T<t>D<d>`, else 0, which leaves the path as
//! programmed. A named tool (`T="name"`) has no number, so no radius.
//!
//! Assumptions:
//! - Outside corners: G450 (the default) goes round on an arc of the tool
//!   radius about the corner, G451 to the intersection of the equidistants;
//!   where they do not meet, the run stops. The feed holds at the tool
//!   centre on compensated arcs (Siemens's default CFTCP).
//! - The programmable frame: compensation works on the contour in base
//!   coordinates, where the steps are. A frame that keeps the plane (turns
//!   about the tool axis, uniform scales, mirrors) maps the programmed
//!   contour's equidistant onto the base contour's, so this is the
//!   programmed path's compensation mapped by the frame, the tool radius
//!   unscaled. A mirror of one plane axis reverses the contour's sense, so
//!   the side swaps (G41 runs as G42), as Siemens does. A frame that turns
//!   the plane out of itself is reported as not run, and the path runs as
//!   programmed.
//! - A frame or plane change, a spline (BSPLINE) or a drilling cycle ends
//!   compensation where it is (the last element on its normal); the next
//!   move with G41/G42 in force starts it again.
//! - KONT, NORM and the other approach modes, DISC, and the radius of a
//!   tool changed while compensation is in force are not modelled: the
//!   radius holds from the start to the cancel.

use nalgebra::{Point2, Vector2};
use ncc_syntax::TextRange;

use super::{Interpreter, TOOL_RADIUS, XYZ};
use crate::{
    compensation::{CompensationError, Settings, Side},
    compensation_driver::{PlaneMove, Refusal, Start},
    trace::{Finding, Position, RunRule, slot},
};

/// The group of G450/G451.
const CORNERS: &str = "G18";

/// The tool data parameter that holds an edge's radius: `$TC_DP6[t,d]`.
const RADIUS_PARAMETER: &str = "$TC_DP6";

impl Interpreter<'_> {
    /// Follows the step just recorded, which started at `start` (base
    /// coordinates), with the compensation in force.
    pub(super) fn compensate(&mut self, start: &Position, range: TextRange) {
        let plane = self.plane();
        let side = match self.state.modes.get(TOOL_RADIUS) {
            Some("G41") => Some(Side::Left),
            Some("G42") => Some(Side::Right),
            _ => None,
        };
        if side.is_some() && !self.state.frame.keeps_plane(plane) {
            self.end_compensation();
            let what = "tool radius compensation in a frame that turns the working plane (the path runs as programmed)";
            return self.state.not_run(what, range);
        }
        // A mirror of one plane axis runs the contour the other way round.
        let swapped = self.state.frame.turns_arcs_over(plane);
        let side = side.map(|side| match (side, swapped) {
            (Side::Left, false) | (Side::Right, true) => Side::Left,
            _ => Side::Right,
        });
        let [a, b, _] = plane.axes().map(|axis| XYZ[axis]);
        let settings = Settings {
            insert_arcs: !self.state.modes.is(CORNERS, "G451"),
            limit_angle: 0.0,
            continuity_limit: 0.0,
            contact_feed: false,
        };
        let start_with = side.map(|side| Start { side, radius: self.tool_radius(), settings, shift: Vector2::zeros() });
        let point = |position: &Position| Point2::new(position[slot(a)], position[slot(b)]);
        let end = self.state.to_base(&self.state.position);
        let (step, plane, frame) = (self.steps.next() - 1, (a, b), self.state.frames);
        let moved = PlaneMove { step, from: point(start), to: point(&end), plane, frame };
        let message = match self.compensation.follow(&mut self.steps, self.state.machine, moved, start_with) {
            Ok(()) => return,
            Err(Refusal::StartNotLine) => {
                "tool radius compensation starts on an arc: the first move after G41 or G42 must be a line, G0 or G1"
            }
            Err(Refusal::CancelNotLine) => {
                "tool radius compensation ends on an arc: the first move after G40 must be a line, G0 or G1"
            }
            Err(Refusal::Failed(error)) => return self.compensation_failed(&error),
        };
        self.state.finding(RunRule::CompensationFailed, range, message);
    }

    /// Ends compensation in force where it is: at the run's end, and before
    /// a spline or a cycle, which it does not follow.
    pub(super) fn end_compensation(&mut self) {
        self.compensation.end(&mut self.steps, self.state.machine);
    }

    /// The radius of the selected tool's edge, in mm.
    fn tool_radius(&self) -> f64 {
        let (tool, edge) = (self.state.tool, self.state.edge);
        if edge == 0 {
            return 0.0;
        }
        let written = self.state.tool_data.get(&(RADIUS_PARAMETER.to_owned(), i64::from(tool), i64::from(edge)));
        written.copied().unwrap_or_else(|| {
            let entry = self.state.machine.cutting_edges.get(&(tool, edge)).copied().unwrap_or_default();
            f64::from(entry.radius) / 1000.0
        })
    }

    fn compensation_failed(&mut self, error: &CompensationError) {
        let message = match *error {
            CompensationError::NoIntersection { .. } => {
                "the tool-centre paths of this block and the one before do not meet (G451): the control stops"
                    .to_owned()
            }
            CompensationError::ArcTooSmall { arc_radius, tool_radius, .. } => format!(
                "the tool radius {tool_radius} mm is not smaller than the radius {arc_radius} mm of this arc, on whose inside the tool runs: the control stops"
            ),
        };
        // The block the control stops at may be the one before this one.
        let step = self.steps.get(error.block());
        let (source, range, rule) = (step.source, step.range, RunRule::CompensationFailed);
        self.state.stopped |= rule.stops();
        self.state.findings.push(Finding { rule, source, range, message });
    }
}
