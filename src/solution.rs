//! The result of a solve: harmonics per DOF, termination, residual history and statistics.

use crate::harmonic::{cos_sin, HarmonicBasis};
use num_complex::Complex64;
use std::time::Duration;

/// Why an iteration stopped. Only [`Termination::Converged`] means the tolerance was met; in
/// every case the [`Solution`] holds the last finite iterate.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The relative residual fell below the tolerance.
    Converged,
    /// The iteration limit was reached first.
    MaxIterations,
    /// The residual grew by more than the divergence factor over its best value: the fixed-point
    /// map is not a contraction here (raise γ, or use an accelerated solver).
    Diverged,
    /// A force or linear solve produced NaN or infinity.
    NonFinite {
        /// What turned non-finite.
        what: String,
    },
    /// The Newton or Broyden matrix is singular (a pivot below 1e-14 of its scale).
    SingularJacobian,
    /// The line search found no step that reduces the residual.
    LineSearchFailed,
    /// The wall-time limit was reached.
    Timeout,
    /// Interrupted from outside.
    Interrupted,
}

impl Termination {
    /// The termination for an error met while iterating: a non-finite value names where
    /// (the error's own `what`, not its message, which would say "non-finite value in" twice).
    pub fn from_error(e: &crate::Error) -> Self {
        Termination::NonFinite {
            what: match e {
                crate::Error::NonFinite { what } => what.clone(),
                other => other.to_string(),
            },
        }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Termination::Converged => write!(f, "converged"),
            Termination::MaxIterations => write!(f, "maximum iterations reached"),
            Termination::Diverged => write!(f, "diverged"),
            Termination::NonFinite { what } => write!(f, "non-finite value in {what}"),
            Termination::SingularJacobian => write!(f, "singular Jacobian"),
            Termination::LineSearchFailed => write!(f, "line search failed to reduce the residual"),
            Termination::Timeout => write!(f, "time limit reached"),
            Termination::Interrupted => write!(f, "interrupted"),
        }
    }
}

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

    /// `max |q_dof|` over one period, to the precision of the harmonics (see
    /// [`Solution::extremes`]).
    ///
    /// ```
    /// use hbal::{HarmonicBasis, Solution};
    /// use num_complex::Complex64;
    /// // q = 2 cos(θ - 0.1234): its maximum lies between any samples.
    /// let q = vec![Complex64::new(0.0, 0.0), Complex64::from_polar(2.0, -0.1234)];
    /// let basis = HarmonicBasis::new(1.0, 1).unwrap();
    /// let sol = Solution::from_harmonics(basis, vec!["x".into()], q, 0.0).unwrap();
    /// assert!((sol.max_abs(0) - 2.0).abs() < 1e-14);
    /// ```
    pub fn max_abs(&self, dof: usize) -> f64 {
        let (lo, hi) = self.extremes(dof);
        lo.abs().max(hi.abs())
    }

    /// `(min q_dof, max q_dof)` over one period: the extremes of 4N samples (at least 64),
    /// each refined by Newton on `q'(θ) = 0` with the analytic derivatives of the harmonics
    /// (within one sample spacing), so exact to rounding instead of to the sampling's
    /// `O((π/4N)²)`.
    pub fn extremes(&self, dof: usize) -> (f64, f64) {
        let points = self.extreme_points();
        let series = self.time_series(dof, points);
        self.extremes_of(dof, &series)
    }

    /// [`Solution::extremes`] of every DOF, with one FFT plan for all (a large model's sweep
    /// point: planning per DOF cost more than the transforms).
    pub fn extremes_all(&self) -> Vec<(f64, f64)> {
        let n = self.dofs.len();
        let h = self.basis.harmonics();
        let points = self.extreme_points();
        let plan = HarmonicBasis::new(self.basis.omega(), h)
            .and_then(|b| b.with_samples(points))
            .ok()
            .filter(|_| n > 1 && points > 2 * h)
            .map(crate::harmonic::AftPlan::new);
        let Some(plan) = plan else {
            return (0..n).map(|i| self.extremes(i)).collect();
        };
        let mut scratch = plan.make_scratch();
        let mut q = vec![Complex64::default(); h + 1];
        let mut series = vec![0.0; points];
        (0..n)
            .map(|dof| {
                for (k, qk) in q.iter_mut().enumerate() {
                    *qk = self.harmonics[k * n + dof];
                }
                plan.synthesize_into(&q, |_| Complex64::new(1.0, 0.0), &mut series, &mut scratch);
                self.extremes_of(dof, &series)
            })
            .collect()
    }

    /// `max |q_i|` of every DOF (see [`Solution::extremes_all`]).
    pub fn max_abs_all(&self) -> Vec<f64> {
        self.extremes_all()
            .into_iter()
            .map(|(lo, hi)| lo.abs().max(hi.abs()))
            .collect()
    }

    /// Samples the extremes are searched on: 4N, at least 64.
    fn extreme_points(&self) -> usize {
        (4 * self.basis.samples()).max(64)
    }

    /// The refined extremes of `dof` from its samples `series` over one period.
    fn extremes_of(&self, dof: usize, series: &[f64]) -> (f64, f64) {
        let points = series.len();
        let step = std::f64::consts::TAU / points as f64;
        let (mut imin, mut imax) = (0, 0);
        for (j, v) in series.iter().enumerate() {
            if *v < series[imin] {
                imin = j;
            }
            if *v > series[imax] {
                imax = j;
            }
        }
        let lo = self.refine_extremum(dof, imin as f64 * step, step, series[imin], -1.0);
        let hi = self.refine_extremum(dof, imax as f64 * step, step, series[imax], 1.0);
        (lo, hi)
    }

    /// The extremum of `q_dof` next to the sample at `theta` (value `at`): `sense` +1 for a
    /// maximum, -1 for a minimum. Newton on `q'` kept within `step` of the sample; the sample
    /// value if Newton does not improve on it.
    fn refine_extremum(&self, dof: usize, theta: f64, step: f64, at: f64, sense: f64) -> f64 {
        let h = self.basis.harmonics();
        let derivs = |t: f64| {
            let (mut q, mut d1, mut d2) = (0.0, 0.0, 0.0);
            // e^{ikt} by the recurrence e^{it} e^{i(k-1)t}: one sine and cosine per call.
            let step = Complex64::from_polar(1.0, t);
            let mut rot = Complex64::new(1.0, 0.0);
            for k in 0..=h {
                if k > 0 {
                    rot *= step;
                }
                let z = self.harmonic(dof, k) * rot;
                let kf = k as f64;
                q += z.re;
                d1 -= kf * z.im;
                d2 -= kf * kf * z.re;
            }
            (q, d1, d2)
        };
        let mut t = theta;
        for _ in 0..20 {
            let (_, d1, d2) = derivs(t);
            if d2 == 0.0 || !d1.is_finite() {
                break;
            }
            let next = (t - d1 / d2).clamp(theta - step, theta + step);
            if (next - t).abs() <= 1e-15 * std::f64::consts::TAU {
                t = next;
                break;
            }
            t = next;
        }
        let (q, _, _) = derivs(t);
        if q.is_finite() && sense * (q - at) >= 0.0 {
            q
        } else {
            at
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// One FFT plan for all DOFs gives the per-DOF extremes, and both find the analytic
    /// extremes of `q = a cos(θ - φ) + b cos(40 θ)` between the samples.
    #[test]
    fn extremes_of_all_dofs_equal_the_per_dof_extremes() {
        let (n, h) = (3, 40);
        let mut q = vec![Complex64::default(); (h + 1) * n];
        for dof in 0..n {
            let a = 1.0 + dof as f64;
            q[n + dof] = Complex64::from_polar(a, -0.3 * dof as f64 - 0.1234);
            q[h * n + dof] = Complex64::new(1e-3, 0.0);
            q[dof] = Complex64::new(0.5 * dof as f64, 0.0);
        }
        let basis = HarmonicBasis::new(2.0, h).unwrap();
        let names = (0..n).map(|i| format!("x{i}")).collect();
        let sol = Solution::from_harmonics(basis, names, q, 0.0).unwrap();
        let all = sol.extremes_all();
        for (dof, &(lo, hi)) in all.iter().enumerate() {
            let (l, u) = sol.extremes(dof);
            assert!((lo - l).abs() < 1e-13 && (hi - u).abs() < 1e-13, "{dof}");
            // The small 40th harmonic moves the extremes of mean ± a by at most its amplitude.
            let (mean, a) = (0.5 * dof as f64, 1.0 + dof as f64);
            assert!((hi - (mean + a)).abs() <= 1e-3 + 1e-12, "{dof}: {hi}");
            assert!((lo - (mean - a)).abs() <= 1e-3 + 1e-12, "{dof}: {lo}");
        }
        assert_eq!(sol.max_abs_all()[2], sol.max_abs(2));
    }
}
