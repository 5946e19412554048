//! The monodromy action `x ↦ Φ(T) x` of the HB orbit's variational equation in the model's own
//! sparse matrices, for the Arnoldi iteration of models with many modes in the excitation band
//! ([`FloquetMethod::Arnoldi`](crate::stability::FloquetMethod::Arnoldi)).
//!
//! Along the HB orbit `q*(t)` the variational equation is
//!
//! `M δq̈ + (D0 + Σ_e w_e Δd_e(t) w_eᵀ) δq̇ + (K0 + Σ_e w_e Δk_e(t) w_eᵀ) δq = 0`,
//!
//! `Δk_e = ∂f_e/∂u - k0_e`, `Δd_e = ∂f_e/∂u̇ - d0_e` at `(Ω t, w_e·q*, w_e·q̇*)`: sparse `K0`,
//! `D0` and one rank-one term per time-varying or nonlinear element. It is integrated over one
//! orbit period by the classical Runge–Kutta method, restarted at every time jump of a law (a
//! rectangular mesh stiffness), in steps short enough that the fastest motion (a Gershgorin
//! bound, the contact stiffness included) keeps its amplitude to 0.1 % over a period and the
//! slow ones that usually decide stability far better (`step_bound`). `Δk_e`, `Δd_e` are evaluated at every stage time from the HB orbit's harmonics.
//! One action costs `8·steps` sparse products: no `2n × 2n` matrix is formed. A coefficient
//! that jumps inside a step (a contact closing or opening) costs that step first order; [`krylov_floquet`](super::krylov_floquet)'s tests measure the result against the dense monodromy on small models.
//!
//! The state is scaled, `x = (δq, δq̇/ω_ref)`, so the Krylov vectors weigh displacements and
//! velocities alike (the eigenvalues are those of `Φ`).

use crate::error::Result;
use crate::model::Model;
use crate::solution::Solution;
use crate::stability::linear_rate::{gershgorin, inverse_diagonal_mass, LinearRate};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The variational equation of one HB orbit, ready to be integrated.
pub(crate) struct VariationalAction {
    n: usize,
    linear: LinearRate,
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
    /// The action along `solution` of `model`, each step of `step_bound` cut into
    /// `subdivision`; `None` where it does not apply (a law with memory, a mass matrix that is
    /// not diagonal).
    pub(crate) fn new(
        model: &Model,
        solution: &Solution,
        subdivision: usize,
    ) -> Result<Option<Self>> {
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
        // The fastest motion and the fastest decay: Gershgorin on M⁻¹(K0 + Σ max(Δk, 0) w wᵀ)
        // and M⁻¹(D0 + Σ max(Δd, 0) w wᵀ), the terms sampled coarsely.
        let coarse: Vec<Vec<(f64, f64)>> =
            (0..256).map(|j| at(period * j as f64 / 256.0)).collect();
        let weights: Vec<&[(usize, f64)]> = elements.iter().map(|e| e.weights()).collect();
        let top = |part: fn(&(f64, f64)) -> f64| -> Vec<f64> {
            (0..elements.len())
                .map(|e| coarse.iter().map(|s| part(&s[e])).fold(0.0, f64::max))
                .collect()
        };
        let w_max = gershgorin(&k0, &inv_mass, &weights, &top(|t| t.0))
            .sqrt()
            .max(basis.fundamental());
        let d_max = gershgorin(&d0, &inv_mass, &weights, &top(|t| t.1));
        // Segments between the laws' time jumps (in the shaft angle Ωt, every revolution of
        // the orbit's period) and the orbit's kink crossings, each in steps of at most h_max.
        let h_max = period
            / ((period / step_bound(period, w_max, d_max)).ceil().max(64.0)
                * subdivision.max(1) as f64);
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
            linear: LinearRate::new(&k0, &d0, &inv_mass),
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
        self.linear.apply(q, v, dv);
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
                dv[i] -= self.inv_mass[i] * wi * f;
            }
        }
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

/// The longest Runge–Kutta step for a period `period`, fastest motion `w_max` and fastest
/// decay rate `d_max` (Gershgorin bounds).
///
/// Over one period the classical Runge–Kutta method damps a motion of frequency `ω` by the
/// factor `|R(ihω)|^{T/h}`, `R(z) = 1 + z + z²/2 + z³/6 + z⁴/24`, `1 − |R(iy)| ≈ y⁶/144`: the
/// relative loss `(hω)⁵ ωT / 144` grows as `ω⁶`, so it is bounded by [`DISSIPATION`] for the
/// fastest motion and the slow motions that usually decide stability are far more exact (their
/// phase error `(hω)⁴ ωT / 120` likewise). The step also keeps `h (ω_max + d_max)` inside the
/// method's stability region (`|z| ≤ 2`, the region reaches 2.8 on both axes).
fn step_bound(period: f64, w_max: f64, d_max: f64) -> f64 {
    let phase = (144.0 * DISSIPATION / (w_max * period)).powf(0.2);
    (phase / w_max).min(2.0 / (w_max + d_max))
}

/// The largest relative loss of amplitude per period the integration may give the fastest
/// motion: a true multiplier of modulus 1 there is found above `1 − DISSIPATION`.
const DISSIPATION: f64 = 1e-3;
