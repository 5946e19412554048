//! The monodromy action `x ↦ Φ(T) x` of the HB orbit's variational equation in the model's own
//! sparse matrices, for the Arnoldi iteration of models with many modes in the excitation band
//! ([`FloquetMethod::Arnoldi`](super::FloquetMethod::Arnoldi)).
//!
//! Along the HB orbit `q*(t)` the variational equation is
//!
//! `M δq̈ + (D0 + Σ_e w_e Δd_e(t) w_eᵀ) δq̇ + (K0 + Σ_e w_e Δk_e(t) w_eᵀ) δq = 0`,
//!
//! `Δk_e = ∂f_e/∂u - k0_e`, `Δd_e = ∂f_e/∂u̇ - d0_e` at `(Ω t, w_e·q*, w_e·q̇*)`: sparse `K0`,
//! `D0` and one rank-one term per time-varying or nonlinear element. It is integrated over one
//! orbit period by the classical Runge–Kutta method, restarted at every time jump of a law (a
//! rectangular mesh stiffness), in steps of at most `h = 0.25/ω_max` (`ω_max` a Gershgorin
//! bound of the fastest motion, the contact stiffness included): the fastest mode
//! keeps its amplitude to 0.4 % over a period, the slow ones that decide stability to far
//! better. `Δk_e`, `Δd_e` are evaluated at every stage time from the HB orbit's harmonics.
//! One action costs `8·steps` sparse products: no `2n × 2n` matrix is formed. A coefficient
//! that jumps inside a step (a contact closing or opening) costs that step first order; [`leading`] measures the result against the dense monodromy on small models.
//!
//! The state is scaled, `x = (δq, δq̇/ω_ref)`, so the Krylov vectors weigh displacements and
//! velocities alike (the eigenvalues are those of `Φ`).

use crate::error::Result;
use crate::model::{Model, SparseMatrix};
use crate::solution::Solution;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The variational equation of one HB orbit, ready to be integrated.
pub(crate) struct VariationalAction {
    n: usize,
    k0: SparseMatrix,
    d0: SparseMatrix,
    inv_mass: Vec<f64>,
    /// Weights of the time-varying or nonlinear elements.
    weights: Vec<Vec<(usize, f64)>>,
    /// The length of every step.
    lengths: Vec<f64>,
    /// `(Δk_e, Δd_e)` per element at the start, middle and end of every step (each taken
    /// inside the step's segment), `[(step · 3 + stage) · m + e]`.
    terms: Vec<(f64, f64)>,
    omega_ref: f64,
}

impl VariationalAction {
    /// The action along `solution` of `model`; `None` where it does not apply (a law with
    /// memory, a mass matrix that is not diagonal).
    pub(crate) fn new(model: &Model, solution: &Solution) -> Result<Option<Self>> {
        if model.memory_element().is_some() {
            return Ok(None);
        }
        let n = model.n_dofs();
        let Some(inv_mass) = inverse_diagonal_mass(model) else {
            return Ok(None);
        };
        let elements: Vec<&crate::model::Element> = model
            .elements()
            .iter()
            .filter(|e| !e.law().is_linear_time_invariant())
            .collect();
        let basis = solution.basis();
        let period = TAU / basis.fundamental();
        let (k0, d0) = (model.k0(), model.d0());
        // Element coordinates' harmonics U_k = Σ w_i Q_ki.
        let h_max = basis.harmonics();
        let coords: Vec<Vec<Complex64>> = elements
            .iter()
            .map(|e| {
                (0..=h_max)
                    .map(|k| {
                        e.weights()
                            .iter()
                            .map(|&(i, w)| solution.harmonic(i, k) * w)
                            .sum()
                    })
                    .collect()
            })
            .collect();
        let at = |t: f64| -> Vec<(f64, f64)> {
            let theta = basis.fundamental() * t;
            elements
                .iter()
                .zip(&coords)
                .map(|(e, u)| {
                    let (mut x, mut v) = (0.0, 0.0);
                    for (k, uk) in u.iter().enumerate() {
                        let z = uk * Complex64::from_polar(1.0, k as f64 * theta);
                        x += z.re;
                        v -= k as f64 * basis.fundamental() * z.im;
                    }
                    let (du, ddu) = e.law().derivatives(basis.omega() * t, x, v);
                    let lin = e.linear_part();
                    (du - lin.stiffness, ddu - lin.damping)
                })
                .collect()
        };
        // The fastest motion: Gershgorin on M⁻¹(K0 + Σ max(Δk, 0) w wᵀ), sampled coarsely.
        let coarse: Vec<Vec<(f64, f64)>> =
            (0..256).map(|j| at(period * j as f64 / 256.0)).collect();
        let mut rows = absolute_row_sums(&k0);
        for (e, element) in elements.iter().enumerate() {
            let top = coarse.iter().map(|s| s[e].0).fold(0.0, f64::max);
            let sum: f64 = element.weights().iter().map(|(_, w)| w.abs()).sum();
            for &(i, w) in element.weights() {
                rows[i] += top * w.abs() * sum;
            }
        }
        let w_max = rows
            .iter()
            .zip(&inv_mass)
            .map(|(r, m)| r * m)
            .fold(0.0, f64::max)
            .sqrt()
            .max(basis.fundamental());
        // Segments between the laws' time jumps (in the shaft angle Ωt, every revolution of
        // the orbit's period) and the orbit's kink crossings, each in steps of at most
        // PHASE_STEP/ω_max.
        let h_max = period / ((period * w_max / PHASE_STEP).ceil()).max(64.0);
        let mut times: Vec<f64> = (0..basis.subharmonic())
            .flat_map(|r| {
                crate::timesim::segment_bounds(model)
                    .into_iter()
                    .map(move |b| (r as f64 * TAU + b) / basis.omega())
            })
            .collect();
        for (e, u) in elements.iter().zip(&coords) {
            let position = |t: f64| -> f64 {
                let theta = basis.fundamental() * t;
                u.iter()
                    .enumerate()
                    .map(|(k, uk)| (uk * Complex64::from_polar(1.0, k as f64 * theta)).re)
                    .sum()
            };
            for kink in e.law().kinks() {
                let found = crossings(|t| position(t) - kink, period, h_max);
                // A force that jumps at the kink (contact damping) needs a saltation matrix,
                // which this flow does not apply: the dense methods do.
                for &t in &found {
                    let (theta, v) = (basis.omega() * t, velocity(u, basis.fundamental(), t));
                    let below = e
                        .law()
                        .derivatives(theta, kink - 1e-9 * kink.abs().max(1e-12), v)
                        .1;
                    let above = e
                        .law()
                        .derivatives(theta, kink + 1e-9 * kink.abs().max(1e-12), v)
                        .1;
                    if (below - above).abs() * v.abs() > 0.0 {
                        return Ok(None);
                    }
                }
                times.extend(found);
            }
        }
        times.sort_by(f64::total_cmp);
        times.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * period);
        let (mut lengths, mut terms) = (Vec::new(), Vec::new());
        {
            for w in times.windows(2) {
                let (a, b) = (w[0], w[1]);
                let count = ((b - a) / h_max).ceil().max(1.0) as usize;
                let h = (b - a) / count as f64;
                let inside = 1e-9 * (b - a);
                for j in 0..count {
                    let t0 = a + j as f64 * h;
                    lengths.push(h);
                    for t in [t0, t0 + 0.5 * h, t0 + h] {
                        terms.extend(at(t.clamp(a + inside, b - inside)));
                    }
                }
            }
        }
        Ok(Some(Self {
            n,
            k0,
            d0,
            inv_mass,
            weights: elements.iter().map(|e| e.weights().to_vec()).collect(),
            lengths,
            terms,
            omega_ref: (w_max * basis.fundamental()).sqrt(),
        }))
    }

    /// The state dimension `2n`.
    pub(crate) fn dim(&self) -> usize {
        2 * self.n
    }

    /// Runge–Kutta steps per action.
    pub(crate) fn steps(&self) -> usize {
        self.lengths.len()
    }

    /// `out = Φ(T) x` in the scaled state (module documentation).
    pub(crate) fn apply(&self, x: &[f64], out: &mut [f64]) -> Result<()> {
        let n = self.n;
        let mut z: Vec<f64> = x.to_vec();
        z[n..].iter_mut().for_each(|v| *v *= self.omega_ref);
        let mut k = [
            vec![0.0; 2 * n],
            vec![0.0; 2 * n],
            vec![0.0; 2 * n],
            vec![0.0; 2 * n],
        ];
        let mut tmp = vec![0.0; 2 * n];
        for (s, &h) in self.lengths.iter().enumerate() {
            self.rate(3 * s, &z, &mut k[0]);
            axpy(&z, 0.5 * h, &k[0], &mut tmp);
            self.rate(3 * s + 1, &tmp, &mut k[1]);
            axpy(&z, 0.5 * h, &k[1], &mut tmp);
            self.rate(3 * s + 1, &tmp, &mut k[2]);
            axpy(&z, h, &k[2], &mut tmp);
            self.rate(3 * s + 2, &tmp, &mut k[3]);
            for i in 0..2 * n {
                z[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
            }
        }
        if z.iter().any(|v| !v.is_finite()) {
            return Err(crate::Error::NonFinite {
                what: "the variational equation along the HB orbit".into(),
            });
        }
        out[..n].copy_from_slice(&z[..n]);
        for (o, v) in out[n..].iter_mut().zip(&z[n..]) {
            *o = v / self.omega_ref;
        }
        Ok(())
    }

    /// `ż` at stage index `s` (`3 · step + stage`).
    fn rate(&self, s: usize, z: &[f64], out: &mut [f64]) {
        let n = self.n;
        let (q, v) = z.split_at(n);
        let (dq, dv) = out.split_at_mut(n);
        dq.copy_from_slice(v);
        dv.fill(0.0);
        self.k0.mul_add(-1.0, q, dv);
        self.d0.mul_add(-1.0, v, dv);
        let m = self.weights.len();
        for (w, &(dk, dd)) in self.weights.iter().zip(&self.terms[s * m..(s + 1) * m]) {
            if dk == 0.0 && dd == 0.0 {
                continue;
            }
            let (u, du) = w.iter().fold((0.0, 0.0), |(a, b), &(i, wi)| {
                (a + wi * q[i], b + wi * v[i])
            });
            let f = dk * u + dd * du;
            for &(i, wi) in w {
                dv[i] -= wi * f;
            }
        }
        dv.iter_mut().zip(&self.inv_mass).for_each(|(a, m)| *a *= m);
    }
}

/// `u̇(t)` of the element coordinate with harmonics `u` at fundamental `w`.
fn velocity(u: &[Complex64], w: f64, t: f64) -> f64 {
    u.iter()
        .enumerate()
        .map(|(k, uk)| -(k as f64 * w) * (uk * Complex64::from_polar(1.0, k as f64 * w * t)).im)
        .sum()
}

/// The roots of `g` in `(0, period)`: sign changes on a grid of spacing at most `h`, each
/// refined by bisection to 1e-13 of the period.
fn crossings(g: impl Fn(f64) -> f64, period: f64, h: f64) -> Vec<f64> {
    let count = (period / h).ceil() as usize;
    let mut out = Vec::new();
    let mut previous = (0.0, g(0.0));
    for j in 1..=count {
        let t = period * j as f64 / count as f64;
        let value = g(t);
        if previous.1 * value < 0.0 {
            let (mut a, mut b, mut ga) = (previous.0, t, previous.1);
            while b - a > 1e-13 * period {
                let mid = 0.5 * (a + b);
                let gm = g(mid);
                if gm * ga <= 0.0 {
                    b = mid;
                } else {
                    (a, ga) = (mid, gm);
                }
            }
            out.push(0.5 * (a + b));
        }
        previous = (t, value);
    }
    out
}

/// `out = a + s b`.
fn axpy(a: &[f64], s: f64, b: &[f64], out: &mut [f64]) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = x + s * y;
    }
}

/// The largest step as a phase of the fastest motion, `h ω_max`: the Runge–Kutta error per
/// period is about `(h ω)⁴` relative for that motion.
const PHASE_STEP: f64 = 0.1;

/// Most Krylov vectors (monodromy actions) per analysis.
const MAX_VECTORS: usize = 120;

/// Agreement of the leading Ritz values between two checks, relative to the largest.
const RITZ_TOL: f64 = 1e-8;

/// The multipliers of largest modulus of the HB orbit `solution` of `model` by the Arnoldi
/// iteration on the monodromy action (module documentation); `None` where the action does not
/// apply (a law with memory, a mass matrix that is not diagonal, a force that jumps at a
/// kink the orbit crosses, a free-free model, whose neutral multipliers 1 the iteration would
/// not set apart).
pub(crate) fn floquet(model: &Model, solution: &Solution) -> Result<Option<super::Floquet>> {
    let Some(action) = VariationalAction::new(model, solution)? else {
        return Ok(None);
    };
    let k0 = model.k0();
    let factor = super::modes::ShiftedStiffness::new(
        &k0,
        model.mass(),
        crate::model::RigidModes::shift(model),
    )?;
    let solve = |x: &mut [f64]| {
        let mut m = nalgebra::DMatrix::from_column_slice(x.len(), 1, x);
        factor.solve_in_place(&mut m);
        x.copy_from_slice(m.as_slice());
    };
    if crate::model::RigidModes::find(model, solve).is_some() {
        return Ok(None);
    }
    let dim = action.dim();
    // A deterministic start with every component present.
    let start: Vec<f64> = (0..dim)
        .map(|i| 1.0 + 0.5 * (((i * 7919) % 997) as f64 / 997.0 - 0.5))
        .collect();
    let ritz = super::arnoldi::leading_eigenvalues(
        dim,
        |x, out| action.apply(x, out),
        &start,
        MAX_VECTORS,
        RITZ_TOL,
    )?;
    let top = ritz.values.first().map_or(0.0, |v| v.norm());
    let multipliers: Vec<Complex64> = ritz
        .values
        .iter()
        .copied()
        .filter(|v| v.norm() >= 1e-3 * top)
        .take(2 * super::arnoldi::LEADING)
        .collect();
    Ok(Some(super::Floquet {
        multipliers,
        neutral: 0,
        orbit_correction: 0.0,
        polished: false,
        orbit_start: super::shooting::hb_start(solution),
        steps: ritz.vectors * action.steps(),
        reduction: Some(super::Reduction {
            dofs: model.n_dofs(),
            modes: 0,
            attachment: 0,
            cutoff: f64::INFINITY,
            estimate: Some(ritz.change / top.max(f64::MIN_POSITIVE)),
            comparison_dofs: None,
            krylov: Some(ritz.vectors),
        }),
        orbit: super::Orbit::Harmonic,
        orbit_difference: None,
        orbit_distance: 0.0,
        other_orbit: None,
    }))
}

/// Smallest model whose multipliers [`FloquetMethod::Auto`](super::FloquetMethod::Auto) takes
/// from the Arnoldi iteration when every mode lies below the reduction's cut-off (a reduced
/// basis would keep them all: a dense `2n × 2n` monodromy matrix).
pub const ARNOLDI_FROM: usize = 256;

/// `true` if every natural frequency of `(K0, M)` lies below `cutoff` (rad/s) by Gershgorin's
/// bound `ω² ≤ max_i Σ_j |K0_ij| / M_ii` (a diagonal mass matrix; `false` otherwise).
pub(crate) fn every_mode_below(model: &Model, cutoff: f64) -> bool {
    let Some(inv_mass) = inverse_diagonal_mass(model) else {
        return false;
    };
    let bound = absolute_row_sums(&model.k0())
        .iter()
        .zip(&inv_mass)
        .map(|(r, m)| r * m)
        .fold(0.0, f64::max);
    bound <= cutoff * cutoff
}

/// `1 / M_ii` of a diagonal, positive mass matrix; `None` otherwise.
fn inverse_diagonal_mass(model: &Model) -> Option<Vec<f64>> {
    let mut inv = vec![0.0; model.n_dofs()];
    for (i, j, v) in model.mass().iter() {
        if i != j && v != 0.0 {
            return None;
        }
        if i == j {
            inv[i] = 1.0 / v;
        }
    }
    inv.iter().all(|v| v.is_finite() && *v > 0.0).then_some(inv)
}

/// `Σ_j |A_ij|` per row.
fn absolute_row_sums(a: &SparseMatrix) -> Vec<f64> {
    let mut rows = vec![0.0; a.n()];
    for (i, _, v) in a.iter() {
        rows[i] += v.abs();
    }
    rows
}
