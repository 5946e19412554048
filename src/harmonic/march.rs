//! The AFT of a law with memory: march the N periodic samples through the law's step until the
//! hysteresis loop closes, and chain the step derivatives into the derivatives of the forces.
//!
//! A pass applies `(f_j, s_j) = step(s_{j-1}; θ_j, u_j, u̇_j)` for `j = 0..N`, starting from the
//! state the previous pass ended in (the first from the law's initial state). The loop is
//! closed once a pass ends where it started, `max_r |s_N - s_0| <= 1e-12 · scale` (`scale` the
//! largest `|u_j|` or `|s|`, at least the smallest normal number); its forces are the periodic
//! ones. A Jenkins element closes after at most two passes (the slider position after a pass
//! that slips is set by the last slip, whatever it started from); the march gives up after
//! [`MAX_PASSES`].
//!
//! **Derivatives.** For directions `c = 0..C` of the unknowns with sample derivatives
//! `(∂u_j/∂x_c, ∂u̇_j/∂x_c) = dir(j, c)`, the state sensitivities `S_j = ∂s_j/∂x` start at 0 (the
//! initial state is a constant) and follow
//!
//! `∂f_j/∂x_c = f_u ∂u_j/∂x_c + f_u̇ ∂u̇_j/∂x_c + Σ_r f_{s,r} (S_{j-1})_{r,c}`,
//! `(S_j)_{r,c} = s_{u,r} ∂u_j/∂x_c + s_{u̇,r} ∂u̇_j/∂x_c + Σ_q s_{s,rq} (S_{j-1})_{q,c}`
//!
//! through every pass, so the result is the exact derivative of the forces the march returns
//! (the earlier passes included: they set the state the last pass starts from). The force at a
//! sample depends on earlier samples, so the harmonic block of the Jacobian is a general
//! `(2H+1)²` matrix; [`crate::residual`] projects the `N × C` sample derivatives `∂f_j/∂x_c` onto
//! the harmonics with one FFT per column. Cost `O(passes · N · C · state²)` plus `C` FFTs.

use crate::force::{Hysteresis, StepDerivatives, MAX_STATE};

/// The march gives up after this many passes over the period.
pub const MAX_PASSES: usize = 16;

/// Relative tolerance of the loop closure.
const CLOSURE: f64 = 1e-12;

/// The loop did not close: the passes made and the last change of the state over a pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NotClosed {
    /// Passes made ([`MAX_PASSES`]).
    pub passes: usize,
    /// `max_r |s_N - s_0|` of the last pass.
    pub change: f64,
}

/// Preallocated buffers of a march with derivatives: the state sensitivities (current and
/// next, `MAX_STATE × C`) and the sample derivatives `∂f_j/∂x_c` at `[c · N + j]`.
#[derive(Debug, Clone, Default)]
pub struct MarchBuffers {
    sens: Vec<f64>,
    next: Vec<f64>,
    /// `∂f_j/∂x_c` of the last pass at `[c · N + j]`.
    pub dfdx: Vec<f64>,
}

impl MarchBuffers {
    /// Buffers for `samples` samples and up to `columns` directions.
    pub fn new(samples: usize, columns: usize) -> Self {
        Self {
            sens: vec![0.0; MAX_STATE * columns],
            next: vec![0.0; MAX_STATE * columns],
            dfdx: vec![0.0; samples * columns],
        }
    }
}

/// Marches `law` over the samples `(θ_j, u_j, u̇_j)` until the loop closes; the forces of the
/// closed loop go into `f`. With `columns > 0` it also writes `∂f_j/∂x_c` for the directions
/// `dir(j, c)` into `b.dfdx` (`b` sized by [`MarchBuffers::new`] for at least `columns`).
/// Returns the number of passes.
#[allow(clippy::too_many_arguments)]
pub fn march(
    law: &dyn Hysteresis,
    theta: &[f64],
    u: &[f64],
    du: &[f64],
    f: &mut [f64],
    columns: usize,
    dir: impl Fn(usize, usize) -> (f64, f64),
    b: &mut MarchBuffers,
) -> Result<usize, NotClosed> {
    let (n, s) = (theta.len(), law.state_len().min(MAX_STATE));
    let mut state = [0.0; MAX_STATE];
    law.initial_state(&mut state[..s]);
    let scale = u.iter().map(|x| x.abs()).fold(f64::MIN_POSITIVE, f64::max);
    if columns > 0 {
        b.sens[..s * columns].fill(0.0);
    }
    let mut d = StepDerivatives::default();
    let mut change = f64::INFINITY;
    for pass in 1..=MAX_PASSES {
        let start = state;
        for j in 0..n {
            if columns == 0 {
                f[j] = law.step(theta[j], u[j], du[j], &mut state[..s]);
                continue;
            }
            f[j] = law.step_derivatives(theta[j], u[j], du[j], &mut state[..s], &mut d);
            for c in 0..columns {
                let (pu, pv) = dir(j, c);
                let mut df = d.df_du * pu + d.df_ddu * pv;
                for r in 0..s {
                    df += d.df_ds[r] * b.sens[r * columns + c];
                    let mut ds = d.ds_du[r] * pu + d.ds_ddu[r] * pv;
                    for q in 0..s {
                        ds += d.ds_ds[r][q] * b.sens[q * columns + c];
                    }
                    b.next[r * columns + c] = ds;
                }
                b.dfdx[c * n + j] = df;
            }
            std::mem::swap(&mut b.sens, &mut b.next);
        }
        change = (0..s)
            .map(|r| (state[r] - start[r]).abs())
            .fold(0.0, f64::max);
        let size = (0..s).map(|r| state[r].abs()).fold(scale, f64::max);
        if change <= CLOSURE * size {
            return Ok(pass);
        }
    }
    Err(NotClosed {
        passes: MAX_PASSES,
        change,
    })
}
