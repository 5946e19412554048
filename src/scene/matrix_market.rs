//! A reader for Matrix Market coordinate files (`.mtx`), the sparse-matrix exchange format that
//! FE programs export (and that `scipy.io.mmwrite` writes).
//!
//! The supported types are `matrix coordinate real general` and `matrix coordinate real
//! symmetric` (`integer` is read as real). The file is a header line, `%` comment lines, a size
//! line `rows columns entries`, then one `row column value` line per entry with 1-based indices.
//! Symmetric storage keeps the lower triangle only (row ≥ column); the reader mirrors it.
//! Repeated positions are kept (they add up when assembled, as in FE assembly).
//!
//! Every error names the file and the line. Hand-written rather than a crate: the format is
//! five rules, and the crates we measured either add a parser generator to the build
//! (`nalgebra-sparse` with `io`: pest, about 45 s) or report errors without line numbers.
//!
//! ```
//! use hbal::scene::matrix_market::parse;
//! let text = "%%MatrixMarket matrix coordinate real symmetric\n\
//!             % a 2 x 2 spring\n\
//!             2 2 3\n\
//!             1 1 2.0\n\
//!             2 1 -1.0\n\
//!             2 2 1.0\n";
//! let m = parse(text, "k.mtx").unwrap();
//! assert_eq!((m.rows, m.cols, m.symmetric), (2, 2, true));
//! // 0-based, the off-diagonal entry mirrored:
//! assert_eq!(m.entries, vec![(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 1.0)]);
//!
//! let err = parse(&text.replace("2 1 -1.0", "1 2 -1.0"), "k.mtx").unwrap_err();
//! assert_eq!(err.line, Some(5));
//! assert!(err.to_string().starts_with("k.mtx:5: entry (1, 2) lies above the diagonal"), "{err}");
//! let err = parse(&text.replace("real", "complex"), "k.mtx").unwrap_err();
//! assert!(err.to_string().starts_with("k.mtx:1: unsupported Matrix Market type"), "{err}");
//! ```

use std::path::Path;

/// A sparse matrix as read from a Matrix Market coordinate file.
#[derive(Debug, Clone, PartialEq)]
pub struct CoordinateMatrix {
    /// Number of rows (from the size line).
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// `(row, column, value)`, 0-based, in file order; with symmetric storage every
    /// off-diagonal entry is followed by its mirror image. Positions may repeat (they add up).
    pub entries: Vec<(usize, usize, f64)>,
    /// The header said `symmetric`.
    pub symmetric: bool,
    /// The 1-based line of the size line (for messages about the size).
    pub size_line: usize,
}

/// A Matrix Market error: the file, the 1-based line if there is one, what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct MtxError {
    /// The file as named by the caller.
    pub file: String,
    /// The line (1-based), if the error sits on one.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for MtxError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{l}: {}", self.file, self.message),
            None => write!(f, "{}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for MtxError {}

/// The header hbal reads, for messages.
const SUPPORTED: &str = "hbal reads `%%MatrixMarket matrix coordinate real general` and \
                         `%%MatrixMarket matrix coordinate real symmetric` (or `integer` for `real`)";

/// Reads and parses a Matrix Market file; errors name `path` as given.
pub fn read(path: &Path) -> Result<CoordinateMatrix, MtxError> {
    let file = path.display().to_string();
    let text = super::bounded_read::read_text(path).map_err(|e| MtxError {
        file: file.clone(),
        line: None,
        message: format!("cannot read the Matrix Market file: {e}"),
    })?;
    parse(&text, &file)
}

/// Parses Matrix Market text; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<CoordinateMatrix, MtxError> {
    let err = |line: usize, message: String| MtxError {
        file: file.to_string(),
        line: Some(line),
        message,
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (_, banner) = lines.next().unwrap_or((1, ""));
    let (symmetric, integer) = header(banner).map_err(|m| err(1, m))?;

    // The size line: the first line that is neither blank nor a comment.
    let mut data = lines.filter(|(_, l)| {
        let t = l.trim_start();
        !t.is_empty() && !t.starts_with('%')
    });
    let (size_line, size) = data.next().ok_or_else(|| {
        err(
            text.lines().count().max(1),
            "the file ends before the size line `rows columns entries`".into(),
        )
    })?;
    let (rows, cols, count) = size_numbers(size).ok_or_else(|| {
        err(
            size_line,
            format!(
                "expected the size line `rows columns entries` (three whole numbers), got `{}`",
                size.trim()
            ),
        )
    })?;
    if symmetric && rows != cols {
        return Err(err(
            size_line,
            format!("symmetric storage needs a square matrix, got {rows} x {cols}"),
        ));
    }

    // Never trust the declared count with an allocation.
    let mut entries = Vec::with_capacity(count.min(1 << 20) * if symmetric { 2 } else { 1 });
    let mut read = 0;
    let mut last_line = size_line;
    for (n, line) in data {
        last_line = n;
        if read == count {
            return Err(err(
                n,
                format!("more entries than the {count} declared on line {size_line}"),
            ));
        }
        let (i, j, v) = entry(line, rows, cols, integer).map_err(|m| err(n, m))?;
        if symmetric && j > i {
            return Err(err(
                n,
                format!(
                    "entry ({i}, {j}) lies above the diagonal: symmetric storage keeps the lower \
                     triangle only (row ≥ column)"
                ),
            ));
        }
        entries.push((i - 1, j - 1, v));
        if symmetric && i != j {
            entries.push((j - 1, i - 1, v));
        }
        read += 1;
    }
    if read < count {
        return Err(err(
            last_line,
            format!(
                "the file ends after {read} of the {count} entries declared on line {size_line}"
            ),
        ));
    }
    Ok(CoordinateMatrix {
        rows,
        cols,
        entries,
        symmetric,
        size_line,
    })
}

/// Checks the banner; returns (symmetric, integer).
fn header(line: &str) -> Result<(bool, bool), String> {
    let tokens: Vec<String> = line
        .split_whitespace()
        .map(|t| t.to_ascii_lowercase())
        .collect();
    if tokens.first().map(String::as_str) != Some("%%matrixmarket") {
        return Err(format!(
            "not a Matrix Market file: the first line must be a header such as \
             `%%MatrixMarket matrix coordinate real general`, got `{}`",
            line.trim()
        ));
    }
    let unsupported = |why: String| {
        format!(
            "unsupported Matrix Market type in `{}`: {why}; {SUPPORTED}",
            line.trim()
        )
    };
    let [_, object, format, field, symmetry] = tokens.as_slice() else {
        return Err(unsupported(format!(
            "expected 4 words after `%%MatrixMarket`, got {}",
            tokens.len() - 1
        )));
    };
    if object != "matrix" {
        return Err(unsupported(format!("`{object}` is not a matrix")));
    }
    match format.as_str() {
        "coordinate" => {}
        "array" => return Err(unsupported("dense `array` storage".into())),
        other => return Err(unsupported(format!("unknown format `{other}`"))),
    }
    let integer = match field.as_str() {
        "real" => false,
        "integer" => true,
        "complex" => return Err(unsupported("complex values".into())),
        "pattern" => return Err(unsupported("a `pattern` file has no values".into())),
        other => return Err(unsupported(format!("unknown field `{other}`"))),
    };
    let symmetric = match symmetry.as_str() {
        "general" => false,
        "symmetric" => true,
        "hermitian" => return Err(unsupported("hermitian storage".into())),
        "skew-symmetric" => return Err(unsupported("skew-symmetric storage".into())),
        other => return Err(unsupported(format!("unknown symmetry `{other}`"))),
    };
    Ok((symmetric, integer))
}

/// `rows columns entries`.
fn size_numbers(line: &str) -> Option<(usize, usize, usize)> {
    let mut t = line.split_whitespace().map(|x| x.parse::<usize>().ok());
    let size = (t.next()??, t.next()??, t.next()??);
    t.next().is_none().then_some(size)
}

/// One `row column value` line, indices checked against the size (1-based, as in the file).
fn entry(
    line: &str,
    rows: usize,
    cols: usize,
    integer: bool,
) -> Result<(usize, usize, f64), String> {
    let tokens: Vec<&str> = line.split_whitespace().collect();
    let [i, j, v] = tokens.as_slice() else {
        return Err(format!(
            "expected an entry `row column value`, got `{}`",
            line.trim()
        ));
    };
    let index = |what: &str, token: &str, limit: usize, plural: &str| -> Result<usize, String> {
        let k: usize = token
            .parse()
            .map_err(|_| format!("{what} index `{token}` is not a whole number"))?;
        if k == 0 || k > limit {
            return Err(format!(
                "{what} {k} is outside 1..={limit} (the {limit} {plural} of the size line; \
                 indices are 1-based)"
            ));
        }
        Ok(k)
    };
    let i = index("row", i, rows, "rows")?;
    let j = index("column", j, cols, "columns")?;
    let value = if integer {
        v.parse::<i64>()
            .map(|x| x as f64)
            .map_err(|_| format!("value `{v}` is not an integer (the header says `integer`)"))?
    } else {
        v.parse::<f64>()
            .map_err(|_| format!("value `{v}` is not a number"))?
    };
    if !value.is_finite() {
        return Err(format!("value `{v}` is not finite"));
    }
    if !crate::error::in_magnitude_range(value) {
        return Err(format!(
            "value `{v}` must be 0 or between {:e} and {:e} in magnitude",
            crate::error::MIN_MAGNITUDE,
            crate::error::MAX_MAGNITUDE
        ));
    }
    Ok((i, j, value))
}

/// Writes `a` as a Matrix Market coordinate file: `real symmetric` storage (the lower
/// triangle) when `a` is symmetric to rounding (`asymmetry <= 1e-13` of its largest entry, as
/// assembly leaves it), else `real general`. Values are written in Rust's shortest
/// round-trip form, so [`read`] gives back the same numbers (the lower triangle's where the
/// storage is symmetric). `comment` becomes `%` lines after the header.
///
/// ```
/// use hbal::model::SparseMatrix;
/// use hbal::scene::matrix_market::{parse, write};
/// let k = SparseMatrix::from_triplets(2, &[(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 0.1)]);
/// let mut text = Vec::new();
/// write(&mut text, &k, "a 2 x 2 spring").unwrap();
/// let m = parse(std::str::from_utf8(&text).unwrap(), "k.mtx").unwrap();
/// assert!(m.symmetric);
/// assert_eq!(m.entries, vec![(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 0.1)]);
/// ```
pub fn write(
    out: &mut impl std::io::Write,
    a: &crate::model::SparseMatrix,
    comment: &str,
) -> std::io::Result<()> {
    let symmetric = a.asymmetry() <= 1e-13 * a.amax();
    let kept = |i: usize, j: usize, v: f64| v != 0.0 && (!symmetric || i >= j);
    let entries = a.iter().filter(|&(i, j, v)| kept(i, j, v)).count();
    let storage = if symmetric { "symmetric" } else { "general" };
    let mut text = format!("%%MatrixMarket matrix coordinate real {storage}\n");
    for line in comment.lines() {
        text.push_str(&format!("% {line}\n"));
    }
    text.push_str(&format!("{} {} {entries}\n", a.n(), a.n()));
    for (i, j, v) in a.iter().filter(|&(i, j, v)| kept(i, j, v)) {
        text.push_str(&format!("{} {} {v:e}\n", i + 1, j + 1));
    }
    out.write_all(text.as_bytes())
}
