//! The interpreter's smaller pieces: the machine the arithmetic reads and
//! writes, the groups it keeps, feeds, arcs and rounding.

use nalgebra::Vector2;
use ncc_syntax::TextRange;

use crate::{
    cnc8x6::arith::{Machine, Parameters, Raw},
    cnc8x6::lower::{BlockData, Word},
    cnc8x6::modes::{Group, Modes},
    machine::MachineConfig,
    machine::{OffsetTable, ToolEntry, ToolTable},
    transform::{self, Frame},
};

use crate::trace::*;

/// What parameter arithmetic reads of the machine while a program runs:
/// the programmed positions (the measured ones are the machine
/// coordinates, as the run has no following error), the machine constants,
/// and the zero-offset and correction tables, which it may write.
///
/// The manual numbers the tables' columns without naming them; the run
/// reads an offset's column k as axis k, and a correction's column 1 as the
/// radius and columns 2–7 as the lengths of axes 1–6, in thousandths.
pub(super) struct ProgramMachine<'r> {
    pub(super) machine: &'r MachineConfig,
    pub(super) position: &'r Position,
    pub(super) frame: &'r Frame,
    pub(super) offsets: &'r mut OffsetTable,
    pub(super) corrections: &'r mut ToolTable,
    pub(super) messages: &'r mut Vec<OperatorMessage>,
    /// The step of the block whose arithmetic runs.
    pub(super) step: usize,
    pub(super) registers: Registers<'r>,
}

/// What the block registers BWRK and AWRK (op 49 tables 4 and 5) hold of
/// the block that runs. The manual names their columns (M and G functions
/// by group, P, H, S, T, Q, D) but not how the two registers differ; the
/// arithmetic runs after the block's own codes took effect, so the run
/// reads both as the state then. P, H and Q, which the run does not keep,
/// are unknown.
pub(super) struct Registers<'r> {
    pub(super) modes: &'r Modes,
    pub(super) speed: f64,
    pub(super) tool: Option<u32>,
    pub(super) correction: u8,
}

impl Registers<'_> {
    pub(super) fn read(&self, group: u16, column: usize) -> Option<Raw> {
        let code = |letter: char| self.modes.get(Group::numbered(letter, usize::from(group))?).map(Raw::from);
        match column {
            1 => code('M'),
            2 => code('G'),
            5 => Some(self.speed.round() as Raw),
            6 => self.tool.map(Raw::from),
            8 => Some(Raw::from(self.correction)),
            _ => None,
        }
    }
}

impl ProgramMachine<'_> {
    fn axis_slot(&self, axis: u8) -> Option<usize> {
        Some(slot(*self.machine.axes.get(usize::from(axis).checked_sub(1)?)?))
    }
}

impl Machine for ProgramMachine<'_> {
    fn measured_position(&self, axis: u8) -> Option<Raw> {
        let index = usize::from(axis).checked_sub(1).filter(|&index| index < self.machine.axes.len())?;
        let axes = &self.machine.axes;
        let measured = self.frame.to_machine(&transform::over_axes(self.position, axes), axes);
        Some((measured.get(index)? * 1000.0).round() as Raw)
    }

    fn programmed_position(&self, axis: u8) -> Option<Raw> {
        Some((self.position[self.axis_slot(axis)?] * 1000.0).round() as Raw)
    }

    fn read_table(&self, table: u8, row: u16, column: u16) -> Option<Raw> {
        let column = usize::from(column);
        match table {
            1 => datum(&mut self.corrections.entry(u8::try_from(row).ok()?), column).map(|datum| Raw::from(*datum)),
            2 => {
                let row = u8::try_from(row).ok().filter(|row| (53..=59).contains(row))?;
                column.checked_sub(1).and_then(|axis| self.offsets.offset(row).get(axis).copied()).map(Raw::from)
            }
            3 => self.machine.known_constant(u32::from(row)),
            4 | 5 => self.registers.read(row, column),
            _ => None,
        }
    }

    fn write_table(&mut self, table: u8, row: u16, column: u16, value: Raw) {
        let (Ok(row), Ok(value), column) = (u8::try_from(row), i32::try_from(value), usize::from(column)) else {
            return;
        };
        match table {
            1 => {
                let mut entry = self.corrections.entry(row);
                if let Some(datum) = datum(&mut entry, column) {
                    *datum = value;
                    self.corrections.entries.insert(row, entry);
                }
            }
            2 if (53..=59).contains(&row) && (1..=6).contains(&column) => {
                let mut values = self.offsets.offset(row);
                values[column - 1] = value;
                self.offsets.rows.insert(row, values);
            }
            _ => {}
        }
    }

    fn message(&mut self, message: Message) {
        self.messages.push(OperatorMessage { step: self.step, message });
    }
}

/// Column `column` of a correction entry: 1 the radius, 2–7 the lengths of
/// axes 1–6.
pub(super) fn datum(entry: &mut ToolEntry, column: usize) -> Option<&mut i32> {
    match column {
        1 => Some(&mut entry.radius),
        2..=7 => entry.lengths.get_mut(column - 2),
        _ => None,
    }
}

/// What else a block does besides its motion, as its step records it.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Functions {
    pub(super) m_functions: u8,
    pub(super) tool_change: bool,
    pub(super) mergeable: bool,
}

/// Minutes a thread of `length` mm takes: the lead per revolution at
/// `speed` rpm, after waiting for the spindle's zero pulse, on average half
/// a revolution (01 §6.10).
pub(super) fn thread_minutes(length: f64, lead: f64, speed: f64) -> f64 {
    length / (lead * speed) + 0.5 / speed
}

/// What a block's move did.
pub(super) struct Moved {
    pub(super) motion: Motion,
    pub(super) length: f64,
    pub(super) duration: f64,
    pub(super) feed: Option<f64>,
    pub(super) path: Path,
}

pub(super) fn distance(start: &Position, end: &Position) -> f64 {
    (0..26).map(|i| (end[i] - start[i]).powi(2)).sum::<f64>().sqrt()
}

/// The state a fixed cycle of the cycle file restores when it returns.
pub(super) struct Snapshot {
    pub(super) modes: Modes,
    pub(super) feed: Option<ProgrammedFeed>,
    pub(super) speed: f64,
    pub(super) speed_limit: Option<f64>,
    pub(super) diameter: bool,
    pub(super) params: Parameters,
}

/// F as written: `value` without a decimal point is mm/min or µm/rev,
/// with one m/min or mm/rev (01 §6.6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ProgrammedFeed {
    pub(super) value: f64,
    pub(super) point: bool,
}

impl ProgrammedFeed {
    /// mm/rev when `per_revolution`, else mm/min.
    pub(super) fn value(self, per_revolution: bool) -> f64 {
        match (self.point, per_revolution) {
            (false, false) | (true, true) => self.value,
            (true, false) => self.value * 1000.0,
            (false, true) => self.value / 1000.0,
        }
    }
}

/// How F is read and the spindle turns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct FeedMode {
    /// F is per revolution (mm/rev) instead of per minute.
    pub(super) per_revolution: bool,
    /// Constant cutting speed: S is a cutting speed, the spindle follows
    /// the controlling coordinate.
    pub(super) css: bool,
}

/// The largest spindle speed S can program, the limit of constant cutting
/// speed without `G76` (the gear ranges' maxima are not configured).
pub(super) const MAX_SPINDLE_SPEED: f64 = 9999.0;

/// An arc in the plane of axes (`a`, `b`) by slot, with a helix's lead.
pub(super) struct Arc {
    pub(super) plane: (usize, usize),
    pub(super) centre: Vector2<f64>,
    pub(super) radius: f64,
    pub(super) start_angle: f64,
    /// Radians, positive counter-clockwise.
    pub(super) sweep: f64,
    /// The travel of the other axes written, in mm.
    pub(super) lead: f64,
}

impl Arc {
    pub(super) fn length(&self) -> f64 {
        (self.radius * self.sweep).hypot(self.lead)
    }

    /// The points where the arc runs furthest along its plane's axes (at
    /// 0°, 90°, 180° and 270°) between its ends, the other axes at `end`.
    pub(super) fn sides<'a>(&'a self, end: &'a Position) -> impl Iterator<Item = Position> + 'a {
        (0..4).filter_map(move |quarter| {
            let angle = f64::from(quarter) * std::f64::consts::FRAC_PI_2;
            let turned = if self.sweep > 0.0 { angle - self.start_angle } else { self.start_angle - angle };
            (turned.rem_euclid(std::f64::consts::TAU) < self.sweep.abs()).then(|| {
                let mut side = *end;
                side[self.plane.0] = round3(self.centre.x + self.radius * angle.cos());
                side[self.plane.1] = round3(self.centre.y + self.radius * angle.sin());
                side
            })
        })
    }

    /// The coordinate of slot `slot` at fraction `t` of the arc, when the
    /// slot is one of the plane's.
    pub(super) fn coordinate(&self, slot: usize, t: f64) -> Option<f64> {
        let angle = self.start_angle + t * self.sweep;
        match slot {
            _ if slot == self.plane.0 => Some(self.centre.x + self.radius * angle.cos()),
            _ if slot == self.plane.1 => Some(self.centre.y + self.radius * angle.sin()),
            _ => None,
        }
    }
}

/// A block's move from `start` to `end`, by the axis words `axes`.
#[derive(Clone, Copy)]
pub(super) struct Move<'b> {
    pub(super) block: &'b BlockData,
    pub(super) range: TextRange,
    pub(super) axes: &'b [&'b Word],
    pub(super) start: Position,
    pub(super) end: Position,
}

/// Positions lie on the µm grid; half of one keeps float noise off the
/// bounds of the axes' ranges.
pub(super) const HALF_MICROMETRE: f64 = 0.0005;
