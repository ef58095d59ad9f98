//! Cooperative cancellation of long core calls (Ctrl-C from Python).
//!
//! A long kernel takes a `&Cancel` and looks at it between units of work that each take well under
//! a second (a τ row, a block chunk, a lag): `cancel.is_cancelled()` to stop early, and
//! `cancel.check()?` once after its parallel loops, so that a call that stopped early returns
//! [`CoreError::Cancelled`] and never a partly filled result. The flag is only read, never part of
//! the arithmetic: a call that is not cancelled gives the same bits as one without the flag.
//!
//! [`run_in_pool_interruptible`] runs such a kernel on its own rayon pool off the calling thread,
//! while the calling thread polls (in Python: for a pending signal) and sets the flag when told to.

use crate::allan::build_pool;
use crate::error::{CoreError, Result};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Duration;

/// A shared "stop now" flag: set once by the caller, read by the workers.
#[derive(Debug, Default)]
pub struct Cancel {
    flag: AtomicBool,
}

impl Cancel {
    /// A flag that is not set.
    pub const fn new() -> Self {
        Cancel {
            flag: AtomicBool::new(false),
        }
    }

    /// Asks every worker that looks at this flag to stop.
    pub fn cancel(&self) {
        // Relaxed is enough: the flag carries no data, and the final `check` of a kernel runs after
        // its parallel loops joined, so it sees any value a worker saw.
        self.flag.store(true, Ordering::Relaxed);
    }

    /// Whether the flag is set: one load, cheap enough to call per chunk of work.
    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// `Err(CoreError::Cancelled)` if the flag is set.
    #[inline]
    pub fn check(&self) -> Result<()> {
        if self.is_cancelled() {
            Err(CoreError::Cancelled)
        } else {
            Ok(())
        }
    }
}

/// Sets `done` and wakes the polling thread when dropped: also when the job panics.
struct WakeOnDrop<'a> {
    done: &'a AtomicBool,
    caller: std::thread::Thread,
}

impl Drop for WakeOnDrop<'_> {
    fn drop(&mut self) {
        self.done.store(true, Ordering::Release);
        self.caller.unpark();
    }
}

/// Runs `job` in a rayon pool of `workers` threads (0: rayon's default), while the calling thread
/// calls `poll` every `poll_every`. When `poll` returns an error, the flag passed to `job` is set,
/// the workers are waited for, and that error is returned (`Err(e)`); otherwise the job's own
/// result comes back as `Ok(result)`. A panic in the job is resumed on the caller.
///
/// The job runs on a pool thread (as with `ThreadPool::install`), the calling thread only waits and
/// polls: it sleeps between polls and is woken as soon as the job ends, so a short call costs no
/// more than with [`run_in_pool`](crate::run_in_pool).
pub fn run_in_pool_interruptible<R: Send, E>(
    workers: usize,
    poll_every: Duration,
    job: impl FnOnce(&Cancel) -> Result<R> + Send,
    mut poll: impl FnMut() -> std::result::Result<(), E>,
) -> std::result::Result<Result<R>, E> {
    let pool = match build_pool(workers) {
        Ok(p) => p,
        Err(e) => return Ok(Err(e)),
    };
    let cancel = Cancel::new();
    let done = AtomicBool::new(false);
    let slot: Mutex<Option<Result<R>>> = Mutex::new(None);
    let mut interrupted = None;
    // The scope ends only when the job has ended (and resumes its panic, if any).
    pool.in_place_scope(|s| {
        let (cancel, done, slot) = (&cancel, &done, &slot);
        let caller = std::thread::current();
        s.spawn(move |_| {
            let _wake = WakeOnDrop { done, caller };
            let r = job(cancel);
            if let Ok(mut guard) = slot.lock() {
                *guard = Some(r);
            }
        });
        while !done.load(Ordering::Acquire) {
            std::thread::park_timeout(poll_every);
            if done.load(Ordering::Acquire) {
                break;
            }
            if let Err(e) = poll() {
                cancel.cancel();
                interrupted = Some(e);
                break;
            }
        }
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    let result = slot.into_inner().ok().flatten();
    Ok(result.expect("the job ran to its end without panicking, so it stored its result"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    /// A job that runs until cancelled (or 30 s), checking the flag every millisecond.
    fn endless(cancel: &Cancel) -> Result<u32> {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(30) {
            if cancel.is_cancelled() {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        cancel.check()?;
        Ok(1)
    }

    #[test]
    fn interrupt_stops_the_job_promptly() {
        let start = Instant::now();
        let mut polls = 0;
        let r = run_in_pool_interruptible(2, Duration::from_millis(10), endless, || {
            polls += 1;
            if start.elapsed() > Duration::from_millis(100) {
                Err("interrupted")
            } else {
                Ok(())
            }
        });
        assert_eq!(r, Err("interrupted"));
        assert!(polls >= 2, "polled {polls} times");
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "{:?}",
            start.elapsed()
        );
    }

    #[test]
    fn quiet_poll_returns_the_result() {
        let r = run_in_pool_interruptible(
            1,
            Duration::from_millis(1),
            |c: &Cancel| {
                std::thread::sleep(Duration::from_millis(20));
                c.check()?;
                Ok(7)
            },
            || Ok::<(), ()>(()),
        );
        assert_eq!(r, Ok(Ok(7)));
    }

    #[test]
    fn core_errors_pass_through() {
        let r = run_in_pool_interruptible(
            1,
            Duration::from_millis(5),
            |_: &Cancel| -> Result<()> { Err(CoreError::InvalidParameter("bad".into())) },
            || Ok::<(), ()>(()),
        );
        assert_eq!(r, Ok(Err(CoreError::InvalidParameter("bad".into()))));
    }

    #[test]
    fn a_panic_in_the_job_reaches_the_caller() {
        let r = std::panic::catch_unwind(|| {
            run_in_pool_interruptible(
                2,
                Duration::from_millis(5),
                |_: &Cancel| -> Result<()> { panic!("boom") },
                || Ok::<(), ()>(()),
            )
        });
        assert!(r.is_err());
    }

    #[test]
    fn a_cancelled_flag_is_an_error() {
        let c = Cancel::new();
        assert_eq!(c.check(), Ok(()));
        c.cancel();
        assert!(c.is_cancelled());
        assert_eq!(c.check(), Err(CoreError::Cancelled));
    }
}
