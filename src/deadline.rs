//! [`Deadline`]: the time limit of a whole run. Derivations, surface
//! grammars and reverse subdivision check it every so often (every few
//! thousand modules, loop iterations or rules, never per expression), and
//! stop with a message that names the limit and how to raise it.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Set by [`Deadline::stop_all`]: every deadline counts as passed.
static STOP_ALL: AtomicBool = AtomicBool::new(false);

/// The time limit of the `subgram` commands that derive, render,
/// subdivide, reverse or reconstruct (`--timeout SECONDS`; 0 for none).
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(600);

/// A moment after which a run stops, and the limit it was set from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Deadline {
    /// `None` when the limit is too far away to be an `Instant`: never.
    at: Option<Instant>,
    limit: Duration,
}

impl Deadline {
    /// `limit` from now.
    ///
    /// ```
    /// let d = subgram::Deadline::after(std::time::Duration::from_secs(600));
    /// assert!(!d.passed());
    /// assert!(d.message().contains("600 s"));
    /// ```
    pub fn after(limit: Duration) -> Deadline {
        Deadline {
            at: Instant::now().checked_add(limit),
            limit,
        }
    }

    /// The limit of a command line's `--timeout SECONDS`: none for 0.
    pub fn from_secs(seconds: f64) -> Option<Deadline> {
        let limit = Duration::try_from_secs_f64(seconds).ok()?;
        (!limit.is_zero()).then(|| Deadline::after(limit))
    }

    /// From `true` until called with `false`, every deadline of this
    /// process counts as passed, so that every run that has one stops at
    /// its next check, with a message that says it was stopped. The Python
    /// package calls it on Ctrl-C (a run there holds no signal of its own);
    /// the command line never does.
    pub fn stop_all(stop: bool) {
        STOP_ALL.store(stop, Ordering::SeqCst);
    }

    /// Whether [`Deadline::stop_all`] holds.
    #[inline]
    fn stopped() -> bool {
        STOP_ALL.load(Ordering::Relaxed)
    }

    /// The limit it was set from.
    pub fn limit(&self) -> Duration {
        self.limit
    }

    /// The time left, `None` once the deadline has passed (a deadline too
    /// far away to be an `Instant` leaves a day at a time).
    pub fn left(&self) -> Option<Duration> {
        if Self::stopped() {
            return None;
        }
        match self.at {
            None => Some(Duration::from_secs(86_400)),
            Some(at) => at
                .checked_duration_since(Instant::now())
                .filter(|d| !d.is_zero()),
        }
    }

    /// True once the deadline has passed.
    #[inline]
    pub fn passed(&self) -> bool {
        Self::stopped() || self.at.is_some_and(|at| Instant::now() >= at)
    }

    /// What a run that went past the deadline says.
    pub fn message(&self) -> String {
        if Self::stopped() {
            return "the run was stopped (interrupted)".to_string();
        }
        format!(
            "the run went past its time limit of {} s; raise it with --timeout SECONDS (0 for no limit)",
            self.limit.as_secs_f64()
        )
    }

    /// `Err(message)` once the deadline has passed.
    #[inline]
    pub fn check(&self) -> Result<(), String> {
        if self.passed() {
            Err(self.message())
        } else {
            Ok(())
        }
    }
}

/// `Err(message)` once `deadline`, if there is one, has passed.
#[inline]
pub(crate) fn check(deadline: Option<Deadline>) -> Result<(), String> {
    match deadline {
        Some(d) => d.check(),
        None => Ok(()),
    }
}

thread_local! {
    /// The deadline of the run this thread is doing, for the code that is
    /// reached through no argument: reading an input (a pipe waits under
    /// it) and writing the outputs (nothing is written once it passed).
    static CURRENT: std::cell::Cell<Option<Deadline>> = const { std::cell::Cell::new(None) };
}

/// While it lives, [`current`] on this thread is the deadline it was made
/// with; dropped, the one before comes back.
#[must_use = "the deadline holds only while the scope lives"]
pub(crate) struct Scope(Option<Deadline>);

/// Makes `deadline` the current one on this thread, for the scope's life.
pub(crate) fn scope(deadline: Option<Deadline>) -> Scope {
    Scope(CURRENT.with(|c| c.replace(deadline)))
}

impl Drop for Scope {
    fn drop(&mut self) {
        CURRENT.with(|c| c.set(self.0));
    }
}

/// Runs `work` with a deadline `limit` from now (none: no limit) as this
/// thread's current one: what it reads waits no longer (a pipe that nobody
/// writes to), and the runs it begins without a limit of their own take
/// this one.
pub fn within<T>(limit: Option<Duration>, work: impl FnOnce() -> T) -> T {
    let _scope = scope(limit.map(Deadline::after));
    work()
}

/// The deadline of the run this thread is doing, if it set one.
pub(crate) fn current() -> Option<Deadline> {
    CURRENT.with(|c| c.get())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scopes_nest_and_restore() {
        assert_eq!(current(), None);
        let a = Deadline::after(Duration::from_secs(5));
        let b = Deadline::after(Duration::from_secs(7));
        {
            let _outer = scope(Some(a));
            assert_eq!(current(), Some(a));
            {
                let _inner = scope(Some(b));
                assert_eq!(current(), Some(b));
            }
            assert_eq!(current(), Some(a));
        }
        assert_eq!(current(), None);
    }
}
