//! hbal's errors as Python exceptions, by the command line's exit-code contract:
//! [`InputError`] (a `ValueError`; exit code 2: bad input, refused before any work),
//! [`SceneError`] (an `InputError` naming the file, field path and position), [`LawError`]
//! (an `InputError`: a Python force law that raised or returned something unusable; the
//! law's own exception is its `__cause__`), and [`NumericalError`] (a `RuntimeError`; exit
//! code 1: a failure along a solve whose input was checked).

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

create_exception!(_hbal, InputError, PyValueError, "Bad input (exit code 2).");
create_exception!(
    _hbal,
    SceneError,
    InputError,
    "A scene error: `file`, `path` (the field), `position` (line, column) and `reason`."
);
create_exception!(
    _hbal,
    LawError,
    InputError,
    "A Python force law raised or returned arrays of the wrong length or non-finite values."
);
create_exception!(
    _hbal,
    NumericalError,
    PyRuntimeError,
    "A numerical failure after the input was checked (exit code 1)."
);

/// The Python exception of a library error.
pub fn to_py(py: Python<'_>, e: hbal::Error) -> PyErr {
    if let hbal::Error::Scene(s) = &e {
        return scene_error(py, s);
    }
    let message = e.to_string();
    if e.exit_code() == 2 {
        InputError::new_err(message)
    } else {
        NumericalError::new_err(message)
    }
}

/// A [`SceneError`] with its attributes.
pub fn scene_error(py: Python<'_>, s: &hbal::scene::SceneError) -> PyErr {
    let err = SceneError::new_err(s.to_string());
    let value = err.value(py);
    // Setting attributes on a fresh exception object cannot fail in practice; if it did,
    // the message still carries everything.
    let _ = value.setattr("file", &s.file);
    let _ = value.setattr("path", s.path.clone());
    let _ = value.setattr("position", s.position);
    let _ = value.setattr("reason", &s.message);
    err
}

/// Registers the exception classes in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("LawError", py.get_type::<LawError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    Ok(())
}
