//! Running a CNC8x6 program: the modal state, motion and time, block by
//! block, in the order the control runs them.
//!
//! What runs:
//! - The program's flow: subprogram calls G71 L Q and macrocycle files
//!   G72 L Q with their repetitions, jumps G73 L Q that run a section Q+1
//!   times, codes from parameters (`GR20`: 73 jumps, 78 does nothing), G04
//!   taking Q from a call in its block, M00/M01 stops, M02/M30, and a step
//!   budget against endless loops.
//! - Motion: G00, G01, arcs and helices G02/G03 (the centre from I/J/K, the
//!   plane from the two axes written, 01 §6.4; the helix's lead from G10
//!   under G09, 02 §4), threads G33, G90/G91.
//! - Feed and spindle: the modal machine of every group ([`Modes`](crate::cnc8x6::modes::Modes)), F
//!   with its decimal-point rules per minute or per revolution and M37's
//!   1 : 100, S, constant cutting speed G96/G97 with the G76 limit, dwell
//!   (G04 Q, in 10 ms, after the block's motion).
//! - Parameters: assignments and arithmetic G26–G29 take effect after the
//!   block's motion, which reads the values from before them.
//! - Fixed cycles G81–G89 after the block's motion until G80: the bodies of
//!   the machine's cycle file with the state restored afterwards, or the
//!   built-in cycles ([`crate::cnc8x6::cycles`]).
//!
//! - Offsets: zero offsets G53–G59 with G92/G93, length corrections D/&,
//!   and radius compensation G41/G42 ([`crate::compensation`]).
//!
//! - Coordinates: diameter programming G74/G75 on the machine's diameter
//!   axis (positions are radii), the recalculations G34–G37 and the
//!   transformations G38/G39/G31 ([`crate::transform`]).
//!
//! Where the control stops on an error, the run stops with a fatal
//! [`Finding`]: a value its address cannot take ([`crate::cnc8x6::formats`]), a
//! position beyond an axis's range or the machine's travel limits, an arc
//! end point off its circle, a call, jump, cycle or arithmetic that cannot
//! run.
//!
//! A block's time is its path length over its feed (G00: the slowest axis
//! at its own rapid rate), plus dwells; ramps and block joining are the
//! velocity model's business. Everything else the control does is reported
//! once per kind as not run yet (copying G05–G07, axis slaving G08, the
//! reference point G30), so that a total never silently leaves something
//! out.

mod driver;
mod index;
mod rules;
mod runner;
mod support;
mod trace;

pub(crate) use self::support::{round3, slot};
pub use self::{driver::*, index::expected_blocks, rules::RunRule, trace::*};

#[cfg(test)]
mod tests;
