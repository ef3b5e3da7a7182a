//! Requests first: background work (the flow walk, preparing states, the
//! cycle-time run) gives way, between two blocks, to a request the editor
//! waits for, so that the request has the cores to itself. On a machine
//! with two cores and two background threads, a request's threads
//! otherwise wait behind them at each hand-over, however low their
//! priority.

use std::{
    cell::Cell,
    sync::{
        Condvar, Mutex,
        atomic::{AtomicU64, AtomicUsize, Ordering},
    },
    time::Duration,
};

/// Requests in progress.
static IN_FLIGHT: AtomicUsize = AtomicUsize::new(0);
/// Requests begun, ever: background work gives way to each once.
static BEGUN: AtomicU64 = AtomicU64::new(0);
/// Notified when the last request in progress ends.
static ENDED: (Mutex<()>, Condvar) = (Mutex::new(()), Condvar::new());

/// The longest a background thread waits for requests: one may wait for
/// something the thread is computing.
const LONGEST_PAUSE: Duration = Duration::from_millis(5);

/// Calls of [`give_way`] between two yields of a background thread's core.
/// The walks call it at every block, so they yield every fraction of a
/// millisecond; the cycle-time run asks every 1,024 blocks, so it yields
/// about once in a long run (a yield costs a thread the rest of its time
/// slice). A request's thread that wakes may have to wait for the core
/// before it can even say it is there: the kernel's fair scheduler leaves a
/// thread that ran a lot lately behind a lower-priority one until the next
/// tick (4 ms).
const CALLS_PER_YIELD: u32 = 128;

thread_local! {
    static BACKGROUND: Cell<bool> = const { Cell::new(false) };
    /// The requests begun when this thread last gave way.
    static GIVEN_WAY_TO: Cell<u64> = const { Cell::new(0) };
    /// Calls since this thread last yielded its core.
    static SINCE_YIELD: Cell<u32> = const { Cell::new(0) };
}

/// A request the editor waits for, while it lives.
#[must_use]
#[derive(Debug)]
pub struct Request(());

impl Request {
    pub fn begin() -> Request {
        BEGUN.fetch_add(1, Ordering::Relaxed);
        IN_FLIGHT.fetch_add(1, Ordering::AcqRel);
        Request(())
    }
}

impl Drop for Request {
    fn drop(&mut self) {
        if IN_FLIGHT.fetch_sub(1, Ordering::AcqRel) == 1 {
            // Under the lock, so that a thread about to wait sees the count
            // or the notification.
            drop(ENDED.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner()));
            ENDED.1.notify_all();
        }
    }
}

/// Where a long walk may stop between two blocks: an edit waiting to
/// change the inputs cancels it, a request makes it give way.
pub(crate) fn between_blocks(db: &dyn crate::db::Db) {
    db.unwind_if_revision_cancelled();
    give_way();
}

/// Makes the calling thread's work give way to requests.
pub fn run_in_background() {
    BACKGROUND.set(true);
}

/// Runs `work` without giving way: it holds what a request may need (a
/// lock), and lets go for requests by itself.
pub(crate) fn without_giving_way<T>(work: impl FnOnce() -> T) -> T {
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            BACKGROUND.set(self.0);
        }
    }
    let _restore = Restore(BACKGROUND.replace(false));
    work()
}

/// On a background thread: yields the core every [`CALLS_PER_YIELD`]
/// calls, and while requests are in progress that it has not given way to
/// yet, waits until they end (at most [`LONGEST_PAUSE`]).
pub fn give_way() {
    if !BACKGROUND.get() {
        return;
    }
    if due_to_yield() {
        std::thread::yield_now();
    }
    if IN_FLIGHT.load(Ordering::Acquire) == 0 {
        return;
    }
    let begun = BEGUN.load(Ordering::Relaxed);
    if GIVEN_WAY_TO.get() == begun {
        return;
    }
    GIVEN_WAY_TO.set(begun);
    let guard = ENDED.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let waited = ENDED.1.wait_timeout_while(guard, LONGEST_PAUSE, |_| IN_FLIGHT.load(Ordering::Acquire) > 0);
    drop(waited.unwrap_or_else(|poisoned| poisoned.into_inner()));
}

/// Counts a call of a background thread; true once every
/// [`CALLS_PER_YIELD`].
fn due_to_yield() -> bool {
    let since = SINCE_YIELD.get() + 1;
    let due = since == CALLS_PER_YIELD;
    SINCE_YIELD.set(if due { 0 } else { since });
    due
}

#[cfg(test)]
mod tests {
    use std::time::Instant;

    use super::*;

    /// A background thread waits while a request is in progress, once per
    /// request and at most the longest pause; other threads never wait.
    #[test]
    fn background_work_gives_way_to_a_request_once() {
        let request = Request::begin();
        let started = Instant::now();
        give_way();
        assert!(started.elapsed() < LONGEST_PAUSE, "not a background thread");
        let waited = std::thread::spawn(|| {
            run_in_background();
            let started = Instant::now();
            give_way();
            let first = started.elapsed();
            let started = Instant::now();
            give_way();
            (first, started.elapsed())
        })
        .join()
        .expect("the thread ends");
        assert!(waited.0 >= LONGEST_PAUSE && waited.1 < LONGEST_PAUSE, "{waited:?}");
        drop(request);
        let ended = std::thread::spawn(|| {
            run_in_background();
            let started = Instant::now();
            give_way();
            started.elapsed()
        });
        assert!(ended.join().expect("the thread ends") < LONGEST_PAUSE);
    }

    /// Only a background thread counts calls, and it yields at every
    /// [`CALLS_PER_YIELD`]th.
    #[test]
    fn a_background_thread_yields_once_every_so_many_calls() {
        std::thread::spawn(|| {
            (0..3 * CALLS_PER_YIELD).for_each(|_| give_way());
            assert_eq!(SINCE_YIELD.get(), 0, "not a background thread");
            run_in_background();
            (1..CALLS_PER_YIELD).for_each(|_| give_way());
            assert_eq!(SINCE_YIELD.get(), CALLS_PER_YIELD - 1);
            give_way();
            assert_eq!(SINCE_YIELD.get(), 0, "yielded");
        })
        .join()
        .expect("the thread ends");
    }
}
