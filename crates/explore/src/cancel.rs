//! Abandoning work nobody waits for: the app cancels a view's request when a newer one
//! supersedes it (a slider moved again), the server drops the request's future, and the
//! [`CancelOnDrop`] guard it held raises the flag the computation polls.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A flag a computation polls to stop early.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// The flag itself, for code that polls an `AtomicBool` (the renderer).
    pub fn flag(&self) -> &AtomicBool {
        &self.0
    }

    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// A guard that cancels this flag when dropped (unless [`CancelOnDrop::disarm`]ed).
    pub fn guard(&self) -> CancelOnDrop {
        CancelOnDrop(Some(self.clone()))
    }
}

/// Cancels its flag when dropped: held by a request's future, it stops the blocking work
/// of a request the client abandoned.
pub struct CancelOnDrop(Option<Cancel>);

impl CancelOnDrop {
    /// The work finished: dropping the guard no longer cancels anything.
    pub fn disarm(mut self) {
        self.0 = None;
    }
}

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if let Some(c) = &self.0 {
            c.cancel();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dropped_guard_cancels_and_a_disarmed_one_does_not() {
        let c = Cancel::default();
        c.guard().disarm();
        assert!(!c.is_cancelled());
        drop(c.guard());
        assert!(c.is_cancelled());
    }
}
