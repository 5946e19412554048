//! An analysis's record, made when Python first reads it: [`Record`] holds the library's
//! typed result and builds its serde form (what `hbal ... --json` prints) on the first
//! `to_python()`. A solve returns at once; what is read pays for the conversion.

use crate::value::to_python;
use hbal::analysis as an;
use pyo3::prelude::*;
use serde_json::Value;
use std::sync::{Arc, Mutex};

/// An analysis whose JSON record can be built.
pub trait ToRecord: Send + Sync {
    fn record(&self) -> Value;
}

macro_rules! by_to_json {
    ($($t:ty),*) => {$(
        impl ToRecord for $t {
            fn record(&self) -> Value {
                self.to_json()
            }
        }
    )*};
}
by_to_json!(
    an::SolveAnalysis,
    an::SweepAnalysis,
    an::ParameterSweepAnalysis,
    an::ModesAnalysis,
    an::CompareAnalysis
);

macro_rules! by_serde {
    ($($t:ty),*) => {$(
        impl ToRecord for $t {
            fn record(&self) -> Value {
                serde_json::to_value(self).unwrap_or_else(|e| serde_json::json!({ "error": e.to_string() }))
            }
        }
    )*};
}
by_serde!(an::TorusSolveAnalysis, an::TorusSweepAnalysis);

/// The analysis, until its record is built.
enum State {
    Pending(Box<dyn ToRecord>),
    Built(Arc<Value>),
}

/// The record of one analysis.
#[pyclass(frozen, module = "hbal._hbal")]
pub struct Record(Mutex<State>);

impl Record {
    pub fn new(analysis: impl ToRecord + 'static) -> Self {
        Record(Mutex::new(State::Pending(Box::new(analysis))))
    }
}

#[pymethods]
impl Record {
    /// The record as new Python objects. It is built on the first call (the analysis is
    /// dropped then). The lock is held only while Rust builds it, never while Python runs
    /// (the conversion may run a finaliser that lets the GIL go to a second reader).
    fn to_python<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let value = {
            let mut state = self.0.lock().unwrap_or_else(|p| p.into_inner());
            let built = match std::mem::replace(&mut *state, State::Built(Arc::default())) {
                State::Pending(analysis) => Arc::new(analysis.record()),
                State::Built(value) => value,
            };
            *state = State::Built(built.clone());
            built
        };
        to_python(py, &value)
    }
}
