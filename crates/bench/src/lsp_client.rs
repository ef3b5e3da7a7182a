//! A small synchronous language-server client for benchmarks and tests.
//!
//! It talks to a child process over stdio with the base protocol's
//! `Content-Length` framing. A reader thread timestamps every incoming
//! message when its body has been read and forwards it over a channel, so
//! latencies are measured from the moment a request is written to the
//! moment its answer arrives, whatever the caller does in between. A writer
//! thread does the writing, so that a write, too, has a timeout: a server
//! that stops reading or answering fails a test instead of hanging it.

use std::{
    collections::VecDeque,
    io::{self, BufRead, BufReader, Read, Write},
    ops::Range,
    path::Path,
    process::{Child, Command, ExitStatus, Stdio},
    sync::mpsc::{self, Receiver, RecvTimeoutError, Sender},
    thread,
    time::{Duration, Instant},
};

use anyhow::{Context, bail};
use line_index::{LineCol, LineIndex, TextSize, WideEncoding, WideLineCol};
use percent_encoding::{AsciiSet, NON_ALPHANUMERIC};
use serde_json::{Value, json};

/// The language id of CNC8x6 documents.
pub const LANGUAGE_ID: &str = "cnc8x6";

/// One message from the server, with the time its last byte was read.
#[derive(Debug, Clone)]
pub struct Message {
    pub received: Instant,
    pub json: Value,
}

impl Message {
    /// The method of a request or notification.
    pub fn method(&self) -> Option<&str> {
        self.json.get("method")?.as_str()
    }

    /// The parameters of a request or notification (`null` when absent).
    pub fn params(&self) -> &Value {
        self.json.get("params").unwrap_or(&Value::Null)
    }

    /// The id of a request or response.
    pub fn id(&self) -> Option<&Value> {
        self.json.get("id")
    }

    /// Whether this is a response (to a request of ours, or an error about
    /// an unreadable message, whose id is `null`).
    pub fn is_response(&self) -> bool {
        self.method().is_none() && self.id().is_some()
    }

    /// The result of a successful response.
    pub fn result(&self) -> Option<&Value> {
        self.json.get("result")
    }

    /// The error code of an error response.
    pub fn error_code(&self) -> Option<i64> {
        self.json.get("error")?.get("code")?.as_i64()
    }
}

/// A request written to the server.
#[derive(Debug, Clone)]
pub struct Request {
    pub id: Value,
    pub sent: Instant,
}

/// The server's resident memory as the kernel reports it (Linux only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Memory {
    /// `VmRSS`: resident now, in bytes.
    pub rss: u64,
    /// `VmHWM`: the peak resident size so far, in bytes.
    pub peak_rss: u64,
}

/// What the reader thread forwards: a message, or why framing was lost.
type Incoming = Result<Message, String>;

/// A language server running as a child process.
#[derive(Debug)]
pub struct Client {
    child: Child,
    /// Frames to write; `None` once stdin is closed or the server stopped
    /// reading it.
    frames: Option<Sender<Vec<u8>>>,
    /// When the write of each frame started, or why it failed.
    written: Receiver<io::Result<Instant>>,
    incoming: Receiver<Incoming>,
    /// Messages received while waiting for another one, oldest first.
    backlog: VecDeque<Message>,
    next_id: i64,
    /// How long a write, `response` and `notification` wait.
    pub timeout: Duration,
}

impl Client {
    /// Starts `command` with piped stdin and stdout; its stderr is left as
    /// the command has it (inherited by default), so server logs show up.
    pub fn spawn(mut command: Command) -> anyhow::Result<Client> {
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .with_context(|| format!("starting {:?}", command.get_program()))?;
        let stdout = child.stdout.take().context("no stdout pipe")?;
        let mut stdin = child.stdin.take().context("no stdin pipe")?;
        let (sender, incoming) = mpsc::channel();
        thread::Builder::new().name("lsp-reader".into()).spawn(move || read_messages(stdout, &sender))?;
        let (frames, to_write) = mpsc::channel::<Vec<u8>>();
        let (report, written) = mpsc::channel();
        thread::Builder::new().name("lsp-writer".into()).spawn(move || {
            for frame in to_write {
                let start = Instant::now();
                let result = stdin.write_all(&frame).and_then(|()| stdin.flush()).map(|()| start);
                if report.send(result).is_err() {
                    return;
                }
            }
        })?;
        Ok(Client {
            frames: Some(frames),
            written,
            child,
            incoming,
            backlog: VecDeque::new(),
            next_id: 1,
            timeout: Duration::from_secs(10),
        })
    }

    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Writes bytes as they are, for tests of broken framing. Returns the
    /// time the write started.
    pub fn send_raw(&mut self, bytes: &[u8]) -> anyhow::Result<Instant> {
        self.write(bytes.to_vec())
    }

    /// Writes one framed message.
    pub fn send(&mut self, message: &Value) -> anyhow::Result<Instant> {
        let body = serde_json::to_vec(message)?;
        let mut frame = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
        frame.extend_from_slice(&body);
        self.write(frame)
    }

    fn write(&mut self, frame: Vec<u8>) -> anyhow::Result<Instant> {
        let frames = self.frames.as_ref().context("stdin is closed")?;
        frames.send(frame).context("the writer thread has stopped")?;
        match self.written.recv_timeout(self.timeout) {
            Ok(result) => result.context("writing to the server"),
            Err(_) => {
                // The write may still finish later; later frames must not
                // be taken for it.
                self.frames = None;
                bail!("the server has not read its input for {:?}", self.timeout)
            }
        }
    }

    /// Sends a notification; `params` of `null` are left out, as for `exit`.
    pub fn notify(&mut self, method: &str, params: Value) -> anyhow::Result<Instant> {
        self.send(&call(method, None, params))
    }

    /// Sends a request; `params` of `null` are left out, as for `shutdown`.
    pub fn request(&mut self, method: &str, params: Value) -> anyhow::Result<Request> {
        let id = json!(self.next_id);
        self.next_id += 1;
        let sent = self.send(&call(method, Some(&id), params))?;
        Ok(Request { id, sent })
    }

    /// Waits for the response to `request` (success or error).
    pub fn response(&mut self, request: &Request) -> anyhow::Result<Message> {
        self.response_to(&request.id)
    }

    /// Waits for a response with this id; `null` for the error responses
    /// to messages the server could not read.
    pub fn response_to(&mut self, id: &Value) -> anyhow::Result<Message> {
        self.wait_for(&format!("the response to request {id}"), self.timeout, |m| m.is_response() && m.id() == Some(id))
    }

    /// Sends a request and waits for its response.
    pub fn call(&mut self, method: &str, params: Value) -> anyhow::Result<Message> {
        let request = self.request(method, params)?;
        self.response(&request)
    }

    /// Waits for a notification with this method that satisfies `accept`.
    pub fn notification(&mut self, method: &str, accept: impl FnMut(&Message) -> bool) -> anyhow::Result<Message> {
        let timeout = self.timeout;
        self.notification_within(method, timeout, accept)
    }

    pub fn notification_within(
        &mut self,
        method: &str,
        timeout: Duration,
        mut accept: impl FnMut(&Message) -> bool,
    ) -> anyhow::Result<Message> {
        self.wait_for(&format!("a {method} notification"), timeout, |m| {
            m.method() == Some(method) && m.id().is_none() && accept(m)
        })
    }

    /// Waits for the `publishDiagnostics` of `uri` at `version`.
    pub fn diagnostics(&mut self, uri: &str, version: i32) -> anyhow::Result<Message> {
        let timeout = self.timeout;
        self.diagnostics_within(uri, version, timeout)
    }

    pub fn diagnostics_within(&mut self, uri: &str, version: i32, timeout: Duration) -> anyhow::Result<Message> {
        self.notification_within("textDocument/publishDiagnostics", timeout, |m| {
            m.params()["uri"] == uri && m.params()["version"] == version
        })
    }

    /// The first message, received earlier or within `timeout`, that
    /// satisfies `accept`. Other messages stay in the backlog for later
    /// waits. Requests from the server are answered as they arrive (see
    /// [`Client::answer`]) and kept in the backlog too.
    pub fn wait_for(
        &mut self,
        what: &str,
        timeout: Duration,
        mut accept: impl FnMut(&Message) -> bool,
    ) -> anyhow::Result<Message> {
        if let Some(at) = self.backlog.iter().position(&mut accept) {
            return Ok(self.backlog.remove(at).expect("position is in the backlog"));
        }
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let message = match self.incoming.recv_timeout(left) {
                Ok(Ok(message)) => message,
                Ok(Err(framing)) => bail!("waiting for {what}: the server's output is not framed: {framing}"),
                Err(RecvTimeoutError::Timeout) => {
                    bail!("waiting for {what}: nothing within {timeout:?}; unclaimed: {}", self.backlog_summary())
                }
                Err(RecvTimeoutError::Disconnected) => bail!("waiting for {what}: the server closed its output"),
            };
            self.answer(&message)?;
            if accept(&message) {
                return Ok(message);
            }
            self.backlog.push_back(message);
        }
    }

    /// Answers a request from the server: the refreshes the client
    /// announces with success, anything else with MethodNotFound.
    fn answer(&mut self, message: &Message) -> anyhow::Result<()> {
        let (Some(method), Some(id)) = (message.method(), message.id()) else { return Ok(()) };
        let answer = if REFRESHES.contains(&method) {
            json!({ "jsonrpc": "2.0", "id": id, "result": null })
        } else {
            let error = json!({ "code": -32601, "message": format!("unsupported request {method}") });
            json!({ "jsonrpc": "2.0", "id": id, "error": error })
        };
        self.send(&answer).map(drop)
    }

    /// Moves everything received so far, unclaimed, out of the client;
    /// requests among it are answered.
    pub fn take_received(&mut self) -> Vec<Message> {
        while let Ok(Ok(message)) = self.incoming.try_recv() {
            // A server that stopped reading fails the next wait instead.
            let _ = self.answer(&message);
            self.backlog.push_back(message);
        }
        self.backlog.drain(..).collect()
    }

    fn backlog_summary(&self) -> String {
        let names: Vec<String> = self
            .backlog
            .iter()
            .map(|m| m.method().map_or_else(|| format!("response {}", m.id().unwrap_or(&Value::Null)), str::to_owned))
            .collect();
        if names.is_empty() { "none".to_owned() } else { names.join(", ") }
    }

    /// `initialize` and `initialized`, with `root` as the workspace folder.
    pub fn initialize(&mut self, root: &Path, options: Option<Value>) -> anyhow::Result<Message> {
        let response = self.call("initialize", initialize_params(root, options))?;
        if response.result().is_none() {
            bail!("initialize failed: {}", response.json);
        }
        self.notify("initialized", json!({}))?;
        Ok(response)
    }

    /// `shutdown`, then `exit`; returns how the process ended.
    pub fn shutdown(&mut self) -> anyhow::Result<ExitStatus> {
        let response = self.call("shutdown", Value::Null)?;
        if response.json.get("error").is_some() {
            bail!("shutdown failed: {}", response.json);
        }
        self.notify("exit", Value::Null)?;
        self.wait_exit(self.timeout)
    }

    /// Closes the server's stdin, as an editor that goes away does.
    pub fn close_stdin(&mut self) {
        // The writer thread ends and drops the pipe.
        self.frames = None;
    }

    /// Waits for the process to end.
    pub fn wait_exit(&mut self, timeout: Duration) -> anyhow::Result<ExitStatus> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(status) = self.child.try_wait()? {
                return Ok(status);
            }
            if Instant::now() >= deadline {
                bail!("the server is still running after {timeout:?}");
            }
            thread::sleep(Duration::from_millis(10));
        }
    }

    /// The server's resident memory; `None` where `/proc` does not exist.
    pub fn memory(&self) -> Option<Memory> {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).ok()?;
        let kilobytes = |key: &str| -> Option<u64> {
            let line = status.lines().find_map(|line| line.strip_prefix(key)?.strip_prefix(':'))?;
            line.trim().strip_suffix("kB")?.trim().parse().ok()
        };
        Some(Memory { rss: kilobytes("VmRSS")? * 1024, peak_rss: kilobytes("VmHWM")? * 1024 })
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        // A test that failed midway must not leave a server behind.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The requests a server may send that the client takes: it fetches inlay
/// hints and code lenses again when asked.
pub const REFRESHES: [&str; 2] = ["workspace/inlayHint/refresh", "workspace/codeLens/refresh"];

/// The `initialize` parameters of a minimal client: UTF-16 positions,
/// versioned diagnostics, Markdown hovers, inlay hints and code lenses
/// that the server may ask to refresh ([`REFRESHES`]).
pub fn initialize_params(root: &Path, options: Option<Value>) -> Value {
    let uri = file_uri(root);
    json!({
        "processId": std::process::id(),
        "clientInfo": { "name": "ncc-bench" },
        "rootUri": uri,
        "workspaceFolders": [{ "uri": uri, "name": "workspace" }],
        "initializationOptions": options,
        "capabilities": {
            "general": { "positionEncodings": ["utf-16"] },
            "workspace": {
                "inlayHint": { "refreshSupport": true },
                "codeLens": { "refreshSupport": true },
            },
            "textDocument": {
                "synchronization": { "dynamicRegistration": false },
                "publishDiagnostics": {
                    "relatedInformation": true,
                    "versionSupport": true,
                    "tagSupport": { "valueSet": [1, 2] },
                },
                "hover": { "contentFormat": ["markdown", "plaintext"] },
                "inlayHint": { "dynamicRegistration": false },
                "codeLens": { "dynamicRegistration": false },
            },
        },
    })
}

/// A request (with an id) or a notification.
fn call(method: &str, id: Option<&Value>, params: Value) -> Value {
    let mut message = json!({ "jsonrpc": "2.0", "method": method });
    if let Some(id) = id {
        message["id"] = id.clone();
    }
    if !params.is_null() {
        message["params"] = params;
    }
    message
}

/// Characters kept as they are in a file URI's path.
const PATH_CHARACTERS: &AsciiSet = &NON_ALPHANUMERIC.remove(b'/').remove(b'-').remove(b'.').remove(b'_').remove(b'~');

/// The `file:` URI of an absolute path.
pub fn file_uri(path: &Path) -> String {
    let path = path.to_string_lossy().replace('\\', "/");
    // Windows paths (`C:/...`) get the slash that Unix paths start with.
    let slash = if path.starts_with('/') { "" } else { "/" };
    format!("file://{slash}{}", percent_encoding::utf8_percent_encode(&path, PATH_CHARACTERS))
}

/// Reads framed messages until the stream ends or loses its framing.
fn read_messages(stdout: impl Read, sender: &Sender<Incoming>) {
    let mut reader = BufReader::new(stdout);
    loop {
        let incoming = match read_message(&mut reader) {
            Ok(Some(json)) => Ok(Message { received: Instant::now(), json }),
            Ok(None) => return,
            Err(error) => Err(error.to_string()),
        };
        let lost = incoming.is_err();
        if sender.send(incoming).is_err() || lost {
            return;
        }
    }
}

/// One message; `None` at the end of the stream between messages.
fn read_message(reader: &mut impl BufRead) -> io::Result<Option<Value>> {
    let invalid = |message: String| io::Error::new(io::ErrorKind::InvalidData, message);
    let mut length = None;
    let mut line = String::new();
    loop {
        line.clear();
        if reader.read_line(&mut line)? == 0 {
            return if length.is_none() { Ok(None) } else { Err(io::ErrorKind::UnexpectedEof.into()) };
        }
        let header = line.strip_suffix("\r\n").ok_or_else(|| invalid(format!("header line {line:?}")))?;
        if header.is_empty() {
            break;
        }
        let (name, value) = header.split_once(':').ok_or_else(|| invalid(format!("header {header:?}")))?;
        if name.eq_ignore_ascii_case("Content-Length") {
            length = Some(value.trim().parse::<usize>().map_err(|_| invalid(format!("header {header:?}")))?);
        }
    }
    let length = length.ok_or_else(|| invalid("no Content-Length header".into()))?;
    let mut body = vec![0; length];
    reader.read_exact(&mut body)?;
    Ok(Some(serde_json::from_slice(&body)?))
}

/// A text document as the client holds it: its text, version and the
/// conversion between byte offsets and LSP positions (UTF-16 columns).
#[derive(Debug)]
pub struct Document {
    pub uri: String,
    pub version: i32,
    text: String,
    index: LineIndex,
}

impl Document {
    /// A document at version 1.
    pub fn new(uri: String, text: String) -> Document {
        let index = LineIndex::new(&text);
        Document { uri, version: 1, text, index }
    }

    pub fn text(&self) -> &str {
        &self.text
    }

    /// `{ "uri": ... }`, as requests name the document.
    pub fn id(&self) -> Value {
        json!({ "uri": self.uri })
    }

    /// The parameters of `textDocument/didOpen`.
    pub fn did_open(&self) -> Value {
        json!({
            "textDocument": { "uri": self.uri, "languageId": LANGUAGE_ID, "version": self.version, "text": self.text },
        })
    }

    /// Parameters naming the document and a position, as hover, definition
    /// and completion take them.
    pub fn at(&self, position: Value) -> Value {
        json!({ "textDocument": self.id(), "position": position })
    }

    /// The LSP position of a byte offset.
    ///
    /// # Panics
    ///
    /// If `offset` is past the end or inside a character.
    pub fn position(&self, offset: usize) -> Value {
        let line_col = self.index.line_col(TextSize::try_from(offset).expect("offset fits in u32"));
        let wide = self.index.to_wide(WideEncoding::Utf16, line_col).expect("a valid position converts to UTF-16");
        json!({ "line": wide.line, "character": wide.col })
    }

    /// The LSP range of a byte range.
    pub fn range(&self, range: Range<usize>) -> Value {
        json!({ "start": self.position(range.start), "end": self.position(range.end) })
    }

    /// The byte offset of an LSP position, if it lies in the document.
    pub fn offset(&self, position: &Value) -> Option<usize> {
        let wide = WideLineCol {
            line: u32::try_from(position["line"].as_u64()?).ok()?,
            col: u32::try_from(position["character"].as_u64()?).ok()?,
        };
        let line_col: LineCol = self.index.to_utf8(WideEncoding::Utf16, wide)?;
        let offset = usize::from(self.index.offset(line_col)?);
        let line_end = self.line_end(line_col.line as usize)?;
        (offset <= line_end && self.text.is_char_boundary(offset)).then_some(offset)
    }

    /// The byte range of an LSP range, if it lies in the document.
    pub fn byte_range(&self, range: &Value) -> Option<Range<usize>> {
        Some(self.offset(&range["start"])?..self.offset(&range["end"])?)
    }

    /// The offset of a position the way LSP 3.17 reads positions past an
    /// end: a character past the end of its line means the line's end, and
    /// a line past the last one means the end of the document.
    pub fn clamped_offset(&self, position: &Value) -> usize {
        let line = position["line"].as_u64().unwrap_or(0) as usize;
        let Some(line_end) = self.line_end(line) else { return self.text.len() };
        let line_start = usize::from(self.index.offset(LineCol { line: line as u32, col: 0 }).unwrap_or_default());
        let mut units = position["character"].as_u64().unwrap_or(0) as usize;
        for (at, c) in self.text[line_start..line_end].char_indices() {
            if units < c.len_utf16() {
                return line_start + at;
            }
            units -= c.len_utf16();
        }
        line_end
    }

    /// The end of line `line` (before its line break), if it exists.
    fn line_end(&self, line: usize) -> Option<usize> {
        let start = usize::from(self.index.offset(LineCol { line: u32::try_from(line).ok()?, col: 0 })?);
        if start > self.text.len() {
            return None;
        }
        let end = self.text[start..].find('\n').map_or(self.text.len(), |at| start + at);
        Some(if self.text[..end].ends_with('\r') { end - 1 } else { end })
    }

    /// Replaces `range` with `new_text`, moves to the next version and
    /// returns the parameters of the matching incremental `didChange`.
    pub fn change(&mut self, range: Range<usize>, new_text: &str) -> Value {
        let lsp_range = self.range(range.clone());
        self.apply(range, new_text);
        self.did_change(lsp_range, new_text)
    }

    /// Like [`change`](Self::change), for an LSP range as it is sent (also
    /// one past the end), applied as [`clamped_offset`](Self::clamped_offset)
    /// reads it.
    pub fn change_lsp(&mut self, lsp_range: Value, new_text: &str) -> Value {
        let start = self.clamped_offset(&lsp_range["start"]);
        let end = self.clamped_offset(&lsp_range["end"]).max(start);
        self.apply(start..end, new_text);
        self.did_change(lsp_range, new_text)
    }

    fn apply(&mut self, range: Range<usize>, new_text: &str) {
        self.text.replace_range(range, new_text);
        self.index = LineIndex::new(&self.text);
        self.version += 1;
    }

    fn did_change(&self, lsp_range: Value, new_text: &str) -> Value {
        json!({
            "textDocument": { "uri": self.uri, "version": self.version },
            "contentChanges": [{ "range": lsp_range, "text": new_text }],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ŽLUŤOUČKÝ` has two-byte letters (one UTF-16 unit each); the emoji
    /// has four bytes and two UTF-16 units.
    const TEXT: &str = "%1\nN10 G0 \"ŽLUŤOUČKÝ 😀\" X1\r\nN20 M30\n";

    fn document() -> Document {
        Document::new("file:///p.NCP".into(), TEXT.into())
    }

    #[test]
    fn positions_count_utf16_units() {
        let doc = document();
        let x1 = TEXT.find("X1").unwrap();
        assert_eq!(doc.position(x1), json!({ "line": 1, "character": 22 }));
        assert_eq!(doc.offset(&json!({ "line": 1, "character": 22 })), Some(x1));
        assert_eq!(doc.position(TEXT.len()), json!({ "line": 3, "character": 0 }));
        // Every offset but the one inside `\r\n` has a position.
        for offset in (0..=TEXT.len()).filter(|&at| TEXT.is_char_boundary(at) && !TEXT[..at].ends_with('\r')) {
            assert_eq!(doc.offset(&doc.position(offset)), Some(offset), "offset {offset}");
        }
    }

    #[test]
    fn positions_outside_the_document_have_no_offset() {
        let doc = document();
        // Past the end of line 1 (24 units before `\r\n`), past the last
        // line, and between the halves of the emoji's surrogate pair.
        for (line, character) in [(1, 25), (4, 0), (1, 19)] {
            assert_eq!(doc.offset(&json!({ "line": line, "character": character })), None, "{line}:{character}");
        }
    }

    #[test]
    fn positions_past_an_end_clamp_like_lsp() {
        let doc = document();
        let line_1_end = TEXT.find("\r\n").unwrap();
        assert_eq!(doc.clamped_offset(&json!({ "line": 1, "character": 99 })), line_1_end);
        assert_eq!(doc.clamped_offset(&json!({ "line": 9, "character": 0 })), TEXT.len());
        assert_eq!(doc.clamped_offset(&json!({ "line": 2, "character": 4 })), TEXT.find("M30").unwrap());
    }

    #[test]
    fn changes_carry_the_range_before_the_edit_and_the_next_version() {
        let mut doc = document();
        let x1 = TEXT.find("X1").unwrap();
        let params = doc.change(x1 + 1..x1 + 2, "25");
        assert_eq!(doc.version, 2);
        assert!(doc.text().contains("X25\r\n"));
        assert_eq!(params["textDocument"]["version"], 2);
        assert_eq!(
            params["contentChanges"][0]["range"],
            json!({ "start": { "line": 1, "character": 23 }, "end": { "line": 1, "character": 24 } })
        );
        let appended = doc
            .change_lsp(json!({ "start": { "line": 7, "character": 0 }, "end": { "line": 8, "character": 1 } }), "*\n");
        assert_eq!(appended["textDocument"]["version"], 3);
        assert!(doc.text().ends_with("N20 M30\n*\n"));
    }

    #[test]
    fn framing_round_trips_and_reports_broken_headers() {
        let mut stream: &[u8] = b"Content-Length: 8\r\nContent-Type: application/vscode-jsonrpc; charset=utf-8\r\n\r\n{\"a\":1}\nContent-Length: 2\r\n\r\n[]";
        assert_eq!(read_message(&mut stream).unwrap(), Some(json!({ "a": 1 })));
        assert_eq!(read_message(&mut stream).unwrap(), Some(json!([])));
        assert_eq!(read_message(&mut stream).unwrap(), None);
        for broken in
            [&b"Content-Length: x\r\n\r\n{}"[..], b"Content-Length: 9\r\n\r\n{}", b"Content-Type: a\r\n\r\n{}"]
        {
            assert!(read_message(&mut &broken[..]).is_err(), "{}", String::from_utf8_lossy(broken));
        }
    }

    /// `cat` sends every message back: a notification returns as itself, a
    /// request as a request from the "server", which the client answers
    /// with MethodNotFound, and that answer comes back as the response.
    #[cfg(unix)]
    #[test]
    fn a_client_talks_to_an_echo() {
        let mut client = Client::spawn(Command::new("cat")).unwrap();
        client.notify("ncc/echo", json!({ "text": "ŘEŽ" })).unwrap();
        let echoed = client.notification("ncc/echo", |m| m.params()["text"] == "ŘEŽ").unwrap();
        let request = client.request("ncc/ping", Value::Null).unwrap();
        let answer = client.response(&request).unwrap();
        assert_eq!(answer.error_code(), Some(-32601), "{}", answer.json);
        assert!(request.sent >= echoed.received && answer.received > request.sent);
        let unclaimed: Vec<Value> = client.take_received().into_iter().map(|m| m.json).collect();
        assert_eq!(unclaimed, [json!({ "jsonrpc": "2.0", "id": 1, "method": "ncc/ping" })]);
        client.close_stdin();
        assert!(client.wait_exit(Duration::from_secs(5)).unwrap().success());
    }

    #[cfg(unix)]
    #[test]
    fn a_server_that_reads_nothing_fails_writes_and_waits_instead_of_hanging() {
        let mut sleep = Command::new("sleep");
        sleep.arg("60");
        let mut client = Client::spawn(sleep).unwrap();
        client.timeout = Duration::from_millis(200);
        // More than a pipe holds.
        let error = client.send_raw(&vec![b' '; 1 << 20]).unwrap_err();
        assert!(error.to_string().contains("has not read its input"), "{error}");
        assert!(client.notify("exit", Value::Null).is_err());
        let error = client.response_to(&json!(1)).unwrap_err();
        assert!(error.to_string().contains("nothing within"), "{error}");
    }

    #[test]
    fn file_uris_escape_what_a_uri_path_cannot_hold() {
        assert_eq!(file_uri(Path::new("/tmp/a b/Ř.NCP")), "file:///tmp/a%20b/%C5%98.NCP");
    }
}
