//! A Haas lathe run written back as a program (`ncc expand`) while it
//! runs: every move as a plain lathe block, with the macro statements,
//! loops and jumps resolved, that runs the same moves.
//!
//! The program is `%`, `O<number> (<title>)`, a setup block, the moves,
//! `M30` and `%` (lathe manual §5.1 (001:1800, 3712)):
//! - The setup block `G18 G21 G40 G97 G98` puts the plane ZX, millimetres,
//!   no tool-nose radius compensation, the spindle in rpm and the feed per
//!   minute in force, whatever ran before the program.
//! - The feed is per minute (G98) because it is what ran: under G99 the
//!   feed per minute is F times the spindle speed, and under G96 that
//!   speed, and with it the feed per minute, follows the diameter along
//!   the move; the run's feed of a block is the average that gives its
//!   time, so written per minute each block takes the time it took. F is
//!   written to 0.001 mm/min.
//! - X is written as the diameter (the run keeps the radius), X and Z to
//!   the micrometre; like F they are written only when they change, but
//!   the first move writes both: the run's start at X0 Z0 is its
//!   assumption, not a place the machine is known to be.
//! - Rapid moves are G00, lines G01, arcs G02/G03 by I (as a radius, as
//!   the manual defines it) and K from the start to the centre, rounded so
//!   that the end lies on the circle within 1 µm; an arc writes both X and
//!   Z, so that a full circle still moves. G02 turns clockwise seen with
//!   +Z to the right and +X up (lathe manual §5.8 (001:591-668)), the
//!   sense the run keeps in its plane (Z, X).
//! - Threads are G32 with the lead as F, after a block `S<rpm> M03` when
//!   the spindle speed changes: a thread needs the spindle turning, and the
//!   run does not say which way it turns, which does not change the time.
//! - Dwells are `G04 P` in ms (without a decimal point, lathe manual §5.3
//!   (001:55-71)), the stops M00/M01 where the run had them; exact stop
//!   G61, and G64 back, where the run's blocks change between them (G09
//!   becomes G61 for one block); `G103 P1` and `G103` where the blocks
//!   change between stopping for the look-ahead limit and not, and
//!   `G187 E` where the corner tolerance changes, in the block of a move
//!   (a block of their own would stop the path), before a dwell or a
//!   thread on a line of their own.
//! - Tools, the spindle's other words and M functions other than stops
//!   are not written: the expansion is the path and its time, without
//!   the waits for the spindle that the velocity model adds to cuts.
//!
//! No block is numbered: the numbers are optional (lathe manual §5.1
//! (001:1800-1824)) and nothing jumps in an expansion. The manual names no
//! line length; blocks of positions within ±99999.999 mm stay under 80
//! characters. Positions are written in G54's coordinates, which the
//! header selects: a step run under another work offset, G52 or G53 is
//! moved to them (a Haas frame is a shift, so an arc's centre moves with
//! its end). Under tool-nose radius compensation with a radius the tool's
//! path is not the programmed one: such a step is not written yet.

use std::{
    collections::HashMap,
    io::{self, Write},
};

use nalgebra::Point2;

use crate::{
    compensation::ToolElement,
    expand::{Expand, ExpandError, Unwritable, centre_offsets},
    machine::MachineConfig,
    trace::{Compensated, Motion, Path, PathMode, Step, StepSink, Stop, slot},
    transform::{Frame, by_letter},
};

/// The plane of the run's arcs: Z first, the radius X second.
const PLANE: (u8, u8) = (b'Z', b'X');

const OUT_OF_PLANE: &str = "an arc outside the lathe's plane ZX (G18) cannot be written for a Haas lathe";
const COMPENSATED: &str =
    "under tool-nose radius compensation the tool's path is not the programmed one; ncc expand does not write it yet";

/// Writes the moves of a Haas lathe run as program `O<number>` to `out`
/// while the run goes: a [`StepSink`] that writes the block of each step as
/// it comes and keeps nothing of it, so that a run of any length expands in
/// the same memory.
#[derive(Debug)]
pub struct Expansion<W: Write> {
    out: W,
    axes: Vec<u8>,
    /// Where the written program has the tool: Z and the diameter X, in µm;
    /// nowhere before its first move.
    at: Option<[i64; 2]>,
    /// The number of the F in force, as written: mm/min, or the lead in
    /// mm after a thread (one modal F serves both).
    feed: Option<String>,
    /// The S in force, rpm.
    speed: Option<i64>,
    /// Whether G61 is in force rather than G64, G103 P1 rather than no
    /// limit, and the corner tolerance in µm.
    exact_stop: bool,
    unjoined: bool,
    corner_tolerance: i64,
    /// The run's frames, and G54's, in which the program is written.
    frames: Vec<Frame>,
    written: Frame,
    /// Where each compensated step's tool path ends, by step (Z, X), until
    /// the step is written.
    tool_ends: HashMap<usize, Point2<f64>>,
    /// The index of the step to come.
    next: usize,
    /// What stopped the expansion: nothing is written after it.
    failure: Option<ExpandError>,
}

impl<W: Write> Expansion<W> {
    /// Starts program `O<number>`, with `title` as its comment, for a run on
    /// `machine`.
    pub fn new(out: W, machine: &MachineConfig, number: u32, title: &str) -> Expansion<W> {
        let mut expansion = Expansion {
            out,
            axes: machine.step_axes().to_vec(),
            at: None,
            feed: None,
            speed: None,
            exact_stop: false,
            unjoined: false,
            corner_tolerance: thousandths(super::dynamics::corner_rounding(machine)),
            frames: Vec::new(),
            written: super::interpreter::reset_frame(machine),
            tool_ends: HashMap::new(),
            next: 0,
            failure: None,
        };
        // A comment ends at the first `)` and does not nest.
        let title: String = title.chars().filter(|&c| c != '(' && c != ')' && !c.is_control()).collect();
        let comment = if title.is_empty() { String::new() } else { format!(" ({title})") };
        let started = write!(expansion.out, "%\nO{number}{comment}\nG18 G21 G40 G54 G97 G98\n");
        expansion.failure = started.err().map(ExpandError::Io);
        expansion
    }

    /// Ends the program after the run, and hands back the output.
    pub fn finish(mut self) -> Result<W, ExpandError> {
        if let Some(failure) = self.failure {
            return Err(failure);
        }
        self.out.write_all(b"M30\n%\n")?;
        self.out.flush()?;
        Ok(self.out)
    }

    /// Writes the blocks of `step`: none for a step without motion, time or
    /// stop.
    fn write(&mut self, step: &Step, index: usize) -> Result<(), ExpandError> {
        let programmed = by_letter(&step.end, &self.axes);
        if let Some(tool) = self.tool_ends.remove(&index)
            && (tool - Point2::new(programmed[slot(b'Z')], programmed[slot(b'X')])).norm() > 1e-6
        {
            let unwritable = Unwritable { source: step.source, range: step.range, reason: COMPENSATED };
            return Err(ExpandError::Unwritable(unwritable));
        }
        let machine = self.frames.get(step.frame).map_or(step.end, |frame| frame.to_machine(&step.end, &self.axes));
        let end = by_letter(&self.written.to_program(&machine, &self.axes), &self.axes);
        let shift = [end[slot(b'Z')] - programmed[slot(b'Z')], end[slot(b'X')] - programmed[slot(b'X')]];
        let to = [thousandths(end[slot(b'Z')]), thousandths(2.0 * end[slot(b'X')])];
        let moved = self.at.map_or([true, true], |at| [to[0] != at[0], to[1] != at[1]]);
        let mut words: Vec<String> = Vec::new();
        match (step.motion, step.path) {
            (Motion::None, _) => {}
            (Motion::Dwell, _) => {
                words.push("G04".to_owned());
                words.push(format!("P{}", (step.duration * 1000.0).round().max(0.0) as i64));
            }
            (Motion::Rapid | Motion::Feed, path) if !moved.contains(&true) && !matches!(path, Path::Arc { .. }) => {}
            (Motion::Rapid, _) => {
                words.push("G00".to_owned());
                words.extend(coordinates(to, moved));
            }
            (Motion::Feed, Path::Straight) => {
                words.push("G01".to_owned());
                words.extend(coordinates(to, moved));
                words.extend(self.feed_word(step.feed));
            }
            (Motion::Feed, Path::Arc { plane, centre, clockwise }) => {
                if plane != PLANE {
                    let unwritable = Unwritable { source: step.source, range: step.range, reason: OUT_OF_PLANE };
                    return Err(ExpandError::Unwritable(unwritable));
                }
                words.push(if clockwise { "G02" } else { "G03" }.to_owned());
                words.extend(coordinates(to, [true, true]));
                // The plane's radius X is half the written diameter.
                let plane_point = |[z, d]: [i64; 2]| [z as f64 / 1000.0, d as f64 / 2000.0];
                let centre = [centre[0] + shift[0], centre[1] + shift[1]];
                let [k, i] = centre_offsets(plane_point(self.at.unwrap_or_default()), plane_point(to), centre);
                words.push(format!("I{}", decimal(thousandths(i), 3)));
                words.push(format!("K{}", decimal(thousandths(k), 3)));
                words.extend(self.feed_word(step.feed));
            }
            (Motion::Feed, Path::Thread { lead, speed }) => {
                let rpm = speed.round() as i64;
                if self.speed != Some(rpm) {
                    self.speed = Some(rpm);
                    self.line(&[format!("S{rpm}"), "M03".to_owned()])?;
                }
                words.push("G32".to_owned());
                words.extend(coordinates(to, moved));
                // A lead from inches needs the fourth place (1.5875 mm).
                words.extend(self.f_word(decimal(((lead * 10_000.0).round() as i64).max(1), 4)));
            }
        }
        if matches!(step.motion, Motion::Rapid | Motion::Feed) {
            self.at = Some(to);
        }
        self.path_modes(step, &mut words)?;
        let exact_stop = step.path_mode == PathMode::ExactStop;
        if !words.is_empty() && exact_stop != self.exact_stop {
            self.exact_stop = exact_stop;
            words.insert(0, if exact_stop { "G61" } else { "G64" }.to_owned());
        }
        match step.stop {
            Some(Stop::Program) => words.push("M00".to_owned()),
            Some(Stop::Optional) => words.push("M01".to_owned()),
            None => {}
        }
        if !words.is_empty() {
            self.line(&words)?;
        }
        Ok(())
    }

    /// Writes where `step` changes the look-ahead limit or the corner
    /// tolerance: into its block's `words`, where a line of its own would
    /// stop a path the run joined, else on a line before it. A G103 P1
    /// line stops no more than the limit does; a block that moves nothing
    /// passes its G187 and its end of the limit on to the next.
    fn path_modes(&mut self, step: &Step, words: &mut Vec<String>) -> io::Result<()> {
        // Under an exact stop the look-ahead limit changes no time.
        let unjoined = step.path_mode == PathMode::Stop;
        let joined_move = !words.is_empty() && words[0] != "G04" && words[0] != "G32";
        if step.path_mode != PathMode::ExactStop && unjoined != self.unjoined {
            if unjoined {
                self.line(&["G103 P1".to_owned()])?;
                self.unjoined = true;
            } else if joined_move {
                words.insert(0, "G103".to_owned());
                self.unjoined = false;
            } else if !words.is_empty() {
                self.line(&["G103".to_owned()])?;
                self.unjoined = false;
            }
        }
        let corner_tolerance = thousandths(f64::from(step.corner_tolerance));
        if !words.is_empty() && corner_tolerance != self.corner_tolerance {
            self.corner_tolerance = corner_tolerance;
            let word = format!("G187 E{}", decimal(corner_tolerance, 3));
            if joined_move { words.insert(0, word) } else { self.line(&[word])? }
        }
        Ok(())
    }

    /// F for a move at `feed` mm/min, when it differs from the F in force.
    fn feed_word(&mut self, feed: Option<f64>) -> Option<String> {
        self.f_word(decimal(thousandths(feed?).max(1), 3))
    }

    /// F of `number`, when it differs from the F in force: [`decimal`]
    /// writes each value one way, so equal values are equal numbers.
    fn f_word(&mut self, number: String) -> Option<String> {
        (self.feed.as_ref() != Some(&number)).then(|| {
            let word = format!("F{number}");
            self.feed = Some(number);
            word
        })
    }

    fn line(&mut self, words: &[String]) -> io::Result<()> {
        writeln!(self.out, "{}", words.join(" "))
    }
}

impl<W: Write> StepSink for Expansion<W> {
    fn step(&mut self, step: Step) {
        if self.failure.is_some() {
            return;
        }
        let index = self.next;
        self.next += 1;
        if let Err(failure) = self.write(&step, index) {
            self.failure = Some(failure);
        }
    }

    fn references(&mut self, frames: &[Frame], _compensated: &[Compensated], tool_centre: &[ToolElement]) {
        self.frames.extend_from_slice(frames.get(self.frames.len()..).unwrap_or_default());
        for piece in tool_centre {
            self.tool_ends.insert(piece.block, piece.path.end());
        }
    }

    /// Nothing more is written after a failure, so the run need not go on.
    fn closed(&self) -> bool {
        self.failure.is_some()
    }
}

impl<W: Write> Expand for Expansion<W> {
    fn finish(self: Box<Self>) -> Result<(), ExpandError> {
        Expansion::finish(*self).map(drop)
    }
}

/// X and Z of a move to `to` (Z and the diameter X, in µm) where `written`
/// says so.
fn coordinates(to: [i64; 2], written: [bool; 2]) -> impl Iterator<Item = String> {
    let [z, x] = written;
    let x = x.then(|| format!("X{}", decimal(to[1], 3)));
    let z = z.then(|| format!("Z{}", decimal(to[0], 3)));
    x.into_iter().chain(z)
}

/// A length or feed in thousandths, the resolution most of the program is
/// written in.
fn thousandths(value: f64) -> i64 {
    (value * 1000.0).round() as i64
}

/// A number of `scaled` units of `10^-places` as the manual writes
/// numbers: with a decimal point, without trailing zeros (`20.`, `0.15`,
/// `-2.5`).
fn decimal(scaled: i64, places: u32) -> String {
    let unit = 10u64.pow(places);
    let sign = if scaled < 0 { "-" } else { "" };
    let magnitude = scaled.unsigned_abs();
    let fraction = format!("{:0width$}", magnitude % unit, width = places as usize);
    format!("{sign}{}.{}", magnitude / unit, fraction.trim_end_matches('0'))
}

#[cfg(test)]
mod tests;
