//! Rules on the order of a program's operations over the walk's modal
//! state (digest §6 rules 15, 23, 28 and 38): where rapid moves go, how a
//! contour is entered and left, how the tool leaves a cut, in what order a
//! hole is made.
//!
//! Assumptions, where the digest is silent:
//! - Rule 15 needs the stock's top on the tool axis, `[sinumerik]
//!   stock-top`, which a program does not state: a G0 that ends below it,
//!   or moves in the plane with the tool below it, cuts at rapid. Without
//!   the key the rule is quiet. A G0 it reports is not reported again by
//!   rule 28.
//! - Rule 23 takes the contour under radius compensation (G41, G42) for
//!   the finishing contour, which the program does not name: the move that
//!   switches compensation on is the lead-in, the first move in the plane
//!   after it the contour's first element, and the move that switches it
//!   off (G40) the lead-out. It reports a lead-in or lead-out in a line
//!   more than [`STEEP_LEAD_DEGREES`] off the contour's tangent there,
//!   unless an arc joins the next (or the last) element on its tangent:
//!   CAM systems switch compensation on or off in a ramp and reach the
//!   contour through a line and an arc.
//!   Arcs count by their centre (I, J, K) or radius (CR); the soft
//!   approach words (G147 …) are not in the catalogue, so the walk does
//!   not know the position after them and the rule stays quiet.
//! - Rule 28 reads "a safe Z" as the height of the tool axis from which
//!   the cut started (the start of the first feed move after a rapid): a
//!   G0 that moves in the plane after a cut that went below that height,
//!   before any move raised the tool above that height or a rapid move
//!   along the tool axis alone raised it, is repositioning at the depth of
//!   the cut. Whether the machine turns (X, Z on a lathe) rather than
//!   mills is not known: the plane's tool axis is taken for the depth. A retract to a lower clearance
//!   plane than the approach counts, since the stock's top is not known.
//! - Rule 38 follows the holes the catalogue's hole cycles make (its
//!   `hole`: drill, bore, tap, ream) at the tool's position in the plane,
//!   called directly or modally (MCALL) at every move; the same hole is
//!   the same point within [`SAME_HOLE_MM`] in the same frame. Drilling
//!   comes first, then boring or tapping, then reaming (004:468-470).
//!   Whether one feature is finished before it is roughed is not known:
//!   the program does not say which cut is which.

use nc_exec::{
    arc::centre_by_radius,
    known::Known,
    sinumerik::{
        frames::Plane,
        lower::{Callee, Dimension, StatementKind, WordValue},
        modes::groups::TOOL_RADIUS,
    },
};
use ncc_catalog::{Dialect, HoleOperation};
use ncc_syntax::TextRange;
use rustc_hash::FxHashMap;

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    sinumerik::{
        checks::visit::{g_number, signed_value},
        model::FileModel,
        walk::{ModalCall, PATH_AXES, SAME_POINT_MM, Step},
    },
};

declare_rules! {
    RAPID_INTO_STOCK = "K015", "rapid-into-stock", Warning, "A G0 move that ends below the stock's top (`[sinumerik] stock-top`), or moves in the plane below it: G0 never cuts.";
    STEEP_LEAD = "K023", "steep-lead-in-out", Info, "A contour under radius compensation entered or left by a line more than 45° off its tangent: the servos' response leaves a mark there; lead in and out on a tangent or at a shallow angle.";
    NO_RETRACT = "K028", "rapid-without-retract", Warning, "A G0 move in the plane after a cut, with the tool still below the height the cut started from: retract along the tool axis first.";
    HOLE_ORDER = "K038", "hole-operations-out-of-order", Info, "A hole cycle that drills, bores or taps a hole after a later operation (boring, tapping, reaming) on the same hole.";
}

/// A lead-in or lead-out turning more than this from the contour's tangent
/// is steep (rule 23).
const STEEP_LEAD_DEGREES: f64 = 45.0;

/// Two elements meeting within this angle join on a tangent (rule 23):
/// CAM output rounds its points.
const TANGENT_DEGREES: f64 = 2.0;

/// Hole positions closer than this, in mm, are the same hole (rule 38).
const SAME_HOLE_MM: f64 = 0.001;

/// A direction in the plane.
type Direction = [f64; 2];

/// A hole by its frame, plane and position in µm.
type HoleKey = (Option<usize>, Plane, i64, i64);

/// A hole's last operation: what, by which cycle, where.
struct HoleMade {
    operation: HoleOperation,
    cycle: &'static str,
    range: TextRange,
}

/// The state the rules keep between blocks.
#[derive(Default)]
pub(crate) struct Operations {
    /// Rule 15: the stock's top on the tool axis, in mm.
    stock_top: Option<f64>,
    /// Rule 23: the contour under compensation so far.
    contour: Contour,
    /// Rule 28: the tool-axis height the cut started from, and whether the
    /// cut went below it.
    approach: Option<f64>,
    cut: bool,
    /// Rule 38: the holes made.
    holes: FxHashMap<HoleKey, HoleMade>,
}

/// The motion of a block in the plane: its direction at the start and at
/// the end, and whether it is an arc.
struct PlaneMove {
    start: Direction,
    end: Direction,
    arc: bool,
}

/// A steep lead-in or lead-out, waiting for what follows it.
struct SteepLead {
    range: TextRange,
    angle: f64,
}

/// Rule 23's view of a contour under radius compensation.
#[derive(Default)]
struct Contour {
    /// The move that switched compensation on, while no element followed.
    lead_in: Option<(TextRange, Direction)>,
    /// A steep entry, reported unless the next junction shows a lead-in
    /// arc: CAM systems switch compensation on in a ramp, then join the
    /// contour by a line and an arc on its tangent.
    entry: Option<SteepLead>,
    /// The tangent at the end of the last element, whether it is an arc,
    /// and whether it joins the element before it on a tangent with an
    /// arc on either side (a lead-out arc).
    end: Option<Direction>,
    end_arc: bool,
    smooth_end: bool,
}

fn angle_degrees(a: Direction, b: Direction) -> Option<f64> {
    let (la, lb) = (a[0].hypot(a[1]), b[0].hypot(b[1]));
    if la < SAME_POINT_MM || lb < SAME_POINT_MM {
        return None;
    }
    let cos = ((a[0] * b[0] + a[1] * b[1]) / (la * lb)).clamp(-1.0, 1.0);
    Some(cos.acos().to_degrees())
}

/// The angle between a lead and the contour's tangent, where it is steep.
fn steep(lead: Direction, tangent: Direction) -> Option<f64> {
    angle_degrees(lead, tangent).filter(|&angle| angle > STEEP_LEAD_DEGREES)
}

/// Rule 23's finding on a lead that `verb`s (enters, leaves) the contour.
fn report_lead(lead: SteepLead, verb: &str, out: &mut Vec<Diagnostic>) {
    let message = format!(
        "the tool {verb} the contour in a line {:.0}° off its tangent: uneven load and the servos' response leave a mark there on a finishing cut; lead in and out on a tangent (an arc) or at a shallow angle (004:898-904)",
        lead.angle
    );
    out.push(Diagnostic::new(&STEEP_LEAD, lead.range, message));
}

impl Contour {
    /// The next element of the contour.
    fn element(&mut self, m: &PlaneMove, out: &mut Vec<Diagnostic>) {
        let tangent_arc = self.end.is_some_and(|end| {
            (self.end_arc || m.arc) && angle_degrees(end, m.start).is_some_and(|angle| angle <= TANGENT_DEGREES)
        });
        if let Some((range, lead)) = self.lead_in.take() {
            self.entry = steep(lead, m.start).map(|angle| SteepLead { range, angle });
        } else if let Some(entry) = self.entry.take()
            && !tangent_arc
        {
            report_lead(entry, "enters", out);
        }
        self.smooth_end = tangent_arc;
        self.end = Some(m.end);
        self.end_arc = m.arc;
    }
}

/// The interpolation parameter of an axis: I for X, J for Y, K for Z.
const CENTRE_WORDS: [&str; 3] = ["I", "J", "K"];

impl Operations {
    /// `stock_top`: the stock's top on the tool axis in µm, where known.
    pub(crate) fn new(stock_top: Option<i32>) -> Operations {
        Operations { stock_top: stock_top.map(|top| f64::from(top) / 1000.0), ..Operations::default() }
    }

    pub(crate) fn step(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        if !step.reached {
            return;
        }
        let plane = step.state.plane();
        self.holes(file, step, plane, out);
        if !step.moves {
            return;
        }
        match plane {
            Some(plane) => {
                self.lead(file, step, plane, out);
                self.retract(file, step, plane, out);
            }
            None => {
                self.contour = Contour::default();
                self.approach = None;
                self.cut = false;
            }
        }
    }

    /// The block's move in the plane, where the walk knows it: a line, or
    /// an arc by its centre or radius.
    fn plane_move(step: &Step<'_>, plane: Plane) -> Option<PlaneMove> {
        let [a, b, _] = plane.axes();
        let from = [step.from[a].known()?, step.from[b].known()?];
        let to = [step.state.position[a].known()?, step.state.position[b].known()?];
        let chord = [to[0] - from[0], to[1] - from[1]];
        let counter_clockwise = match step.state.motion()? {
            "G0" | "G1" => return Some(PlaneMove { start: chord, end: chord, arc: false }),
            "G2" => false,
            "G3" => true,
            _ => return None,
        };
        let word = |address: &str| {
            step.block.statements.iter().find_map(|s| match &s.kind {
                StatementKind::Word(w) if w.address == address => w.value.as_ref(),
                _ => None,
            })
        };
        let centre = match word("CR") {
            Some(radius) => centre_by_radius(from, to, signed_value(radius)?, counter_clockwise, SAME_POINT_MM)?,
            None => {
                let offset = |axis: usize| -> Option<f64> {
                    match word(CENTRE_WORDS[axis]) {
                        None => Some(0.0),
                        Some(value @ WordValue::Expr { dimension: Some(Dimension::Absolute), .. }) => {
                            Some(signed_value(value)? - from[if axis == a { 0 } else { 1 }])
                        }
                        Some(value) => signed_value(value),
                    }
                };
                if word(CENTRE_WORDS[a]).is_none() && word(CENTRE_WORDS[b]).is_none() {
                    return None;
                }
                [from[0] + offset(a)?, from[1] + offset(b)?]
            }
        };
        // The tangent turns the radius a quarter: clockwise for G2.
        let tangent = |point: Direction| {
            let radius = [point[0] - centre[0], point[1] - centre[1]];
            if counter_clockwise { [-radius[1], radius[0]] } else { [radius[1], -radius[0]] }
        };
        Some(PlaneMove { start: tangent(from), end: tangent(to), arc: true })
    }

    /// Rule 23: the lead-in and lead-out of a contour under compensation.
    fn lead(&mut self, file: &FileModel, step: &Step<'_>, plane: Plane, out: &mut Vec<Diagnostic>) {
        let switched = |numbers: &[u32]| {
            step.block.statements.iter().find(|s| {
                matches!(&s.kind, StatementKind::Word(w) if w.address == "G" && g_number(w).is_some_and(|n| numbers.contains(&n)))
            })
        };
        let movement = Self::plane_move(step, plane);
        let in_plane = movement.as_ref().filter(|m| m.start[0].hypot(m.start[1]) > SAME_POINT_MM);
        let line = matches!(step.state.motion(), Some("G0" | "G1"));
        let contour = &mut self.contour;
        match step.state.modes.get(TOOL_RADIUS) {
            Some("G41" | "G42") => {
                if let Some(statement) = switched(&[41, 42]) {
                    let range = file.in_file(step.index, statement.range);
                    *contour =
                        Contour { lead_in: in_plane.filter(|_| line).map(|m| (range, m.start)), ..Contour::default() };
                } else if let Some(m) = in_plane {
                    contour.element(m, out);
                } else if movement.is_none() {
                    // A move the walk cannot follow; one along the tool
                    // axis alone keeps the contour.
                    *contour = Contour::default();
                }
            }
            compensation => {
                if let Some(entry) = contour.entry.take() {
                    report_lead(entry, "enters", out);
                }
                if compensation == Some("G40")
                    && let (Some(statement), Some(end), Some(m)) = (switched(&[40]), contour.end, in_plane)
                    && line
                    && !contour.smooth_end
                    && let Some(angle) = steep(end, m.start)
                {
                    report_lead(SteepLead { range: file.in_file(step.index, statement.range), angle }, "leaves", out);
                }
                *contour = Contour::default();
            }
        }
    }

    /// Rule 28: repositioning in the plane at the depth of the cut.
    fn retract(&mut self, file: &FileModel, step: &Step<'_>, plane: Plane, out: &mut Vec<Diagnostic>) {
        let [a, b, tool] = plane.axes();
        let moved = |axis: usize| matches!((step.from[axis], step.state.position[axis]), (Known::Is(f), Known::Is(t)) if (t - f).abs() > SAME_POINT_MM);
        let in_plane = moved(a) || moved(b);
        let rapid = step.state.motion() == Some("G0");
        let into_stock = rapid
            && self.rapid_into_stock(file, step, tool, [step.from[tool], step.state.position[tool]], in_plane, out);
        let (Known::Is(from), Known::Is(to)) = (step.from[tool], step.state.position[tool]) else {
            self.approach = None;
            self.cut = false;
            return;
        };
        match step.state.feed_motion() {
            Known::Is(true) => {
                let approach = *self.approach.get_or_insert(from);
                self.cut |= to < approach - SAME_POINT_MM;
            }
            Known::Is(false) if rapid => {
                if !into_stock
                    && in_plane
                    && self.cut
                    && let Some(approach) = self.approach.filter(|&approach| from < approach - SAME_POINT_MM)
                {
                    let range = step.first_statement(file);
                    let axis = PATH_AXES[tool];
                    let message = format!(
                        "G0 moves in the plane with the tool at {axis}{from}, below {axis}{approach} where the cut started: the tool drags through the part or a clamp on its way; retract in {axis} alone first (004:381-383)"
                    );
                    out.push(Diagnostic::new(&NO_RETRACT, range, message));
                }
                if in_plane || to > from + SAME_POINT_MM {
                    self.approach = None;
                    self.cut = false;
                }
            }
            _ => {
                self.approach = None;
                self.cut = false;
            }
        }
    }

    /// Rule 15: a G0 from `heights[0]` to `heights[1]` on the tool axis
    /// that cuts the stock, as far as the walk knows them; whether it
    /// reported.
    fn rapid_into_stock(
        &self,
        file: &FileModel,
        step: &Step<'_>,
        tool: usize,
        [from, to]: [Known<f64>; 2],
        in_plane: bool,
        out: &mut Vec<Diagnostic>,
    ) -> bool {
        let Some(top) = self.stock_top else { return false };
        let below = |height: Known<f64>| height.known().filter(|&height| height < top - SAME_POINT_MM);
        let axis = PATH_AXES[tool];
        let message = if let Some(to) = below(to) {
            format!(
                "G0 ends at {axis}{to}, below the stock's top {axis}{top}: a rapid move never cuts; stop above the stock and feed in (004:821-825, 444)"
            )
        } else if let Some(from) = below(from).filter(|_| in_plane) {
            format!(
                "G0 moves in the plane with the tool at {axis}{from}, below the stock's top {axis}{top}: it cuts at rapid; retract above the stock first (004:821-825, 444)"
            )
        } else {
            return false;
        };
        let range = step.first_statement(file);
        out.push(Diagnostic::new(&RAPID_INTO_STOCK, range, message));
        true
    }

    /// Rule 38: the operations on each hole, in order.
    fn holes(&mut self, file: &FileModel, step: &Step<'_>, plane: Option<Plane>, out: &mut Vec<Diagnostic>) {
        let state = step.state;
        let catalogue = Dialect::Sinumerik.catalogue();
        let direct = step.block.statements.iter().find_map(|s| match &s.kind {
            StatementKind::Call(call) => match &call.callee {
                Callee::Cycle(name) => catalogue.hole_cycle(name).map(|cycle| (cycle, s.range)),
                _ => None,
            },
            _ => None,
        });
        let modal = match state.modal_call {
            Known::Is(Some(ModalCall::Hole(cycle))) if step.moves => Some((cycle, step.block.statements[0].range)),
            _ => None,
        };
        let Some((cycle, range)) = direct.or(modal) else { return };
        let (Some(plane), Known::Is(frame)) = (plane, state.frame) else { return };
        let [a, b, _] = plane.axes();
        let (Known::Is(x), Known::Is(y)) = (state.position[a], state.position[b]) else { return };
        let Some(operation) = cycle.hole else { return };
        let micrometres = |value: f64| (value / SAME_HOLE_MM).round() as i64;
        let key = (frame, plane, micrometres(x), micrometres(y));
        let range = file.in_file(step.index, range);
        if let Some(before) = self.holes.get(&key)
            && operation.stage() < before.operation.stage()
        {
            let message = format!(
                "{} {} the hole at {}{x} {}{y} after {} {} it: drill first, then bore or tap, then ream (004:468-470)",
                cycle.code,
                operation.done(),
                PATH_AXES[a],
                PATH_AXES[b],
                before.cycle,
                before.operation.done(),
            );
            out.push(Diagnostic::new(&HOLE_ORDER, range, message).with_related(
                None,
                before.range,
                format!("{} {} it here", before.cycle, before.operation.done()),
            ));
            return;
        }
        self.holes.insert(key, HoleMade { operation, cycle: &cycle.code, range });
    }
}
