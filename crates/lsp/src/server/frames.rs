//! A guard between stdio and the protocol layer. tower-lsp-server's reader
//! stops for good at the first frame it cannot decode, so one malformed
//! message would end the server. Frames are checked here first and only
//! well-formed messages pass; the rest are answered as JSON-RPC and the
//! protocol say (Parse error, Invalid request, MethodNotFound for unknown
//! `$/` requests) and reading goes on.

use std::{
    collections::HashMap,
    io::{self, Read, Write},
    pin::Pin,
    sync::{Arc, Mutex, MutexGuard},
    task::{Context, Poll},
};

use ncc_analysis::interactive;

use serde_json::{Value, json};
use tokio::io::{
    AsyncBufRead, AsyncBufReadExt, AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt, BufReader, ReadBuf,
};

const CONTENT_LENGTH: &[u8] = b"content-length:";

/// One message read from a stream.
enum Frame {
    Body(Vec<u8>),
    /// Headers without a usable length; the reader skipped to the next.
    BadHeader,
}

/// Reads the next frame; `None` at the end of the stream.
async fn read_frame<R: AsyncBufRead + Unpin>(reader: &mut R) -> io::Result<Option<Frame>> {
    let mut length: Option<usize> = None;
    let mut bad = false;
    let mut line = Vec::new();
    loop {
        line.clear();
        if reader.read_until(b'\n', &mut line).await? == 0 {
            return Ok(None);
        }
        let lower = line.to_ascii_lowercase();
        // After a bad header the next message may start mid-line, right
        // after the previous body.
        let start = lower.windows(CONTENT_LENGTH.len()).position(|w| w == CONTENT_LENGTH);
        if let Some(start) = start.filter(|&start| start > 0 || bad) {
            bad = false;
            line.drain(..start);
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\r', '\n']);
        if text.is_empty() {
            match length {
                Some(length) if !bad => {
                    let mut body = vec![0; length];
                    reader.read_exact(&mut body).await?;
                    return Ok(Some(Frame::Body(body)));
                }
                _ => return Ok(Some(Frame::BadHeader)),
            }
        }
        if let Some((name, value)) = text.split_once(':')
            && name.trim().eq_ignore_ascii_case("content-length")
        {
            length = value.trim().parse().ok();
            bad |= length.is_none();
        }
    }
}

fn framed(body: &[u8]) -> Vec<u8> {
    let mut frame = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    frame.extend_from_slice(body);
    frame
}

fn error_response(id: Value, code: i64, message: &str) -> Vec<u8> {
    let response = json!({ "jsonrpc": "2.0", "id": id, "error": { "code": code, "message": message } });
    framed(response.to_string().as_bytes())
}

/// What to do with a message body: pass it on, or answer it here.
/// A well-formed message's request id (`None`: a notification or a
/// response), or the answer to a malformed one.
fn check(body: &[u8]) -> Result<Option<Value>, Vec<u8>> {
    let value: Value =
        serde_json::from_slice(body).map_err(|error| error_response(Value::Null, -32700, &error.to_string()))?;
    let Some(message) = value.as_object() else {
        return Err(error_response(Value::Null, -32600, "a message must be a JSON object"));
    };
    let id = message.get("id").cloned();
    match (message.get("method").and_then(Value::as_str), id) {
        // The protocol: a `$/` request the server does not know is
        // MethodNotFound (tower-lsp-server drops it unanswered).
        (Some(method), Some(id)) if method.starts_with("$/") => {
            Err(error_response(id, -32601, &format!("unknown method {method}")))
        }
        (Some(_), id) => Ok(id),
        (None, Some(_)) if message.contains_key("result") || message.contains_key("error") => Ok(None),
        (None, id) => Err(error_response(id.unwrap_or(Value::Null), -32600, "neither a request nor a response")),
    }
}

/// Copies well-formed messages from `input` to `server`, and answers the
/// rest through `answer`.
pub(crate) async fn guard_input(
    input: impl AsyncRead + Unpin,
    mut server: impl AsyncWrite + Unpin,
    answer: impl Fn(&[u8]) -> io::Result<()>,
    pending: Pending,
) -> io::Result<()> {
    let mut reader = BufReader::new(input);
    while let Some(frame) = read_frame(&mut reader).await? {
        match frame {
            Frame::Body(body) => match check(&body) {
                Ok(id) => {
                    if let Some(id) = id {
                        pending.read(&id);
                    }
                    server.write_all(&framed(&body)).await?;
                    server.flush().await?;
                }
                Err(rejection) => {
                    tracing::warn!("rejected a message: {}", String::from_utf8_lossy(&body));
                    answer(&rejection)?;
                }
            },
            Frame::BadHeader => tracing::warn!("skipped a message without a valid Content-Length"),
        }
    }
    Ok(())
}

/// Passes the server's messages, whole, to `write`.
pub(crate) async fn forward_output(
    server: impl AsyncRead + Unpin,
    write: impl Fn(&[u8]) -> io::Result<()>,
    pending: Pending,
) -> io::Result<()> {
    let mut reader = BufReader::new(server);
    while let Some(frame) = read_frame(&mut reader).await? {
        if let Frame::Body(body) = frame {
            // Written first: background work resumes when the request ends,
            // and would take the core the write waits for.
            write(&framed(&body))?;
            pending.answered(&body);
        }
    }
    Ok(())
}

/// Writes one whole frame to stdout: the threads that write hold its lock
/// for a frame, so frames never interleave.
pub(crate) fn write_stdout(frame: &[u8]) -> io::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(frame)?;
    out.flush()
}

/// A stream read on the thread that polls it. On a thread of its own a
/// read waits there, where `tokio::io::stdin` hands every read to the
/// blocking pool and back: two thread wake-ups per message, each a wait
/// for a core while background work holds both.
pub(crate) struct Blocking<R>(pub R);

impl<R: Read + Unpin> AsyncRead for Blocking<R> {
    fn poll_read(mut self: Pin<&mut Self>, _cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        let read = self.0.read(buf.initialize_unfilled());
        Poll::Ready(read.map(|count| buf.advance(count)))
    }
}

/// The client's requests the server has not answered yet: background work
/// gives way to them from the moment they are read until their answers
/// leave, so that the hand-overs between the threads that read, answer
/// and write find a core.
#[derive(Debug, Clone, Default)]
pub(crate) struct Pending(Arc<Mutex<HashMap<String, interactive::Request>>>);

impl Pending {
    fn read(&self, id: &Value) {
        self.lock().insert(id.to_string(), interactive::Request::begin());
    }

    /// Ends the request `body` answers, if it is a response.
    fn answered(&self, body: &[u8]) {
        /// A message's id and whether it has a method, the rest skipped.
        #[derive(serde::Deserialize)]
        struct Envelope {
            id: Option<Value>,
            method: Option<serde::de::IgnoredAny>,
        }
        // Most frames pass with no request pending (diagnostics, which may
        // be large): they are not read.
        if self.lock().is_empty() {
            return;
        }
        let Ok(Envelope { id: Some(id), method: None }) = serde_json::from_slice(body) else { return };
        self.lock().remove(&id.to_string());
    }

    fn lock(&self) -> MutexGuard<'_, HashMap<String, interactive::Request>> {
        self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    async fn frames(input: &[u8]) -> Vec<Option<Vec<u8>>> {
        let mut reader = BufReader::new(input);
        let mut out = Vec::new();
        while let Some(frame) = read_frame(&mut reader).await.unwrap() {
            out.push(match frame {
                Frame::Body(body) => Some(body),
                Frame::BadHeader => None,
            });
        }
        out
    }

    #[tokio::test]
    async fn frames_are_read_and_bad_headers_skipped() {
        let input = b"Content-Length: 2\r\nContent-Type: x\r\n\r\n{}Content-Length: twelve\r\n\r\n{}Content-Length: 4\r\n\r\nnullcontent-length: 1\r\n\r\n1";
        let read = frames(input).await;
        assert_eq!(read, vec![Some(b"{}".to_vec()), None, Some(b"null".to_vec()), Some(b"1".to_vec())]);
    }

    #[test]
    fn messages_are_checked_as_json_rpc_says() {
        let code = |body: &str| {
            check(body.as_bytes()).err().map(|answer| {
                let text = String::from_utf8(answer).unwrap();
                let json: Value = serde_json::from_str(text.split("\r\n\r\n").nth(1).unwrap()).unwrap();
                (json["error"]["code"].as_i64().unwrap(), json["id"].clone())
            })
        };
        assert_eq!(code("not json"), Some((-32700, Value::Null)));
        assert_eq!(code("42"), Some((-32600, Value::Null)));
        assert_eq!(code("[]"), Some((-32600, Value::Null)));
        assert_eq!(code(r#"{"jsonrpc":"2.0","params":{}}"#), Some((-32600, Value::Null)));
        assert_eq!(code(r#"{"jsonrpc":"2.0","id":7,"method":"$/x"}"#), Some((-32601, json!(7))));
        assert_eq!(code(r#"{"jsonrpc":"2.0","method":"$/cancelRequest","params":{"id":1}}"#), None);
        assert_eq!(code(r#"{"jsonrpc":"2.0","id":1,"method":"initialize","params":{}}"#), None);
        assert_eq!(code(r#"{"jsonrpc":"2.0","id":1,"result":null}"#), None);
    }

    /// A request is pending from when it is read until its answer passes;
    /// notifications and the server's own requests are not.
    #[test]
    fn requests_are_pending_until_answered() {
        let pending = Pending::default();
        let hover = br#"{"jsonrpc":"2.0","id":7,"method":"textDocument/hover","params":{}}"#;
        let changed = br#"{"jsonrpc":"2.0","method":"textDocument/didChange","params":{}}"#;
        for body in [&hover[..], &changed[..]] {
            if let Some(id) = check(body).expect("well-formed") {
                pending.read(&id);
            }
        }
        assert_eq!(pending.lock().keys().collect::<Vec<_>>(), ["7"]);
        pending.answered(br#"{"jsonrpc":"2.0","id":1,"method":"workspace/inlayHint/refresh"}"#);
        pending.answered(br#"{"jsonrpc":"2.0","id":8,"result":null}"#);
        assert_eq!(pending.lock().len(), 1);
        pending.answered(br#"{"jsonrpc":"2.0","result":{"contents":"G01"},"id":7}"#);
        assert!(pending.lock().is_empty());
    }

    /// A request ends once its answer is written, not before.
    #[tokio::test]
    async fn a_request_ends_after_its_answer_is_written() {
        let pending = Pending::default();
        pending.read(&json!(7));
        let answer = framed(br#"{"jsonrpc":"2.0","id":7,"result":null}"#);
        let pending_at_write = std::cell::RefCell::new(Vec::new());
        let write = |frame: &[u8]| {
            assert_eq!(frame, answer);
            pending_at_write.borrow_mut().push(pending.lock().len());
            Ok(())
        };
        forward_output(&answer[..], write, pending.clone()).await.expect("forwarded");
        assert_eq!(*pending_at_write.borrow(), [1]);
        assert!(pending.lock().is_empty());
    }
}
