//! What a Python law returns: three values `(f, df_du, df_ddu)`, each a float array of the
//! samples' length or one number. Integers and floats are taken; a complex, string, boolean,
//! object or masked value is refused with the reason (numpy would drop an imaginary part or
//! a mask without a word).

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyFloat;

/// Whether `law` gives, called with three floats, bit for bit what it gives for arrays of
/// one sample. Then the time-domain reference and the Floquet analysis, which evaluate one
/// sample at a time, call it with floats: numpy's arithmetic on a number costs a tenth of
/// that on an array. A law that needs arrays (`len(u)`, `u.shape`) keeps arrays. An
/// interruption (Ctrl-C) during the check is the error.
pub fn takes_floats(py: Python<'_>, law: &Bound<'_, PyAny>) -> PyResult<bool> {
    let points = [(0.0, 1e-3, 1e-2), (2.0, -0.3, 0.5), (4.0, 1.7, -2.0)];
    for &(t, u, du) in &points {
        let with_floats = interrupted(py, law.call1((t, u, du)))?;
        let with_arrays = interrupted(
            py,
            law.call1((
                PyArray1::from_slice(py, &[t]),
                PyArray1::from_slice(py, &[u]),
                PyArray1::from_slice(py, &[du]),
            )),
        )?;
        let a = with_floats.and_then(|r| three(py, &r, 1).ok());
        let b = with_arrays.and_then(|r| three(py, &r, 1).ok());
        match (a, b) {
            (Some(a), Some(b)) if (0..3).all(|j| a[j][0].to_bits() == b[j][0].to_bits()) => {}
            _ => return Ok(false),
        }
    }
    Ok(true)
}

/// A call's value, `None` where it raised an `Exception`; an interruption is the error.
fn interrupted<'py>(
    py: Python<'py>,
    r: PyResult<Bound<'py, PyAny>>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    match r {
        Err(e) if !e.is_instance_of::<pyo3::exceptions::PyException>(py) => Err(e),
        r => Ok(r.ok()),
    }
}

/// The three parts `(f, df_du, df_ddu)` of a law's return value, each of `n` samples.
pub fn three(
    py: Python<'_>,
    returned: &Bound<'_, PyAny>,
    n: usize,
) -> Result<[Vec<f64>; 3], String> {
    let type_name = |x: &Bound<'_, PyAny>| {
        x.get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default()
    };
    let parts: Vec<Bound<'_, PyAny>> = returned
        .try_iter()
        .and_then(|it| it.collect::<PyResult<Vec<_>>>())
        .ok()
        .filter(|p| p.len() == 3 && !returned.is_instance_of::<pyo3::types::PyDict>())
        .ok_or_else(|| {
            format!(
                "must return three values (f, df_du, df_ddu), got {}",
                type_name(returned)
            )
        })?;
    let what = ["f", "df_du", "df_ddu"];
    let mut output: [Vec<f64>; 3] = Default::default();
    for (j, part) in parts.iter().enumerate() {
        output[j] = samples(py, part, n).map_err(|reason| format!("{} {reason}", what[j]))?;
    }
    Ok(output)
}

/// The `n` values of one returned part: a float64 array of length `n`, an integer or float
/// array or sequence, or one number for all samples.
fn samples(py: Python<'_>, part: &Bound<'_, PyAny>, n: usize) -> Result<Vec<f64>, String> {
    if let Ok(x) = part.cast::<PyFloat>() {
        return Ok(vec![x.value(); n]);
    }
    if let Ok(a) = part.extract::<PyReadonlyArray1<'_, f64>>() {
        if !part.hasattr("mask").unwrap_or(false) {
            return of_length(a.as_array().iter().copied().collect(), n);
        }
    }
    let np = py.import("numpy").map_err(|e| e.to_string())?;
    if part.hasattr("mask").unwrap_or(false) {
        return Err("is a masked array: return plain values".into());
    }
    let raw = np
        .call_method1("asarray", (part,))
        .map_err(|e| format!("is not an array of numbers: {e}"))?;
    let kind: String = raw
        .getattr("dtype")
        .and_then(|d| d.getattr("kind"))
        .and_then(|k| k.extract())
        .map_err(|e| e.to_string())?;
    if kind != "f" && kind != "i" && kind != "u" {
        let dtype = raw
            .getattr("dtype")
            .map(|d| d.to_string())
            .unwrap_or_default();
        return Err(format!("must hold real numbers, got dtype {dtype}"));
    }
    let converted = raw
        .call_method1("astype", ("float64",))
        .map_err(|e| e.to_string())?;
    let ndim: usize = converted
        .getattr("ndim")
        .and_then(|d| d.extract())
        .map_err(|e| e.to_string())?;
    if ndim == 0 {
        let x: f64 = converted.extract().map_err(|e: PyErr| e.to_string())?;
        return Ok(vec![x; n]);
    }
    let array: PyReadonlyArray1<'_, f64> = converted
        .extract()
        .map_err(|_| "must be a one-dimensional array".to_string())?;
    of_length(array.as_array().iter().copied().collect(), n)
}

fn of_length(values: Vec<f64>, n: usize) -> Result<Vec<f64>, String> {
    if values.len() == n {
        Ok(values)
    } else {
        Err(format!("has {} values for {n} samples", values.len()))
    }
}
