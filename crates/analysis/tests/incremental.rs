//! Changing one block recomputes only what depends on it.

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
fn an_edit_relowers_and_rechecks_only_the_touched_block() {
    let text = program(50);
    let mut host = AnalysisHost::with_database(RootDatabase::with_execution_log(), Config::default());
    let file = host.add_file("main.NCP", text.as_str());
    assert!(host.analysis().diagnostics(file).is_empty());
    let first = host.db().take_executions();
    assert_eq!(count(&first, "lower_block"), 51, "{first:#?}");

    // Change `X25.` to `X26.` in block N25.
    let at = text.find("N25 G01 X25.").unwrap() + "N25 G01 X2".len();
    let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::from(1)), "6");
    host.apply_edit(file, &edit);
    assert!(host.analysis().diagnostics(file).is_empty());
    let second = host.db().take_executions();
    assert_eq!(count(&second, "lower_block"), 1, "{second:#?}");
    assert_eq!(count(&second, "block_diagnostics"), 1, "{second:#?}");

    // An edit that introduces an error is reported at the right place.
    let at = text.find("N40 G01 X40.").unwrap() + "N40 G01 X".len();
    let edit = TextEdit::replace(TextRange::at(TextSize::from(at as u32), TextSize::from(0)), "123456");
    host.apply_edit(file, &edit);
    let diagnostics = host.analysis().diagnostics(file);
    assert_eq!(diagnostics.len(), 1, "{diagnostics:#?}");
    assert_eq!(diagnostics[0].name, "too-many-digits");
    let third = host.db().take_executions();
    assert_eq!(count(&third, "lower_block"), 1, "{third:#?}");
}
