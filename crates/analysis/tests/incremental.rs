//! Changing one block recomputes only what depends on it: the block's chunk
//! (a run of blocks) is lowered and checked again, no other.

use ncc_analysis::{
    AnalysisHost, Config, Dialect, FileId, Known, RootDatabase, TextEdit, TextRange, TextSize,
    cnc8x6::flow::{ModalState, ParamState},
};

fn program(blocks: usize) -> String {
    let mut text = String::from("%1 \"INCREMENTAL\"\n");
    for n in 1..=blocks {
        text.push_str(&format!("N{n} G01 X{n}. Y-{n}.5 F200\n"));
    }
    text.push_str("N9999 M30\n*\n");
    text
}

fn count(executions: &[String], query: &str) -> usize {
    executions.iter().filter(|e| e.starts_with(query)).count()
}

#[test]
fn an_edit_relowers_and_rechecks_only_the_touched_chunk() {
    let text = program(5000);
    let mut host = AnalysisHost::with_database(RootDatabase::with_execution_log(), Dialect::Cnc8x6, Config::default());
    let file = host.add_file("main.NCP", text.as_str());
    assert!(host.analysis().diagnostics(file).is_empty());
    let first = host.db().take_executions();
    let chunks = count(&first, "chunk_diagnostics");
    assert!(chunks > 5, "a program of 5000 blocks has several chunks: {chunks}");
    assert_eq!(count(&first, "chunk_summaries"), chunks);

    // Change `X2500.` to `X2600.` in block N2500.
    let at = text.find("N2500 G01 X2500.").unwrap() + "N2500 G01 X2".len();
    let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::from(1)), "6");
    host.apply_edit(file, &edit);
    assert!(host.analysis().diagnostics(file).is_empty());
    let second = host.db().take_executions();
    assert_eq!(count(&second, "chunk_diagnostics"), 1, "only the edited block's chunk is checked again: {second:#?}");
    assert_eq!(count(&second, "chunk_summaries"), 1, "{second:#?}");

    // An edit that introduces an error is reported at the right place.
    let at = text.find("N4000 G01 X4000.").unwrap() + "N4000 G01 X".len();
    let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::from(0)), "12");
    host.apply_edit(file, &edit);
    let diagnostics = host.analysis().diagnostics(file);
    assert_eq!(diagnostics.len(), 1, "{diagnostics:#?}");
    assert_eq!(diagnostics[0].name, "too-many-digits");
    let third = host.db().take_executions();
    assert_eq!(count(&third, "chunk_diagnostics"), 1, "{third:#?}");
}

/// A program whose state changes along the way: feeds, parameters, planes,
/// and a subprogram, called from the main body if `calls`.
fn stateful_program(blocks: usize, calls: bool) -> String {
    let mut text = String::from("%2 \"STATES\"\nN1 G90 G17 F100 S500 R1=10.\n");
    for n in 2..=blocks {
        let extra = match n % 97 {
            0 if calls => " G71 L5".to_owned(),
            13 => format!(" F{}", 100 + n),
            29 => format!(" R1={n}."),
            41 => " G18".to_owned(),
            59 => " G17".to_owned(),
            _ => String::new(),
        };
        text.push_str(&format!("N{n} G01 X{n}. YR1{extra}\n"));
    }
    text.push_str("N9990 M30\nN9991 G79 L5\nN9992 G91 F33 R1=3.\nN9993 G70\n*\n");
    text
}

/// The states the walk reaches each block in, as a fresh analysis sees
/// them, equal what an analysis that kept checkpoints across edits says.
#[test]
fn states_after_edits_equal_a_fresh_walk() {
    // Without calls the checkpoints before an edit survive it; with them,
    // those after a call do not (the subprogram's ranges moved).
    for calls in [false, true] {
        states_after_edits_equal_a_fresh_walk_in(stateful_program(700, calls));
    }
}

fn states_after_edits_equal_a_fresh_walk_in(mut text: String) {
    let mut host = AnalysisHost::new(Config::default());
    let file = host.add_file("main.NCP", text.as_str());
    let probes = |text: &str| -> Vec<TextSize> {
        ["N3 ", "N130 ", "N260 ", "N400 ", "N555 ", "N699 ", "N9992 "]
            .iter()
            .filter_map(|block| text.find(block))
            .map(|at| TextSize::from(at as u32 + 1))
            .collect()
    };
    // Questions fill the checkpoints before every edit.
    for offset in probes(&text) {
        host.analysis().states_at(file, offset);
    }
    let edits: [(&str, &str); 7] = [
        ("N300 G01 X300.", "N300 G01 G91 X300."),
        ("N200 G01 X200. YR1", "N200 G01 X200. YR1 F7"),
        ("N9992 G91 F33", "N9992 G91 F44"),
        ("N150 G01", "N150 G02"),
        ("N5 G01 X5. YR1", "N5 G01 X5. YR1 R1=99."),
        ("N600 G01 X600.", "N600 G01 X600.\nN601 G79 L6\nN602 G70"),
        ("N2 G01", "N2 G19 G01"),
    ];
    for (find, replace) in edits {
        let at = text.find(find).unwrap_or_else(|| panic!("{find}"));
        let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::of(find)), replace);
        host.apply_edit(file, &edit);
        edit.apply(&mut text);
        let mut fresh = AnalysisHost::new(Config::default());
        let fresh_file = fresh.add_file("main.NCP", text.as_str());
        for offset in probes(&text) {
            let kept = host.analysis().states_at(file, offset);
            assert_eq!(kept, fresh.analysis().states_at(fresh_file, offset), "after `{replace}`, at {offset:?}");
        }
    }
}

/// Block numbers are compared across chunks only where their ranges
/// overlap; a duplicate far apart, in a program numbered in order or not,
/// is found either way, and each later use points at the first.
#[test]
fn duplicate_block_numbers_are_found_across_chunks() {
    let block = |n: usize| format!("N{n} G01 X{n}. Y-{n}.5 F200\n");
    let check = |numbers: Vec<usize>, duplicate: usize| {
        let mut text = String::from("%1\n");
        for &n in &numbers {
            text.push_str(&block(n));
        }
        text.push_str("N99999 M30\n*\n");
        let mut host = AnalysisHost::default();
        let file = host.add_file("main.NCP", text.as_str());
        let found: Vec<_> = host.analysis().diagnostics(file).into_iter().filter(|d| d.code == "P104").collect();
        let later = text.rfind(&format!("N{duplicate} ")).unwrap();
        let first = text.find(&format!("N{duplicate} ")).unwrap();
        assert_eq!(found.len(), 1, "{found:#?}");
        assert_eq!(usize::from(found[0].range.start()), later);
        assert_eq!(usize::from(found[0].related[0].range.start()), first);
    };
    // In order, with N10 used again near the end.
    let mut ascending: Vec<usize> = (1..=4000).map(|n| n * 10).collect();
    ascending[3900] = 10;
    check(ascending, 10);
    // Descending, then a run in order: every chunk's range overlaps others.
    let mut mixed: Vec<usize> = (1..=2000).rev().chain(3000..5000).collect();
    mixed.push(1500);
    check(mixed, 1500);
}

/// An edit changes a text nobody else holds in place, and copies one that
/// someone still reads.
#[test]
fn edits_change_an_unshared_text_in_place() {
    let mut host = AnalysisHost::default();
    let file = host.add_file("main.NCP", program(100));
    let at = program(100).find("X50.").unwrap() + 1;
    let digit = |text: &str| text[at..at + 1].to_owned();
    let edit = |digit: &str| TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::from(1)), digit);
    let buffer = host.analysis().text(file).as_ptr();
    host.apply_edit(file, &edit("6"));
    assert_eq!(host.analysis().text(file).as_ptr(), buffer, "the text was copied");
    assert_eq!(digit(&host.analysis().text(file)), "6");

    let held = host.analysis().text(file);
    host.apply_edit(file, &edit("7"));
    assert_eq!(digit(&held), "6", "a text someone holds never changes");
    assert_eq!(digit(&host.analysis().text(file)), "7");
    assert!(host.analysis().diagnostics(file).is_empty());
}

/// The states a fresh analysis of `text` finds at `offset`.
fn fresh_states(text: &str, offset: TextSize) -> Vec<(ModalState, ParamState)> {
    let mut host = AnalysisHost::new(Config::default());
    let file = host.add_file("main.NCP", text);
    host.analysis().states_at(file, offset)
}

/// Replaces the first `find` in `text` with `replace`, in the host too.
fn replace(host: &mut AnalysisHost, file: FileId, text: &mut String, find: &str, replace: &str) {
    let at = text.find(find).unwrap_or_else(|| panic!("`{find}` is not in the program"));
    let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::of(find)), replace);
    host.apply_edit(file, &edit);
    edit.apply(text);
}

/// Where block `number` starts.
fn block(text: &str, number: usize) -> TextSize {
    let at = text.find(&format!("\nN{number} ")).unwrap_or_else(|| panic!("no block N{number}"));
    TextSize::from(at as u32 + 1)
}

/// The one state the checkpoints give at block `number`, checked against a
/// fresh walk.
fn state_at(host: &AnalysisHost, file: FileId, text: &str, number: usize) -> (ModalState, ParamState) {
    let offset = block(text, number);
    let kept = host.analysis().states_at(file, offset);
    assert_eq!(kept, fresh_states(text, offset), "at N{number}");
    assert_eq!(kept.len(), 1, "N{number} is in the main body");
    kept.into_iter().next().unwrap()
}

/// A host whose checkpoints cover `text` up to block `last`.
fn filled(text: String, last: usize) -> (AnalysisHost, FileId, String) {
    let mut host = AnalysisHost::new(Config::default());
    let file = host.add_file("main.NCP", text.as_str());
    host.analysis().states_at(file, block(&text, last));
    (host, file, text)
}

/// Edits early in a long program whose effect on the state ends within a
/// block or two leave the checkpoints far after them good.
#[test]
fn a_question_far_after_an_early_edit_equals_a_fresh_walk() {
    let (mut host, file, mut text) = filled(stateful_program(4000, false), 4000);
    for (find, with) in
        [("N100 G01 X100.", "N100 G01 X1000."), ("N101 G01 X101.", "N101 G01  X101."), ("N5 G01 X5", "N5 G01 X")]
    {
        replace(&mut host, file, &mut text, find, with);
        for number in [3990, 2500, 120, 3000] {
            state_at(&host, file, &text, number);
        }
    }
}

/// An edit that changes the state before the checkpoints shows in every
/// later answer: the checkpoints after it are checked against the walk.
#[test]
fn an_edit_that_changes_the_state_reaches_the_checkpoints_after_it() {
    let (mut host, file, mut text) = filled(stateful_program(4000, false), 4000);
    // N110 sets the feed (110 % 97 == 13), which holds until N207.
    replace(&mut host, file, &mut text, "N110 G01 X110. YR1 F210", "N110 G01 X110. YR1 F999");
    let (state, _) = state_at(&host, file, &text, 200);
    assert_eq!(state.feed.known().flatten().map(|f| f.value.to_string()), Some("999".to_owned()));
    state_at(&host, file, &text, 3500);

    // N126 assigns R1 (126 % 97 == 29), which every block's Y reads.
    replace(&mut host, file, &mut text, "N126 G01 X126. YR1 R1=126.", "N126 G01 X126. YR1 R1=5.");
    let (state, params) = state_at(&host, file, &text, 200);
    assert_eq!(params.values.get(1), Some(5000));
    assert_eq!(state.position(b'Y'), Some(5000));
    state_at(&host, file, &text, 3600);

    // G91 holds to the end; the blocks around it hold no text range a
    // later state keeps, so only the walk tells the checkpoints after it.
    replace(&mut host, file, &mut text, "N140 G01", "N140 G91");
    let (state, _) = state_at(&host, file, &text, 3900);
    assert_eq!(state.g(9), Some(Some(91)));
    state_at(&host, file, &text, 2000);
    replace(&mut host, file, &mut text, "N140 G91", "N140 G01");
    let (state, _) = state_at(&host, file, &text, 3900);
    assert_eq!(state.g(9), Some(Some(90)));
}

/// Inserted and deleted blocks move the checkpoints after them.
#[test]
fn inserted_and_deleted_blocks_move_the_checkpoints() {
    let (mut host, file, mut text) = filled(stateful_program(4000, false), 4000);
    let numbers = [3950, 1000, 300, 2222];
    let edits: [(&str, &str); 6] = [
        // A block of its own, setting the feed until N304.
        ("\nN300 ", "\nN7000 G01 F5\nN300 "),
        // A line break inside a block.
        ("N400 G01 X400.", "N400 G01\nX400."),
        // A block deleted.
        ("N500 G01 X500. YR1\n", ""),
        // Two blocks joined.
        ("YR1\nN601 ", "YR1 N601 "),
        // A block split in two.
        ("N700 G01 X700. YR1", "N700 G01\nN7001 X700. YR1"),
        // A blank line.
        ("\nN800 ", "\n\nN800 "),
    ];
    for (find, with) in edits {
        replace(&mut host, file, &mut text, find, with);
        for number in numbers {
            state_at(&host, file, &text, number);
        }
    }
    // Several lines deleted at once, across checkpoints.
    let lines = text.find("N900 ").unwrap()..text.find("N1300 ").unwrap();
    let edit =
        TextEdit::replace(TextRange::new(TextSize::from(lines.start as u32), TextSize::from(lines.end as u32)), "");
    host.apply_edit(file, &edit);
    edit.apply(&mut text);
    for number in [3950, 1400, 300, 850] {
        state_at(&host, file, &text, number);
    }
}

/// Editing a subprogram changes the state after every call of it.
#[test]
fn an_edited_subprogram_reaches_the_checkpoints_after_its_calls() {
    // L5 ends at its G70; the blocks after it belong to no unit.
    let subprogram = "N9993 X1.\nN9994 G17\nN9995 G70\nN9996 G19\nN9997 X5.\n";
    let text = stateful_program(4000, true).replace("N9993 G70\n", subprogram);
    let (mut host, file, mut text) = filled(text, 4000);
    let plane = |state: &ModalState, code| state.modes.g_groups().any(|slot| slot == Known::Is(Some(code)));
    let feed = |state: &ModalState| state.feed.known().flatten().map(|f| f.value.to_string());
    // The checkpoint before N2817 follows the call in N2813 (a multiple of
    // 97), whose feed holds until N2826; the one before N897 follows the
    // call in N873, whose plane holds until N914.
    let (state, _) = state_at(&host, file, &text, 2820);
    assert_eq!(feed(&state).as_deref(), Some("33"));
    let (state, _) = state_at(&host, file, &text, 900);
    assert!(plane(&state, 17), "{state:?}");
    // No text range in the states points into the edited blocks: only the
    // subprogram's blocks the walk entered tell.
    replace(&mut host, file, &mut text, "N9994 G17", "N9994 G18");
    let (state, _) = state_at(&host, file, &text, 900);
    assert!(plane(&state, 18), "{state:?}");
    replace(&mut host, file, &mut text, "N9992 G91 F33", "N9992 G91 F44");
    let (state, _) = state_at(&host, file, &text, 2820);
    assert_eq!(feed(&state).as_deref(), Some("44"));
    // An edit in the subprogram that changes no state moves its ranges.
    replace(&mut host, file, &mut text, "N9992 G91", "N9992  G91");
    state_at(&host, file, &text, 2820);
    // An edit in the main body moves the subprogram after it.
    replace(&mut host, file, &mut text, "N50 G01", "N50  G01");
    for number in [2820, 900, 60] {
        state_at(&host, file, &text, number);
    }
    // A G70 after its last one makes L5 end there: the edit is not in L5's
    // blocks, but L5 changed. A call still returns at the first G70 it
    // reaches, as the control does...
    replace(&mut host, file, &mut text, "N9997 X5.", "N9997 G70");
    let (state, _) = state_at(&host, file, &text, 900);
    assert!(plane(&state, 18), "{state:?}");
    // ...and runs the G19 after it only when a jump leads there.
    replace(&mut host, file, &mut text, "N9994 G18", "N9994 G18 G73 L9996");
    let (state, _) = state_at(&host, file, &text, 900);
    assert!(plane(&state, 19), "{state:?}");
}

/// A fixed sequence of random edits, each followed by questions here and
/// there (or by none, so that several edits meet the checkpoints at once):
/// every answer equals a fresh walk.
#[test]
fn random_edits_keep_the_states_equal_to_a_fresh_walk() {
    random_edits_in(stateful_program(1500, true), 120);
}

/// The same with jumps: one over a few blocks, and a loop back over it,
/// which the edits move, break and mend.
#[test]
fn random_edits_around_jumps_keep_the_states_equal_to_a_fresh_walk() {
    let text = stateful_program(1500, true)
        .replace("N300 G01 X300. YR1", "N300 G01 X300. YR1 G73 L305")
        .replace("N700 G01 X700. YR1", "N700 G01 X700. YR1 G73 L290 Q2");
    random_edits_in(text, 60);
}

fn random_edits_in(mut text: String, rounds: usize) {
    let mut host = AnalysisHost::new(Config::default());
    let file = host.add_file("main.NCP", text.as_str());
    let mut seed = 0x9E37_79B9_7F4A_7C15_u64;
    let mut below = |bound: usize| {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (seed >> 33) as usize % bound
    };
    for round in 0..rounds {
        let lines: Vec<usize> = std::iter::once(0).chain(text.match_indices('\n').map(|(at, _)| at + 1)).collect();
        // Any line but the header and the end.
        let line = 1 + below(lines.len() - 3);
        let (start, end) = (lines[line], lines[line + 1]);
        let at = start + below(end - start);
        let (range, insert) = match below(6) {
            0 => (at..at, char::from(b'0' + below(10) as u8).to_string()),
            1 => (at..at + 1, String::new()),
            2 => (at..at, "\n".to_owned()),
            3 => (start..end, String::new()),
            4 => (start..start, ["N1 G91\n", "N2 F7\n", "N3 R1=2.\n", "N4 G18\n", "N5 G71 L5\n"][below(5)].to_owned()),
            _ => {
                let flips = [("G90", "G91"), ("G91", "G90"), ("G17", "G18"), ("F1", "F2"), ("R1=", "R1=9")];
                let (from, to) = flips[below(flips.len())];
                match text[start..].find(from).map(|i| start + i) {
                    Some(i) => (i..i + from.len(), to.to_owned()),
                    None => (at..at, " ".to_owned()),
                }
            }
        };
        if text[range.clone()].contains(['%', '*']) {
            continue;
        }
        let edit = TextEdit::replace(
            TextRange::new(TextSize::from(range.start as u32), TextSize::from(range.end as u32)),
            insert,
        );
        host.apply_edit(file, &edit);
        edit.apply(&mut text);
        if below(2) == 0 {
            host.analysis().prepare_states(file);
        }
        if below(3) == 0 {
            continue;
        }
        let mut fresh = AnalysisHost::new(Config::default());
        let fresh_file = fresh.add_file("main.NCP", text.as_str());
        for _ in 0..3 {
            let offset = TextSize::from(below(text.len()) as u32);
            let kept = host.analysis().states_at(file, offset);
            assert_eq!(kept, fresh.analysis().states_at(fresh_file, offset), "round {round}, at {offset:?}");
        }
    }
}

/// Preparing the states on another thread while questions come: every
/// answer equals a fresh walk's, and the preparation gives way to them.
#[test]
fn questions_during_preparation_equal_a_fresh_walk() {
    let text = stateful_program(3000, true);
    let mut host = AnalysisHost::new(Config::default());
    let file = host.add_file("main.NCP", text.as_str());
    let mut fresh = AnalysisHost::new(Config::default());
    let fresh_file = fresh.add_file("main.NCP", text.as_str());
    let preparing = host.analysis();
    let preparation = std::thread::spawn(move || preparing.prepare_states(file));
    let analysis = host.analysis();
    for step in 1..60 {
        let offset = TextSize::from((text.len() * step / 60) as u32);
        assert_eq!(analysis.states_at(file, offset), fresh.analysis().states_at(fresh_file, offset), "at {offset:?}");
    }
    preparation.join().unwrap();
    let offset = TextSize::from(text.len() as u32 - 20);
    assert_eq!(analysis.states_at(file, offset), fresh.analysis().states_at(fresh_file, offset));
}

/// An edit over most of the text (a paste over it) lets go of the old
/// text's results before the new text is analysed; a key does not.
#[test]
fn an_edit_over_most_of_the_text_lets_go_of_the_old_results_at_once() {
    let old_text = "G0 X1 Y1\nG1 X2 F100\nG1 Y5\nM30\n";
    let mut host = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
    let file = host.add_file("PART.MPF", old_text);
    // The program's lowered blocks, which the cycle-time run reads.
    let blocks = |host: &AnalysisHost| match host.analysis().run_input(file).and_then(|input| input.lowered) {
        Some(nc_exec::run::LoweredProgram::Sinumerik(unit)) => std::sync::Arc::downgrade(&unit),
        _ => panic!("a Sinumerik program has its lowered blocks"),
    };
    let before_key = blocks(&host);
    host.apply_edit(file, &TextEdit::replace(TextRange::at(TextSize::from(4), TextSize::from(1)), "7"));
    assert!(before_key.upgrade().is_some(), "kept until the next question, as salsa does");

    let before_paste = blocks(&host);
    let pasted = "G0 X5\nG1 X6 Y7 F200\nM30\n";
    // A snapshot alive during the edit would make it wait forever.
    let whole = TextRange::up_to(TextSize::of(host.analysis().text(file).as_str()));
    host.apply_edit(file, &TextEdit::replace(whole, pasted));
    assert!(before_paste.upgrade().is_none(), "the old blocks outlived the paste");
    let mut fresh = AnalysisHost::in_dialect(Dialect::Sinumerik, Config::default());
    let fresh_file = fresh.add_file("PART.MPF", pasted);
    assert_eq!(host.analysis().text(file).as_str(), pasted);
    assert_eq!(
        format!("{:?}", host.analysis().diagnostics(file)),
        format!("{:?}", fresh.analysis().diagnostics(fresh_file))
    );
    assert_eq!(
        host.analysis().run_input(file).map(|input| input.text),
        fresh.analysis().run_input(fresh_file).map(|input| input.text)
    );
}
