//! The golden corpus: what ncc says about every bundled example, test
//! fixture and rule fixture, kept in `tests/golden/`. A change of any output
//! fails here and shows where; a deliberate one is taken over with
//! `UPDATE_GOLDEN=1 cargo test -p ncc --test golden` and reviewed in the diff.
//!
//! Per program: `ncc check --format json`, `ncc run --format json` (and
//! the files the program wrote),
//! `ncc expand` and `ncc plot` as the command line gives them, then the
//! analysis answers an editor shows: hover at the start of every word of the
//! first lines, the inlay hints, and the cycle-time estimate (headline, hints
//! and block hovers).

use std::{
    fmt::Write as _,
    path::{Path, PathBuf},
    process::Command,
};

use ncc_analysis::{AnalysisHost, Config, CycleTimeHints, Dialect, TextSize};
use ncc_catalog::macrocycle_number;
use ncc_syntax::encoding;

/// Lines of a program whose words are hovered (hover text is long).
const HOVERED_LINES: usize = 12;

/// Lines of a section kept as they are; the rest is kept as its line count
/// and hash, which still fails the test on any change.
const SHOWN_LINES: usize = 200;

/// Blocks a run may take: the programs that loop forever stop here.
const RUN_BUDGET: usize = 5_000;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// The corpus: the programs of every dialect, by their names, under these
/// directories, relative to the workspace, sorted.
fn corpus() -> Vec<PathBuf> {
    let root = workspace();
    let mut programs = Vec::new();
    for directory in ["examples", "tests/fixtures", "crates/analysis/test_data", "crates/syntax/test_data"] {
        let mut stack = vec![root.join(directory)];
        while let Some(directory) = stack.pop() {
            for entry in std::fs::read_dir(&directory).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                } else if Dialect::by_default_for(&path).is_some() {
                    programs.push(path.strip_prefix(&root).unwrap().to_owned());
                }
            }
        }
    }
    programs.sort();
    programs
}

fn read(path: &Path) -> std::io::Result<String> {
    Ok(encoding::decode(std::fs::read(path)?).0)
}

/// One command's output, as the golden file keeps it.
fn command(out: &mut String, title: &str, args: &[&str]) -> std::process::Output {
    let output = Command::new(env!("CARGO_BIN_EXE_ncc")).args(args).current_dir(workspace()).output().unwrap();
    writeln!(out, "== {title} (exit {:?})", output.status.code()).unwrap();
    out.push_str(&relative(&String::from_utf8_lossy(&output.stdout)));
    if !output.stderr.is_empty() {
        out.push_str("-- stderr\n");
        out.push_str(&relative(&String::from_utf8_lossy(&output.stderr)));
    }
    output
}

/// `text` with the workspace's absolute path (files found through the
/// project's `ncc.toml` are named by it) written as `<root>`, so that the
/// outputs do not depend on where the checkout is.
fn relative(text: &str) -> String {
    text.replace(workspace().to_str().unwrap(), "<root>")
}

fn cli_outputs(out: &mut String, program: &Path, scratch: &Path) {
    let file = program.to_str().unwrap();
    command(out, "check --format json", &["check", "--format", "json", file]);
    let budget = RUN_BUDGET.to_string();
    let written = scratch.join("written");
    let _ = std::fs::remove_dir_all(&written);
    let write_dir = written.to_str().unwrap();
    let run = ["run", "--format", "json", "--step-budget", &budget, "--write-dir", write_dir, file];
    command(out, "run --format json", &run);
    for (path, text) in files_below(&written) {
        writeln!(out, "== written {path}").unwrap();
        out.push_str(&text);
    }
    *out = out.replace(write_dir, "<written>");
    command(out, "expand", &["expand", "--step-budget", &budget, file]);
    let svg = scratch.join("plot.svg");
    let _ = std::fs::remove_file(&svg);
    command(out, "plot", &["plot", "--step-budget", &budget, "-o", svg.to_str().unwrap(), file]);
    if let Ok(picture) = std::fs::read_to_string(&svg) {
        let picture = relative(&picture);
        out.push_str(&picture);
        if !picture.ends_with('\n') {
            out.push('\n');
        }
    }
}

/// The files below `directory` with their text, by their path from it
/// (`/`-separated), sorted.
fn files_below(top: &Path) -> Vec<(String, String)> {
    let mut files = Vec::new();
    let mut stack = vec![top.to_owned()];
    while let Some(directory) = stack.pop() {
        for entry in std::fs::read_dir(&directory).into_iter().flatten() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let relative = path.strip_prefix(top).unwrap();
                files.push((relative.to_string_lossy().replace('\\', "/"), read(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}

/// The configuration the program is analysed with: a rule fixture's own
/// `<name>.toml`, else the `ncc.toml` above it, else the defaults.
fn config_for(path: &Path) -> Config {
    let own = path.with_extension("toml");
    let file = if own.is_file() { Some(own) } else { Config::find_for(path) };
    match file {
        Some(file) => Config::from_toml(&std::fs::read_to_string(&file).unwrap(), &file, read)
            .unwrap_or_else(|e| panic!("{}: {e}", file.display())),
        None => Config::default(),
    }
}

/// Macrocycle files beside `path`, as `ncc check` adds them, and beside
/// a Sinumerik program the Sinumerik files it may call by name.
fn neighbours(path: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(path.parent().unwrap())
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|other| {
            let macrocycle = macrocycle_number(other).is_some() && other.extension().is_none();
            // A Sinumerik program calls the programs beside it by name.
            let sinumerik = |file: &Path| Dialect::by_default_for(file) == Some(Dialect::Sinumerik);
            other != path && other.is_file() && (macrocycle || (sinumerik(path) && sinumerik(other)))
        })
        .collect();
    found.sort();
    found
}

fn analysis_outputs(out: &mut String, program: &Path) {
    let root = workspace();
    let path = root.join(program);
    let text = read(&path).unwrap();
    // Every file of the corpus has a dialect by its name.
    let dialect = Dialect::by_default_for(&path).expect("the corpus holds programs only");
    let mut host = AnalysisHost::in_dialect(dialect, config_for(&path));
    for other in neighbours(&path) {
        let name = other.strip_prefix(&root).unwrap().display().to_string();
        host.add_file(name, read(&other).unwrap());
    }
    let file = host.add_file(program.display().to_string(), text.clone());
    let analysis = host.analysis();

    out.push_str("== hover\n");
    for offset in word_starts(&text) {
        if let Some(hover) = analysis.hover(file, offset) {
            let range = hover.range;
            writeln!(out, "-- {offset:?} {range:?}\n{}", hover.markdown).unwrap();
        }
    }
    out.push_str("== inlay hints\n");
    for hint in analysis.inlay_hints(file, None) {
        writeln!(out, "{:?} {:?} {:?} {:?}", hint.offset, hint.kind, hint.label, hint.tooltip).unwrap();
    }
    out.push_str("== cycle time\n");
    let Some(input) = analysis.run_input(file) else {
        out.push_str("(not a program)\n");
        return;
    };
    let estimate = input.estimate(None, RUN_BUDGET, &|| false).expect("never abandoned");
    writeln!(out, "{}", estimate.headline()).unwrap();
    for hint in estimate.inlay_hints(None, CycleTimeHints::PerBlock) {
        writeln!(out, "{:?} {:?} {:?}", hint.offset, hint.label, hint.tooltip).unwrap();
    }
    for offset in line_starts(&text) {
        if let Some(hover) = estimate.hover(offset) {
            writeln!(out, "-- {offset:?}\n{hover}").unwrap();
        }
    }
}

/// The first offset of every word on the first lines.
fn word_starts(text: &str) -> Vec<TextSize> {
    let mut starts = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n').take(HOVERED_LINES) {
        let mut previous = b' ';
        for (i, byte) in line.bytes().enumerate() {
            if !byte.is_ascii_whitespace() && previous.is_ascii_whitespace() {
                starts.push(TextSize::from((offset + i) as u32));
            }
            previous = byte;
        }
        offset += line.len();
    }
    starts
}

fn line_starts(text: &str) -> Vec<TextSize> {
    let mut offset = 0;
    text.split_inclusive('\n')
        .take(HOVERED_LINES)
        .map(|line| {
            let start = TextSize::from(offset as u32);
            offset += line.len();
            start
        })
        .collect()
}

/// Each `== ` section with its first `SHOWN_LINES` lines, then a line that
/// counts and hashes the rest.
fn shortened(out: &str) -> String {
    let mut kept = String::new();
    let mut rest = Vec::new();
    let mut shown = 0;
    let flush = |kept: &mut String, rest: &mut Vec<&str>| {
        if !rest.is_empty() {
            writeln!(kept, "… {} more lines, FNV-1a {:016x}", rest.len(), fnv1a(rest)).unwrap();
            rest.clear();
        }
    };
    for line in out.lines() {
        if line.starts_with("== ") {
            flush(&mut kept, &mut rest);
            shown = 0;
        }
        if shown < SHOWN_LINES {
            kept.push_str(line);
            kept.push('\n');
            shown += 1;
        } else {
            rest.push(line);
        }
    }
    flush(&mut kept, &mut rest);
    kept
}

/// A hash that stays the same across Rust versions and platforms.
fn fnv1a(lines: &[&str]) -> u64 {
    lines
        .iter()
        .flat_map(|line| line.bytes().chain([b'\n']))
        .fold(0xcbf2_9ce4_8422_2325, |hash, byte| (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3))
}

/// `examples/milling/holes.NCP` → `examples__milling__holes.NCP.txt`.
fn golden_name(program: &Path) -> String {
    format!("{}.txt", program.display().to_string().replace('/', "__"))
}

#[test]
fn every_program_gives_the_recorded_outputs() {
    let root = workspace();
    let golden = root.join("tests/golden");
    let update = std::env::var_os("UPDATE_GOLDEN").is_some();
    let scratch = tempfile::tempdir().unwrap();
    let programs = corpus();
    assert!(programs.len() >= 100, "the corpus has {} programs", programs.len());
    let mut differ = Vec::new();
    let mut expected_names = Vec::new();
    for program in &programs {
        let mut out = String::new();
        cli_outputs(&mut out, program, scratch.path());
        analysis_outputs(&mut out, program);
        let name = golden_name(program);
        let file = golden.join(&name);
        let out = shortened(&out);
        if update {
            std::fs::create_dir_all(&golden).unwrap();
            std::fs::write(&file, &out).unwrap();
        } else if std::fs::read_to_string(&file).ok() != Some(out.clone()) {
            differ.push(file.strip_prefix(&root).unwrap().display().to_string());
            std::fs::write(scratch.path().join(&name), &out).unwrap();
        }
        expected_names.push(name);
    }
    let stale: Vec<String> = std::fs::read_dir(&golden)
        .map(|entries| entries.map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    let stale: Vec<&String> = stale.iter().filter(|name| !expected_names.contains(name)).collect();
    if update {
        for name in stale {
            std::fs::remove_file(golden.join(name)).unwrap();
        }
        return;
    }
    if !differ.is_empty() || !stale.is_empty() {
        panic!(
            "outputs differ from the golden files: {differ:#?}\nthe new outputs are in {}\n\
             golden files of no program: {stale:#?}\n(UPDATE_GOLDEN=1 takes deliberate changes over)",
            scratch.keep().display()
        );
    }
}
