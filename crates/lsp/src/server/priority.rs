//! The scheduling of background threads: the flow walk, the state
//! preparation and the cycle-time run take up to hundreds of milliseconds
//! on a large program, and an edit's or a request's threads must not wait
//! for a core behind them.

use ncc_analysis::interactive;

/// A background thread's nice value.
const NICE: i32 = 10;

/// The time slice a background thread asks for (Linux 6.12 and later):
/// longer than the kernel's default (at most 3 ms), so that a thread of a
/// request, which wakes with the default, preempts it at once. With equal
/// slices the running thread keeps the core until a timer tick, up to 4 ms
/// later, at every hand-over of the request, however low its priority.
/// Short enough that two background threads sharing a core take turns.
#[cfg(target_os = "linux")]
const SLICE_NS: u64 = 6_000_000;

/// Lowers the calling thread's priority and lengthens its time slice, and
/// makes its work give way to requests between blocks. Not the idle
/// scheduling class, which requests would preempt as well: a thread cannot
/// leave it without privileges, and a build running in the editor's
/// session starves it, so that the cycle-time hint would not come until
/// the build ends.
pub(super) fn background() {
    // Failing leaves the thread as it was.
    #[cfg(target_os = "linux")]
    if !lower_with_long_slice() {
        // On Linux the "process" priority is the calling thread's.
        let _ = rustix::process::setpriority_process(None, NICE);
    }
    interactive::run_in_background();
}

/// `sched_setattr` on the calling thread: nice [`NICE`], slice
/// [`SLICE_NS`] (older kernels ignore the slice). Whether it succeeded.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)] // The one system call neither std nor rustix wraps.
fn lower_with_long_slice() -> bool {
    let attr = libc::sched_attr {
        size: size_of::<libc::sched_attr>() as u32,
        sched_policy: libc::SCHED_OTHER as u32,
        sched_flags: 0,
        sched_nice: NICE,
        sched_priority: 0,
        sched_runtime: SLICE_NS,
        sched_deadline: 0,
        sched_period: 0,
    };
    // SAFETY: the kernel reads `attr.size` bytes of a live `sched_attr`;
    // thread 0 is the calling thread.
    unsafe { libc::syscall(libc::SYS_sched_setattr, 0, &raw const attr, 0) == 0 }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// A line of the calling thread's scheduler statistics.
    fn own_sched(field: &str) -> Option<u64> {
        let stats = std::fs::read_to_string("/proc/thread-self/sched").ok()?;
        let line = stats.lines().find(|line| line.split(':').next().is_some_and(|name| name.trim() == field))?;
        line.split(':').nth(1)?.trim().parse().ok()
    }

    fn kernel_version() -> (u32, u32) {
        let release = std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default();
        let mut numbers = release.split(['.', '-']).map(|part| part.trim().parse().unwrap_or(0));
        (numbers.next().unwrap_or(0), numbers.next().unwrap_or(0))
    }

    /// A background thread runs at nice 10 and, where the kernel takes a
    /// thread's own slice, with the long slice.
    #[test]
    fn a_background_thread_has_a_lower_priority_and_a_longer_slice() {
        std::thread::spawn(|| {
            let lengthened = lower_with_long_slice();
            assert_eq!(rustix::process::getpriority_process(None).ok(), Some(NICE));
            if lengthened && kernel_version() >= (6, 12) {
                assert_eq!(own_sched("se.slice"), Some(SLICE_NS));
            }
            // Idempotent, and the public entry point does the same.
            background();
            assert_eq!(rustix::process::getpriority_process(None).ok(), Some(NICE));
        })
        .join()
        .expect("the thread ends");
    }
}
