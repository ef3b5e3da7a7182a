//! The programmable frame and the control's cycles in a run: frame
//! commands and CYCLE800 change the frame the tool's program coordinates
//! are read in, arcs are put into base coordinates through it, and the
//! drilling cycles become moves of the block that calls them.

use ncc_catalog::Dialect;
use ncc_syntax::TextRange;

use super::{At, Facts, Interpreter, Moved, PLANE, STILL, XYZ, distance};
use crate::{
    sinumerik::{
        cycles::{self, CycleMove, Hole, SpindleAction},
        frames::{FrameCommand, FrameKind, Plane},
        lower::{Command, Expr, ExprKind},
    },
    trace::{Motion, Path, Position, RunRule, Stop, slot},
};

impl Interpreter<'_> {
    /// A frame command (TRANS, ATRANS, ROT, SCALE, MIRROR and their
    /// additive forms): the tool stays where it is, its program
    /// coordinates are those of the new frame.
    pub(super) fn frame(&mut self, command: &Command, range: TextRange) {
        let Some(frame_command) = FrameCommand::from_name(&command.name) else {
            return self.state.not_run(&command.name, range);
        };
        let mut values = Vec::with_capacity(command.words.len());
        for word in &command.words {
            let Some((value, _)) = self.word_number(word) else { return };
            let value = match frame_command.kind {
                FrameKind::Translation => self.length(value),
                FrameKind::Rotation | FrameKind::Scale | FrameKind::Mirror => value,
            };
            values.push((word.address.as_str(), value));
        }
        let plane = self.plane();
        let base = self.state.to_base(&self.state.position);
        match self.state.frame.apply(frame_command, &values, plane) {
            Ok(()) => {
                self.state.position = self.state.to_program(&base);
                self.state.frames += 1;
            }
            Err(error) => {
                let range = command.words.get(error.word).map_or(range, |word| word.range);
                self.state.finding(RunRule::ValueRefused, range, &error.to_string());
            }
        }
    }

    /// The working plane of G17, G18, G19.
    pub(super) fn plane(&self) -> Plane {
        self.state.modes.get(PLANE).and_then(Plane::from_code).unwrap_or_default()
    }

    /// A call of a control's cycle: the drilling cycles as moves of the
    /// block that calls them, CYCLE800 as the frame it swivels to; others
    /// (CYCLE832, …) are reported as not run.
    pub(super) fn cycle(&mut self, at: At, name: &str, arguments: &[Option<Expr>], range: TextRange) {
        // The catalogue's hole cycles: CYCLE81 … CYCLE89, CYCLE840.
        let drilling = Dialect::Sinumerik.catalogue().hole_cycle(name).is_some();
        if !drilling && name != "CYCLE800" {
            return self.state.not_run(&format!("the cycle {name}"), range);
        }
        let mut values = Vec::with_capacity(arguments.len());
        for argument in arguments {
            let value = match argument {
                // A string (CYCLE800's swivel data record) is not read.
                Some(expr) if matches!(expr.kind, ExprKind::String(_)) => None,
                Some(expr) => {
                    let result = self.eval().number(expr);
                    let Some(value) = self.check(result) else { return };
                    Some(value)
                }
                None => None,
            };
            values.push(value);
        }
        let result = if drilling {
            let hole = Hole {
                position: XYZ.map(|letter| self.state.position[slot(letter)]),
                plane: self.plane(),
                feed: self.feed_rate_quiet().unwrap_or(0.0),
                spindle: self.signed_rpm(),
            };
            cycles::drilling(name, &values, &hole).map(|moves| self.cycle_moves(at, &moves, range))
        } else {
            cycles::swivel(&values).map(|swivel| {
                let base = self.state.to_base(&self.state.position);
                swivel.apply_to(&mut self.state.frame);
                self.state.position = self.state.to_program(&base);
                self.state.frames += 1;
            })
        };
        if let Err(error) = result {
            self.state.finding(RunRule::CycleFailed, range, &error.to_string());
        }
    }

    /// A drilling cycle's moves as steps of the block at `at`.
    pub(super) fn cycle_moves(&mut self, at: At, moves: &[CycleMove], range: TextRange) {
        self.end_compensation();
        for cycle_move in moves {
            let start = self.state.to_base(&self.state.position);
            let mut to_point = |to: &[f64; 3]| {
                for (letter, value) in XYZ.into_iter().zip(to) {
                    self.state.position[slot(letter)] = *value;
                }
                let end = self.state.to_base(&self.state.position);
                (distance(&start, &end), end)
            };
            let (moved, stop) = match *cycle_move {
                CycleMove::Rapid(to) => {
                    let (length, end) = to_point(&to);
                    (self.rapid(&start, &end, length), None)
                }
                CycleMove::Feed { to, feed } => {
                    let (length, _) = to_point(&to);
                    let duration = if feed > 0.0 { length / feed * 60.0 } else { 0.0 };
                    let moved =
                        Moved { motion: Motion::Feed, path: Path::Straight, length, duration, feed: Some(feed) };
                    (moved, None)
                }
                CycleMove::Tap { to, lead, rpm } => {
                    let (length, _) = to_point(&to);
                    let feed = lead.abs() * rpm.abs();
                    let duration = if feed > 0.0 { length / feed * 60.0 } else { 0.0 };
                    let path = Path::Thread { lead: lead.abs(), speed: rpm.abs() };
                    (Moved { motion: Motion::Feed, path, length, duration, feed: Some(feed) }, None)
                }
                CycleMove::Dwell(seconds) => (Moved { motion: Motion::Dwell, duration: seconds, ..STILL }, None),
                CycleMove::Spindle(action) => {
                    let code = match action {
                        SpindleAction::Turn(rpm) => {
                            self.state.speed = rpm.abs();
                            if rpm < 0.0 { "M4" } else { "M3" }
                        }
                        SpindleAction::Stop | SpindleAction::Orient(_) => "M5",
                    };
                    if let Some(code) = Dialect::Sinumerik.catalogue().code_named(code) {
                        self.state.modes.set(code);
                    }
                    continue;
                }
                CycleMove::ProgramStop => (STILL, Some(Stop::Program)),
            };
            self.record(at, range, moved, Facts::default(), stop);
        }
    }

    /// The path of an arc programmed from `start` to `end` as the frame
    /// puts it in base coordinates: its centre moved and its sense turned
    /// over by mirrors; a straight move, reported, where the frame makes
    /// the circle an ellipse or turns it out of its plane.
    pub(super) fn arc_in_base(&mut self, path: Path, start: &Position, range: TextRange) -> Path {
        let Path::Arc { plane: (a, b), centre, clockwise } = path else { return path };
        if self.state.frame.is_identity() {
            return path;
        }
        let plane = self.plane();
        if !self.state.frame.keeps_plane(plane) {
            let what = "an arc in a frame that makes its circle an ellipse or turns it out of its plane (run straight)";
            self.state.not_run(what, range);
            return Path::Straight;
        }
        let mut centre_point = *start;
        centre_point[slot(a)] = centre[0];
        centre_point[slot(b)] = centre[1];
        let moved = self.state.to_base(&centre_point);
        Path::Arc {
            plane: (a, b),
            centre: [moved[slot(a)], moved[slot(b)]],
            clockwise: clockwise != self.state.frame.turns_arcs_over(plane),
        }
    }
}
