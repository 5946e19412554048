//! An independent evaluation of the Galerkin equations of harmonic balance, for checking the
//! AFT's quadrature: the element forces' harmonics `F_k = (1/π) ∫ f(θ, u, u̇) e^{-ikθ} dθ`
//! (`1/2π` for k = 0) by 16-point Gauss–Legendre on short sub-intervals of the pieces between
//! the kinks' crossings (found on 2^14 samples and refined by bisection) and the laws' time
//! jumps: exact to rounding for a law smooth on each piece, whatever the AFT does.

use hbal::force::ForceLaw;
use hbal::num_complex::Complex64;
use hbal::Model;
use std::f64::consts::{PI, TAU};

/// Gauss–Legendre nodes and weights on [-1, 1] (Newton on P_n).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|i| {
            let mut x = (PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    (p0, p1) = (p1, p2);
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / dp;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// `(u(θ), u̇(θ))` of the harmonics `uk` with fundamental `omega`.
fn synth(uk: &[Complex64], omega: f64, theta: f64) -> (f64, f64) {
    uk.iter().enumerate().fold((0.0, 0.0), |(u, v), (k, c)| {
        let z = c * Complex64::from_polar(1.0, k as f64 * theta);
        (u + z.re, v - k as f64 * omega * z.im)
    })
}

/// The angles in [0, 2π) where the law's pieces change along `u`: kink crossings and time jumps.
fn breaks(law: &dyn ForceLaw, uk: &[Complex64], omega: f64) -> Vec<f64> {
    const N: usize = 1 << 14;
    let mut out: Vec<f64> = law.time_breakpoints();
    let u: Vec<f64> = (0..=N)
        .map(|j| synth(uk, omega, TAU * j as f64 / N as f64).0)
        .collect();
    for kappa in law.kinks() {
        for j in 0..N {
            let (a, b) = (u[j] - kappa, u[j + 1] - kappa);
            if (a > 0.0) == (b > 0.0) {
                continue;
            }
            let (mut lo, mut hi) = (TAU * j as f64 / N as f64, TAU * (j + 1) as f64 / N as f64);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if (synth(uk, omega, mid).0 - kappa > 0.0) == (a > 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            out.push(0.5 * (lo + hi));
        }
    }
    out.iter_mut().for_each(|t| *t = t.rem_euclid(TAU));
    out.sort_by(f64::total_cmp);
    out
}

/// The harmonics `0..=h` of `f(θ, u(θ), u̇(θ))` along `uk` (shaft angle θ, fundamental Ω).
pub fn force_harmonics(
    law: &dyn ForceLaw,
    uk: &[Complex64],
    omega: f64,
    h: usize,
) -> Vec<Complex64> {
    let gl = gauss_legendre(16);
    let mut cuts = breaks(law, uk, omega);
    cuts.push(cuts.first().map_or(TAU, |c| c + TAU));
    if cuts.len() == 1 {
        cuts.insert(0, 0.0);
    }
    let longest = PI / (2.0 * (h + uk.len()) as f64);
    let mut out = vec![Complex64::default(); h + 1];
    for w in cuts.windows(2) {
        let chunks = ((w[1] - w[0]) / longest).ceil().max(1.0) as usize;
        let len = (w[1] - w[0]) / chunks as f64;
        for c in 0..chunks {
            let mid = w[0] + (c as f64 + 0.5) * len;
            for &(x, wt) in &gl {
                let t = mid + 0.5 * len * x;
                let (u, v) = synth(uk, omega, t);
                let f = law.force(t.rem_euclid(TAU), u, v) * wt * 0.5 * len;
                for (k, o) in out.iter_mut().enumerate() {
                    let scale = if k == 0 { 0.5 / PI } else { 1.0 / PI };
                    *o += f * scale * Complex64::from_polar(1.0, -(k as f64) * t);
                }
            }
        }
    }
    out
}

/// `max_k |R_k|_∞ / max |load|` of the Galerkin equations
/// `(-(kΩ)² M + ikΩ D + K) Q_k + Σ_e w_e F_{e,k} - L_k = 0`, `k = 0..=H`, at the harmonics `q`
/// (harmonic-major, ν = 1), with the element forces from [`force_harmonics`].
pub fn residual_relative_to_load(model: &Model, omega: f64, q: &[Complex64]) -> f64 {
    let (r, loads) = residual(model, omega, q);
    let largest = loads.iter().map(|l| l.norm()).fold(0.0, f64::max);
    r.iter().map(|c| c.norm()).fold(0.0, f64::max) / largest
}

/// The same residual in the Parseval norm `sqrt(Σ_i |R_0i|² + ½ Σ_{k≥1} |R_ki|²)` relative
/// to the load's (what hbal's relative residuals use).
pub fn parseval_residual_relative_to_load(model: &Model, omega: f64, q: &[Complex64]) -> f64 {
    let n = model.n_dofs();
    let parseval = |v: &[Complex64]| {
        v.iter()
            .enumerate()
            .map(|(j, c)| {
                if j < n {
                    c.norm_sqr()
                } else {
                    0.5 * c.norm_sqr()
                }
            })
            .sum::<f64>()
            .sqrt()
    };
    let (r, _) = residual(model, omega, q);
    let mut load = vec![Complex64::default(); q.len()];
    for l in model.loads() {
        if l.order * n + l.dof < load.len() {
            load[l.order * n + l.dof] += hbal::harmonic::from_cos_sin(l.cos, l.sin);
        }
    }
    parseval(&r) / parseval(&load)
}

/// The Galerkin residual `R_k` (harmonic-major) and the loads.
fn residual(model: &Model, omega: f64, q: &[Complex64]) -> (Vec<Complex64>, Vec<Complex64>) {
    let n = model.n_dofs();
    let h = q.len() / n - 1;
    let mut r = vec![Complex64::default(); q.len()];
    for k in 0..=h {
        let (kw, qk) = (k as f64 * omega, &q[k * n..(k + 1) * n]);
        let rk = &mut r[k * n..(k + 1) * n];
        for (i, j, m) in model.mass().iter() {
            rk[i] -= kw * kw * m * qk[j];
        }
        for (i, j, d) in model.structural_damping().iter() {
            rk[i] += Complex64::new(0.0, kw) * d * qk[j];
        }
        for (i, j, s) in model.structural_stiffness().iter() {
            rk[i] += s * qk[j];
        }
    }
    for e in model.elements() {
        let uk: Vec<Complex64> = (0..=h)
            .map(|k| e.weights().iter().map(|&(i, w)| q[k * n + i] * w).sum())
            .collect();
        let f = force_harmonics(e.law(), &uk, omega, h);
        for (k, fk) in f.iter().enumerate() {
            for &(i, w) in e.weights() {
                r[k * n + i] += fk * w;
            }
        }
    }
    let mut loads = Vec::new();
    for l in model.loads() {
        let load = hbal::harmonic::from_cos_sin(l.cos, l.sin);
        loads.push(load);
        if l.order <= h {
            r[l.order * n + l.dof] -= load;
        }
    }
    (r, loads)
}
