//! The linear part on the torus: `Z(ν) = -ν² M + i ν D0 + K0 (+ i H)` at every line
//! `ν_j = Ω (k_j·r)` of the index set, condensed exactly onto the element coordinates as in
//! the one-frequency engine ([`crate::linear::condensation`]):
//!
//! `G_j = Wᵀ Z_j⁻¹ W`, condensed load `L_j = G_j⁻¹ Wᵀ Z_j⁻¹ F_j`, and the balance
//! `G_j⁻¹ U_j + N_j(U) = L_j` in the m coordinates per line; the full response is
//! `Q_j = Z_j⁻¹ F_j - Z_j⁻¹ W N_j(U)`. Dense: one LU of `Z_j` (n × n) per line, for the
//! drivetrain-sized models the torus is for (a free-free model's static line is augmented as
//! in [`crate::model::rigid`]).

use super::IndexSet;
use crate::error::{Error, Result};
use crate::harmonic::SINGULAR_PIVOT;
use crate::model::DenseMatrices;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The factored, condensed linear part at one speed.
#[derive(Debug, Clone)]
pub(super) struct TorusLinear {
    m: usize,
    /// `Z_j⁻¹ [W | F_j]` per line (n × (m+1)).
    pub(super) solved: Vec<DMatrix<Complex64>>,
    /// `G_j⁻¹` per line (m × m).
    pub(super) stiffness: Vec<DMatrix<Complex64>>,
    /// `G_j = Wᵀ Z_j⁻¹ W` per line (m × m), the receptance of the fixed point.
    pub(super) receptance: Vec<DMatrix<Complex64>>,
    /// `L_j`, line-major (`j m + c`); in the receptance form the linear response `G_j L_j`.
    pub(super) load: Vec<Complex64>,
    /// The element coordinates are linearly dependent (`G_j` singular, a loop of meshes): the
    /// balance is written `U + G N(U) − G L = 0` and `stiffness` is empty.
    pub(super) receptance_form: bool,
}

impl TorusLinear {
    /// Factors `Z_j` at speed `omega` for every line of `set` (with `augmentation` added at
    /// `k = 0`), condenses onto the columns of `w` (n × m) with the full load `f` (line-major,
    /// `j n + i`).
    pub(super) fn new(
        dense: &DenseMatrices,
        augmentation: Option<&DMatrix<f64>>,
        set: &IndexSet,
        omega: f64,
        w: &DMatrix<f64>,
        f: &[Complex64],
    ) -> Result<Self> {
        let (n, m) = (w.nrows(), w.ncols());
        let wc = w.map(|v| Complex64::new(v, 0.0));
        let mut solved = Vec::with_capacity(set.len());
        let mut stiffness = Vec::with_capacity(set.len());
        let mut receptance = Vec::with_capacity(set.len());
        let mut load = Vec::with_capacity(set.len() * m);
        let mut linear_response = Vec::with_capacity(set.len() * m);
        let mut dependent = false;
        for j in 0..set.len() {
            let nu = omega * set.ratio(j);
            let (z, scale) = dynamic_stiffness(dense, nu, augmentation.filter(|_| j == 0));
            let lu = z.lu();
            check_pivots(lu.u().diagonal().iter().map(|p| p.norm()), scale, || {
                singular(set, j, nu)
            })?;
            let mut rhs = DMatrix::zeros(n, m + 1);
            rhs.columns_mut(0, m).copy_from(&wc);
            for i in 0..n {
                rhs[(i, m)] = f[j * n + i];
            }
            if !lu.solve_mut(&mut rhs) {
                return Err(singular(set, j, nu));
            }
            if m > 0 {
                let g = wc.transpose() * rhs.columns(0, m);
                let u_lin = wc.transpose() * rhs.column(m);
                linear_response.extend(u_lin.iter().copied());
                if !dependent {
                    let g_scale = g.iter().map(|v| v.norm()).fold(0.0, f64::max);
                    let g_lu = g.clone().lu();
                    let diagonal = g_lu.u().diagonal();
                    let pivots = diagonal.iter().map(|p| p.norm());
                    match check_pivots(pivots, g_scale, || singular(set, j, nu))
                        .ok()
                        .and_then(|_| g_lu.try_inverse())
                    {
                        Some(g_inv) => {
                            load.extend((&g_inv * &u_lin).iter().copied());
                            stiffness.push(g_inv);
                        }
                        // Dependent coordinates (a loop of meshes, as a planet's sun and ring
                        // meshes with the carrier): every line in the receptance form.
                        None => dependent = true,
                    }
                }
                receptance.push(g);
            }
            solved.push(rhs);
        }
        if dependent {
            stiffness.clear();
            load = linear_response;
        }
        Ok(Self {
            m,
            solved,
            stiffness,
            receptance,
            load,
            receptance_form: dependent,
        })
    }

    /// `out_j ← G_j⁻¹ x_j` (line-major, m per line); in the receptance form `out ← x`.
    pub(super) fn apply_stiffness(&self, x: &[Complex64], out: &mut [Complex64]) {
        let m = self.m;
        if self.receptance_form {
            out.copy_from_slice(x);
            return;
        }
        for (j, g) in self.stiffness.iter().enumerate() {
            for a in 0..m {
                out[j * m + a] = (0..m).map(|b| g[(a, b)] * x[j * m + b]).sum();
            }
        }
    }

    /// The full response `Q_j = Z_j⁻¹ F_j - Z_j⁻¹ W N_j` (line-major, n per line) of the
    /// condensed rest `rest` (line-major, m per line).
    pub(super) fn recover(&self, rest: &[Complex64]) -> Vec<Complex64> {
        let m = self.m;
        let mut out = Vec::new();
        for (j, x) in self.solved.iter().enumerate() {
            for i in 0..x.nrows() {
                let mut q = x[(i, m)];
                for c in 0..m {
                    q -= x[(i, c)] * rest[j * m + c];
                }
                out.push(q);
            }
        }
        out
    }
}

/// `Z(ν) = -ν² M + i ν D0 + K0`, with `+ i H` at `ν > 0` and `augmentation` added where given
/// (the static line of a free-free model), and the scale of its entries for the pivot test.
pub(super) fn dynamic_stiffness(
    dense: &DenseMatrices,
    nu: f64,
    augmentation: Option<&DMatrix<f64>>,
) -> (DMatrix<Complex64>, f64) {
    let n = dense.mass.nrows();
    let mut z = DMatrix::from_fn(n, n, |a, b| {
        Complex64::new(
            dense.k0[(a, b)] - nu * nu * dense.mass[(a, b)],
            nu * dense.d0[(a, b)],
        )
    });
    let mut scale = dense
        .k0
        .amax()
        .max(nu * nu * dense.mass.amax())
        .max(nu * dense.d0.amax());
    if let Some(a) = augmentation {
        z += a.map(|v| Complex64::new(v, 0.0));
    }
    if nu > 0.0 && dense.hysteretic.amax() > 0.0 {
        z += dense.hysteretic.map(|v| Complex64::new(0.0, v));
        scale = scale.max(dense.hysteretic.amax());
    }
    (z, scale)
}

/// An error from `err` where the smallest pivot is at most [`SINGULAR_PIVOT`] of `scale`.
fn check_pivots(
    pivots: impl Iterator<Item = f64>,
    scale: f64,
    err: impl FnOnce() -> Error,
) -> Result<()> {
    let min = pivots.fold(f64::INFINITY, f64::min);
    if !(scale.is_finite() && min.is_finite() && scale > 0.0 && min > SINGULAR_PIVOT * scale) {
        return Err(err());
    }
    Ok(())
}

fn singular(set: &IndexSet, j: usize, nu: f64) -> Error {
    Error::SingularDynamicStiffness {
        harmonic: j,
        omega: nu,
        relative_pivot: 0.0,
        hint: format!(
            "torus line {:?} at {nu} rad/s: {}",
            set.k(j),
            if j == 0 {
                "K0 is singular and not by a rigid-body mode; ground the motion or fix the DOF"
            } else {
                "an undamped natural frequency coincides with this line; add damping or shift the speed"
            }
        ),
    }
}
