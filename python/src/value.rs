//! Scene documents and results between Python objects and `serde_json::Value`, number by
//! number (no text in between, so every float crosses bit for bit).
//!
//! Python → document: `dict` (string keys), `list`/`tuple`, `str`, `bool`, `int`, `float`,
//! `None`, and anything with `tolist()` (numpy arrays and scalars). A NaN or infinity, a
//! key that is not a string or an object of another type is an error naming its place
//! (`mass[1][0]`).

use crate::errors::InputError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Map, Number, Value};

/// The document of the Python object `obj`; `what` names it in errors (e.g. `scene`).
pub fn to_value(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Value> {
    let mut path = String::new();
    convert(obj, &mut path).map_err(|reason| {
        let at = if path.is_empty() {
            what.to_string()
        } else {
            format!("{what}: {path}")
        };
        InputError::new_err(format!("{at}: {reason}"))
    })
}

/// How deep a document may nest (a scene is a few levels deep; a cycle is infinitely).
const MAX_DEPTH: usize = 64;

/// Converts `obj`; on an error `path` is left at the offending place.
fn convert(obj: &Bound<'_, PyAny>, path: &mut String) -> Result<Value, String> {
    convert_at(obj, path, 0)
}

fn convert_at(obj: &Bound<'_, PyAny>, path: &mut String, depth: usize) -> Result<Value, String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "nested more than {MAX_DEPTH} levels deep (a list or dict that holds itself?)"
        ));
    }
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        if let Ok(i) = obj.extract::<i64>() {
            return Ok(Value::Number(i.into()));
        }
        if let Ok(u) = obj.extract::<u64>() {
            return Ok(Value::Number(u.into()));
        }
        return Err("an integer beyond 64 bits".into());
    }
    if let Ok(f) = obj.cast::<PyFloat>() {
        let x = f.value();
        return Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| format!("must be a finite number, got {x}"));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_string()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        let base = path.len();
        for (k, v) in d.iter() {
            let key = k
                .cast::<PyString>()
                .map_err(|_| format!("keys must be strings, got {}", type_name(&k)))?
                .to_string();
            push_key(path, &key);
            map.insert(key, convert_at(&v, path, depth + 1)?);
            path.truncate(base);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let base = path.len();
        let mut items = Vec::new();
        for (i, v) in obj.try_iter().map_err(|e| e.to_string())?.enumerate() {
            path.push_str(&format!("[{i}]"));
            items.push(convert_at(&v.map_err(|e| e.to_string())?, path, depth + 1)?);
            path.truncate(base);
        }
        return Ok(Value::Array(items));
    }
    // numpy arrays and scalars (np.float64 is a float already; np.int64, np.bool_ are not).
    if obj.hasattr("tolist").unwrap_or(false) {
        let plain = obj.call_method0("tolist").map_err(|e| e.to_string())?;
        if plain.hasattr("tolist").unwrap_or(false) {
            return Err(format!("cannot read a {}", type_name(obj)));
        }
        return convert_at(&plain, path, depth + 1);
    }
    Err(format!(
        "expected a number, string, bool, list or dict, got {}",
        type_name(obj)
    ))
}

fn push_key(path: &mut String, key: &str) {
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(key);
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "object".into())
}

/// The Python object of a document: `dict`, `list`, `str`, `bool`, `int`, `float`, `None`.
pub fn to_python<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                PyFloat::new(py, n.as_f64().unwrap_or(f64::NAN)).into_any()
            }
        }
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for v in items {
                list.append(to_python(py, v)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, to_python(py, v)?)?;
            }
            dict.into_any()
        }
    })
}
