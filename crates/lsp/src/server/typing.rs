//! Background work that the next key would throw away waits for a pause in
//! typing. On a large file the cycle-time run after a jump and the flow walk
//! take longer than the time between two keys; started after each key,
//! they only hold a core that the newest edit's diagnostics and its
//! cycle-time run need.

use std::{sync::Mutex, time::Duration};

use ncc_analysis::Analysis;
use tower_lsp_server::ls_types::Uri;

use super::{State, lock};

/// Work this long is not started while typing goes on: two keys come
/// closer together.
pub(crate) const LONG_WORK: Duration = Duration::from_millis(50);

/// How long a document whose work is long waits without an edit before
/// the work starts: shorter than a human's pause between keys.
pub(crate) const TYPING_PAUSE: Duration = Duration::from_millis(40);

/// The snapshot the flow walk of `uri` at `version` reads: `analysis` when
/// its last walk took less than [`LONG_WORK`]; otherwise a new one after a
/// pause in typing, and none when an edit came meanwhile. The snapshot is
/// let go of while waiting, since an edit waits until every snapshot is
/// dropped (holding the state's lock: it is taken here only without one).
pub(super) fn flow_walk_snapshot(
    state: &Mutex<State>,
    uri: &Uri,
    version: i32,
    last_walk: Duration,
    analysis: Analysis,
) -> Option<Analysis> {
    if last_walk < LONG_WORK {
        return Some(analysis);
    }
    drop(analysis);
    std::thread::sleep(TYPING_PAUSE);
    let state = lock(state);
    let document = state.documents.get(uri).filter(|document| document.version == version)?;
    Some(state.workspaces.get(document.workspace).analysis())
}

#[cfg(test)]
mod tests {
    use std::{str::FromStr, time::Instant};

    use super::*;
    use crate::server::workspace::Workspaces;

    /// A flow walk waits for a pause only after a long one, lets go of the
    /// state meanwhile, and does not start when an edit came.
    #[test]
    fn a_flow_walk_after_a_long_one_waits_for_a_pause_in_typing() {
        let uri = Uri::from_str("file:///tmp/PART.MPF").unwrap();
        let mut state = State { workspaces: Workspaces::new(None), ..State::default() };
        assert!(state.open(uri.clone(), "G0 X1\nM30\n".into(), 1).is_empty());
        let state = Mutex::new(state);
        let snapshot = || {
            let state = lock(&state);
            state.workspaces.get(state.documents[&uri].workspace).analysis()
        };

        let started = Instant::now();
        // The lock is free while it waits: no edit comes, and it walks.
        assert!(flow_walk_snapshot(&state, &uri, 1, LONG_WORK, snapshot()).is_some());
        assert!(started.elapsed() >= TYPING_PAUSE);

        lock(&state).documents.get_mut(&uri).unwrap().version = 2;
        assert!(flow_walk_snapshot(&state, &uri, 1, LONG_WORK, snapshot()).is_none(), "version 2 came");
        // A short walk starts at once, without looking for newer versions.
        assert!(flow_walk_snapshot(&state, &uri, 1, LONG_WORK / 2, snapshot()).is_some());
    }
}
