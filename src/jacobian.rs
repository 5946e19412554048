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

/// Scratch of the assembly: the bins `ĝ_m`, `m = -H..=2H`, of both derivatives, and one local
/// column.
#[derive(Debug, Clone)]
pub(crate) struct JacobianScratch {
    ext_u: Vec<Complex64>,
    ext_du: Vec<Complex64>,
    column: Vec<f64>,
}

impl JacobianScratch {
    pub(crate) fn new(h: usize) -> Self {
        Self {
            ext_u: vec![Complex64::default(); 3 * h + 1],
            ext_du: vec![Complex64::default(); 3 * h + 1],
            column: vec![0.0; 2 * h + 1],
        }
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
    scratch: &mut JacobianScratch,
) {
    for (i, (eu, ed)) in scratch
        .ext_u
        .iter_mut()
        .zip(scratch.ext_du.iter_mut())
        .enumerate()
    {
        let m = i as i64 - h as i64;
        *eu = bin(spec_u, samples, m);
        *ed = bin(spec_du, samples, m);
    }
    let rows = jac.nrows();
    let data = jac.as_mut_slice(); // column-major
    for l in 0..=h {
        let lw = l as f64 * omega;
        for part in [Part::Cos, Part::Sin] {
            if l == 0 && part == Part::Sin {
                continue;
            }
            // Local column of a_l or b_l: rows a_k, b_k for k = 0..=H.
            for k in 0..=h {
                // ĝ_{k-l} at index k - l + H, ĝ_{k+l} at index k + l + H.
                let (um, up) = (scratch.ext_u[k + h - l], scratch.ext_u[k + l + h]);
                let (dm, dp) = (scratch.ext_du[k + h - l], scratch.ext_du[k + l + h]);
                // a_l: (ĝu_- + ĝu_+)/2 + i lΩ (ĝu̇_- - ĝu̇_+)/2;
                // b_l: -i (ĝu_- - ĝu_+)/2 + lΩ (ĝu̇_- + ĝu̇_+)/2.
                let d = match part {
                    Part::Cos => {
                        let s = um + up;
                        let t = dm - dp;
                        Complex64::new(0.5 * (s.re - lw * t.im), 0.5 * (s.im + lw * t.re))
                    }
                    Part::Sin => {
                        let s = um - up;
                        let t = dp + dm;
                        Complex64::new(0.5 * (s.im + lw * t.re), 0.5 * (-s.re + lw * t.im))
                    }
                };
                if k == 0 {
                    scratch.column[0] = d.re;
                } else {
                    scratch.column[2 * k - 1] = 2.0 * d.re;
                    scratch.column[2 * k] = -2.0 * d.im;
                }
            }
            add_local_column(
                &scratch.column,
                RealLayout::block(l, part),
                weights,
                n,
                data,
                rows,
            );
        }
    }
}

/// `jac += (w wᵀ) ⊗ column` in the columns of block `cb`: the local column (rows in the real
/// layout of one coordinate, `2H+1`) of the element's unknown `cb` spread over its DOFs.
/// `data` is the column-major storage of the Jacobian with `rows` rows.
#[inline]
pub(crate) fn add_local_column(
    column: &[f64],
    cb: usize,
    weights: &[(usize, f64)],
    n: usize,
    data: &mut [f64],
    rows: usize,
) {
    for &(j, wj) in weights {
        let col = &mut data[(cb * n + j) * rows..(cb * n + j + 1) * rows];
        for &(i, wi) in weights {
            let w = wi * wj;
            if n == 1 {
                for (x, c) in col.iter_mut().zip(column) {
                    *x += w * c;
                }
            } else {
                for (r, c) in column.iter().enumerate() {
                    col[r * n + i] += w * c;
                }
            }
        }
    }
}
