//! [`Deadline`]: the time limit of a whole run. Derivations, surface
//! grammars and reverse subdivision check it every so often (every few
//! thousand modules, loop iterations or rules, never per expression), and
//! stop with a message that names the limit and how to raise it.

use std::time::{Duration, Instant};

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

    /// The limit it was set from.
    pub fn limit(&self) -> Duration {
        self.limit
    }

    /// True once the deadline has passed.
    #[inline]
    pub fn passed(&self) -> bool {
        self.at.is_some_and(|at| Instant::now() >= at)
    }

    /// What a run that went past the deadline says.
    pub fn message(&self) -> String {
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
