//! The exact Jacobian of the AFT rest of one element.
//!
//! With `g_u = ∂f/∂u - k0`, `g_u̇ = ∂f/∂u̇ - d0` sampled at `θ_j` and their normalised DFT bins
//! `ĝ_m` (periodic in N, `ĝ_{-m} = conj ĝ_m`), the discrete harmonic `k` of
//! `g_u ∂u/∂x + g_u̇ ∂u̇/∂x` for the local unknowns of `u = Σ a_l cos lθ + b_l sin lθ` is
//!
//! - column `a_l`: `D = (ĝu_{k-l} + ĝu_{k+l})/2 - lΩ (ĝu̇_{k-l} - ĝu̇_{k+l})/(2i)`,
//! - column `b_l`: `D = (ĝu_{k-l} - ĝu_{k+l})/(2i) + lΩ (ĝu̇_{k-l} + ĝu̇_{k+l})/2`,
//!
//! from `cos lθ · e^{-ikθ}` and `sin lθ · e^{-ikθ}` shifting the spectrum by `±l`. The rows are
//! `a_k = 2 Re D` (`Re D` for k = 0) and `b_k = -2 Im D`. This is the derivative of the sampled
//! residual itself (aliasing included), so Newton converges quadratically on it; it costs two
//! FFTs and `O(H²)` per element instead of `2H+1` FFTs.

use crate::harmonic::{Part, RealLayout};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// `ĝ_m` for `|m| < N` (always true here: `|k ± l| <= 2H < N`), without integer division.
#[inline]
fn bin(g: &[Complex64], samples: usize, m: i64) -> Complex64 {
    let (a, conj) = if m < 0 {
        ((-m) as usize, true)
    } else {
        (m as usize, false)
    };
    let v = if a < g.len() {
        g[a]
    } else {
        g[samples - a].conj()
    };
    if conj {
        v.conj()
    } else {
        v
    }
}

/// `jac += (w wᵀ) ⊗ L` for one element, from the DFT bins of its derivative samples.
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_element_jacobian(
    spec_u: &[Complex64],
    spec_du: &[Complex64],
    samples: usize,
    h: usize,
    omega: f64,
    weights: &[(usize, f64)],
    n: usize,
    jac: &mut DMatrix<f64>,
) {
    let half_i = Complex64::new(0.0, -0.5); // 1/(2i)
    for l in 0..=h {
        let lw = l as f64 * omega;
        for k in 0..=h {
            let (km, kp) = (k as i64 - l as i64, (k + l) as i64);
            let (um, up) = (bin(spec_u, samples, km), bin(spec_u, samples, kp));
            let (dm, dp) = (bin(spec_du, samples, km), bin(spec_du, samples, kp));
            let col_a = (um + up) * 0.5 - (dm - dp) * half_i * lw;
            let col_b = (um - up) * half_i + (dm + dp) * (0.5 * lw);
            let scale = if k == 0 { 1.0 } else { 2.0 };
            let row_a = RealLayout::block(k, Part::Cos);
            let row_b = RealLayout::block(k, Part::Sin);
            let ca = RealLayout::block(l, Part::Cos);
            let cb = RealLayout::block(l, Part::Sin);
            let mut entries = [
                (row_a, ca, scale * col_a.re),
                (0, 0, 0.0),
                (0, 0, 0.0),
                (0, 0, 0.0),
            ];
            let mut count = 1;
            if k > 0 {
                entries[count] = (row_b, ca, -2.0 * col_a.im);
                count += 1;
            }
            if l > 0 {
                entries[count] = (row_a, cb, scale * col_b.re);
                count += 1;
                if k > 0 {
                    entries[count] = (row_b, cb, -2.0 * col_b.im);
                    count += 1;
                }
            }
            if let [(i, wi)] = weights {
                // One-DOF element: no weight products.
                for &(rb, cbk, v) in &entries[..count] {
                    jac[(rb * n + i, cbk * n + i)] += wi * wi * v;
                }
            } else {
                for &(rb, cbk, v) in &entries[..count] {
                    for &(i, wi) in weights {
                        for &(j, wj) in weights {
                            jac[(rb * n + i, cbk * n + j)] += wi * wj * v;
                        }
                    }
                }
            }
        }
    }
}
