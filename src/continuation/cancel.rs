//! Stopping a long analysis from outside: a [`Cancel`] token the caller keeps a clone of and
//! sets (from a Ctrl-C handler, another thread, a Python binding); a sweep checks it after
//! every point and ends with [`BranchStop::Cancelled`](super::BranchStop::Cancelled), its
//! points so far kept.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A shared cancellation flag; [`Cancel::default`] is one nobody can set.
///
/// ```
/// use hbal::continuation::Cancel;
/// let token = Cancel::new();
/// let held = token.clone();
/// assert!(!token.is_cancelled());
/// held.cancel();
/// assert!(token.is_cancelled());
/// assert!(!Cancel::default().is_cancelled());
/// ```
#[derive(Debug, Clone, Default)]
pub struct Cancel(Option<Arc<AtomicBool>>);

impl Cancel {
    /// A token that [`cancel`](Self::cancel) on any of its clones sets.
    pub fn new() -> Self {
        Self(Some(Arc::new(AtomicBool::new(false))))
    }

    /// Asks every analysis holding this token (or a clone) to stop at its next point.
    pub fn cancel(&self) {
        if let Some(flag) = &self.0 {
            flag.store(true, Ordering::Relaxed);
        }
    }

    /// `true` once [`cancel`](Self::cancel) was called on this token or a clone.
    pub fn is_cancelled(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }
}

/// Two tokens are equal when they share one flag (or neither has one).
impl PartialEq for Cancel {
    fn eq(&self, other: &Self) -> bool {
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        }
    }
}
