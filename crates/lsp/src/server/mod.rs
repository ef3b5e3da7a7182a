//! `ncc lsp`: the language server.
//!
//! Edits are applied to the analysis host synchronously, in the order they
//! arrive, before the handler first awaits (so tower-lsp-server's
//! concurrent dispatch cannot reorder them). Every question runs on a
//! snapshot on tokio's blocking pool; an edit cancels the snapshots still
//! computing (salsa unwinds them), and their requests answer
//! `ContentModified`. No handler waits for a reply from the client.
//!
//! Diagnostics are pushed in two steps per version: the findings that need
//! no flow walk as soon as the edited chunk is checked (with the previous
//! flow findings moved along with the edit), then the complete set when
//! the flow walk is done — unless a newer edit came first. Where the walk
//! takes long, it waits for a pause in typing (`typing.rs`).
//!
//! The predicted cycle time (`cycle_time.rs`) is estimated on a thread of
//! its own after each edit; inlay hints, a code lens and hover show it.

mod convert;
mod cycle_time;
mod frames;
mod handlers;
mod plot;
mod priority;
mod semantic;
mod typing;
mod workspace;

use std::{
    collections::HashMap,
    path::PathBuf,
    process::ExitCode,
    sync::{
        Arc, Mutex, MutexGuard,
        atomic::{AtomicBool, Ordering},
    },
    time::{Duration, Instant},
};

use ncc_analysis::{Analysis, Cancelled, CycleTimeHints, Diagnostic, Dialect, FileId, Findings, TextRange, TextSize};
use tokio::sync::mpsc;
use tower_lsp_server::{
    Client, LanguageServer, LspService,
    jsonrpc::{self, ErrorCode},
    ls_types::{self as lsp, Uri},
};

use tracing_subscriber::{filter::Targets, layer::SubscriberExt, util::SubscriberInitExt};

use self::{
    convert::LineMap,
    workspace::{Opened, Workspaces},
};

/// How much the server logs to stderr.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub(crate) enum LogLevel {
    Error,
    Warn,
    Info,
    Debug,
    Trace,
}

/// Serves the protocol; `dialect`, when given, is every document's.
pub(crate) fn run(log_level: LogLevel, dialect: Option<Dialect>) -> ExitCode {
    let level = match log_level {
        LogLevel::Error => tracing::Level::ERROR,
        LogLevel::Warn => tracing::Level::WARN,
        LogLevel::Info => tracing::Level::INFO,
        LogLevel::Debug => tracing::Level::DEBUG,
        LogLevel::Trace => tracing::Level::TRACE,
    };
    // The server's own events and the protocol layer's at the chosen level;
    // the database's bookkeeping only when something goes wrong.
    let filter = Targets::new()
        .with_target(env!("CARGO_CRATE_NAME"), level)
        .with_target("tower_lsp_server", level)
        .with_default(tracing::Level::WARN);
    tracing_subscriber::registry()
        .with(tracing_subscriber::fmt::layer().with_writer(std::io::stderr).with_ansi(false))
        .with(filter)
        .init();
    without_huge_pages();
    let runtime = match tokio::runtime::Builder::new_multi_thread().enable_all().build() {
        Ok(runtime) => runtime,
        Err(error) => {
            eprintln!("ncc lsp: cannot start the runtime: {error}");
            return ExitCode::from(2);
        }
    };
    let shut_down = Arc::new(AtomicBool::new(false));
    let flag = shut_down.clone();
    runtime.block_on(async move {
        let (service, socket) = LspService::new(move |client| Server::new(client, flag, dialect));
        // The protocol layer talks to in-memory pipes; the frames guard sits
        // between them and stdio.
        let (server_input, guarded_input) = tokio::io::duplex(1 << 16);
        let (server_output, server_frames) = tokio::io::duplex(1 << 16);
        let pending = frames::Pending::default();
        // Stdin and stdout each have a thread of their own that reads or
        // writes them directly: a message crosses one thread fewer each way
        // than through the runtime's tasks and blocking pool.
        let handle = tokio::runtime::Handle::current();
        let (reading, writing) = (handle.clone(), pending.clone());
        let spawned = std::thread::Builder::new().name("ncc-stdin".into()).spawn(move || {
            let stdin = frames::Blocking(std::io::stdin());
            reading.block_on(frames::guard_input(stdin, guarded_input, frames::write_stdout, pending))
        });
        let forward = std::thread::Builder::new()
            .name("ncc-stdout".into())
            .spawn(move || handle.block_on(frames::forward_output(server_frames, frames::write_stdout, writing)));
        if let Err(error) = spawned.as_ref().and(forward.as_ref()) {
            tracing::error!("cannot start the threads that read and write stdio: {error}");
            return;
        }
        tower_lsp_server::Server::new(server_input, server_output, socket).serve(service).await;
        // Stdin may never close (a client that sent `exit`): its thread
        // ends with the process. Everything the server wrote reaches stdout.
        if let Ok(forward) = forward {
            let _ = tokio::task::spawn_blocking(move || forward.join()).await;
        }
    });
    // Blocking tasks still computing are abandoned: their snapshots answer
    // nobody now.
    runtime.shutdown_background();
    // The protocol's rule: exit after shutdown is success, otherwise not.
    if shut_down.load(Ordering::SeqCst) { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}

/// An open document.
#[derive(Debug)]
struct Document {
    workspace: usize,
    /// The dialect it is read in.
    dialect: Dialect,
    file: FileId,
    version: i32,
    map: LineMap,
    /// The flow findings last computed, moved along with later edits until
    /// they are computed again.
    flow: Findings,
    /// How long the last flow walk took, or at least took when an edit
    /// cancelled it.
    walk_took: Duration,
    cycle: cycle_time::Cycle,
}

#[derive(Debug, Default)]
struct State {
    workspaces: Workspaces,
    documents: HashMap<Uri, Document>,
    /// `ncc.cycleTime.inlayHints`.
    cycle_hints: CycleTimeHints,
    refresh: cycle_time::Refresh,
}

impl State {
    /// Opens a document; returns what went wrong reading its project.
    fn open(&mut self, uri: Uri, text: String, version: i32) -> Vec<String> {
        let Opened { index: workspace, dialect, file, errors } = self.workspaces.open(&uri, text);
        let map = LineMap::new(self.workspaces.get(workspace).analysis().text(file));
        let (flow, walk_took, cycle) = Default::default();
        self.documents.insert(uri, Document { workspace, dialect, file, version, map, flow, walk_took, cycle });
        errors
    }
}

#[derive(Debug)]
pub(crate) struct Server {
    client: Client,
    state: Arc<Mutex<State>>,
    shut_down: Arc<AtomicBool>,
    publisher: mpsc::UnboundedSender<Publication>,
    timer: cycle_time::Timer,
    /// Asks the client to refresh what shows the cycle time.
    refresh: mpsc::UnboundedSender<()>,
}

/// Diagnostics of one version of a document, to send.
type Publication = (Uri, Vec<lsp::Diagnostic>, i32);

/// Sends diagnostics in the order they were computed, never an older
/// version's after a newer one's. Blocking threads hand their results over
/// without waiting, so a snapshot is never held while the output is busy
/// (an edit waiting for that snapshot would block the runtime).
async fn publish(client: Client, mut publications: mpsc::UnboundedReceiver<Publication>) {
    let mut sent: HashMap<Uri, i32> = HashMap::new();
    while let Some((uri, diagnostics, version)) = publications.recv().await {
        if sent.get(&uri).is_some_and(|&newest| newest > version) {
            continue;
        }
        sent.insert(uri.clone(), version);
        client.publish_diagnostics(uri, diagnostics, Some(version)).await;
    }
}

/// A request's view of a document: a snapshot and what converts positions.
struct Snapshot {
    analysis: Analysis,
    file: FileId,
    map: LineMap,
    uri: Uri,
    /// The cycle-time estimate, where it holds.
    cycle: Option<cycle_time::View>,
    cycle_hints: CycleTimeHints,
}

impl Server {
    fn new(client: Client, shut_down: Arc<AtomicBool>, dialect: Option<Dialect>) -> Server {
        let (publisher, publications) = mpsc::unbounded_channel();
        tokio::spawn(publish(client.clone(), publications));
        let state = Arc::new(Mutex::new(State { workspaces: Workspaces::new(dialect), ..State::default() }));
        let (refresh, refreshes) = mpsc::unbounded_channel();
        tokio::spawn(cycle_time::refresh(client.clone(), state.clone(), refreshes));
        let timer = cycle_time::Timer::start(state.clone(), refresh.clone());
        Server { client, state, shut_down, publisher, timer, refresh }
    }

    fn state(&self) -> MutexGuard<'_, State> {
        lock(&self.state)
    }

    /// A snapshot of `uri`'s document.
    fn snapshot(&self, uri: &Uri) -> jsonrpc::Result<Snapshot> {
        let state = self.state();
        let document =
            state.documents.get(uri).ok_or_else(|| invalid_params(format!("{} is not open", uri.as_str())))?;
        Ok(Snapshot {
            analysis: state.workspaces.get(document.workspace).analysis(),
            file: document.file,
            map: document.map.clone(),
            uri: uri.clone(),
            cycle: cycle_time::View::of(&document.cycle),
            cycle_hints: state.cycle_hints,
        })
    }

    /// Runs `query` on a snapshot of `uri`'s document on the blocking pool.
    async fn query<T: Send + 'static>(
        &self,
        uri: &Uri,
        query: impl FnOnce(&Snapshot) -> T + Send + 'static,
    ) -> jsonrpc::Result<T> {
        let snapshot = self.snapshot(uri)?;
        // On this thread, which hands the runtime's other tasks to another
        // while it answers: the answer waits for no thread to wake up.
        let answered = tokio::task::block_in_place(move || {
            let answer = std::panic::AssertUnwindSafe(|| query(&snapshot));
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| Cancelled::catch(answer)))
        });
        match answered {
            Ok(Ok(answer)) => Ok(answer),
            Ok(Err(_cancelled)) => Err(jsonrpc::Error {
                code: ErrorCode::ContentModified,
                message: "the document changed while answering".into(),
                data: None,
            }),
            Err(_panic) => {
                tracing::error!("request failed: the query panicked");
                Err(jsonrpc::Error::internal_error())
            }
        }
    }

    /// Pushes the document's diagnostics for its current version (local
    /// findings first, then the complete set) and prepares its modal
    /// states, so that a hover anywhere finds a checkpoint near it.
    ///
    /// After an edit, preparing mostly walks across the edit; it comes
    /// before the flow walk, which takes far longer. When the document was
    /// just `opened`, the states of the whole program are prepared on
    /// another thread while the local findings are computed (about as long,
    /// on the other core), and those wait for it: the document is ready,
    /// hover included, when its first diagnostics arrive.
    fn analyze(&self, uri: Uri, opened: bool) {
        // Positions, not the text: this thread outlives the next edit.
        let (analysis, file, version, positions, carried, last_walk) = {
            let state = self.state();
            let Some(document) = state.documents.get(&uri) else { return };
            let analysis = state.workspaces.get(document.workspace).analysis();
            let (positions, carried) = (document.map.positions(), document.flow.clone());
            (analysis, document.file, document.version, positions, carried, document.walk_took)
        };
        let publisher = self.publisher.clone();
        let state = self.state.clone();
        // The snapshots live only on these threads, so an edit waiting to
        // cancel them never waits for the async runtime. Threads of their
        // own, since they lower their priority for the long walks.
        let spawned = std::thread::Builder::new().name("ncc-diagnostics".into()).spawn(move || {
            let send = {
                let uri = uri.clone();
                move |diagnostics: Vec<Diagnostic>| {
                    let diagnostics = diagnostics.iter().map(|d| convert::diagnostic(&positions, &uri, d)).collect();
                    let _ = publisher.send((uri.clone(), diagnostics, version));
                }
            };
            let started = Instant::now();
            let prepare = |analysis: &Analysis| {
                let started = Instant::now();
                match Cancelled::catch(|| analysis.prepare_states(file)) {
                    Ok(()) => {
                        tracing::debug!("{} v{version}: states prepared in {:?}", uri.as_str(), started.elapsed())
                    }
                    Err(_) => tracing::debug!("{} v{version}: preparing states cancelled by an edit", uri.as_str()),
                }
            };
            let local = std::thread::scope(|scope| {
                if opened {
                    let analysis = analysis.clone();
                    let spawned = std::thread::Builder::new()
                        .name("ncc-states".into())
                        .spawn_scoped(scope, move || prepare(&analysis));
                    if let Err(error) = spawned {
                        tracing::error!("cannot start a thread preparing states: {error}");
                    }
                }
                Cancelled::catch(|| {
                    let local = analysis.local_findings(file);
                    let mut first = local.clone();
                    first.append(carried);
                    (analysis.limit(file, first), local)
                })
            });
            let Ok((first, local)) = local else { return };
            tracing::debug!("{} v{version}: local diagnostics in {:?}", uri.as_str(), started.elapsed());
            send(first);
            priority::background();
            if !opened {
                prepare(&analysis);
            }
            // A long walk waits until typing pauses: the next key would
            // cancel it, and the edit's cycle-time run needs the core.
            let (walk_state, walk_uri) = (state.clone(), uri.clone());
            let walk = move |analysis: Analysis| {
                let walk_started = Instant::now();
                let all = Cancelled::catch(|| {
                    let flow = analysis.flow_findings(file);
                    let mut all = local;
                    all.append(flow.clone());
                    (analysis.limit(file, all), flow)
                });
                // Dropped before taking the lock: the edit that cancelled
                // the walk holds the lock until every snapshot is dropped.
                drop(analysis);
                let walked = walk_started.elapsed();
                let mut guard = lock(&state);
                let Some(document) = guard.documents.get_mut(&uri) else { return };
                let Ok((all, flow)) = all else {
                    document.walk_took = document.walk_took.max(walked);
                    tracing::debug!("{} v{version}: flow walk cancelled by an edit", uri.as_str());
                    return;
                };
                tracing::debug!("{} v{version}: all diagnostics in {:?}", uri.as_str(), started.elapsed());
                if document.version != version {
                    return;
                }
                document.flow = flow;
                document.walk_took = walked;
                drop(guard);
                send(all);
                // The version's work is done: typing paused.
                crate::return_free_memory();
            };
            typing::walk_when_typing_pauses(walk_state, walk_uri, version, last_walk, analysis, walk);
        });
        if let Err(error) = spawned {
            tracing::error!("cannot start a diagnostics thread: {error}");
        }
    }
}

/// Transparent huge pages off for the server's process. mimalloc asks for
/// them on its arenas, and the kernel then keeps 2 MB for a page the
/// allocator holds a few small blocks in: a long session's resident memory
/// grows with the scatter of what it keeps, not with what it keeps.
fn without_huge_pages() {
    // Failing leaves the process as it was.
    #[cfg(target_os = "linux")]
    let _ = rustix::thread::disable_transparent_huge_pages(true);
}

/// A panic while holding the lock leaves consistent data (edits are
/// applied whole), so a poisoned lock is still usable.
fn lock(state: &Mutex<State>) -> MutexGuard<'_, State> {
    state.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn invalid_params(message: String) -> jsonrpc::Error {
    jsonrpc::Error { code: ErrorCode::InvalidParams, message: message.into(), data: None }
}

/// A request the server understood but refuses, with the reason for the
/// user (a rename to a name the control would not take): LSP's
/// `RequestFailed`, which the JSON-RPC crate does not name.
fn request_failed(message: String) -> jsonrpc::Error {
    jsonrpc::Error { code: ErrorCode::ServerError(-32803), message: message.into(), data: None }
}

/// The server's configuration from the client.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
struct InitializationOptions {
    /// The `ncc.toml` to use for every document, instead of finding one
    /// upwards from each document.
    config_file: Option<PathBuf>,
    #[serde(default)]
    cycle_time: CycleTimeSettings,
}

/// `ncc.cycleTime`: in the initialization options, and in the settings of
/// `workspace/didChangeConfiguration` (below `ncc`).
#[derive(Debug, Default, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
struct CycleTimeSettings {
    inlay_hints: Option<CycleTimeHints>,
}

impl CycleTimeSettings {
    /// The settings in a `didChangeConfiguration` payload, `{ "ncc": { … } }`
    /// or the section itself; `None` when it holds none.
    fn changed(settings: &serde_json::Value) -> Option<Result<CycleTimeSettings, serde_json::Error>> {
        let section = settings.get("ncc").unwrap_or(settings).get("cycleTime")?;
        Some(serde_json::from_value(section.clone()))
    }
}

impl LanguageServer for Server {
    async fn initialize(&self, params: lsp::InitializeParams) -> jsonrpc::Result<lsp::InitializeResult> {
        let options: InitializationOptions = match params.initialization_options {
            Some(value) => serde_json::from_value(value)
                .map_err(|error| invalid_params(format!("initializationOptions: {error}")))?,
            None => InitializationOptions::default(),
        };
        let roots: Vec<PathBuf> = params
            .workspace_folders
            .iter()
            .flatten()
            .filter_map(|folder| folder.uri.to_file_path().map(|p| p.into_owned()))
            .collect();
        #[allow(deprecated)] // Older clients send only `rootUri`.
        let roots = if roots.is_empty() {
            params.root_uri.iter().filter_map(|uri| uri.to_file_path().map(|p| p.into_owned())).collect()
        } else {
            roots
        };
        // Refresh requests only to a client that takes them.
        let workspace = params.capabilities.workspace.as_ref();
        let refresh = cycle_time::Refresh {
            inlay_hints: workspace.and_then(|w| w.inlay_hint.as_ref()?.refresh_support).unwrap_or(false),
            code_lenses: workspace.and_then(|w| w.code_lens.as_ref()?.refresh_support).unwrap_or(false),
        };
        let errors = {
            let mut state = self.state();
            state.workspaces.configure(options.config_file);
            state.cycle_hints = options.cycle_time.inlay_hints.unwrap_or_default();
            state.refresh = refresh;
            state.workspaces.load_roots(&roots)
        };
        for error in errors {
            self.client.show_message(lsp::MessageType::ERROR, error).await;
        }
        Ok(lsp::InitializeResult {
            capabilities: handlers::capabilities(),
            server_info: Some(server_info()),
            offset_encoding: None,
        })
    }

    async fn shutdown(&self) -> jsonrpc::Result<()> {
        self.shut_down.store(true, Ordering::SeqCst);
        Ok(())
    }

    async fn did_open(&self, params: lsp::DidOpenTextDocumentParams) {
        let document = params.text_document;
        let errors = self.state().open(document.uri.clone(), document.text, document.version);
        self.timer.request(document.uri.clone(), document.version);
        self.analyze(document.uri, true);
        for error in errors {
            self.client.show_message(lsp::MessageType::ERROR, error).await;
        }
    }

    async fn did_change(&self, params: lsp::DidChangeTextDocumentParams) {
        let uri = params.text_document.uri;
        {
            let started = Instant::now();
            let mut guard = self.state();
            let state = &mut *guard;
            let Some(document) = state.documents.get_mut(&uri) else {
                tracing::warn!("change of {} which is not open", uri.as_str());
                return;
            };
            let host = state.workspaces.host_mut(document.workspace);
            for change in &params.content_changes {
                let edit = document.map.edit(change);
                // The map lets go of the text, so that the edit can change it
                // in place.
                let before = std::mem::replace(&mut document.map, LineMap::new(Arc::default())).positions();
                host.apply_edit(document.file, &edit);
                document.map = LineMap::edited(&before, &edit, host.analysis().text(document.file));
                document.flow = std::mem::take(&mut document.flow).moved_through(&edit);
                document.cycle.edited(TextRange::at(edit.delete.start(), TextSize::of(&edit.insert)));
            }
            document.version = params.text_document.version;
            tracing::debug!("{} v{}: edits applied in {:?}", uri.as_str(), document.version, started.elapsed());
            self.timer.request(uri.clone(), document.version);
            // A macrocycle or cycle file the other programs of the
            // workspace call may have changed: their runs tell.
            let workspace = document.workspace;
            for (other, document) in &state.documents {
                if document.workspace == workspace && *other != uri {
                    self.timer.request(other.clone(), document.version);
                }
            }
        }
        self.analyze(uri, false);
    }

    async fn did_close(&self, params: lsp::DidCloseTextDocumentParams) {
        let uri = params.text_document.uri;
        {
            let mut state = self.state();
            if let Some(document) = state.documents.remove(&uri) {
                state.workspaces.close(document.workspace, &uri, document.file);
            }
        }
        self.timer.forget(&uri);
        crate::return_free_memory();
        self.client.publish_diagnostics(uri, Vec::new(), None).await;
    }

    async fn hover(&self, params: lsp::HoverParams) -> jsonrpc::Result<Option<lsp::Hover>> {
        let position = params.text_document_position_params;
        self.query(&position.text_document.uri, move |s| handlers::hover(s, position.position)).await
    }

    async fn goto_definition(
        &self,
        params: lsp::GotoDefinitionParams,
    ) -> jsonrpc::Result<Option<lsp::GotoDefinitionResponse>> {
        let position = params.text_document_position_params;
        let uri = position.text_document.uri.clone();
        let targets = self.query(&uri, move |s| handlers::definition(s, position.position)).await?;
        let state = self.state();
        let Some(workspace) = state.documents.get(&uri).map(|d| d.workspace) else { return Ok(None) };
        let mut addresses = state.workspaces.addresses(workspace);
        let links: Vec<_> = targets.into_iter().filter_map(|target| addresses.location_link(target)).collect();
        Ok((!links.is_empty()).then_some(lsp::GotoDefinitionResponse::Link(links)))
    }

    async fn completion(&self, params: lsp::CompletionParams) -> jsonrpc::Result<Option<lsp::CompletionResponse>> {
        let position = params.text_document_position;
        let items =
            self.query(&position.text_document.uri, move |s| handlers::completion(s, position.position)).await?;
        Ok(Some(lsp::CompletionResponse::Array(items)))
    }

    async fn formatting(&self, params: lsp::DocumentFormattingParams) -> jsonrpc::Result<Option<Vec<lsp::TextEdit>>> {
        self.query(&params.text_document.uri, |s| handlers::formatting(s, None)).await.map(Some)
    }

    async fn range_formatting(
        &self,
        params: lsp::DocumentRangeFormattingParams,
    ) -> jsonrpc::Result<Option<Vec<lsp::TextEdit>>> {
        self.query(&params.text_document.uri, move |s| handlers::formatting(s, Some(params.range))).await.map(Some)
    }

    async fn inlay_hint(&self, params: lsp::InlayHintParams) -> jsonrpc::Result<Option<Vec<lsp::InlayHint>>> {
        self.query(&params.text_document.uri, move |s| handlers::inlay_hints(s, params.range)).await.map(Some)
    }

    async fn code_lens(&self, params: lsp::CodeLensParams) -> jsonrpc::Result<Option<Vec<lsp::CodeLens>>> {
        self.query(&params.text_document.uri, handlers::code_lenses).await.map(Some)
    }

    async fn did_change_configuration(&self, params: lsp::DidChangeConfigurationParams) {
        match CycleTimeSettings::changed(&params.settings) {
            Some(Ok(settings)) => {
                let hints = settings.inlay_hints.unwrap_or_default();
                let changed = std::mem::replace(&mut self.state().cycle_hints, hints) != hints;
                if changed {
                    let _ = self.refresh.send(());
                }
            }
            Some(Err(error)) => tracing::warn!("ncc.cycleTime: {error}"),
            None => {}
        }
    }

    async fn references(&self, params: lsp::ReferenceParams) -> jsonrpc::Result<Option<Vec<lsp::Location>>> {
        let position = params.text_document_position;
        let uri = position.text_document.uri.clone();
        let include = params.context.include_declaration;
        let references = self.query(&uri, move |s| handlers::references(s, position.position, include)).await?;
        let state = self.state();
        let Some(workspace) = state.documents.get(&uri).map(|d| d.workspace) else { return Ok(None) };
        let mut addresses = state.workspaces.addresses(workspace);
        let locations = references
            .into_iter()
            .filter_map(|reference| addresses.location(reference.file, reference.range))
            .collect();
        Ok(Some(locations))
    }

    async fn prepare_rename(
        &self,
        params: lsp::TextDocumentPositionParams,
    ) -> jsonrpc::Result<Option<lsp::PrepareRenameResponse>> {
        let position = params.position;
        let answer = self.query(&params.text_document.uri, move |s| handlers::prepare_rename(s, position)).await?;
        answer.map(Some).map_err(request_failed)
    }

    async fn rename(&self, params: lsp::RenameParams) -> jsonrpc::Result<Option<lsp::WorkspaceEdit>> {
        let position = params.text_document_position;
        let (uri, new_name) = (position.text_document.uri.clone(), params.new_name);
        let renaming = self
            .query(&uri, move |s| handlers::rename(s, position.position, &new_name))
            .await?
            .map_err(request_failed)?;
        let state = self.state();
        let Some(workspace) = state.documents.get(&uri).map(|d| d.workspace) else { return Ok(None) };
        Ok(Some(state.workspaces.addresses(workspace).workspace_edit(&renaming)))
    }

    async fn signature_help(&self, params: lsp::SignatureHelpParams) -> jsonrpc::Result<Option<lsp::SignatureHelp>> {
        let position = params.text_document_position_params;
        self.query(&position.text_document.uri, move |s| handlers::signature_help(s, position.position)).await
    }

    async fn document_highlight(
        &self,
        params: lsp::DocumentHighlightParams,
    ) -> jsonrpc::Result<Option<Vec<lsp::DocumentHighlight>>> {
        let position = params.text_document_position_params;
        let highlights = self
            .query(&position.text_document.uri, move |s| {
                handlers::references(s, position.position, true)
                    .into_iter()
                    .filter(|reference| reference.file == s.file)
                    .map(|reference| lsp::DocumentHighlight {
                        range: s.map.range(reference.range),
                        kind: Some(if handlers::is_write(reference.kind) {
                            lsp::DocumentHighlightKind::WRITE
                        } else {
                            lsp::DocumentHighlightKind::READ
                        }),
                    })
                    .collect()
            })
            .await?;
        Ok(Some(highlights))
    }

    async fn document_symbol(
        &self,
        params: lsp::DocumentSymbolParams,
    ) -> jsonrpc::Result<Option<lsp::DocumentSymbolResponse>> {
        let symbols = self.query(&params.text_document.uri, handlers::document_symbols).await?;
        Ok(Some(lsp::DocumentSymbolResponse::Nested(symbols)))
    }

    async fn folding_range(&self, params: lsp::FoldingRangeParams) -> jsonrpc::Result<Option<Vec<lsp::FoldingRange>>> {
        self.query(&params.text_document.uri, handlers::folding_ranges).await.map(Some)
    }

    async fn semantic_tokens_full(
        &self,
        params: lsp::SemanticTokensParams,
    ) -> jsonrpc::Result<Option<lsp::SemanticTokensResult>> {
        let tokens = self.query(&params.text_document.uri, |s| handlers::semantic_tokens(s, None)).await?;
        Ok(Some(lsp::SemanticTokensResult::Tokens(tokens)))
    }

    async fn semantic_tokens_range(
        &self,
        params: lsp::SemanticTokensRangeParams,
    ) -> jsonrpc::Result<Option<lsp::SemanticTokensRangeResult>> {
        let range = params.range;
        let tokens = self.query(&params.text_document.uri, move |s| handlers::semantic_tokens(s, Some(range))).await?;
        Ok(Some(lsp::SemanticTokensRangeResult::Tokens(tokens)))
    }

    async fn code_action(&self, params: lsp::CodeActionParams) -> jsonrpc::Result<Option<lsp::CodeActionResponse>> {
        let uri = params.text_document.uri.clone();
        self.query(&uri, move |s| handlers::code_actions(s, params.range, &params.context)).await.map(Some)
    }

    async fn execute_command(&self, params: lsp::ExecuteCommandParams) -> jsonrpc::Result<Option<lsp::LSPAny>> {
        match params.command.as_str() {
            plot::COMMAND => plot::execute(self, params.arguments).await,
            command => Err(invalid_params(format!("unknown command `{command}`"))),
        }
    }
}

fn server_info() -> lsp::ServerInfo {
    lsp::ServerInfo { name: "ncc".into(), version: Some(env!("CARGO_PKG_VERSION").into()) }
}
