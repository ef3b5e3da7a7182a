//! `ncc-bench`: measurements of ncc against peer tools.
//!
//! ```text
//! cargo run --release -p ncc-bench -- parse [--dialect cnc8x6] [--blocks 1000000] [--runs 3]
//! cargo run --release -p ncc-bench -- generate --blocks 1000000 --syntax cnc8x6 -o big.NCP
//! cargo run --release -p ncc-bench -- generate --blocks 1000000 --syntax sinumerik-parametric -o param.MPF
//! cargo build --release -p ncc -p ncc-bench && target/release/ncc-bench lsp [--json]
//! cargo build --release -p ncc -p ncc-bench && target/release/ncc-bench lsp-memory [--edits 30000] [--json]
//! cargo build --release -p ncc -p ncc-bench && target/release/ncc-bench exec [--blocks 1000000] [--runs 3] [--json]
//! ```
#![allow(unsafe_code)] // The counting allocator below; nothing else.

mod lsp_memory;

use std::{
    alloc::{GlobalAlloc, Layout},
    hint::black_box,
    path::{Path, PathBuf},
    process::{Command as Process, Stdio},
    sync::atomic::{AtomicUsize, Ordering::Relaxed},
    time::{Duration, Instant},
};

use anyhow::Context;
use clap::{Parser, Subcommand, ValueEnum};
use ncc_analysis::Dialect;
use ncc_bench::{
    cnc8x6::progen::{self, Move, Syntax},
    edits::{self, Lcg},
    lsp_client::{self, Client, Document},
    rs274, sinumerik,
};
use ncc_syntax::Parse;
use serde_json::{Value, json};

/// mimalloc, counting the bytes in use and their peak.
struct CountingAlloc;

static IN_USE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded unchanged to mimalloc; the counters are
// only statistics.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let in_use = IN_USE.fetch_add(layout.size(), Relaxed) + layout.size();
        PEAK.fetch_max(in_use, Relaxed);
        unsafe { mimalloc::MiMalloc.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        IN_USE.fetch_sub(layout.size(), Relaxed);
        unsafe { mimalloc::MiMalloc.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            let in_use = IN_USE.fetch_add(new_size - layout.size(), Relaxed) + new_size - layout.size();
            PEAK.fetch_max(in_use, Relaxed);
        } else {
            IN_USE.fetch_sub(layout.size() - new_size, Relaxed);
        }
        unsafe { mimalloc::MiMalloc.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: CountingAlloc = CountingAlloc;

#[derive(Parser)]
#[command(about = "Benchmarks of ncc against peer tools")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Parse a generated surfacing program with ncc (lossless CST) and the
    /// same toolpath in NGC syntax with the `gcode` crate.
    Parse {
        #[command(flatten)]
        dialect: DialectArg,
        #[arg(long, default_value_t = 1_000_000)]
        blocks: usize,
        /// Timed runs per parser; the best one counts.
        #[arg(long, default_value_t = 3)]
        runs: usize,
    },
    /// Time incremental reparses after single-character edits at random
    /// places of a generated program, against a full parse.
    Reparse {
        #[command(flatten)]
        dialect: DialectArg,
        #[arg(long, default_value_t = 100_000)]
        blocks: usize,
        #[arg(long, default_value_t = 200)]
        edits: usize,
    },
    /// Check a generated program with the full analysis: time and peak heap.
    Check {
        #[command(flatten)]
        dialect: DialectArg,
        #[arg(long, default_value_t = 1_000_000)]
        blocks: usize,
    },
    /// Drive the language server (`ncc lsp`) through an editing session on a
    /// generated program: time from each single-character edit to its
    /// diagnostics, of a hover after each edit, of hovers anywhere after a
    /// pause, and from an edit that changes a block's time to the inlay
    /// hint that shows the new time.
    Lsp {
        /// The `ncc` binary [default: the one beside ncc-bench].
        #[arg(long)]
        server: Option<PathBuf>,
        #[command(flatten)]
        dialect: DialectArg,
        #[arg(long, default_value_t = 100_000)]
        blocks: usize,
        #[arg(long, default_value_t = 200)]
        edits: usize,
        /// Print the results as one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Drive the language server (`ncc lsp`) through a long editing session
    /// on a generated program at an editor's pace, and print its resident
    /// memory every `--sample-every` edits and after the document closes.
    LspMemory {
        /// The `ncc` binary [default: the one beside ncc-bench].
        #[arg(long)]
        server: Option<PathBuf>,
        #[command(flatten)]
        dialect: DialectArg,
        #[arg(long, default_value_t = 100_000)]
        blocks: usize,
        #[arg(long, default_value_t = 30_000)]
        edits: usize,
        #[arg(long, default_value_t = 1_000)]
        sample_every: usize,
        /// Every this many edits, wait until the server has finished its
        /// background work (complete diagnostics, cycle-time estimate).
        #[arg(long, default_value_t = 100)]
        pause_every: usize,
        /// Print the results as one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Run a generated surfacing program with `ncc run` and the same
    /// toolpath in NGC syntax with LinuxCNC's `rs274 -g`, each a process
    /// whose output is discarded.
    Exec {
        /// The `ncc` binary [default: the one beside ncc-bench].
        #[arg(long)]
        ncc: Option<PathBuf>,
        #[command(flatten)]
        dialect: DialectArg,
        #[arg(long, default_value_t = 1_000_000)]
        blocks: usize,
        /// Timed runs of each; the best one counts.
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Print the results as one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Parse a file once (for profilers such as perf or callgrind).
    ParseFile {
        path: PathBuf,
        #[command(flatten)]
        dialect: DialectArg,
        /// Threads for ncc.
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Parse with the `gcode` crate instead (the file must be NGC).
        #[arg(long)]
        gcode: bool,
    },
    /// Write a generated program.
    Generate {
        #[arg(long, default_value_t = 1_000_000)]
        blocks: usize,
        #[arg(long, value_enum, default_value_t = SyntaxArg::Cnc8x6)]
        syntax: SyntaxArg,
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// The dialect of the programs a benchmark reads.
#[derive(clap::Args)]
struct DialectArg {
    /// The dialect's name.
    #[arg(long = "dialect", value_name = "NAME", default_value_t = Dialect::default())]
    id: Dialect,
}

/// The toolpath `moves` as a program of `dialect`.
fn program_text(dialect: Dialect, moves: &[Move]) -> String {
    match dialect {
        Dialect::Cnc8x6 => progen::write(moves, Syntax::Cnc8x6),
        Dialect::HaasLathe => progen::write(moves, Syntax::HaasLathe),
        Dialect::Sinumerik => progen::write(moves, Syntax::Sinumerik),
    }
}

/// The generated surfacing program of `blocks` blocks in `dialect`.
fn generated_program(dialect: Dialect, blocks: usize) -> String {
    program_text(dialect, &progen::surfacing(blocks))
}

/// The name of the generated program's file: the dialect's extension.
fn program_file_name(dialect: Dialect) -> String {
    let extension = dialect.default_extensions().first().copied().unwrap_or_default();
    format!("surface.{extension}")
}

/// A place inside a code word of a generated program near `offset`, to
/// hover.
pub(crate) fn code_near(dialect: Dialect, text: &str, offset: usize, rng: &mut Lcg) -> Option<usize> {
    match dialect {
        Dialect::Cnc8x6 => progen::g_code_near(text, offset, rng),
        Dialect::HaasLathe => progen::g_code_near(text, offset, rng),
        Dialect::Sinumerik => progen::g_code_near(text, offset, rng),
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum SyntaxArg {
    Cnc8x6,
    Ngc,
    HaasLathe,
    Sinumerik,
    /// A parametric Sinumerik program rather than CAM output.
    SinumerikParametric,
}

fn main() -> anyhow::Result<()> {
    match Cli::parse().command {
        Command::Parse { dialect, blocks, runs } => parse_benchmark(dialect.id, blocks, runs.max(1)),
        Command::Reparse { dialect, blocks, edits } => reparse_benchmark(dialect.id, blocks, edits),
        Command::Check { dialect, blocks } => check_benchmark(dialect.id, blocks),
        Command::Lsp { server, dialect, blocks, edits, json } => {
            let dialect = dialect.id;
            lsp_benchmark(&server.map_or_else(ncc_beside_bench, Ok)?, dialect, blocks, edits, json)
        }
        Command::LspMemory { server, dialect, blocks, edits, sample_every, pause_every, json } => {
            let dialect = dialect.id;
            lsp_memory::run(
                &server.map_or_else(ncc_beside_bench, Ok)?,
                &lsp_memory::Options { dialect, blocks, edits, sample_every, pause_every, json },
            )
        }
        Command::Exec { ncc, dialect, blocks, runs, json } => {
            let dialect = dialect.id;
            exec_benchmark(&ncc.map_or_else(ncc_beside_bench, Ok)?, dialect, blocks, runs.max(1), json)
        }
        Command::ParseFile { path, dialect, threads, gcode } => {
            let dialect = dialect.id;
            let text = std::fs::read_to_string(&path)?;
            let start = Instant::now();
            if gcode {
                let program = gcode::parse(&text).map_err(|e| anyhow::anyhow!("{e:?}"))?;
                println!("{} blocks in {:?}", program.blocks.len(), start.elapsed());
                std::mem::forget(program);
            } else {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
                let parse = pool.install(|| Parse::new(&text, dialect));
                println!("{} errors in {:?}", parse.errors().len(), start.elapsed());
                std::mem::forget(parse);
            }
            Ok(())
        }
        Command::Generate { blocks, syntax, output } => {
            let syntax = match syntax {
                SyntaxArg::Cnc8x6 => Syntax::Cnc8x6,
                SyntaxArg::Ngc => Syntax::Ngc,
                SyntaxArg::HaasLathe => Syntax::HaasLathe,
                SyntaxArg::Sinumerik => Syntax::Sinumerik,
                SyntaxArg::SinumerikParametric => {
                    let text = sinumerik::parametric(blocks);
                    return std::fs::write(&output, text).with_context(|| format!("writing {}", output.display()));
                }
            };
            let text = progen::write(&progen::surfacing(blocks), syntax);
            std::fs::write(&output, text).with_context(|| format!("writing {}", output.display()))
        }
    }
}

/// The `ncc` binary of the same build as this one.
fn ncc_beside_bench() -> anyhow::Result<PathBuf> {
    Ok(std::env::current_exe()?.with_file_name(format!("ncc{}", std::env::consts::EXE_SUFFIX)))
}

struct Measurement {
    best: Duration,
    /// Peak heap growth during one run, result included.
    peak_bytes: usize,
}

/// Runs `f` `runs` times; the best time and the largest peak count.
fn measure<T>(runs: usize, mut f: impl FnMut() -> T) -> Measurement {
    let mut best = Duration::MAX;
    let mut peak_bytes = 0;
    for _ in 0..runs {
        let base = IN_USE.load(Relaxed);
        PEAK.store(base, Relaxed);
        let start = Instant::now();
        let result = black_box(f());
        best = best.min(start.elapsed());
        peak_bytes = peak_bytes.max(PEAK.load(Relaxed) - base);
        drop(result);
    }
    Measurement { best, peak_bytes }
}

/// What the `gcode` crate reads beside a program of `dialect`: the same
/// bytes where it reads them (a Haas program is plain ISO code to it), else
/// the same toolpath in NGC (CNC8x6's header, `"` comments and `*` end, and
/// Sinumerik's header and `;` comments are not G-code it knows); and what
/// the output calls it.
fn gcode_input(dialect: Dialect, moves: &[Move], program: &str) -> (String, &'static str) {
    match dialect {
        Dialect::Cnc8x6 => (progen::write(moves, Syntax::Ngc), "NGC"),
        Dialect::HaasLathe => (program.to_owned(), "the same bytes"),
        Dialect::Sinumerik => (progen::write(moves, Syntax::Ngc), "NGC"),
    }
}

fn parse_benchmark(dialect: Dialect, blocks: usize, runs: usize) -> anyhow::Result<()> {
    let moves = progen::surfacing(blocks);
    let cnc = program_text(dialect, &moves);
    let (ngc, peer_input) = gcode_input(dialect, &moves, &cnc);
    drop(moves);

    // Sanity: both parsers accept their input completely.
    let parse = Parse::new(&cnc, dialect);
    anyhow::ensure!(parse.errors().is_empty(), "ncc found errors: {:?}", &parse.errors()[..1]);
    anyhow::ensure!(parse.tree().blocks().count() >= blocks, "ncc block count");
    drop(parse);
    let program = gcode::parse(&ngc).map_err(|e| anyhow::anyhow!("gcode rejected its input: {e:?}"))?;
    anyhow::ensure!(program.blocks.len() >= blocks, "gcode block count {}", program.blocks.len());
    drop(program);

    let threads = rayon::current_num_threads();
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    println!(
        "parse benchmark: {blocks} blocks; {} {:.1} MB, gcode reads {peer_input}, {:.1} MB; best of {runs} runs",
        dialect.title(),
        cnc.len() as f64 / 1e6,
        ngc.len() as f64 / 1e6
    );
    let gcode_rs = measure(runs, || gcode::parse(&ngc));
    let ncc_one = measure(runs, || single.install(|| Parse::new(&cnc, dialect)));
    let ncc_all = measure(runs, || Parse::new(&cnc, dialect));

    let rate = |m: &Measurement| blocks as f64 / m.best.as_secs_f64();
    let row = |name: &str, m: &Measurement| {
        println!(
            "  {name:<34} {:>9.1} ms {:>12.0} blocks/s {:>9.1} MB peak",
            m.best.as_secs_f64() * 1e3,
            rate(m),
            m.peak_bytes as f64 / 1e6
        );
    };
    row("gcode 0.7 (gcode::parse)", &gcode_rs);
    row("ncc lossless CST, 1 thread", &ncc_one);
    row(&format!("ncc lossless CST, {threads} threads"), &ncc_all);
    println!(
        "  speed ratio ncc/gcode:  {:.2}x (1 thread), {:.2}x ({threads} threads)   goal >= 2x",
        rate(&ncc_one) / rate(&gcode_rs),
        rate(&ncc_all) / rate(&gcode_rs)
    );
    println!(
        "  memory ratio ncc/gcode: {:.2}x (1 thread), {:.2}x ({threads} threads)   goal <= 1x",
        ncc_one.peak_bytes as f64 / gcode_rs.peak_bytes as f64,
        ncc_all.peak_bytes as f64 / gcode_rs.peak_bytes as f64
    );
    if dialect != progen::REFERENCE {
        print_ratios_to_cnc8x6(dialect, blocks, runs)?;
    }
    Ok(())
}

/// How much slower per byte than CNC8x6 another dialect may parse.
const PER_BYTE_GOAL: f64 = 1.3;

/// Programs of `dialect` that are not CAM output, by name, of about
/// `blocks` lines.
fn other_programs(dialect: Dialect, blocks: usize) -> Vec<(&'static str, String)> {
    match dialect {
        Dialect::Sinumerik => vec![("parametric program", sinumerik::parametric(blocks))],
        Dialect::Cnc8x6 => Vec::new(),
        Dialect::HaasLathe => Vec::new(),
    }
}

/// Prints the parse throughput per byte of `dialect`'s programs of about
/// `blocks` lines (its CAM output and its other programs) as a ratio to
/// that of CNC8x6 CAM output of the same size, on one thread and on all.
fn print_ratios_to_cnc8x6(dialect: Dialect, blocks: usize, runs: usize) -> anyhow::Result<()> {
    let threads = rayon::current_num_threads();
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let bytes_per_s = |text: &str, dialect: Dialect| {
        let one = measure(runs, || single.install(|| Parse::new(text, dialect)));
        let all = measure(runs, || Parse::new(text, dialect));
        [one, all].map(|m| text.len() as f64 / m.best.as_secs_f64())
    };
    let sample = 10_000;
    let cnc_block_len = program_text(progen::REFERENCE, &progen::surfacing(sample)).len() as f64 / sample as f64;
    println!(
        "  {} per byte against CNC8x6 CAM output of the same size (1.00x as fast, goal >= {:.2}x on 1 thread):",
        dialect.title(),
        1.0 / PER_BYTE_GOAL
    );
    let mut programs = vec![("CAM G1 program", generated_program(dialect, blocks))];
    programs.extend(other_programs(dialect, blocks));
    for (name, text) in programs {
        anyhow::ensure!(Parse::new(&text, dialect).errors().is_empty(), "ncc found errors in the {name}");
        let cnc = program_text(progen::REFERENCE, &progen::surfacing((text.len() as f64 / cnc_block_len) as usize));
        let [cnc_one, cnc_all] = bytes_per_s(&cnc, progen::REFERENCE);
        let [one, all] = bytes_per_s(&text, dialect);
        println!(
            "    {name:<20} {:>6.1} MB  {:.2}x (1 thread), {:.2}x ({threads} threads)",
            text.len() as f64 / 1e6,
            one / cnc_one,
            all / cnc_all
        );
    }
    Ok(())
}

/// The seed of the random edits: the same edits on every run.
const SEED: u64 = 0x2545_F491_4F6C_DD1D;

/// The `p` quantile of sorted, non-empty samples.
fn percentile(sorted: &[Duration], p: f64) -> Duration {
    sorted[((sorted.len() - 1) as f64 * p) as usize]
}

fn reparse_benchmark(dialect: Dialect, blocks: usize, edits: usize) -> anyhow::Result<()> {
    use ncc_syntax::{TextEdit, TextRange, TextSize};

    let mut text = generated_program(dialect, blocks);
    let start = Instant::now();
    let mut parse = Parse::new(&text, dialect);
    let full = start.elapsed();

    let mut rng = Lcg::new(SEED);
    let mut times = Vec::with_capacity(edits);
    for _ in 0..edits {
        let at = (0..=rng.below(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
        let insert = ["1", " ", "X", "\n", "-", "."][rng.below(6)];
        let delete = if rng.below(2) == 0 && at < text.len() && text.is_char_boundary(at + 1) { 1 } else { 0 };
        let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::from(delete)), insert);
        edit.apply(&mut text);
        let start = Instant::now();
        parse = parse.reparse(&edit, &text);
        times.push(start.elapsed());
    }
    anyhow::ensure!(parse == Parse::new(&text, dialect), "incremental result differs from a full parse");
    times.sort();
    println!("reparse benchmark: {blocks} blocks ({:.1} MB), {edits} single-character edits", text.len() as f64 / 1e6);
    println!("  full parse   {:>9.3} ms", full.as_secs_f64() * 1e3);
    println!("  reparse p50  {:>9.3} ms", percentile(&times, 0.5).as_secs_f64() * 1e3);
    println!("  reparse p99  {:>9.3} ms", percentile(&times, 0.99).as_secs_f64() * 1e3);
    Ok(())
}

fn check_benchmark(dialect: Dialect, blocks: usize) -> anyhow::Result<()> {
    let text = generated_program(dialect, blocks);
    let mb = text.len() as f64 / 1e6;
    let base = IN_USE.load(Relaxed);
    PEAK.store(base, Relaxed);
    let start = Instant::now();
    let mut host = ncc_analysis::AnalysisHost::in_dialect(dialect, ncc_analysis::Config::default());
    let file = host.add_file(program_file_name(dialect), text);
    let parsed = start.elapsed();
    let after_parse = IN_USE.load(Relaxed) - base;
    let diagnostics = host.analysis().diagnostics(file);
    let total = start.elapsed();
    // Hints and infos (short moves without a compressor, an arc without
    // nose compensation) are advice on a valid program.
    let problems: Vec<_> = diagnostics.iter().filter(|d| d.severity >= ncc_analysis::Severity::Warning).collect();
    anyhow::ensure!(problems.is_empty(), "findings in a generated program: {:?}", &problems[..1]);
    println!("check benchmark: {blocks} blocks ({mb:.1} MB)");
    println!("  parse            {:>9.1} ms", parsed.as_secs_f64() * 1e3);
    println!(
        "  parse + analysis {:>9.1} ms ({:.0} blocks/s)",
        total.as_secs_f64() * 1e3,
        blocks as f64 / total.as_secs_f64()
    );
    println!(
        "  heap after parse {:>9.1} MB, held at the end {:.1} MB",
        after_parse as f64 / 1e6,
        (IN_USE.load(Relaxed) - base) as f64 / 1e6
    );
    println!(
        "  peak heap        {:>9.1} MB ({:.0} bytes per block)",
        (PEAK.load(Relaxed) - base) as f64 / 1e6,
        (PEAK.load(Relaxed) - base) as f64 / blocks as f64
    );
    Ok(())
}

/// The latency goals of the language server.
const EDIT_GOAL: Duration = Duration::from_millis(16);
const HOVER_GOAL: Duration = Duration::from_millis(2);
const CYCLE_TIME_GOAL: Duration = Duration::from_millis(16);
/// Edits without a new time, and none with one, after which the cycle-time
/// latency is given up.
const UNFOLLOWED_EDITS: usize = 10;
/// The pause after the edits, and the hovers at random places after it.
const IDLE: Duration = Duration::from_secs(3);
const IDLE_HOVERS: usize = 100;
/// The longest the hint edits wait for the estimate of the text typed back
/// as generated (a run of most of it).
const RESTORED_ESTIMATE: Duration = Duration::from_secs(20);
/// Thread round trips measured during the pause.
const WAKE_UPS: usize = 1000;

/// Latencies of one kind, and the goal for their 99th percentile.
struct Latencies {
    name: &'static str,
    goal: Option<Duration>,
    samples: Vec<Duration>,
}

impl Latencies {
    fn new(name: &'static str, goal: Duration, capacity: usize) -> Latencies {
        Latencies { name, goal: Some(goal), samples: Vec::with_capacity(capacity) }
    }

    /// p50, p90, p99 and max.
    fn quantiles(&self) -> [Duration; 4] {
        let mut sorted = self.samples.clone();
        sorted.sort();
        [percentile(&sorted, 0.5), percentile(&sorted, 0.9), percentile(&sorted, 0.99), percentile(&sorted, 1.0)]
    }

    fn met(&self) -> Option<bool> {
        self.goal.map(|goal| self.quantiles()[2] < goal)
    }

    fn json(&self) -> Value {
        let [p50, p90, p99, max] = self.quantiles().map(|d| d.as_secs_f64() * 1e3);
        let goal = self.goal.map(|goal| goal.as_secs_f64() * 1e3);
        json!({ "p50_ms": p50, "p90_ms": p90, "p99_ms": p99, "max_ms": max, "goal_p99_ms": goal, "met": self.met() })
    }

    fn print(&self) {
        let [p50, p90, p99, max] = self.quantiles().map(|d| d.as_secs_f64() * 1e3);
        let goal = match (self.goal, self.met()) {
            (Some(goal), Some(met)) => {
                format!("   goal p99 < {} ms: {}", goal.as_millis(), if met { "met" } else { "NOT met" })
            }
            _ => String::new(),
        };
        println!(
            "  {:<22} p50 {p50:>7.2} ms  p90 {p90:>7.2} ms  p99 {p99:>7.2} ms  max {max:>7.2} ms{goal}",
            self.name
        );
    }
}

/// The machine's CPU time so far, from `/proc/stat` (Linux).
struct CpuTimes {
    /// Ticks of every kind, and those a hypervisor gave to other guests.
    total: u64,
    steal: u64,
}

impl CpuTimes {
    fn now() -> Option<CpuTimes> {
        let stat = std::fs::read_to_string("/proc/stat").ok()?;
        let ticks: Vec<u64> = stat.lines().next()?.split_whitespace().skip(1).map_while(|n| n.parse().ok()).collect();
        // user nice system idle iowait irq softirq steal (guest time is
        // counted in user already).
        let (total, steal) = (ticks.iter().take(8).sum(), *ticks.get(7)?);
        Some(CpuTimes { total, steal })
    }

    /// The share of the time since `before` that the machine's CPUs did
    /// not get: a virtual machine on a busy host is slow at random moments,
    /// which shows in every percentile above.
    fn stolen_since(&self, before: &CpuTimes) -> f64 {
        let total = self.total.saturating_sub(before.total);
        if total == 0 { 0.0 } else { self.steal.saturating_sub(before.steal) as f64 / total as f64 }
    }
}

/// How long a sleeping thread takes to start running after it is woken,
/// a few milliseconds after it went to sleep, while the waking thread
/// stays on its core: what every hand-over between threads costs on this
/// machine now. On a virtual machine a woken thread may have to wait for
/// the hypervisor to run an idle virtual CPU again. A request to the
/// server and its answer pass through several threads on both sides, so
/// this tells a noisy machine from a slow server.
fn wake_ups(count: usize) -> Latencies {
    use std::sync::{
        Arc,
        atomic::{AtomicBool, AtomicU64},
    };
    let epoch = Instant::now();
    let woken_at = Arc::new(AtomicU64::new(0));
    let stop = Arc::new(AtomicBool::new(false));
    let sleeper = {
        let (woken_at, stop) = (woken_at.clone(), stop.clone());
        std::thread::spawn(move || {
            while !stop.load(Relaxed) {
                std::thread::park();
                woken_at.store(epoch.elapsed().as_nanos() as u64, Relaxed);
            }
        })
    };
    let mut latencies = Latencies { name: "thread wake-ups", goal: None, samples: Vec::with_capacity(count) };
    for _ in 0..count {
        std::thread::sleep(Duration::from_millis(2));
        woken_at.store(0, Relaxed);
        let woken = epoch.elapsed();
        sleeper.thread().unpark();
        // Spin, so that this thread's core stays busy.
        let deadline = Instant::now() + Duration::from_secs(1);
        while woken_at.load(Relaxed) == 0 && Instant::now() < deadline {
            std::hint::spin_loop();
        }
        let ran = Duration::from_nanos(woken_at.load(Relaxed));
        latencies.samples.push(ran.saturating_sub(woken));
    }
    stop.store(true, Relaxed);
    sleeper.thread().unpark();
    let _ = sleeper.join();
    latencies
}

/// The server at `server` started on a workspace that holds a generated
/// program of `blocks` blocks, and that program as a document not yet
/// opened; the workspace lasts as long as the returned directory.
pub(crate) fn serve_generated_program(
    server: &Path,
    dialect: Dialect,
    blocks: usize,
) -> anyhow::Result<(Client, tempfile::TempDir, Document)> {
    let text = generated_program(dialect, blocks);
    // Editors open files that exist: the server may look beside them, and
    // a closed document stays in the workspace as its file.
    let dir = tempfile::tempdir()?;
    let path = dir.path().join(program_file_name(dialect));
    std::fs::write(&path, &text)?;
    let mut process = Process::new(server);
    process.arg("lsp");
    let mut client = Client::spawn(process)?;
    // A slow answer is measured, only a missing one fails the run.
    client.timeout = Duration::from_secs(120);
    client.initialize(dir.path(), None)?;
    Ok((client, dir, Document::new(lsp_client::file_uri(&path), text)))
}

fn lsp_benchmark(server: &Path, dialect: Dialect, blocks: usize, edits: usize, as_json: bool) -> anyhow::Result<()> {
    anyhow::ensure!(edits > 0, "--edits must be at least 1");
    let (mut client, _workspace, mut doc) = serve_generated_program(server, dialect, blocks)?;
    let bytes = doc.text().len();
    let generated = doc.text().to_owned();
    let cpu_before = CpuTimes::now();
    let opened = client.notify("textDocument/didOpen", doc.did_open())?;
    let open = client.diagnostics(&doc.uri, doc.version)?.received - opened;

    let mut rng = Lcg::new(SEED);
    let mut diagnostics = Latencies::new("edit → diagnostics", EDIT_GOAL, edits);
    let mut hovers = Latencies::new("hover", HOVER_GOAL, edits);
    let mut empty_hovers = 0;
    for _ in 0..edits {
        let edit = edits::typing_edit(doc.text(), &mut rng).context("the program has no block to edit")?;
        let change = doc.change(edit.range.clone(), &edit.insert);
        let sent = client.notify("textDocument/didChange", change)?;
        diagnostics.samples.push(client.diagnostics(&doc.uri, doc.version)?.received - sent);

        let target = code_near(dialect, doc.text(), edit.range.start, &mut rng).context("no G code near the edit")?;
        let request = client.request("textDocument/hover", doc.at(doc.position(target)))?;
        let response = client.response(&request)?;
        anyhow::ensure!(response.error_code().is_none(), "hover failed: {}", response.json);
        hovers.samples.push(response.received - request.sent);
        if response.result().is_none_or(Value::is_null) {
            empty_hovers += 1;
        }
        // Anything else the server sent about this version (a later, more
        // complete diagnostics set, say) is not measured.
        client.take_received();
    }

    // After a pause in typing the server has prepared the whole program:
    // hovers anywhere. The machine is measured meanwhile.
    let started = Instant::now();
    let machine = wake_ups(WAKE_UPS);
    std::thread::sleep(IDLE.saturating_sub(started.elapsed()));
    let mut idle_hovers = Latencies::new("hover after a pause", HOVER_GOAL, IDLE_HOVERS);
    for _ in 0..IDLE_HOVERS {
        let anywhere = rng.below(doc.text().len());
        let target = code_near(dialect, doc.text(), anywhere, &mut rng).context("no G code in the program")?;
        let request = client.request("textDocument/hover", doc.at(doc.position(target)))?;
        let response = client.response(&request)?;
        anyhow::ensure!(response.error_code().is_none(), "hover failed: {}", response.json);
        idle_hovers.samples.push(response.received - request.sent);
    }
    // A dialect without an interpreter shows no block times to wait for.
    let cycle_times = if nc_exec::run::interprets(dialect) {
        // The typing above may have stopped the run early (a deleted digit
        // moves an arc's end off its circle), which leaves the blocks after
        // the stop without a time: the program is typed back as generated.
        let whole = 0..doc.text().len();
        client.take_received();
        client.notify("textDocument/didChange", doc.change(whole, &generated))?;
        client.diagnostics(&doc.uri, doc.version)?;
        // That text is estimated again from the first place the typing
        // changed: the edits measured come after it, as typing after a
        // paste, not while it runs. No refresh comes when an estimate of
        // that text is already kept.
        let refresh = |m: &lsp_client::Message| m.method() == Some("workspace/inlayHint/refresh");
        let _ = client.wait_for("the estimate of the restored text", RESTORED_ESTIMATE, refresh);
        Some(cycle_time_latencies(&mut client, &mut doc, edits, &mut rng)?)
    } else {
        None
    };
    let memory = client.memory();
    let stolen = cpu_before.zip(CpuTimes::now()).map(|(before, after)| after.stolen_since(&before));
    let exit = client.shutdown()?;

    let mb = bytes as f64 / 1e6;
    if as_json {
        let output = json!({
            "blocks": blocks,
            "bytes": bytes,
            "edits": edits,
            "open_to_diagnostics_ms": open.as_secs_f64() * 1e3,
            "edit_to_diagnostics": diagnostics.json(),
            "hover": hovers.json(),
            "hover_after_pause": idle_hovers.json(),
            "edit_to_cycle_time_hint": cycle_times.as_ref().filter(|(times, _)| !times.samples.is_empty()).map(|(times, _)| times.json()),
            "edits_without_a_new_time": cycle_times.as_ref().map(|(_, unchanged)| unchanged),
            "thread_wake_up": machine.json(),
            "cpu_time_stolen": stolen,
            "empty_hovers": empty_hovers,
            "peak_rss_bytes": memory.map(|m| m.peak_rss),
            "exit_code": exit.code(),
        });
        println!("{output:#}");
    } else {
        println!("lsp benchmark: {blocks} blocks ({mb:.1} MB), {edits} single-character edits, {}", server.display());
        println!("  didOpen → diagnostics  {:>9.1} ms", open.as_secs_f64() * 1e3);
        diagnostics.print();
        hovers.print();
        idle_hovers.print();
        match &cycle_times {
            Some((times, _)) if times.samples.is_empty() => {
                println!(
                    "  edit → cycle-time hint none of the first {UNFOLLOWED_EDITS} coordinate edits changed its line's time"
                );
            }
            Some((times, unchanged)) => {
                times.print();
                if *unchanged > 0 {
                    println!("  {unchanged} of {edits} coordinate edits left their line's time as it was");
                }
            }
            None => {
                println!("  edit → cycle-time hint not measured: ncc does not run {} programs yet", dialect.title())
            }
        }
        machine.print();
        if let Some(stolen) = stolen {
            println!("  CPU time stolen        {:>9.1} %  (the hypervisor ran other guests)", stolen * 100.0);
        }
        if empty_hovers > 0 {
            println!("  {empty_hovers} of {edits} hovers on a G code answered nothing");
        }
        match memory {
            Some(memory) => println!("  server peak RSS        {:>9.1} MB", memory.peak_rss as f64 / 1e6),
            None => println!("  server peak RSS        unknown (no /proc)"),
        }
    }
    anyhow::ensure!(exit.success(), "the server ended with {exit} after shutdown and exit");
    Ok(())
}

/// Edits that change a block's time, each timed until the inlay hints of
/// its line show a new time: a digit typed before a coordinate's digits
/// (`X12.4` to `X712.4`) lengthens the move. The server asks the client to
/// refresh the hints when an estimate is ready; each refresh is answered
/// by asking for the hints of the edited line. An edit whose line shows
/// the same time (or none) a second after the last refresh is counted
/// apart, not timed. When the first edits all leave their time as it was,
/// the hints do not follow edits, and the rest are not waited for.
fn cycle_time_latencies(
    client: &mut Client,
    doc: &mut Document,
    edits: usize,
    rng: &mut Lcg,
) -> anyhow::Result<(Latencies, usize)> {
    let mut latencies = Latencies::new("edit → cycle-time hint", CYCLE_TIME_GOAL, edits);
    let mut unchanged = 0;
    for _ in 0..edits {
        if latencies.samples.is_empty() && unchanged == UNFOLLOWED_EDITS {
            break;
        }
        let at = coordinate_digits(doc.text(), rng).context("no coordinate to edit")?;
        let line = doc.text()[..at].rfind('\n').map_or(0, |i| i + 1);
        let line_end = doc.text()[at..].find('\n').map_or(doc.text().len(), |i| at + i);
        let before = block_time_hint(client, doc, line..line_end)?;
        client.take_received();
        let sent = client.notify("textDocument/didChange", doc.change(at..at, "7"))?;
        let line_end = line_end + 1;
        // The first refresh may take a long time on a slow machine; a later
        // one for the same edit would come soon.
        let mut wait = client.timeout;
        loop {
            let refreshed =
                client.wait_for("an inlay hint refresh", wait, |m| m.method() == Some("workspace/inlayHint/refresh"));
            if refreshed.is_err() && wait < client.timeout {
                unchanged += 1;
                break;
            }
            refreshed?;
            let request = client.request(
                "textDocument/inlayHint",
                json!({
                    "textDocument": doc.id(),
                    "range": doc.range(line..line_end),
                }),
            )?;
            let response = client.response(&request)?;
            let now = block_time_label(&response);
            if now.is_some() && now != before {
                latencies.samples.push(response.received - sent);
                break;
            }
            wait = Duration::from_secs(1);
        }
    }
    Ok((latencies, unchanged))
}

/// The label of the block-time hint in the hints of `range`.
fn block_time_hint(
    client: &mut Client,
    doc: &Document,
    range: std::ops::Range<usize>,
) -> anyhow::Result<Option<String>> {
    let response =
        client.call("textDocument/inlayHint", json!({ "textDocument": doc.id(), "range": doc.range(range) }))?;
    Ok(block_time_label(&response))
}

/// A block's time is the hint that is neither a parameter value (`= …`)
/// nor a speed break (`▼ …`).
fn block_time_label(response: &lsp_client::Message) -> Option<String> {
    response
        .result()?
        .as_array()?
        .iter()
        .filter_map(|hint| hint["label"].as_str())
        .find(|label| !label.starts_with('=') && !label.starts_with('▼'))
        .map(str::to_owned)
}

/// Where a digit typed into the X, Y or Z value of a random straight move
/// goes: before its first digit. Not before an arc, whose start would move
/// off its circle, and the run would stop there.
fn coordinate_digits(text: &str, rng: &mut Lcg) -> Option<usize> {
    for _ in 0..1000 {
        let at = rng.below(text.len().max(1));
        let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
        let end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let line = &text[start..end];
        let next = text.get(end + 1..).and_then(|rest| rest.lines().next()).unwrap_or_default();
        let arc = |line: &str| line.split(' ').any(|word| word.starts_with(['I', 'J', 'K']));
        if !progen::is_linear_move(line) || arc(next) {
            continue;
        }
        let mut word_start = start;
        for word in line.split(' ') {
            if word.starts_with(['X', 'Y', 'Z'])
                && let Some(digit) = word.find(|c: char| c.is_ascii_digit())
            {
                return Some(word_start + digit);
            }
            word_start += word.len() + 1;
        }
    }
    None
}

fn exec_benchmark(ncc: &Path, dialect: Dialect, blocks: usize, runs: usize, as_json: bool) -> anyhow::Result<()> {
    let rs274 = rs274::find().context(rs274::MISSING)?;
    anyhow::ensure!(ncc.is_file(), "{} not found: cargo build --release -p ncc", ncc.display());
    let moves = progen::surfacing(blocks);
    let dir = tempfile::tempdir()?;
    let (cnc, ngc) = (dir.path().join(program_file_name(dialect)), dir.path().join("surface.ngc"));
    // On disk before the runs, so that writing them back does not run
    // beside one tool's runs and not the other's.
    let write_synced = |path: &Path, text: String| -> std::io::Result<()> {
        let mut file = std::fs::File::create(path)?;
        std::io::Write::write_all(&mut file, text.as_bytes())?;
        file.sync_all()
    };
    write_synced(&cnc, program_text(dialect, &moves))?;
    write_synced(&ngc, progen::write(&moves, Syntax::Ngc))?;
    drop(moves);
    let mut ncc_run = Process::new(ncc);
    ncc_run.arg("run").arg(&cnc).stdout(Stdio::null());
    let mut rs274_run = Process::new(&rs274);
    rs274_run.arg("-g").arg(&ngc).stdin(Stdio::null()).stdout(Stdio::null());

    // Each tool's runs one after the other, an untimed one first: on a
    // virtual machine a CPU that sat idle (the second one, while
    // single-threaded rs274 ran) is slow to come back, which would fall on
    // ncc's threads alone. The untimed runs must reach the program end, and
    // bring the files into the page cache. What ncc does not run yet it
    // names.
    let rs274_output = rs274_run.output()?;
    anyhow::ensure!(rs274_output.status.success(), "rs274 failed:\n{}", String::from_utf8_lossy(&rs274_output.stderr));
    let timed = |process: &mut Process| -> anyhow::Result<Duration> {
        let mut best = Duration::MAX;
        for _ in 0..runs {
            let start = Instant::now();
            let status = process.stderr(Stdio::null()).status()?;
            best = best.min(start.elapsed());
            anyhow::ensure!(status.success(), "{process:?} ended with {status}");
        }
        Ok(best)
    };
    let rs274_time = timed(&mut rs274_run)?;
    let ncc_output = ncc_run.output()?;
    let ncc_notes = String::from_utf8_lossy(&ncc_output.stderr).replace(&format!("{}/", dir.path().display()), "");
    anyhow::ensure!(ncc_output.status.success(), "ncc run failed:\n{ncc_notes}");
    let ncc_time = timed(&mut ncc_run)?;
    let rate = |time: Duration| blocks as f64 / time.as_secs_f64();
    if as_json {
        let output = json!({
            "blocks": blocks,
            "runs": runs,
            "ncc_s": ncc_time.as_secs_f64(),
            "rs274_s": rs274_time.as_secs_f64(),
            "ncc_blocks_per_s": rate(ncc_time),
            "rs274_blocks_per_s": rate(rs274_time),
            "ratio": rate(ncc_time) / rate(rs274_time),
            "ncc_notes": ncc_notes.lines().collect::<Vec<_>>(),
        });
        println!("{output:#}");
    } else {
        println!(
            "exec benchmark: {blocks} blocks; CNC8x6 {:.1} MB, NGC {:.1} MB; best of {runs} runs",
            std::fs::metadata(&cnc)?.len() as f64 / 1e6,
            std::fs::metadata(&ngc)?.len() as f64 / 1e6
        );
        for (name, time) in [("ncc run", ncc_time), ("rs274 -g (LinuxCNC)", rs274_time)] {
            println!("  {name:<20} {:>9.1} ms {:>12.0} blocks/s", time.as_secs_f64() * 1e3, rate(time));
        }
        println!("  speed ratio ncc/rs274: {:.2}x   goal >= 10x", rate(ncc_time) / rate(rs274_time));
        for note in ncc_notes.lines() {
            println!("  ncc: {note}");
        }
    }
    Ok(())
}
