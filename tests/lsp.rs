//! End-to-end tests of the language server, `ncc lsp`: answers to broken
//! and unexpected messages, positions outside the document, a very large
//! document, rapid edits, and the lifecycle. Each test runs its own server
//! through the client in `ncc-bench`, whose every wait has a timeout.

use std::{process::Command, time::Duration};

use ncc_bench::{
    cnc8x6::progen::{self, Syntax},
    edits::{Lcg, typing_edit},
    lsp_client::{Client, Document, Message, file_uri, initialize_params},
};
use serde_json::{Value, json};
use tempfile::TempDir;

/// JSON-RPC and LSP error codes.
const PARSE_ERROR: i64 = -32700;
const INVALID_REQUEST: i64 = -32600;
const METHOD_NOT_FOUND: i64 = -32601;
const INVALID_PARAMS: i64 = -32602;
const SERVER_NOT_INITIALIZED: i64 = -32002;

/// A program whose comments hold two-byte Czech letters and a four-byte
/// emoji (two UTF-16 units), with two syntax errors after them.
const CZECH: &str = "%7 \"ZKUŠEBNÍ PROGRAM – ŘEZÁNÍ\"
N10 G00 X0 Y0 \"ŽLUŤOUČKÝ KŮŇ 🙂\" Z2 U36.  12
N20 G01 X10 F100 \"ČÁRKA, TEČKA ŘEŽ\"
N30 Z-  5.
N40 M30
*
";

fn server() -> Client {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ncc"));
    command.arg("lsp");
    Client::spawn(command).unwrap()
}

/// An initialized server with an empty workspace folder.
fn session() -> (Client, TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let mut client = server();
    client.initialize(dir.path(), None).unwrap();
    (client, dir)
}

fn document(dir: &TempDir, name: &str, text: &str) -> Document {
    Document::new(file_uri(&dir.path().join(name)), text.to_owned())
}

/// Opens `doc` and waits for its first diagnostics.
fn open(client: &mut Client, doc: &Document) -> Message {
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();
    client.diagnostics(&doc.uri, doc.version).unwrap()
}

/// The diagnostics of `doc`'s current version once the server is done with
/// it. The server may push a quick partial set before the complete one and
/// does not say which is last, so the last one within a quiet second counts.
fn settled_diagnostics(client: &mut Client, doc: &Document) -> Message {
    let mut last = client.diagnostics(&doc.uri, doc.version).unwrap();
    while let Ok(later) = client.diagnostics_within(&doc.uri, doc.version, Duration::from_secs(1)) {
        last = later;
    }
    last
}

/// What must agree between two copies of one text.
#[derive(Debug, PartialEq)]
struct Analysed {
    /// The settled diagnostics, with the document's URI taken out.
    diagnostics: String,
    semantic_tokens: Value,
}

fn analysed(client: &mut Client, doc: &Document, settled: &Message) -> Analysed {
    let tokens = client.call("textDocument/semanticTokens/full", json!({ "textDocument": doc.id() })).unwrap();
    Analysed {
        diagnostics: settled.params()["diagnostics"].to_string().replace(&doc.uri, "URI"),
        semantic_tokens: tokens.result().unwrap_or_else(|| panic!("semantic tokens: {}", tokens.json))["data"].clone(),
    }
}

/// Asserts that a fresh copy of `doc`'s text is analysed as `edited`.
fn assert_same_as_a_fresh_copy(client: &mut Client, dir: &TempDir, doc: &Document, edited: &Analysed) {
    let copy = document(dir, "copy.NCP", doc.text());
    client.notify("textDocument/didOpen", copy.did_open()).unwrap();
    let settled = settled_diagnostics(client, &copy);
    assert_eq!(edited, &analysed(client, &copy, &settled), "the edited document differs from a fresh copy");
}

/// Asserts that the server answers an ordinary request on an open document.
fn assert_serving(client: &mut Client, dir: &TempDir) {
    let doc = document(dir, "alive.NCP", "%1\nN10 G01 X1 F100\nN20 M30\n");
    open(client, &doc);
    let hover = client.call("textDocument/hover", doc.at(doc.position(doc.text().find("G01").unwrap()))).unwrap();
    assert!(hover.result().is_some_and(|r| r["contents"]["value"].as_str().is_some()), "{}", hover.json);
}

fn framed(body: &str) -> Vec<u8> {
    format!("Content-Length: {}\r\n\r\n{body}", body.len()).into_bytes()
}

#[test]
fn a_body_that_is_not_json_is_a_parse_error() {
    let (mut client, dir) = session();
    client.send_raw(&framed("not json!")).unwrap();
    let error = client.response_to(&Value::Null).unwrap();
    assert_eq!(error.error_code(), Some(PARSE_ERROR), "{}", error.json);
    assert_serving(&mut client, &dir);
}

#[test]
fn json_that_is_not_a_request_is_an_invalid_request() {
    let (mut client, dir) = session();
    // JSON-RPC 2.0: a value that is not an object, an empty batch (LSP has
    // no batches), an object with neither method nor id.
    for body in ["42", "[]", r#"{"jsonrpc":"2.0","params":{}}"#] {
        client.send_raw(&framed(body)).unwrap();
        let error = client.response_to(&Value::Null).unwrap();
        assert_eq!(error.error_code(), Some(INVALID_REQUEST), "{body}: {}", error.json);
    }
    assert_serving(&mut client, &dir);
}

#[test]
fn a_bad_content_length_is_skipped() {
    let (mut client, dir) = session();
    // A length that is not a number can be skipped up to the next header.
    // (A wrong number cannot be detected: it shifts every later message.)
    client.send_raw(b"Content-Length: twelve\r\n\r\n{}").unwrap();
    assert_serving(&mut client, &dir);
}

#[test]
fn unknown_methods_are_method_not_found_and_unknown_notifications_are_ignored() {
    let (mut client, dir) = session();
    let unknown = client.call("foo/bar", json!({})).unwrap();
    assert_eq!(unknown.error_code(), Some(METHOD_NOT_FOUND), "{}", unknown.json);
    client.notify("foo/baz", json!({})).unwrap();
    client.notify("$/ncc/unknown", json!({})).unwrap();
    // LSP: a `$/` request the server does not know is MethodNotFound too.
    let dollar = client.call("$/ncc/unknown", json!({})).unwrap();
    assert_eq!(dollar.error_code(), Some(METHOD_NOT_FOUND), "{}", dollar.json);
    assert_serving(&mut client, &dir);
    let answers: Vec<Value> = client.take_received().into_iter().filter(Message::is_response).map(|m| m.json).collect();
    assert!(answers.is_empty(), "notifications were answered: {answers:?}");
}

#[test]
fn requests_before_initialize_fail_and_initialize_comes_once() {
    let dir = tempfile::tempdir().unwrap();
    let mut client = server();
    let doc = document(&dir, "early.NCP", "%1\nN10 G01 X1 F100\nN20 M30\n");
    let g01 = doc.position(doc.text().find("G01").unwrap());
    let early = client.call("textDocument/hover", doc.at(g01.clone())).unwrap();
    assert_eq!(early.error_code(), Some(SERVER_NOT_INITIALIZED), "{}", early.json);
    // LSP: notifications before initialize are dropped.
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();

    let initialized = client.initialize(dir.path(), None).unwrap();
    let capabilities = &initialized.result().unwrap()["capabilities"];
    let sync = &capabilities["textDocumentSync"];
    assert!(sync == 2 || sync["change"] == 2, "incremental sync: {capabilities}");
    assert!(matches!(capabilities["positionEncoding"].as_str(), None | Some("utf-16")), "{capabilities}");

    let dropped = client.call("textDocument/hover", doc.at(g01)).unwrap();
    assert!(dropped.result().is_none_or(Value::is_null), "the early didOpen was kept: {}", dropped.json);
    let again = client.call("initialize", initialize_params(dir.path(), None)).unwrap();
    assert!(again.error_code().is_some(), "a second initialize succeeded: {}", again.json);
    assert_serving(&mut client, &dir);
}

#[test]
fn positions_past_the_end_are_clamped_and_the_document_stays_in_sync() {
    let (mut client, dir) = session();
    let mut doc = document(&dir, "czech.NCP", CZECH);
    open(&mut client, &doc);

    // Line 2 ends in a comment with Czech letters: its length in UTF-16
    // units points into a letter when read as bytes.
    let line = CZECH.lines().nth(2).unwrap();
    let units = line.encode_utf16().count();
    let into_a_letter = (units + 1..line.len()).find(|&i| !line.is_char_boundary(i)).unwrap();
    let emoji_units = CZECH.lines().nth(1).unwrap().split('🙂').next().unwrap().encode_utf16().count();
    let past_line_ends = [json!({ "line": 2, "character": into_a_letter }), json!({ "line": 3, "character": 10_000 })];
    let elsewhere = [
        // Past the last line, at the protocol's largest position, and
        // between the two UTF-16 units of the emoji.
        json!({ "line": 99, "character": 0 }),
        json!({ "line": i32::MAX, "character": i32::MAX }),
        json!({ "line": 1, "character": emoji_units + 1 }),
    ];
    for position in past_line_ends.iter().chain(&elsewhere) {
        let requests = [
            ("textDocument/hover", doc.at(position.clone())),
            ("textDocument/definition", doc.at(position.clone())),
            ("textDocument/completion", doc.at(position.clone())),
            ("textDocument/references", {
                let mut params = doc.at(position.clone());
                params["context"] = json!({ "includeDeclaration": true });
                params
            }),
        ];
        for (method, params) in requests {
            let answer = client.call(method, params).unwrap();
            // LSP 3.17 clamps a character past the line's end; outside the
            // lines it says nothing, so "invalid params" is an answer too.
            let clamped = past_line_ends.contains(position);
            assert!(
                answer.result().is_some() || (!clamped && answer.error_code() == Some(INVALID_PARAMS)),
                "{method} at {position}: {}",
                answer.json
            );
        }
    }

    // Changes whose ranges end past the line, and past the document, apply
    // where clamping puts them: a number with a space at the end of line 1,
    // a comment after the end.
    let changes = [
        (json!({ "start": { "line": 1, "character": 500 }, "end": { "line": 1, "character": 600 } }), " Y1 5"),
        (json!({ "start": { "line": 40, "character": 0 }, "end": { "line": 50, "character": 3 } }), "\"KONEC\"\n"),
    ];
    for (range, text) in changes {
        client.notify("textDocument/didChange", doc.change_lsp(range, text)).unwrap();
    }
    // An ordinary edit after them lands where the client means it only if
    // both sides still hold the same text.
    let x10 = doc.text().find("X10").unwrap();
    client.notify("textDocument/didChange", doc.change(x10 + 1..x10 + 1, " ")).unwrap();
    let formatting = json!({ "textDocument": doc.id(), "options": { "tabSize": 4, "insertSpaces": true } });
    let formatted = client.call("textDocument/formatting", formatting).unwrap();
    for edit in formatted.result().unwrap_or_else(|| panic!("{}", formatted.json)).as_array().into_iter().flatten() {
        assert!(doc.byte_range(&edit["range"]).is_some(), "formatting edit outside the document: {edit}");
    }
    let settled = settled_diagnostics(&mut client, &doc);
    let edited = analysed(&mut client, &doc, &settled);
    assert_ne!(edited.diagnostics, "[]", "the edits leave errors to compare");
    assert_same_as_a_fresh_copy(&mut client, &dir, &doc, &edited);
}

#[test]
fn a_very_large_document_does_not_stop_the_server() {
    // 1.5 million blocks make about 50 MB. Debug builds leave the workspace
    // crates unoptimised and CI has two cores, so there a tenth of it shows
    // the same behaviour in reasonable time; release runs the full size.
    let blocks = if cfg!(debug_assertions) { 150_000 } else { 1_500_000 };
    let (mut client, dir) = session();
    let small = document(&dir, "small.NCP", "%1\nN10 G01 X1 F100\nN20 M30\n");
    open(&mut client, &small);
    let big = document(&dir, "big.NCP", &progen::write(&progen::surfacing(blocks), Syntax::Cnc8x6));
    client.notify("textDocument/didOpen", big.did_open()).unwrap();

    // The small document is answered while the big one is analysed, not
    // after its complete diagnostics.
    let hover =
        client.request("textDocument/hover", small.at(small.position(small.text().find("G01").unwrap()))).unwrap();
    let answer = client.response(&hover).unwrap();
    assert!(answer.result().is_some_and(|r| !r.is_null()), "{}", answer.json);

    client.timeout = Duration::from_secs(300);
    let published = settled_diagnostics(&mut client, &big);
    assert_eq!(published.params()["diagnostics"], json!([]), "a generated program is clean");
    assert!(answer.received < published.received, "the hover on the small document waited for the big one");
}

/// A megabyte of random text on one line, hundreds of thousands of
/// findings: the server publishes ten and counts the rest, and goes on
/// answering.
#[test]
fn a_megabyte_line_of_random_text_gets_ten_findings_and_a_count() {
    let (mut client, dir) = session();
    client.timeout = Duration::from_secs(120);
    let doc = document(&dir, "random.NCP", &progen::random_line(1 << 20, 7));
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();
    let settled = settled_diagnostics(&mut client, &doc);
    let diagnostics = settled.params()["diagnostics"].as_array().unwrap();
    assert_eq!(diagnostics.len(), 11, "{}", settled.json);
    let rest = diagnostics.iter().find(|d| d["code"] == "Z001").unwrap();
    assert_eq!(rest["severity"], 1, "an error among them: {rest}");
    assert_serving(&mut client, &dir);
}

#[test]
fn rapid_edits_end_in_the_diagnostics_of_the_final_text_without_growing() {
    let (mut client, dir) = session();
    // 170 kB: keeping every version's text would add 170 MB.
    let mut doc = document(&dir, "edited.NCP", &progen::write(&progen::surfacing(5_000), Syntax::Cnc8x6));
    open(&mut client, &doc);
    settled_diagnostics(&mut client, &doc);
    let before = client.memory();

    let mut rng = Lcg::new(1);
    for _ in 0..1000 {
        let edit = typing_edit(doc.text(), &mut rng).unwrap();
        client.notify("textDocument/didChange", doc.change(edit.range, &edit.insert)).unwrap();
    }
    // Debug builds take about 15 s to catch up with the edits.
    client.timeout = Duration::from_secs(90);
    let last = settled_diagnostics(&mut client, &doc);
    // Nothing older may follow the final version's diagnostics: an editor
    // would show findings of a text that no longer exists.
    let stale: Vec<Value> = client
        .take_received()
        .into_iter()
        .filter(|m| m.method() == Some("textDocument/publishDiagnostics") && m.received > last.received)
        .map(|m| m.params()["version"].clone())
        .collect();
    assert!(stale.is_empty(), "diagnostics of versions {stale:?} came after version {}", doc.version);

    if let (Some(before), Some(after)) = (before, client.memory()) {
        // The caches of the analysis grow by about 10 MB; a history of
        // texts, trees or analyses would cost far more than the bound.
        let grown = after.rss.saturating_sub(before.rss);
        assert!(grown < 64 << 20, "RSS grew by {} MB over 1000 edits", grown >> 20);
    }

    let edited = analysed(&mut client, &doc, &last);
    assert_same_as_a_fresh_copy(&mut client, &dir, &doc, &edited);
}

/// `workspace/executeCommand` `ncc.plot`.
fn plot(client: &mut Client, arguments: Value) -> Message {
    client.call("workspace/executeCommand", json!({ "command": "ncc.plot", "arguments": arguments })).unwrap()
}

/// The lines of an SVG picture's moves (`<path data-line=...`), with the
/// file they name when it is not the program.
fn plotted_moves(svg: &str) -> Vec<(u64, Option<String>)> {
    let attribute = |line: &str, name: &str| {
        let start = line.find(&format!(" {name}=\""))? + name.len() + 3;
        Some(line[start..][..line[start..].find('"')?].to_owned())
    };
    svg.lines()
        .filter(|line| line.starts_with("<path "))
        .map(|line| {
            let number = attribute(line, "data-line").and_then(|n| n.parse().ok());
            (number.unwrap_or_else(|| panic!("a move without data-line: {line}")), attribute(line, "data-file"))
        })
        .collect()
}

/// `ncc.plot` draws what `ncc plot` draws, from the open document's text
/// with its unsaved edits; a document the server does not have, and a run
/// that stops, are errors that say why.
#[test]
fn the_plot_command_draws_the_document_as_edited() {
    let dir = tempfile::tempdir().unwrap();
    let mut client = server();
    let initialized = client.initialize(dir.path(), None).unwrap();
    let commands = &initialized.result().unwrap()["capabilities"]["executeCommandProvider"]["commands"];
    assert!(commands.as_array().is_some_and(|c| c.contains(&json!("ncc.plot"))), "{commands}");

    // The macrocycle file is on disk beside the program; the program is
    // not: only the editor has its text.
    let macro_path = dir.path().join("L9001");
    std::fs::write(&macro_path, "N1 G79 L9001\nN2 G91 G01 X10 F600\nN3 G90 G70\n").unwrap();
    let program = dir.path().join("PLOT.NCP");
    let mut doc =
        Document::new(file_uri(&program), "%1\nN10 G00 X10 Y0\nN20 G01 X20 F600\nN30 G72 L9001\nN40 M30\n".into());
    open(&mut client, &doc);

    let answer = plot(&mut client, json!([doc.uri]));
    let result = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
    let svg = result["svg"].as_str().unwrap();
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""), "{svg}");
    let macro_file = Some(macro_path.display().to_string());
    assert_eq!(plotted_moves(svg), [(2, None), (3, None), (2, macro_file.clone())], "{svg}");
    let first_time = result["totalTimeS"].as_f64().unwrap();
    assert!(first_time > 0.0, "{result}");
    assert_eq!(result["findings"], json!([]));
    assert_eq!(result["view"], "top", "a mill's plane view by default: {result}");
    let answer = plot(&mut client, json!([doc.uri, { "view": "iso" }]));
    let result = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
    assert_eq!(result["view"], "iso", "{result}");
    assert!(result["svg"].as_str().unwrap().contains("data-projection=\"isometric\""), "{result}");

    // An edit that is not saved: a move on a new line 5.
    let n40 = doc.text().find("N40").unwrap();
    client.notify("textDocument/didChange", doc.change(n40..n40, "N35 G01 Y30\n")).unwrap();
    let answer = plot(&mut client, json!([doc.uri]));
    let result = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
    let svg = result["svg"].as_str().unwrap();
    assert_eq!(plotted_moves(svg), [(2, None), (3, None), (2, macro_file), (5, None)], "{svg}");
    assert!(result["totalTimeS"].as_f64().unwrap() > first_time, "{result}");

    // The same picture as `ncc plot` draws of that text saved.
    std::fs::write(&program, doc.text()).unwrap();
    let out = dir.path().join("plot.svg");
    let status =
        Command::new(env!("CARGO_BIN_EXE_ncc")).arg("plot").arg(&program).arg("-o").arg(&out).status().unwrap();
    assert!(status.success());
    assert_eq!(std::fs::read_to_string(&out).unwrap(), svg, "ncc plot and ncc.plot differ");

    // Documents the server does not have, and arguments that name none.
    let elsewhere = file_uri(&dir.path().join("NOT-OPEN.NCP"));
    for (arguments, expected) in [
        (json!([elsewhere]), "is not open"),
        (json!(["not a uri"]), "is not a URI"),
        (json!([]), "takes the document's URI"),
        (json!([{ "uri": doc.uri }]), "takes the document's URI"),
        (json!([doc.uri, { "view": "sideways" }]), "unknown variant `sideways`"),
        (json!([doc.uri, { "zoom": 2 }]), "unknown field `zoom`"),
    ] {
        let answer = plot(&mut client, arguments.clone());
        assert_eq!(answer.error_code(), Some(INVALID_PARAMS), "{arguments}: {}", answer.json);
        let message = answer.json["error"]["message"].as_str().unwrap();
        assert!(message.contains("ncc.plot") && message.contains(expected), "{arguments}: {message}");
    }

    // A run that stops: the error says where and why, and its data holds
    // the picture of the run up to there.
    let l9001 = doc.text().find("L9001").unwrap();
    client.notify("textDocument/didChange", doc.change(l9001..l9001 + 5, "L9002")).unwrap();
    let answer = plot(&mut client, json!([doc.uri]));
    assert_eq!(answer.error_code(), Some(-32803), "RequestFailed: {}", answer.json);
    let error = &answer.json["error"];
    assert_eq!(error["message"], "the run stopped at line 4: there is no macrocycle file L9002 to call", "{error}");
    assert_eq!(plotted_moves(error["data"]["svg"].as_str().unwrap()), [(2, None), (3, None)], "{error}");
    assert_eq!(error["data"]["findings"][0]["stopped"], true, "{error}");

    // A new document that is no file yet is drawn too, without a project.
    let untitled = Document::new("untitled:Untitled-1".into(), "%1\nN10 G01 X5 F100\nN20 M30\n".into());
    client.notify("textDocument/didOpen", untitled.did_open()).unwrap();
    let answer = plot(&mut client, json!([untitled.uri]));
    let result = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
    assert_eq!(plotted_moves(result["svg"].as_str().unwrap()), [(2, None)], "{result}");
    assert_serving(&mut client, &dir);
}

/// `ncc.plot` draws a lathe's program in the view asked for, the diameter
/// view by default, as `ncc plot --view` does, and says which it drew.
#[test]
fn the_plot_command_draws_a_lathe_in_the_view_asked_for() {
    let (mut client, dir) = session();
    let text = "%\nO00001\nG18 G21 G99 G54\nT101\nG97 S1000 M03\nG00 X50. Z10.\nG01 Z-20. F0.2\nM30\n%\n";
    let doc = document(&dir, "O0001.nc", text);
    open(&mut client, &doc);
    let program = dir.path().join("O0001.nc");
    std::fs::write(&program, text).unwrap();
    for (options, view) in
        [(None, "diameter"), (Some(json!({})), "diameter"), (Some(json!({ "view": "radius" })), "radius")]
    {
        let arguments = match &options {
            Some(options) => json!([doc.uri, options]),
            None => json!([doc.uri]),
        };
        let answer = plot(&mut client, arguments);
        let result = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
        assert_eq!(result["view"], view, "{options:?}: {result}");
        let out = dir.path().join("plot.svg");
        let status = Command::new(env!("CARGO_BIN_EXE_ncc"))
            .args(["plot", "--view", view, "-o"])
            .arg(&out)
            .arg(&program)
            .status()
            .unwrap();
        assert!(status.success());
        assert_eq!(std::fs::read_to_string(&out).unwrap(), result["svg"], "{options:?}: ncc plot and ncc.plot differ");
    }
    assert_serving(&mut client, &dir);
}

/// Completion in a Haas lathe program: the calls' targets, each replacing
/// its word, and the letters that ask for them announced.
#[test]
fn completion_in_a_haas_program_offers_the_targets() {
    let dir = tempfile::tempdir().unwrap();
    let mut client = server();
    let initialized = client.initialize(dir.path(), None).unwrap();
    let triggers = &initialized.result().unwrap()["capabilities"]["completionProvider"]["triggerCharacters"];
    for letter in ["#", "G", "L", "M", "P", "Q", "R"] {
        assert!(triggers.as_array().is_some_and(|t| t.contains(&json!(letter))), "{letter} in {triggers}");
    }
    let called = document(&dir, "O02000.nc", "%\nO02000 (SUB)\nM99\n%\n");
    open(&mut client, &called);
    let text = "%\nO01000\nM97 P20\nM98 P2\nM30\nN20 G00 X10.\nM99\n%\n";
    let doc = document(&dir, "O01000.nc", text);
    open(&mut client, &doc);
    let complete = |client: &mut Client, after: &str| {
        let offset = text.find(after).unwrap() + after.len();
        let answer = client.call("textDocument/completion", doc.at(doc.position(offset))).unwrap();
        answer.result().unwrap_or_else(|| panic!("{}", answer.json)).clone()
    };
    let items = complete(&mut client, "M97 P2");
    assert_eq!(items[0]["label"], "P20", "{items}");
    assert_eq!(items[0]["kind"], 18, "a reference: {items}");
    assert_eq!(
        items[0]["textEdit"]["range"],
        json!({ "start": { "line": 2, "character": 4 }, "end": { "line": 2, "character": 7 } })
    );
    let items = complete(&mut client, "M98 P2");
    assert_eq!(items[0]["label"], "P2000", "{items}");
    assert_eq!(items[0]["detail"], "SUB", "{items}");
    assert_eq!(items[0]["kind"], 3, "a function: {items}");
    assert_serving(&mut client, &dir);
}

/// Range formatting changes the selected lines only, in the project's
/// style, and whole-document formatting all of them.
#[test]
fn range_formatting_formats_the_selected_lines_in_the_projects_style() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ncc.toml"), "[format]\ncase = \"upper\"\n").unwrap();
    let mut client = server();
    let initialized = client.initialize(dir.path(), None).unwrap();
    assert_eq!(initialized.result().unwrap()["capabilities"]["documentRangeFormattingProvider"], json!(true));
    let doc = document(&dir, "PART.MPF", "g0  x1\ng1  x2 f100\ng1  x3\nM30\n");
    open(&mut client, &doc);
    let options = json!({ "tabSize": 4, "insertSpaces": true });
    let line_2 = json!({ "start": { "line": 1, "character": 2 }, "end": { "line": 1, "character": 3 } });
    let ranged = json!({ "textDocument": doc.id(), "range": line_2, "options": options });
    let answer = client.call("textDocument/rangeFormatting", ranged).unwrap();
    assert_eq!(
        answer.result().unwrap_or_else(|| panic!("{}", answer.json)),
        &json!([{ "range": { "start": { "line": 1, "character": 0 }, "end": { "line": 1, "character": 8 } },
                  "newText": "G1 X2 F" }])
    );
    let whole = json!({ "textDocument": doc.id(), "options": options });
    let answer = client.call("textDocument/formatting", whole).unwrap();
    assert_eq!(answer.result().and_then(Value::as_array).map(Vec::len), Some(3), "{}", answer.json);
    assert_serving(&mut client, &dir);
}

/// On a line that starts with a block number, a source action renumbers
/// the blocks with their jumps, or says, disabled, why it would be unsafe;
/// only when asked for, not as the cursor moves.
#[test]
fn renumbering_is_a_code_action_on_a_numbered_line() {
    let (mut client, dir) = session();
    let doc = document(&dir, "O0001.nc", "N5 G00 X1.\nIF [#1 LT 2] GOTO5\nM30\n");
    open(&mut client, &doc);
    let actions = |client: &mut Client, doc: &Document, line: u32| {
        let range = json!({ "start": { "line": line, "character": 0 }, "end": { "line": line, "character": 0 } });
        let params = json!({ "textDocument": doc.id(), "range": range, "context": { "diagnostics": [] } });
        let answer = client.call("textDocument/codeAction", params).unwrap();
        answer.result().unwrap_or_else(|| panic!("{}", answer.json)).clone()
    };
    let found = actions(&mut client, &doc, 0);
    let renumber = found.as_array().unwrap().iter().find(|a| a["kind"] == "source").expect("a renumbering action");
    assert_eq!(renumber["title"], "Renumber the blocks N10, N20, … and the jumps to them");
    let edits = &renumber["edit"]["changes"][doc.uri.as_str()];
    let texts: Vec<_> = edits.as_array().unwrap().iter().map(|edit| edit["newText"].clone()).collect();
    assert_eq!(texts, [json!("10"), json!("10")], "{edits}");
    assert!(!actions(&mut client, &doc, 2).as_array().unwrap().iter().any(|a| a["kind"] == "source"));
    // Not where the editor asks by itself as the cursor moves.
    let range = json!({ "start": { "line": 0, "character": 0 }, "end": { "line": 0, "character": 0 } });
    let automatic =
        json!({ "textDocument": doc.id(), "range": range, "context": { "diagnostics": [], "triggerKind": 2 } });
    let answer = client.call("textDocument/codeAction", automatic).unwrap();
    assert_eq!(answer.result(), Some(&json!([])), "{}", answer.json);

    let refused = document(&dir, "O0002.nc", "N5 G00 X1.\nGOTO #1\nM30\n");
    open(&mut client, &refused);
    let found = actions(&mut client, &refused, 0);
    let renumber = found.as_array().unwrap().iter().find(|a| a["kind"] == "source").expect("a renumbering action");
    assert_eq!(
        renumber["disabled"]["reason"],
        "line 2: the target is computed when the program runs: renumbering could break it"
    );
    assert_serving(&mut client, &dir);
}

/// Renaming a Sinumerik program edits every file that calls it and renames
/// its file, as one workspace edit.
#[test]
fn renaming_a_program_edits_its_callers_and_renames_its_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("PROFIL.SPF"), "PROC PROFIL\nG1 X10 F100\nM17\n").unwrap();
    let main = document(&dir, "MAIN.MPF", "PROFIL\nM30\n");
    std::fs::write(dir.path().join("MAIN.MPF"), main.text()).unwrap();
    let mut client = server();
    client.initialize(dir.path(), None).unwrap();
    open(&mut client, &main);
    let mut params = main.at(main.position(2));
    params["newName"] = json!("KONTUR");
    let answer = client.call("textDocument/rename", params).unwrap();
    let changes = answer.result().unwrap_or_else(|| panic!("{}", answer.json))["documentChanges"].clone();
    let operations = changes.as_array().unwrap_or_else(|| panic!("{changes}"));
    let renamed = operations.iter().find(|op| op["kind"] == "rename").unwrap_or_else(|| panic!("{changes}"));
    assert!(renamed["oldUri"].as_str().unwrap().ends_with("/PROFIL.SPF"), "{renamed}");
    assert!(renamed["newUri"].as_str().unwrap().ends_with("/KONTUR.SPF"), "{renamed}");
    let edited: Vec<_> = operations.iter().filter_map(|op| op["textDocument"]["uri"].as_str()).collect();
    assert_eq!(edited.len(), 2, "{changes}");
    assert_serving(&mut client, &dir);
}

#[test]
fn shutdown_then_exit_ends_with_success() {
    let (mut client, dir) = session();
    let doc = document(&dir, "a.NCP", "%1\nN10 G01 X1 F100\nN20 M30\n");
    open(&mut client, &doc);
    let shutdown = client.call("shutdown", Value::Null).unwrap();
    assert_eq!(shutdown.result(), Some(&Value::Null), "{}", shutdown.json);
    // LSP: requests after shutdown are invalid.
    let late = client.call("textDocument/hover", doc.at(doc.position(0))).unwrap();
    assert_eq!(late.error_code(), Some(INVALID_REQUEST), "{}", late.json);
    client.notify("exit", Value::Null).unwrap();
    assert_eq!(client.wait_exit(Duration::from_secs(10)).unwrap().code(), Some(0));
}

#[test]
fn exit_without_shutdown_ends_with_failure() {
    let (mut client, _dir) = session();
    client.notify("exit", Value::Null).unwrap();
    assert_eq!(client.wait_exit(Duration::from_secs(10)).unwrap().code(), Some(1));
}

#[test]
fn closing_stdin_ends_the_server() {
    let (mut client, _dir) = session();
    client.close_stdin();
    client.wait_exit(Duration::from_secs(10)).unwrap();
}

/// A corner under continuity: N20 turns 90° from N10, and N30 again.
const CORNERS: &str = "%1\nN10 G23 G01 X10 F600\nN20 Y10 R1=5 \"SIDE\"\nN30 X20\nN40 M30\n*\n";

/// The hints of `CORNERS`, by line: the parameter value, each block's time
/// (1035 ms: 10 mm at 10 mm/s with R236 ramps and the settle) and where
/// the speed drops. The times equal `ncc run`'s velocity model.
const PER_BLOCK: [&str; 7] = [
    "1: 1.03 s",
    "1: ▼ corner −35 ms",
    "2: = 0.005",
    "2: 1.03 s",
    "2: ▼ corner −35 ms",
    "3: 1.03 s",
    "3: ▼ non-motion −22 ms",
];
const CUMULATIVE: [&str; 3] = ["1: Σ 1.03 s", "2: Σ 2.07 s", "3: Σ 3.10 s"];
const CUMULATIVE_AT_F1200: [&str; 3] = ["1: Σ 560 ms", "2: Σ 1.12 s", "3: Σ 1.68 s"];
const CORNER_TOOLTIP: &str = "**Speed drops** (corner): a corner of 90.0°, not below R39 (60.000°). 600 → 0 mm/min; 35 ms lost against a smooth join.";
const HEADLINE: &str = "Cycle time 3.10 s · cutting 3.10 s · rapid 0 s · 3 breaks cost 92 ms";
const N20_HOVER: &str = "**Predicted time:** takes 1.03 s, starts at 1.03 s\n\n\
    **Speed:** entry 0 → peak 600 → exit 0 mm/min over 1.03 s\n\n\
    **Speed drops** (corner): a corner of 90.0°, not below R39 (60.000°). 600 → 0 mm/min; 35 ms lost against a smooth join.";

/// Waits until the server asks for fresh inlay hints: an estimate is ready.
fn estimated(client: &mut Client) {
    client
        .wait_for("an inlay hint refresh", client.timeout, |m| m.method() == Some("workspace/inlayHint/refresh"))
        .unwrap();
}

/// The inlay hints of the whole document, as `line: label`, and their
/// tooltips.
fn inlay_hints(client: &mut Client, doc: &Document) -> (Vec<String>, Vec<String>) {
    let params = json!({ "textDocument": doc.id(), "range": doc.range(0..doc.text().len()) });
    let answer = client.call("textDocument/inlayHint", params).unwrap();
    let hints = answer.result().and_then(Value::as_array).unwrap_or_else(|| panic!("{}", answer.json));
    let labels = hints.iter().map(|hint| format!("{}: {}", hint["position"]["line"], hint["label"].as_str().unwrap()));
    let tooltips = hints.iter().map(|hint| hint["tooltip"]["value"].as_str().unwrap_or_default().to_owned());
    (labels.collect(), tooltips.collect())
}

#[test]
fn cycle_time_inlay_hints_per_block_cumulative_and_off() {
    let (mut client, dir) = session();
    let doc = document(&dir, "corners.NCP", CORNERS);
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();
    estimated(&mut client);
    let (labels, tooltips) = inlay_hints(&mut client, &doc);
    // Each block's time at its line's end, after the parameter value, and
    // a marker where the speed drops.
    assert_eq!(labels, PER_BLOCK, "{tooltips:#?}");
    let marker = &tooltips[labels.iter().position(|label| label.contains('▼')).unwrap()];
    assert_eq!(marker, CORNER_TOOLTIP);

    let configure = |client: &mut Client, hints: &str| {
        let settings = json!({ "settings": { "ncc": { "cycleTime": { "inlayHints": hints } } } });
        client.notify("workspace/didChangeConfiguration", settings).unwrap();
        estimated(client);
    };
    configure(&mut client, "cumulative");
    let (labels, _) = inlay_hints(&mut client, &doc);
    let times: Vec<&String> = labels.iter().filter(|label| label.contains('Σ')).collect();
    assert_eq!(times, CUMULATIVE);
    configure(&mut client, "off");
    assert_eq!(inlay_hints(&mut client, &doc).0, ["2: = 0.005"]);
}

#[test]
fn cycle_time_setting_from_initialization_options_and_edits_update_the_hints() {
    let dir = tempfile::tempdir().unwrap();
    let mut client = server();
    client.initialize(dir.path(), Some(json!({ "cycleTime": { "inlayHints": "cumulative" } }))).unwrap();
    let mut doc = document(&dir, "corners.NCP", CORNERS);
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();
    estimated(&mut client);
    let (labels, _) = inlay_hints(&mut client, &doc);
    assert_eq!(labels.iter().filter(|label| label.contains('Σ')).collect::<Vec<_>>(), CUMULATIVE);
    // Twice the feed: every move takes about half as long.
    let feed = doc.text().find("F600").unwrap();
    client.notify("textDocument/didChange", doc.change(feed + 1..feed + 2, "12")).unwrap();
    estimated(&mut client);
    let (labels, _) = inlay_hints(&mut client, &doc);
    assert_eq!(labels.iter().filter(|label| label.contains('Σ')).collect::<Vec<_>>(), CUMULATIVE_AT_F1200);
}

#[test]
fn an_edit_of_a_macrocycle_file_updates_the_times_of_the_program_that_calls_it() {
    let (mut client, dir) = session();
    let mut macrocycle = document(&dir, "L9001", "N1 G79 L9001\nN2 G01 X10\nN3 G70\n*\n");
    client.notify("textDocument/didOpen", macrocycle.did_open()).unwrap();
    let program = document(&dir, "main.NCP", "%1\nN10 G91 G01 F600\nN20 G72 L9001\nN30 M30\n*\n");
    client.notify("textDocument/didOpen", program.did_open()).unwrap();
    estimated(&mut client);
    let call_time = |client: &mut Client| {
        let (labels, _) = inlay_hints(client, &program);
        labels.into_iter().find(|label| label.starts_with("2: ") && !label.contains('▼'))
    };
    // 10 mm at 10 mm/s, with its ramps and the stop after it.
    assert_eq!(call_time(&mut client).as_deref(), Some("2: 1.03 s"));
    // Twice the way in the macrocycle: the calling block takes longer.
    let x = macrocycle.text().find("X10").unwrap();
    client.notify("textDocument/didChange", macrocycle.change(x + 1..x + 3, "20")).unwrap();
    estimated(&mut client);
    assert_eq!(call_time(&mut client).as_deref(), Some("2: 2.03 s"));
}

#[test]
fn the_program_total_is_a_code_lens_on_the_header() {
    let (mut client, dir) = session();
    let doc = document(&dir, "corners.NCP", CORNERS);
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();
    estimated(&mut client);
    let answer = client.call("textDocument/codeLens", json!({ "textDocument": doc.id() })).unwrap();
    let lenses = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
    assert_eq!(lenses.as_array().map(Vec::len), Some(1), "{lenses}");
    assert_eq!(lenses[0]["range"]["start"], json!({ "line": 0, "character": 0 }));
    assert_eq!(lenses[0]["command"]["title"], HEADLINE);
}

#[test]
fn hover_on_a_block_adds_its_speed_profile() {
    let (mut client, dir) = session();
    let doc = document(&dir, "corners.NCP", CORNERS);
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();
    estimated(&mut client);
    let hover = |client: &mut Client, at: &str| {
        let answer = client.call("textDocument/hover", doc.at(doc.position(doc.text().find(at).unwrap()))).unwrap();
        answer.result().and_then(|r| r["contents"]["value"].as_str()).unwrap_or_default().to_owned()
    };
    // On a word: the catalogue's text and modal state, then the time.
    let on_y = hover(&mut client, "Y10");
    let (documentation, time) = on_y.rsplit_once("\n\n---\n\n").unwrap();
    assert!(documentation.contains("**Modal state before this block:**"), "{on_y}");
    assert_eq!(time, N20_HOVER);
    // Anywhere else in the block: the time alone.
    assert_eq!(hover(&mut client, "SIDE"), N20_HOVER);
}

/// A Sinumerik subprogram with a jump the wrong way on line 7 and a
/// syntax error on line 8, where its run stops.
const SINUMERIK: &str = "PROC PART(REAL DEPTH) SAVE
DEF STRING[20] NAME=\"A\"
; two comment lines
; fold together
G642 SOFT
START: $P_UIFR[1,X,TR]=5
IF DEPTH>2 GOTOF START
R1=(5+
WHILE R1<10
  NAME=SUBSTR(NAME<<\"B\",0,1)
ENDWHILE
M17
";

#[test]
fn a_sinumerik_document_gets_its_syntax_errors_hover_tokens_and_outline() {
    let (mut client, dir) = session();
    let doc = document(&dir, "PART.SPF", SINUMERIK);
    client.notify("textDocument/didOpen", doc.did_open()).unwrap();
    let published = settled_diagnostics(&mut client, &doc);
    let diagnostics = published.params()["diagnostics"].as_array().unwrap();
    let found: Vec<(&str, u64)> = diagnostics
        .iter()
        .map(|d| (d["code"].as_str().unwrap(), d["range"]["start"]["line"].as_u64().unwrap()))
        .collect();
    assert_eq!(found, [("K105", 6), ("S029", 7), ("S024", 7)], "{}", published.json);
    let at = json!({ "line": 6, "character": 11 });
    let actions = client
        .call(
            "textDocument/codeAction",
            json!({ "textDocument": doc.id(), "range": { "start": at, "end": at }, "context": { "diagnostics": [] } }),
        )
        .unwrap();
    assert!(actions.json.to_string().contains("Write GOTOB"), "{}", actions.json);

    let hover = |client: &mut Client, at: &str| {
        let answer = client.call("textDocument/hover", doc.at(doc.position(doc.text().find(at).unwrap()))).unwrap();
        answer.result().and_then(|r| r["contents"]["value"].as_str()).unwrap_or_default().to_owned()
    };
    assert!(hover(&mut client, "G642").starts_with("### G642"), "{}", hover(&mut client, "G642"));
    assert!(hover(&mut client, "SOFT").starts_with("### SOFT"), "{}", hover(&mut client, "SOFT"));
    assert!(hover(&mut client, "GOTOF").starts_with("### GOTOF — Jump forward"), "{}", hover(&mut client, "GOTOF"));
    // Known by its prefix: a variable ncc does not document, never an error.
    assert!(
        hover(&mut client, "$P_UIFR").starts_with("### $P_… — a system variable"),
        "{}",
        hover(&mut client, "$P_UIFR")
    );
    let substr = hover(&mut client, "SUBSTR(");
    assert!(substr.starts_with("### SUBSTR") && substr.contains("```\nSUBSTR("), "{substr}");
    // A name of the program's own shows its definition.
    let own = hover(&mut client, "NAME=");
    assert!(own.starts_with("**variable `NAME`**") && own.contains("DEF STRING[20] NAME=\"A\""), "{own}");

    let tokens = client.call("textDocument/semanticTokens/full", json!({ "textDocument": doc.id() })).unwrap();
    let data = tokens.result().unwrap()["data"].as_array().unwrap().clone();
    let types = ["keyword", "macro", "property", "function", "label", "variable", "number", "comment", "operator"];
    let types: Vec<&str> = types.into_iter().chain(["error", "type", "string"]).collect();
    let (mut line, mut start) = (0, 0);
    let mut classified = Vec::new();
    for token in data.chunks(5) {
        let number = |i: usize| token[i].as_u64().unwrap() as usize;
        line += number(0);
        start = if number(0) == 0 { start + number(1) } else { number(1) };
        let text: String = doc.text().lines().nth(line).unwrap().chars().skip(start).take(number(2)).collect();
        classified.push((text, types[number(3)]));
    }
    for (text, kind) in [
        ("PROC", "keyword"),
        ("PART", "function"),
        ("\"A\"", "string"),
        ("START:", "label"),
        ("$P_UIFR", "property"),
        (">", "operator"),
        ("START", "label"),
        ("<<", "operator"),
        ("(", "operator"),
        ("NAME", "variable"),
        ("SUBSTR", "keyword"),
        ("G642", "keyword"),
    ] {
        assert!(classified.contains(&(text.to_owned(), kind)), "{text} as {kind}: {classified:?}");
    }

    let symbols = client.call("textDocument/documentSymbol", json!({ "textDocument": doc.id() })).unwrap();
    let symbols = symbols.result().unwrap().as_array().unwrap().clone();
    assert_eq!(symbols.len(), 1, "{symbols:?}");
    assert_eq!(symbols[0]["name"], "PART");
    let children: Vec<&Value> = symbols[0]["children"].as_array().unwrap().iter().map(|c| &c["name"]).collect();
    assert_eq!(children, ["NAME", "START", "WHILE R1<10"], "{symbols:?}");

    let folds = client.call("textDocument/foldingRange", json!({ "textDocument": doc.id() })).unwrap();
    let folds: Vec<(u64, u64)> = folds
        .result()
        .unwrap()
        .as_array()
        .unwrap()
        .iter()
        .map(|f| (f["startLine"].as_u64().unwrap(), f["endLine"].as_u64().unwrap()))
        .collect();
    assert_eq!(folds, [(2, 3), (8, 10)]);
    // The run stops at the malformed line: the total says so.
    estimated(&mut client);
    let lenses = client.call("textDocument/codeLens", json!({ "textDocument": doc.id() })).unwrap();
    let title = &lenses.result().unwrap()[0]["command"]["title"];
    assert_eq!(title, "Cycle time 0 s · cutting 0 s · rapid 0 s · the run stopped early", "{}", lenses.json);
    assert_serving(&mut client, &dir);
}

#[test]
fn the_project_decides_a_documents_dialect() {
    let (mut client, dir) = session();
    std::fs::create_dir(dir.path().join("siemens")).unwrap();
    std::fs::write(dir.path().join("siemens/ncc.toml"), "dialect = \"sinumerik\"\n").unwrap();
    std::fs::write(dir.path().join("ncc.toml"), "[extensions]\nPRG = \"cnc8x6\"\n").unwrap();
    // Named CNC8x6 by its extension, but in a Sinumerik project: `*` is
    // no Sinumerik.
    let siemens = document(&dir, "siemens/A.NCP", "%1\nN10 G01 X1\n*\n");
    client.notify("textDocument/didOpen", siemens.did_open()).unwrap();
    let published = settled_diagnostics(&mut client, &siemens);
    let mut codes = published.params()["diagnostics"].as_array().unwrap().iter().filter_map(|d| d["code"].as_str());
    assert!(codes.any(|code| code == "S001"), "{}", published.json);
    // An extension of the project's own: analysed as CNC8x6.
    let mapped = document(&dir, "B.PRG", "%1\nN10 G01 X1\nN20 M30\n*\n");
    client.notify("textDocument/didOpen", mapped.did_open()).unwrap();
    let published = settled_diagnostics(&mut client, &mapped);
    let codes: Vec<&str> =
        published.params()["diagnostics"].as_array().unwrap().iter().filter_map(|d| d["code"].as_str()).collect();
    assert_eq!(codes, ["M401"], "{}", published.json);
    assert_serving(&mut client, &dir);
}

/// `ncc.plot` runs the called files as the editor has them, as the inline
/// times do: an unsaved edit of a macrocycle file changes the picture.
#[test]
fn the_plot_command_runs_called_files_as_edited() {
    let (mut client, dir) = session();
    let macro_path = dir.path().join("L9001");
    std::fs::write(&macro_path, "N1 G79 L9001\nN2 G91 G01 X10 F600\nN3 G90 G70\n*\n").unwrap();
    let program = document(&dir, "MAIN.NCP", "%1\nN10 G00 X0 Y0\nN20 G72 L9001\nN30 M30\n*\n");
    open(&mut client, &program);
    let total = |client: &mut Client| {
        let answer = plot(client, json!([program.uri]));
        answer.result().unwrap_or_else(|| panic!("{}", answer.json))["totalTimeS"].as_f64().unwrap()
    };
    let on_disk = total(&mut client);
    let mut macrocycle = Document::new(file_uri(&macro_path), std::fs::read_to_string(&macro_path).unwrap());
    open(&mut client, &macrocycle);
    assert_eq!(total(&mut client), on_disk);
    // Three times the way, not saved: 20 mm more at 10 mm/s.
    let x = macrocycle.text().find("X10").unwrap();
    client.notify("textDocument/didChange", macrocycle.change(x + 1..x + 3, "30")).unwrap();
    let edited = total(&mut client);
    assert!((edited - on_disk - 2.0).abs() < 0.01, "{on_disk} s before the edit, {edited} s after");
}

/// Go to definition, rename and signature help in a Sinumerik program that
/// calls a subprogram of the workspace.
#[test]
fn sinumerik_definition_rename_and_signature_help() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("PROFIL.SPF"), "PROC PROFIL(REAL C, BOOL H, REAL X)\nG1 X=X\nRET\n").unwrap();
    let mut client = server();
    let initialized = client.initialize(dir.path(), None).unwrap();
    let capabilities = &initialized.result().unwrap()["capabilities"];
    assert_eq!(capabilities["renameProvider"], json!({ "prepareProvider": true }), "{capabilities}");
    assert_eq!(capabilities["signatureHelpProvider"]["triggerCharacters"], json!(["(", ","]), "{capabilities}");
    let text = "DEF INT DELKA\nDELKA=5 ; DELKA\nPROFIL(,TRUE,DELKA)\nM30\n";
    let doc = document(&dir, "MAIN.MPF", text);
    open(&mut client, &doc);
    let at = |needle: &str| doc.at(doc.position(text.find(needle).unwrap()));
    let range = |line: u32, start: u32, end: u32| json!({ "start": { "line": line, "character": start }, "end": { "line": line, "character": end } });

    let answer = client.call("textDocument/definition", at("PROFIL(")).unwrap();
    let links = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
    assert!(links[0]["targetUri"].as_str().is_some_and(|uri| uri.ends_with("/PROFIL.SPF")), "{links}");
    assert_eq!(links[0]["targetSelectionRange"], range(0, 5, 11), "{links}");

    let answer = client.call("textDocument/prepareRename", at("DELKA=")).unwrap();
    assert_eq!(answer.result(), Some(&range(1, 0, 5)), "{}", answer.json);
    let mut params = at("DELKA=");
    params["newName"] = json!("LENGTH");
    let answer = client.call("textDocument/rename", params.clone()).unwrap();
    let edits = &answer.result().unwrap_or_else(|| panic!("{}", answer.json))["changes"][&doc.uri];
    let edited: Vec<(&Value, &Value)> =
        edits.as_array().unwrap().iter().map(|e| (&e["range"], &e["newText"])).collect();
    // The comment keeps its word.
    let renamed = json!("LENGTH");
    assert_eq!(edited, [(&range(0, 8, 13), &renamed), (&range(1, 0, 5), &renamed), (&range(2, 13, 18), &renamed)]);
    params["newName"] = json!("1X");
    let refused = client.call("textDocument/rename", params).unwrap();
    assert_eq!(refused.error_code(), Some(-32803), "{}", refused.json);
    assert!(
        refused.json["error"]["message"].as_str().is_some_and(|m| m.contains("not a valid name")),
        "{}",
        refused.json
    );
    let refused = client.call("textDocument/prepareRename", at("M30")).unwrap();
    assert_eq!(refused.error_code(), Some(-32803), "{}", refused.json);

    let answer = client.call("textDocument/signatureHelp", at("DELKA)")).unwrap();
    let help = answer.result().unwrap_or_else(|| panic!("{}", answer.json));
    assert_eq!(help["signatures"][0]["label"], "PROFIL(REAL C, BOOL H, REAL X)", "{help}");
    assert_eq!(help["activeParameter"], 2, "{help}");
    assert_eq!(help["signatures"][0]["parameters"][2]["label"], json!([23, 29]), "{help}");
    let outside = client.call("textDocument/signatureHelp", at("M30")).unwrap();
    assert_eq!(outside.result(), Some(&Value::Null), "{}", outside.json);
    assert_serving(&mut client, &dir);
}
