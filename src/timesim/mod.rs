//! Time-domain reference: integrate the same [`Model`] with the same force laws until the
//! response is periodic.
//!
//! `M q̈ = f(t) - D q̇ - K q - Σ_e w_e f_e(Ω t, w_e·q, w_e·q̇)` is integrated from rest (or a given
//! state) with DOP853 (crate `differential-equations`), one period `T = 2π/Ω` at a time, until
//! two successive period-end states agree: `max_i |y_i(nT) - y_i((n-1)T)| / s_i < tol`, with the
//! state scales `s_i` of the linear frequency-domain solution. One more period is then sampled
//! at N equidistant times and its harmonics taken by FFT.
//!
//! Discontinuities: the integrator is restarted at every time jump a law declares
//! ([`ForceLaw::time_breakpoints`](crate::force::ForceLaw::time_breakpoints)), and inside a
//! segment the laws see angles clamped to it, so a rectangular mesh stiffness is integrated
//! exactly piecewise. State-dependent kinks (backlash contact) are left to the error control;
//! tighten `rtol` (or limit the step with `max_step`) to check them. Laws with memory
//! (a Jenkins slider) keep their state frozen over a step and commit it after the step, with a
//! restart where the frozen state stops being the true one (the module `timesim::memory` in the source).

mod memory;
mod period;
mod period_map;
mod rhs;
mod scale;

use crate::error::{Error, Result};
use crate::harmonic::{AftPlan, HarmonicBasis};
use crate::model::Model;
use num_complex::Complex64;
use rhs::Rhs;
use scale::state_scale;
use std::f64::consts::TAU;
use std::time::{Duration, Instant};

pub(crate) use period::segment_bounds;
pub(crate) use period_map::PeriodMap;

/// Options of the time-domain reference.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeSimulation {
    /// Relative tolerance of DOP853. Default 1e-10.
    pub rtol: f64,
    /// Steady state once successive period-end states differ by less than this (relative to the
    /// state scales). Default 1e-8.
    pub steady_tolerance: f64,
    /// Give up after this many periods. Default 100 000.
    pub max_periods: usize,
    /// Give up once the period-to-period difference has not improved on its best value for
    /// this many periods: the integration noise (set by `rtol`, worst at contact kinks) is above
    /// `steady_tolerance`. Default 200.
    pub stall_periods: usize,
    /// Samples of the final period (harmonics up to N/2 - 1 are returned). Default 1024.
    pub samples: usize,
    /// Largest step as a fraction of the period, if any. Default none.
    pub max_step: Option<f64>,
    /// Initial `(q, q̇)`; default rest.
    pub initial: Option<(Vec<f64>, Vec<f64>)>,
    /// Give up once the integrator has taken this many steps (checked after every period;
    /// [`TimeStop::StepLimit`]). Default none.
    pub max_steps: Option<usize>,
}

impl Default for TimeSimulation {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            steady_tolerance: 1e-8,
            max_periods: 100_000,
            stall_periods: 200,
            samples: 1024,
            max_step: None,
            initial: None,
            max_steps: None,
        }
    }
}

/// Why the time integration stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeStop {
    /// Successive periods agree to the steady tolerance.
    Steady,
    /// `max_periods` reached while the difference was still falling.
    MaxPeriods,
    /// The difference stopped falling above the steady tolerance (`stall_periods` without a new
    /// best): tighten `rtol` or loosen `steady_tolerance`.
    Stalled,
    /// `max_steps` reached before the difference met the steady tolerance.
    StepLimit,
}

/// The periodic response found by time integration.
#[derive(Debug, Clone)]
pub struct TimeResponse {
    /// Fundamental Ω (rad/s).
    pub omega: f64,
    /// DOF names.
    pub dofs: Vec<String>,
    /// `true` if the steady-state criterion was met.
    pub converged: bool,
    /// Why the integration stopped.
    pub stop: TimeStop,
    /// Periods integrated until steady state.
    pub periods: usize,
    /// Accepted plus rejected steps until steady state.
    pub steps: usize,
    /// Right-hand-side evaluations until steady state.
    pub rhs_evaluations: usize,
    /// Wall time until steady state (without the sampling period).
    pub wall_time: Duration,
    /// The last relative period-to-period difference.
    pub period_difference: f64,
    /// State scales `s_i` used for the tolerances (q then q̇).
    pub state_scale: Vec<f64>,
    /// `q_i(θ_j)` of the final period, `samples[i][j]`, `θ_j = 2π j / N`.
    pub samples: Vec<Vec<f64>>,
    /// Harmonics of the final period, harmonic-major (`Q[k * n + i]`), k = 0..N/2-1.
    pub harmonics: Vec<Complex64>,
    /// State `(q, q̇)` at the end.
    pub end_state: Vec<f64>,
}

impl TimeResponse {
    /// Number of harmonics in [`TimeResponse::harmonics`].
    pub fn max_harmonic(&self) -> usize {
        self.harmonics.len() / self.dofs.len() - 1
    }

    /// `Q_k` of DOF `dof` (zero above the sampled range).
    pub fn harmonic(&self, dof: usize, k: usize) -> Complex64 {
        self.harmonics
            .get(k * self.dofs.len() + dof)
            .copied()
            .unwrap_or_default()
    }
}

impl TimeSimulation {
    /// Defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// Integrates `model` at fundamental `omega` (rad/s) to its periodic steady state.
    pub fn run(&self, model: &Model, omega: f64) -> Result<TimeResponse> {
        self.validate()?;
        model.refuse_hysteretic("time simulation")?;
        model.check_load_speeds(omega, omega)?;
        crate::error::check_positive("time simulation", "omega", omega)?;
        let n = model.n_dofs();
        let period = TAU / omega;
        let scale = state_scale(model, omega);
        let atol: Vec<f64> = scale.iter().map(|s| 1e-3 * self.rtol * s).collect();
        let mut y = vec![0.0; 2 * n];
        if let Some((q0, v0)) = &self.initial {
            if q0.len() != n || v0.len() != n {
                return Err(Error::DimensionMismatch {
                    context: "initial state".into(),
                    expected: format!("{n} displacements and {n} velocities"),
                    got: format!("{} and {}", q0.len(), v0.len()),
                });
            }
            y[..n].copy_from_slice(q0);
            y[n..].copy_from_slice(v0);
        }
        let rhs = Rhs::new(model, omega)?;
        let bounds = segment_bounds(model);

        let start = Instant::now();
        let (mut steps, mut evals) = (0usize, 0usize);
        let mut periods = 0;
        let mut diff = f64::INFINITY;
        let (mut best, mut best_period) = (f64::INFINITY, 0);
        let mut stop = TimeStop::MaxPeriods;
        while periods < self.max_periods {
            let prev = y.clone();
            self.integrate_period(
                &rhs, &bounds, periods, period, &atol, &mut y, None, &mut steps, &mut evals,
            )?;
            periods += 1;
            diff = prev
                .iter()
                .zip(&y)
                .zip(&scale)
                .map(|((a, b), s)| (a - b).abs() / s)
                .fold(0.0, f64::max);
            if !diff.is_finite() {
                return Err(Error::NonFinite {
                    what: format!("time integration after {periods} periods"),
                });
            }
            if diff < self.steady_tolerance {
                stop = TimeStop::Steady;
                break;
            }
            if self.max_steps.is_some_and(|m| steps >= m) {
                stop = TimeStop::StepLimit;
                break;
            }
            if diff < best {
                (best, best_period) = (diff, periods);
            } else if periods - best_period >= self.stall_periods {
                stop = TimeStop::Stalled;
                break;
            }
        }
        let wall_time = start.elapsed();
        let converged = stop == TimeStop::Steady;

        // Sample one more period.
        let ns = self.samples;
        let mut samples = vec![vec![0.0; ns]; n];
        let (mut s2, mut e2) = (0, 0);
        self.integrate_period(
            &rhs,
            &bounds,
            periods,
            period,
            &atol,
            &mut y,
            Some(&mut samples),
            &mut s2,
            &mut e2,
        )?;
        let h = ns / 2 - 1;
        let basis = HarmonicBasis::new(omega, h)?.with_samples(ns)?;
        let plan = AftPlan::new(basis);
        let mut scratch = plan.make_scratch();
        let mut harmonics = vec![Complex64::default(); (h + 1) * n];
        let mut buf = vec![0.0; ns];
        let mut hk = vec![Complex64::default(); h + 1];
        for (i, s) in samples.iter().enumerate() {
            buf.copy_from_slice(s);
            plan.analyze_into(&mut buf, &mut hk, &mut scratch);
            for k in 0..=h {
                harmonics[k * n + i] = hk[k];
            }
        }
        Ok(TimeResponse {
            omega,
            dofs: model.dof_names().to_vec(),
            converged,
            stop,
            periods,
            steps,
            rhs_evaluations: evals,
            wall_time,
            period_difference: diff,
            state_scale: scale,
            samples,
            harmonics,
            end_state: y,
        })
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let ctx = "time simulation";
        if !(self.rtol.is_finite() && self.rtol > 0.0 && self.rtol < 1.0) {
            return Err(Error::invalid(ctx, "rtol", self.rtol, "in (0, 1)"));
        }
        crate::error::check_positive(ctx, "steady_tolerance", self.steady_tolerance)?;
        if self.stall_periods == 0 {
            return Err(Error::invalid(ctx, "stall_periods", 0.0, ">= 1"));
        }
        if self.samples < 8 {
            return Err(Error::invalid(ctx, "samples", self.samples as f64, ">= 8"));
        }
        if let Some(h) = self.max_step {
            crate::error::check_positive(ctx, "max_step", h)?;
        }
        Ok(())
    }
}
