//! Distances between periodic solutions given by their harmonics: over all DOFs (here) and
//! per quantity ([`quantities`]).

pub mod quantities;
pub use quantities::{quantity_errors, Quantity, QuantityError};

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

/// [`relative_error`] of two solutions of `model` without what is a convention in them: the
/// part of the mean (order 0) along the rigid-body modes of a free-free model, removed from
/// both (`q_0 ← q_0 - R Rᵀ M q_0`, [`RigidModes::project_motion`]). hbal fixes
/// `Rᵀ M q_0 = 0`, a time simulation keeps the rigid angle it drifted to; the vibration, the
/// rigid-body oscillation at orders `k >= 1` and the static wind-up between the DOFs are all
/// compared. A model without rigid-body modes (or too large for dense matrices) is compared
/// as it is.
///
/// ```
/// use hbal::num_complex::Complex64 as C;
/// use hbal::Model;
/// // Two free inertias on a spring: a mean angle common to both is a convention.
/// let model = Model::builder(&["a", "b"])
///     .mass_diagonal(&[1.0, 1.0])
///     .stiffness(hbal::nalgebra::dmatrix![1.0, -1.0; -1.0, 1.0])
///     .load("a", 1, 1.0, 0.0)
///     .load("b", 1, -1.0, 0.0)
///     .build()
///     .unwrap();
/// let a = [C::new(0.0, 0.0), C::new(0.0, 0.0), C::new(1.0, 0.0), C::new(-1.0, 0.0)];
/// let b = [C::new(0.3, 0.0), C::new(0.3, 0.0), C::new(1.0, 0.0), C::new(-1.0, 0.0)];
/// assert!(hbal::compare::relative_error(&a, &b, 2, 1) > 0.2);
/// assert!(hbal::compare::model_relative_error(&model, &a, &b, 1) < 1e-15);
/// ```
///
/// [`RigidModes::project_motion`]: crate::model::RigidModes::project_motion
pub fn model_relative_error(
    model: &crate::Model,
    a: &[Complex64],
    b: &[Complex64],
    h: usize,
) -> f64 {
    let n = model.n_dofs();
    let rigid = model
        .dense("comparison")
        .ok()
        .and_then(|dense| crate::model::rigid::find_dense(model, &dense));
    let Some(rigid) = rigid else {
        return relative_error(a, b, n, h);
    };
    let without_rigid_mean = |x: &[Complex64]| {
        let mut x = x.to_vec();
        if x.len() >= n {
            rigid.project_motion(&mut x[..n]);
        }
        x
    };
    relative_error(&without_rigid_mean(a), &without_rigid_mean(b), n, h)
}
