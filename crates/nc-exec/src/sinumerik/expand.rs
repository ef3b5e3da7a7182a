//! A Sinumerik run written back as a program (`ncc expand`) while it runs:
//! every move as a plain block, with the variables, loops, jumps, calls,
//! splines and written files resolved, that runs the same moves.
//!
//! The program is a comment with its title, a setup block `G17 G71 G90
//! G94 G60 BRISK` (the plane XY, mm, absolute, feed per minute, exact
//! stop, no jerk limit, whatever ran before), the moves and `M30`:
//! - Rapid moves are G0, lines G1, arcs G2/G3 with the plane (G17, G18,
//!   G19) written where it changes and the centre as I, J, K from the
//!   start, rounded so that the end lies on the circle within 1 µm; an
//!   arc writes all its plane's axes, so that a full circle still moves.
//!   A BSPLINE is its straight pieces.
//! - Positions to the micrometre (degrees to 0.001 on rotary axes) and F
//!   in mm/min to 0.001, each written when it changes, every axis on the
//!   first move: the run's start at 0 is its assumption, not a place the
//!   machine is known to be. The feed is what ran: under G95 F times the
//!   spindle speed.
//! - Dwells are `G4 F` in seconds, stops M0/M1 where the run had them;
//!   SOFT and BRISK where the jerk limit changes, in the block of a move;
//!   G60, or G642 with the corner tolerance as `CTOL=`, where the way the
//!   path passes into the next move changes, in the block before it (the
//!   expansion writes a block once the next one has come).
//! - Tools, the spindle and other M functions are not written: the
//!   expansion is the path and its time.
//! - Under tool radius compensation G41/G42 the moves are those of the
//!   tool centre ([`crate::tool_path`]), a step's pieces one block each,
//!   and G41/G42/G40 are not written.

use std::io::{self, Write};

use super::interpreter::reset_frame;
use crate::{
    compensation::ToolElement,
    expand::{Expand, ExpandError, centre_offsets},
    machine::MachineConfig,
    tool_path::{CentredSteps, OwnCentred, tool_moves},
    trace::{Axes, Compensated, MAX_AXES, Motion, Path, PathMode, Step, StepSink, Stop, round3},
    transform::Frame,
};

/// Writes the moves of a Sinumerik run to `out` while the run goes: a
/// [`StepSink`] that writes the block of each step as it comes and keeps
/// nothing of it.
#[derive(Debug)]
pub struct Expansion<W: Write> {
    out: W,
    axes: Vec<u8>,
    /// Where the written program has the tool, in thousandths, by the
    /// machine's axes; nowhere before its first move.
    at: Option<Vec<i64>>,
    feed: Option<i64>,
    plane: (u8, u8),
    exact_stop: bool,
    jerk_limited: bool,
    /// The corner tolerance written, in µm; `None` under G60.
    corner: Option<i64>,
    /// The words of the block written last: how the path passes from it
    /// into the next one is that step's to say.
    pending: Option<Vec<String>>,
    /// Radius compensation of the steps to come.
    centres: CentredSteps,
    failure: Option<ExpandError>,
}

impl<W: Write> Expansion<W> {
    /// Starts the program with `title` as its comment, for a run on
    /// `machine`.
    pub fn new(out: W, machine: &MachineConfig, title: &str) -> Expansion<W> {
        debug_assert_eq!(reset_frame(machine), Default::default(), "the steps are in the frame the program starts in");
        let mut expansion = Expansion {
            out,
            axes: machine.step_axes().to_vec(),
            at: None,
            feed: None,
            plane: (b'X', b'Y'),
            exact_stop: true,
            jerk_limited: false,
            corner: None,
            pending: None,
            centres: CentredSteps::default(),
            failure: None,
        };
        let title: String = title.chars().filter(|c| !c.is_control()).collect();
        let started = write!(expansion.out, "; {title}\nG17 G71 G90 G94 G60 BRISK\n");
        expansion.failure = started.err().map(ExpandError::Io);
        expansion
    }

    /// The position `step` ends at, in thousandths, by the machine's axes.
    fn thousandths(&self, step: &Step) -> Vec<i64> {
        self.axes.iter().zip(&step.end).map(|(_, &value)| (round3(value) * 1000.0).round() as i64).collect()
    }

    /// Writes the blocks of `step`: under radius compensation (`own`) one
    /// for each move of the tool centre, the last with the step's stop.
    fn write_centred(&mut self, step: &Step, own: Option<&OwnCentred>) -> io::Result<()> {
        let Some(own) = own else { return self.write(step) };
        let mut start: Axes = [0.0; MAX_AXES];
        for (value, &at) in start.iter_mut().zip(self.at.iter().flatten()) {
            *value = at as f64 / 1000.0;
        }
        let moves = tool_moves(step, &start, Some(&own.centred()), &self.axes);
        let last = moves.len() - 1;
        for (k, tool_move) in moves.into_iter().enumerate() {
            let stop = if k == last { step.stop } else { None };
            let made = Step { end: tool_move.end, path: tool_move.path, feed: tool_move.feed, stop, ..step.clone() };
            self.write(&made)?;
        }
        Ok(())
    }

    /// Writes the block of `step`: none for a step without motion, time or
    /// stop.
    fn write(&mut self, step: &Step) -> io::Result<()> {
        let to = self.thousandths(step);
        let moved: Vec<bool> = match &self.at {
            Some(at) => at.iter().zip(&to).map(|(a, b)| a != b).collect(),
            None => vec![true; to.len()],
        };
        let mut words: Vec<String> = Vec::new();
        match (step.motion, step.path) {
            (Motion::None, _) => {}
            (Motion::Dwell, _) => words.push(format!("G4 F{}", decimal((step.duration * 1000.0).round() as i64))),
            (Motion::Rapid | Motion::Feed, path) if !moved.contains(&true) && !matches!(path, Path::Arc { .. }) => {}
            (Motion::Rapid, _) => {
                words.push("G0".to_owned());
                words.extend(self.coordinates(&to, &moved));
            }
            (Motion::Feed, Path::Arc { plane, centre, clockwise }) => {
                let index = |letter: u8| self.axes.iter().position(|&axis| axis == letter);
                let (Some(a), Some(b)) = (index(plane.0), index(plane.1)) else { return Ok(()) };
                if plane != self.plane {
                    self.plane = plane;
                    words.push(plane_code(plane).to_owned());
                }
                words.push(if clockwise { "G2" } else { "G3" }.to_owned());
                let mut all = moved.clone();
                all[a] = true;
                all[b] = true;
                words.extend(self.coordinates(&to, &all));
                let from = self.at.clone().unwrap_or_else(|| vec![0; to.len()]);
                let point = |values: &[i64]| [values[a] as f64 / 1000.0, values[b] as f64 / 1000.0];
                let offsets = centre_offsets(point(&from), point(&to), centre);
                for (letter, offset) in [plane.0, plane.1].into_iter().zip(offsets) {
                    let name = char::from(b'I' + (letter - b'X'));
                    words.push(format!("{name}{}", decimal((offset * 1000.0).round() as i64)));
                }
                words.extend(self.feed_word(step.feed));
            }
            (Motion::Feed, _) => {
                words.push("G1".to_owned());
                words.extend(self.coordinates(&to, &moved));
                words.extend(self.feed_word(step.feed));
            }
        }
        if matches!(step.motion, Motion::Rapid | Motion::Feed) {
            self.at = Some(to);
        }
        if !words.is_empty() && step.jerk_limited != self.jerk_limited {
            self.jerk_limited = step.jerk_limited;
            words.insert(0, if step.jerk_limited { "SOFT" } else { "BRISK" }.to_owned());
        }
        match step.stop {
            Some(Stop::Program) => words.push("M0".to_owned()),
            Some(Stop::Optional) => words.push("M1".to_owned()),
            None => {}
        }
        if words.is_empty() {
            return Ok(());
        }
        let joining = self.joining(step);
        self.flush(joining)?;
        self.pending = Some(words);
        Ok(())
    }

    /// Writes the block before, with the mode that passes from it into
    /// the next (`joining`).
    fn flush(&mut self, joining: Option<String>) -> io::Result<()> {
        let Some(mut words) = self.pending.take() else { return Ok(()) };
        words.splice(0..0, joining);
        writeln!(self.out, "{}", words.join(" "))
    }

    /// The path mode that passes into `step` as it ran, where it changes:
    /// G60 for an exact stop, else G642 with the corner tolerance as CTOL,
    /// which the policy takes as it is.
    fn joining(&mut self, step: &Step) -> Option<String> {
        let exact_stop = step.path_mode == PathMode::ExactStop;
        let corner = (!exact_stop && step.corner_tolerance.is_finite())
            .then(|| (f64::from(step.corner_tolerance) * 1000.0).round() as i64);
        if (exact_stop, corner) == (self.exact_stop, self.corner) {
            return None;
        }
        (self.exact_stop, self.corner) = (exact_stop, corner);
        Some(match corner {
            _ if exact_stop => "G60".to_owned(),
            Some(corner) => format!("G642 CTOL={}", decimal(corner)),
            None => "G64".to_owned(),
        })
    }

    /// The words of the axes `moved` marks, to their place in `to`.
    fn coordinates(&self, to: &[i64], moved: &[bool]) -> Vec<String> {
        self.axes
            .iter()
            .zip(to)
            .zip(moved)
            .filter(|(_, moved)| **moved)
            .map(|((&axis, &value), _)| format!("{}{}", char::from(axis), decimal(value)))
            .collect()
    }

    /// `F` when the feed changes.
    fn feed_word(&mut self, feed: Option<f64>) -> Option<String> {
        let feed = (feed? * 1000.0).round() as i64;
        if self.feed == Some(feed) {
            return None;
        }
        self.feed = Some(feed);
        Some(format!("F{}", decimal(feed)))
    }
}

fn plane_code(plane: (u8, u8)) -> &'static str {
    match plane {
        (b'Z', b'X') => "G18",
        (b'Y', b'Z') => "G19",
        _ => "G17",
    }
}

/// Thousandths written as a decimal without trailing zeros: `12500` is
/// `12.5`, `-3000` is `-3`.
fn decimal(thousandths: i64) -> String {
    let sign = if thousandths < 0 { "-" } else { "" };
    let (whole, fraction) = (thousandths.unsigned_abs() / 1000, thousandths.unsigned_abs() % 1000);
    if fraction == 0 {
        return format!("{sign}{whole}");
    }
    let digits = format!("{fraction:03}");
    format!("{sign}{whole}.{}", digits.trim_end_matches('0'))
}

impl<W: Write> StepSink for Expansion<W> {
    fn step(&mut self, step: Step) {
        let own = self.centres.next_step();
        if self.failure.is_none()
            && let Err(error) = self.write_centred(&step, own.as_ref())
        {
            self.failure = Some(ExpandError::Io(error));
        }
    }

    fn references(&mut self, _frames: &[Frame], compensated: &[Compensated], pieces: &[ToolElement]) {
        self.centres.references(compensated, pieces);
    }

    fn closed(&self) -> bool {
        self.failure.is_some()
    }
}

impl<W: Write> Expand for Expansion<W> {
    fn finish(mut self: Box<Self>) -> Result<(), ExpandError> {
        if let Some(failure) = self.failure.take() {
            return Err(failure);
        }
        self.flush(None)?;
        self.out.write_all(b"M30\n")?;
        self.out.flush()?;
        Ok(())
    }
}

#[cfg(test)]
mod tests;
