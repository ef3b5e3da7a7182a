//! The predicted cycle time of a program, block by block.
//!
//! The program runs on the executor (`nc_exec::run`) with the workspace's
//! macrocycle files and cycle file, and the velocity model times the
//! steps. Each block of the file gets the time of all its executions; the
//! steps of other files (a macrocycle, a cycle body) are charged to the
//! block of this file that ran last before them: the call.
//!
//! The run needs no database: [`RunInput`] takes what it reads from a
//! snapshot, so a long run never holds one (an edit would wait for it).

use std::{fmt::Write as _, sync::Arc};

use nc_exec::{
    run::{Environment, Motion, Step, Totals},
    velocity::{self, Break, Dynamics, Reason, Timer, TimingSink},
};
use ncc_syntax::{TextRange, TextSize, ast::AstNode};
use rustc_hash::FxHashMap;

use crate::{
    InlayHint, InlayHintKind, MachineConfig,
    db::{Db, Settings, SourceFile},
    model::{self, FileKind},
};

/// What the cycle-time inlay hints show.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum CycleTimeHints {
    /// Each block's own time.
    #[default]
    PerBlock,
    /// The time since the program's start at each block's end.
    Cumulative,
    /// None (the speed-break markers stay off too).
    Off,
}

/// A program's predicted run, per block of the file and in total. Owned
/// and self-contained, so that a later estimate can start from it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Estimate {
    /// The blocks of the file that ran, in the order they are written.
    pub blocks: Vec<BlockTime>,
    pub totals: CycleTotals,
    /// Why the run stopped before the program's end, if it did.
    pub stopped: Option<String>,
}

/// One block of the file as it ran.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockTime {
    pub range: TextRange,
    /// Seconds since the program's start when its first execution starts
    /// and ends (with the files it calls).
    pub start: f64,
    pub end: f64,
    /// Seconds of all its executions, with the steps of the files it calls.
    pub total: f64,
    pub executions: usize,
    /// Its own motion in its last execution.
    pub profile: velocity::Profile,
    /// The speed breaks at it, one per reason.
    pub breaks: Vec<BreakAt>,
}

/// The drops of the path speed at a block for one reason, over all its
/// executions.
#[derive(Debug, Clone, PartialEq)]
pub struct BreakAt {
    /// Displayed, the reason in the control's terms; `code()`, its short
    /// name.
    pub reason: Reason,
    /// mm/min before the drop and at it, in the last execution.
    pub before: f64,
    pub at: f64,
    /// Seconds lost against a smooth join, over all executions.
    pub lost: f64,
    pub count: usize,
}

/// The whole program.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CycleTotals {
    pub total: f64,
    pub cutting: f64,
    pub rapid: f64,
    pub dwell: f64,
    pub breaks: usize,
    /// Seconds all breaks cost against smooth joins.
    pub lost: f64,
}

/// What a run of a file reads from the workspace, taken from a snapshot.
#[derive(Debug, Clone)]
pub struct RunInput {
    pub text: Arc<String>,
    pub machine: MachineConfig,
    pub files: WorkspaceFiles,
}

/// The macrocycle files and possible cycle files of a workspace.
#[derive(Debug, Clone, Default)]
pub struct WorkspaceFiles {
    macrocycles: FxHashMap<u32, Arc<String>>,
    /// Every other file by its name without directory and extension, for
    /// the cycle file the machine names.
    by_stem: Vec<(String, Arc<String>)>,
}

impl Environment for WorkspaceFiles {
    fn macrocycle(&self, number: u32) -> Option<String> {
        self.macrocycles.get(&number).map(|text| String::clone(text))
    }

    fn cycle_file(&self, name: &str) -> Option<String> {
        let stem = model::file_stem(name);
        self.by_stem.iter().find(|(s, _)| s.eq_ignore_ascii_case(stem)).map(|(_, text)| String::clone(text))
    }
}

/// What a run of `file` needs; `None` for macrocycle and cycle files,
/// which run only when a program calls them.
pub(crate) fn run_input(db: &dyn Db, file: SourceFile) -> Option<RunInput> {
    if model::file_kind(db, file) != FileKind::Program {
        return None;
    }
    let settings = Settings::get(db);
    let mut files = WorkspaceFiles::default();
    for (&number, found) in model::macrocycles(db) {
        if let Some(first) = found.first() {
            files.macrocycles.insert(number, first.text(db).clone());
        }
    }
    for &other in settings.files(db) {
        if other != file {
            files.by_stem.push((model::file_stem(other.path(db)).to_owned(), other.text(db).clone()));
        }
    }
    Some(RunInput { text: file.text(db).clone(), machine: settings.config(db).machine.clone(), files })
}

/// Where the program's total is shown: the `%` header, or the first block.
pub(crate) fn program_head(db: &dyn Db, file: SourceFile) -> Option<TextRange> {
    let tree = file.parse(db).tree();
    match tree.header() {
        Some(header) => Some(header.syntax().text_range()),
        None => tree.blocks().next().map(|block| block.syntax().text_range()),
    }
}

impl RunInput {
    pub fn estimate(&self, previous: Option<&Estimate>, edit: Option<TextRange>, budget: usize) -> Estimate {
        estimate(previous, &self.text, edit, &self.files, &self.machine, budget)
    }
}

/// The one way to an estimate. `previous` is the estimate of the text
/// before `edit` (the changed range in the new text, `None` when unknown):
/// they are where a run will resume from a checkpoint before the edit;
/// for now every estimate runs the program from its start.
pub fn estimate(
    previous: Option<&Estimate>,
    text: &str,
    edit: Option<TextRange>,
    files: &dyn Environment,
    machine: &MachineConfig,
    budget: usize,
) -> Estimate {
    let _resume_from = (previous, edit);
    let dynamics = Dynamics::of(machine);
    // The model times the steps as they come: the run keeps none. It runs
    // on the run's thread, leaving the other core to the editor's requests.
    let mut timer = Timer::new(machine.step_axes(), &dynamics, Charges::default());
    let trace = nc_exec::run::run_into(text, files, machine, budget, &mut timer);
    let charges = timer.finish();
    let mut blocks = charges.blocks;
    blocks.sort_by_key(|block| block.range.start());
    let totals = charges.totals;
    Estimate {
        blocks,
        totals: CycleTotals {
            total: totals.total_time,
            cutting: totals.time(Motion::Feed),
            rapid: totals.time(Motion::Rapid),
            dwell: totals.time(Motion::Dwell),
            breaks: charges.breaks,
            lost: charges.lost,
        },
        stopped: trace.findings.iter().find(|finding| finding.fatal).map(|finding| finding.message.clone()),
    }
}

/// Every step charged to a block of the file as the model times it, and
/// the sums.
#[derive(Default)]
struct Charges {
    blocks: Vec<BlockTime>,
    index_of: FxHashMap<TextSize, usize>,
    /// The block of the last step of this file: steps of other files are
    /// its, and a new execution starts when another block's step comes.
    current: Option<usize>,
    /// Seconds since the program's start.
    clock: f64,
    totals: Totals,
    breaks: usize,
    lost: f64,
}

impl Charges {
    /// The block a step is charged to: its own in this file, found or
    /// added, else the block that ran last.
    fn block_of(&mut self, step: &Step) -> Option<usize> {
        if step.source != 0 {
            return self.current;
        }
        let Charges { blocks, index_of, clock, .. } = self;
        Some(*index_of.entry(step.range.start()).or_insert_with(|| {
            blocks.push(BlockTime {
                range: step.range,
                start: *clock,
                end: *clock,
                total: 0.0,
                executions: 0,
                profile: velocity::Profile::default(),
                breaks: Vec::new(),
            });
            blocks.len() - 1
        }))
    }
}

impl TimingSink for Charges {
    fn speed_break(&mut self, step: &Step, speed_break: Break) {
        self.breaks += 1;
        self.lost += speed_break.lost;
        let Some(index) = self.block_of(step) else { return };
        let block = &mut self.blocks[index];
        let code = speed_break.reason.code();
        match block.breaks.iter_mut().find(|known| known.reason.code() == code) {
            Some(known) => {
                known.reason = speed_break.reason;
                (known.before, known.at) = (speed_break.before, speed_break.at);
                known.lost += speed_break.lost;
                known.count += 1;
            }
            None => block.breaks.push(BreakAt {
                reason: speed_break.reason,
                before: speed_break.before,
                at: speed_break.at,
                lost: speed_break.lost,
                count: 1,
            }),
        }
    }

    fn timed(&mut self, step: &Step, profile: velocity::Profile) {
        let start = self.clock;
        self.clock += profile.duration;
        self.totals.add(step, profile.duration);
        let index = self.block_of(step);
        if step.source == 0
            && let Some(own) = index
        {
            let block = &mut self.blocks[own];
            if self.current == index {
                block.profile.peak = block.profile.peak.max(profile.peak);
                block.profile.exit = profile.exit;
                block.profile.duration += profile.duration;
            } else {
                block.executions += 1;
                block.profile = profile;
            }
            self.current = index;
        }
        if let Some(block) = index.map(|index| &mut self.blocks[index]) {
            block.total += profile.duration;
            if block.executions == 1 {
                block.end = start + profile.duration;
            }
        }
    }
}

impl Estimate {
    /// The block whose range holds `offset` (its end included).
    pub fn block_at(&self, offset: TextSize) -> Option<&BlockTime> {
        let after = self.blocks.partition_point(|block| block.range.start() <= offset);
        self.blocks[..after].last().filter(|block| block.range.contains_inclusive(offset))
    }

    /// The hints in `range` (everywhere without one), at the end of each
    /// block's last line in `text`: its time, and a marker per reason the
    /// speed drops there.
    pub fn inlay_hints(&self, text: &str, range: Option<TextRange>, mode: CycleTimeHints) -> Vec<InlayHint> {
        if mode == CycleTimeHints::Off {
            return Vec::new();
        }
        let first = range.map_or(0, |range| self.blocks.partition_point(|block| block.range.end() < range.start()));
        let mut hints = Vec::new();
        for block in &self.blocks[first..] {
            if range.is_some_and(|range| block.range.start() > range.end()) {
                break;
            }
            if block.total <= 0.0 {
                continue;
            }
            let offset = line_end(text, block.range);
            // A block that ends where the range starts has its hints on
            // the line before.
            if range.is_some_and(|range| !range.contains_inclusive(offset)) {
                continue;
            }
            let label = match mode {
                CycleTimeHints::Cumulative => format!("Σ {}", short_time(block.end)),
                _ => short_time(block.total),
            };
            hints.push(InlayHint { offset, label, kind: InlayHintKind::BlockTime, tooltip: Some(block.summary()) });
            for speed_break in &block.breaks {
                let times = if speed_break.count > 1 { format!(" ×{}", speed_break.count) } else { String::new() };
                hints.push(InlayHint {
                    offset,
                    label: format!("▼ {}{times} −{}", speed_break.reason.code(), short_time(speed_break.lost)),
                    kind: InlayHintKind::SpeedBreak,
                    tooltip: Some(speed_break.explanation()),
                });
            }
        }
        hints
    }

    /// The program's total in one line, for the top of the file.
    pub fn headline(&self) -> String {
        let t = &self.totals;
        let mut line = format!(
            "Cycle time {} · cutting {} · rapid {}",
            short_time(t.total),
            short_time(t.cutting),
            short_time(t.rapid)
        );
        if t.dwell > 0.0 {
            let _ = write!(line, " · dwell {}", short_time(t.dwell));
        }
        match t.breaks {
            0 => {}
            1 => {
                let _ = write!(line, " · 1 break costs {}", short_time(t.lost));
            }
            n => {
                let _ = write!(line, " · {n} breaks cost {}", short_time(t.lost));
            }
        }
        if self.stopped.is_some() {
            line.push_str(" · the run stopped early");
        }
        line
    }

    /// Markdown about the block at `offset`: when it runs, how long, and
    /// its speed; `None` for a block that did not run.
    pub fn hover(&self, offset: TextSize) -> Option<String> {
        let block = self.block_at(offset)?;
        let mut text = format!("**Predicted time:** {}", block.summary());
        let p = &block.profile;
        if p.peak > 0.0 {
            let last = if block.executions > 1 { " (last run)" } else { "" };
            let _ = write!(
                text,
                "\n\n**Speed{last}:** entry {:.0} → peak {:.0} → exit {:.0} mm/min over {}",
                p.entry,
                p.peak,
                p.exit,
                short_time(p.duration)
            );
        }
        for speed_break in &block.breaks {
            let _ = write!(text, "\n\n{}", speed_break.explanation());
        }
        Some(text)
    }
}

impl BlockTime {
    /// `takes 420 ms, starts at 1:02.3 (3 runs)`.
    fn summary(&self) -> String {
        let runs = if self.executions > 1 { format!(" in {} runs", self.executions) } else { String::new() };
        format!("takes {}{runs}, starts at {}", short_time(self.total), short_time(self.start))
    }
}

impl BreakAt {
    /// The reason in the control's terms, the speeds and the cost.
    fn explanation(&self) -> String {
        let times = if self.count > 1 { format!(" ({} runs)", self.count) } else { String::new() };
        format!(
            "**Speed drops** ({}): {}. {:.0} → {:.0} mm/min; {} lost against a smooth join{times}.",
            self.reason.code(),
            self.reason,
            self.before,
            self.at,
            short_time(self.lost)
        )
    }
}

/// The end of the last line of `range` that holds more than white space.
fn line_end(text: &str, range: TextRange) -> TextSize {
    let block = text.get(usize::from(range.start())..usize::from(range.end())).unwrap_or_default();
    range.start() + TextSize::of(block.trim_end())
}

/// Hours, minutes and seconds of a non-negative time.
fn hms(seconds: f64) -> (f64, f64, f64) {
    let whole = seconds.max(0.0);
    let hours = (whole / 3600.0).floor();
    let minutes = ((whole - hours * 3600.0) / 60.0).floor();
    (hours, minutes, whole - hours * 3600.0 - minutes * 60.0)
}

/// `h:mm:ss.sss`, for reports.
pub fn clock(seconds: f64) -> String {
    let (hours, minutes, seconds) = hms(seconds);
    format!("{hours}:{minutes:02}:{seconds:06.3}")
}

/// A short time for the editor: `0 s`, `0.4 ms`, `420 ms`, `4.25 s`,
/// `1:23.4`, `1:02:03.4`.
pub fn short_time(seconds: f64) -> String {
    let seconds = seconds.max(0.0);
    if seconds == 0.0 {
        return "0 s".to_owned();
    }
    if seconds < 0.01 {
        return format!("{:.1} ms", seconds * 1000.0);
    }
    if seconds < 0.9995 {
        return format!("{:.0} ms", seconds * 1000.0);
    }
    if seconds < 59.995 {
        return format!("{seconds:.2} s");
    }
    // Rounded first, so that 59.97 s is not `0:60.0`.
    let (hours, minutes, seconds) = hms((seconds * 10.0).round() / 10.0);
    if hours > 0.0 { format!("{hours}:{minutes:02}:{seconds:04.1}") } else { format!("{minutes}:{seconds:04.1}") }
}

#[cfg(test)]
mod tests {
    use expect_test::{Expect, expect};

    use super::*;
    use crate::{AnalysisHost, Config};

    /// The estimate of `program` in a workspace that also holds `others`
    /// (path, text).
    fn estimated(program: &str, others: &[(&str, &str)]) -> Estimate {
        let mut host = AnalysisHost::new(Config::default());
        let file = host.add_file("/p/PROGRAM.NCP", program);
        for (path, text) in others {
            host.add_file(*path, *text);
        }
        let input = host.analysis().run_input(file).expect("a program");
        input.estimate(None, None, nc_exec::run::DEFAULT_STEP_BUDGET)
    }

    /// One line per block: its first line, when it starts, its time, its
    /// runs, its speed profile and breaks, in ms and mm/min.
    fn render(program: &str, estimate: &Estimate) -> String {
        let ms = |s: f64| format!("{:.1}", s * 1000.0);
        let mut out = String::new();
        for block in &estimate.blocks {
            let text = program[block.range].lines().next().unwrap_or_default();
            let p = &block.profile;
            let _ = write!(
                out,
                "{text:<24} start {:>7} end {:>7} total {:>7} ×{} speed {:.0}/{:.0}/{:.0} in {}",
                ms(block.start),
                ms(block.end),
                ms(block.total),
                block.executions,
                p.entry,
                p.peak,
                p.exit,
                ms(p.duration)
            );
            for b in &block.breaks {
                let _ = write!(out, " | {} ×{} {:.0}→{:.0} −{}", b.reason.code(), b.count, b.before, b.at, ms(b.lost));
            }
            out.push('\n');
        }
        let t = &estimate.totals;
        let _ = writeln!(
            out,
            "total {} cutting {} rapid {} dwell {} breaks {} lost {}",
            ms(t.total),
            ms(t.cutting),
            ms(t.rapid),
            ms(t.dwell),
            t.breaks,
            ms(t.lost)
        );
        out
    }

    fn check(program: &str, others: &[(&str, &str)], expect: Expect) -> Estimate {
        let estimate = estimated(program, others);
        expect.assert_eq(&render(program, &estimate));
        estimate
    }

    /// The velocity model's own timing of the program alone.
    fn model_total(program: &str) -> f64 {
        let machine = MachineConfig::default();
        let trace = nc_exec::run::run(program, &nc_exec::run::NoFiles, &machine, 1000);
        velocity::time(&trace, &Dynamics::of(&machine)).total_time()
    }

    #[test]
    fn a_corner_stops_the_path_and_costs_its_ramps() {
        let program = "%1\nN10 G23 G01 X10 F600\nN20 Y10\nN30 X20\nN40 M30\n*\n";
        let estimate = check(
            program,
            &[],
            expect![[r#"
                N10 G23 G01 X10 F600     start     0.0 end  1035.0 total  1035.0 ×1 speed 0/600/0 in 1035.0 | corner ×1 600→0 −35.0
                N20 Y10                  start  1035.0 end  2070.0 total  1035.0 ×1 speed 0/600/0 in 1035.0 | corner ×1 600→0 −35.0
                N30 X20                  start  2070.0 end  3105.0 total  1035.0 ×1 speed 0/600/0 in 1035.0 | non-motion ×1 600→0 −22.5
                N40 M30                  start  3105.0 end  3105.0 total     0.0 ×1 speed 0/0/0 in 0.0
                total 3105.0 cutting 3105.0 rapid 0.0 dwell 0.0 breaks 3 lost 92.5
            "#]],
        );
        assert_eq!(estimate.totals.total, model_total(program));
        let sum: f64 = estimate.blocks.iter().map(|block| block.total).sum();
        assert!((sum - estimate.totals.total).abs() < 1e-9, "{sum} vs {}", estimate.totals.total);
    }

    #[test]
    fn a_subprogram_called_three_times_is_charged_each_run() {
        let program = "%1\nN1 G23 G01 F600 G71 L1 Q3\nN2 M30\nN3 G79 L1\nN4 G91 X10\nN5 G70\n*\n";
        let estimate = check(
            program,
            &[],
            expect![[r#"
                N1 G23 G01 F600 G71 L1 Q3 start     0.0 end     0.0 total     0.0 ×1 speed 0/0/0 in 0.0
                N2 M30                   start  3105.0 end  3105.0 total     0.0 ×1 speed 0/0/0 in 0.0
                N4 G91 X10               start     0.0 end  1035.0 total  3105.0 ×3 speed 0/600/0 in 1035.0 | non-motion ×3 600→0 −67.5
                N5 G70                   start  1035.0 end  1035.0 total     0.0 ×3 speed 0/0/0 in 0.0
                total 3105.0 cutting 3105.0 rapid 0.0 dwell 0.0 breaks 3 lost 67.5
            "#]],
        );
        assert_eq!(estimate.totals.total, model_total(program));
    }

    #[test]
    fn a_macrocycle_is_charged_to_the_calling_block() {
        let program = "%1\nN10 G91 G01 F600\nN20 G72 L9001 Q2\nN30 G90 X0\nN40 M30\n*\n";
        let macrocycle = "N1 G79 L9001\nN2 G01 X10\nN3 Y5\nN4 G70\n*\n";
        let estimate = check(
            program,
            &[("/p/L9001", macrocycle)],
            expect![[r#"
                N10 G91 G01 F600         start     0.0 end     0.0 total     0.0 ×1 speed 0/0/0 in 0.0
                N20 G72 L9001 Q2         start     0.0 end  3120.0 total  3120.0 ×1 speed 0/0/0 in 0.0 | g98 ×2 600→0 −60.0 | non-motion ×2 600→0 −50.0
                N30 G90 X0               start  3120.0 end  5150.0 total  2030.0 ×1 speed 0/600/0 in 2030.0 | non-motion ×1 600→0 −25.0
                N40 M30                  start  5150.0 end  5150.0 total     0.0 ×1 speed 0/0/0 in 0.0
                total 5150.0 cutting 5150.0 rapid 0.0 dwell 0.0 breaks 5 lost 135.0
            "#]],
        );
        // Everything the macrocycle did is in N20.
        let call = &estimate.blocks[1];
        let rest: f64 = estimate.blocks.iter().filter(|block| block.range != call.range).map(|b| b.total).sum();
        assert!((call.total + rest - estimate.totals.total).abs() < 1e-9);
        assert!(call.total > 3.0, "two runs of 15 mm at 10 mm/s and their ramps: {}", call.total);
    }

    #[test]
    fn hints_hover_and_headline_show_the_times() {
        let program = "%1\nN10 G23 G01 X10 F600\nN20 Y10 \"SIDE\"\nN30 M30\n*\n";
        let estimate = estimated(program, &[]);
        let hints: Vec<String> = estimate
            .inlay_hints(program, None, CycleTimeHints::PerBlock)
            .iter()
            .map(|hint| {
                format!("{}: {}", &program[..usize::from(hint.offset)].rsplit('\n').next().unwrap(), hint.label)
            })
            .collect();
        expect![[r#"
            [
                "N10 G23 G01 X10 F600: 1.03 s",
                "N10 G23 G01 X10 F600: ▼ corner −35 ms",
                "N20 Y10 \"SIDE\": 1.03 s",
                "N20 Y10 \"SIDE\": ▼ non-motion −22 ms",
            ]
        "#]]
        .assert_debug_eq(&hints);
        let cumulative: Vec<String> = estimate
            .inlay_hints(program, None, CycleTimeHints::Cumulative)
            .into_iter()
            .filter(|hint| hint.kind == InlayHintKind::BlockTime)
            .map(|hint| hint.label)
            .collect();
        expect![[r#"
            [
                "Σ 1.03 s",
                "Σ 2.07 s",
            ]
        "#]]
        .assert_debug_eq(&cumulative);
        assert!(estimate.inlay_hints(program, None, CycleTimeHints::Off).is_empty());
        // Only the hints in the range: the line of N20, not N10's before it.
        let n20 = TextSize::from(program.find("N20").unwrap() as u32);
        let line = TextRange::new(n20, TextSize::from(program.find("\nN30").unwrap() as u32));
        let ranged: Vec<String> =
            estimate.inlay_hints(program, Some(line), CycleTimeHints::PerBlock).into_iter().map(|h| h.label).collect();
        assert_eq!(ranged, ["1.03 s", "▼ non-motion −22 ms"]);
        expect![[r#"
            **Predicted time:** takes 1.03 s, starts at 1.03 s

            **Speed:** entry 0 → peak 600 → exit 0 mm/min over 1.03 s

            **Speed drops** (non-motion): a block without motion between moves. 600 → 0 mm/min; 22 ms lost against a smooth join."#]].assert_eq(&estimate.hover(n20 + TextSize::from(5)).unwrap());
        expect!["Cycle time 2.07 s · cutting 2.07 s · rapid 0 s · 2 breaks cost 57 ms"].assert_eq(&estimate.headline());
        assert_eq!(estimate.hover(TextSize::from(0)), None, "the header is no block");
    }

    #[test]
    fn times_read_short() {
        let shown: Vec<String> =
            [0.0, 0.0004, 0.0123, 0.42, 0.9996, 4.254, 59.97, 83.44, 3723.4].map(short_time).to_vec();
        expect![[r#"
            [
                "0 s",
                "0.4 ms",
                "12 ms",
                "420 ms",
                "1.00 s",
                "4.25 s",
                "59.97 s",
                "1:23.4",
                "1:02:03.4",
            ]
        "#]]
        .assert_debug_eq(&shown);
        assert_eq!(clock(3723.4), "1:02:03.400");
    }
}
