//! `ncc run FILE`: runs a program on the executor and prints what the
//! machine would do: the time split into cutting, rapid and dwell, the
//! path lengths, the tools and the end position; `--format json` adds a
//! record per block.

use std::{
    cell::RefCell,
    collections::BTreeMap,
    path::{Path, PathBuf},
    process::ExitCode,
};

use line_index::LineIndex;
use nc_exec::run::{Motion, Position, Trace};
use ncc_analysis::Config;
use ncc_syntax::{Dialect, Parse, TextSize};
use serde_json::{Value, json};

use crate::check;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Format {
    Human,
    Json,
}

pub(crate) fn run(path: &Path, format: Format, step_budget: usize) -> ExitCode {
    let text = match check::read_program(path) {
        Ok(text) => text,
        Err(error) => {
            eprintln!("error: {}: {error}", path.display());
            return ExitCode::from(2);
        }
    };
    let config = match Config::find_for(path).map(|config| check::load_config(&config)).transpose() {
        Ok(config) => config.unwrap_or_default(),
        Err(error) => {
            eprintln!("error: {error}");
            return ExitCode::from(2);
        }
    };
    let parse = Parse::new(&text, Dialect::Cnc8x6);
    let library = Library::for_program(path);
    let trace = nc_exec::run::run(&parse, &|number| library.load(number), &config.machine, step_budget);
    let sources = library.sources(path, text, &trace);
    let place = |source: usize, offset| sources[source].place(offset);
    let axes = &config.machine.axes;
    match format {
        Format::Human => print_summary(path, &trace, axes, &place),
        Format::Json => {
            let output = json!({
                "file": path.display().to_string(),
                "total_time_s": trace.total_time(),
                "cutting_time_s": trace.time_in(Motion::Feed),
                "rapid_time_s": trace.time_in(Motion::Rapid),
                "dwell_time_s": trace.time_in(Motion::Dwell),
                "cutting_length_mm": trace.length_in(Motion::Feed),
                "rapid_length_mm": trace.length_in(Motion::Rapid),
                "tools": trace.tools,
                "end_position": position_json(&trace.end_position(), axes),
                "blocks": trace.steps.iter().map(|step| {
                    let (start, end) = (position_json(&step.start, axes), position_json(&step.end, axes));
                    json!({
                    "file": sources[step.source].path.display().to_string(),
                    "line": sources[step.source].line(step.range.start()),
                    "motion": match step.motion {
                        Motion::None => "none",
                        Motion::Rapid => "rapid",
                        Motion::Feed => "feed",
                        Motion::Dwell => "dwell",
                    },
                    "start_time_s": step.start_time,
                    "duration_s": step.duration,
                    "length_mm": step.length,
                    "feed_mm_min": step.feed,
                    // Program and machine coordinates coincide until the
                    // executor runs zero offsets.
                    "start": { "program": start.clone(), "machine": start },
                    "end": { "program": end.clone(), "machine": end },
                })}).collect::<Vec<Value>>(),
                "findings": trace.findings.iter().map(|finding| json!({
                    "file": sources[finding.source].path.display().to_string(),
                    "line": sources[finding.source].line(finding.range.start()),
                    "message": finding.message,
                    "stopped": finding.fatal,
                })).collect::<Vec<Value>>(),
            });
            println!("{output:#}");
        }
    }
    if trace.findings.iter().any(|finding| finding.fatal) { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

fn print_summary(path: &Path, trace: &Trace, axes: &[u8], place: &dyn Fn(usize, TextSize) -> String) {
    for finding in &trace.findings {
        eprintln!("{}: {}", place(finding.source, finding.range.start()), finding.message);
    }
    println!("{}", path.display());
    println!("  total time   {}", clock(trace.total_time()));
    println!("    cutting    {}  {:>12.3} mm", clock(trace.time_in(Motion::Feed)), trace.length_in(Motion::Feed));
    println!("    rapid      {}  {:>12.3} mm", clock(trace.time_in(Motion::Rapid)), trace.length_in(Motion::Rapid));
    println!("    dwell      {}", clock(trace.time_in(Motion::Dwell)));
    let tools: Vec<String> = trace.tools.iter().map(|tool| format!("T{tool}")).collect();
    println!("  tools        {}", if tools.is_empty() { "none".to_owned() } else { tools.join(" ") });
    let end = trace.end_position();
    let position: Vec<String> =
        axes.iter().map(|&axis| format!("{}{:.3}", char::from(axis), end[usize::from(axis - b'A')])).collect();
    println!("  end position {}", position.join(" "));
}

/// Where a run finds macrocycle files (`G72 L9001` calls the file `L9001`,
/// with or without an extension): beside the program first, then anywhere
/// in its project, the directory of its `ncc.toml`.
struct Library {
    candidates: Vec<PathBuf>,
    /// The files read, by number, with their text.
    read: RefCell<BTreeMap<u32, (PathBuf, String)>>,
}

impl Library {
    fn for_program(path: &Path) -> Library {
        let beside = check::macrocycles_beside(&[(path.to_path_buf(), String::new())]).into_iter().map(|(p, _)| p);
        let project = Config::find_for(path).and_then(|config| Some(config.parent()?.to_path_buf()));
        let in_project = project.map(|root| check::collect_files(&[root]).0).unwrap_or_default();
        let candidates = beside.chain(in_project.into_iter().filter(|path| check::is_macrocycle(path))).collect();
        Library { candidates, read: RefCell::default() }
    }

    fn load(&self, number: u32) -> Option<Parse> {
        let path = self.candidates.iter().find(|path| check::macrocycle_number(path) == Some(number))?;
        let text = check::read_program(path).ok()?;
        let parse = Parse::new(&text, Dialect::Cnc8x6);
        self.read.borrow_mut().insert(number, (path.clone(), text));
        Some(parse)
    }

    /// The program and the macrocycle files in the trace's source order.
    fn sources(&self, path: &Path, text: String, trace: &Trace) -> Vec<Source> {
        let mut read = self.read.take();
        let program = Source { path: path.to_path_buf(), lines: LineIndex::new(&text) };
        let macrocycles = trace.macrocycles.iter().filter_map(|number| read.remove(number));
        std::iter::once(program)
            .chain(macrocycles.map(|(path, text)| Source { path, lines: LineIndex::new(&text) }))
            .collect()
    }
}

/// A file a run read, for locating its blocks.
struct Source {
    path: PathBuf,
    lines: LineIndex,
}

impl Source {
    fn line(&self, offset: TextSize) -> u32 {
        self.lines.line_col(offset).line + 1
    }

    /// `path:line`.
    fn place(&self, offset: TextSize) -> String {
        format!("{}:{}", self.path.display(), self.line(offset))
    }
}

/// `h:mm:ss.sss`.
fn clock(seconds: f64) -> String {
    // An empty sum of floats is -0.0, which would print with a sign.
    let whole = if seconds > 0.0 { seconds } else { 0.0 };
    let hours = (whole / 3600.0).floor();
    let minutes = ((whole - hours * 3600.0) / 60.0).floor();
    format!("{hours}:{minutes:02}:{:06.3}", whole - hours * 3600.0 - minutes * 60.0)
}

fn position_json(position: &Position, axes: &[u8]) -> Value {
    axes.iter().map(|&axis| (char::from(axis).to_string(), json!(position[usize::from(axis - b'A')]))).collect()
}
