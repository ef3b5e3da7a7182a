//! Runs radius compensation over a run's steps, for the interpreters that
//! take it up on the first move after the code that selects it and leave it
//! on the first move after the cancel: each step's move in the plane goes
//! to a [`Compensator`], whose pieces become the trace's tool-centre path
//! ([`Compensated`] spans and [`ToolElement`]s) and replace the steps'
//! lengths and times.
//!
//! The interpreter says, step by step, which side the tool runs on (or that
//! compensation is cancelled) and, at a start, the radius, the corner
//! settings and a shift from the compensated point to the point the
//! control positions (a lathe's imaginary tip; zero elsewhere). The rules:
//! - compensation starts on the first step that moves in the plane with a
//!   side selected, which must be a line (rapid or feed); a radius of 0 or
//!   less leaves the path as programmed;
//! - it is cancelled on the first step that moves in the plane without a
//!   side, which must be a line, ending on the programmed point;
//! - it ends where it is (the last element on its normal) when the step's
//!   frame or plane changes, or at the run's end;
//! - each piece takes the time of its length at the step's feed (scaled
//!   on compensated arcs), or at the rapid rates of the plane's axes.

use nalgebra::{Point2, Vector2};

use crate::{
    compensation::{CompensationError, Compensator, Element, Settings, Side, ToolElement},
    machine::MachineConfig,
    trace::{Compensated, Motion, Path, Undelivered},
};

/// How compensation starts, from the step that starts it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    pub side: Side,
    pub radius: f64,
    pub settings: Settings,
    /// From the compensated point to the point the control positions.
    pub shift: Vector2<f64>,
}

/// A step's move as compensation sees it: its start and end in the plane,
/// the plane's axes (the order of the points) and the frame it runs in
/// (compensation does not cross a change of either).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneMove {
    pub step: usize,
    pub from: Point2<f64>,
    pub to: Point2<f64>,
    pub plane: (u8, u8),
    pub frame: usize,
}

/// Why a step could not be compensated; the interpreter says it in its
/// control's words.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    /// The first move to compensate is an arc or a thread.
    StartNotLine,
    /// The first move after the cancel is an arc or a thread; compensation
    /// is dropped.
    CancelNotLine,
    Failed(CompensationError),
}

/// Compensation in force.
#[derive(Debug, Clone)]
struct Active {
    compensator: Compensator,
    shift: Vector2<f64>,
    plane: (u8, u8),
    frame: usize,
}

/// Radius compensation over a run, and the tool-centre path it made.
#[derive(Debug, Clone, Default)]
pub struct Driver {
    active: Option<Active>,
    /// The tool-centre path, in the order compensation fixed it (a move
    /// late): [`Driver::into_parts`] sorts it by step.
    pub tool_centre: Vec<ToolElement>,
    pub compensated: Vec<Compensated>,
}

impl Driver {
    pub fn is_active(&self) -> bool {
        self.active.is_some()
    }

    /// The first step whose tool path may still change.
    pub fn open_step(&self) -> Option<usize> {
        self.active.as_ref().map(|active| active.compensator.open_block())
    }

    /// Follows the step of `moved` under `start` (`None`: cancelled, or a
    /// move that runs without): starts, continues or cancels compensation,
    /// and charges the pieces it fixes to their steps in `steps`.
    pub fn follow(
        &mut self,
        steps: &mut Undelivered,
        machine: &MachineConfig,
        moved: PlaneMove,
        start: Option<Start>,
    ) -> Result<(), Refusal> {
        let PlaneMove { step: index, from, to, plane, frame } = moved;
        let step = steps.get(index);
        let moves = from != to || matches!(step.path, Path::Arc { .. });
        let line = matches!(step.motion, Motion::Rapid | Motion::Feed) && step.path == Path::Straight;
        let element = match step.path {
            Path::Arc { centre, clockwise, .. } => {
                Element::Arc { from, to, centre: Point2::new(centre[0], centre[1]), clockwise }
            }
            _ => Element::Line { from, to },
        };
        if self.active.as_ref().is_some_and(|active| (active.frame, active.plane) != (frame, plane)) {
            self.end(steps, machine);
        }
        let (pieces, active) = match (self.active.take(), start) {
            (None, Some(start)) if moves => {
                if start.radius <= 0.0 {
                    return Ok(());
                }
                if !line {
                    return Err(Refusal::StartNotLine);
                }
                let Start { side, radius, settings, shift } = start;
                let compensator = Compensator::start(settings, side, radius, index, from - shift, to - shift);
                self.active = Some(Active { compensator, shift, plane, frame });
                self.compensated.push(Compensated { steps: index..index + 1, plane });
                return Ok(());
            }
            (Some(active), None) if moves => {
                if !line {
                    return Err(Refusal::CancelNotLine);
                }
                let Active { compensator, shift, plane, .. } = active;
                (compensator.cancel(index, to - shift), (shift, plane))
            }
            (Some(mut active), _) => {
                let pushed = if moves { active.compensator.push(index, element) } else { Ok(Vec::new()) };
                let placed = (active.shift, active.plane);
                // Kept on an error too, so that the run's end fixes the
                // element before the step the control stops at.
                self.active = Some(active);
                (pushed.map_err(Refusal::Failed)?, placed)
            }
            (None, _) => return Ok(()),
        };
        if let Some(compensated) = self.compensated.last_mut() {
            compensated.steps.end = index + 1;
        }
        self.charge(steps, machine, pieces, active);
        Ok(())
    }

    /// Ends compensation still in force where the run ends or its frame
    /// changes: the tool centre stays on the normal at the last programmed
    /// point.
    pub fn end(&mut self, steps: &mut Undelivered, machine: &MachineConfig) {
        if let Some(active) = self.active.take() {
            let placed = (active.shift, active.plane);
            self.charge(steps, machine, vec![active.compensator.finish()], placed);
        }
    }

    /// The tool-centre path in the order of its steps, and the spans.
    pub fn into_parts(mut self) -> (Vec<ToolElement>, Vec<Compensated>) {
        self.tool_centre.sort_by_key(|piece| piece.block);
        (self.tool_centre, self.compensated)
    }

    /// Puts the length and time of `pieces`, moved by `shift`, in `plane`,
    /// on the steps they belong to, in place of the programmed ones.
    fn charge(
        &mut self,
        steps: &mut Undelivered,
        machine: &MachineConfig,
        pieces: Vec<ToolElement>,
        (shift, plane): (Vector2<f64>, (u8, u8)),
    ) {
        for piece in pieces {
            let piece = ToolElement { path: shifted(piece.path, shift), ..piece };
            let length = piece.path.length();
            let step = steps.get(piece.block);
            let duration = match (step.motion, step.feed) {
                (Motion::Feed, Some(feed)) => length / (feed * piece.feed_scale) * 60.0,
                (Motion::Feed, None) => 0.0,
                _ => rapid_seconds(machine, plane, piece.path.start(), piece.path.end()),
            };
            // A step's pieces come together (its corner, then its
            // contour): the first replaces the programmed length and time.
            let first = self.tool_centre.last().is_none_or(|last| last.block != piece.block);
            let step = steps.get_mut(piece.block);
            if first {
                (step.length, step.duration) = (0.0, 0.0);
            }
            step.length += length;
            step.duration += duration;
            self.tool_centre.push(piece);
        }
    }
}

/// A rapid move in the plane `(a, b)`: each axis at its own rate, the
/// slowest deciding.
fn rapid_seconds(machine: &MachineConfig, (a, b): (u8, u8), from: Point2<f64>, to: Point2<f64>) -> f64 {
    let minutes = [(a, to.x - from.x), (b, to.y - from.y)]
        .map(|(axis, delta)| delta.abs() / f64::from(machine.axis_rapid_rate(axis)))
        .into_iter()
        .fold(0.0, f64::max);
    minutes * 60.0
}

fn shifted(element: Element, by: Vector2<f64>) -> Element {
    match element {
        Element::Line { from, to } => Element::Line { from: from + by, to: to + by },
        Element::Arc { from, to, centre, clockwise } => {
            Element::Arc { from: from + by, to: to + by, centre: centre + by, clockwise }
        }
    }
}
