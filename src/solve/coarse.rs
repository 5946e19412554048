//! A two-level preconditioner: Newton's Jacobian on the low harmonics, the dynamic stiffness
//! on the rest.
//!
//! The paper's fixed point is `x ← x - Z⁻¹ R(x)`: block-diagonal per harmonic, so it ignores
//! the coupling that the time-varying and nonlinear forces create between harmonics. Above a
//! few dozen harmonics that coupling is weak against `Z_k ≈ -(kΩ)² M` and the fixed point
//! contracts fast; below, near the resonances, it is what makes the fixed point stall. The
//! two-level map replaces the low block by the exact AFT Jacobian `J_c` of the basis with
//! `H_c` harmonics, evaluated once at the start:
//!
//! `P = diag(J_c, Z_{H_c+1}, ..., Z_H)`, `x ← x - P⁻¹ R(x)`.
//!
//! Each step costs one AFT on the fine basis (`O(N log N)`), `H - H_c` small solves and one
//! solve with the dense factors of `J_c` (`(n (2H_c + 1))²`); Anderson acceleration on top
//! removes the remaining slow directions. This is what lets a solution with 512 or 4096
//! harmonics converge in a few dozen FFT-cost steps where a dense Newton step would take
//! `(n (2H + 1))³` (the "nonlinear Galerkin" idea of slaving the fast harmonics to the slow
//! ones; here the slaving is iterated to the exact fine-basis solution).

use super::{lu, Newton};
use crate::error::Result;
use crate::harmonic::{embed, RealLayout};
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::HarmonicBasis;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::cell::RefCell;

/// The factored Jacobian of the low harmonics `0..=H_c`.
#[derive(Debug, Clone)]
pub struct CoarseBlock {
    layout: RealLayout,
    lu: DMatrix<f64>,
    perm: Vec<usize>,
    scratch: RefCell<Vec<f64>>,
}

impl CoarseBlock {
    /// Harmonics `H_c` of the block.
    pub fn harmonics(&self) -> usize {
        self.layout.h
    }

    /// Builds the block for the fine problem: factors the Jacobian of the basis with `hc`
    /// harmonics at the low harmonics of `initial`, or, without one, at the solution there
    /// (chord steps from the linear solution, Newton if they stall). Returns the block and the low-harmonic start
    /// embedded in the fine basis, or `None` if the coarse Jacobian is singular.
    pub fn build(
        fine: &HarmonicBalance,
        hc: usize,
        initial: Option<&[Complex64]>,
    ) -> Result<Option<(Self, Vec<Complex64>)>> {
        let basis = fine.basis();
        let n = fine.layout().n;
        // Only its Jacobian is used: no tail correction.
        let coarse = HarmonicBasis::new(basis.omega(), hc)?
            .with_subharmonic(basis.subharmonic())?
            .with_tail_correction(false);
        let hb = HarmonicBalance::with_formulation(fine.model(), coarse, fine.formulation())?;
        let mut ws = hb.workspace();
        let layout = hb.layout();
        let len = layout.len();
        let mut x = vec![0.0; len];
        let mut r = vec![0.0; len];
        let mut jac = DMatrix::zeros(len, len);
        let mut perm = vec![0; len];
        let factored = match initial {
            Some(q) => {
                layout.pack(&q[..(hc + 1) * n], &mut x);
                false
            }
            None => {
                // Chord steps from the linear solution with its Jacobian's factors: one
                // factorisation where the model is linear or mildly nonlinear; Newton where
                // they stall (contact), factored again at its solution.
                x = super::run::initial_x(&hb, None, true)?;
                hb.residual_real_into(&x, &mut r, Some(&mut jac), &mut ws)?;
                lu::factor_in_place(&mut jac, &mut perm)
                    && chord(&hb, &mut ws, &jac, &perm, &mut x, &mut r)?
            }
        };
        if !factored {
            if initial.is_none() {
                let mut q = vec![Complex64::default(); hb.len()];
                layout.unpack(&x, &mut q);
                let sol = Newton::new().solve_from(&hb, &q, &mut ws)?;
                // The solution holds every DOF; the unknowns may be the element coordinates.
                if let (true, Some(u)) = (sol.is_converged(), hb.unknowns_of_full(sol.harmonics()))
                {
                    layout.pack(&u, &mut x);
                }
            }
            hb.residual_real_into(&x, &mut r, Some(&mut jac), &mut ws)?;
            if !lu::factor_in_place(&mut jac, &mut perm) {
                return Ok(None);
            }
        }
        let mut q = vec![Complex64::default(); hb.len()];
        layout.unpack(&x, &mut q);
        let start = embed(&q, n, 1, basis.harmonics());
        let block = Self {
            layout,
            lu: jac,
            perm,
            scratch: RefCell::new(vec![0.0; layout.len()]),
        };
        Ok(Some((block, start)))
    }

    /// `step ← J_c⁻¹ R_c` in place, for the complex residual of the harmonics `0..=H_c`.
    pub fn solve_in_place(&self, residual: &mut [Complex64]) {
        let mut real = self.scratch.borrow_mut();
        self.layout.pack(residual, &mut real);
        lu::solve_in_place(&self.lu, &self.perm, &mut real);
        self.layout.unpack(&real, residual);
    }
}

/// Chord steps `x ← x - J⁻¹ R(x)` with fixed factors until the relative residual is below
/// 1e-10 (`true`) or a step fails to halve it (`false`, `x` at the last improvement).
fn chord(
    hb: &HarmonicBalance,
    ws: &mut crate::residual::Workspace,
    lu_factors: &DMatrix<f64>,
    perm: &[usize],
    x: &mut [f64],
    r: &mut [f64],
) -> Result<bool> {
    let layout = hb.layout();
    let scale = hb.norm(hb.external_load()).max(f64::MIN_POSITIVE);
    let mut last = layout.norm(r) / scale;
    let mut step = r.to_vec();
    for _ in 0..10 {
        if last <= 1e-10 {
            return Ok(true);
        }
        step.copy_from_slice(r);
        lu::solve_in_place(lu_factors, perm, &mut step);
        for (xi, d) in x.iter_mut().zip(&step) {
            *xi -= d;
        }
        hb.residual_real_into(x, r, None, ws)?;
        let rel = layout.norm(r) / scale;
        if rel.is_nan() || rel > 0.5 * last {
            for (xi, d) in x.iter_mut().zip(&step) {
                *xi += d;
            }
            return Ok(false);
        }
        last = rel;
    }
    Ok(last <= 1e-10)
}

/// Largest real unknowns `n (2 H_c + 1)` of the coarse block chosen by
/// [`coarse_harmonics`]: its dense factors stay below a few milliseconds.
pub const MAX_COARSE_UNKNOWNS: usize = 640;

/// The highest undamped natural frequency `ω_max` (rad/s) of `(M, K0)`: `√λ_max` of
/// `L⁻¹ K0 L⁻ᵀ` with `M = L Lᵀ`; `None` if `M` is not positive definite.
pub fn highest_natural_frequency(model: &Model) -> Option<f64> {
    let (_, sym) = mass_normalised_stiffness(model)?;
    let lambda = sym.symmetric_eigenvalues().max();
    lambda.is_finite().then(|| lambda.max(0.0).sqrt())
}

/// `M = L Lᵀ` and `L⁻¹ K0 L⁻ᵀ` (symmetrised) of `model`; `None` if `M` is not positive
/// definite.
fn mass_normalised_stiffness(
    model: &Model,
) -> Option<(nalgebra::DMatrix<f64>, nalgebra::DMatrix<f64>)> {
    let dense = model.dense("natural frequencies").ok()?;
    let l = dense.mass.cholesky()?.l();
    let a = l.solve_lower_triangular(&dense.k0)?;
    let b = l.solve_lower_triangular(&a.transpose())?;
    let sym = (&b + b.transpose()) * 0.5;
    Some((l, sym))
}

/// The undamped normal modes of `(M, K0)`: natural frequencies (rad/s) and M-normalised mode
/// shapes (columns); `None` if `M` is not positive definite.
pub(crate) struct NormalModes {
    pub(crate) frequencies: Vec<f64>,
    pub(crate) shapes: nalgebra::DMatrix<f64>,
}

/// [`NormalModes`] of `model` by a dense symmetric eigenproblem of `L⁻¹ K0 L⁻ᵀ`, `M = L Lᵀ`.
pub(crate) fn normal_modes(model: &Model) -> Option<NormalModes> {
    let (l, sym) = mass_normalised_stiffness(model)?;
    let eig = sym.symmetric_eigen();
    let shapes = l.transpose().solve_upper_triangular(&eig.eigenvectors)?;
    let frequencies = eig.eigenvalues.iter().map(|l| l.max(0.0).sqrt()).collect();
    Some(NormalModes {
        frequencies,
        shapes,
    })
}

/// The coarse harmonics for the two-level map on `basis`: every harmonic up to 1.5 times
/// the highest natural frequency of `(M, K0)` (above it, `Z_k` dominates the coupling and the
/// per-harmonic step contracts), at least 32 and every order of the model, at most
/// [`MAX_COARSE_UNKNOWNS`] real unknowns. `None` if that is not below `H` or the cap does not
/// reach the model's highest order (use Newton).
pub fn coarse_harmonics(model: &Model, basis: &HarmonicBasis) -> Option<usize> {
    coarse_harmonics_within(model, basis, MAX_COARSE_UNKNOWNS)
}

/// [`coarse_harmonics`] with another cap on the block's real unknowns `n (2 H_c + 1)`: a
/// slow-speed case whose resonance sits at harmonic 771 (the two-shaft model at 60 rpm)
/// needs 2313 of them, 1.2 s of dense factorisation.
pub fn coarse_harmonics_within(
    model: &Model,
    basis: &HarmonicBasis,
    max_unknowns: usize,
) -> Option<usize> {
    let n = model.n_dofs().max(1);
    let cap = (max_unknowns / n).saturating_sub(1) / 2;
    let least = model.max_order() * basis.subharmonic();
    if cap < least.max(1) {
        // The block cannot hold every order of the model (a large model): no two-level map,
        // and no dense eigenvalue problem of (M, K0) to find that out.
        return None;
    }
    let fundamental = basis.fundamental();
    let resonant = highest_natural_frequency(model)
        .map(|w| (1.5 * w / fundamental).ceil())
        .filter(|h| h.is_finite())
        .unwrap_or(0.0)
        .min(1e9) as usize;
    let hc = resonant.max(32).max(least).min(cap);
    (hc < basis.harmonics()).then_some(hc)
}
