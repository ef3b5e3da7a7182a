//! The executor of partprograms: it runs them on a model of the control
//! and produces a printable trace with the predicted cycle time. The
//! analysis calls into it (the arithmetic, the lowering), never the other
//! way round.
//!
//! - [`arc`]: circular arcs from their ends and centre, for the runner and
//!   the checker alike.
//! - [`cnc8x6`]: what belongs to the CNC8x6 dialect, to become its own
//!   crate: [`cnc8x6::lower`] (blocks as plain data, read from the syntax
//!   tree; the analysis uses it too), [`cnc8x6::arith`] (the
//!   parameter-arithmetic evaluator of G26–G29, over partly unknown values,
//!   so the checker uses it as well), [`cnc8x6::formats`] (what the control
//!   refuses in a value), [`cnc8x6::modes`] (the code in force of every G
//!   and M group), [`cnc8x6::program_flow`] (which block runs after a block,
//!   for the runner and the checker's flow walk alike), [`cnc8x6::cycles`]
//!   (the built-in fixed cycles G81–G89), [`cnc8x6::tables`] (zero offsets
//!   and tool corrections in the control's files) and [`cnc8x6::expand`]
//!   (a run written back as a program of plain motion blocks).
//! - [`compensation`]: the tool-centre path of radius compensation G41/G42
//!   (equidistants, corners, start and cancel), for the runner to drive.
//! - [`envelope`]: the CNC8x9 envelope velocity, a streaming look-ahead
//!   planner of up to 500 blocks with linear or jerk-limited ramps.
//! - [`machine`]: the machine a program runs on (axes, rates, limits,
//!   constants).
//! - [`run`]: running a program block by block into a [`run::Trace`]: the
//!   trace's vocabulary, the run driver with its checkpoints, the block
//!   index and the interpreter.
//! - [`tool_path`]: the moves and positions of the tool centre, which
//!   radius compensation moves off the programmed contour.
//! - [`transform`]: the coordinate recalculations G34–G37 and the
//!   transformations G38/G39/G31, and the frames from program to machine
//!   coordinates they make.

pub mod arc;
pub mod cnc8x6;
pub(crate) mod compensation;
pub(crate) mod envelope;
pub mod machine;
pub mod run;
pub mod tool_path;
pub(crate) mod transform;
pub mod velocity;
