//! The laws of the live scenes, by registry key, and where a law's failure goes.
//!
//! A scene's documents given to the library name each Python law by a key unique to the
//! scene (`name#lawN`), so that the library finds the function wherever it builds the scene
//! again (a parameter sweep builds it at every value). A law's failure goes to the
//! [`FailureSlot`] of the analysis that runs it: each analysis of a scene with Python laws
//! builds its own copy of the scene inside a [`SlotScope`], whose slot the laws built there
//! take.

use hbal::continuation::Cancel;
use pyo3::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

/// The marker between a law's name and its build in a registry key.
pub const KEY_MARK: &str = "#law";

/// The first failure of a Python law in one analysis, and the sweep to stop on it.
#[derive(Debug, Default)]
pub struct FailureSlot {
    failure: Mutex<Option<PyErr>>,
    failed: AtomicBool,
    cancel: Mutex<Option<Cancel>>,
}

impl FailureSlot {
    /// Keeps the first failure and stops the analysis's sweep at its next point.
    pub fn record(&self, e: PyErr) {
        let mut slot = self.failure.lock().unwrap_or_else(|p| p.into_inner());
        if slot.is_none() {
            *slot = Some(e);
        }
        self.failed.store(true, Ordering::Relaxed);
        if let Some(c) = &*self.cancel.lock().unwrap_or_else(|p| p.into_inner()) {
            c.cancel();
        }
    }

    /// Whether a law failed in this analysis: its later calls give NaN at once, so that the
    /// solver's fallbacks end quickly.
    pub fn failed(&self) -> bool {
        self.failed.load(Ordering::Relaxed)
    }

    /// The failure, if a law failed (the slot is emptied).
    pub fn take(&self) -> Option<PyErr> {
        self.failure
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take()
    }

    /// The sweep a failure stops.
    pub fn stops(&self, cancel: &Cancel) {
        *self.cancel.lock().unwrap_or_else(|p| p.into_inner()) = Some(cancel.clone());
    }
}

/// A law as registered for a scene.
#[derive(Debug)]
pub struct Registered {
    pub callable: Py<PyAny>,
    /// The slot of the scene's own build (and of `check`).
    pub slot: Arc<FailureSlot>,
    /// One sample may be passed as three floats (see [`super::returned::takes_floats`]).
    pub floats: bool,
}

type Registry = HashMap<String, Arc<Registered>>;

fn lock() -> MutexGuard<'static, Registry> {
    static REGISTRY: OnceLock<Mutex<Registry>> = OnceLock::new();
    REGISTRY
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|p| p.into_inner())
}

/// Registers `law` under `key`.
pub fn register(key: String, law: Registered) {
    lock().insert(key, Arc::new(law));
}

/// The law under `key`.
pub fn find(key: &str) -> Option<Arc<Registered>> {
    lock().get(key).cloned()
}

/// Removes the laws under `keys`. They are dropped after the registry's lock is released:
/// dropping a function may free another scene, which unregisters its own laws.
pub fn unregister(keys: &[String]) {
    let removed: Vec<_> = {
        let mut map = lock();
        keys.iter().filter_map(|k| map.remove(k)).collect()
    };
    drop(removed);
}

/// The user's name of a registry key.
pub fn user_name(key: &str) -> &str {
    key.find(KEY_MARK).map_or(key, |at| &key[..at])
}

thread_local! {
    static CURRENT: RefCell<Option<Arc<FailureSlot>>> = const { RefCell::new(None) };
}

/// While it lives, the laws built on this thread report to its slot.
pub struct SlotScope {
    before: Option<Arc<FailureSlot>>,
}

impl SlotScope {
    pub fn enter(slot: Arc<FailureSlot>) -> Self {
        let before = CURRENT.with(|c| c.borrow_mut().replace(slot));
        SlotScope { before }
    }
}

impl Drop for SlotScope {
    fn drop(&mut self) {
        CURRENT.with(|c| *c.borrow_mut() = self.before.take());
    }
}

/// The slot of the analysis building on this thread, if any.
pub fn current_slot() -> Option<Arc<FailureSlot>> {
    CURRENT.with(|c| c.borrow().clone())
}
