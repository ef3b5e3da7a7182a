//! Background work that the next key would throw away waits for a pause in
//! typing. On a large file the cycle-time run after a jump and the flow walk
//! take longer than the time between two keys; started after each key,
//! they only hold a core that the newest edit's diagnostics and its
//! cycle-time run need.

use std::{
    sync::{Arc, Mutex},
    time::Duration,
};

use ncc_analysis::Analysis;
use tower_lsp_server::ls_types::Uri;

use super::{State, lock, priority};

/// Work this long is not started while typing goes on: two keys come
/// closer together.
pub(crate) const LONG_WORK: Duration = Duration::from_millis(50);

/// How long a document whose work is long waits without an edit before
/// the work starts: shorter than a human's pause between keys.
pub(crate) const TYPING_PAUSE: Duration = Duration::from_millis(40);

/// Runs `walk` on the snapshot of `uri` at `version`: at once on `analysis`
/// when the document's last walk took less than [`LONG_WORK`]; otherwise
/// on a new snapshot after a pause in typing, and not at all when an edit
/// came meanwhile.
///
/// The wait is on a thread of its own and the calling thread goes on to
/// end: a thread's allocator keeps the pages it freed until it allocates
/// again or ends, and while typing a dozen threads would wait at once, each
/// with the pages of its edit's diagnostics. The snapshot is let go of
/// while waiting, since an edit waits until every snapshot is dropped
/// (holding the state's lock: it is taken here only without one).
pub(super) fn walk_when_typing_pauses(
    state: Arc<Mutex<State>>,
    uri: Uri,
    version: i32,
    last_walk: Duration,
    analysis: Analysis,
    walk: impl FnOnce(Analysis) + Send + 'static,
) {
    if last_walk < LONG_WORK {
        return walk(analysis);
    }
    drop(analysis);
    let waiting = std::thread::Builder::new().name("ncc-flow-walk".into()).spawn(move || {
        priority::background();
        std::thread::sleep(TYPING_PAUSE);
        let analysis = {
            let state = lock(&state);
            let Some(document) = state.documents.get(&uri).filter(|document| document.version == version) else {
                return;
            };
            state.workspaces.get(document.workspace).analysis()
        };
        walk(analysis);
    });
    if let Err(error) = waiting {
        tracing::error!("cannot start a thread for the flow walk: {error}");
    }
}

#[cfg(test)]
mod tests {
    use std::{str::FromStr, sync::mpsc, time::Instant};

    use super::*;
    use crate::server::workspace::Workspaces;

    /// A flow walk waits for a pause only after a long one, on a thread of
    /// its own while the caller goes on, lets go of the state meanwhile,
    /// and does not start when an edit came.
    #[test]
    fn a_flow_walk_after_a_long_one_waits_for_a_pause_in_typing() {
        let uri = Uri::from_str("file:///tmp/PART.MPF").unwrap();
        let mut state = State { workspaces: Workspaces::new(None), ..State::default() };
        assert!(state.open(uri.clone(), "G0 X1\nM30\n".into(), 1).is_empty());
        let state = Arc::new(Mutex::new(state));
        let snapshot = || {
            let state = lock(&state);
            state.workspaces.get(state.documents[&uri].workspace).analysis()
        };
        // Where and when each walk ran; the channel closes when a walk
        // is dropped without running.
        let walk_after_pause = |last_walk: Duration| {
            let (ran, runs) = mpsc::channel();
            let walk = move |_: Analysis| {
                let _ = ran.send((std::thread::current().name().map(str::to_owned), Instant::now()));
            };
            walk_when_typing_pauses(state.clone(), uri.clone(), 1, last_walk, snapshot(), walk);
            runs
        };

        let started = Instant::now();
        let runs = walk_after_pause(LONG_WORK);
        assert!(started.elapsed() < TYPING_PAUSE, "the caller does not wait");
        // The lock is free while it waits: no edit comes, and it walks.
        drop(lock(&state));
        let (thread, ran) = runs.recv().expect("the walk runs");
        assert_eq!(thread.as_deref(), Some("ncc-flow-walk"));
        assert!(ran - started >= TYPING_PAUSE);

        lock(&state).documents.get_mut(&uri).unwrap().version = 2;
        assert!(walk_after_pause(LONG_WORK).recv().is_err(), "version 2 came");
        // A short walk runs at once on the calling thread, without looking
        // for newer versions.
        let (thread, _) = walk_after_pause(LONG_WORK / 2).try_recv().expect("the walk ran");
        assert_eq!(thread, std::thread::current().name().map(str::to_owned));
    }
}
