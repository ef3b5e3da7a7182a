//! `ncc-bench`: measurements of ncc against peer tools.
//!
//! ```text
//! cargo run --release -p ncc-bench -- parse [--blocks 1000000] [--runs 3]
//! cargo run --release -p ncc-bench -- generate --blocks 1000000 --syntax cnc8x6 -o big.NCP
//! ```
#![allow(unsafe_code)] // The counting allocator below; nothing else.

use std::{
    alloc::{GlobalAlloc, Layout},
    hint::black_box,
    path::PathBuf,
    sync::atomic::{AtomicUsize, Ordering::Relaxed},
    time::{Duration, Instant},
};

use anyhow::Context;
use clap::{Parser, Subcommand, ValueEnum};
use ncc_bench::progen::{self, Syntax};
use ncc_syntax::{Dialect, Parse};

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
        #[arg(long, default_value_t = 1_000_000)]
        blocks: usize,
        /// Timed runs per parser; the best one counts.
        #[arg(long, default_value_t = 3)]
        runs: usize,
    },
    /// Time incremental reparses after single-character edits at random
    /// places of a generated program, against a full parse.
    Reparse {
        #[arg(long, default_value_t = 100_000)]
        blocks: usize,
        #[arg(long, default_value_t = 200)]
        edits: usize,
    },
    /// Check a generated program with the full analysis: time and peak heap.
    Check {
        #[arg(long, default_value_t = 1_000_000)]
        blocks: usize,
    },
    /// Parse a file once (for profilers such as perf or callgrind).
    ParseFile {
        path: PathBuf,
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

#[derive(Clone, Copy, ValueEnum)]
enum SyntaxArg {
    Cnc8x6,
    Ngc,
}

fn main() -> anyhow::Result<()> {
    match Cli::parse().command {
        Command::Parse { blocks, runs } => parse_benchmark(blocks, runs.max(1)),
        Command::Reparse { blocks, edits } => reparse_benchmark(blocks, edits),
        Command::Check { blocks } => check_benchmark(blocks),
        Command::ParseFile { path, threads, gcode } => {
            let text = std::fs::read_to_string(&path)?;
            let start = Instant::now();
            if gcode {
                let program = gcode::parse(&text).map_err(|e| anyhow::anyhow!("{e:?}"))?;
                println!("{} blocks in {:?}", program.blocks.len(), start.elapsed());
                std::mem::forget(program);
            } else {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
                let parse = pool.install(|| Parse::new(&text, Dialect::Cnc8x6));
                println!("{} errors in {:?}", parse.errors().len(), start.elapsed());
                std::mem::forget(parse);
            }
            Ok(())
        }
        Command::Generate { blocks, syntax, output } => {
            let syntax = match syntax {
                SyntaxArg::Cnc8x6 => Syntax::Cnc8x6,
                SyntaxArg::Ngc => Syntax::Ngc,
            };
            let text = progen::write(&progen::surfacing(blocks), syntax);
            std::fs::write(&output, text).with_context(|| format!("writing {}", output.display()))
        }
    }
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

fn parse_benchmark(blocks: usize, runs: usize) -> anyhow::Result<()> {
    let moves = progen::surfacing(blocks);
    let cnc = progen::write(&moves, Syntax::Cnc8x6);
    let ngc = progen::write(&moves, Syntax::Ngc);
    drop(moves);

    // Sanity: both parsers accept their input completely.
    let parse = Parse::new(&cnc, Dialect::Cnc8x6);
    anyhow::ensure!(parse.errors().is_empty(), "ncc found errors: {:?}", &parse.errors()[..1]);
    anyhow::ensure!(parse.tree().blocks().count() == blocks, "ncc block count");
    drop(parse);
    let program = gcode::parse(&ngc).map_err(|e| anyhow::anyhow!("gcode rejected the NGC program: {e:?}"))?;
    anyhow::ensure!(program.blocks.len() >= blocks, "gcode block count {}", program.blocks.len());
    drop(program);

    let threads = rayon::current_num_threads();
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    println!(
        "parse benchmark: {blocks} blocks; CNC8x6 {:.1} MB, NGC {:.1} MB; best of {runs} runs",
        cnc.len() as f64 / 1e6,
        ngc.len() as f64 / 1e6
    );
    let gcode_rs = measure(runs, || gcode::parse(&ngc));
    let ncc_one = measure(runs, || single.install(|| Parse::new(&cnc, Dialect::Cnc8x6)));
    let ncc_all = measure(runs, || Parse::new(&cnc, Dialect::Cnc8x6));

    let rate = |m: &Measurement| blocks as f64 / m.best.as_secs_f64();
    let row = |name: &str, m: &Measurement| {
        println!(
            "  {name:<34} {:>9.1} ms {:>12.0} blocks/s {:>9.1} MB peak",
            m.best.as_secs_f64() * 1e3,
            rate(m),
            m.peak_bytes as f64 / 1e6
        );
    };
    row("gcode 0.7 (gcode::parse, NGC)", &gcode_rs);
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
    Ok(())
}

fn reparse_benchmark(blocks: usize, edits: usize) -> anyhow::Result<()> {
    use ncc_syntax::{TextEdit, TextRange, TextSize};

    let mut text = progen::write(&progen::surfacing(blocks), Syntax::Cnc8x6);
    let start = Instant::now();
    let mut parse = Parse::new(&text, Dialect::Cnc8x6);
    let full = start.elapsed();

    // A fixed linear congruential sequence: the same edits on every run.
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move |bound: usize| {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (seed >> 33) as usize % bound
    };
    let mut times = Vec::with_capacity(edits);
    for _ in 0..edits {
        let at = (0..=next(text.len())).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
        let insert = ["1", " ", "X", "\n", "-", "."][next(6)];
        let delete = if next(2) == 0 && at < text.len() && text.is_char_boundary(at + 1) { 1 } else { 0 };
        let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::from(delete)), insert);
        edit.apply(&mut text);
        let start = Instant::now();
        parse = parse.reparse(&edit, &text);
        times.push(start.elapsed());
    }
    anyhow::ensure!(parse == Parse::new(&text, Dialect::Cnc8x6), "incremental result differs from a full parse");
    times.sort();
    let percentile = |p: f64| times[((times.len() - 1) as f64 * p) as usize];
    println!("reparse benchmark: {blocks} blocks ({:.1} MB), {edits} single-character edits", text.len() as f64 / 1e6);
    println!("  full parse   {:>9.3} ms", full.as_secs_f64() * 1e3);
    println!("  reparse p50  {:>9.3} ms", percentile(0.5).as_secs_f64() * 1e3);
    println!("  reparse p99  {:>9.3} ms", percentile(0.99).as_secs_f64() * 1e3);
    Ok(())
}

fn check_benchmark(blocks: usize) -> anyhow::Result<()> {
    let text = progen::write(&progen::surfacing(blocks), Syntax::Cnc8x6);
    let mb = text.len() as f64 / 1e6;
    let base = IN_USE.load(Relaxed);
    PEAK.store(base, Relaxed);
    let start = Instant::now();
    let mut host = ncc_analysis::AnalysisHost::default();
    let file = host.add_file("surface.NCP", text);
    let parsed = start.elapsed();
    let after_parse = IN_USE.load(Relaxed) - base;
    let diagnostics = host.analysis().diagnostics(file);
    let total = start.elapsed();
    anyhow::ensure!(diagnostics.is_empty(), "findings in a generated program: {:?}", &diagnostics[..1]);
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
