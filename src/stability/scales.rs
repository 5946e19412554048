//! The scales of the shooting's state and the fastest time scale along the orbit, from the
//! HB orbit sampled in the integration coordinates.

use super::system::Coordinates;
use crate::solution::Solution;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// `(s_q, ω_max, amplitudes)` in the coordinates `sys`: the largest coordinate of the orbit (1
/// if it is zero), the fastest angular frequency along it,
/// `max(Ω, sqrt(λ_max(M⁻¹K(t))) + λ_max(M⁻¹D(t))/2)` over the HB samples, which also limits
/// the integrator's step to `1/ω_max`, and the largest `(|u_e|, |u̇_e|)` of every element.
/// `harmonics` are the orbit's in these coordinates.
pub(crate) fn scales(
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
