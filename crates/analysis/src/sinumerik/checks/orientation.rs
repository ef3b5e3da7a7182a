//! Rules on the tool's orientation over the walk's modal state (digest §6
//! rules 71 and 72): a ball-nose tool standing square to its path, a tool
//! tilted far at a concave point of its pass.
//!
//! Assumptions, where the digest is silent:
//! - Rule 71 needs the tools with a ball end, `[sinumerik]
//!   ball-nose-tools`, which a program does not state; without the key it
//!   is quiet. It reads "the tool axis normal to the surface" as the axis
//!   square (within [`SQUARE_DEGREES`]) to a feed move under a
//!   transformation (TRAORI), where the tool could tilt: the surface under
//!   a path is not known, but a tool square to it is square to the
//!   surface along it. The axis is the vector A3, B3, C3, or Z where the
//!   angles leave the tool upright; other angles are not read, since their
//!   direction depends on the machine. It reports the first such move of
//!   each tool.
//! - The tilt is the angle between the tool and Z, from which the
//!   orientation is measured, whatever the plane: from the vector A3, B3,
//!   C3 where the walk knows all three, else from the angles, B2 under
//!   Euler angles (ORIEULER: A2 turns about Z, B2 then tilts) and
//!   `acos(cos A2 · cos B2)` under RPY angles (ORIRPY), as Siemens
//!   documents them.
//! - A point of a pass is concave where the path bends towards the tool:
//!   the tool-axis height at the end of a feed move lies more than
//!   [`CONCAVE_MM`] below the chord from the start of that move to the end
//!   of the next, measured by the distance in X and Y; a spline's control
//!   points stand for its curve. What the surface does across the pass is
//!   not known.
//! - A tilt above [`TILT_IN_CONCAVE_DEGREES`] at such a point is reported
//!   at the block that tilted the tool there: the thesis's L27 tilts 17° to
//!   28° at the three deepest points of its concave centre, where it
//!   gouged the finished surface in simulation (004:2957-2965), and up to
//!   40° on its flanks, which are not concave.

use nc_exec::{
    known::Known,
    sinumerik::{
        lower::{ExprKind, StatementKind, WordValue},
        modes::groups::ORIENTATION_ANGLES,
    },
};
use ncc_syntax::TextRange;

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    sinumerik::{
        checks::{
            program::TRANSFORMATION_OFF,
            visit::{is_transformation, number, word_is},
        },
        model::FileModel,
        walk::{FOLLOWED, SAME_POINT_MM, Step},
    },
};

declare_rules! {
    BALL_CENTRE_CUTS = "K071", "ball-centre-cuts", Info, "A ball-nose tool (`[sinumerik] ball-nose-tools`) whose axis stands square to its path under TRAORI: its centre, where the cutting speed is zero, cuts; tilt it along the path.";
    TILT_IN_CONCAVE = "K072", "tilt-in-concave", Warning, "A tool tilted more than 15° at a concave point of its pass: the tool may gouge the finished surface; scale the angle down there.";
}

/// A tool axis within this of a right angle to the path is square to it.
const SQUARE_DEGREES: f64 = 2.0;

/// A tilt above this at a concave point is reported.
const TILT_IN_CONCAVE_DEGREES: f64 = 15.0;

/// A point this far below the chord of its neighbours is concave.
const CONCAVE_MM: f64 = 0.01;

/// The orientation angles' code for RPY angles.
const RPY: &str = "ORIRPY";

/// Where the followed words are: the angles A2, B2 and the vector A3, B3,
/// C3.
const A2: usize = 6;
const B2: usize = 7;
const VECTOR: std::ops::Range<usize> = 9..12;

/// The last feed move's start and end, and the tilt at its end with the
/// word that set it.
struct Previous {
    from: [f64; 3],
    to: [f64; 3],
    tilt: Option<(f64, TextRange)>,
}

pub(crate) struct Orientation<'a> {
    previous: Option<Previous>,
    /// Rule 71: the configured ball-nose tools, the tool in the spindle
    /// (file order) and whether it is one, whether a transformation is on,
    /// and the tools reported.
    ball_nose_tools: &'a [String],
    tool: Option<(String, bool)>,
    transformed: bool,
    reported: Vec<String>,
}

impl<'a> Orientation<'a> {
    pub(crate) fn new(ball_nose_tools: &'a [String]) -> Orientation<'a> {
        Orientation { previous: None, ball_nose_tools, tool: None, transformed: false, reported: Vec::new() }
    }

    pub(crate) fn step(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        if !step.reached {
            return;
        }
        self.tool_and_transformation(step);
        if !step.moves {
            return;
        }
        self.ball_centre(file, step, out);
        let point = |position: &[Known<f64>]| -> Option<[f64; 3]> {
            Some([position[0].known()?, position[1].known()?, position[2].known()?])
        };
        let (Known::Is(true), Some(from), Some(to)) =
            (step.state.feed_motion(), point(&step.from), point(&step.state.position))
        else {
            self.previous = None;
            return;
        };
        if let Some(previous) = self.previous.take()
            && same(previous.to, from)
            && let Some((tilt, range)) = previous.tilt
            && tilt > TILT_IN_CONCAVE_DEGREES
            && let Some(depth) = below_chord(previous.from, from, to).filter(|&depth| depth > CONCAVE_MM)
        {
            let message = format!(
                "the tool tilts {tilt:.1}° from Z at a concave point of its pass, {depth:.3} mm below the chord of its neighbours: in the thesis's L27 such a tilt removed material of the finished surface; scale the angle down in concave regions (004:2957-2965)"
            );
            out.push(Diagnostic::new(&TILT_IN_CONCAVE, range, message));
        }
        self.previous = Some(Previous { from, to, tilt: tilt(file, step) });
    }
}

impl Orientation<'_> {
    /// The tool a T word selects, and TRAORI or TRAFOOF.
    fn tool_and_transformation(&mut self, step: &Step<'_>) {
        for statement in &step.block.statements {
            match &statement.kind {
                StatementKind::Word(word) if word.address == "T" => {
                    self.tool = word.value.as_ref().and_then(tool_name).map(|name| {
                        let ball = self.ball_nose_tools.iter().any(|tool| tool.eq_ignore_ascii_case(&name));
                        (name, ball)
                    });
                }
                StatementKind::Command(command) if is_transformation(&command.name) => {
                    self.transformed = command.name != TRANSFORMATION_OFF;
                }
                _ => {}
            }
        }
    }

    /// Rule 71: a ball-nose tool square to its path under TRAORI.
    fn ball_centre(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let Some((tool, true)) = &self.tool else { return };
        if !self.transformed || step.state.feed_motion() != Known::Is(true) || self.reported.contains(tool) {
            return;
        }
        let direction: Option<Vec<f64>> =
            (0..3).map(|axis| Some(step.state.position[axis].known()? - step.from[axis].known()?)).collect();
        let (Some(direction), Some(axis)) = (direction, tool_axis(step)) else { return };
        let length = direction.iter().map(|c| c * c).sum::<f64>().sqrt();
        if length <= SAME_POINT_MM {
            return;
        }
        let cos = direction.iter().zip(axis).map(|(d, a)| d * a).sum::<f64>() / length;
        if cos.abs() > SQUARE_DEGREES.to_radians().sin() {
            return;
        }
        self.reported.push(tool.clone());
        let range = step.first_statement(file);
        let message = format!(
            "the ball-nose tool {tool} stands square to its path: its centre, where the cutting speed is zero, cuts the surface; tilt the tool along the path, as the thesis tilted it by the vector A3=1 B3=2 C3=6 (004:2947-2951)"
        );
        out.push(Diagnostic::new(&BALL_CENTRE_CUTS, range, message));
    }
}

/// A tool as T names it: `T="BALL_6"`, `T12`, `T=12`.
fn tool_name(value: &WordValue) -> Option<String> {
    if let WordValue::Expr { expr, .. } = value
        && let ExprKind::String(name) = &expr.kind
    {
        return Some(name.clone());
    }
    number(value).map(|number| number.value().to_string())
}

/// The vector A3, B3, C3 as a unit vector, where the walk knows all three
/// (`Some(None)` for a vector without length); `None` where it does not.
fn programmed_vector(step: &Step<'_>) -> Option<Option<[f64; 3]>> {
    let position = &step.state.position;
    let [a, b, c] = [VECTOR.start, VECTOR.start + 1, VECTOR.start + 2].map(|axis| position[axis].known());
    let vector = [a?, b?, c?];
    let length = vector.iter().map(|c| c * c).sum::<f64>().sqrt();
    Some((length > f64::EPSILON).then(|| vector.map(|c| c / length)))
}

/// The tool's axis as a unit vector where the walk knows it: the vector
/// A3, B3, C3, or Z where the angles leave the tool upright.
fn tool_axis(step: &Step<'_>) -> Option<[f64; 3]> {
    if let Some(vector) = programmed_vector(step) {
        return vector;
    }
    let position = &step.state.position;
    let upright = |axis: usize| position[axis].known().is_some_and(|angle| angle.abs() <= f64::EPSILON);
    let upright = match step.state.modes.get(ORIENTATION_ANGLES)? {
        RPY => upright(A2) && upright(B2),
        _ => upright(B2),
    };
    upright.then_some([0.0, 0.0, 1.0])
}

fn same(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(b).all(|(a, b)| (a - b).abs() <= SAME_POINT_MM)
}

/// How far `middle` lies below the chord from `start` to `end` in Z, at
/// its share of the distance in the plane; `None` where the moves do not
/// move in the plane.
fn below_chord(start: [f64; 3], middle: [f64; 3], end: [f64; 3]) -> Option<f64> {
    let first = (middle[0] - start[0]).hypot(middle[1] - start[1]);
    let second = (end[0] - middle[0]).hypot(end[1] - middle[1]);
    if first <= SAME_POINT_MM || second <= SAME_POINT_MM {
        return None;
    }
    let chord = start[2] + (end[2] - start[2]) * first / (first + second);
    Some(chord - middle[2])
}

/// The tool's tilt from Z after the step, in degrees, and the word of the
/// block that gives it.
fn tilt(file: &FileModel, step: &Step<'_>) -> Option<(f64, TextRange)> {
    let written = |axis: usize| step.find(file, |statement| word_is(statement, FOLLOWED[axis]));
    if let Some(vector) = programmed_vector(step) {
        let degrees = vector?[2].clamp(-1.0, 1.0).acos().to_degrees();
        return Some((degrees, VECTOR.clone().find_map(written)?));
    }
    let position = &step.state.position;
    let b = position[B2].known()?;
    let degrees = match step.state.modes.get(ORIENTATION_ANGLES)? {
        RPY => (position[A2].known()?.to_radians().cos() * b.to_radians().cos()).clamp(-1.0, 1.0).acos().to_degrees(),
        _ => b.abs(),
    };
    Some((degrees, written(B2).or_else(|| written(A2))?))
}
