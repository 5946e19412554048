//! Locating an error in a scene document: field paths from serde's messages, the line and
//! column of a syntax error, non-finite numbers.

use serde_json::Value;

/// The path of the first NaN or infinite float in a TOML value (JSON has none).
pub(super) fn non_finite(v: &toml::Value, path: String) -> Option<(String, f64)> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Some((path, *x)),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| non_finite(x, format!("{path}[{i}]"))),
        toml::Value::Table(t) => t.iter().find_map(|(k, x)| {
            let p = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            non_finite(x, p)
        }),
        _ => None,
    }
}

/// The path of the first number in `v` that is not 0 and outside the magnitude range
/// [[`MIN_MAGNITUDE`](crate::error::MIN_MAGNITUDE),
/// [`MAX_MAGNITUDE`](crate::error::MAX_MAGNITUDE)], with its value.
pub(super) fn out_of_range(v: &Value, path: String) -> Option<(String, f64)> {
    let child = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        Value::Number(x) => {
            let x = x.as_f64().unwrap_or(f64::NAN);
            (!crate::error::in_magnitude_range(x)).then_some((path, x))
        }
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| out_of_range(x, format!("{path}[{i}]"))),
        Value::Object(m) => m.iter().find_map(|(k, x)| out_of_range(x, child(k))),
        _ => None,
    }
}

/// Where in `v` a key named `key` (or, with `as_value`, a string equal to it) sits, as a path.
pub(super) fn locate(v: &Value, needle: &str, as_value: bool, path: String) -> Option<String> {
    match v {
        Value::Object(map) => map.iter().find_map(|(k, x)| {
            let p = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            if (!as_value && k == needle) || (as_value && x.as_str() == Some(needle)) {
                Some(p)
            } else {
                locate(x, needle, as_value, p)
            }
        }),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| locate(x, needle, as_value, format!("{path}[{i}]"))),
        _ => None,
    }
}

/// The first back-quoted word of a serde message.
pub(super) fn quoted(message: &str) -> Option<&str> {
    message.split('`').nth(1)
}

/// For "unknown field `x`" errors, the path of the offending field itself.
pub(super) fn field_path(path: String, message: &str) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return path;
    };
    let Some(name) = rest.split('`').next() else {
        return path;
    };
    if path == "." || path.is_empty() {
        name.to_string()
    } else if path == name || path.ends_with(&format!(".{name}")) {
        path
    } else {
        format!("{path}.{name}")
    }
}

/// `.json` (any case) is JSON; everything else TOML.
pub(super) fn is_json(file: &str) -> bool {
    file.to_ascii_lowercase().ends_with(".json")
}

pub(super) fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}
