//! `ncc-bench lsp-memory`: the language server's resident memory over a
//! long editing session, and after the document closes.
//!
//! The edits come at an editor's pace, as in the `lsp` benchmark: each
//! waits for its first diagnostics and is followed by a hover near it
//! (which meets the modal-state checkpoints being prepared after the
//! edit). Every `pause_every`-th edit is followed by a pause in typing, in
//! which the server finishes what it does in the background (the complete
//! diagnostics after the flow walk, the cycle-time estimate and its
//! checkpoints) and the client asks for the inlay hints of the lines around
//! the edit, as an editor shows them. The resident size is read after such
//! a pause, so that every sample sees the server at rest.

use std::{
    path::Path,
    time::{Duration, Instant},
};

use anyhow::Context;
use ncc_bench::{
    edits::{self, Lcg},
    lsp_client::{Client, Document},
};
use ncc_syntax::Dialect;
use serde_json::{Value, json};

use crate::{SEED, code_near};

/// The goal: the resident size after all edits within 25 % of the one
/// after the first sample.
const GROWTH_GOAL: f64 = 1.25;
/// How long a pause waits for an estimate's refresh before it goes on
/// without one (an edit may leave a line's estimate as it was).
const REFRESH_WAIT: Duration = Duration::from_secs(10);
/// The lines around an edit whose inlay hints the client asks for: what an
/// editor window shows.
const VISIBLE_LINES: usize = 50;
/// After the document closes, the time the server gets to let go of it.
const SETTLE: Duration = Duration::from_secs(1);

pub struct Options {
    pub dialect: Dialect,
    pub blocks: usize,
    pub edits: usize,
    pub sample_every: usize,
    pub pause_every: usize,
    pub json: bool,
}

/// One reading of the server's resident size.
struct Sample {
    edits: usize,
    rss: u64,
    /// Since the document was opened.
    elapsed: Duration,
}

pub fn run(server: &Path, options: &Options) -> anyhow::Result<()> {
    let Options { dialect, blocks, edits, sample_every, pause_every, json: as_json } = *options;
    anyhow::ensure!(edits > 0 && sample_every > 0 && pause_every > 0, "counts must be at least 1");
    let (mut client, _workspace, mut doc) = crate::serve_generated_program(server, dialect, blocks)?;
    let bytes = doc.text().len();
    let rss = |client: &Client| client.memory().map(|m| m.rss).context("the server's memory is unknown (no /proc)");
    let before_open = rss(&client)?;
    let mb = |bytes: u64| bytes as f64 / 1e6;
    // The curve as it comes: a run takes minutes.
    let show = |sample: &Sample| {
        if !as_json {
            println!("  {:>8}  {:>9.1}  {:>9.1}", sample.edits, mb(sample.rss), sample.elapsed.as_secs_f64());
        }
    };
    if !as_json {
        println!(
            "lsp-memory benchmark: {blocks} blocks ({:.1} MB), {edits} single-character edits, a pause after every \
             {pause_every}th, {}",
            bytes as f64 / 1e6,
            server.display()
        );
        println!("  {:>8}  {:>9}  {:>9}", "edits", "RSS MB", "time s");
        println!("  {:>8}  {:>9.1}", "unopened", mb(before_open));
    }

    let started = Instant::now();
    client.notify("textDocument/didOpen", doc.did_open())?;
    client.diagnostics(&doc.uri, doc.version)?;
    pause(&mut client, &doc, 0)?;
    let mut samples = vec![Sample { edits: 0, rss: rss(&client)?, elapsed: started.elapsed() }];
    show(&samples[0]);

    let mut rng = Lcg::new(SEED);
    let mut missing_refreshes = 0;
    for done in 1..=edits {
        let edit = edits::typing_edit(doc.text(), &mut rng).context("the program has no block to edit")?;
        client.take_received();
        client.notify("textDocument/didChange", doc.change(edit.range.clone(), &edit.insert))?;
        client.diagnostics(&doc.uri, doc.version)?;
        let target = code_near(dialect, doc.text(), edit.range.start, &mut rng).context("no G code near the edit")?;
        let hover = client.call("textDocument/hover", doc.at(doc.position(target)))?;
        anyhow::ensure!(hover.error_code().is_none(), "hover failed: {}", hover.json);
        let sample = done % sample_every == 0 || done == edits;
        if (sample || done % pause_every == 0) && !pause(&mut client, &doc, edit.range.start)? {
            missing_refreshes += 1;
        }
        if sample {
            samples.push(Sample { edits: done, rss: rss(&client)?, elapsed: started.elapsed() });
            show(&samples[samples.len() - 1]);
        }
    }

    client.take_received();
    client.notify("textDocument/didClose", json!({ "textDocument": doc.id() }))?;
    client.notification("textDocument/publishDiagnostics", |m| {
        m.params()["uri"] == doc.uri.as_str() && m.params()["version"].is_null()
    })?;
    std::thread::sleep(SETTLE);
    let after_close = rss(&client)?;
    let exit = client.shutdown()?;
    anyhow::ensure!(exit.success(), "the server ended with {exit} after shutdown and exit");

    let at = |edits: usize| samples.iter().find(|s| s.edits == edits).map(|s| s.rss);
    let first = at(sample_every.min(edits)).context("no sample")?;
    let last = samples.last().context("no sample")?.rss;
    let growth = last as f64 / first as f64;
    if as_json {
        let curve: Vec<Value> = samples
            .iter()
            .map(|s| json!({ "edits": s.edits, "rss_bytes": s.rss, "elapsed_s": s.elapsed.as_secs_f64() }))
            .collect();
        let output = json!({
            "blocks": blocks,
            "bytes": bytes,
            "edits": edits,
            "pause_every": pause_every,
            "rss_before_open_bytes": before_open,
            "curve": curve,
            "rss_after_close_bytes": after_close,
            "growth": growth,
            "pauses_without_a_refresh": missing_refreshes,
        });
        println!("{output:#}");
    } else {
        println!("  {:>8}  {:>9.1}", "closed", mb(after_close));
        let verdict = if growth <= GROWTH_GOAL { "met" } else { "NOT met" };
        println!("  RSS({edits})/RSS({}) = {growth:.3}   goal <= {GROWTH_GOAL}: {verdict}", sample_every.min(edits));
        println!(
            "  after close {:+.1} MB against before open, {:+.1} MB against the last sample",
            mb(after_close) - mb(before_open),
            mb(after_close) - mb(last)
        );
        if missing_refreshes > 0 {
            println!("  {missing_refreshes} pauses ended without a cycle-time refresh");
        }
    }
    Ok(())
}

/// Waits until the server is done with the current version, whose first
/// diagnostics have come: its complete diagnostics, then the cycle-time
/// estimate's refresh, after which the client asks for the inlay hints of
/// the lines around `at`. Returns whether the refresh came.
fn pause(client: &mut Client, doc: &Document, at: usize) -> anyhow::Result<bool> {
    client.diagnostics(&doc.uri, doc.version)?;
    let refreshed = client
        .wait_for("an inlay hint refresh", REFRESH_WAIT, |m| m.method() == Some("workspace/inlayHint/refresh"))
        .is_ok();
    let text = doc.text();
    let line_start = |from: usize, lines: usize, up: bool| {
        let mut at = from;
        for _ in 0..lines {
            at = if up {
                text[..at.saturating_sub(1)].rfind('\n').map_or(0, |i| i + 1)
            } else {
                text[at..].find('\n').map_or(text.len(), |i| at + i + 1)
            };
        }
        at
    };
    let visible = line_start(at, VISIBLE_LINES / 2, true)..line_start(at, VISIBLE_LINES / 2, false);
    let hints =
        client.call("textDocument/inlayHint", json!({ "textDocument": doc.id(), "range": doc.range(visible) }))?;
    anyhow::ensure!(hints.error_code().is_none(), "inlay hints failed: {}", hints.json);
    Ok(refreshed)
}
