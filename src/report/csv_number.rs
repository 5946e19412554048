//! Numbers in the CSV files: scientific notation with 15 significant digits, trailing zeros
//! dropped, so that a speed computed as `ω / (rad/s per rpm)` reads `6e3`, not
//! `6.000000000000001e3`, and a zero reads `0`, never `-0e0` (issue 36). Fifteen digits keep
//! every value to within 1e-15 relative (the JSON records keep every bit).

/// `x` for a CSV cell (module documentation); `NaN` and `inf` as Rust prints them.
///
/// ```
/// use hbal::report::csv_number;
/// assert_eq!(csv_number(6000.000000000001), "6e3");
/// assert_eq!(csv_number(-0.0), "0");
/// assert_eq!(csv_number(-1.25e-7), "-1.25e-7");
/// assert_eq!(csv_number(0.1 + 0.2), "3e-1");
/// assert_eq!(csv_number(1.0 / 3.0), "3.33333333333333e-1");
/// ```
pub fn csv_number(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let s = format!("{x:.14e}");
    match s.split_once('e') {
        Some((mantissa, exponent)) => {
            let m = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{m}e{exponent}")
        }
        None => s,
    }
}
