//! The result of a solve: harmonics per DOF, termination, residual history and statistics.

mod extremes;
mod termination;

use crate::harmonic::{cos_sin, HarmonicBasis};
use num_complex::Complex64;
use std::time::Duration;

pub use termination::Termination;

/// Counts of the work a solve did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SolveStats {
    /// Solver iterations (linear solves of all harmonics).
    pub iterations: usize,
    /// Residual evaluations (AFT passes).
    pub residual_evaluations: usize,
    /// Real FFTs of length N.
    pub ffts: usize,
    /// Calls of [`ForceLaw::force`](crate::force::ForceLaw::force).
    pub force_evaluations: usize,
    /// Jacobian evaluations (Newton, Broyden restarts).
    pub jacobians: usize,
    /// Dense LU factorisations of a Jacobian.
    pub factorizations: usize,
}

/// A periodic solution `q(θ) = Re Σ_k Q_k e^{ikθ}`, `θ = Ω t`, with how it was obtained.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Solution {
    pub(crate) basis: HarmonicBasis,
    pub(crate) dofs: Vec<String>,
    /// `Q[k * n + i]`, harmonic-major.
    pub(crate) harmonics: Vec<Complex64>,
    /// Why the solve stopped.
    pub termination: Termination,
    /// Relative residual `‖R(Q)‖ / ‖F_ext‖` (Parseval norms; without a load
    /// `‖R‖ / max(‖Z Q‖, ‖F_rest‖)`) of every iterate, starting with the initial guess.
    pub history: Vec<f64>,
    /// When each history entry was reached, in seconds since the solve started.
    #[serde(default)]
    pub history_seconds: Vec<f64>,
    /// Work counts.
    pub stats: SolveStats,
    /// Wall time of the solve (plans built beforehand).
    pub wall_time: Duration,
}

impl Solution {
    /// A solution made of given harmonics (a branch point, a previous result): harmonic-major
    /// `Q[k * n + i]` with `n = dofs.len()` and `k = 0..=H` of `basis`; the termination is
    /// [`Termination::Converged`] with the residual `residual`.
    pub fn from_harmonics(
        basis: HarmonicBasis,
        dofs: Vec<String>,
        harmonics: Vec<Complex64>,
        residual: f64,
    ) -> crate::Result<Self> {
        let expected = (basis.harmonics() + 1) * dofs.len();
        if harmonics.len() != expected {
            return Err(crate::Error::DimensionMismatch {
                context: "solution harmonics".into(),
                expected: format!("{expected} (H + 1 = {} per DOF)", basis.harmonics() + 1),
                got: format!("{}", harmonics.len()),
            });
        }
        Ok(Self {
            basis,
            dofs,
            harmonics,
            termination: Termination::Converged,
            history: vec![residual],
            history_seconds: Vec::new(),
            stats: SolveStats::default(),
            wall_time: Duration::ZERO,
        })
    }

    /// Floquet stability of this periodic solution of `model` (default
    /// [`FloquetOptions`](crate::stability::FloquetOptions)): the multipliers of the exact
    /// periodic orbit next to it, found by Newton shooting from this solution.
    pub fn stability(&self, model: &crate::Model) -> crate::Result<crate::stability::Floquet> {
        crate::stability::floquet(model, self)
    }

    /// `true` if the tolerance was met.
    pub fn is_converged(&self) -> bool {
        self.termination == Termination::Converged
    }

    /// The harmonic basis.
    pub fn basis(&self) -> &HarmonicBasis {
        &self.basis
    }

    /// DOF names.
    pub fn dof_names(&self) -> &[String] {
        &self.dofs
    }

    /// All harmonics, harmonic-major (`Q[k * n + i]`).
    pub fn harmonics(&self) -> &[Complex64] {
        &self.harmonics
    }

    /// The last relative residual.
    pub fn residual(&self) -> f64 {
        self.history.last().copied().unwrap_or(f64::NAN)
    }

    /// Index of a DOF by name.
    pub fn dof_index(&self, name: &str) -> Option<usize> {
        self.dofs.iter().position(|d| d == name)
    }

    /// Complex harmonic `Q_k` of DOF `dof` (`a_k - i b_k`); zero above H.
    ///
    /// # Panics
    /// If `dof` is not below the number of DOFs (as do all per-DOF accessors; look indices up
    /// with [`Solution::dof_index`]).
    pub fn harmonic(&self, dof: usize, k: usize) -> Complex64 {
        let n = self.dofs.len();
        assert!(
            dof < n,
            "DOF index {dof} out of range: the model has {n} DOFs"
        );
        if k > self.basis.harmonics() {
            return Complex64::default();
        }
        self.harmonics[k * n + dof]
    }

    /// `(a_k, b_k)` of `a_k cos kθ + b_k sin kθ` for DOF `dof`.
    pub fn cos_sin(&self, dof: usize, k: usize) -> (f64, f64) {
        cos_sin(self.harmonic(dof, k))
    }

    /// `q_dof(θ)` at angle `θ = (Ω/ν) t` of the fundamental (`Ω t` unless the basis is
    /// period-multiplied). Panics as [`Solution::harmonic`].
    pub fn displacement(&self, dof: usize, theta: f64) -> f64 {
        (0..=self.basis.harmonics())
            .map(|k| (self.harmonic(dof, k) * Complex64::from_polar(1.0, k as f64 * theta)).re)
            .sum()
    }

    /// `q̇_dof(θ)` at angle `θ = (Ω/ν) t`.
    pub fn velocity(&self, dof: usize, theta: f64) -> f64 {
        let w = self.basis.fundamental();
        (1..=self.basis.harmonics())
            .map(|k| {
                (self.harmonic(dof, k)
                    * Complex64::new(0.0, k as f64 * w)
                    * Complex64::from_polar(1.0, k as f64 * theta))
                .re
            })
            .sum()
    }

    /// `q_dof` at `points` equidistant angles over one period, starting at θ = 0 (by an inverse
    /// FFT when `points >= 2H+1`, so `O(points log points)`).
    pub fn time_series(&self, dof: usize, points: usize) -> Vec<f64> {
        let n = self.dofs.len();
        assert!(
            dof < n,
            "DOF index {dof} out of range: the model has {n} DOFs"
        );
        let h = self.basis.harmonics();
        // An FFT (with its planning) pays off once the direct sum has many terms.
        if points > 2 * h && points >= 2 && points * h > 20_000 {
            if let Ok(basis) =
                HarmonicBasis::new(self.basis.omega(), h).and_then(|b| b.with_samples(points))
            {
                let plan = crate::harmonic::AftPlan::new(basis);
                let mut scratch = plan.make_scratch();
                let q: Vec<Complex64> = (0..=h).map(|k| self.harmonics[k * n + dof]).collect();
                let mut out = vec![0.0; points];
                plan.synthesize_into(&q, |_| Complex64::new(1.0, 0.0), &mut out, &mut scratch);
                return out;
            }
        }
        (0..points)
            .map(|j| {
                // e^{ikθ} by the recurrence: one sin/cos per point.
                let step =
                    Complex64::from_polar(1.0, std::f64::consts::TAU * j as f64 / points as f64);
                let mut rot = Complex64::new(1.0, 0.0);
                let mut q = self.harmonics[dof].re;
                for k in 1..=h {
                    rot *= step;
                    q += (self.harmonics[k * n + dof] * rot).re;
                }
                q
            })
            .collect()
    }

    /// Truncation-error estimate: the RMS of the top quarter of the kept harmonics
    /// (`k > H - ⌈H/4⌉`) relative to the RMS of the whole oscillating part (`k >= 1`), over all
    /// DOFs. A spectrum that is resolved decays, so this is small; near 1 means H is too low.
    pub fn truncation_estimate(&self) -> f64 {
        let (n, h) = (self.dofs.len(), self.basis.harmonics());
        if h == 0 {
            return 0.0;
        }
        let top = h - h.div_ceil(4);
        let (mut tail, mut all) = (0.0, 0.0);
        for k in 1..=h {
            let e: f64 = self.harmonics[k * n..(k + 1) * n]
                .iter()
                .map(|v| v.norm_sqr())
                .sum();
            all += e;
            if k > top {
                tail += e;
            }
        }
        if all == 0.0 {
            0.0
        } else {
            (tail / all).sqrt()
        }
    }
}
