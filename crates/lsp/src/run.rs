//! `ncc run FILE`: runs a program on the executor and prints what the
//! machine would do: the time split into cutting, rapid and dwell, the
//! path lengths, the tools and the end position; `--format json` adds a
//! record per block.

use std::{path::Path, process::ExitCode};

use line_index::LineIndex;
use nc_exec::run::{Motion, Position, Trace};
use ncc_analysis::Config;
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
    let parse = ncc_syntax::Parse::new(&text, ncc_syntax::Dialect::Cnc8x6);
    let trace = nc_exec::run::run(&parse, &config.machine, step_budget);
    let lines = LineIndex::new(&text);
    let line = |offset| lines.line_col(offset).line + 1;
    let axes = &config.machine.axes;
    match format {
        Format::Human => print_summary(path, &trace, axes, &line),
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
                    "line": line(step.range.start()),
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
                    "line": line(finding.range.start()),
                    "message": finding.message,
                    "stopped": finding.fatal,
                })).collect::<Vec<Value>>(),
            });
            println!("{output:#}");
        }
    }
    if trace.findings.iter().any(|finding| finding.fatal) { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

fn print_summary(path: &Path, trace: &Trace, axes: &[u8], line: &dyn Fn(ncc_syntax::TextSize) -> u32) {
    for finding in &trace.findings {
        eprintln!("{}:{}: {}", path.display(), line(finding.range.start()), finding.message);
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

/// `h:mm:ss.sss`.
fn clock(seconds: f64) -> String {
    let whole = seconds.max(0.0);
    let hours = (whole / 3600.0).floor();
    let minutes = ((whole - hours * 3600.0) / 60.0).floor();
    format!("{hours}:{minutes:02}:{:06.3}", whole - hours * 3600.0 - minutes * 60.0)
}

fn position_json(position: &Position, axes: &[u8]) -> Value {
    axes.iter().map(|&axis| (char::from(axis).to_string(), json!(position[usize::from(axis - b'A')]))).collect()
}
