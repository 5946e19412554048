//! The exact periodic solution of a linear scene whose coefficients are piecewise constant in
//! time: rectangular mesh stiffness (with constant or stiffness-proportional damping), linear
//! springs and dampers, harmonic loads.
//!
//! Harmonic balance truncates: where the mesh stiffness jumps, every jump rings the natural
//! frequencies, and at low speed (the paper's two-shaft model at 60 rpm: the mesh period is
//! 771 natural periods long) the harmonics up to 1.5 times the resonance order are needed. Such
//! a scene is linear time-invariant between the jumps, and its periodic solution is known in
//! closed form there:
//!
//! **On a piece** `θ_p <= θ < θ_{p+1}` (`θ = Ω t`) with constant `K_p`, `D_p`, the motion is
//! the piece's own steady state under the harmonic loads, `q_p(θ) = Re Σ_k Q_k^p e^{ikθ}` with
//! `Z_p(kΩ) Q_k^p = F_k`, `Z_p(ω) = K_p + iω D_p - ω² M` (a harmonic balance of an LTI
//! system, exact with the loads' orders), plus a free motion: in the state `x = (q, q̇)`,
//!
//! `x(t) = x_p(t) + e^{A_p (t - t_p)} h_p`, `A_p = [0 I; -M⁻¹K_p -M⁻¹D_p]`.
//!
//! **Matching.** `q` and `q̇` are continuous at a jump (the force stays bounded), so
//! `x(t_{p+1}) = x_p(t_{p+1}) + Φ_p (x(t_p) - x_p(t_p))` with `Φ_p = e^{A_p τ_p}`; over the
//! period `x(T) = Φ x(0) + c`, and periodicity gives `(I - Φ) x(0) = c`: one dense solve of
//! size 2n (`Φ` is the monodromy matrix; `I - Φ` is regular unless a Floquet multiplier is 1).
//!
//! **Harmonics.** `Q_l = (Ω/π) ∫_0^T q(t) e^{-ilΩt} dt` for `l >= 1` and the mean
//! `Q_0 = (Ω/2π) ∫_0^T q(t) dt` (one-sided), piece by piece, exactly: the steady-state parts through the Fourier coefficients of the piece's
//! window, the free motion through
//! `∫_0^τ e^{(A - s) r} dr h = (A - s)⁻¹ (e^{-sτ} Φ h - h)`, `s = ilΩ`, whose displacement
//! part is `y = -Z_p(lΩ)⁻¹ (M r_v + (D_p + sM) r_q)` for `r = (r_q, r_v)`: one complex n × n
//! solve per harmonic and piece configuration. Nothing is truncated and nothing sampled; the
//! harmonics `0..=H` are exact to rounding, at any speed.
//!
//! **In time.** The same closed form gives the solution anywhere in the period:
//! [`ExactSolution::extremes`] ([`waveform`]) finds the extremes of every DOF, element
//! coordinate and force, and the mean forces, from it rather than from the harmonics
//! `0..=H` (at 60 rpm the two-shaft model's largest deflection is 38 % above what the
//! harmonics 0..32 show).
//!
//! **Scaling.** The exponentials, `Φ` and the periodicity solve work in the scaled state
//! `(q, q̇/ω_s)`, `ω_s` the highest natural frequency's estimate, so that the solve's pivots
//! (and the rounding estimate made from them) do not depend on the time unit.
//!
//! **Free bodies.** A model that floats free (rigid-body modes, [`crate::model::RigidModes`])
//! has its rigid motion separated exactly and the rest shifted to a regular system
//! ([`free_body`]): the mean rigid position is zero, as with harmonic balance.
//!
//! **What it refuses.** A law that is not linear with piecewise-constant coefficients, more
//! than [`PiecewiseExact::MAX_DOFS`] DOFs, and a model that floats free under mean loads that
//! do not balance. [`PiecewiseExact::check`] tells in advance.
//!
//! ```
//! use hbal::catalog::TwoShaft;
//! use hbal::solve::PiecewiseExact;
//! use hbal::HarmonicBasis;
//! let shaft = TwoShaft::new(60.0);
//! let basis = HarmonicBasis::new(shaft.mesh_omega(), 32)?;
//! let exact = PiecewiseExact::new().solve_exact(&shaft.model()?, &basis)?;
//! // The static deflection under L0 = 10 N m, between 10/5e5 and 10/2.5e5 rad:
//! let mean = exact.solution.harmonic(0, 0).re;
//! assert!(mean > 2e-5 && mean < 4e-5);
//! assert!(exact.estimate.kept_harmonics < 1e-12);
//! # Ok::<(), hbal::Error>(())
//! ```

use super::accuracy::ErrorEstimate;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::{Solution, SolveStats, Termination};
use crate::HarmonicBasis;
use num_complex::Complex64;
use std::time::Instant;

mod admission;
mod factor;
pub mod free_body;
mod periodic;
mod phasors;
mod schedule;
pub mod waveform;

use periodic::Periodic;
use schedule::Schedule;
use waveform::Waveform;
pub use waveform::{ElementExtremes, ExactExtremes, Range};

/// The exact solver for linear scenes with piecewise-constant coefficients
/// ([module docs](self)); scene files name it `method = "piecewise_exact"`.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PiecewiseExact {}

/// An exact solution with its error estimate.
#[derive(Debug, Clone)]
pub struct ExactSolution {
    /// The harmonics `0..=H` of the basis.
    pub solution: Solution,
    /// `relative`: the content of the harmonics `H+1..=L` (what the basis lacks), relative to
    /// the harmonics `0..=L`, where `L` (`reference_harmonics`) is at least `2H` and, as far
    /// as the work budget allows, four times the highest natural frequency (estimated from the
    /// diagonal of `M⁻¹K`), where the jumps ring; where the budget stops `L` short of that,
    /// `lower_bound` is set (the content beyond `L` is not counted). `kept_harmonics`: a rough
    /// rounding estimate of the periodicity solve, machine precision times the ratio of the
    /// largest to the smallest pivot of `I - Φ` in the scaled state (not a bound; the harmonics
    /// themselves are exact). Both at least 1e-15.
    pub estimate: ErrorEstimate,
    /// The Floquet multipliers, the eigenvalues of the monodromy matrix `Φ`, by decreasing
    /// modulus: exact to rounding (a linear scene's stability does not depend on the orbit).
    /// The orbit is stable if all lie inside the unit circle. A model that floats free has
    /// two more per rigid-body mode, exactly 1, counted in `neutral` and left out.
    pub multipliers: Vec<Complex64>,
    /// Multipliers exactly 1 of the rigid-body motion (two per mode), left out.
    pub neutral: usize,
    /// The closed form, for [`ExactSolution::extremes`].
    waveform: std::sync::Arc<Waveform>,
}

impl ExactSolution {
    /// The extremes of every DOF, element coordinate and element force over the exact
    /// periodic solution, and the elements' mean forces, from the closed form in time (not
    /// from the harmonics `0..=H`, which lack the ringing above H): see
    /// [`waveform`] for the method.
    ///
    /// ```
    /// use hbal::catalog::TwoShaft;
    /// use hbal::solve::PiecewiseExact;
    /// use hbal::HarmonicBasis;
    /// let shaft = TwoShaft::new(60.0);
    /// let exact = PiecewiseExact::new()
    ///     .solve_exact(&shaft.model()?, &HarmonicBasis::new(shaft.mesh_omega(), 32)?)?;
    /// let x = exact.extremes();
    /// // The mesh carries the mean load L0 = 10 N m exactly.
    /// assert!((x.elements[0].force_mean - 10.0).abs() < 1e-9);
    /// // The largest deflection lies above the one-tooth static deflection 10/2.5e5.
    /// assert!(x.dofs[0].1 > 10.0 / 2.5e5);
    /// # Ok::<(), hbal::Error>(())
    /// ```
    pub fn extremes(&self) -> ExactExtremes {
        self.waveform.extremes()
    }

    /// The stability of the orbit: the exact monodromy matrix's multipliers (no shooting, no
    /// orbit to correct; a free body's multipliers 1 counted as neutral).
    pub fn floquet(&self) -> crate::stability::Floquet {
        crate::stability::Floquet {
            multipliers: self.multipliers.clone(),
            neutral: self.neutral,
            orbit_correction: 0.0,
            polished: true,
            orbit_start: Vec::new(),
            steps: 0,
            reduction: None,
            orbit: crate::stability::Orbit::Exact,
            orbit_difference: None,
            orbit_distance: 0.0,
            other_orbit: None,
        }
    }

    /// The exact `q_i(θ_j)` at `θ_j = 2π j / points` (`[i][j]`), from the closed form.
    pub fn time_series(&self, points: usize) -> Vec<Vec<f64>> {
        self.waveform.time_series(points)
    }

    /// The harmonics `0..points/2` (of the forcing period; on a period-ν basis at `kν`) of the
    /// closed form in time, harmonic-major (`Q[k n + i]`),
    /// from `points` samples of [`ExactSolution::time_series`] (rounded up to an even number,
    /// at least 4): with the ringing after each stiffness jump that the harmonics `0..=H` of
    /// [`ExactSolution::solution`] leave out, up to the aliasing of content above `points/2`.
    /// `hbal compare` compares them per quantity with the time domain's.
    pub fn series_harmonics(&self, points: usize) -> Result<Vec<Complex64>> {
        let points = points.max(4).next_multiple_of(2);
        let h = points / 2 - 1;
        let own = self.solution.basis();
        // The closed form's period is the forcing period: order j sits at harmonic jν of a
        // period-ν basis.
        let nu = own.subharmonic();
        let basis = HarmonicBasis::new(own.omega(), h)?.with_samples(points)?;
        let plan = crate::harmonic::AftPlan::new(basis);
        let mut scratch = plan.make_scratch();
        let series = self.time_series(points);
        let n = series.len();
        let mut out = vec![Complex64::default(); (h * nu + 1) * n];
        let mut one = vec![Complex64::default(); h + 1];
        for (i, mut x) in series.into_iter().enumerate() {
            plan.analyze_into(&mut x, &mut one, &mut scratch);
            for (k, c) in one.iter().enumerate() {
                out[k * nu * n + i] = *c;
            }
        }
        Ok(out)
    }

    /// Samples a period needs to show the fastest motion (16 per period of the highest
    /// natural frequency's estimate or of the highest load order), at least 256 and at most
    /// 65536 or what the work budget allows (about 760 for 256 DOFs).
    pub fn resolving_points(&self) -> usize {
        let s = &self.waveform.schedule;
        let per = (16.0 * self.waveform.fastest() / s.omega).ceil();
        // Work about 8 n² per sample, within SERIES_WORK.
        let affordable = SERIES_WORK / (8.0 * (s.n * s.n) as f64);
        (per.min(65536.0).min(affordable) as usize).max(256)
    }
}

impl PiecewiseExact {
    /// Largest model in DOFs: the monodromy matrix is dense, 2n × 2n, and its exponentials cost
    /// `(2n)³` each.
    pub const MAX_DOFS: usize = 256;

    /// The solver.
    pub fn new() -> Self {
        Self {}
    }

    /// `Ok` if this solver can solve `model`, else the error [`PiecewiseExact::solve_exact`]
    /// would give (naming the element that is not linear with piecewise-constant
    /// coefficients, or the size).
    pub fn check(model: &Model) -> Result<()> {
        schedule::check(model)
    }

    /// The method's run-time interface: the exact solution in the basis of `hb` (no start
    /// needed, no iteration).
    pub fn solve_from_option(
        &self,
        hb: &HarmonicBalance,
        _initial: Option<&[Complex64]>,
        _ws: &mut Workspace,
    ) -> Result<Solution> {
        Ok(self.solve_exact(hb.model(), hb.basis())?.solution)
    }

    /// The exact solution's harmonics `0..=H` in `basis`, and its estimate from the harmonics
    /// `H+1..=L` ([`ExactSolution::estimate`]). An error names the element that is not linear
    /// with piecewise-constant coefficients, a model above [`PiecewiseExact::MAX_DOFS`], a
    /// model that floats free under mean loads that do not balance, or the harmonic where a
    /// piece's `Z_p` is singular (an undamped resonance at a load's or a harmonic's
    /// frequency).
    pub fn solve_exact(&self, model: &Model, basis: &HarmonicBasis) -> Result<ExactSolution> {
        let start = Instant::now();
        let nu = basis.subharmonic();
        let h = basis.harmonics();
        // A singular Z_p is reported at the basis's harmonic (order l of Ω is harmonic l ν).
        let in_basis = |e: Error| match e {
            Error::SingularDynamicStiffness {
                harmonic,
                omega,
                relative_pivot,
                hint,
            } => Error::SingularDynamicStiffness {
                harmonic: harmonic * nu,
                omega,
                relative_pivot,
                hint,
            },
            e => e,
        };
        let schedule = Schedule::new(model, basis.omega()).map_err(in_basis)?;
        let n = schedule.n;
        // Orders of Ω computed: those the basis holds (harmonic j is order j/ν), and for the
        // estimate of what it lacks at least twice as many, up to four times the highest
        // natural frequency (where a jump's ringing lives) as far as the work budget allows.
        let ringing = (4.0 * schedule.highest_frequency() / basis.omega()).ceil();
        let per_order = schedule.configurations.len() * n * n * n + schedule.pieces.len() * n * n;
        let affordable = (ESTIMATE_WORK / per_order.max(1) as f64).floor();
        let orders = ((2 * h).div_ceil(nu) as f64).max(ringing.min(affordable)) as usize;
        let lower_bound = (orders as f64) < ringing;
        let periodic = schedule.periodic_state().map_err(in_basis)?;
        let exact = schedule.harmonics(&periodic, orders).map_err(in_basis)?;
        let mut harmonics = vec![Complex64::new(0.0, 0.0); (h + 1) * n];
        let mut kept = 0.0;
        let mut all = 0.0;
        for l in 0..=orders {
            let weight = if l == 0 { 1.0 } else { 0.5 };
            let block = &exact[l * n..(l + 1) * n];
            let energy: f64 = block.iter().map(|c| c.norm_sqr()).sum::<f64>() * weight;
            all += energy;
            if l * nu <= h {
                kept += energy;
                harmonics[l * nu * n..(l * nu + 1) * n].copy_from_slice(block);
            }
        }
        if !all.is_finite() {
            return Err(Error::NonFinite {
                what: "the exact piecewise solution".into(),
            });
        }
        let missing = if all > 0.0 {
            ((all - kept).max(0.0) / all).sqrt()
        } else {
            0.0
        };
        let rounding = (f64::EPSILON * periodic.condition).max(1e-15);
        let estimate = ErrorEstimate {
            relative: missing.max(rounding),
            kept_harmonics: rounding,
            reference_harmonics: orders * nu,
            lower_bound,
            worst_quantity: None,
            worst_force: None,
            quadrature: None,
        };
        // The exact solution has harmonics above H: an element's force from the kept ones
        // balances the equation of motion only with the tail correction's part (see
        // `report::element_outputs`), on unless the basis turns it off.
        let basis = basis.with_tail_correction(basis.tail_correction_setting().unwrap_or(true));
        let solution = Solution {
            basis,
            dofs: model.dof_names().to_vec(),
            harmonics,
            termination: Termination::Converged,
            history: vec![periodic.closure],
            history_seconds: vec![start.elapsed().as_secs_f64()],
            stats: SolveStats {
                iterations: 1,
                factorizations: 1,
                ..SolveStats::default()
            },
            wall_time: start.elapsed(),
        };
        let neutral = 2 * schedule.rigid_modes();
        let Periodic {
            free_start,
            free_end,
            multipliers,
            ..
        } = periodic;
        let waveform = Waveform {
            schedule,
            free_start,
            free_end,
            weights: model
                .elements()
                .iter()
                .map(|e| e.weights().to_vec())
                .collect(),
        };
        Ok(ExactSolution {
            solution,
            estimate,
            multipliers,
            neutral,
            waveform: std::sync::Arc::new(waveform),
        })
    }
}

/// The work (about `points × 8 n²` operations) of [`ExactSolution::resolving_points`].
const SERIES_WORK: f64 = 4e8;

/// The work (about `L × configurations × n³` operations) the estimate may spend on orders
/// beyond 2H.
const ESTIMATE_WORK: f64 = 2e7;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_estimate;
