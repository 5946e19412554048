//! Force laws written in Python: the element type `python` of a scene,
//! `{ type = "python", law = "name" }`, whose `name` is a vectorised Python function
//! `law(theta, u, du) -> (f, df_du, df_ddu)` given with the scene (`Scene(..., laws=...)`).
//!
//! The AFT calls it once per element and pass with numpy arrays of θ, u, u̇ (the
//! [`ForceLaw::force_batch`] and [`ForceLaw::derivatives_batch`] hooks); the force and the
//! derivatives of one pass come from one call (the second hook reuses the first's arrays
//! when its samples are the same). Each of the three returned values is a float64 array of
//! the samples' length or a number for all of them. The time-domain reference and the
//! Floquet analysis call it with one sample at a time.
//!
//! A law that raises, or returns something of the wrong length or a non-finite value, gives
//! NaN to the solver (which stops on it, never reporting it converged), and its failure is
//! kept in the scene's [`FailureSlot`]: the analysis then raises `LawError` naming the law,
//! with the law's own exception as its cause.

use crate::errors::LawError;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyTuple};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// The first failure of any Python law of one scene.
#[derive(Debug, Default)]
pub struct FailureSlot(Mutex<Option<PyErr>>);

impl FailureSlot {
    fn record(&self, e: PyErr) {
        let mut slot = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if slot.is_none() {
            *slot = Some(e);
        }
    }

    /// The failure, if a law failed (the slot is emptied).
    pub fn take(&self) -> Option<PyErr> {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).take()
    }
}

/// A law as registered for a scene: the callable and the scene's failure slot.
#[derive(Debug)]
pub struct Registered {
    pub callable: Py<PyAny>,
    pub slot: Arc<FailureSlot>,
    /// One sample may be passed as three floats (see [`takes_floats`]).
    pub floats: bool,
}

/// Whether `law` gives, called with three floats, bit for bit what it gives for arrays of
/// one sample. Then the time-domain reference and the Floquet analysis, which evaluate one
/// sample at a time, call it with floats: numpy's arithmetic on a number costs a tenth of
/// that on an array. A law that needs arrays (`len(u)`, `u.shape`) keeps arrays.
pub fn takes_floats(py: Python<'_>, law: &Bound<'_, PyAny>) -> bool {
    let points = [(0.0, 1e-3, 1e-2), (2.0, -0.3, 0.5), (4.0, 1.7, -2.0)];
    points.iter().all(|&(t, u, du)| {
        let with_floats = law
            .call1((t, u, du))
            .ok()
            .and_then(|r| three(py, &r, 1).ok());
        let with_arrays = law
            .call1((
                PyArray1::from_slice(py, &[t]),
                PyArray1::from_slice(py, &[u]),
                PyArray1::from_slice(py, &[du]),
            ))
            .ok()
            .and_then(|r| three(py, &r, 1).ok());
        match (with_floats, with_arrays) {
            (Some(a), Some(b)) => (0..3).all(|j| a[j][0].to_bits() == b[j][0].to_bits()),
            _ => false,
        }
    })
}

/// The three parts `(f, df_du, df_ddu)` of a law's return value, each of `n` samples.
fn three(py: Python<'_>, returned: &Bound<'_, PyAny>, n: usize) -> Result<[Vec<f64>; 3], String> {
    let parts: Vec<Bound<'_, PyAny>> = returned
        .try_iter()
        .and_then(|it| it.collect::<PyResult<Vec<_>>>())
        .ok()
        .filter(|p| p.len() == 3)
        .ok_or_else(|| {
            format!(
                "must return three values (f, df_du, df_ddu), got {}",
                returned
                    .get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            )
        })?;
    let what = ["f", "df_du", "df_ddu"];
    let mut output: [Vec<f64>; 3] = Default::default();
    for (j, part) in parts.iter().enumerate() {
        output[j] = samples(py, part, n).map_err(|reason| format!("{} {reason}", what[j]))?;
    }
    Ok(output)
}

/// Laws by registry key (`name#n`, unique per scene handle): the scene documents given to
/// the library carry these keys, so that a law is found wherever the library builds the
/// scene again (a parameter sweep builds it at every value).
fn registry() -> &'static Mutex<HashMap<String, Arc<Registered>>> {
    static REGISTRY: OnceLock<Mutex<HashMap<String, Arc<Registered>>>> = OnceLock::new();
    REGISTRY.get_or_init(Default::default)
}

/// Registers `law` under `key`.
pub fn register(key: String, law: Registered) {
    lock().insert(key, Arc::new(law));
}

/// Removes the laws under `keys` (the scene handle is gone).
pub fn unregister(keys: &[String]) {
    let mut map = lock();
    for k in keys {
        map.remove(k);
    }
}

fn lock() -> std::sync::MutexGuard<'static, HashMap<String, Arc<Registered>>> {
    registry().lock().unwrap_or_else(|p| p.into_inner())
}

/// The user's name of a registry key.
pub fn user_name(key: &str) -> &str {
    key.split('#').next().unwrap_or(key)
}

/// What a scene element of type `python` holds.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    /// The law's name in the scene's `laws`.
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
    last: Mutex<LastCall>,
}

impl TryFrom<Spec> for PythonLaw {
    type Error = String;
    fn try_from(spec: Spec) -> Result<Self, String> {
        let law = lock().get(&spec.law).cloned().ok_or_else(|| {
            format!(
                "no Python law named `{}`: give it in the scene's `laws` (a dict of names and functions)",
                user_name(&spec.law)
            )
        })?;
        if let Some(k) = spec.kinks.iter().find(|k| !k.is_finite()) {
            return Err(format!("kinks must be finite, got {k}"));
        }
        Ok(PythonLaw {
            key: spec.law,
            kinks: spec.kinks,
            law,
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
    /// The GIL is taken before the cache's lock, on every thread: a thread waiting for the
    /// lock never holds the GIL another thread needs to release the lock.
    fn evaluate(&self, theta: &[f64], u: &[f64], du: &[f64], want: Want, out: Out<'_>) {
        crate::thread_state::keep();
        Python::attach(|py| {
            let mut last = self.last.lock().unwrap_or_else(|p| p.into_inner());
            let same = last.input[0] == theta && last.input[1] == u && last.input[2] == du;
            if !same {
                let called = if theta.len() == 1 && self.law.floats {
                    self.call_floats(py, theta[0], u[0], du[0], &mut last.output)
                } else {
                    self.call(py, theta, u, du)
                        .map(|output| last.output = output)
                };
                if let Err(e) = called {
                    last.input = Default::default();
                    self.law.slot.record(e);
                    out.fill(f64::NAN);
                    return;
                }
                for (kept, given) in last.input.iter_mut().zip([theta, u, du]) {
                    kept.clear();
                    kept.extend_from_slice(given);
                }
            }
            match want {
                Want::Force => out.force.copy_from_slice(&last.output[0]),
                Want::Derivatives => {
                    out.dfdu.copy_from_slice(&last.output[1]);
                    out.dfddu.copy_from_slice(&last.output[2]);
                }
            }
        });
    }

    /// One sample as floats: the common return of three floats read without allocating,
    /// anything else by [`PythonLaw::call`]'s checks.
    fn call_floats(
        &self,
        py: Python<'_>,
        theta: f64,
        u: f64,
        du: f64,
        output: &mut [Vec<f64>; 3],
    ) -> PyResult<()> {
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
                    for (o, x) in output.iter_mut().zip(floats) {
                        o.clear();
                        o.push(x);
                    }
                    return Ok(());
                }
            }
        }
        *output = self.checked(py, returned, &[theta], &[u], &[du])?;
        Ok(())
    }

    /// One call of the Python function, its three results checked.
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
    /// exception, or a `LawError` naming what is wrong.
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
            let err = LawError::new_err(format!("Python law `{name}` raised: {e}"));
            err.set_cause(py, Some(e));
            err
        })?;
        let output = three(py, &returned, theta.len())
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

/// The `n` values of one returned part: a float64 array of length `n`, another array or
/// sequence numpy converts to one, or one number for all samples.
fn samples(py: Python<'_>, part: &Bound<'_, PyAny>, n: usize) -> Result<Vec<f64>, String> {
    if let Ok(x) = part.cast::<PyFloat>() {
        return Ok(vec![x.value(); n]);
    }
    let array: PyReadonlyArray1<'_, f64> = match part.extract() {
        Ok(a) => a,
        Err(_) => {
            let np = py.import("numpy").map_err(|e| e.to_string())?;
            let converted = np
                .call_method1("asarray", (part, "float64"))
                .map_err(|e| format!("is not a float array: {e}"))?;
            if converted
                .getattr("ndim")
                .and_then(|d| d.extract::<usize>())
                .ok()
                == Some(0)
            {
                let x: f64 = converted.extract().map_err(|e: PyErr| e.to_string())?;
                return Ok(vec![x; n]);
            }
            converted
                .extract()
                .map_err(|_| "must be a one-dimensional array".to_string())?
        }
    };
    let view = array.as_array();
    if view.len() != n {
        return Err(format!("has {} values for {n} samples", view.len()));
    }
    Ok(view.iter().copied().collect())
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
