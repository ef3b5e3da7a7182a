//! `ncc run FILE`: runs a program on the executor, times it with the
//! velocity model and prints what the machine would do: the time split
//! into cutting, rapid and dwell, the path lengths, the tools, the end
//! position and the breaks of the path speed; `--format json` adds a
//! record per block and every break. `ncc expand`, `ncc plot` and
//! `ncc lower` share the run, and so does the language server's `ncc.plot`
//! command, which runs an editor's text ([`Program`]) and draws it with
//! [`Ran::plotted`] as `ncc plot` does. Positions are the tool centre's,
//! which radius compensation moves off the programmed contour.

use std::{
    cell::{OnceCell, RefCell},
    fmt::Write as _,
    io::{self, IsTerminal, Write as _},
    path::{Path, PathBuf},
    process::ExitCode,
};

use indicatif::{ProgressBar, ProgressStyle};
use nc_exec::{
    cnc8x6::{self, lower::BlockData},
    expand::{Expand, ExpandError},
    haas_lathe,
    run::{
        Axes, Called, Environment, Message, MessageDisplay, Motion, Step, Stop, Tool, Totals, Trace, WrittenFile,
        expected_blocks,
    },
    sinumerik,
    velocity::{self, Dynamics, Timer, Timing, TimingSink},
};
use ncc_analysis::{Config, Dialect, Rule, Severity, Suppressions, WorkspaceFiles, clock};
use ncc_syntax::{BlockParser, Parse, TextSize, ast::AstNode, visible};
use serde::Serialize;

use crate::{
    check::{self, shown_path},
    plot::{Sketch, View},
    positions::{Columns, TextIndex},
};

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Format {
    Human,
    Json,
}

/// A program to run: its text, and where it comes from.
pub(crate) struct Program<'a> {
    /// Its file, beside which (and in whose project) the run finds the
    /// macrocycle files and the cycle file; `None` for a text that is no
    /// file (an editor's new document).
    pub path: Option<&'a Path>,
    /// What messages, `data-file` attributes and titles call it.
    pub name: String,
    /// The text to run: an editor's may differ from the file's.
    pub text: &'a str,
    /// The dialect it is read in.
    pub dialect: Dialect,
    /// The `ncc.toml` that applies, whose directory is the project.
    pub config: Option<&'a Path>,
    /// The files it calls as an editor has them; `None` reads them from
    /// disk.
    pub files: Option<&'a WorkspaceFiles>,
}

/// A program run on the machine of its project.
pub(crate) struct Ran {
    trace: Trace,
    /// The levels of the run's rules.
    config: Config,
    /// The machine's dynamics, for the velocity model.
    dynamics: Dynamics,
    sources: Vec<Source>,
}

impl Program<'_> {
    /// Its configuration: the machine, and the levels of the run's rules.
    fn config(&self) -> Result<Config, String> {
        Ok(self.config.map(check::load_config).transpose()?.unwrap_or_default().for_dialect(self.dialect))
    }
}

/// Reads the program at `path`; the error is the exit code after the
/// message is printed.
fn read(path: &Path) -> Result<String, ExitCode> {
    check::read_program(path).map_err(|error| {
        eprintln!("error: {}: {error}", shown_path(path));
        ExitCode::from(2)
    })
}

/// Runs `command` on the program at `path` with the `ncc.toml` found for
/// it; a program that cannot be read is exit status 2.
fn on_program(path: &Path, dialect: Option<Dialect>, command: impl FnOnce(&Program<'_>) -> ExitCode) -> ExitCode {
    let mut projects = check::Projects::default();
    let dialect = check::dialect_for(&mut projects, path, dialect);
    let text = match read(path) {
        Ok(text) => text,
        Err(code) => return code,
    };
    let config = projects.config_path(Some(path));
    command(&Program {
        path: Some(path),
        name: path.display().to_string(),
        text: &text,
        dialect,
        config: config.as_deref(),
        files: None,
    })
}

/// Prints a configuration error; the exit code says so.
fn config_error(error: String) -> ExitCode {
    eprintln!("error: {error}");
    ExitCode::from(2)
}

impl Ran {
    /// On stderr, one line each, as `ncc check --format short` writes them.
    fn print_findings(&self) {
        for finding in self.findings() {
            let (file, line, message) =
                (visible::escaped(finding.file), finding.line, visible::escaped(finding.message));
            eprintln!("{file}:{line}: {}[{}]: {message}", finding.severity.as_str(), finding.rule.code);
        }
    }

    /// Runs `program` on the machine its configuration describes. The
    /// error is a configuration that cannot be read; a program that stops
    /// on an error has its run up to there (see [`Ran::stop`]).
    pub(crate) fn of(program: &Program<'_>, step_budget: usize, progress: Progress) -> Result<Ran, String> {
        let config = program.config()?;
        Ok(Ran::run(program, &config, progress, |text, library| {
            nc_exec::run::run(text, library, &config.machine, step_budget)
        }))
    }

    /// Like [`Ran::of`], through the velocity model as the steps come,
    /// keeping only what the summary shows: the trace keeps no steps.
    fn tally(program: &Program<'_>, step_budget: usize, progress: Progress) -> Result<(Ran, Tally), String> {
        let config = program.config()?;
        let machine = &config.machine;
        let dynamics = nc_exec::run::dynamics(machine);
        let tally_with = |places: Places| {
            let timer = Timer::new(machine.step_axes(), &dynamics, Tally { places, ..Tally::default() });
            let mut timed = None;
            let ran = Ran::run(program, &config, progress, |text, library| {
                // The model runs beside the executor, on the other core.
                let (trace, timer) = nc_exec::run::run_beside(text, library, machine, step_budget, timer);
                timed = Some(timer.finish());
                trace
            });
            (ran, timed.unwrap_or_default())
        };
        let (ran, mut tally) = tally_with(Places::InOrder(Grouping::default()));
        if let Places::InOrder(grouping) = &mut tally.places {
            grouping.close_block();
            return Ok((ran, tally));
        }
        // A loop or a call came back to a block: the run again, keeping
        // every break to sort (breaks can come at every block: room
        // reserved and never touched costs nothing, growing copies).
        let (ran, mut tally) = tally_with(Places::Kept(Vec::with_capacity(expected_blocks(program.text))));
        if let Places::Kept(mut kept) = std::mem::replace(&mut tally.places, Places::OutOfOrder) {
            kept.sort_by_key(PlacedBreak::place);
            let mut grouping = Grouping::default();
            kept.into_iter().for_each(|placed| grouping.add(placed));
            grouping.close_block();
            tally.places = Places::InOrder(grouping);
        }
        Ok((ran, tally))
    }

    /// Runs `program` through the velocity model as the steps come, keeping
    /// what the picture draws of the first `max_moves` ([`Sketch`]), and
    /// draws it in `view`: the trace keeps those steps only.
    pub(crate) fn plotted(
        program: &Program<'_>,
        step_budget: usize,
        max_moves: usize,
        view: View,
        progress: Progress,
    ) -> Result<(Ran, Plot), String> {
        let config = program.config()?;
        let machine = &config.machine;
        let dynamics = nc_exec::run::dynamics(machine);
        let timer = Timer::new(machine.step_axes(), &dynamics, Sketch::new(max_moves));
        let mut sketched = None;
        let mut ran = Ran::run(program, &config, progress, |text, library| {
            let (trace, timer) = nc_exec::run::run_beside(text, library, machine, step_budget, timer);
            sketched = Some(timer.finish());
            trace
        });
        let mut sketch = sketched.unwrap_or_else(|| Sketch::new(max_moves));
        ran.trace.steps = std::mem::take(&mut sketch.steps);
        let title = format!("{} · ncc plot", ran.sources[0].name);
        let svg = crate::plot::svg(&ran.trace, &sketch, &ran, &title, view);
        let capped = sketch.capped().map(|drawn| crate::plot::capped_note(drawn, sketch.moves));
        let view = view.drawn(&ran.trace);
        Ok((ran, Plot { svg, total_time: sketch.total_time, capped, view }))
    }

    /// Runs `program` with `execute` (which keeps the steps or hands them
    /// on) and the files of its project.
    fn run(
        program: &Program<'_>,
        config: &Config,
        progress: Progress,
        execute: impl FnOnce(&str, &Library<'_>) -> Trace,
    ) -> Ran {
        let text = program.text;
        let library = Library::for_program(program, progress);
        let trace = execute(text, &library);
        if let Some(bar) = library.progress.get() {
            bar.finish_and_clear();
        }
        let sources = library.sources(&program.name, text, program.dialect, &trace);
        Ran { trace, config: config.clone(), dynamics: nc_exec::run::dynamics(&config.machine), sources }
    }

    /// The run timed with the control's velocity model.
    fn timing(&self) -> Timing {
        velocity::time(&self.trace, &self.dynamics)
    }

    fn exit_code(&self) -> ExitCode {
        if self.stop().is_some() { ExitCode::FAILURE } else { ExitCode::SUCCESS }
    }

    /// The run's findings in the order they came, each with its file (the
    /// program's name for the program), its line and whether the run
    /// stopped there, at the level the configuration gives its rule; those
    /// of rules turned off or silenced by an `ncc:ignore` comment are left
    /// out, unless the run stopped there.
    pub(crate) fn findings(&self) -> impl Iterator<Item = RunFinding<'_>> {
        self.trace.findings.iter().filter_map(|finding| {
            let source = &self.sources[finding.source];
            let rule = Rule::of_run(finding.rule);
            let silenced = source.suppressions.silences(finding.range.start(), rule.code, rule.name);
            let level = self.config.level_of(rule).filter(|_| !silenced);
            let severity = if finding.stops() { level.unwrap_or(rule.severity) } else { level? };
            Some(RunFinding {
                rule,
                severity,
                file: &source.name,
                in_program: finding.source == 0,
                line: source.line(finding.range.start()),
                message: &finding.message,
                stopped: finding.stops(),
            })
        })
    }

    /// The error the run stopped on, if it did.
    pub(crate) fn stop(&self) -> Option<RunFinding<'_>> {
        self.findings().find(|finding| finding.stopped)
    }
}

/// The program's number from its `%` header.
fn program_number(text: &str) -> Option<u32> {
    BlockParser::new(text).header().and_then(|header| header.number()).and_then(|n| u32::try_from(n.scaled(0)?).ok())
}

/// What a run found at a place: an instruction it does not run yet, an
/// error the control stops on.
pub(crate) struct RunFinding<'a> {
    pub rule: &'static Rule,
    pub severity: Severity,
    pub file: &'a str,
    /// In the program itself, not in a file it called.
    pub in_program: bool,
    /// Counted from 1.
    pub line: u32,
    pub message: &'a str,
    pub stopped: bool,
}

/// The toolpath picture of a run, and the total time its legend shows.
pub(crate) struct Plot {
    pub svg: String,
    /// Seconds, with the velocity model.
    pub total_time: f64,
    /// What the picture says when it draws only the first moves.
    pub capped: Option<String>,
    /// The view the picture is drawn in.
    pub view: View,
}

/// Whether a long run shows a spinner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Progress {
    /// On stderr, when it is a terminal (the command line).
    OnTerminal,
    /// Never (the language server, whose stderr is its log).
    Hidden,
}

pub(crate) fn run(
    path: &Path,
    dialect: Option<Dialect>,
    format: Format,
    step_budget: usize,
    write_dir: &Path,
) -> ExitCode {
    on_program(path, dialect, |program| run_program(program, path, format, step_budget, write_dir))
}

fn run_program(program: &Program<'_>, path: &Path, format: Format, step_budget: usize, write_dir: &Path) -> ExitCode {
    if !nc_exec::run::interprets(program.dialect) {
        return not_run(program, step_budget);
    }
    let (ran, written) = match format {
        Format::Human => {
            let (ran, tally) = match Ran::tally(program, step_budget, Progress::OnTerminal) {
                Ok(ran) => ran,
                Err(error) => return config_error(error),
            };
            ran.print_findings();
            let mut out = io::stdout().lock();
            let written = out.write_all(summary(path, &ran, &tally).as_bytes()).and_then(|()| out.flush());
            (ran, written)
        }
        Format::Json => {
            let ran = match Ran::of(program, step_budget, Progress::OnTerminal) {
                Ok(ran) => ran,
                Err(error) => return config_error(error),
            };
            ran.print_findings();
            let timing = ran.timing();
            let report = Report::new(path, &ran, &timing);
            let mut out = io::BufWriter::new(io::stdout().lock());
            let written = serde_json::to_writer_pretty(&mut out, &report)
                .map_err(io::Error::from)
                .and_then(|()| writeln!(out))
                .and_then(|()| out.flush());
            (ran, written)
        }
    };
    if let Err(error) = written
        && error.kind() != io::ErrorKind::BrokenPipe
    {
        eprintln!("error: writing the output: {error}");
        return ExitCode::from(2);
    }
    if let Err(error) = write_files(&ran.trace.written, write_dir) {
        eprintln!("error: {error}");
        return ExitCode::from(2);
    }
    ran.exit_code()
}

/// Writes the files the run wrote below `directory`, each at the path
/// [`written_path`] gives; creates it only when there is one.
fn write_files(files: &[WrittenFile], directory: &Path) -> Result<(), String> {
    for file in files {
        let Some(relative) = written_path(&file.path) else {
            return Err(format!("the program wrote {}, a path that would leave {}", file.path, directory.display()));
        };
        let path = directory.join(relative);
        let written =
            path.parent().map_or(Ok(()), std::fs::create_dir_all).and_then(|()| std::fs::write(&path, &file.text));
        written.map_err(|error| format!("writing {}: {error}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// Where a file the control names `path` goes below the directory the
/// written files go to: `_N_X_DIR` is the directory `X`, `_N_NAME_EXT` the
/// file `NAME.EXT`, other names stay; `None` for a path that would leave
/// the directory (`..`, an absolute one once the control's directories
/// are mapped, a drive or a backslash).
fn written_path(path: &str) -> Option<PathBuf> {
    let mut relative = PathBuf::new();
    let parts: Vec<&str> = path.split('/').collect();
    for (index, part) in parts.iter().enumerate() {
        // A leading `/` is the control's root, for the control's
        // directories only.
        if part.is_empty()
            && index == 0
            && parts.get(1).is_some_and(|next| next.starts_with("_N_") && next.ends_with("_DIR"))
        {
            continue;
        }
        let unsafe_part = part.is_empty() || *part == "." || *part == ".." || part.contains(['\\', ':']);
        if unsafe_part {
            return None;
        }
        let inner = part.strip_prefix("_N_").filter(|inner| !inner.is_empty());
        let mapped = match inner.and_then(|inner| inner.rsplit_once('_')) {
            Some((name, "DIR")) if index + 1 < parts.len() => name.to_owned(),
            Some((name, extension)) if index + 1 == parts.len() && !name.is_empty() => format!("{name}.{extension}"),
            _ => (*part).to_owned(),
        };
        relative.push(mapped);
    }
    (!relative.as_os_str().is_empty()).then_some(relative)
}

/// `ncc expand`: the run written back as a program of plain motion blocks,
/// to `output` or stdout, each block as its move comes: a run of any length
/// expands in the same memory. A move the program cannot express stops the
/// writing; the output file is then removed.
pub(crate) fn expand(path: &Path, dialect: Option<Dialect>, output: Option<&Path>, step_budget: usize) -> ExitCode {
    on_program(path, dialect, |program| expand_program(program, path, output, step_budget))
}

fn expand_program(program: &Program<'_>, path: &Path, output: Option<&Path>, step_budget: usize) -> ExitCode {
    let config = match program.config() {
        Ok(config) => config,
        Err(error) => return config_error(error),
    };
    let machine = &config.machine;
    let name = path.file_name().map_or_else(|| path.display().to_string(), |name| name.to_string_lossy().into_owned());
    let title = format!("EXPANDED FROM {name}");
    // The expansion is written in the program's own dialect.
    let (mut expansion, target): (Box<dyn Expand>, String) = match program.dialect {
        Dialect::Cnc8x6 => {
            let number = program_number(program.text).unwrap_or(1);
            let Some((out, target)) = open_output(output) else { return ExitCode::from(2) };
            (Box::new(cnc8x6::expand::Expansion::new(out, machine, number, &title)), target)
        }
        Dialect::HaasLathe => {
            let number = haas_lathe::program::first_program_number(program.text).unwrap_or(1);
            let Some((out, target)) = open_output(output) else { return ExitCode::from(2) };
            (Box::new(haas_lathe::expand::Expansion::new(out, machine, number, &title)), target)
        }
        Dialect::Sinumerik => {
            let Some((out, target)) = open_output(output) else { return ExitCode::from(2) };
            (Box::new(sinumerik::expand::Expansion::new(out, machine, &title)), target)
        }
    };
    let ran = Ran::run(program, &config, Progress::OnTerminal, |text, library| {
        nc_exec::run::run_into(text, library, machine, step_budget, &mut *expansion)
    });
    ran.print_findings();
    let failure = match expansion.finish() {
        Ok(()) => return ran.exit_code(),
        Err(ExpandError::Io(error)) if error.kind() == io::ErrorKind::BrokenPipe => return ran.exit_code(),
        Err(failure) => failure,
    };
    let code = match failure {
        ExpandError::Unwritable(unwritable) => {
            let message = visible::escaped(&unwritable.to_string()).into_owned();
            eprintln!("error: {}: {message}", ran.sources[unwritable.source].place(unwritable.range.start()));
            ExitCode::FAILURE
        }
        ExpandError::Io(error) => {
            eprintln!("error: writing {target}: {error}");
            ExitCode::from(2)
        }
    };
    if let Some(output) = output {
        // A program cut short must not pass for the expansion.
        let _ = std::fs::remove_file(output);
    }
    code
}

/// A program the executor does not run: its run makes no step and says so
/// in its one finding, which is all the command prints; no time, file or
/// picture comes out of it, and the exit status says so.
fn not_run(program: &Program<'_>, step_budget: usize) -> ExitCode {
    match Ran::of(program, step_budget, Progress::OnTerminal) {
        Ok(ran) => {
            ran.print_findings();
            ExitCode::FAILURE
        }
        Err(error) => config_error(error),
    }
}

/// Where an expansion goes, buffered, and its name for messages; `None`
/// after saying why a file cannot be written.
fn open_output(output: Option<&Path>) -> Option<(io::BufWriter<Box<dyn io::Write>>, String)> {
    let (out, target): (Box<dyn io::Write>, String) = match output {
        Some(output) => match std::fs::File::create(output) {
            Ok(file) => (Box::new(file), output.display().to_string()),
            Err(error) => {
                eprintln!("error: writing {}: {error}", output.display());
                return None;
            }
        },
        None => (Box::new(io::stdout().lock()), "stdout".to_owned()),
    };
    Some((io::BufWriter::new(out), target))
}

/// `ncc plot FILE -o OUT`: the toolpath as an SVG picture of the first
/// `max_moves` moves, a lathe's in `view`.
pub(crate) fn plot(
    path: &Path,
    dialect: Option<Dialect>,
    output: &Path,
    step_budget: usize,
    max_moves: usize,
    view: View,
) -> ExitCode {
    on_program(path, dialect, |program| plot_program(program, output, step_budget, max_moves, view))
}

fn plot_program(program: &Program<'_>, output: &Path, step_budget: usize, max_moves: usize, view: View) -> ExitCode {
    if !nc_exec::run::interprets(program.dialect) {
        return not_run(program, step_budget);
    }
    let (ran, picture) = match Ran::plotted(program, step_budget, max_moves, view, Progress::OnTerminal) {
        Ok(plotted) => plotted,
        Err(error) => return config_error(error),
    };
    ran.print_findings();
    if let Some(note) = &picture.capped {
        eprintln!("note: {note} (--max-moves draws more)");
    }
    let png = output.extension().is_some_and(|extension| extension.eq_ignore_ascii_case("png"));
    let bytes = if png {
        match crate::plot::png(&picture.svg) {
            Ok(bytes) => bytes,
            Err(error) => {
                eprintln!("error: drawing {}: {error}", output.display());
                return ExitCode::from(2);
            }
        }
    } else {
        picture.svg.into_bytes()
    };
    match std::fs::write(output, bytes) {
        Ok(()) => ran.exit_code(),
        Err(error) => {
            eprintln!("error: writing {}: {error}", output.display());
            ExitCode::from(2)
        }
    }
}

impl crate::plot::Lines for Ran {
    fn line_of(&self, step: usize) -> u32 {
        let step = &self.trace.steps[step];
        self.sources[step.source].line(step.range.start())
    }

    fn file_of(&self, step: usize) -> Option<&str> {
        let source = self.trace.steps[step].source;
        (source != 0).then(|| self.sources[source].name.as_str())
    }
}

/// The program at `path` parsed in its dialect; the error is the exit code
/// after the message is printed.
fn parsed(path: &Path, dialect: Option<Dialect>) -> Result<(String, Parse), ExitCode> {
    let dialect = check::dialect_for(&mut check::Projects::default(), path, dialect);
    let text = read(path)?;
    let parse = Parse::new(&text, dialect);
    Ok((text, parse))
}

/// `ncc parse FILE`: the lossless syntax tree.
pub(crate) fn parse(path: &Path, dialect: Option<Dialect>) -> ExitCode {
    match parsed(path, dialect) {
        Ok((_, parse)) => {
            print!("{}", parse.debug_dump());
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}

/// `ncc lower FILE`: each block as the executor reads it, after its line.
pub(crate) fn lower(path: &Path, dialect: Option<Dialect>) -> ExitCode {
    let (text, parse) = match parsed(path, dialect) {
        Ok(parsed) => parsed,
        Err(code) => return code,
    };
    let lines = TextIndex::new(&text);
    let mut out = String::new();
    match parse.dialect() {
        Dialect::Cnc8x6 => {
            for block in parse.tree().blocks() {
                let line = lines.line_col(block.syntax().text_range().start(), Columns::Characters).0 + 1;
                let _ = writeln!(out, "{line:>6}  {}", BlockData::lower(block.syntax().green()));
            }
        }
        Dialect::HaasLathe => {
            for (range, block) in haas_lathe::lower::block_nodes(parse.green()) {
                let line = lines.line_col(range.start(), Columns::Characters).0 + 1;
                let _ = writeln!(out, "{line:>6}  {}", haas_lathe::lower::HaasBlock::lower(block));
            }
        }
        Dialect::Sinumerik => {
            for (range, block) in sinumerik::lower::block_nodes(parse.green()) {
                // A line of only a comment or blanks is a block that does nothing.
                let shown = sinumerik::lower::SinumerikBlock::lower(block).to_string();
                if !shown.is_empty() {
                    let line = lines.line_col(range.start(), Columns::Characters).0 + 1;
                    let _ = writeln!(out, "{line:>6}  {shown}");
                }
            }
        }
    }
    let mut stdout = io::stdout().lock();
    match stdout.write_all(out.as_bytes()).and_then(|()| stdout.flush()) {
        Err(error) if error.kind() != io::ErrorKind::BrokenPipe => {
            eprintln!("error: writing stdout: {error}");
            ExitCode::from(2)
        }
        _ => ExitCode::SUCCESS,
    }
}

/// Breaks the summary lists: the costliest a program could avoid (rapid
/// moves and threads always stop); JSON lists them all.
const LISTED_BREAKS: usize = 10;

/// What the summary shows of a run's steps, gathered as the velocity
/// model times them: a long run never holds its steps.
#[derive(Default)]
struct Tally {
    totals: Totals,
    /// The steps timed, and the last one's programmed end.
    steps: usize,
    end: Axes,
    /// Breaks by kind (in the order first met) and what they cost.
    by_reason: Vec<(&'static str, usize)>,
    breaks: usize,
    lost: f64,
    places: Places,
}

/// The places where a program could avoid its breaks (rapid moves and
/// threads always stop), grouped: a block that runs many times (a loop, a
/// subprogram) is one place.
enum Places {
    /// As they come, while the blocks come in order (a program without
    /// loops or calls), holding only the costliest.
    InOrder(Grouping),
    /// A break came back to an earlier block: the grouping so far is not
    /// the whole story.
    OutOfOrder,
    /// Every break, to sort.
    Kept(Vec<PlacedBreak>),
}

impl Default for Places {
    fn default() -> Places {
        Places::InOrder(Grouping::default())
    }
}

/// Breaks grouped by place as they come in order of place; the breaks of
/// one block (of different kinds, or of a cycle's moves) come together.
#[derive(Default)]
struct Grouping {
    /// Each place's first break, its runs and its cost: the block at
    /// hand's, one per kind, and the costliest of those before.
    block: Vec<(PlacedBreak, usize, f64)>,
    top: Vec<(PlacedBreak, usize, f64)>,
    /// Places met.
    places: usize,
}

impl Grouping {
    /// Whether `placed` can follow: it is at the block at hand or after it.
    fn in_order(&self, placed: &PlacedBreak) -> bool {
        self.block.first().is_none_or(|(first, ..)| (first.source, first.at) <= (placed.source, placed.at))
    }

    fn add(&mut self, placed: PlacedBreak) {
        if self.block.first().is_some_and(|(first, ..)| (first.source, first.at) != (placed.source, placed.at)) {
            self.close_block();
        }
        match self.block.iter_mut().find(|(first, ..)| first.place() == placed.place()) {
            Some((_, times, total)) => {
                *times += 1;
                *total += placed.lost;
            }
            None => {
                let lost = placed.lost;
                self.block.push((placed, 1, lost));
            }
        }
    }

    fn close_block(&mut self) {
        let by_cost = |a: &(PlacedBreak, usize, f64), b: &(PlacedBreak, usize, f64)| {
            b.2.total_cmp(&a.2).then(a.0.place().cmp(&b.0.place()))
        };
        self.places += self.block.len();
        for place in self.block.drain(..) {
            if self.top.len() == LISTED_BREAKS && self.top.last().is_some_and(|last| by_cost(&place, last).is_ge()) {
                continue;
            }
            self.top.push(place);
            self.top.sort_by(by_cost);
            self.top.truncate(LISTED_BREAKS);
        }
    }
}

/// A break with the file and the block it is at, small: a long program
/// can break at every block.
struct PlacedBreak {
    source: u32,
    at: TextSize,
    reason: velocity::Stated,
    /// mm/min, as shown.
    speed_before: f32,
    speed_at: f32,
    lost: f64,
}

impl PlacedBreak {
    /// The place a break is at, by kind: a block that runs many times (a
    /// loop, a subprogram) is one place.
    fn place(&self) -> (u32, TextSize, &'static str) {
        (self.source, self.at, self.reason.code())
    }
}

impl TimingSink for Tally {
    fn speed_break(&mut self, step: &Step, speed_break: velocity::Break) {
        let velocity::Break { reason, before, at, lost, .. } = speed_break;
        self.breaks += 1;
        self.lost += lost;
        match self.by_reason.iter_mut().find(|(code, _)| *code == reason.code()) {
            Some((_, count)) => *count += 1,
            None => self.by_reason.push((reason.code(), 1)),
        }
        if !reason.avoidable() {
            return;
        }
        let source = u32::try_from(step.source).unwrap_or(u32::MAX);
        let (speed_before, speed_at) = (before as f32, at as f32);
        let placed = PlacedBreak { source, at: step.range.start(), reason, speed_before, speed_at, lost };
        match &mut self.places {
            Places::InOrder(grouping) if grouping.in_order(&placed) => grouping.add(placed),
            Places::InOrder(_) => self.places = Places::OutOfOrder,
            Places::OutOfOrder => {}
            Places::Kept(kept) => kept.push(placed),
        }
    }

    fn timed(&mut self, step: &Step, profile: velocity::Profile) {
        self.totals.add(step, profile.duration);
        self.steps += 1;
        self.end = step.end;
    }
}

fn summary(path: &Path, ran: &Ran, tally: &Tally) -> String {
    let trace = &ran.trace;
    let mut out = String::new();
    let (feed, rapid) = (Motion::Feed, Motion::Rapid);
    let totals = &tally.totals;
    let _ = writeln!(out, "{}", shown_path(path));
    let (total, at_feed) = (clock(totals.total_time), clock(totals.programmed_time));
    let _ = writeln!(out, "  total time   {total}  ({at_feed} at the programmed feeds)");
    let _ = writeln!(out, "    cutting    {}  {:>12.3} mm", clock(totals.time(feed)), totals.length(feed));
    let _ = writeln!(out, "    rapid      {}  {:>12.3} mm", clock(totals.time(rapid)), totals.length(rapid));
    let _ = writeln!(out, "    dwell      {}", clock(totals.time(Motion::Dwell)));
    let (program_stops, optional_stops) = (totals.program_stops, totals.optional_stops);
    if program_stops + optional_stops > 0 {
        let _ = writeln!(
            out,
            "  stops        {program_stops} × M00, {optional_stops} × M01 (the wait for the operator is not counted)"
        );
    }
    if !trace.messages.is_empty() {
        let mut codes: Vec<u8> = trace.messages.iter().map(|shown| shown.message.code).collect();
        codes.sort_unstable();
        codes.dedup();
        let codes: Vec<String> = codes.iter().map(u8::to_string).collect();
        let _ = writeln!(out, "  messages     {} by operation 51 (codes {})", trace.messages.len(), codes.join(", "));
    }
    let tools: Vec<String> = trace.tools.iter().map(Tool::to_string).collect();
    let _ = writeln!(out, "  tools        {}", if tools.is_empty() { "none".to_owned() } else { tools.join(" ") });
    // Turners read the diameter axis as a diameter; the trace keeps radii.
    let as_written = |axis: u8, value: f64| if trace.diameter_axis == Some(axis) { 2.0 * value } else { value };
    // Where the tool centre ended: off the programmed end when the program
    // ends under radius compensation.
    let end = tally.steps.checked_sub(1).map_or(tally.end, |last| trace.tool_end(last, &tally.end));
    let position: Vec<String> = trace
        .axes
        .iter()
        .zip(end)
        .map(|(&axis, value)| format!("{}{:.3}", char::from(axis), as_written(axis, value)))
        .collect();
    let diameter = trace.diameter_axis.map(|axis| format!(" ({} as a diameter)", char::from(axis))).unwrap_or_default();
    let _ = writeln!(out, "  end position {}{diameter}", position.join(" "));
    if tally.breaks > 0 {
        let mut by_reason = tally.by_reason.clone();
        by_reason.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
        let by_reason: Vec<String> = by_reason.iter().map(|(code, n)| format!("{n} {code}")).collect();
        let _ = writeln!(
            out,
            "  breaks       {} where the path speed drops ({}), costing {}",
            tally.breaks,
            by_reason.join(", "),
            clock(tally.lost)
        );
        if let Places::InOrder(grouping) = &tally.places {
            for (placed, times, lost) in &grouping.top {
                let place = ran.sources[placed.source as usize].place(placed.at);
                let times = if *times > 1 { format!(" ({times} runs)") } else { String::new() };
                let (reason, before, at) = (placed.reason, placed.speed_before, placed.speed_at);
                let _ = writeln!(out, "    {place}  {reason}: {before:.0} → {at:.0} mm/min, {lost:.3} s{times}");
            }
            if grouping.places > LISTED_BREAKS {
                let more = grouping.places - LISTED_BREAKS;
                let _ = writeln!(out, "    … and {more} more places (--format json lists every break)");
            }
        }
    }
    out
}

/// `ncc run --format json`, written as it is serialised: a run of a
/// million blocks never holds its records in memory.
/// A tool in the report: its number, or its name (Sinumerik `T="…"`).
#[derive(Serialize)]
#[serde(untagged)]
enum ToolJson<'a> {
    Number(u32),
    Name(&'a str),
}

impl<'a> ToolJson<'a> {
    fn of(tool: &'a Tool) -> ToolJson<'a> {
        match tool {
            Tool::Number(number) => ToolJson::Number(*number),
            Tool::Name(name) => ToolJson::Name(name),
        }
    }
}

#[derive(Serialize)]
struct Report<'a> {
    file: String,
    /// With the velocity model; `programmed_time_s` at the programmed feeds.
    total_time_s: f64,
    programmed_time_s: f64,
    cutting_time_s: f64,
    rapid_time_s: f64,
    dwell_time_s: f64,
    cutting_length_mm: f64,
    rapid_length_mm: f64,
    tools: Vec<ToolJson<'a>>,
    /// Where the tool centre ended, and the programmed end when the last
    /// block ran under radius compensation.
    end_position: Values<'a>,
    #[serde(skip_serializing_if = "Option::is_none")]
    programmed_end_position: Option<Values<'a>>,
    blocks: Records<'a>,
    breaks: Vec<BreakRecord<'a>>,
    messages: Vec<MessageRecord<'a>>,
    findings: Vec<FindingRecord<'a>>,
}

impl<'a> Report<'a> {
    fn new(path: &Path, ran: &'a Ran, timing: &'a Timing) -> Report<'a> {
        let (trace, sources) = (&ran.trace, &ran.sources);
        let axes = &trace.axes;
        let totals = trace.totals_with(timing.profiles.iter().map(|profile| profile.duration));
        let last = trace.steps.len().checked_sub(1);
        Report {
            file: path.display().to_string(),
            total_time_s: totals.total_time,
            programmed_time_s: totals.programmed_time,
            cutting_time_s: totals.time(Motion::Feed),
            rapid_time_s: totals.time(Motion::Rapid),
            dwell_time_s: totals.time(Motion::Dwell),
            cutting_length_mm: totals.length(Motion::Feed),
            rapid_length_mm: totals.length(Motion::Rapid),
            tools: trace.tools.iter().map(ToolJson::of).collect(),
            end_position: Values(last.map_or(trace.end(), |last| trace.tool_end(last, &trace.end())), axes),
            programmed_end_position: last.and_then(|last| trace.centred(last)).map(|_| Values(trace.end(), axes)),
            blocks: Records { trace, timing, sources },
            breaks: timing
                .breaks
                .iter()
                .map(|speed_break| {
                    let step = &trace.steps[speed_break.step];
                    let source = &sources[step.source];
                    BreakRecord {
                        file: &source.name,
                        line: source.line(step.range.start()),
                        reason: speed_break.reason.code(),
                        message: speed_break.reason.to_string(),
                        speed_before_mm_min: speed_break.before,
                        speed_at_mm_min: speed_break.at,
                        lost_s: speed_break.lost,
                    }
                })
                .collect(),
            messages: trace
                .messages
                .iter()
                .map(|shown| {
                    let source = &sources[trace.steps[shown.step].source];
                    let Message { code, parameter, value, display } = shown.message;
                    MessageRecord {
                        file: &source.name,
                        line: source.line(trace.steps[shown.step].range.start()),
                        code,
                        parameter,
                        value: value.map(|raw| raw as f64 / 1000.0),
                        display: match display {
                            MessageDisplay::Cancel => "cancel".to_owned(),
                            MessageDisplay::Permanent => "permanent".to_owned(),
                            MessageDisplay::OneBlock => "one block".to_owned(),
                            MessageDisplay::Seconds(seconds) => format!("{seconds} s"),
                        },
                    }
                })
                .collect(),
            findings: ran
                .findings()
                .map(|finding| FindingRecord {
                    code: finding.rule.code,
                    name: finding.rule.name,
                    severity: finding.severity.as_str(),
                    file: finding.file,
                    line: finding.line,
                    message: finding.message,
                    stopped: finding.stopped,
                })
                .collect(),
        }
    }
}

/// The block records, serialised one by one.
struct Records<'a> {
    trace: &'a Trace,
    timing: &'a Timing,
    sources: &'a [Source],
}

impl Serialize for Records<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let steps = self.trace.steps.iter().zip(&self.timing.profiles).zip(self.timing.start_times()).enumerate();
        let (trace, axes) = (self.trace, &self.trace.axes);
        serializer.collect_seq(steps.map(|(index, ((step, profile), start_time))| {
            let source = &self.sources[step.source];
            let centred = trace.centred(index).is_some();
            BlockRecord {
                file: &source.name,
                line: source.line(step.range.start()),
                motion: match step.motion {
                    Motion::None => "none",
                    Motion::Rapid => "rapid",
                    Motion::Feed => "feed",
                    Motion::Dwell => "dwell",
                },
                stop: step.stop.map(|stop| match stop {
                    Stop::Program => "M00",
                    Stop::Optional => "M01",
                }),
                start_time_s: start_time,
                duration_s: profile.duration,
                programmed_duration_s: step.duration,
                length_mm: step.length,
                feed_mm_min: step.feed,
                entry_speed_mm_min: profile.entry,
                peak_speed_mm_min: profile.peak,
                exit_speed_mm_min: profile.exit,
                start: Coordinates {
                    program: Values(trace.tool_start_of(index), axes),
                    machine: Values(trace.tool_machine_start(index), axes),
                    programmed: centred.then(|| Placed {
                        program: Values(trace.start_of(index), axes),
                        machine: Values(trace.machine_start(index), axes),
                    }),
                },
                end: Coordinates {
                    program: Values(trace.tool_end(index, &step.end), axes),
                    machine: Values(trace.tool_machine_end(index), axes),
                    programmed: centred.then(|| Placed {
                        program: Values(step.end, axes),
                        machine: Values(trace.machine_end(index), axes),
                    }),
                },
            }
        }))
    }
}

#[derive(Serialize)]
struct BlockRecord<'a> {
    file: &'a str,
    line: u32,
    motion: &'static str,
    stop: Option<&'static str>,
    start_time_s: f64,
    /// With the velocity model, and at the programmed feed.
    duration_s: f64,
    programmed_duration_s: f64,
    length_mm: f64,
    feed_mm_min: Option<f64>,
    entry_speed_mm_min: f64,
    peak_speed_mm_min: f64,
    exit_speed_mm_min: f64,
    start: Coordinates<'a>,
    end: Coordinates<'a>,
}

/// Where the tool centre is, in program and machine coordinates, and under
/// radius compensation where the program put the block.
#[derive(Serialize)]
struct Coordinates<'a> {
    program: Values<'a>,
    machine: Values<'a>,
    #[serde(skip_serializing_if = "Option::is_none")]
    programmed: Option<Placed<'a>>,
}

/// A programmed point in program and machine coordinates.
#[derive(Serialize)]
struct Placed<'a> {
    program: Values<'a>,
    machine: Values<'a>,
}

/// A message of operation 51: its code, the parameter it shows with the
/// value it had, and how long it stays.
#[derive(Serialize)]
struct MessageRecord<'a> {
    file: &'a str,
    line: u32,
    code: u8,
    parameter: u8,
    value: Option<f64>,
    display: String,
}

#[derive(Serialize)]
struct BreakRecord<'a> {
    file: &'a str,
    line: u32,
    reason: &'static str,
    message: String,
    speed_before_mm_min: f64,
    speed_at_mm_min: f64,
    lost_s: f64,
}

#[derive(Serialize)]
struct FindingRecord<'a> {
    code: &'static str,
    name: &'static str,
    severity: &'static str,
    file: &'a str,
    line: u32,
    message: &'a str,
    stopped: bool,
}

/// Axis values as `{"X": …, "Y": …}`, in the machine's order.
struct Values<'a>(Axes, &'a [u8]);

impl Serialize for Values<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let Values(values, axes) = self;
        serializer.collect_map(axes.iter().zip(values).map(|(&axis, value)| (char::from(axis), value)))
    }
}

/// Where a run finds the files a program uses: macrocycle files
/// (`G72 L9001` calls the file `L9001`, with or without an extension), the
/// machine's cycle file, by name, and Haas programs (`M98 P1234` calls the
/// file `O1234` or `O01234`, with or without an extension). It looks
/// beside the program first, then anywhere in its project, the directory
/// of its `ncc.toml`.
struct Library<'a> {
    candidates: Vec<PathBuf>,
    /// The editor's files, which take the place of the candidates.
    snapshot: Option<&'a WorkspaceFiles>,
    /// The files read, with their text.
    read: RefCell<Vec<(Called, PathBuf, String)>>,
    /// A spinner on stderr once a run is long enough to wait for, when a
    /// person is watching.
    progress: OnceCell<ProgressBar>,
}

impl<'a> Library<'a> {
    fn for_program(program: &Program<'a>, progress: Progress) -> Library<'a> {
        let candidates = match program.path {
            Some(path) if program.files.is_none() => {
                let directory = path.parent().filter(|dir| !dir.as_os_str().is_empty()).unwrap_or(Path::new("."));
                let beside = std::fs::read_dir(directory).into_iter().flatten().flatten().map(|entry| entry.path());
                let project = program.config.and_then(Path::parent).map(Path::to_path_buf);
                let in_project = project
                    .into_iter()
                    .flat_map(|root| check::collect_files(&[root], &mut check::Projects::default(), None).files)
                    .map(|(path, _)| path);
                beside.chain(in_project).filter(|path| path.is_file()).collect()
            }
            _ => Vec::new(),
        };
        let progress = match progress {
            Progress::OnTerminal => OnceCell::new(),
            Progress::Hidden => OnceCell::from(ProgressBar::hidden()),
        };
        Library { candidates, snapshot: program.files, read: RefCell::default(), progress }
    }

    /// The file `called`: from the editor's snapshot when there is one
    /// (`in_snapshot` finds it), else the first candidate that `matches`.
    fn read(
        &self,
        called: &Called,
        matches: impl Fn(&Path) -> bool,
        in_snapshot: impl FnOnce(&WorkspaceFiles) -> Option<(&str, &str)>,
    ) -> Option<String> {
        let (path, text) = match self.snapshot {
            Some(files) => in_snapshot(files).map(|(path, text)| (PathBuf::from(path), text.to_owned()))?,
            None => {
                let path = self.candidates.iter().find(|path| matches(path))?;
                (path.clone(), check::read_program(path).ok()?)
            }
        };
        self.read.borrow_mut().push((called.clone(), path, text.clone()));
        Some(text)
    }

    /// The program and the files the run read, in the trace's source order.
    fn sources(&self, name: &str, text: &str, dialect: Dialect, trace: &Trace) -> Vec<Source> {
        let read = self.read.take();
        let source = |name: String, text: &str| Source {
            name,
            lines: TextIndex::new(text),
            suppressions: Suppressions::of_text(text, dialect),
        };
        let files = trace.files.iter().map(|called| match called {
            Called::Written(path) => {
                let written = trace.written.iter().find(|file| file.path == *path);
                source(path.clone(), written.map_or("", |file| file.text.as_str()))
            }
            _ => match read.iter().find(|(c, _, _)| c == called) {
                Some((_, path, text)) => source(path.display().to_string(), text),
                None => source(String::new(), ""),
            },
        });
        std::iter::once(source(name.to_owned(), text)).chain(files).collect()
    }
}

impl Environment for Library<'_> {
    fn file(&self, called: &Called) -> Option<String> {
        match called {
            &Called::Number(number) => {
                let named = |path: &Path| check::macrocycle_number(path) == Some(number);
                self.read(called, named, |files| files.macrocycle_file(number))
            }
            Called::Name(name) => {
                let named = |path: &Path| {
                    path.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.eq_ignore_ascii_case(name))
                };
                self.read(called, named, |files| files.cycle_file_named(name))
            }
            &Called::Program(number) => {
                let named = |path: &Path| ncc_catalog::program_file_number(path) == Some(number);
                self.read(called, named, |files| files.program_file(number))
            }
            Called::ControlFile(name) => {
                let named = |path: &Path| ncc_catalog::is_control_file(path, name);
                self.read(called, named, |files| files.control_file(name))
            }
            // The run keeps what it wrote itself.
            Called::Written(_) => None,
        }
    }

    fn progress(&self, blocks_run: usize) {
        let bar = self.progress.get_or_init(|| {
            if !io::stderr().is_terminal() {
                return ProgressBar::hidden();
            }
            let bar = ProgressBar::new_spinner();
            if let Ok(style) = ProgressStyle::with_template("{spinner} running: {human_pos} blocks {elapsed}") {
                bar.set_style(style);
            }
            bar
        });
        bar.set_position(blocks_run as u64);
    }
}

/// A file a run read, for locating its blocks.
struct Source {
    name: String,
    lines: TextIndex,
    /// Its `ncc:ignore` comments.
    suppressions: Suppressions,
}

impl Source {
    fn line(&self, offset: TextSize) -> u32 {
        self.lines.line_col(offset, Columns::Characters).0 + 1
    }

    /// `path:line`, for people.
    fn place(&self, offset: TextSize) -> String {
        format!("{}:{}", visible::escaped(&self.name), self.line(offset))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_paths_map_the_controls_names_and_stay_inside() {
        let mapped = |path: &str| written_path(path).map(|path| path.to_string_lossy().replace('\\', "/"));
        assert_eq!(
            mapped("/_N_MPF_DIR/_N_VACKA_DIR/_N_GEOMETRIE_VACKA_SPF").as_deref(),
            Some("MPF/VACKA/GEOMETRIE_VACKA.SPF")
        );
        assert_eq!(mapped("_N_PART_MPF").as_deref(), Some("PART.MPF"));
        assert_eq!(mapped("NOTES.TXT").as_deref(), Some("NOTES.TXT"));
        for leaving in ["/ETC/PASSWD", "/_N_MPF_DIR/../X", "..", "A/./B", "C:X", "A\\B", "", "/_N_MPF_DIR/"] {
            assert_eq!(mapped(leaving), None, "{leaving}");
        }
    }
}
