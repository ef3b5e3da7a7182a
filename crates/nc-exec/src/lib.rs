//! The executor of partprograms: it runs them on a model of the control
//! and produces a printable trace with the predicted cycle time. The
//! analysis calls into it (the arithmetic, the lowering), never the other
//! way round.
//!
//! Neutral modules know no code number; each dialect's module owns its
//! language from lowering to steps, and the run driver picks the
//! interpreter of the machine's control. The modules depend on each other
//! without a cycle: a dialect uses the neutral modules, never the other
//! way round, but for the one match in [`run`] that picks the interpreter.
//!
//! - [`arc`]: circular arcs from their ends and centre, for the runner and
//!   the checker alike.
//! - `axes`: positions by axis letter and over the machine's axes.
//! - [`cnc8x6`]: what belongs to the CNC8x6 dialect, to become its own
//!   crate: [`cnc8x6::lower`] (blocks as plain data, read from the syntax
//!   tree; the analysis uses it too), [`cnc8x6::arith`] (the
//!   parameter-arithmetic evaluator of G26–G29, over partly unknown values,
//!   so the checker uses it as well), [`cnc8x6::formats`] (what the control
//!   refuses in a value), [`cnc8x6::modes`] (the code in force of every G
//!   and M group), [`cnc8x6::program_flow`] (which block runs after a block,
//!   for the runner and the checker's flow walk alike), [`cnc8x6::cycles`]
//!   (the built-in fixed cycles G81–G89), [`cnc8x6::tables`] (zero offsets
//!   and tool corrections in the control's files), `cnc8x6::interpreter`
//!   (the control's state, motion and time block by block, with its block
//!   index and program flow), [`cnc8x6::dynamics`] (the velocity and
//!   compensation settings from the machine constants) and
//!   [`cnc8x6::expand`] (a run written back as a program of plain motion
//!   blocks).
//! - [`compensation`]: the tool-centre path of radius compensation G41/G42
//!   (equidistants, corners, start and cancel), for the runner to drive.
//! - [`haas_lathe`]: what belongs to the Haas lathe dialect:
//!   [`haas_lathe::lower`] (blocks as plain data, read from the syntax
//!   tree), [`haas_lathe::eval`] (macro expressions over partly unknown
//!   variables), [`haas_lathe::program`] (the programs of a file, their
//!   block numbers, the P/Q contours of G70–G73 and the targets of calls
//!   and jumps), [`haas_lathe::cycles`] and [`haas_lathe::roughing`] (the
//!   canned cycles as moves), [`haas_lathe::interpreter`] (the modal
//!   state, motion, cycles, macro statements and time of a program, block
//!   by block, which [`run`] runs on a Haas machine),
//!   [`haas_lathe::dynamics`] (its velocity policy) and
//!   [`haas_lathe::expand`] (a run written back as plain lathe blocks).
//! - [`expand`]: what the writers of expanded programs share, and the
//!   [`expand::Expand`] interface the command line drives them by.
//! - [`envelope`]: the CNC8x9 envelope velocity, a streaming look-ahead
//!   planner of up to 500 blocks with linear or jerk-limited ramps.
//! - `green`: reading the parsers' green trees, for every dialect's lowering.
//! - [`known`]: values a static reading may not know.
//! - [`lowered`]: a file's lowered blocks in chunks, which the editor's
//!   analysis and a run share.
//! - [`machine`]: the machine a program runs on (its control, axes, rates,
//!   limits, constants and tables).
//! - `ramp`: how fast the path speed may change (acceleration and jerk:
//!   linear ramps or S-curves), for both velocity planners.
//! - [`run`]: running a program on its machine into a [`run::Trace`] or a
//!   sink, on a thread of its own or this one, from a checkpoint or the
//!   start.
//! - [`sinumerik`]: what belongs to the Siemens Sinumerik dialect:
//!   [`sinumerik::lower`] (blocks as plain data, read from the syntax tree
//!   and the catalogue), [`sinumerik::program`] (labels, block numbers,
//!   control structures, declarations, jumps and calls of a file),
//!   [`sinumerik::eval`] (typed values, variables and expressions),
//!   [`sinumerik::frames`] (the programmable frame TRANS … AMIRROR),
//!   [`sinumerik::cycles`] (the drilling cycles CYCLE81–CYCLE89 as moves,
//!   the swivel CYCLE800 as a frame), [`sinumerik::dynamics`] (its
//!   velocity policy, and the modes G60, G64x, SOFT and BRISK a run keeps)
//!   and `sinumerik::interpreter` (the control flow, calls, files, motion,
//!   frames, cycles, splines and time of a program, which [`run`] runs on a
//!   Sinumerik machine).
//! - [`spline`]: rational B-spline curves (NURBS) over any axes, built
//!   from the data a control programs them by: points, derivatives,
//!   curvature, length, polylines within a chord tolerance.
//! - [`trace`]: what a run produces and how it hands it on: steps,
//!   findings and their rules, the sink and the checkpoints.
//! - [`tool_path`]: the moves and positions of the tool centre, which
//!   radius compensation moves off the programmed contour.
//! - [`transform`]: the coordinate recalculations G34–G37 and the
//!   transformations G38/G39/G31, and the frames from program to machine
//!   coordinates they make.

pub mod arc;
pub(crate) mod axes;
pub mod cnc8x6;
pub(crate) mod compensation;
pub(crate) mod compensation_driver;
pub(crate) mod envelope;
pub mod expand;
pub(crate) mod green;
pub mod haas_lathe;
pub mod known;
pub mod lowered;
pub mod machine;
pub(crate) mod ramp;
pub mod run;
pub mod sinumerik;
pub mod spline;
pub mod tool_path;
pub(crate) mod trace;
pub(crate) mod transform;
pub mod velocity;
