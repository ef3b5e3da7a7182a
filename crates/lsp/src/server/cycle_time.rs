//! The predicted cycle time of open programs, estimated in the background.
//!
//! An edit (or an open) leaves a job per document; one worker thread runs
//! the newest job of each document, so typing faster than a run takes
//! skips the versions in between, as a debounce would. A run is given up
//! when a newer version of its document waits, and a document whose last
//! run took long ([`LONG_WORK`]) waits for a pause in typing
//! ([`TYPING_PAUSE`]) before it runs: a run that the next key throws away
//! only holds a core the edits' diagnostics need. The run holds no
//! snapshot: it reads the text, the machine and the workspace's files
//! first, and an edit meanwhile only makes its result stale. A result is
//! kept only if the document is still at its version; then the client is
//! asked to refresh its inlay hints and code lenses. The worker runs at the
//! lower priority of the flow walk, and gives back the memory it freed once
//! typing pauses.

use std::{
    collections::HashMap,
    sync::{Arc, Condvar, Mutex},
    time::{Duration, Instant},
};

use ncc_analysis::{Cancelled, Estimate, TextRange, TextSize, interactive};
use tokio::sync::mpsc;
use tower_lsp_server::{Client, ls_types::Uri};

use super::{
    State, lock, priority,
    typing::{LONG_WORK, TYPING_PAUSE},
};

/// Blocks a run executes at most: a million steps hold a few hundred
/// megabytes while the model times them; a program that runs longer (a
/// jump loop without end) shows that its run stopped.
const STEP_BUDGET: usize = 1_000_000;

/// How long the worker goes without a job before it gives the memory its
/// runs freed back to the system: longer than a pause between keys, so
/// that the next edit's run reuses that memory rather than fresh pages the
/// system must clear for it (a large file's estimate fills megabytes).
const IDLE_BEFORE_RETURNING_MEMORY: Duration = Duration::from_millis(500);

/// A document's estimate, as the server keeps it.
#[derive(Debug, Default)]
pub(crate) struct Cycle {
    pub estimate: Option<Arc<Estimate>>,
    /// Where the text first differs from the estimate's text, after edits
    /// since its version: answers before it still hold.
    pub stale_from: Option<TextSize>,
}

impl Cycle {
    /// Notes an edit that wrote `written` (a range of the new text).
    pub fn edited(&mut self, written: TextRange) {
        let start = written.start();
        self.stale_from = Some(self.stale_from.map_or(start, |stale| stale.min(start)));
    }
}

/// The estimate a request may use, and up to where.
#[derive(Debug, Clone)]
pub(crate) struct View {
    pub estimate: Arc<Estimate>,
    pub valid_before: TextSize,
}

impl View {
    pub fn of(cycle: &Cycle) -> Option<View> {
        let estimate = cycle.estimate.clone()?;
        Some(View { estimate, valid_before: cycle.stale_from.unwrap_or(TextSize::from(u32::MAX)) })
    }

    /// Whether the estimate still holds for the block at `offset`.
    pub fn holds_at(&self, offset: TextSize) -> bool {
        self.estimate.block_at(offset).is_some_and(|block| block.range.end() <= self.valid_before)
    }
}

/// The newest version of each document to estimate, and how long each
/// open document's last complete run took (unless it ran through most of
/// the text) or the longest given up since.
#[derive(Debug, Default)]
struct Jobs {
    pending: HashMap<Uri, i32>,
    took: HashMap<Uri, Duration>,
}

/// The worker and its queue.
#[derive(Debug, Clone)]
pub(crate) struct Timer {
    jobs: Arc<(Mutex<Jobs>, Condvar)>,
}

impl Timer {
    /// Starts the worker; results go into `state`, and a message on
    /// `refresh` asks the client to show them.
    pub fn start(state: Arc<Mutex<State>>, refresh: mpsc::UnboundedSender<()>) -> Timer {
        let timer = Timer { jobs: Arc::default() };
        let jobs = timer.jobs.clone();
        let spawned = std::thread::Builder::new().name("ncc-cycle-time".into()).spawn(move || {
            // Diagnostics and hovers of the edit come first: on two cores a
            // run at normal priority doubles their latency.
            priority::background();
            // Whether runs freed memory since it was last given back.
            let mut holding = false;
            loop {
                let (uri, version, took) = {
                    let (lock, ready) = &*jobs;
                    let mut guard = lock.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
                    loop {
                        if let Some(uri) = guard.pending.keys().next().cloned() {
                            let version = guard.pending.remove(&uri).expect("the key was just found");
                            let took = guard.took.get(&uri).copied();
                            break (uri, version, took);
                        }
                        if !holding {
                            guard = ready.wait(guard).unwrap_or_else(|poisoned| poisoned.into_inner());
                            continue;
                        }
                        let waited = ready.wait_timeout(guard, IDLE_BEFORE_RETURNING_MEMORY);
                        let (waiting, timeout) = waited.unwrap_or_else(|poisoned| poisoned.into_inner());
                        guard = waiting;
                        if timeout.timed_out() && guard.pending.is_empty() {
                            // Typing paused.
                            drop(guard);
                            crate::return_free_memory();
                            holding = false;
                            guard = lock.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
                        }
                    }
                };
                if took.is_some_and(|took| took >= LONG_WORK) {
                    let (lock, ready) = &*jobs;
                    let guard = lock.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
                    let (_guard, waited) = ready
                        .wait_timeout_while(guard, TYPING_PAUSE, |jobs| !jobs.pending.contains_key(&uri))
                        .unwrap_or_else(|poisoned| poisoned.into_inner());
                    if !waited.timed_out() {
                        // Typing goes on: the newer version is the job.
                        continue;
                    }
                }
                // A failed run must not end the worker: later edits may run.
                let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(&state, &jobs, &uri, version)));
                let (lock, _) = &*jobs;
                let mut guard = lock.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
                match ran {
                    Ok(Ran::Kept(run_took)) => {
                        match run_took {
                            Some(run_took) => guard.took.insert(uri, run_took),
                            None => guard.took.remove(&uri),
                        };
                        let _ = refresh.send(());
                    }
                    // At least as long as it ran.
                    Ok(Ran::GivenUp(ran)) => {
                        let known = guard.took.entry(uri).or_default();
                        *known = (*known).max(ran);
                    }
                    Ok(Ran::Nothing) => {}
                    Err(_) => tracing::error!("{} v{version}: estimating the cycle time failed", uri.as_str()),
                }
                holding = true;
                drop(guard);
            }
        });
        if let Err(error) = spawned {
            tracing::error!("cannot start the cycle-time thread: {error}");
        }
        timer
    }

    /// Asks for an estimate of `uri` at `version`, instead of any older one
    /// not yet started.
    pub fn request(&self, uri: Uri, version: i32) {
        let (lock, ready) = &*self.jobs;
        lock.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).pending.insert(uri, version);
        ready.notify_one();
    }

    pub fn forget(&self, uri: &Uri) {
        let (lock, _) = &*self.jobs;
        let mut jobs = lock.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        jobs.pending.remove(uri);
        jobs.took.remove(uri);
    }
}

/// What became of a job.
enum Ran {
    /// The estimate is the document's, after running this long, when that
    /// tells how long the next run takes.
    Kept(Option<Duration>),
    /// A newer version came after running this long.
    GivenUp(Duration),
    /// Nothing to run, or the result came too late.
    Nothing,
}

/// Estimates one version, given up when a newer one is asked for (typing
/// goes on: its result would be thrown away).
fn run(state: &Mutex<State>, jobs: &(Mutex<Jobs>, Condvar), uri: &Uri, version: i32) -> Ran {
    let (analysis, file, previous) = {
        let state = lock(state);
        let Some(document) = state.documents.get(uri).filter(|document| document.version == version) else {
            return Ran::Nothing;
        };
        let cycle = &document.cycle;
        (state.workspaces.get(document.workspace).analysis(), document.file, cycle.estimate.clone())
    };
    let started = Instant::now();
    // Read, then let go of the snapshot: the run may take a while.
    let Ok(input) = Cancelled::catch(|| analysis.run_input(file)) else { return Ran::Nothing };
    drop(analysis);
    let Some(input) = input else { return Ran::Nothing };
    // Another document changed, but none this program reads.
    if previous.as_ref().is_some_and(|previous| previous.holds_for(&input)) {
        return Ran::Nothing;
    }
    // Asked between blocks: the run gives way to requests there too.
    let newer = || {
        interactive::give_way();
        jobs.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).pending.contains_key(uri)
    };
    let Some(estimate) = input.estimate(previous.as_deref(), STEP_BUDGET, &newer) else {
        tracing::debug!("{} v{version}: cycle time given up for a newer version", uri.as_str());
        return Ran::GivenUp(started.elapsed());
    };
    let estimate = Arc::new(estimate);
    let rerun = &estimate.rerun;
    // A run through most of the text (a whole run, or one after edits all
    // over it) says nothing of the next one, which resumes from its estimate.
    let tells = usize::from(rerun.end - rerun.start) * 2 < input.text.len();
    drop(input);
    tracing::debug!(
        "{} v{version}: cycle time estimated in {:?}, running bytes {rerun:?}",
        uri.as_str(),
        started.elapsed()
    );
    let mut state = lock(state);
    match state.documents.get_mut(uri) {
        Some(document) if document.version == version => {
            document.cycle = Cycle { estimate: Some(estimate), stale_from: None };
            Ran::Kept(tells.then(|| started.elapsed()))
        }
        _ => Ran::Nothing,
    }
}

/// What the client said it can do with refresh requests.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Refresh {
    pub inlay_hints: bool,
    pub code_lenses: bool,
}

/// Asks the client to fetch inlay hints and code lenses again whenever an
/// estimate is ready (one request for several that came meanwhile).
pub(crate) async fn refresh(client: Client, state: Arc<Mutex<State>>, mut ready: mpsc::UnboundedReceiver<()>) {
    while ready.recv().await.is_some() {
        while ready.try_recv().is_ok() {}
        let can = lock(&state).refresh;
        if can.inlay_hints && client.inlay_hint_refresh().await.is_err() {
            tracing::debug!("the client refused to refresh inlay hints");
        }
        if can.code_lenses && client.code_lens_refresh().await.is_err() {
            tracing::debug!("the client refused to refresh code lenses");
        }
    }
}

#[cfg(test)]
mod tests {
    use std::str::FromStr;

    use super::*;

    #[test]
    fn a_closed_document_leaves_nothing_behind() {
        let timer = Timer { jobs: Arc::default() };
        let uri = Uri::from_str("file:///PART.MPF").unwrap();
        timer.request(uri.clone(), 3);
        timer.jobs.0.lock().unwrap().took.insert(uri.clone(), LONG_WORK);
        timer.forget(&uri);
        let jobs = timer.jobs.0.lock().unwrap();
        assert!(jobs.pending.is_empty() && jobs.took.is_empty(), "{jobs:?}");
    }
}
