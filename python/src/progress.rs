//! Progress of a sweep to a Python callback `progress(fraction, stage)`, and Ctrl-C: at every
//! report the pending signals are checked (the GIL is taken for that moment); a
//! `KeyboardInterrupt`, or an exception of the callback, cancels the sweep at its next point
//! and is raised when the analysis returns.

use hbal::analysis::Observer;
use hbal::continuation::Cancel;
use pyo3::prelude::*;

/// An observer calling Python.
pub struct PyProgress {
    callback: Option<Py<PyAny>>,
    stage: String,
    pub cancel: Cancel,
    error: Option<PyErr>,
}

impl PyProgress {
    pub fn new(callback: Option<Py<PyAny>>) -> Self {
        Self {
            callback,
            stage: "sweep".into(),
            cancel: Cancel::new(),
            error: None,
        }
    }

    /// The interruption or the callback's exception, if there was one.
    pub fn raise(&mut self) -> PyResult<()> {
        self.error.take().map_or(Ok(()), Err)
    }

    fn report(&mut self, fraction: f64) {
        if self.error.is_some() {
            return;
        }
        let outcome = Python::attach(|py| {
            py.check_signals()?;
            if let Some(cb) = &self.callback {
                cb.call1(py, (fraction, self.stage.as_str()))?;
            }
            Ok::<_, PyErr>(())
        });
        if let Err(e) = outcome {
            self.error = Some(e);
            self.cancel.cancel();
        }
    }
}

impl Observer for PyProgress {
    fn progress(&mut self, fraction: f64) {
        self.report(fraction);
    }

    fn stage(&mut self, what: &str) {
        self.stage = what.to_string();
        self.report(0.0);
    }
}
