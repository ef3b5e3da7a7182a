//! Changing one block recomputes only what depends on it: the block's chunk
//! (a run of blocks) is lowered and checked again, no other.

use ncc_analysis::{AnalysisHost, Config, RootDatabase, TextEdit, TextRange, TextSize};

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
    let mut host = AnalysisHost::with_database(RootDatabase::with_execution_log(), Config::default());
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
