//! The paper's iterative linear solver (Bauer et al. 2021, section 3, eq. 5).
//!
//! Starting from `Q = 0` (or a warm start), repeat:
//! 1. evaluate `f_rhs(t) = f(t) - D1(t) q̇(t) - K1(t) q(t)` (and any nonlinearity) in the time
//!    domain and take its harmonics `F_rhs = F_ext - F_rest(Q)` (steps 2a, 2b);
//! 2. solve `Z_k Q'_k = F_rhs,k` for every harmonic with the factored
//!    `Z_k = -(kΩ)² M + i kΩ D0 + K0` (step 2c);
//! 3. relax `Q ← γ Q + (1-γ) Q'` (step 2d; γ = 0 is the undamped iteration);
//! 4. synthesise `q(t)`, `q̇(t)` (step 2e, done inside the next AFT).
//!
//! The first solve from `Q = 0` is the classic linear frequency-domain solution. The residual
//! `R(Q) = Z Q - F_rhs(Q)` of every iterate comes from the same AFT and is checked against the
//! tolerance before the next solve.

use crate::error::{Error, Result};
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::{Solution, SolveStats, Termination};
use num_complex::Complex64;
use std::time::Instant;

/// Options of the paper's fixed-point iteration.
///
/// ```
/// use hbal::{force::CubicSpring, FixedPoint, HarmonicBalance, HarmonicBasis, Model};
/// // Weak Duffing oscillator x'' + 0.1 x' + x + 0.1 x³ = 0.1 cos(2t), away from resonance.
/// let model = Model::builder(&["x"])
///     .mass_diagonal(&[1.0])
///     .damping(nalgebra::DMatrix::from_element(1, 1, 0.1))
///     .element("duffing", &[("x", 1.0)], CubicSpring::new(1.0, 0.1))
///     .load("x", 1, 0.1, 0.0)
///     .build()?;
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(2.0, 7)?)?;
/// let sol = FixedPoint::new().with_tolerance(1e-12)?.solve(&hb, &mut hb.workspace())?;
/// assert!(sol.is_converged());
/// let (a1, _) = sol.cos_sin(0, 1);
/// assert!((a1 + 0.0332).abs() < 1e-3); // close to the linear -0.1/3
/// # Ok::<(), hbal::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FixedPoint {
    /// Relaxation γ ∈ [0, 1): `Q ← γ Q + (1-γ) Q'`. Default 0 (the paper's run).
    pub gamma: f64,
    /// Relative residual tolerance, in [0, 1). Default 1e-10.
    pub tolerance: f64,
    /// Maximum number of linear solves. Default 200.
    pub max_iterations: usize,
    /// Stop as diverged once the residual exceeds this factor times its best value. Default 1e3.
    pub divergence_factor: f64,
}

impl Default for FixedPoint {
    fn default() -> Self {
        Self {
            gamma: 0.0,
            tolerance: 1e-10,
            max_iterations: 200,
            divergence_factor: 1e3,
        }
    }
}

impl FixedPoint {
    /// Defaults: γ = 0, tolerance 1e-10, 200 iterations.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets γ ∈ [0, 1).
    pub fn with_gamma(mut self, gamma: f64) -> Result<Self> {
        if !(gamma.is_finite() && (0.0..1.0).contains(&gamma)) {
            return Err(Error::invalid("fixed point", "gamma", gamma, "in [0, 1)"));
        }
        self.gamma = gamma;
        Ok(self)
    }

    /// Sets the relative residual tolerance, in [0, 1) (0: run to the iteration limit).
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self> {
        if !(tolerance.is_finite() && (0.0..1.0).contains(&tolerance)) {
            return Err(Error::invalid(
                "fixed point",
                "tolerance",
                tolerance,
                "in [0, 1)",
            ));
        }
        self.tolerance = tolerance;
        Ok(self)
    }

    /// Sets the maximum number of linear solves.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// Solves from `Q = 0`: the first iterate is the linear frequency-domain solution.
    pub fn solve(&self, hb: &HarmonicBalance, ws: &mut Workspace) -> Result<Solution> {
        ws.q.fill(Complex64::default());
        self.iterate(hb, ws)
    }

    /// Solves from the warm start `initial` (harmonic-major, `(H+1)·n`).
    pub fn solve_from(
        &self,
        hb: &HarmonicBalance,
        initial: &[Complex64],
        ws: &mut Workspace,
    ) -> Result<Solution> {
        if initial.len() != hb.len() {
            return Err(Error::DimensionMismatch {
                context: "initial harmonics".into(),
                expected: format!("{} ((H+1) * n)", hb.len()),
                got: initial.len().to_string(),
            });
        }
        ws.q.copy_from_slice(initial);
        self.iterate(hb, ws)
    }

    fn iterate(&self, hb: &HarmonicBalance, ws: &mut Workspace) -> Result<Solution> {
        self.with_gamma(self.gamma)?
            .with_tolerance(self.tolerance)?;
        let start = Instant::now();
        let n = hb.model().n_dofs();
        let h = hb.basis().harmonics();
        let z = hb.dynamic_stiffness();
        let f_ext = hb.external_load();
        let ext_norm = hb.norm(f_ext);
        ws.stats = SolveStats::default();
        ws.eval.ffts = 0;
        ws.eval.force_evaluations = 0;
        let mut history = Vec::with_capacity(self.max_iterations + 1);
        let mut best = f64::INFINITY;
        let termination = loop {
            // Steps 2a-2b: time-domain rest and its harmonics.
            let evaluated = hb.rest_into(&ws.q, &mut ws.rest, &mut ws.eval);
            ws.stats.residual_evaluations += 1;
            if let Err(e) = evaluated {
                break Termination::NonFinite {
                    what: e.to_string(),
                };
            }
            // Residual of the current iterate: R = Z Q - (F_ext - F_rest).
            for k in 0..=h {
                let s = k * n..(k + 1) * n;
                z.apply(k, &ws.q[s.clone()], &mut ws.zq[s.clone()]);
                for i in s {
                    ws.rhs[i] = f_ext[i] - ws.rest[i];
                }
            }
            // Relative to the load, so that divergence shows as growth; without a load, relative
            // to the larger of the linear and the rest force.
            let scale = if ext_norm > 0.0 {
                ext_norm
            } else {
                hb.norm(&ws.zq).max(hb.norm(&ws.rest))
            };
            let mut r2 = 0.0;
            for (idx, (zq, rhs)) in ws.zq.iter().zip(&ws.rhs).enumerate() {
                let w = if idx < n { 1.0 } else { 0.5 };
                r2 += w * (zq - rhs).norm_sqr();
            }
            let rel = if scale > 0.0 {
                r2.sqrt() / scale
            } else {
                r2.sqrt()
            };
            if !rel.is_finite() {
                break Termination::NonFinite {
                    what: "residual".into(),
                };
            }
            history.push(rel);
            best = best.min(rel);
            if rel <= self.tolerance {
                break Termination::Converged;
            }
            if ws.stats.iterations >= self.max_iterations {
                break Termination::MaxIterations;
            }
            if rel > self.divergence_factor * best {
                break Termination::Diverged;
            }
            // Step 2c: Q' = Z⁻¹ F_rhs per harmonic; step 2d: relax.
            for k in 0..=h {
                z.solve_in_place(k, &mut ws.rhs[k * n..(k + 1) * n]);
            }
            if !ws.rhs.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
                break Termination::NonFinite {
                    what: "linear solve".into(),
                };
            }
            let g = self.gamma;
            for (q, qn) in ws.q.iter_mut().zip(&ws.rhs) {
                *q = *q * g + qn * (1.0 - g);
            }
            ws.stats.iterations += 1;
        };
        ws.stats.ffts = ws.eval.ffts;
        ws.stats.force_evaluations = ws.eval.force_evaluations;
        Ok(Solution {
            basis: *hb.basis(),
            dofs: hb.model().dof_names().to_vec(),
            harmonics: ws.q.clone(),
            termination,
            history,
            stats: ws.stats,
            wall_time: start.elapsed(),
        })
    }
}
