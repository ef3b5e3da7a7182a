//! `ncc run FILE`: runs a program on the executor, times it with the
//! velocity model and prints what the machine would do: the time split
//! into cutting, rapid and dwell, the path lengths, the tools, the end
//! position and the breaks of the path speed; `--format json` adds a
//! record per block and every break. `ncc expand`, `ncc plot` and
//! `ncc lower` share the run.

use std::{
    cell::{OnceCell, RefCell},
    fmt::Write as _,
    io::{self, IsTerminal, Write as _},
    path::{Path, PathBuf},
    process::ExitCode,
};

use indicatif::{ProgressBar, ProgressStyle};
use line_index::LineIndex;
use nc_exec::{
    arith::{Message, MessageDisplay},
    lower::BlockData,
    run::{Axes, Called, Environment, Motion, Stop, Trace},
    velocity::{self, Dynamics, Timing},
};
use ncc_analysis::{Config, clock};
use ncc_syntax::{BlockParser, Dialect, Parse, TextSize, ast::AstNode};
use serde::Serialize;

use crate::check;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Format {
    Human,
    Json,
}

/// A program run on the machine of its project.
struct Ran {
    trace: Trace,
    /// The machine's dynamics, for the velocity model.
    dynamics: Dynamics,
    sources: Vec<Source>,
    /// The program's number from its `%` header.
    number: Option<u32>,
}

impl Ran {
    /// Runs the program at `path`; the error is the exit code after the
    /// message is printed.
    fn new(path: &Path, step_budget: usize) -> Result<Ran, ExitCode> {
        let text = check::read_program(path).map_err(|error| {
            eprintln!("error: {}: {error}", path.display());
            ExitCode::from(2)
        })?;
        let config = Config::find_for(path).map(|config| check::load_config(&config)).transpose().map_err(|error| {
            eprintln!("error: {error}");
            ExitCode::from(2)
        })?;
        let config = config.unwrap_or_default();
        let number = BlockParser::new(&text)
            .header()
            .and_then(|header| header.number())
            .and_then(|n| u32::try_from(n.scaled(0)?).ok());
        let library = Library::for_program(path);
        let trace = nc_exec::run::run(&text, &library, &config.machine, step_budget);
        if let Some(bar) = library.progress.get() {
            bar.finish_and_clear();
        }
        let sources = library.sources(path, text, &trace);
        for finding in &trace.findings {
            eprintln!("{}: {}", sources[finding.source].place(finding.range.start()), finding.message);
        }
        Ok(Ran { trace, dynamics: Dynamics::of(&config.machine), sources, number })
    }

    /// The run timed with the control's velocity model.
    fn timing(&self) -> Timing {
        velocity::time(&self.trace, &self.dynamics)
    }

    fn exit_code(&self) -> ExitCode {
        if self.trace.findings.iter().any(|finding| finding.fatal) { ExitCode::FAILURE } else { ExitCode::SUCCESS }
    }
}

pub(crate) fn run(path: &Path, format: Format, step_budget: usize) -> ExitCode {
    let ran = match Ran::new(path, step_budget) {
        Ok(ran) => ran,
        Err(code) => return code,
    };
    let timing = ran.timing();
    let written = match format {
        Format::Human => {
            let mut out = io::stdout().lock();
            out.write_all(summary(path, &ran, &timing).as_bytes()).and_then(|()| out.flush())
        }
        Format::Json => {
            let report = Report::new(path, &ran, &timing);
            let mut out = io::BufWriter::new(io::stdout().lock());
            serde_json::to_writer_pretty(&mut out, &report)
                .map_err(io::Error::from)
                .and_then(|()| writeln!(out))
                .and_then(|()| out.flush())
        }
    };
    if let Err(error) = written
        && error.kind() != io::ErrorKind::BrokenPipe
    {
        eprintln!("error: writing the output: {error}");
        return ExitCode::from(2);
    }
    ran.exit_code()
}

/// `ncc expand`: the run written back as a program of plain motion blocks,
/// to `output` or stdout.
pub(crate) fn expand(path: &Path, output: Option<&Path>, step_budget: usize) -> ExitCode {
    let ran = match Ran::new(path, step_budget) {
        Ok(ran) => ran,
        Err(code) => return code,
    };
    let name = path.file_name().map_or_else(|| path.display().to_string(), |name| name.to_string_lossy().into_owned());
    let title = format!("EXPANDED FROM {name}");
    let text = match nc_exec::expand::write(&ran.trace, ran.number.unwrap_or(1), &title) {
        Ok(text) => text,
        Err(unwritable) => {
            let step = &ran.trace.steps[unwritable.step];
            eprintln!("error: {}: {unwritable}", ran.sources[step.source].place(step.range.start()));
            return ExitCode::FAILURE;
        }
    };
    let written = match output {
        Some(output) => std::fs::write(output, &text).map_err(|error| (output.display().to_string(), error)),
        None => {
            let mut out = io::stdout().lock();
            out.write_all(text.as_bytes()).and_then(|()| out.flush()).map_err(|error| ("stdout".to_owned(), error))
        }
    };
    match written {
        Err((target, error)) if error.kind() != io::ErrorKind::BrokenPipe => {
            eprintln!("error: writing {target}: {error}");
            ExitCode::from(2)
        }
        _ => ran.exit_code(),
    }
}

/// `ncc plot FILE -o OUT`: the toolpath as an SVG picture.
pub(crate) fn plot(path: &Path, output: &Path, step_budget: usize) -> ExitCode {
    let ran = match Ran::new(path, step_budget) {
        Ok(ran) => ran,
        Err(code) => return code,
    };
    let title = format!("{} · ncc plot", path.display());
    let svg = crate::plot::svg(&ran.trace, &ran.timing(), &ran, &title);
    match std::fs::write(output, svg) {
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
}

/// `ncc lower FILE`: each block as the executor reads it, after its line.
pub(crate) fn lower(path: &Path) -> ExitCode {
    let text = match check::read_program(path) {
        Ok(text) => text,
        Err(error) => {
            eprintln!("error: {}: {error}", path.display());
            return ExitCode::from(2);
        }
    };
    let parse = Parse::new(&text, Dialect::Cnc8x6);
    let lines = LineIndex::new(&text);
    let mut out = String::new();
    for block in parse.tree().blocks() {
        let line = lines.line_col(block.syntax().text_range().start()).line + 1;
        let _ = writeln!(out, "{line:>6}  {}", BlockData::lower(block.syntax().green()));
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

fn summary(path: &Path, ran: &Ran, timing: &Timing) -> String {
    let trace = &ran.trace;
    let mut out = String::new();
    let (feed, rapid) = (Motion::Feed, Motion::Rapid);
    let totals = trace.totals_with(timing.profiles.iter().map(|profile| profile.duration));
    let _ = writeln!(out, "{}", path.display());
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
    let tools: Vec<String> = trace.tools.iter().map(|tool| format!("T{tool}")).collect();
    let _ = writeln!(out, "  tools        {}", if tools.is_empty() { "none".to_owned() } else { tools.join(" ") });
    // Turners read the diameter axis as a diameter; the trace keeps radii.
    let as_written = |axis: u8, value: f64| if trace.diameter_axis == Some(axis) { 2.0 * value } else { value };
    let position: Vec<String> = trace
        .axes
        .iter()
        .zip(trace.end())
        .map(|(&axis, value)| format!("{}{:.3}", char::from(axis), as_written(axis, value)))
        .collect();
    let diameter = trace.diameter_axis.map(|axis| format!(" ({} as a diameter)", char::from(axis))).unwrap_or_default();
    let _ = writeln!(out, "  end position {}{diameter}", position.join(" "));
    if !timing.breaks.is_empty() {
        let lost: f64 = timing.breaks.iter().map(|b| b.lost).sum();
        let count = timing.breaks.len();
        let mut by_reason: Vec<(&str, usize)> = Vec::new();
        for speed_break in &timing.breaks {
            let code = speed_break.reason.code();
            match by_reason.iter_mut().find(|(known, _)| *known == code) {
                Some((_, n)) => *n += 1,
                None => by_reason.push((code, 1)),
            }
        }
        by_reason.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
        let by_reason: Vec<String> = by_reason.iter().map(|(code, n)| format!("{n} {code}")).collect();
        let _ = writeln!(
            out,
            "  breaks       {count} where the path speed drops ({}), costing {}",
            by_reason.join(", "),
            clock(lost)
        );
        // The costliest places the program could avoid: a block that runs
        // many times (a loop, a subprogram) is one place.
        let place_of = |speed_break: &velocity::Break| {
            let step = &trace.steps[speed_break.step];
            (step.source, step.range.start(), speed_break.reason.code())
        };
        // Grouped by place. A program without loops or calls meets its
        // places in order, and needs no sort.
        let avoidable = timing.breaks.iter().filter(|speed_break| speed_break.reason.avoidable());
        let in_order = avoidable.clone().zip(avoidable.clone().skip(1)).all(|(a, b)| {
            let (a, b) = (&trace.steps[a.step], &trace.steps[b.step]);
            (a.source, a.range.start()) <= (b.source, b.range.start())
        });
        let avoidable: Box<dyn Iterator<Item = &velocity::Break>> = if in_order {
            Box::new(avoidable)
        } else {
            let mut sorted: Vec<((usize, TextSize, &str), &velocity::Break)> =
                avoidable.map(|speed_break| (place_of(speed_break), speed_break)).collect();
            sorted.sort_by_key(|&(place, _)| place);
            Box::new(sorted.into_iter().map(|(_, speed_break)| speed_break))
        };
        // Each place's first break, its runs and its cost; the costliest kept.
        let mut top: Vec<(&velocity::Break, usize, f64)> = Vec::with_capacity(LISTED_BREAKS + 1);
        let by_cost = |a: &(&velocity::Break, usize, f64), b: &(&velocity::Break, usize, f64)| {
            b.2.total_cmp(&a.2).then(a.0.step.cmp(&b.0.step))
        };
        let mut keep = |place| {
            if top.len() == LISTED_BREAKS && top.last().is_some_and(|last| by_cost(&place, last).is_ge()) {
                return;
            }
            top.push(place);
            top.sort_by(by_cost);
            top.truncate(LISTED_BREAKS);
        };
        let mut listed = 0;
        let mut current: Option<(&velocity::Break, usize, f64)> = None;
        for speed_break in avoidable {
            match &mut current {
                Some((first, times, lost)) if place_of(first) == place_of(speed_break) => {
                    *times += 1;
                    *lost += speed_break.lost;
                }
                _ => {
                    listed += 1;
                    if let Some(place) = current.replace((speed_break, 1, speed_break.lost)) {
                        keep(place);
                    }
                }
            }
        }
        if let Some(place) = current {
            keep(place);
        }
        for (speed_break, times, lost) in top {
            let step = &trace.steps[speed_break.step];
            let place = ran.sources[step.source].place(step.range.start());
            let times = if times > 1 { format!(" ({times} runs)") } else { String::new() };
            let (reason, before, at) = (speed_break.reason, speed_break.before, speed_break.at);
            let _ = writeln!(out, "    {place}  {reason}: {before:.0} → {at:.0} mm/min, {lost:.3} s{times}");
        }
        if listed > LISTED_BREAKS {
            let _ = writeln!(out, "    … and {} more places (--format json lists every break)", listed - LISTED_BREAKS);
        }
    }
    out
}

/// `ncc run --format json`, written as it is serialised: a run of a
/// million blocks never holds its records in memory.
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
    tools: &'a [u32],
    end_position: Values<'a>,
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
        Report {
            file: path.display().to_string(),
            total_time_s: totals.total_time,
            programmed_time_s: totals.programmed_time,
            cutting_time_s: totals.time(Motion::Feed),
            rapid_time_s: totals.time(Motion::Rapid),
            dwell_time_s: totals.time(Motion::Dwell),
            cutting_length_mm: totals.length(Motion::Feed),
            rapid_length_mm: totals.length(Motion::Rapid),
            tools: &trace.tools,
            end_position: Values(trace.end(), axes),
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
            findings: trace
                .findings
                .iter()
                .map(|finding| FindingRecord {
                    file: &sources[finding.source].name,
                    line: sources[finding.source].line(finding.range.start()),
                    message: &finding.message,
                    stopped: finding.fatal,
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
        serializer.collect_seq(steps.map(|(index, ((step, profile), start_time))| {
            let source = &self.sources[step.source];
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
                    program: Values(self.trace.start_of(index), &self.trace.axes),
                    machine: Values(self.trace.machine_start(index), &self.trace.axes),
                },
                end: Coordinates {
                    program: Values(step.end, &self.trace.axes),
                    machine: Values(self.trace.machine_end(index), &self.trace.axes),
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

#[derive(Serialize)]
struct Coordinates<'a> {
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
/// (`G72 L9001` calls the file `L9001`, with or without an extension) and
/// the machine's cycle file, by name. It looks beside the program first,
/// then anywhere in its project, the directory of its `ncc.toml`.
struct Library {
    candidates: Vec<PathBuf>,
    /// The files read, with their text.
    read: RefCell<Vec<(Called, PathBuf, String)>>,
    /// A spinner on stderr once a run is long enough to wait for, when a
    /// person is watching.
    progress: OnceCell<ProgressBar>,
}

impl Library {
    fn for_program(path: &Path) -> Library {
        let directory = path.parent().filter(|dir| !dir.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let beside = std::fs::read_dir(directory).into_iter().flatten().flatten().map(|entry| entry.path());
        let project = Config::find_for(path).and_then(|config| Some(config.parent()?.to_path_buf()));
        let in_project = project.map(|root| check::collect_files(&[root]).0).unwrap_or_default();
        let candidates = beside.chain(in_project).filter(|path| path.is_file()).collect();
        Library { candidates, read: RefCell::default(), progress: OnceCell::new() }
    }

    fn read(&self, called: Called, matches: impl Fn(&Path) -> bool) -> Option<String> {
        let path = self.candidates.iter().find(|path| matches(path))?;
        let text = check::read_program(path).ok()?;
        self.read.borrow_mut().push((called, path.clone(), text.clone()));
        Some(text)
    }

    /// The program and the files the run read, in the trace's source order.
    fn sources(&self, path: &Path, text: String, trace: &Trace) -> Vec<Source> {
        let read = self.read.take();
        let source = |path: &Path, text: &str| Source { name: path.display().to_string(), lines: LineIndex::new(text) };
        let files = trace.files.iter().filter_map(|called| read.iter().find(|(c, _, _)| c == called));
        std::iter::once(source(path, &text)).chain(files.map(|(_, path, text)| source(path, text))).collect()
    }
}

impl Environment for Library {
    fn macrocycle(&self, number: u32) -> Option<String> {
        self.read(Called::Macrocycle(number), |path| check::macrocycle_number(path) == Some(number))
    }

    fn cycle_file(&self, name: &str) -> Option<String> {
        let named =
            |path: &Path| path.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.eq_ignore_ascii_case(name));
        self.read(Called::CycleFile, named)
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
    lines: LineIndex,
}

impl Source {
    fn line(&self, offset: TextSize) -> u32 {
        self.lines.line_col(offset).line + 1
    }

    /// `path:line`.
    fn place(&self, offset: TextSize) -> String {
        format!("{}:{}", self.name, self.line(offset))
    }
}
