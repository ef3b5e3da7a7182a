//! The executor of partprograms: it runs them on a model of the control
//! and produces a printable trace with the predicted cycle time. The
//! analysis calls into it (the arithmetic, the lowering), never the other
//! way round.
//!
//! - [`arith`]: the parameter-arithmetic evaluator of G26–G29 (control words
//!   in R5–R8, operations 0–51), and a block's assignments and arithmetic.
//!   It works on partly unknown parameters, so the static analysis uses it
//!   as well.
//! - [`compensation`]: the tool-centre path of radius compensation G41/G42
//!   (equidistants, corners, start and cancel), for the runner to drive.
//! - [`cycles`]: the built-in fixed cycles G81–G89 (milling and lathe), as
//!   lists of moves for the runner, when the machine loads no cycle file.
//! - [`envelope`]: the CNC8x9 envelope velocity, a streaming look-ahead
//!   planner of up to 500 blocks with linear or jerk-limited ramps.
//! - [`expand`]: a run written back as a program of plain motion blocks.
//! - [`formats`]: what the control refuses in a value, by its address's
//!   format; the checker words its findings with it too.
//! - [`lower`]: blocks as plain data (words, parameter assignments,
//!   comments), read from the syntax tree; the analysis uses it too.
//! - [`machine`]: the machine a program runs on (axes, rates, limits,
//!   constants), and [`tables`]: its zero offsets and tool corrections with
//!   readers for the control's files.
//! - [`modes`]: the active code of every G and M group.
//! - [`program_flow`]: which block runs after a block (calls, jumps,
//!   returns), for the runner and the checker's flow walk alike.
//! - [`run`]: running a program block by block into a [`run::Trace`].
//! - [`tool_path`]: the moves and positions of the tool centre, which
//!   radius compensation moves off the programmed contour.
//! - [`transform`]: the coordinate recalculations G34–G37 and the
//!   transformations G38/G39/G31, and the frames from program to machine
//!   coordinates they make.

pub mod arith;
pub mod compensation;
pub mod cycles;
pub mod envelope;
pub mod expand;
pub mod formats;
pub mod lower;
pub mod machine;
pub mod modes;
pub mod program_flow;
pub mod run;
pub mod tables;
pub mod tool_path;
pub mod transform;
pub mod velocity;
