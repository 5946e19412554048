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
        InputError::new_err(python_names(&message))
    } else {
        NumericalError::new_err(message)
    }
}

/// The command line's flags of the options this package takes, and their argument names.
const FLAGS: &[(&str, &str)] = &[
    ("from", "start"),
    ("start", "guess"),
    ("no-stability", "stability=False"),
    ("no-fallback", "fallback=False"),
    ("to", "to"),
    ("out", "out"),
    ("output", "output"),
    ("points", "points"),
    ("max-points", "max_points"),
    ("max-step", "max_step"),
    ("tolerance", "tolerance"),
    ("harmonics", "harmonics"),
    ("samples", "samples"),
    ("method", "method"),
    ("formulation", "formulation"),
    ("dofs", "dofs"),
    ("parameter", "parameter"),
    ("stability-orbit", "stability_orbit"),
    ("max-hz", "max_hz"),
];

/// The library's message with the command line's flags (those of [`FLAGS`], as words of
/// their own) named as this package's arguments: "--from needs --to" becomes "`start` needs
/// `to`". Anything else with `--` (a name, a path) is left as it is.
pub fn python_names(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(at) = rest.find("--") {
        let (before, after) = (&rest[..at], &rest[at + 2..]);
        let len = after
            .find(|c: char| !(c.is_ascii_lowercase() || c == '-'))
            .unwrap_or(after.len());
        let ends_word = after[len..]
            .chars()
            .next()
            .is_none_or(|c| !(c.is_alphanumeric() || c == '_' || c == '/' || c == '.'));
        let starts_word = before
            .chars()
            .next_back()
            .is_none_or(|c| c == ' ' || c == '(' || c == '`');
        let name = FLAGS.iter().find(|f| f.0 == &after[..len]).map(|f| f.1);
        out.push_str(before);
        match name.filter(|_| starts_word && ends_word) {
            Some(name) if before.ends_with('`') => out.push_str(name),
            Some(name) => {
                out.push('`');
                out.push_str(name);
                out.push('`');
            }
            None => {
                out.push_str("--");
                rest = after;
                continue;
            }
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    out
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

#[cfg(test)]
mod tests {
    use super::python_names;

    #[test]
    fn flags_become_argument_names() {
        assert_eq!(
            python_names("--from needs --to (the run-up's end speed)"),
            "`start` needs `to` (the run-up's end speed)"
        );
        assert_eq!(
            python_names("--out /tmp/x: cannot create the directory"),
            "`out` /tmp/x: cannot create the directory"
        );
        assert_eq!(python_names("`--start` x"), "`guess` x");
        assert_eq!(
            python_names("--max-points must be >= 1"),
            "`max_points` must be >= 1"
        );
        // Not a flag: inside a word, a bare `--`, a number, a name or path that is no flag.
        assert_eq!(python_names("a--b -- --5"), "a--b -- --5");
        assert_eq!(
            python_names("(its 1 DOFs: `--gear-shaft`) /x --y --to/z"),
            "(its 1 DOFs: `--gear-shaft`) /x --y --to/z"
        );
    }
}
