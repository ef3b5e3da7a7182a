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
