//! Linear time-invariant models: the harmonic balance in closed form.
//!
//! Where every element is linear and time-invariant
//! ([`Model::is_linear_time_invariant`]), the nonlinear rest vanishes and the harmonics
//! decouple: `Z_k(Ω) Q_k = F_k` per harmonic, `Z_k = -(kΩ)² M + i kΩ D0 + K0`. One solve per
//! harmonic gives the exact periodic solution (loads at orders up to H; nothing excites the
//! harmonics above). Its only error is rounding, which one step of iterative refinement
//! measures: `δ = Z_k⁻¹ (F_k - Z_k Q_k)` ([`time_invariant_reference`]), and the error
//! estimate is `Q` against `Q + δ`.

use crate::error::Result;
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solution::Solution;
use num_complex::Complex64;

/// The exact periodic solution of the linear time-invariant model of `hb` (full formulation)
/// by one solve per harmonic, with its relative residual; `None` where the shortcut does not
/// apply (a time-varying or nonlinear element, the condensed formulation).
///
/// ```
/// use hbal::{HarmonicBalance, HarmonicBasis, Model};
/// use hbal::nalgebra::DMatrix;
/// // m ẍ + c ẋ + k x = cos Ωt: Q_1 = 1 / (k - Ω² m + iΩc).
/// let model = Model::builder(&["x"])
///     .mass_diagonal(&[1.0])
///     .damping(DMatrix::from_element(1, 1, 0.1))
///     .stiffness(DMatrix::from_element(1, 1, 4.0))
///     .load("x", 1, 1.0, 0.0)
///     .build()?;
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.5, 4)?)?;
/// let sol = hbal::solve::solve_time_invariant(&hb).expect("a linear time-invariant model");
/// let q1 = sol.harmonic(0, 1);
/// let exact = 1.0 / hbal::num_complex::Complex64::new(4.0 - 1.5 * 1.5, 0.15);
/// assert!((q1 - exact).norm() < 1e-15);
/// assert!(sol.residual() < 1e-15);
/// # Ok::<(), hbal::Error>(())
/// ```
pub fn solve_time_invariant(hb: &HarmonicBalance) -> Option<Solution> {
    if !hb.model().is_linear_time_invariant() || hb.is_condensed() {
        return None;
    }
    let started = std::time::Instant::now();
    let q = direct(hb, hb.split_load());
    let residual = relative_residual(hb, &q);
    let mut sol =
        Solution::from_harmonics(*hb.basis(), hb.model().dof_names().to_vec(), q, residual).ok()?;
    sol.stats.iterations = 1;
    sol.wall_time = started.elapsed();
    Some(sol)
}

/// `dQ/dΩ = -Z⁻¹ (dZ/dΩ) Q` of the solution `x` (real layout) of the linear time-invariant
/// model of `hb` at its Ω, in the real layout (the branch's slope, for placing a sweep's
/// points).
pub(crate) fn omega_slope(
    hb: &HarmonicBalance,
    x: &[f64],
    ws: &mut crate::residual::Workspace,
) -> Result<Vec<f64>> {
    let layout = hb.layout();
    let mut r = vec![0.0; layout.len()];
    hb.omega_derivative_real_into(x, &mut r, ws)?;
    let mut f = vec![Complex64::default(); hb.len()];
    layout.unpack(&r, &mut f);
    let mut dq = direct(hb, &f);
    dq.iter_mut().for_each(|v| *v = -*v);
    layout.pack(&dq, &mut r);
    Ok(r)
}

/// `Z_k⁻¹ f_k` for every harmonic.
fn direct(hb: &HarmonicBalance, f: &[Complex64]) -> Vec<Complex64> {
    let n = hb.len() / (hb.basis().harmonics() + 1);
    let mut q = f.to_vec();
    for (k, block) in q.chunks_mut(n).enumerate() {
        hb.dynamic_stiffness().solve_in_place(k, block);
    }
    q
}

/// `F - Z Q` per harmonic.
fn defect(hb: &HarmonicBalance, q: &[Complex64]) -> Vec<Complex64> {
    let n = hb.len() / (hb.basis().harmonics() + 1);
    let mut zq = vec![Complex64::default(); n];
    let mut r = hb.split_load().to_vec();
    for (k, (qk, rk)) in q.chunks(n).zip(r.chunks_mut(n)).enumerate() {
        hb.dynamic_stiffness().apply(k, qk, &mut zq);
        rk.iter_mut().zip(&zq).for_each(|(r, z)| *r -= z);
    }
    r
}

/// `‖F - Z Q‖ / ‖F‖` (Parseval norms; against `‖Z Q‖` without a load).
fn relative_residual(hb: &HarmonicBalance, q: &[Complex64]) -> f64 {
    let r = hb.norm(&defect(hb, q));
    let load = hb.norm(hb.split_load());
    if load > 0.0 {
        r / load
    } else {
        r
    }
}

/// The reference the error estimate of `solution` (of the linear time-invariant `model`)
/// compares against ([`refined`]). `None` where the shortcut does not apply.
pub(crate) fn time_invariant_reference(
    model: &Model,
    solution: &Solution,
) -> Result<Option<Solution>> {
    if !model.is_linear_time_invariant() || model.n_dofs() > Model::MAX_DENSE_DOFS {
        return Ok(None);
    }
    let hb = HarmonicBalance::with_formulation(model, *solution.basis(), crate::Formulation::Full)?;
    refined(&hb, solution).map(Some)
}

/// The error estimate of `solution`, the exact solution of the linear time-invariant model of
/// `hb` on its basis, against [`refined`]: rounding only.
pub(crate) fn time_invariant_estimate(
    hb: &HarmonicBalance,
    solution: &Solution,
) -> Result<super::ErrorEstimate> {
    let fine = refined(hb, solution)?;
    Ok(super::accuracy::compare(hb.model(), solution, &fine))
}

/// `Q + δ` after one step of iterative refinement with the factors of `hb` (on the basis of
/// `solution`), on the basis with twice the harmonics: zero above H, where no load acts.
fn refined(hb: &HarmonicBalance, solution: &Solution) -> Result<Solution> {
    let basis = solution.basis();
    let mut q = solution.harmonics().to_vec();
    let delta = direct(hb, &defect(hb, &q));
    q.iter_mut().zip(&delta).for_each(|(q, d)| *q += d);
    let residual = relative_residual(hb, &q);
    let n = hb.model().n_dofs();
    let fine = super::accuracy::scaled(basis, 2 * basis.harmonics().max(1))?;
    let q = crate::harmonic::embed(&q, n, 1, fine.harmonics());
    Solution::from_harmonics(fine, hb.model().dof_names().to_vec(), q, residual)
}
