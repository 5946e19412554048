//! Distances between periodic solutions given by their harmonics.

use num_complex::Complex64;

/// Relative Parseval distance of two harmonic-major arrays with `n` DOFs over the orders
/// `0..=h`: `‖A - B‖ / ‖B‖` with `‖X‖² = Σ_i |X_0i|² + ½ Σ_{k≥1} |X_ki|²` (the RMS over one
/// period). Orders missing from a shorter array count as zero.
///
/// ```
/// use num_complex::Complex64 as C;
/// let b = [C::new(1.0, 0.0), C::new(2.0, 0.0)];
/// let a = [C::new(1.0, 0.0), C::new(2.0, 0.2)];
/// // ‖B‖² = 1 + ½·4 = 3, ‖A-B‖² = ½·0.04
/// assert!((hbal::compare::relative_error(&a, &b, 1, 1) - (0.02f64 / 3.0).sqrt()).abs() < 1e-15);
/// ```
pub fn relative_error(a: &[Complex64], b: &[Complex64], n: usize, h: usize) -> f64 {
    let (mut d, mut r) = (0.0, 0.0);
    for k in 0..=h {
        let w = if k == 0 { 1.0 } else { 0.5 };
        for i in 0..n {
            let idx = k * n + i;
            let av = a.get(idx).copied().unwrap_or_default();
            let bv = b.get(idx).copied().unwrap_or_default();
            d += w * (av - bv).norm_sqr();
            r += w * bv.norm_sqr();
        }
    }
    if r == 0.0 {
        d.sqrt()
    } else {
        (d / r).sqrt()
    }
}
