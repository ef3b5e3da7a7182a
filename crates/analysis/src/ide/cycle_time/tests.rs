use expect_test::{Expect, expect};

use super::*;
use crate::{AnalysisHost, Config, TextEdit};

/// The estimate of `program` in a workspace that also holds `others`
/// (path, text).
fn estimated(program: &str, others: &[(&str, &str)]) -> Estimate {
    let mut host = AnalysisHost::new(Config::default());
    let file = host.add_file("/p/PROGRAM.NCP", program);
    for (path, text) in others {
        host.add_file(*path, *text);
    }
    let input = host.analysis().run_input(file).expect("a program");
    input.estimate(None, nc_exec::run::DEFAULT_STEP_BUDGET, &|| false).expect("never abandoned")
}

/// One line per block: its first line, when it starts, its time, its
/// runs, its speed profile and breaks, in ms and mm/min.
fn render(program: &str, estimate: &Estimate) -> String {
    let ms = |s: f64| format!("{:.1}", s * 1000.0);
    let mut out = String::new();
    for block in estimate.blocks.iter() {
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
    velocity::time(&trace, &nc_exec::run::dynamics(&machine)).total_time()
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
    let call = &estimate.blocks.get(1).expect("the call ran");
    let rest: f64 = estimate.blocks.iter().filter(|block| block.range != call.range).map(|b| b.total).sum();
    assert!((call.total + rest - estimate.totals.total).abs() < 1e-9);
    assert!(call.total > 3.0, "two runs of 15 mm at 10 mm/s and their ramps: {}", call.total);
}

#[test]
fn hints_hover_and_headline_show_the_times() {
    let program = "%1\nN10 G23 G01 X10 F600\nN20 Y10 \"SIDE\"\nN30 M30\n*\n";
    let estimate = estimated(program, &[]);
    let hints: Vec<String> = estimate
        .inlay_hints(None, CycleTimeHints::PerBlock)
        .iter()
        .map(|hint| format!("{}: {}", &program[..usize::from(hint.offset)].rsplit('\n').next().unwrap(), hint.label))
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
        .inlay_hints(None, CycleTimeHints::Cumulative)
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
    assert!(estimate.inlay_hints(None, CycleTimeHints::Off).is_empty());
    // Only the hints in the range: the line of N20, not N10's before it.
    let n20 = TextSize::from(program.find("N20").unwrap() as u32);
    let line = TextRange::new(n20, TextSize::from(program.find("\nN30").unwrap() as u32));
    let ranged: Vec<String> =
        estimate.inlay_hints(Some(line), CycleTimeHints::PerBlock).into_iter().map(|h| h.label).collect();
    assert_eq!(ranged, ["1.03 s", "▼ non-motion −22 ms"]);
    expect![[r#"
        **Predicted time:** takes 1.03 s, starts at 1.03 s

        **Speed:** entry 0 → peak 600 → exit 0 mm/min over 1.03 s

        **Speed drops** (non-motion): a block without motion between moves. 600 → 0 mm/min; 22 ms lost against a smooth join."#]].assert_eq(&estimate.hover(n20 + TextSize::from(5)).unwrap());
    expect!["Cycle time 2.07 s · cutting 2.07 s · rapid 0 s · 2 breaks cost 57 ms"].assert_eq(&estimate.headline());
    assert_eq!(estimate.hover(TextSize::from(0)), None, "the header is no block");
}

#[test]
fn a_blocks_hints_end_its_last_line_of_program_text_not_the_comment_lines_after_it() {
    let program = "%1\nN10 R11=5.\nN20 G01 X10\nY10 F600 \"SIDE\"  \n\"NEXT\"\nN30 / G00 ZR11\n\"LIFT\"\n  \"CLEAR\"\n\nN40 M30\n*\n";
    let estimate = estimated(program, &[]);
    // Each line with its hints in brackets where they stand.
    let mut shown = program.to_owned();
    for hint in estimate.inlay_hints(None, CycleTimeHints::PerBlock).iter().rev() {
        shown.insert_str(usize::from(hint.offset), &format!("[{}]", hint.label));
    }
    expect![[r#"
        %1
        N10 R11=5.
        N20 G01 X10
        Y10 F600 "SIDE"[1.44 s][▼ rapid −34 ms]  
        "NEXT"
        N30 / G00 ZR11[161 ms][▼ rapid −61 ms]
        "LIFT"
          "CLEAR"

        N40 M30
        *
    "#]]
    .assert_eq(&shown);
}

/// A CAM-like program of `blocks` moves: absolute contours with
/// corners, rapids, a dwell now and then.
fn long_program(blocks: usize) -> String {
    let mut text = String::from("%1\nN1 G54 G90 G00 X0 Y0 Z5 M03 S8000\nN2 G01 Z-1 F1200\n");
    for i in 0..blocks {
        let (x, y) = ((i % 97) as f64 * 0.7, (i / 97) as f64 * 1.3 + (i % 5) as f64 * 0.2);
        let block = match i % 50 {
            17 => "G04 Q10".to_owned(),
            31 => format!("G00 X{x:.3} Y{y:.3}"),
            32 => format!("G01 X{x:.3} Y{y:.3} F900"),
            _ => format!("X{x:.3} Y{y:.3}"),
        };
        text.push_str(&format!("N{} {block}\n", i + 3));
    }
    text.push_str("N99999 G00 Z5 M30\n");
    text
}

fn estimate_of(text: &str, previous: Option<&Estimate>) -> Estimate {
    let machine = MachineConfig::default();
    estimate(previous, &Arc::new(text.to_owned()), &WorkspaceFiles::default(), &machine, 1_000_000)
}

/// The estimates agree on every block and total, to rounding.
fn assert_alike(resumed: &Estimate, whole: &Estimate) {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()));
    assert_eq!(resumed.blocks.len(), whole.blocks.len());
    for (r, w) in resumed.blocks.iter().zip(whole.blocks.iter()) {
        assert_eq!((r.range, r.executions, &r.profile), (w.range, w.executions, &w.profile));
        assert!(close(r.start, w.start) && close(r.end, w.end) && close(r.total, w.total), "{r:?} vs {w:?}");
        assert_eq!(r.breaks.len(), w.breaks.len(), "{r:?} vs {w:?}");
        for (r, w) in r.breaks.iter().zip(&w.breaks) {
            assert_eq!((r.reason.code(), r.count), (w.reason.code(), w.count));
            assert!(close(r.lost, w.lost));
        }
    }
    let (r, w) = (&resumed.totals, &whole.totals);
    assert_eq!(r.breaks, w.breaks);
    for (a, b) in [(r.total, w.total), (r.cutting, w.cutting), (r.rapid, w.rapid), (r.dwell, w.dwell), (r.lost, w.lost)]
    {
        assert!(close(a, b), "{r:?} vs {w:?}");
    }
    assert_eq!(resumed.stopped, whole.stopped);
}

#[test]
fn an_edit_reruns_from_the_checkpoint_before_it_to_where_the_run_takes_its_course_again() {
    let text = long_program(5000);
    let first = estimate_of(&text, None);
    assert_eq!(first.rerun, TextSize::default()..TextSize::of(text.as_str()));
    assert!(first.checkpoints.len() >= 5, "{} checkpoints", first.checkpoints.len());
    // A digit typed into an absolute coordinate in the middle.
    let at = text.find("N2503 X").expect("the block") + "N2503 X".len();
    let edited = format!("{}7{}", &text[..at], &text[at..]);
    let resumed = estimate_of(&edited, Some(&first));
    let whole = estimate_of(&edited, None);
    assert_alike(&resumed, &whole);
    assert!(resumed.totals.total > first.totals.total, "the move got longer");
    // From the checkpoint at block 2000 (N2001) to the one at block 3000.
    let rerun = usize::from(resumed.rerun.start)..usize::from(resumed.rerun.end);
    assert!(edited[rerun.clone()].starts_with("N2001 ") && edited[rerun.end..].starts_with("N3001 "), "{rerun:?}");
    // Edited again, from the resumed estimate: its checkpoints hold.
    let at = edited.find("N4321 X").expect("the block") + "N4321 X".len();
    let again = format!("{}{}", &edited[..at], &edited[at + 1..]);
    let resumed = estimate_of(&again, Some(&resumed));
    assert_alike(&resumed, &estimate_of(&again, None));
    assert!(resumed.rerun.end < TextSize::of(again.as_str()));
}

#[test]
fn checkpoints_after_the_first_block_a_jump_goes_back_to_are_not_used() {
    // N1000 … N2502 run twice: a checkpoint after N1000 does not have
    // their final charges.
    let text = long_program(2500).replace("N99999 G00", "N99998 G73 L1000 Q1\nN99999 G00");
    let first = estimate_of(&text, None);
    let n1000 = TextSize::of(&text[..text.find("N1000 ").expect("the block")]);
    assert!(first.checkpoints.iter().all(|stored| stored.run.offset() <= n1000));
    for (edit, at) in [("", "N2000 X"), ("7", "N2000 X"), ("7", "N900 X")] {
        let at = text.find(at).expect("the block") + 7;
        let edited = format!("{}{edit}{}", &text[..at], &text[at..]);
        let resumed = estimate_of(&edited, Some(&first));
        assert_alike(&resumed, &estimate_of(&edited, None));
        assert!(resumed.blocks.iter().any(|block| block.executions == 2));
    }
}

#[test]
fn checkpoints_after_a_loop_that_closed_before_them_are_used() {
    // N1000 … N1010 run twice, and nothing after them goes back.
    let text = long_haas_program(2500).replace("N1011 ", "#1 = #1 + 1\nIF [#1 LT 2] GOTO 1000\nN1011 ");
    let first = haas_estimate_of(&text, None);
    let loop_end = TextSize::of(&text[..text.find("N1011 ").expect("the block")]);
    assert!(first.checkpoints.iter().any(|stored| stored.run.offset() > loop_end));
    let at = text.find("N2200 X").expect("the block") + "N2200 X".len();
    let edited = format!("{}7{}", &text[..at], &text[at..]);
    let resumed = haas_estimate_of(&edited, Some(&first));
    assert_alike(&resumed, &haas_estimate_of(&edited, None));
    assert!(resumed.rerun.start > loop_end, "{:?} reran from before the loop's end", resumed.rerun);
    assert!(resumed.blocks.iter().any(|block| block.executions == 2));
}

#[test]
fn a_block_more_in_a_program_that_fills_the_step_budget_stops_the_run() {
    let machine = MachineConfig::default();
    let files = WorkspaceFiles::default();
    let text = Arc::new(long_program(2500));
    let budget = estimate(None, &text, &files, &machine, 1_000_000).blocks_run;
    let first = estimate(None, &text, &files, &machine, budget);
    assert_eq!(first.stopped, None);
    let at = text.find("N1503 ").expect("the block");
    let edited = Arc::new(format!("{}N5 X1 Y1\n{}", &text[..at], &text[at..]));
    let resumed = estimate(Some(&first), &edited, &files, &machine, budget);
    let whole = estimate(None, &edited, &files, &machine, budget);
    assert!(whole.stopped.is_some());
    assert_alike(&resumed, &whole);
}

#[test]
fn an_edit_that_changes_everything_after_it_reruns_to_the_end() {
    let text = long_program(3000);
    let first = estimate_of(&text, None);
    let edited = text.replacen("N1500 ", "N1500 G91 ", 1);
    let resumed = estimate_of(&edited, Some(&first));
    assert_eq!(resumed.rerun.end, TextSize::of(edited.as_str()));
    assert!(resumed.rerun.start > TextSize::default());
    assert_alike(&resumed, &estimate_of(&edited, None));
}

#[test]
fn under_the_envelope_velocity_an_edit_reruns_from_the_checkpoint_before_it_to_the_end() {
    let machine = MachineConfig { constants: [(338, 20)].into(), ..MachineConfig::default() };
    let files = WorkspaceFiles::default();
    let text = Arc::new(long_program(3000));
    let first = estimate(None, &text, &files, &machine, 1_000_000);
    let at = text.find("N1503 X").expect("the block") + "N1503 X".len();
    let edited = Arc::new(format!("{}7{}", &text[..at], &text[at..]));
    let resumed = estimate(Some(&first), &edited, &files, &machine, 1_000_000);
    assert!(edited[usize::from(resumed.rerun.start)..].starts_with("N1001 "));
    assert_eq!(resumed.rerun.end, TextSize::of(edited.as_str()));
    assert_alike(&resumed, &estimate(None, &edited, &files, &machine, 1_000_000));
}

#[test]
fn a_changed_macrocycle_file_reruns_from_the_last_checkpoint() {
    let text = long_program(2500).replace("N99999 G00 Z5 M30", "N99998 G72 L9001\nN99999 G00 Z5 M30");
    let files = |x: &str| WorkspaceFiles {
        own_program: None,
        macrocycles: [(
            9001,
            ("L9001".to_owned(), Arc::new(format!("N1 G79 L9001\nN2 G91 G01 X{x}\nN3 G90 G70\n*\n"))),
        )]
        .into_iter()
        .collect(),
        by_stem: Vec::new(),
        programs: FxHashMap::default(),
        control_files: Vec::new(),
    };
    let machine = MachineConfig::default();
    let text = Arc::new(text);
    let first = estimate(None, &text, &files("10"), &machine, 1_000_000);
    // Not the file's text: an edit of the file then changes it in place.
    assert!(!Arc::ptr_eq(&first.text, &text));
    assert!(first.holds_for(&RunInput {
        text: text.clone(),
        machine: machine.clone(),
        files: files("10"),
        lowered: None
    }));
    let changed = files("30");
    assert!(!first.holds_for(&RunInput {
        text: text.clone(),
        machine: machine.clone(),
        files: changed.clone(),
        lowered: None
    }));
    let resumed = estimate(Some(&first), &text, &changed, &machine, 1_000_000);
    assert!(resumed.rerun.start > TextSize::default());
    assert_alike(&resumed, &estimate(None, &text, &changed, &machine, 1_000_000));
    // 20 mm more at the last feed, 900 mm/min.
    let longer = resumed.totals.total - first.totals.total;
    assert!((longer - 20.0 / 15.0).abs() < 0.05, "{longer}");
}

/// A Haas program's M98 runs the program file named after the number
/// in the workspace, as the editor has it.
#[test]
fn a_haas_program_runs_the_program_files_of_the_workspace() {
    let mut host = AnalysisHost::in_dialect(Dialect::HaasLathe, Config::default());
    let file = host.add_file("/p/main.nc", "O1\nM98 P1000\nM30\n");
    host.add_file("/p/O01000.nc", "O1000\nG98 G01 W-10. F600.\nM99\n");
    host.add_file("/p/other.nc", "O2\nM30\n");
    let input = host.analysis().run_input(file).expect("a program");
    assert_eq!(input.files.program_file(1000).map(|(path, _)| path), Some("/p/O01000.nc"));
    assert_eq!(input.files.program_file(2), None, "found by its file's name only");
    // 10 mm at 600 mm/min, with the ramps.
    let total = input.estimate(None, 1000, &|| false).expect("never abandoned").totals.total;
    assert!(total >= 1.0, "{total}");
}

/// The program file being edited is one of the workspace's program files
/// (`O01234.nc`): its edit changes the run's text, not the files it calls,
/// so the estimate resumes and rejoins; its own number runs its current
/// text.
#[test]
fn an_edit_of_a_haas_program_file_named_after_its_number_resumes_its_estimate() {
    let text = long_haas_program(5000);
    let mut host = AnalysisHost::in_dialect(Dialect::HaasLathe, Config::default());
    let file = host.add_file("/p/O00001.nc", text.as_str());
    let input = host.analysis().run_input(file).expect("a program");
    assert_eq!(input.files.program_file(1), None, "the run's own text, not a copy");
    let first = input.estimate(None, 1_000_000, &|| false).expect("never abandoned");
    let at = text.find("N2503 X").expect("the block") + "N2503 X".len();
    host.apply_edit(file, &TextEdit::replace(TextRange::empty(TextSize::of(&text[..at])), "7"));
    let edited = host.analysis().run_input(file).expect("a program");
    let resumed = edited.estimate(Some(&first), 1_000_000, &|| false).expect("never abandoned");
    assert!(usize::from(resumed.rerun.end) < edited.text.len(), "{:?}", resumed.rerun);
    assert_alike(&resumed, &haas_estimate_of(&edited.text, None));

    let own = WithOwnProgram { environment: &edited.files, number: edited.files.own_program, text: &edited.text };
    assert_eq!(own.file(&Called::Program(1)).as_deref(), Some(edited.text.as_str()));
}

/// The run of a Haas program in the editor reads the blocks the analysis
/// lowered chunk by chunk, edit after edit, and times them as a run that
/// lowers the text itself does.
#[test]
fn a_haas_run_of_the_analysis_blocks_equals_a_run_of_the_text() {
    // A digit typed, a loop back inserted before a block, a digit deleted.
    let lines = "N4000 G01 X5. Z-3.\n#1 = #1 + 1\nIF [#1 LT 2] GOTO 3000\n";
    let edits = [("N2503 X", 0, "7"), ("N4000 ", 0, lines), ("N17 X", 1, "")];
    assert_runs_of_the_analysis_blocks_equal_runs_of_the_text(Dialect::HaasLathe, long_haas_program(5000), &edits);
}

/// As [`a_haas_run_of_the_analysis_blocks_equals_a_run_of_the_text`], for
/// Sinumerik.
#[test]
fn a_sinumerik_run_of_the_analysis_blocks_equals_a_run_of_the_text() {
    let lines = "R1=0\nWHILE R1<2\nN4000 G1 X5 Y-3\nR1=R1+1\nENDWHILE\n";
    let edits = [("N2503 G1 X", 0, "7"), ("N4000 ", 0, lines), ("N17 G1 X", 1, "")];
    assert_runs_of_the_analysis_blocks_equal_runs_of_the_text(Dialect::Sinumerik, long_sinumerik_program(5000), &edits);
}

/// Opens `text` in the analysis and applies `edits` (after the first
/// `before` (its end, when it ends with a letter), `deleted` bytes
/// replaced by `written`): each time, the estimate of the analysis's run
/// input, resumed from the last, equals a whole run of the text.
fn assert_runs_of_the_analysis_blocks_equal_runs_of_the_text(
    dialect: Dialect,
    text: String,
    edits: &[(&str, u32, &str)],
) {
    let machine = MachineConfig::of_control(dialect);
    let whole = |text: &Arc<String>| estimate(None, text, &WorkspaceFiles::default(), &machine, 1_000_000);
    let mut host = AnalysisHost::in_dialect(dialect, Config::default());
    let file = host.add_file("/p/surface.nc", text.as_str());
    let input = host.analysis().run_input(file).expect("a program");
    assert!(input.lowered.is_some());
    let mut previous = input.estimate(None, 1_000_000, &|| false).expect("never abandoned");
    assert_alike(&previous, &whole(&input.text));
    for &(before, deleted, written) in edits {
        let text = host.analysis().run_input(file).expect("a program").text;
        let mut at = text.find(before).expect("the block");
        if before.ends_with(|c: char| c.is_ascii_alphabetic()) {
            at += before.len();
        }
        let range = TextRange::at(TextSize::of(&text[..at]), TextSize::from(deleted));
        host.apply_edit(file, &TextEdit::replace(range, written));
        let edited = host.analysis().run_input(file).expect("a program");
        // The model read from the chunks' marks is the model of all blocks.
        if let Some(LoweredProgram::Sinumerik(unit)) = &edited.lowered {
            assert_eq!(unit.model, nc_exec::sinumerik::program::SinumerikModel::new(unit.blocks.iter()));
        }
        let resumed = edited.estimate(Some(&previous), 1_000_000, &|| false).expect("never abandoned");
        assert_alike(&resumed, &whole(&edited.text));
        previous = resumed;
    }
}

/// An estimate asked for a text typed on meanwhile is given up.
#[test]
fn an_abandoned_estimate_is_none() {
    let mut host = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
    let file = host.add_file("/p/MAIN.MPF", "G1 X10 F100\nM30\n");
    let input = host.analysis().run_input(file).expect("a program");
    assert!(input.estimate(None, 1000, &|| true).is_none());
    assert!(input.estimate(None, 1000, &|| false).is_some_and(|estimate| estimate.totals.total > 0.0));
}

/// In a dialect whose lines are blocks, a block's hints stand at the
/// end of its own line, not after the lines below it.
#[test]
fn hints_of_a_line_dialect_stand_on_the_blocks_line() {
    let machine = MachineConfig::of_control(Dialect::Sinumerik);
    let text = Arc::new("G0 X10 Z2 ; in\nR1=5\nG1 X20 F600\nM30\n".to_owned());
    let estimate = estimate(None, &text, &WorkspaceFiles::default(), &machine, 1000);
    let lines: Vec<&str> = estimate
        .inlay_hints(None, CycleTimeHints::PerBlock)
        .iter()
        .filter(|hint| hint.kind == InlayHintKind::BlockTime)
        .map(|hint| text[..usize::from(hint.offset)].lines().last().unwrap_or_default())
        .collect();
    assert_eq!(lines, ["G0 X10 Z2 ; in", "G1 X20 F600"]);
}

/// A Haas lathe estimate knows its input: an edit of another file
/// does not run it again.
#[test]
fn a_haas_estimate_holds_for_its_input() {
    let machine = MachineConfig::of_control(Dialect::HaasLathe);
    let text = Arc::new("O1\nG98 G01 X20. Z-10. F100.\nM30\n".to_owned());
    let files = WorkspaceFiles::default();
    let first = estimate(None, &text, &files, &machine, 1000);
    assert_eq!(first.checkpoints.iter().map(|stored| stored.run.block()).collect::<Vec<_>>(), [0]);
    // 5 mm of radius and 10 mm of Z at 100 mm/min, with the ramps.
    assert!(first.totals.total > 125.0f64.sqrt() / 100.0 * 60.0, "{}", first.totals.total);
    assert!(first.holds_for(&RunInput {
        text: text.clone(),
        machine: machine.clone(),
        files: files.clone(),
        lowered: None
    }));
    let milling = MachineConfig::default();
    assert!(!first.holds_for(&RunInput { text: text.clone(), machine: milling, files, lowered: None }));
}

/// A long Haas lathe program: moves from CAM, a dwell now and then, and
/// a local subprogram after its end that edits may call.
fn long_haas_program(blocks: usize) -> String {
    let mut text = String::from("O1\nG54 G18 G97 G98 G00 X0 Z5. M03 S1000\n#100 = 1.\nG01 Z0 F1200.\n");
    for i in 0..blocks {
        let (x, z) = ((i % 97) as f64 * 0.7, -((i / 97) as f64 * 1.3 + (i % 5) as f64 * 0.2));
        let block = match i % 250 {
            17 => "G04 P10".to_owned(),
            31 => format!("G00 X{x:.3} Z{z:.3}"),
            32 => format!("G01 X{x:.3} Z{z:.3} F900."),
            _ => format!("X{x:.3} Z{z:.3}"),
        };
        text.push_str(&format!("N{} {block}\n", i + 3));
    }
    text.push_str("N99999 G00 X100. M30\nN90000 G01 W-0.5\nW0.5\nM99\n");
    text
}

fn haas_estimate_of(text: &str, previous: Option<&Estimate>) -> Estimate {
    let machine = MachineConfig::of_control(Dialect::HaasLathe);
    estimate(previous, &Arc::new(text.to_owned()), &WorkspaceFiles::default(), &machine, 1_000_000)
}

#[test]
fn a_haas_run_takes_no_checkpoints_after_calling_a_subprogram_written_after_the_main_program() {
    let text = long_haas_program(5000).replace("N1503 ", "M97 P90000\nN1503 ");
    let first = haas_estimate_of(&text, None);
    let call = TextSize::of(&text[..text.find("M97 P90000").expect("the call")]);
    let blocks: Vec<usize> = first.checkpoints.iter().map(|stored| stored.run.block()).collect();
    assert!(first.checkpoints.iter().all(|stored| stored.run.offset() < call), "{blocks:?}");
    assert_eq!(blocks, [0, 1000]);
    let at = text.find("N2503 X").expect("the block") + "N2503 X".len();
    let edited = format!("{}7{}", &text[..at], &text[at..]);
    let resumed = haas_estimate_of(&edited, Some(&first));
    assert_alike(&resumed, &haas_estimate_of(&edited, None));
    assert!(edited[usize::from(resumed.rerun.start)..].starts_with("N999 "));
}

#[test]
fn an_edit_of_a_haas_program_reruns_from_the_checkpoint_before_it_to_where_the_run_takes_its_course_again() {
    let text = long_haas_program(5000);
    let first = haas_estimate_of(&text, None);
    assert_eq!(first.stopped, None);
    assert!(first.checkpoints.len() >= 5, "{} checkpoints", first.checkpoints.len());
    // A digit typed into an absolute coordinate in the middle.
    let at = text.find("N2503 X").expect("the block") + "N2503 X".len();
    let edited = format!("{}7{}", &text[..at], &text[at..]);
    let resumed = haas_estimate_of(&edited, Some(&first));
    let whole = haas_estimate_of(&edited, None);
    assert_alike(&resumed, &whole);
    assert!(resumed.totals.total > first.totals.total, "the move got longer");
    // From the checkpoint at block 2000 (N1999) to the one at block 3000.
    let rerun = usize::from(resumed.rerun.start)..usize::from(resumed.rerun.end);
    assert!(edited[rerun.clone()].starts_with("N1999 ") && edited[rerun.end..].starts_with("N2999 "), "{rerun:?}");
    // Edited again, from the resumed estimate: its checkpoints hold.
    let at = edited.find("N4321 X").expect("the block") + "N4321 X".len();
    let again = format!("{}{}", &edited[..at], &edited[at + 1..]);
    let resumed = haas_estimate_of(&again, Some(&resumed));
    assert_alike(&resumed, &haas_estimate_of(&again, None));
    assert!(resumed.rerun.end < TextSize::of(again.as_str()));
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(12))]

    /// Resumed estimates equal whole runs, edit after edit: digits
    /// typed or deleted, blocks inserted or removed, a jump back or
    /// forward inserted, a jump to no block (the run stops there).
    #[test]
    fn resumed_estimates_equal_whole_runs(
        edits in proptest::collection::vec((0.0f64..1.0, 0u8..6), 1..4),
    ) {
        let later = ["N6 G73 L1000 Q1\n", "N7 G73 L77777 Q1\n"];
        assert_edits_resume_as_whole_runs(long_program(2500), &edits, "N5 G01 X1 Y1 F2000\n", &later, estimate_of);
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(12))]

    /// Resumed estimates of a Haas lathe program equal whole runs, edit
    /// after edit: digits typed or deleted, blocks inserted or removed,
    /// a jump back or forward once, a jump to no block (the run stops
    /// there), a call, a block numbered like a jump's target.
    #[test]
    fn resumed_haas_estimates_equal_whole_runs(
        edits in proptest::collection::vec((0.0f64..1.0, 0u8..8), 1..4),
    ) {
        let later = ["#1 = #1 + 1\nIF [#1 LT 2] GOTO 1000\n", "GOTO 77777\n", "M97 P90000\n", "N1000 G01 X2.\n"];
        let first = "N5 G01 X1. Z1. F2000.\n";
        assert_edits_resume_as_whole_runs(long_haas_program(2500), &edits, first, &later, haas_estimate_of);
    }
}

/// A CAM-like Sinumerik program of `blocks` moves after a few variables,
/// a label to jump back to and the modes.
fn long_sinumerik_program(blocks: usize) -> String {
    let mut text = String::from("DEF REAL SAFE=5\nDEF INT PASS\nTOP: R2=R2+1\nR1=0\n");
    text.push_str("N1 G17 G54 G90 G0 X0 Y0 Z=SAFE S8000 M3\nN2 G1 Z-1 F1200\n");
    for i in 0..blocks {
        let (x, y) = ((i % 97) as f64 * 0.7, (i / 97) as f64 * 1.3 + (i % 5) as f64 * 0.2);
        let block = match i % 250 {
            17 => "G4 F0.01".to_owned(),
            31 => format!("G0 X{x:.3} Y{y:.3}"),
            32 => format!("G1 X{x:.3} Y{y:.3} F900"),
            _ => format!("G1 X{x:.3} Y{y:.3} F{}", 1000 + i % 3 * 100),
        };
        text.push_str(&format!("N{} {block}\n", i + 3));
    }
    text.push_str("N99999 G0 Z5 M30\n");
    text
}

fn sinumerik_estimate_of(text: &str, previous: Option<&Estimate>) -> Estimate {
    let machine = MachineConfig::of_control(Dialect::Sinumerik);
    estimate(previous, &Arc::new(text.to_owned()), &WorkspaceFiles::default(), &machine, 1_000_000)
}

#[test]
fn an_edit_of_a_sinumerik_program_reruns_from_the_checkpoint_before_it_to_where_the_run_takes_its_course_again() {
    let text = long_sinumerik_program(5000);
    let first = sinumerik_estimate_of(&text, None);
    assert_eq!(first.stopped, None);
    assert!(first.checkpoints.len() >= 5, "{} checkpoints", first.checkpoints.len());
    // A digit typed into an absolute coordinate in the middle.
    let at = text.find("N2503 G1 X").expect("the block") + "N2503 G1 X".len();
    let edited = format!("{}7{}", &text[..at], &text[at..]);
    let resumed = sinumerik_estimate_of(&edited, Some(&first));
    let whole = sinumerik_estimate_of(&edited, None);
    assert_alike(&resumed, &whole);
    assert!(resumed.totals.total > first.totals.total, "the move got longer");
    // From the checkpoint at block 2000 (N1997) to the one at block 3000.
    let rerun = usize::from(resumed.rerun.start)..usize::from(resumed.rerun.end);
    assert!(edited[rerun.clone()].starts_with("N1997 ") && edited[rerun.end..].starts_with("N2997 "), "{rerun:?}");
    // Edited again, from the resumed estimate: its checkpoints hold.
    let at = edited.find("N4321 G1 X").expect("the block") + "N4321 G1 X".len();
    let again = format!("{}{}", &edited[..at], &edited[at + 1..]);
    let resumed = sinumerik_estimate_of(&again, Some(&resumed));
    assert_alike(&resumed, &sinumerik_estimate_of(&again, None));
    assert!(resumed.rerun.end < TextSize::of(again.as_str()));
    // A variable the moves do not read, set otherwise before the
    // checkpoints: a jump back to the label could run it, so the run goes
    // to the end; and the same as a whole run.
    let renamed = again.replace("R1=0", "R1=0+0");
    let resumed = sinumerik_estimate_of(&renamed, Some(&resumed));
    assert_alike(&resumed, &sinumerik_estimate_of(&renamed, None));
    assert_eq!(resumed.rerun.end, TextSize::of(renamed.as_str()));
}

#[test]
fn a_sinumerik_block_without_a_step_that_a_jump_back_runs_again_is_part_of_the_course() {
    // The label's block is the last before the checkpoint at block 1000,
    // and the jump back runs it again: what it computes then shows only
    // in the move at the end.
    let text = long_sinumerik_program(2500);
    let at = text.match_indices('\n').nth(998).expect("the line").0 + 1;
    let end = "R2=R2+1\nIF R2<3 GOTOB LBL\nG1 X=R1 Y1\nN99999 ";
    let text = format!("{}LBL: R1=R2-1\n{}", &text[..at], &text[at..]).replace("N99999 ", end);
    let first = sinumerik_estimate_of(&text, None);
    assert_eq!(first.stopped, None);
    let after = TextSize::of(&text[..at]) + TextSize::of("LBL: R1=R2-1\n");
    assert!(first.checkpoints.iter().any(|stored| stored.run.offset() == after));
    // As long, and the same value on the first run (R2 is 1), another on
    // the second.
    let edited = text.replace("LBL: R1=R2-1", "LBL: R1=1-R2");
    let resumed = sinumerik_estimate_of(&edited, Some(&first));
    assert_alike(&resumed, &sinumerik_estimate_of(&edited, None));
    assert_ne!(resumed.totals.total, first.totals.total, "the last move ends elsewhere");
}

#[test]
fn a_haas_block_without_a_move_that_a_jump_back_runs_again_drops_the_checkpoints_after_it() {
    // As for Sinumerik, but a Haas macro block makes a step without a
    // move: its second run shows, and the checkpoints after it go.
    let text = long_haas_program(2500);
    let at = text.match_indices('\n').nth(998).expect("the line").0 + 1;
    let end = "#2 = #2 + 1\nIF [#2 LT 3] GOTO 2\nG01 X[#1] Z1.\nN99999 ";
    let text = format!("{}N2 #1 = #2 - 1\n{}", &text[..at], &text[at..]).replace("N99999 ", end);
    let first = haas_estimate_of(&text, None);
    assert_eq!(first.stopped, None);
    let n2 = TextSize::of(&text[..at]);
    assert!(first.checkpoints.iter().all(|stored| stored.run.offset() <= n2));
    // The same value on the first run (#2 is 0), another on the others.
    let edited = text.replace("N2 #1 = #2 - 1", "N2 #1 = 1 - #2");
    let resumed = haas_estimate_of(&edited, Some(&first));
    assert_alike(&resumed, &haas_estimate_of(&edited, None));
    assert_ne!(resumed.totals.total, first.totals.total, "the last move ends elsewhere");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(12))]

    /// Resumed estimates of a Sinumerik program equal whole runs, edit
    /// after edit: digits typed or deleted, blocks inserted or removed, a
    /// WHILE loop, a jump back to the label at the top, a label and a jump
    /// back to it, IF … ENDIF, a jump to no label (the run stops there).
    #[test]
    fn resumed_sinumerik_estimates_equal_whole_runs(
        edits in proptest::collection::vec((0.0f64..1.0, 0u8..10), 1..4),
    ) {
        let later = [
            "WHILE R1<2\nR1=R1+1\nG1 X=R1 Y1\nENDWHILE\n",
            "IF R2<2 GOTOB TOP\n",
            "LBL: G1 X2 Y2\n",
            "R3=R3+1\nIF R3<2 GOTOB LBL\n",
            "IF R2>0\nG1 X3 Y3\nENDIF\n",
            "GOTOF NOWHERE\n",
        ];
        let first = "N5 G1 X1 Y1 F2000\n";
        assert_edits_resume_as_whole_runs(long_sinumerik_program(2500), &edits, first, &later, sinumerik_estimate_of);
    }
}

/// Applies `edits` to `text` one by one, at a place (a fraction of the
/// text) of a kind: a digit typed into (0) or deleted from (1) an X
/// word, the block `first` inserted anywhere (2), a block of `later`
/// (3 on) inserted after the first line, else a line removed; after
/// each, the estimate resumed from the last equals a whole run's.
fn assert_edits_resume_as_whole_runs(
    mut text: String,
    edits: &[(f64, u8)],
    first: &str,
    later: &[&str],
    estimate_of: fn(&str, Option<&Estimate>) -> Estimate,
) {
    let mut previous = estimate_of(&text, None);
    for &(place, kind) in edits {
        let line_start = text[..(place * text.len() as f64) as usize].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[line_start..].find('\n').map_or(text.len(), |i| line_start + i + 1);
        let word = text[line_start..line_end].find(" X").map(|i| line_start + i + 2);
        let block = usize::from(kind).checked_sub(3).and_then(|i| later.get(i));
        match (kind, word, block) {
            (0, Some(at), _) => text.insert(at, '3'),
            (1, Some(at), _) => {
                text.remove(at);
            }
            (2, _, _) => text.insert_str(line_start, first),
            (_, _, Some(block)) if line_start > 0 => text.insert_str(line_start, block),
            _ if line_start > 0 && line_end < text.len() => text.replace_range(line_start..line_end, ""),
            _ => {}
        }
        let resumed = estimate_of(&text, Some(&previous));
        assert_alike(&resumed, &estimate_of(&text, None));
        previous = resumed;
    }
}

#[test]
fn times_read_short() {
    let shown: Vec<String> = [0.0, 0.0004, 0.0123, 0.42, 0.9996, 4.254, 59.97, 83.44, 3723.4].map(short_time).to_vec();
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
    // Rounded to the millisecond before it is split: never `:60.000`.
    assert_eq!(clock(119_999.999_9), "33:20:00.000");
    assert_eq!(clock(59.9996), "0:01:00.000");
}
