//! Newton shooting and the monodromy matrix in given coordinates (the model's DOFs or a reduced
//! basis, [`Coordinates`]): `x₀ ← x₀ - (Φ - I)⁻¹ (φ_T(x₀) - x₀)` from the HB state at `t = 0`
//! (projected onto the coordinates), then the multipliers of `Φ` without its neutral block.

use super::dopri::Stepper;
use super::exponential::ExpFlow;
use super::flow::{Flow, FlowOptions};
use super::system::Coordinates;
use super::{affine, eigenvalues, neutral, Floquet, FloquetOptions, Integrator};
use crate::error::{Error, Result};
use crate::solution::Solution;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Where the shooting starts.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Start<'a> {
    /// The HB state at `t = 0`.
    Hb,
    /// The HB state plus a correction `(δq, δq̇)` in the model's DOFs (a sweep's previous
    /// point's correction).
    Corrected(&'a [f64]),
    /// A state `(q, q̇)` in the model's DOFs (the exact orbit on another basis).
    State(&'a [f64]),
}

/// When the shooting stops.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Goal<'a> {
    /// At the exact periodic orbit (scaled residual below `10 rtol`).
    Exact,
    /// The comparison of the reduction's estimate: once the change of the multipliers that
    /// the next Newton step `δ̃` would bring, predicted as `κ ‖δ̃‖∞` with the sensitivity `κ`
    /// measured by the first analysis, is below 1 % of their distance to `reference`.
    Compare {
        reference: &'a [Complex64],
        kappa: f64,
    },
}

/// A Floquet analysis and the sensitivity of its multipliers to the orbit's start: `κ` =
/// the [`distance`] between the multipliers of the first two shooting iterations over the
/// first Newton step (`None` if the first period was already converged).
pub(crate) struct Shot {
    pub(crate) floquet: Floquet,
    pub(crate) kappa: Option<f64>,
}

/// The Floquet analysis of `solution` in the coordinates `sys`.
pub(crate) fn shoot(
    sys: &Coordinates,
    solution: &Solution,
    options: &FloquetOptions,
    start: Start,
    goal: Goal,
) -> Result<Shot> {
    let n_model = sys.model.n_dofs();
    let n = sys.len();
    let omega = solution.basis().omega();
    let h = solution.basis().harmonics();
    // The HB orbit's harmonics in these coordinates (real and imaginary parts projected).
    let harmonics: Vec<Complex64> = if sys.basis.is_none() {
        solution.harmonics()[..(h + 1) * n_model].to_vec()
    } else {
        let mut out = Vec::with_capacity((h + 1) * n);
        for k in 0..=h {
            let block = &solution.harmonics()[k * n_model..(k + 1) * n_model];
            let re = sys.project(&block.iter().map(|z| z.re).collect::<Vec<_>>());
            let im = sys.project(&block.iter().map(|z| z.im).collect::<Vec<_>>());
            out.extend(re.iter().zip(&im).map(|(&a, &b)| Complex64::new(a, b)));
        }
        out
    };
    let (scale_q, omega_max, amplitudes) = scales(sys, solution, &harmonics);
    let scale_v = scale_q * omega_max;
    let runge_kutta = || -> Result<Integration> {
        Ok(Integration::RungeKutta {
            flow: Flow::new(sys, omega, scale_q, scale_v, options.rtol)?,
            stepper: Stepper::new(2 * sys.len() * (1 + 2 * sys.len())),
            opts: FlowOptions {
                rtol: options.rtol,
                h_max: 1.0 / omega_max,
                max_steps: options.max_steps,
            },
        })
    };
    let mut flow = if options.integrator == Integrator::Auto
        && affine::piecewise_affine(sys.model, &amplitudes)
    {
        Integration::Exponential(ExpFlow::new(
            sys,
            omega,
            scale_q,
            scale_v,
            omega_max,
            options.max_steps,
        )?)
    } else {
        runge_kutta()?
    };
    let mut earlier_steps = 0;
    let s2 = 2 * n;
    let scale = |i: usize| if i < n { scale_q } else { scale_v };
    // The HB state at t = 0 in the model's DOFs and in these coordinates.
    let x_hb: Vec<f64> = (0..n_model)
        .map(|i| solution.displacement(i, 0.0))
        .chain((0..n_model).map(|i| solution.velocity(i, 0.0)))
        .collect();
    if x_hb.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "initial state of the Floquet analysis".into(),
        });
    }
    let usable = |s: &[f64]| s.len() == 2 * n_model && s.iter().all(|v| v.is_finite());
    let from: Vec<f64> = match start {
        Start::Corrected(d) if usable(d) => x_hb.iter().zip(d).map(|(a, b)| a + b).collect(),
        Start::State(s) if usable(s) => s.to_vec(),
        _ => x_hb.clone(),
    };
    let mut x0 = sys.project(&from[..n_model]);
    x0.extend(sys.project(&from[n_model..]));
    let rigid = neutral::rigid_body_modes(sys);
    let (positions, all) = neutral::state_bases(&rigid);
    let free_positions = neutral::complement(&positions, s2);
    // The multipliers of Φ̃ without its neutral block.
    let w = (all.ncols() > 0).then(|| neutral::complement(&all, s2));
    let multipliers_of = |phi: &DMatrix<f64>| match &w {
        None => eigenvalues(phi),
        Some(w) => eigenvalues(&(w.transpose() * phi * w)),
    };
    let mut first: Option<(Vec<Complex64>, f64)> = None;
    let mut kappa = None;
    let mut y = vec![0.0; s2 * (1 + s2)];
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
        let mut affine = true;
        for _ in 0..solution.basis().subharmonic() {
            affine = affine && flow.period(&mut y)?;
        }
        if !affine {
            // A law bent inside a piece: the Runge–Kutta flow from the same start.
            earlier_steps += flow.steps();
            flow = runge_kutta()?;
            continue;
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
        if let (1, Some((mu, step))) = (iteration, &first) {
            kappa = Some(distance(mu, &multipliers_of(&phi)) / step);
        }
        // Converged to the integration noise, or Newton has stalled there.
        if res <= 10.0 * options.rtol {
            polished = true;
            break;
        }
        if iteration >= options.max_shooting || !res.is_finite() || res >= 0.5 * last_residual {
            polished = res <= 1e3 * options.rtol;
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
        let step = delta.amax();
        if iteration == 1 && matches!(goal, Goal::Exact) {
            first = Some((multipliers_of(&phi), step));
        }
        if let Goal::Compare { reference, kappa } = goal {
            if kappa * step <= 0.01 * distance(reference, &multipliers_of(&phi)) {
                break;
            }
        }
        for i in 0..s2 {
            x0[i] += delta[i] * scale(i);
        }
    }
    // The exact orbit's start in the model's DOFs, against the HB state there.
    let mut orbit_start = sys.lift(&x0[..n]);
    orbit_start.extend(sys.lift(&x0[n..]));
    let full_scale_q = if sys.basis.is_none() {
        scale_q
    } else {
        // An upper bound of max |q_i(t)|: max_i Σ_k |Q_ik|.
        let bound = (0..n_model)
            .map(|i| (0..=h).map(|k| solution.harmonic(i, k).norm()).sum::<f64>())
            .fold(0.0, f64::max);
        if bound > 0.0 && bound.is_finite() {
            bound
        } else {
            1.0
        }
    };
    let full_scale = |i: usize| {
        if i < n_model {
            full_scale_q
        } else {
            full_scale_q * omega_max
        }
    };
    let orbit_correction = (0..2 * n_model)
        .map(|i| (orbit_start[i] - x_hb[i]).abs() / full_scale(i))
        .fold(0.0, f64::max);
    let multipliers = multipliers_of(&phi);
    if multipliers
        .iter()
        .any(|m| !(m.re.is_finite() && m.im.is_finite()))
    {
        return Err(Error::NonFinite {
            what: "Floquet multipliers".into(),
        });
    }
    Ok(Shot {
        floquet: Floquet {
            multipliers,
            neutral: all.ncols(),
            orbit_correction,
            polished,
            orbit_start,
            steps: earlier_steps + flow.steps(),
            reduction: None,
        },
        kappa,
    })
}

/// The larger of `max_i min_j |a_i - b_j|` over the leading `a_i` and the same over the
/// leading `b_j`, leading meaning a modulus at least half the largest of both sets (at most 8
/// from each): a multiplier that only one basis has counts with its distance to the other's
/// nearest.
pub(crate) fn distance(a: &[Complex64], b: &[Complex64]) -> f64 {
    let top = a
        .first()
        .map_or(0.0, |m| m.norm())
        .max(b.first().map_or(0.0, |m| m.norm()));
    let one_way = |a: &[Complex64], b: &[Complex64]| {
        a.iter()
            .take(8)
            .filter(|m| m.norm() >= 0.5 * top)
            .map(|m| b.iter().map(|o| (m - o).norm()).fold(m.norm(), f64::min))
            .fold(0.0, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}

/// The flow over a period: exponentials or Runge–Kutta.
enum Integration<'c, 'm> {
    RungeKutta {
        flow: Flow<'c, 'm>,
        stepper: Stepper,
        opts: FlowOptions,
    },
    Exponential(ExpFlow<'c, 'm>),
}

impl Integration<'_, '_> {
    /// One period of `y = (q, q̇, Φ̃)`; `Ok(false)` if the exponential flow met a law that is
    /// not affine on its piece.
    fn period(&mut self, y: &mut [f64]) -> Result<bool> {
        match self {
            Integration::RungeKutta {
                flow,
                stepper,
                opts,
            } => flow.period(y, opts, stepper).map(|()| true),
            Integration::Exponential(flow) => flow.period(y),
        }
    }

    fn steps(&self) -> usize {
        match self {
            Integration::RungeKutta { flow, .. } => flow.steps,
            Integration::Exponential(flow) => flow.steps,
        }
    }
}

/// `(s_q, ω_max, amplitudes)` in the coordinates `sys`: the largest coordinate of the orbit (1
/// if it is zero), the fastest angular frequency along it,
/// `max(Ω, sqrt(λ_max(M⁻¹K(t))) + λ_max(M⁻¹D(t))/2)` over the HB samples, which also limits
/// the integrator's step to `1/ω_max`, and the largest `(|u_e|, |u̇_e|)` of every element.
/// `harmonics` are the orbit's in these coordinates.
fn scales(
    sys: &Coordinates,
    solution: &Solution,
    harmonics: &[Complex64],
) -> (f64, f64, Vec<(f64, f64)>) {
    let n = sys.len();
    let omega = solution.basis().omega();
    let samples = solution.basis().samples().max(16);
    let (series, rates) = sampled_orbit(solution, harmonics, n, samples);
    let mut scale_q = series
        .iter()
        .flat_map(|s| s.iter())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if !(scale_q.is_finite() && scale_q > 0.0) {
        scale_q = 1.0;
    }
    // Largest and smallest element stiffness and damping along the orbit, from the samples.
    let mut k_max = sys.stiffness.clone();
    let mut d_max = sys.damping.clone();
    let (mut q, mut v) = (vec![0.0; n], vec![0.0; n]);
    let mut amplitudes = Vec::with_capacity(sys.weights.len());
    for (ei, e) in sys.model.elements().iter().enumerate() {
        let (mut km, mut dm) = (0.0_f64, 0.0_f64);
        let (mut au, mut adu) = (0.0_f64, 0.0_f64);
        for j in 0..samples {
            // The shaft angle Ωt at sample j (ν times the fundamental's).
            let theta = std::f64::consts::TAU
                * ((j * solution.basis().subharmonic()) % samples) as f64
                / samples as f64;
            for i in 0..n {
                q[i] = series[i][j];
                v[i] = rates[i][j];
            }
            let (u, du) = (sys.gather(ei, &q), sys.gather(ei, &v));
            let (k, d) = e.law().derivatives(theta, u, du);
            km = km.max(k.abs());
            dm = dm.max(d.abs());
            au = au.max(u.abs());
            adu = adu.max(du.abs());
        }
        amplitudes.push((au, adu));
        let mean = e.linear_part();
        for &(i, wi) in &sys.weights[ei] {
            for &(j, wj) in &sys.weights[ei] {
                k_max[(i, j)] += km.max(mean.stiffness.abs()) * wi * wj;
                d_max[(i, j)] += dm.max(mean.damping.abs()) * wi * wj;
            }
        }
    }
    let mut omega_max = omega;
    if let Some(chol) = sys.mass.clone().cholesky() {
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
    (scale_q, omega_max, amplitudes)
}

/// `(q_i(θ_j), q̇_i(θ_j))` of the `n` coordinates with `harmonics` (harmonic-major) at
/// `samples` equidistant angles, by the recurrence `e^{ikθ} = e^{iθ} e^{i(k-1)θ}` (one sine
/// and cosine per sample).
fn sampled_orbit(
    solution: &Solution,
    harmonics: &[Complex64],
    n: usize,
    samples: usize,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let h = solution.basis().harmonics();
    let omega = solution.basis().fundamental();
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
