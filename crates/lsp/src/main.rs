//! `ncc`: the command line of the CNC partprogram toolchain.

mod check;
mod excerpt;
mod explain;
mod fmt;
mod plot;
mod positions;
mod report;
mod rules;
mod run;
mod sarif;
mod server;

use std::{path::PathBuf, process::ExitCode};

use clap::{Parser, Subcommand};
use ncc_analysis::Dialect;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Gives the memory mimalloc holds free back to the system. mimalloc keeps
/// freed memory for later allocations and returns it only when it
/// allocates or frees again a while after: a server that goes idle after a
/// burst of work would hold on to its peak.
#[allow(unsafe_code)] // One call into mimalloc; nothing else.
pub(crate) fn return_free_memory() {
    // SAFETY: `mi_collect` takes nothing and touches only memory that no
    // allocation uses.
    unsafe { libmimalloc_sys::mi_collect(true) }
}

#[derive(Parser)]
#[command(
    name = "ncc",
    version,
    about = "Checker, language server and toolchain for CNC partprograms",
    long_about = "Checker, language server and toolchain for CNC partprograms.\n\n\
        A program's dialect is `--dialect`, else `dialect` in its project's ncc.toml, else what its \
        extension maps to ([extensions] in ncc.toml; by default *.NCP and macrocycle files L<n> are \
        cnc8x6 (MEFI CNC8x6), *.MPF and *.SPF sinumerik, *.nc and *.tap haas-lathe)."
)]
struct Cli {
    /// The dialect of every program read, whatever its name and project
    /// say: cnc8x6, haas-lathe or sinumerik.
    #[arg(long, global = true, value_name = "NAME")]
    dialect: Option<Dialect>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check partprograms and report every problem found.
    ///
    /// Directories are searched for partprograms (by default `*.NCP` and
    /// macrocycle files `L<number>`, `*.MPF`, `*.SPF`, `*.nc` and `*.tap`;
    /// see `[extensions]` in ncc.toml), honouring `.gitignore`. Exit status:
    /// 0 when no error or warning was found, 1 when one was, 2 when a path
    /// or an `ncc.toml` could not be read.
    Check {
        /// Files or directories to check.
        #[arg(default_value = ".")]
        paths: Vec<PathBuf>,
        /// Output format.
        #[arg(long, value_enum, default_value_t = check::Format::Human)]
        format: check::Format,
    },
    /// Format partprograms in place, in the style of `[format]` in their
    /// project's `ncc.toml`.
    ///
    /// Formatting never changes what a program does: by default it changes
    /// spacing only (one space between a block's items, comments kept in
    /// their column, trailing spaces removed); `[format]` can ask for
    /// upper-case letters, trimmed decimal numbers and the standard word
    /// order. Text next to a syntax error is left as written. Directories
    /// are searched as `ncc check` searches them. Exit status: 0 when done,
    /// 1 when `--check` or `--diff` found a file to reformat, 2 when a path
    /// or an `ncc.toml` could not be read or a file written.
    Fmt {
        /// Files or directories to format.
        #[arg(default_value = ".")]
        paths: Vec<PathBuf>,
        /// Change nothing; list the files formatting would change and exit
        /// with 1 if there are any (for pre-commit and CI).
        #[arg(long)]
        check: bool,
        /// Change nothing; print what formatting would change as a unified
        /// diff, and exit with 1 if it would change anything.
        #[arg(long)]
        diff: bool,
        /// Renumber the blocks START, START+STEP, … in file order, with
        /// every reference to them (jumps, contour P/Q, local calls), so the
        /// program does what it did; a file where a computed or missing
        /// target makes that unsafe is left as it is, with the reason.
        #[arg(long, value_name = "START,STEP")]
        renumber: Option<fmt::Renumber>,
    },
    /// Explain a code, address, parameter, machine constant, operation or
    /// the rule of a diagnostic's code.
    ///
    /// Examples: `G40`, `M30`, `X`, `&`, `R5` (program parameter), `R39`
    /// (machine constant 39, then parameter 39), `mc:39`, `param:39`,
    /// `op:48` (parameter-arithmetic operation), `group:G3`, `K105` (the
    /// rule of `ncc check`).
    Explain {
        /// What to explain.
        #[arg(required_unless_present = "list")]
        query: Option<String>,
        /// List everything the catalogue knows, with counts.
        #[arg(long, conflicts_with = "query")]
        list: bool,
    },
    /// List the rules of `ncc check` and of the executor: code, default
    /// severity, name.
    ///
    /// Names and codes are what `ncc.toml` and `ncc:ignore` comments use.
    Rules {
        /// Show only the rule with this code, or rules whose name contains it.
        query: Option<String>,
        /// Print a Markdown reference, grouped by kind (what docs/rules.md holds).
        #[arg(long, conflicts_with = "query")]
        markdown: bool,
    },
    /// Serve the Language Server Protocol over stdin and stdout.
    ///
    /// For editors: diagnostics, hover, go to definition and the rest of
    /// what `ncc check` and `ncc explain` know, while typing.
    Lsp {
        /// How much to log to stderr.
        #[arg(long, value_enum, default_value_t = server::LogLevel::Warn)]
        log_level: server::LogLevel,
        /// Print the version and exit.
        #[arg(long)]
        version: bool,
    },
    /// Run a program on the executor and print what the machine would do.
    ///
    /// The summary splits the time into cutting, rapid and dwell, with the
    /// path lengths, the tools used and the end position. Times follow the
    /// control's velocity model (ramps, block joining G98/G24/G23, R39
    /// corners, one block of look-ahead, the arc limit); the summary lists
    /// the breaks where the path speed drops and what they cost. The
    /// executor runs motion, threads, feed units, constant cutting speed,
    /// dwell, parameters and their arithmetic, subprograms, macrocycle
    /// files, jumps and fixed cycles; anything else it names as not run yet.
    /// Exit status 1 when the run stopped on an error.
    Run {
        /// The program to run.
        file: PathBuf,
        /// Output format: `json` adds a record per block and every break.
        #[arg(long, value_enum, default_value_t = run::Format::Human)]
        format: run::Format,
        /// Stop after running this many blocks (a jump loop that never
        /// ends, runaway calls).
        #[arg(long, default_value_t = nc_exec::run::DEFAULT_STEP_BUDGET)]
        step_budget: usize,
        /// Where the files the program writes go (Sinumerik WRITE): the
        /// control's path below this directory, created when the program
        /// writes one (`/_N_MPF_DIR/_N_PART_SPF` is `MPF/PART.SPF`).
        #[arg(long, default_value = "ncc-written")]
        write_dir: PathBuf,
    },
    /// Draw the toolpath as an SVG picture: XY (ZX on a lathe), or a mill's
    /// three axes in an isometric view; feed moves coloured by the speed of
    /// the velocity model, rapid moves dashed, the breaks of the path speed
    /// marked, the programmed contour beside the tool centre under radius
    /// compensation, a grid with a scale in mm, fitted to the cutting moves,
    /// with a legend, the part's extent and the total time.
    Plot {
        /// The program to draw.
        file: PathBuf,
        /// The SVG file to write; a name ending in `.png` writes the picture
        /// as a PNG image instead, for reports.
        #[arg(short, long)]
        output: PathBuf,
        /// Stop after running this many blocks.
        #[arg(long, default_value_t = nc_exec::run::DEFAULT_STEP_BUDGET)]
        step_budget: usize,
        /// Draw at most the first this many moves (the time and the breaks
        /// in the legend stay the whole run's).
        #[arg(long, default_value_t = plot::DEFAULT_MAX_MOVES)]
        max_moves: usize,
        /// On a lathe: `diameter` draws the whole profile, mirrored about
        /// the spindle axis, with X labelled as the program's diameters;
        /// `radius` draws the machined half with X labelled as radii. On a
        /// mill: `top` (or the default) draws the plane, `iso` the three
        /// axes in an isometric view, in the box of the part's extent with
        /// its heights labelled.
        #[arg(long, value_enum, default_value_t = plot::View::Diameter)]
        view: plot::View,
    },
    /// Write a program as the moves it runs: plain numbered blocks with
    /// calls, jumps, cycles and parameters resolved.
    ///
    /// The output is a CNC8x6 program (G90, G94, F in mm/min) that runs the
    /// same moves; findings of the run go to stderr, and the exit status is
    /// 1 when the run stopped on an error.
    Expand {
        /// The program to expand.
        file: PathBuf,
        /// Write the program here instead of to stdout.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Stop after running this many blocks.
        #[arg(long, default_value_t = nc_exec::run::DEFAULT_STEP_BUDGET)]
        step_budget: usize,
    },
    /// Print the blocks as the executor reads them, one per line with its
    /// line number: the lowered form, without comments and layout (see
    /// docs/ir.md).
    Lower {
        /// The program to lower.
        file: PathBuf,
    },
    /// Print the syntax tree of a partprogram (a debugging aid).
    Parse {
        /// The program to parse.
        file: PathBuf,
    },
}

fn main() -> ExitCode {
    let Cli { dialect, command } = Cli::parse();
    match command {
        Command::Check { paths, format } => check::run(&paths, format, dialect),
        Command::Fmt { paths, check, diff, renumber } => {
            let mode = if diff {
                fmt::Mode::Diff
            } else if check {
                fmt::Mode::Check
            } else {
                fmt::Mode::Write
            };
            fmt::run(&paths, mode, renumber, dialect)
        }
        Command::Explain { query, list } => explain::run(query.as_deref(), list, dialect),
        Command::Rules { query, markdown } => rules::run(query.as_deref(), markdown),
        Command::Lsp { version: true, .. } => {
            println!("ncc {}", env!("CARGO_PKG_VERSION"));
            ExitCode::SUCCESS
        }
        Command::Lsp { log_level, .. } => server::run(log_level, dialect),
        Command::Run { file, format, step_budget, write_dir } => {
            run::run(&file, dialect, format, step_budget, &write_dir)
        }
        Command::Expand { file, output, step_budget } => run::expand(&file, dialect, output.as_deref(), step_budget),
        Command::Lower { file } => run::lower(&file, dialect),
        Command::Plot { file, output, step_budget, max_moves, view } => {
            run::plot(&file, dialect, &output, step_budget, max_moves, view)
        }
        Command::Parse { file } => run::parse(&file, dialect),
    }
}
