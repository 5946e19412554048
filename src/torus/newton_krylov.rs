//! Newton's method on the condensed torus balance with the Jacobian applied by AFT and the
//! steps solved by GMRES, preconditioned by the averaged Jacobian
//! `P_j = G_j⁻¹ + diag_c(ḡ_u + i ν_j ḡ_u̇)`: block diagonal over the lines (m × m each), it
//! is the exact Jacobian where the elements' derivatives are constant on the grid, and
//! cheap to factor where the dense Jacobian (`(2 |K| m)²` entries) would not be.

use super::balance::{TorusBalance, TorusWorkspace};
use super::gmres::{gmres, GmresOutcome};
use super::TorusSolution;
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Newton–Krylov settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonKrylov {
    /// Converged at `‖R‖ <= tolerance · max(‖L‖, ‖G⁻¹ U‖)`.
    pub tolerance: f64,
    /// Most Newton steps.
    pub max_iterations: usize,
    /// Largest relative tolerance of a step's linear solve (the forcing term); each step
    /// asks for at most this, less as the last step's linear model proves accurate
    /// (Eisenstat & Walker 1996, choice 1),
    /// never below what the tolerance needs.
    pub forcing: f64,
    /// GMRES restart length.
    pub restart: usize,
    /// Most Jacobian products per step.
    pub max_linear: usize,
}

impl Default for NewtonKrylov {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 40,
            forcing: 0.1,
            restart: 120,
            max_linear: 360,
        }
    }
}

pub(super) fn norm(x: &[Complex64]) -> f64 {
    x.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt()
}

impl NewtonKrylov {
    /// Solves `hb` from `start` (the linear response where `None`). A step that does not
    /// lower the residual after 12 halvings ends the run, marked not converged.
    pub fn solve(&self, hb: &TorusBalance, start: Option<&[Complex64]>) -> Result<TorusSolution> {
        let mut ws = hb.workspace();
        let mut u = start_of(hb, start)?;
        let len = hb.len();
        let (mut iterations, mut linear) = (0, 0);
        let mut r = vec![Complex64::default(); len];
        let mut relative = 0.0;
        let mut converged = len == 0;
        if len > 0 {
            hb.residual_into(&u, &mut r, true, &mut ws)?;
            let mut step = vec![Complex64::default(); len];
            // The last step: ‖R‖ before it, the norm its linear model predicted, its forcing.
            let mut last: Option<(f64, f64, f64)> = None;
            loop {
                relative = relative_residual(hb, &u, &r);
                if relative <= self.tolerance {
                    converged = true;
                    break;
                }
                if iterations >= self.max_iterations {
                    break;
                }
                iterations += 1;
                let r_norm = norm(&r);
                let eta = forcing(last, r_norm, self.forcing)
                    .max(0.5 * self.tolerance / relative)
                    .min(0.5);
                let outcome = self.direction(hb, &r, eta, &mut step, &mut ws);
                linear += outcome.iterations;
                let Some(alpha) = line_search(hb, &mut u, &mut r, &step, true, &mut ws)? else {
                    break;
                };
                // ‖R + α J s‖ ≤ (1 − α) ‖R‖ + α ‖R + J s‖ (exact for a full step).
                let predicted = r_norm * (1.0 - alpha + alpha * outcome.relative_residual);
                last = Some((r_norm, predicted, eta));
            }
        }
        finish(hb, &u, &mut ws, relative, converged, iterations, linear)
    }

    /// The Newton direction `step ≈ -J⁻¹ r` to the relative tolerance `eta`; returns the
    /// Jacobian products it took and the linear residual it reached.
    fn direction(
        &self,
        hb: &TorusBalance,
        r: &[Complex64],
        eta: f64,
        step: &mut [Complex64],
        ws: &mut TorusWorkspace,
    ) -> GmresOutcome {
        let blocks = preconditioner(hb, ws);
        let m = hb.coordinates();
        let rhs: Vec<Complex64> = r.iter().map(|v| -v).collect();
        let ws = std::cell::RefCell::new(ws);
        gmres(
            |v, out| hb.jacobian_apply(v, out, &mut ws.borrow_mut()),
            |v| apply_blocks(&blocks, m, v),
            &rhs,
            step,
            eta,
            self.restart,
            self.max_linear,
        )
    }
}

/// The forcing term of a step (Eisenstat & Walker 1996, choice 1, with its safeguard): how far
/// the last step's linear model missed the residual it reached,
/// `|‖R_k‖ − ‖R_{k−1} + α J s‖| / ‖R_{k−1}‖`, at most `first` (also the first step's). Where the
/// Jacobian is exact it falls superlinearly; where it is not (the contact-edge correction's
/// derivative is the derivative of the exact integral, not of its corrected quadrature) it
/// stops GMRES from solving beyond what the model is worth.
fn forcing(last: Option<(f64, f64, f64)>, r_norm: f64, first: f64) -> f64 {
    let Some((previous, predicted, eta)) = last else {
        return first;
    };
    let missed = (r_norm - predicted).abs() / previous;
    let safeguard = eta.powf(0.5 * (1.0 + 5f64.sqrt()));
    let eta = if safeguard > 0.1 {
        missed.max(safeguard)
    } else {
        missed
    };
    eta.min(first)
}

/// The unknowns to start from: `start`, or the linear response; an error for a start of
/// another length than the balance's unknowns.
pub(super) fn start_of(hb: &TorusBalance, start: Option<&[Complex64]>) -> Result<Vec<Complex64>> {
    match start {
        None => Ok(hb.linear_start()),
        Some(s) if s.len() == hb.len() => Ok(s.to_vec()),
        Some(s) => Err(crate::Error::DimensionMismatch {
            context: "torus start (lines × element coordinates)".into(),
            expected: hb.len().to_string(),
            got: s.len().to_string(),
        }),
    }
}

/// `‖R‖ / max(‖L‖, ‖G⁻¹ U‖)`.
pub(super) fn relative_residual(hb: &TorusBalance, u: &[Complex64], r: &[Complex64]) -> f64 {
    let mut lin = vec![Complex64::default(); u.len()];
    hb.linear.apply_stiffness(u, &mut lin);
    norm(r) / norm(hb.load()).max(norm(&lin)).max(f64::MIN_POSITIVE)
}

/// Backtracking along `step` from `u` (Armijo on ‖R‖ with a small slope, 12 halvings): moves
/// `u` and its residual `r` (with the Jacobian's samples where `derivatives`) and returns the
/// fraction of the step taken on success; `None` (and `u`, `r` as they were) where no step
/// lowers ‖R‖.
pub(super) fn line_search(
    hb: &TorusBalance,
    u: &mut Vec<Complex64>,
    r: &mut Vec<Complex64>,
    step: &[Complex64],
    derivatives: bool,
    ws: &mut TorusWorkspace,
) -> Result<Option<f64>> {
    let r_norm = norm(r);
    let mut trial = vec![Complex64::default(); u.len()];
    let mut r_trial = vec![Complex64::default(); u.len()];
    let mut alpha = 1.0;
    for _ in 0..12 {
        for ((t, x), s) in trial.iter_mut().zip(u.iter()).zip(step) {
            *t = x + s * alpha;
        }
        hb.residual_into(&trial, &mut r_trial, derivatives, ws)?;
        if norm(&r_trial) <= (1.0 - 1e-4 * alpha) * r_norm {
            *u = trial;
            *r = r_trial;
            return Ok(Some(alpha));
        }
        alpha *= 0.5;
    }
    hb.residual_into(u, r, derivatives, ws)?;
    Ok(None)
}

/// The solution at `u`: full harmonics, truncation estimates, and how the solver got there.
pub(super) fn finish(
    hb: &TorusBalance,
    u: &[Complex64],
    ws: &mut TorusWorkspace,
    relative: f64,
    converged: bool,
    iterations: usize,
    linear: usize,
) -> Result<TorusSolution> {
    let q = hb.full_harmonics(u, ws)?;
    let truncation = hb.truncation_estimates(u, ws)?;
    Ok(TorusSolution {
        relative_residual: relative,
        converged,
        iterations,
        linear_iterations: linear,
        truncation,
        ..solution(hb, u, &q)
    })
}

/// `P_j⁻¹` per line: the inverse of `G_j⁻¹ + diag(ḡ_u + i ν_j ḡ_u̇)`.
pub(super) fn preconditioner(hb: &TorusBalance, ws: &TorusWorkspace) -> Vec<DMatrix<Complex64>> {
    let means = hb.mean_derivatives(ws);
    let receptance = hb.linear.receptance_form;
    let blocks = if receptance {
        &hb.linear.receptance
    } else {
        &hb.linear.stiffness
    };
    blocks
        .iter()
        .enumerate()
        .map(|(j, g)| {
            let nu = hb.frequency(j);
            let mut p = g.clone();
            if receptance {
                // I + G diag(ḡ_u + i ν ḡ_u̇)
                for (c, (a, b)) in means.iter().enumerate() {
                    let d = Complex64::new(*a, nu * b);
                    for r in 0..p.nrows() {
                        p[(r, c)] = g[(r, c)] * d;
                    }
                }
                for c in 0..p.nrows() {
                    p[(c, c)] += 1.0;
                }
            } else {
                for (c, (a, b)) in means.iter().enumerate() {
                    p[(c, c)] += Complex64::new(*a, nu * b);
                }
            }
            p.clone().try_inverse().unwrap_or_else(|| {
                DMatrix::from_diagonal(&p.diagonal().map(|v| {
                    if v.norm() > 0.0 {
                        1.0 / v
                    } else {
                        Complex64::new(1.0, 0.0)
                    }
                }))
            })
        })
        .collect()
}

pub(super) fn apply_blocks(blocks: &[DMatrix<Complex64>], m: usize, v: &mut [Complex64]) {
    let mut tmp = [Complex64::default(); 16];
    for (j, p) in blocks.iter().enumerate() {
        let x = &mut v[j * m..(j + 1) * m];
        if m <= 16 {
            for a in 0..m {
                tmp[a] = (0..m).map(|b| p[(a, b)] * x[b]).sum();
            }
            x.copy_from_slice(&tmp[..m]);
        } else {
            let y: Vec<Complex64> = (0..m)
                .map(|a| (0..m).map(|b| p[(a, b)] * x[b]).sum())
                .collect();
            x.copy_from_slice(&y);
        }
    }
}

/// The structural fields of a solution (the solver fills in how it got there).
fn solution(hb: &TorusBalance, u: &[Complex64], q: &[Complex64]) -> TorusSolution {
    let tm = hb.torus_model();
    let set = hb.set();
    TorusSolution {
        omega: hb.omega(),
        bases: tm.bases().names().to_vec(),
        ratios: tm.bases().ratios().to_vec(),
        dofs: tm.model().dof_names().to_vec(),
        indices: (0..set.len()).map(|j| set.k(j).to_vec()).collect(),
        frequencies: (0..set.len()).map(|j| hb.frequency(j)).collect(),
        harmonics: q.iter().map(|v| (v.re, v.im)).collect(),
        unknowns: u.iter().map(|v| (v.re, v.im)).collect(),
        relative_residual: f64::NAN,
        converged: false,
        iterations: 0,
        linear_iterations: 0,
        truncation: Vec::new(),
    }
}
