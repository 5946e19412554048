//! Force laws written in Python: the element type `python` of a scene,
//! `{ type = "python", law = "name" }`, whose `name` is a vectorised Python function
//! `law(theta, u, du) -> (f, df_du, df_ddu)` given with the scene (`Scene(..., laws=...)`).
//!
//! The AFT calls it once per element and pass with numpy arrays of θ, u, u̇ (the
//! [`ForceLaw::force_batch`] and [`ForceLaw::derivatives_batch`] hooks); the force and the
//! derivatives of one pass come from one call (the second hook reuses the first's arrays
//! when its samples are the same). The time-domain reference and the Floquet analysis call
//! it with one sample at a time ([`returned::takes_floats`]).
//!
//! A law that raises, or returns something of the wrong length or a non-finite value, gives
//! NaN to the solver (which stops on it, never reporting it converged), and its failure goes
//! to the analysis's [`FailureSlot`], which stops a sweep at its next point: the analysis
//! then raises `LawError` naming the law, with the law's own exception as its cause (a
//! `KeyboardInterrupt` or `SystemExit` is raised as it is).

pub mod registry;
pub mod returned;

use crate::errors::LawError;
use numpy::PyArray1;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyTuple};
use registry::{user_name, FailureSlot, Registered};
use std::sync::{Arc, Mutex};

/// What a scene element of type `python` holds.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    /// The law's registry key (its name in the scene's `laws`, as the scene's documents
    /// carry it).
    law: String,
    /// Values of u where the law is not smooth (contact edges), for the Floquet analysis.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    kinks: Vec<f64>,
}

/// The arrays of the last call, reused when the derivatives of the same samples follow.
#[derive(Debug, Default)]
struct LastCall {
    input: [Vec<f64>; 3],
    output: [Vec<f64>; 3],
}

/// A force law evaluated by a Python function.
#[derive(Debug, serde::Deserialize)]
#[serde(try_from = "Spec")]
pub struct PythonLaw {
    key: String,
    kinks: Vec<f64>,
    law: Arc<Registered>,
    /// Where its failures go: the slot of the analysis that built it.
    slot: Arc<FailureSlot>,
    last: Mutex<LastCall>,
}

impl TryFrom<Spec> for PythonLaw {
    type Error = String;
    fn try_from(spec: Spec) -> Result<Self, String> {
        let law = registry::find(&spec.law).ok_or_else(|| {
            format!(
                "no Python law named `{}`: give it in the scene's `laws` (a dict of names and functions)",
                user_name(&spec.law)
            )
        })?;
        if let Some(k) = spec.kinks.iter().find(|k| !k.is_finite()) {
            return Err(format!("kinks must be finite, got {k}"));
        }
        let slot = registry::current_slot().unwrap_or_else(|| law.slot.clone());
        Ok(PythonLaw {
            key: spec.law,
            kinks: spec.kinks,
            law,
            slot,
            last: Mutex::default(),
        })
    }
}

impl serde::Serialize for PythonLaw {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Spec {
            law: user_name(&self.key).to_string(),
            kinks: self.kinks.clone(),
        }
        .serialize(s)
    }
}

impl PythonLaw {
    /// f, ∂f/∂u, ∂f/∂u̇ at the samples, into `out` (NaN and the failure recorded on error).
    ///
    /// The GIL is taken before the cache's lock on every thread (a thread waiting for the
    /// lock never holds the GIL another needs to release it), and the lock is not held
    /// while Python runs (a law may run an analysis of its own scene).
    fn evaluate(&self, theta: &[f64], u: &[f64], du: &[f64], want: Want, out: Out<'_>) {
        if self.slot.failed() {
            out.fill(f64::NAN);
            return;
        }
        crate::thread_state::keep();
        Python::attach(|py| {
            let lock = || self.last.lock().unwrap_or_else(|p| p.into_inner());
            {
                let last = lock();
                if last.input[0] == theta && last.input[1] == u && last.input[2] == du {
                    out.take(want, &last.output);
                    return;
                }
            }
            let called = if theta.len() == 1 && self.law.floats {
                self.call_floats(py, theta[0], u[0], du[0])
            } else {
                self.call(py, theta, u, du)
            };
            match called {
                Ok(output) => {
                    let mut last = lock();
                    out.take(want, &output);
                    last.output = output;
                    for (kept, given) in last.input.iter_mut().zip([theta, u, du]) {
                        kept.clear();
                        kept.extend_from_slice(given);
                    }
                }
                Err(e) => {
                    lock().input = Default::default();
                    self.slot.record(e);
                    out.fill(f64::NAN);
                }
            }
        });
    }

    /// One sample as floats: the common return of three floats read directly, anything
    /// else by [`PythonLaw::checked`].
    fn call_floats(&self, py: Python<'_>, theta: f64, u: f64, du: f64) -> PyResult<[Vec<f64>; 3]> {
        let returned = self.law.callable.bind(py).call1((theta, u, du));
        if let Ok(Ok(t)) = returned.as_ref().map(|r| r.cast::<PyTuple>()) {
            if t.len() == 3 {
                let mut floats = [f64::NAN; 3];
                for (j, x) in floats.iter_mut().enumerate() {
                    if let Ok(f) = t.get_item(j).and_then(|p| Ok(p.cast_into::<PyFloat>()?)) {
                        *x = f.value();
                    }
                }
                if floats.iter().all(|x| x.is_finite()) {
                    return Ok(floats.map(|x| vec![x]));
                }
            }
        }
        self.checked(py, returned, &[theta], &[u], &[du])
    }

    /// One call of the Python function with arrays, its three results checked.
    fn call(
        &self,
        py: Python<'_>,
        theta: &[f64],
        u: &[f64],
        du: &[f64],
    ) -> PyResult<[Vec<f64>; 3]> {
        let returned = self.law.callable.bind(py).call1((
            PyArray1::from_slice(py, theta),
            PyArray1::from_slice(py, u),
            PyArray1::from_slice(py, du),
        ));
        self.checked(py, returned, theta, u, du)
    }

    /// The three results of a call at the samples `theta`, `u`, `du`, checked: the law's
    /// exception as a `LawError` (an interruption as it is), or one naming what is wrong.
    fn checked(
        &self,
        py: Python<'_>,
        returned: PyResult<Bound<'_, PyAny>>,
        theta: &[f64],
        u: &[f64],
        du: &[f64],
    ) -> PyResult<[Vec<f64>; 3]> {
        let name = user_name(&self.key);
        let returned = returned.map_err(|e| {
            if !e.is_instance_of::<PyException>(py) {
                return e; // KeyboardInterrupt, SystemExit
            }
            let err = LawError::new_err(format!("Python law `{name}` raised: {e}"));
            err.set_cause(py, Some(e));
            err
        })?;
        let output = returned::three(py, &returned, theta.len())
            .map_err(|reason| LawError::new_err(format!("Python law `{name}`: {reason}")))?;
        let what = ["f", "df_du", "df_ddu"];
        for j in 0..3 {
            if let Some(i) = output[j].iter().position(|x| !x.is_finite()) {
                return Err(LawError::new_err(format!(
                    "Python law `{name}`: {} is {} at theta = {}, u = {}, du = {}",
                    what[j], output[j][i], theta[i], u[i], du[i]
                )));
            }
        }
        Ok(output)
    }
}

#[derive(Clone, Copy)]
enum Want {
    Force,
    Derivatives,
}

struct Out<'a> {
    force: &'a mut [f64],
    dfdu: &'a mut [f64],
    dfddu: &'a mut [f64],
}

impl Out<'_> {
    fn take(self, want: Want, output: &[Vec<f64>; 3]) {
        match want {
            Want::Force => self.force.copy_from_slice(&output[0]),
            Want::Derivatives => {
                self.dfdu.copy_from_slice(&output[1]);
                self.dfddu.copy_from_slice(&output[2]);
            }
        }
    }

    fn fill(self, x: f64) {
        self.force.fill(x);
        self.dfdu.fill(x);
        self.dfddu.fill(x);
    }
}
#[typetag::serde(name = "python")]
impl hbal::force::ForceLaw for PythonLaw {
    fn force(&self, theta: f64, u: f64, du: f64) -> f64 {
        let mut f = [0.0];
        self.force_batch(&[theta], &[u], &[du], &mut f);
        f[0]
    }

    fn force_batch(&self, theta: &[f64], u: &[f64], du: &[f64], out: &mut [f64]) {
        let out = Out {
            force: out,
            dfdu: &mut [],
            dfddu: &mut [],
        };
        self.evaluate(theta, u, du, Want::Force, out);
    }

    fn derivatives(&self, theta: f64, u: f64, du: f64) -> (f64, f64) {
        let (mut a, mut b) = ([0.0], [0.0]);
        self.derivatives_batch(&[theta], &[u], &[du], &mut a, &mut b);
        (a[0], b[0])
    }

    fn derivatives_batch(
        &self,
        theta: &[f64],
        u: &[f64],
        du: &[f64],
        dfdu: &mut [f64],
        dfddu: &mut [f64],
    ) {
        let out = Out {
            force: &mut [],
            dfdu,
            dfddu,
        };
        self.evaluate(theta, u, du, Want::Derivatives, out);
    }

    /// The library's default (the 64-point average of the linearisation at rest) in one call.
    fn linear_part(&self) -> hbal::force::LinearPart {
        const POINTS: usize = 64;
        let theta: Vec<f64> = (0..POINTS)
            .map(|j| std::f64::consts::TAU * j as f64 / POINTS as f64)
            .collect();
        let zero = vec![0.0; POINTS];
        let (mut f, mut k, mut d) = (zero.clone(), zero.clone(), zero.clone());
        self.force_batch(&theta, &zero, &zero, &mut f);
        self.derivatives_batch(&theta, &zero, &zero, &mut k, &mut d);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / POINTS as f64;
        hbal::force::LinearPart {
            stiffness: mean(&k),
            damping: mean(&d),
            offset: mean(&f),
        }
    }

    fn kinks(&self) -> Vec<f64> {
        self.kinks.clone()
    }
}
