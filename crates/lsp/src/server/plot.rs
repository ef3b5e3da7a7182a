//! The `ncc.plot` command (`workspace/executeCommand`): the picture
//! `ncc plot` draws, of an open document's current text, unsaved edits
//! included, for the editor's toolpath view.
//!
//! Arguments: the document's URI, then optionally `{ view }`, as `ncc
//! plot --view`: how a lathe's picture shows X (`"radius"` or
//! `"diameter"`, the default), a mill's the plane (`"top"`, the default) or
//! its three axes (`"iso"`). The answer is `{ svg, totalTimeS, findings,
//! view }`, `view` the one drawn. A run that stops on an error answers a `RequestFailed`
//! error whose message says where and why, with the picture of the run
//! up to there as its `data`.

use std::{path::PathBuf, sync::Arc};

use ncc_analysis::{Dialect, WorkspaceFiles};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use tower_lsp_server::{
    jsonrpc::{self, ErrorCode},
    ls_types::Uri,
};

use super::{Server, invalid_params};
use crate::{
    plot::{DEFAULT_MAX_MOVES, View},
    run::{Program, Progress, Ran},
};

/// The command's name.
pub(crate) const COMMAND: &str = "ncc.plot";

/// LSP's `RequestFailed`: the request was valid, the program cannot run.
const REQUEST_FAILED: i64 = -32803;

/// The answer, as the extension reads it.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Plotted {
    svg: String,
    /// Seconds, with the velocity model.
    total_time_s: f64,
    /// What the run did not run, and where it stopped.
    findings: Vec<Finding>,
    /// The view drawn.
    view: View,
}

/// The optional second argument.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Options {
    #[serde(default)]
    view: View,
}

#[derive(Serialize)]
struct Finding {
    /// Set when the finding is in another file than the document (a
    /// macrocycle file): that file's path.
    #[serde(skip_serializing_if = "Option::is_none")]
    file: Option<String>,
    /// Counted from 1.
    line: u32,
    message: String,
    stopped: bool,
}

/// What the run needs from the server's state, taken under its lock.
struct Job {
    text: Arc<String>,
    /// The called files as the editor has them.
    files: Option<WorkspaceFiles>,
    path: Option<PathBuf>,
    name: String,
    dialect: Dialect,
    config: Option<PathBuf>,
    view: View,
}

/// Runs the command: `arguments` is `[uri]` or `[uri, options]`.
pub(crate) async fn execute(server: &Server, arguments: Vec<Value>) -> jsonrpc::Result<Option<Value>> {
    let (uri, options) = match arguments.as_slice() {
        [Value::String(uri)] => (uri, None),
        [Value::String(uri), options] => (uri, Some(options)),
        _ => {
            return Err(invalid_params(format!(
                "{COMMAND} takes the document's URI, then optionally {{ \"view\": \"radius\" | \"diameter\" | \"top\" | \"iso\" }}"
            )));
        }
    };
    let uri =
        uri.parse::<Uri>().map_err(|error| invalid_params(format!("{COMMAND}: `{uri}` is not a URI: {error}")))?;
    let view = match options {
        Some(options) => {
            Options::deserialize(options)
                .map_err(|error| invalid_params(format!("{COMMAND}: the options {options}: {error}")))?
                .view
        }
        None => View::default(),
    };
    let job = {
        let state = server.state();
        let document = state
            .documents
            .get(&uri)
            .ok_or_else(|| invalid_params(format!("{COMMAND}: {} is not open", uri.as_str())))?;
        let path = uri.to_file_path().map(|path| path.into_owned());
        let name = path.as_ref().map_or_else(|| uri.as_str().to_owned(), |path| path.display().to_string());
        let config = state.workspaces.config_path(document.workspace).map(PathBuf::from);
        let files =
            state.workspaces.get(document.workspace).analysis().run_input(document.file).map(|input| input.files);
        Job { text: document.map.text.clone(), files, path, name, dialect: document.dialect, config, view }
    };
    // A run takes as long as the program's blocks; the blocking pool keeps
    // it off the threads that answer the other requests.
    let task = tokio::task::spawn_blocking(move || plot(job));
    match task.await {
        Ok(answer) => answer.map(Some),
        Err(join_error) => {
            tracing::error!("{COMMAND} failed: {join_error}");
            Err(jsonrpc::Error::internal_error())
        }
    }
}

fn plot(job: Job) -> jsonrpc::Result<Value> {
    // The text of our own, so that an edit during the run need not copy it.
    let text = Arc::unwrap_or_clone(job.text);
    let program = Program {
        path: job.path.as_deref(),
        name: job.name,
        text: &text,
        dialect: job.dialect,
        config: job.config.as_deref(),
        files: job.files.as_ref(),
    };
    let (ran, picture) =
        Ran::plotted(&program, nc_exec::run::DEFAULT_STEP_BUDGET, DEFAULT_MAX_MOVES, job.view, Progress::Hidden)
            .map_err(|error| jsonrpc::Error {
                code: ErrorCode::ServerError(REQUEST_FAILED),
                message: error.into(),
                data: None,
            })?;
    let findings = ran
        .findings()
        .map(|finding| Finding {
            file: (!finding.in_program).then(|| finding.file.to_owned()),
            line: finding.line,
            message: finding.message.to_owned(),
            stopped: finding.stopped,
        })
        .collect();
    let stop = match ran.stop() {
        Some(stop) => {
            let place = if stop.in_program { String::new() } else { format!("{} ", stop.file) };
            Some(format!("the run stopped at {place}line {}: {}", stop.line, stop.message))
        }
        // Nothing to draw: the run's one finding says why.
        None if !nc_exec::run::interprets(program.dialect) => ran.findings().next().map(|f| f.message.to_owned()),
        None => None,
    };
    let plotted = Plotted { svg: picture.svg, total_time_s: picture.total_time, findings, view: picture.view };
    let plotted = serde_json::to_value(plotted).map_err(|_| jsonrpc::Error::internal_error())?;
    match stop {
        Some(message) => Err(jsonrpc::Error {
            code: ErrorCode::ServerError(REQUEST_FAILED),
            message: message.into(),
            data: Some(plotted),
        }),
        None => Ok(plotted),
    }
}
