//! Stability of a periodic solution: Floquet multipliers from the monodromy matrix.
//!
//! The variational equation of `M q̈ + D q̇ + K q + Σ w f(θ, w·q, w·q̇) = f(t)` about a periodic
//! solution `q*(t)` is `ż = A(t) z`, `z = (δq, δq̇)`, with
//!
//! `A(t) = [[0, I], [-M⁻¹ (K + Σ w k(t) wᵀ), -M⁻¹ (D + Σ w d(t) wᵀ)]]`,
//! `k(t) = ∂f/∂u`, `d(t) = ∂f/∂u̇` at `(Ω t, w·q*, w·q̇*)`.
//!
//! The monodromy matrix `Φ(T)` solves `Φ̇ = A(t) Φ`, `Φ(0) = I`, over one period; its
//! eigenvalues are the Floquet multipliers. hbal integrates it together with the orbit itself
//! ([`flow`](self) module: Dormand–Prince 5(4) with error control, the step limited by the
//! fastest time scale of the model along the orbit, restarted at every time jump of a law and at
//! every kink crossing, with the saltation matrix where a force jumps). It starts on the
//! harmonic-balance orbit and polishes it by Newton shooting, `x₀ ← x₀ - (Φ - I)⁻¹ (φ_T(x₀) -
//! x₀)`, so the multipliers belong to the exact periodic orbit next to the HB solution, to the
//! integrator's tolerance, whatever H; the size of that correction
//! ([`Floquet::orbit_correction`]) measures the HB solution's own error at `t = 0`.
//!
//! Rigid-body modes give multipliers that are exactly 1 by construction; they are identified
//! from the model ([`Floquet::neutral`]) and left out of [`Floquet::multipliers`] and the
//! stability decision. The solution is stable if every other multiplier lies inside the unit
//! circle (up to [`STABILITY_MARGIN`]). A multiplier leaving through +1 is a fold (or a
//! symmetry-breaking branch point), through −1 a period doubling, a complex pair a
//! Neimark–Sacker bifurcation.
//!
//! ```
//! use hbal::force::CubicSpring;
//! use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
//! // A Duffing oscillator far from resonance: one stable orbit.
//! let model = Model::builder(&["x"])
//!     .mass_diagonal(&[1.0])
//!     .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.02))
//!     .element("spring", &[("x", 1.0)], CubicSpring::new(1.0, 1.0))
//!     .load("x", 1, 0.1, 0.0)
//!     .build()?;
//! let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.5, 7)?)?;
//! let solution = Newton::new().solve(&hb, &mut hb.workspace())?;
//! let floquet = hbal::stability::floquet(&model, &solution)?;
//! assert!(floquet.is_stable());
//! // The product of the multipliers is det Φ = exp(-c T / m) (Liouville):
//! let product: f64 = floquet.multipliers.iter().map(|m| m.norm()).product();
//! // (to the integrator's default tolerance, rtol 1e-8: here 1e-7)
//! assert!((product - (-0.02 * std::f64::consts::TAU / 0.5_f64).exp()).abs() < 1e-6);
//! # Ok::<(), hbal::Error>(())
//! ```

mod dopri;
mod flow;
mod neutral;

use crate::error::{Error, Result};
use crate::model::Model;
use crate::solution::Solution;
use dopri::Stepper;
use flow::{Flow, FlowOptions};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// A multiplier counts as outside the unit circle once its modulus exceeds `1 + margin`.
pub const STABILITY_MARGIN: f64 = 1e-6;

/// How a multiplier sits relative to the unit circle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bifurcation {
    /// Real multiplier near +1.
    Fold,
    /// Real multiplier near −1.
    PeriodDoubling,
    /// A real multiplier through +1 where the branch does not turn: a symmetry-breaking
    /// (pitchfork) or transcritical branch point, where another branch crosses. Set by the
    /// continuation, which sees the branch's geometry.
    BranchPoint,
    /// Complex pair on the unit circle.
    NeimarkSacker,
}

/// Floquet multipliers of a periodic solution.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Floquet {
    /// The multipliers that decide stability, largest modulus first (neutral ones excluded).
    pub multipliers: Vec<Complex64>,
    /// Multipliers that are exactly 1 by construction (two per rigid-body mode), left out.
    #[serde(default)]
    pub neutral: usize,
    /// `max_i |x₀,i - x₀*,i| / s_i`: how far the shooting moved the HB state at `t = 0` to reach
    /// the exact periodic orbit, relative to the state scales (`s_q` the largest `|q|`, `s_v`
    /// the same times the fastest frequency). An independent error estimate of the HB orbit.
    #[serde(default)]
    pub orbit_correction: f64,
    /// `true` if Newton shooting converged; otherwise the multipliers are those along the
    /// orbit started from the HB state (still accurate to about the HB error).
    #[serde(default)]
    pub polished: bool,
    /// The state `(q, q̇)` at `t = 0` of the orbit the multipliers belong to (the exact
    /// periodic orbit when [`Floquet::polished`]).
    #[serde(default)]
    pub orbit_start: Vec<f64>,
    /// Integration steps (accepted, rejected and event re-steps) over all periods integrated.
    #[serde(default)]
    pub steps: usize,
}

impl Floquet {
    /// Largest modulus.
    pub fn max_abs(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |m| m.norm())
    }

    /// `true` if every multiplier lies inside the unit circle: `max |μ| <= 1 +`
    /// [`STABILITY_MARGIN`].
    pub fn is_stable(&self) -> bool {
        self.max_abs() <= 1.0 + STABILITY_MARGIN
    }

    /// Number of real multipliers greater than 1 (a fold or branch point changes it by one).
    pub fn real_unstable(&self) -> usize {
        self.multipliers
            .iter()
            .filter(|m| m.im.abs() <= 1e-9 * m.norm().max(1.0) && m.re > 1.0)
            .count()
    }

    /// The kind of the critical multiplier (the one of largest modulus), by where it sits on
    /// the unit circle: argument within 0.1 rad of 0 (fold), of π (period doubling), else
    /// Neimark–Sacker.
    pub fn critical(&self) -> Option<Bifurcation> {
        let m = *self.multipliers.first()?;
        let angle = m.arg().abs();
        Some(if angle < 0.1 {
            Bifurcation::Fold
        } else if angle > std::f64::consts::PI - 0.1 {
            Bifurcation::PeriodDoubling
        } else {
            Bifurcation::NeimarkSacker
        })
    }
}

/// Options of the Floquet analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloquetOptions {
    /// Relative tolerance of the integrator. Default 1e-8 (multipliers to about 1e-7 or better).
    pub rtol: f64,
    /// Newton shooting iterations (0: the multipliers along the orbit started from the HB
    /// state). Default 6.
    pub max_shooting: usize,
    /// Steps per period before giving up. Default 2 000 000.
    pub max_steps: usize,
}

impl Default for FloquetOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            max_shooting: 6,
            max_steps: 2_000_000,
        }
    }
}

/// Floquet multipliers of `solution` (a periodic solution of `model`) with the default
/// [`FloquetOptions`].
pub fn floquet(model: &Model, solution: &Solution) -> Result<Floquet> {
    FloquetOptions::default().compute(model, solution)
}

impl FloquetOptions {
    /// Defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// The multipliers of the periodic orbit of `model` next to `solution`.
    pub fn compute(&self, model: &Model, solution: &Solution) -> Result<Floquet> {
        if !(self.rtol > 1e-15 && self.rtol < 1e-2) {
            return Err(Error::invalid(
                "floquet",
                "rtol",
                self.rtol,
                "in (1e-15, 1e-2)",
            ));
        }
        let n = model.n_dofs();
        if solution.harmonics().len() < n || solution.dof_names().len() != n {
            return Err(Error::DimensionMismatch {
                context: "floquet".into(),
                expected: format!("a solution with {n} DOFs"),
                got: format!("{} DOFs", solution.dof_names().len()),
            });
        }
        // The monodromy matrix is dense (2n × 2n): refuse what would not fit.
        model.dense("stability (Floquet multipliers)")?;
        let omega = solution.basis().omega();
        let (scale_q, omega_max) = scales(model, solution);
        let scale_v = scale_q * omega_max;
        let mut flow = Flow::new(model, omega, scale_q, scale_v, self.rtol)?;
        let opts = FlowOptions {
            rtol: self.rtol,
            h_max: 1.0 / omega_max,
            max_steps: self.max_steps,
        };
        let s2 = 2 * n;
        let scale = |i: usize| if i < n { scale_q } else { scale_v };
        let mut x0: Vec<f64> = (0..n)
            .map(|i| solution.displacement(i, 0.0))
            .chain((0..n).map(|i| solution.velocity(i, 0.0)))
            .collect();
        if x0.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "initial state of the Floquet analysis".into(),
            });
        }
        let x_hb = x0.clone();
        let rigid = neutral::rigid_body_modes(model);
        let (positions, all) = neutral::state_bases(&rigid);
        let free_positions = neutral::complement(&positions, s2);
        let mut stepper = Stepper::new(flow.len());
        let mut y = vec![0.0; flow.len()];
        let mut phi = DMatrix::<f64>::zeros(s2, s2);
        let mut polished = false;
        let mut last_residual = f64::INFINITY;
        let mut iteration = 0;
        loop {
            y[..s2].copy_from_slice(&x0);
            y[s2..].fill(0.0);
            for i in 0..s2 {
                y[s2 + i * s2 + i] = 1.0;
            }
            // A period-multiplied orbit: ν excitation periods (the system is T-periodic).
            for _ in 0..solution.basis().subharmonic() {
                flow.period(&mut y, &opts, &mut stepper)?;
            }
            phi.copy_from_slice(&y[s2..]);
            if phi.iter().any(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "monodromy matrix".into(),
                });
            }
            // Scaled shooting residual r̃ = S⁻¹ (φ_T(x₀) - x₀).
            let r = DVector::from_fn(s2, |i, _| (y[i] - x0[i]) / scale(i));
            let res = r.amax();
            // Converged to the integration noise, or Newton has stalled there.
            if res <= 10.0 * self.rtol {
                polished = true;
                break;
            }
            if iteration >= self.max_shooting || !res.is_finite() || res >= 0.5 * last_residual {
                polished = res <= 1e3 * self.rtol;
                break;
            }
            last_residual = res;
            iteration += 1;
            // (Φ̃ - I) δ̃ = -r̃ with δ̃ orthogonal to rigid-body positions.
            let a = (&phi - DMatrix::<f64>::identity(s2, s2)) * &free_positions;
            let svd = a.svd(true, true);
            let tol = 1e-13 * svd.singular_values.max();
            let Ok(z) = svd.solve(&(-&r), tol) else {
                break;
            };
            let delta = &free_positions * z;
            for i in 0..s2 {
                x0[i] += delta[i] * scale(i);
            }
        }
        let orbit_correction = (0..s2)
            .map(|i| (x0[i] - x_hb[i]).abs() / scale(i))
            .fold(0.0, f64::max);
        let multipliers = if all.ncols() == 0 {
            eigenvalues(&phi)
        } else {
            let w = neutral::complement(&all, s2);
            eigenvalues(&(w.transpose() * &phi * &w))
        };
        if multipliers
            .iter()
            .any(|m| !(m.re.is_finite() && m.im.is_finite()))
        {
            return Err(Error::NonFinite {
                what: "Floquet multipliers".into(),
            });
        }
        Ok(Floquet {
            multipliers,
            neutral: all.ncols(),
            orbit_correction,
            polished,
            orbit_start: x0,
            steps: flow.steps,
        })
    }
}

/// Eigenvalues sorted by modulus, largest first.
fn eigenvalues(a: &DMatrix<f64>) -> Vec<Complex64> {
    let mut m: Vec<Complex64> = a.complex_eigenvalues().iter().copied().collect();
    m.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    m
}

/// `(s_q, ω_max)`: the largest displacement of the orbit (1 if it is zero) and the fastest
/// angular frequency along it, `max(Ω, sqrt(λ_max(M⁻¹K(t))) + λ_max(M⁻¹D(t))/2)` over the HB
/// samples, which also limits the integrator's step to `1/ω_max`.
fn scales(model: &Model, solution: &Solution) -> (f64, f64) {
    let n = model.n_dofs();
    let omega = solution.basis().omega();
    let samples = solution.basis().samples().max(16);
    let (series, rates) = sampled_orbit(solution, samples);
    let mut scale_q = series
        .iter()
        .flat_map(|s| s.iter())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if !(scale_q.is_finite() && scale_q > 0.0) {
        scale_q = 1.0;
    }
    // Largest and smallest element stiffness and damping along the orbit, from the samples.
    let mut k_max = model.structural_stiffness().to_dense();
    let mut d_max = model.structural_damping().to_dense();
    let (mut q, mut v) = (vec![0.0; n], vec![0.0; n]);
    for e in model.elements() {
        let (mut km, mut dm) = (0.0_f64, 0.0_f64);
        for j in 0..samples {
            // The shaft angle Ωt at sample j (ν times the fundamental's).
            let theta = std::f64::consts::TAU
                * ((j * solution.basis().subharmonic()) % samples) as f64
                / samples as f64;
            for i in 0..n {
                q[i] = series[i][j];
                v[i] = rates[i][j];
            }
            let (k, d) = e.law().derivatives(theta, e.gather(&q), e.gather(&v));
            km = km.max(k.abs());
            dm = dm.max(d.abs());
        }
        let mean = e.linear_part();
        e.add_outer(&mut k_max, km.max(mean.stiffness.abs()));
        e.add_outer(&mut d_max, dm.max(mean.damping.abs()));
    }
    let mut omega_max = omega;
    if let Some(chol) = model.mass().to_dense().cholesky() {
        if let Some(l_inv) = chol.l().try_inverse() {
            let largest = |a: &DMatrix<f64>| {
                let s = &l_inv * a * l_inv.transpose();
                let s = (&s + s.transpose()) * 0.5;
                s.symmetric_eigenvalues()
                    .iter()
                    .fold(0.0_f64, |m, v| m.max(v.abs()))
            };
            let w = largest(&k_max).sqrt() + 0.5 * largest(&d_max);
            if w.is_finite() {
                omega_max = omega_max.max(w);
            }
        }
    }
    (scale_q, omega_max)
}

/// `(q_i(θ_j), q̇_i(θ_j))` at `samples` equidistant angles, by the recurrence
/// `e^{ikθ} = e^{iθ} e^{i(k-1)θ}` (one sine and cosine per sample).
fn sampled_orbit(solution: &Solution, samples: usize) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let n = solution.dof_names().len();
    let h = solution.basis().harmonics();
    let omega = solution.basis().fundamental();
    let harmonics = solution.harmonics();
    let mut q = vec![vec![0.0; samples]; n];
    let mut v = vec![vec![0.0; samples]; n];
    for j in 0..samples {
        let step = Complex64::from_polar(1.0, std::f64::consts::TAU * j as f64 / samples as f64);
        let mut rot = Complex64::new(1.0, 0.0);
        for i in 0..n {
            q[i][j] = harmonics[i].re;
        }
        for k in 1..=h {
            rot *= step;
            for i in 0..n {
                let z = harmonics[k * n + i] * rot;
                q[i][j] += z.re;
                v[i][j] -= k as f64 * omega * z.im;
            }
        }
    }
    (q, v)
}
