//! Coordinates: the work offsets G54–G59 and G110–G129 (lathe manual §7.3
//! (001:126-131, 233-277)), the local shift G52 (001:114-119), moves in
//! machine coordinates G53 (001:116-124, 464-465) and the reference point
//! returns G28 and G29 (001:78-97).
//!
//! The reference point is the machine zero (001:471-477); the run starts
//! there, where the machine finds its position again after power-off by
//! passing its reference points (001:422-425). A work offset is the
//! machine position of the program's zero, from the machine's offset
//! table; G52 shifts the program's zero from there. Each stretch of steps
//! under one offset and shift has its frame
//! ([`Trace::frames`](crate::trace::Trace)), so that the steps keep their
//! program coordinates. Choosing another offset or shift moves nothing:
//! the tool's program position changes instead.
//!
//! Assumptions the manual does not settle:
//! - The offset table's X is a diameter, as every X on this control is
//!   (§5.4 (001:480)) and the machine zero's distance in the manual's
//!   figure is ("X-250. Ø", 001:440); so are G53's and G52's X. An offset
//!   the machine does not give is zero, so that a program runs in its own
//!   coordinates.
//! - G53 moves at rapid whatever motion mode is in force (OQ-5; External:
//!   Haas moves G53 blocks at rapid); its U and W count from the position
//!   as elsewhere.
//! - G52 X/Z set the shift, U/W add to it (OQ-31 leaves U/W open); the
//!   shift holds under every work offset until `G52 X0 Z0`.
//! - G28 moves at rapid to the intermediate point its X/Z (U/W) give, in
//!   the program's coordinates, then to the reference point, on the axes it
//!   names; `G28` alone names both (External: Haas, OQ-20), and a bare
//!   letter (`G28 X Z`, 001:91) names its axis without an intermediate
//!   point (Fanuc/Haas convention for the rest, External).
//! - G29 moves at rapid on the axes it names to the intermediate point of
//!   the last G28, then to its own X/Z, U/W counting from the intermediate
//!   point (Fanuc, External). Without a G28 before it, it goes straight
//!   there.
//! - G10 writes work offsets as Haas and Fanuc controls do (External; the
//!   manual prints only the format, 001:74, OQ-17): `L2 P1`–`P6` the offsets
//!   G54–G59, `L20 P1`–`P20` G110–G129; X and Z set the offset's value, U
//!   and W add to it, X a diameter as in the table. The value holds for the
//!   rest of the run, and at once when the offset is in force. G10's other
//!   pages (the tool offsets of L1, L10, L11, the shift of L2 P0) are not
//!   run.

use super::{Interpreter, Moved, STILL};
use crate::{
    haas_lathe::{
        cycles::{Move, Point},
        lower::HaasBlock,
    },
    machine::MachineConfig,
    trace::{Motion, Path, Position, slot},
    transform::{Frame, over_axes},
};
use ncc_syntax::TextRange;

/// The catalogue's group of the work offsets.
const WORK_OFFSET: &str = "G12";

/// What the coordinates keep between blocks.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Coordinates {
    /// G52's shift (Z, X radius).
    local: Point,
    /// Machine minus program coordinates (Z, X radius) in force.
    pub(super) translation: Point,
    /// The last G28's intermediate point in machine coordinates, per axis
    /// it named (Z, X radius).
    via: [Option<f64>; 2],
    /// The work offsets G10 wrote, by G code (Z, X radius), over the
    /// machine's table.
    written: Vec<(u8, Point)>,
}

/// The work offset G10 `L` `P` writes, by its G code.
fn written_offset(page: u32, number: u32) -> Option<u8> {
    let code = match (page, number) {
        (2, 1..=6) => 53 + number,
        (20, 1..=20) => 109 + number,
        _ => return None,
    };
    u8::try_from(code).ok()
}

/// Machine minus program coordinates (Z, X radius) under the work offset
/// `G<code>` of `machine`'s table.
fn work_offset(machine: &MachineConfig, code: u8) -> Point {
    let row = machine.offsets.offset(code);
    let axis = |letter| machine.step_axes().iter().position(|&axis| axis == letter).map_or(0.0, |i| f64::from(row[i]));
    [axis(b'Z') / 1000.0, axis(b'X') / 2000.0]
}

/// A frame of translation `[z, x]`.
fn frame(machine: &MachineConfig, [z, x]: Point) -> Frame {
    let mut translation: Position = [0.0; 26];
    (translation[slot(b'Z')], translation[slot(b'X')]) = (z, x);
    Frame { translation: over_axes(&translation, machine.step_axes()), transformations: Vec::new() }
}

/// The frame a run starts in: the work offset G54.
pub(crate) fn reset_frame(machine: &MachineConfig) -> Frame {
    frame(machine, work_offset(machine, 54))
}

impl Interpreter<'_> {
    /// The run's first frame, the tool at the machine zero.
    pub(super) fn start_coordinates(&mut self) {
        self.coordinates.translation = work_offset(&self.machine, 54);
        let [z, x] = self.coordinates.translation;
        // 0 - 0 is 0, where -0 would print as -0.
        (self.position[slot(b'Z')], self.position[slot(b'X')]) = (0.0 - z, 0.0 - x);
        self.frames = vec![frame(&self.machine, [z, x])];
    }

    /// Puts in force the frame of the work offset and G52 in force: the
    /// tool stays where it is, its program position changes.
    pub(super) fn update_frame(&mut self) {
        let code = self.modes.get(WORK_OFFSET).and_then(|code| u8::try_from(code).ok()).unwrap_or(54);
        let [z, x] = self.work_offset(code);
        let translation = [z + self.coordinates.local[0], x + self.coordinates.local[1]];
        let before = std::mem::replace(&mut self.coordinates.translation, translation);
        if before == translation {
            return;
        }
        self.position[slot(b'Z')] += before[0] - translation[0];
        self.position[slot(b'X')] += before[1] - translation[1];
        self.frame = self.frame_of(translation);
    }

    /// The work offset `G<code>`: as G10 wrote it, else the machine's.
    fn work_offset(&self, code: u8) -> Point {
        let written = self.coordinates.written.iter().find(|(written, _)| *written == code);
        written.map_or_else(|| work_offset(&self.machine, code), |&(_, offset)| offset)
    }

    /// G10: writes the work offset its L and P name.
    fn write_offset(&mut self, block: &HaasBlock, range: TextRange) {
        let whole = |interpreter: &mut Self, letter| {
            block.word(letter).and_then(|word| interpreter.number(word, range)).map(|value| value as u32)
        };
        let (page, number) = (whole(self, b'L'), whole(self, b'P'));
        let Some(code) = page.zip(number).and_then(|(page, number)| written_offset(page, number)) else {
            let page = page.map_or_else(String::new, |page| format!(" L{page}"));
            self.not_run(&format!("G10{page} (only the work offsets of L2 P1-P6 and L20 P1-P20 are written)"), range);
            return;
        };
        let [z, x] = self.work_offset(code);
        let mut offset: Position = [0.0; 26];
        (offset[slot(b'Z')], offset[slot(b'X')]) = (z, x);
        if let Some(end) = self.end_point(block, range, &offset) {
            let value = [end[slot(b'Z')], end[slot(b'X')]];
            self.coordinates.written.retain(|(written, _)| *written != code);
            self.coordinates.written.push((code, value));
            self.update_frame();
        }
    }

    /// The index of the frame of `translation`, added when new.
    pub(super) fn frame_of(&mut self, translation: Point) -> usize {
        let frame = frame(&self.machine, translation);
        match self.frames.iter().position(|known| *known == frame) {
            Some(index) => index,
            None => {
                self.frames.push(frame);
                self.frames.len() - 1
            }
        }
    }

    /// `position` in machine coordinates.
    pub(super) fn in_machine(&self, position: &Position) -> Position {
        let mut machine = *position;
        machine[slot(b'Z')] += self.coordinates.translation[0];
        machine[slot(b'X')] += self.coordinates.translation[1];
        machine
    }

    /// A block of G10, G28, G29, G52 or G53: its words are no ordinary
    /// move.
    pub(super) fn coordinates(&mut self, code: u32, block: &HaasBlock, range: TextRange) -> Moved {
        match code {
            10 => {
                self.write_offset(block, range);
                STILL
            }
            52 => {
                let mut shift: Position = [0.0; 26];
                (shift[slot(b'Z')], shift[slot(b'X')]) = (self.coordinates.local[0], self.coordinates.local[1]);
                if let Some(end) = self.end_point(block, range, &shift) {
                    self.coordinates.local = [end[slot(b'Z')], end[slot(b'X')]];
                    self.update_frame();
                }
                STILL
            }
            53 => self.machine_move(block, range),
            _ => self.reference_return(code, block, range),
        }
    }

    /// G53: a rapid move to the block's X/Z in machine coordinates.
    fn machine_move(&mut self, block: &HaasBlock, range: TextRange) -> Moved {
        let start = self.in_machine(&self.position);
        let Some(end) = self.end_point(block, range, &start) else { return STILL };
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let (from, to) = ([start[z], start[x]], [end[z], end[x]]);
        let [tz, tx] = self.coordinates.translation;
        (self.position[z], self.position[x]) = (end[z] - tz, end[x] - tx);
        let length = (to[0] - from[0]).hypot(to[1] - from[1]);
        Moved {
            motion: Motion::Rapid,
            path: Path::Straight,
            length,
            duration: self.rapid_seconds(from, to),
            feed: None,
        }
    }

    /// G28 or G29 on the axes the block names (Z, X).
    fn reference_return(&mut self, code: u32, block: &HaasBlock, range: TextRange) -> Moved {
        let names = |absolute, incremental| block.word(absolute).is_some() || block.word(incremental).is_some();
        let mut named = [names(b'Z', b'W'), names(b'X', b'U')];
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let translation = self.coordinates.translation;
        let position = self.position;
        let here = [position[z], position[x]];
        let moves = if code == 28 {
            if named == [false; 2] {
                named = [true; 2];
            }
            let via = self.end_point(block, range, &position).unwrap_or(position);
            let via = [via[z], via[x]];
            let mut reference = here;
            for axis in 0..2 {
                if named[axis] {
                    self.coordinates.via[axis] = Some(via[axis] + translation[axis]);
                    reference[axis] = 0.0 - translation[axis];
                }
            }
            [Move::Rapid(via), Move::Rapid(reference)]
        } else {
            let mut via = position;
            for (axis, letter) in [b'Z', b'X'].into_iter().enumerate() {
                if let Some(machine) = self.coordinates.via[axis].filter(|_| named[axis]) {
                    via[slot(letter)] = machine - translation[axis];
                }
            }
            let target = self.end_point(block, range, &via).unwrap_or(position);
            [Move::Rapid([via[z], via[x]]), Move::Rapid([target[z], target[x]])]
        };
        self.emit(range, Ok(moves.to_vec()))
    }
}
