//! A Python thread state kept for the life of each Rust thread that calls Python laws.
//!
//! The library runs some of its work on threads of its own (a sweep's stability runs beside
//! its continuation). On such a thread every `Python::attach` would create a Python thread
//! state and delete it again on release (with its frame stack: an mmap and munmap per law
//! call, 10 µs). [`keep`] creates one on the thread's first call instead, releases the GIL
//! at once and keeps the state until the thread ends, so that later calls only take the
//! GIL. Python's own threads (the caller's) have a state already and are left alone.

use pyo3::ffi;
use std::cell::RefCell;

/// The kept state of this thread: released on the thread's exit.
struct Kept {
    saved: *mut ffi::PyThreadState,
    state: ffi::PyGILState_STATE,
}

impl Drop for Kept {
    fn drop(&mut self) {
        // SAFETY: `saved` is this thread's state, saved by `PyEval_SaveThread` in `keep`
        // and not used since; restoring it takes the GIL, and the release matching the
        // `PyGILState_Ensure` of `keep` deletes the state and releases the GIL. The threads
        // that keep one are the library's scoped threads, which end inside an analysis
        // call, while the interpreter runs.
        unsafe {
            if ffi::Py_IsInitialized() != 0 {
                ffi::PyEval_RestoreThread(self.saved);
                ffi::PyGILState_Release(self.state);
            }
        }
    }
}

thread_local! {
    static KEPT: RefCell<Option<Kept>> = const { RefCell::new(None) };
}

/// Makes sure this thread has a Python thread state that outlives the next call.
pub fn keep() {
    KEPT.with(|kept| {
        if kept.borrow().is_some() {
            return;
        }
        // SAFETY: these are the C API's documented calls for a thread Python did not
        // create: `PyGILState_Ensure` creates its state and takes the GIL, and
        // `PyEval_SaveThread` releases the GIL at once, keeping the state. A thread that
        // has a state already (Python's own) is left alone.
        unsafe {
            if ffi::Py_IsInitialized() == 0 || !ffi::PyGILState_GetThisThreadState().is_null() {
                return;
            }
            let state = ffi::PyGILState_Ensure();
            let saved = ffi::PyEval_SaveThread();
            *kept.borrow_mut() = Some(Kept { saved, state });
        }
    });
}
