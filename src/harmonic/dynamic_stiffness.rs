//! The dynamic stiffness `Z_k = -(kΩ)² M + i kΩ D0 + K0` per harmonic, factored once.

use super::HarmonicBasis;
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVectorViewMut, Dyn, LU};
use num_complex::Complex64;

/// Smallest accepted LU pivot relative to the scale of `Z_k`; below it `Z_k` counts as singular
/// (nalgebra's LU only reports exactly zero pivots).
pub const SINGULAR_PIVOT: f64 = 1e-11;

/// The error for a `Z_k` (or its LU) with a non-finite entry: not a resonance, but numbers
/// out of range (`(kΩ)² M` overflows).
pub(crate) fn non_finite_stiffness(k: usize, w: f64) -> Error {
    Error::NonFinite {
        what: format!(
            "the dynamic stiffness at harmonic {k} ({w:e} rad/s): the mass, damping or \
             stiffness times the frequency (squared) is out of range"
        ),
    }
}

/// `Z_k` and its LU factors for `k = 0..=H`.
#[derive(Debug, Clone)]
pub struct DynamicStiffness {
    n: usize,
    matrices: Vec<DMatrix<Complex64>>,
    factors: Vec<LU<Complex64, Dyn, Dyn>>,
}

impl DynamicStiffness {
    /// Builds and factors `Z_k`; an error names the first singular harmonic.
    pub fn new(
        basis: &HarmonicBasis,
        m: &DMatrix<f64>,
        d0: &DMatrix<f64>,
        k0: &DMatrix<f64>,
    ) -> Result<Self> {
        Self::with_static_augmentation(basis, m, d0, k0, None)
    }

    /// [`DynamicStiffness::new`] with `Z_0 = K0 + A` for a free-free model, `A = s M R Rᵀ M`
    /// ([`RigidModes::augmentation`](crate::model::RigidModes::augmentation)): regular, and
    /// its solutions are the static solutions `K0 q_0 = f_0` with `Rᵀ M q_0 = 0` (see
    /// [`crate::model::rigid`]). Harmonics `k >= 1` are unchanged.
    pub fn with_static_augmentation(
        basis: &HarmonicBasis,
        m: &DMatrix<f64>,
        d0: &DMatrix<f64>,
        k0: &DMatrix<f64>,
        augmentation: Option<&DMatrix<f64>>,
    ) -> Result<Self> {
        Self::build(basis, [m, d0, k0], augmentation, None)
    }

    /// `Z_k` of a model's dense matrices, with its hysteretic damping `H` (`+ i H` for
    /// `k >= 1`, [`crate::model::ModelBuilder::hysteretic`]) and the static augmentation of a
    /// free-free model, if any.
    pub fn of_model(
        basis: &HarmonicBasis,
        dense: &crate::model::DenseMatrices,
        augmentation: Option<&DMatrix<f64>>,
    ) -> Result<Self> {
        let h = (dense.hysteretic.amax() > 0.0).then_some(&dense.hysteretic);
        Self::build(basis, [&dense.mass, &dense.d0, &dense.k0], augmentation, h)
    }

    fn build(
        basis: &HarmonicBasis,
        [m, d0, k0]: [&DMatrix<f64>; 3],
        augmentation: Option<&DMatrix<f64>>,
        hysteretic: Option<&DMatrix<f64>>,
    ) -> Result<Self> {
        let n = m.nrows();
        let mut matrices = Vec::with_capacity(basis.harmonics() + 1);
        let mut factors = Vec::with_capacity(basis.harmonics() + 1);
        for k in 0..=basis.harmonics() {
            let w = k as f64 * basis.fundamental();
            let mut z = DMatrix::from_fn(n, n, |i, j| {
                Complex64::new(k0[(i, j)] - w * w * m[(i, j)], w * d0[(i, j)])
            });
            if let (0, Some(a)) = (k, augmentation) {
                z += a.map(|v| Complex64::new(v, 0.0));
            }
            let mut scale = k0.amax().max(w * w * m.amax()).max(w * d0.amax());
            if let (1.., Some(h)) = (k, hysteretic) {
                z += h.map(|v| Complex64::new(0.0, v));
                scale = scale.max(h.amax());
            }
            let lu = z.clone().lu();
            let u = lu.u();
            let pivots = (0..n).map(|i| u[(i, i)].norm());
            if !scale.is_finite() || pivots.clone().any(|p| !p.is_finite()) {
                return Err(non_finite_stiffness(k, w));
            }
            let min_pivot = pivots.fold(f64::INFINITY, f64::min);
            let relative_pivot = if scale > 0.0 { min_pivot / scale } else { 0.0 };
            if relative_pivot <= SINGULAR_PIVOT {
                let hint = if k == 0 {
                    "K0 is singular, but not by a rigid-body mode (free-free models and motions \
                     held only by damping to ground are handled): a motion held only by an \
                     element without linear stiffness, or a massless DOF; ground it with a \
                     stiffness or fix the DOF"
                        .to_string()
                } else {
                    format!(
                        "an undamped natural frequency at {w} rad/s coincides with harmonic {k}; \
                         add damping or shift the speed"
                    )
                };
                return Err(Error::SingularDynamicStiffness {
                    harmonic: k,
                    omega: w,
                    relative_pivot,
                    hint,
                });
            }
            matrices.push(z);
            factors.push(lu);
        }
        Ok(Self {
            n,
            matrices,
            factors,
        })
    }

    /// No harmonics (a placeholder until the real one is built).
    pub(crate) fn empty() -> Self {
        Self {
            n: 0,
            matrices: Vec::new(),
            factors: Vec::new(),
        }
    }

    /// Factors given matrices `Z_k`, `k = 0..=H` (all `n × n`): the condensed formulation's
    /// `G_k⁻¹` (harmonic k at `k·fundamental`). An error names the first singular harmonic.
    pub fn from_matrices(matrices: Vec<DMatrix<Complex64>>, fundamental: f64) -> Result<Self> {
        let n = matrices.first().map_or(0, |m| m.nrows());
        let mut factors = Vec::with_capacity(matrices.len());
        for (k, z) in matrices.iter().enumerate() {
            let scale = z.iter().map(|v| v.norm()).fold(0.0, f64::max);
            let lu = z.clone().lu();
            let u = lu.u();
            let pivots = (0..n).map(|i| u[(i, i)].norm());
            if !scale.is_finite() || pivots.clone().any(|p| !p.is_finite()) {
                return Err(non_finite_stiffness(k, k as f64 * fundamental));
            }
            let min_pivot = pivots.fold(f64::INFINITY, f64::min);
            let relative_pivot = if scale > 0.0 { min_pivot / scale } else { 0.0 };
            if relative_pivot <= SINGULAR_PIVOT {
                return Err(Error::SingularDynamicStiffness {
                    harmonic: k,
                    omega: k as f64 * fundamental,
                    relative_pivot,
                    hint: "the condensed dynamic stiffness is singular".into(),
                });
            }
            factors.push(lu);
        }
        Ok(Self {
            n,
            matrices,
            factors,
        })
    }

    /// `Z_k`.
    pub fn matrix(&self, k: usize) -> &DMatrix<Complex64> {
        &self.matrices[k]
    }

    /// `x ← Z_k⁻¹ x` for the n entries of harmonic k (no allocation).
    #[inline]
    pub fn solve_in_place(&self, k: usize, x: &mut [Complex64]) {
        let mut v = DVectorViewMut::from_slice(x, self.n);
        self.factors[k].solve_mut(&mut v);
    }

    /// `out ← Z_k x`.
    #[inline]
    pub fn apply(&self, k: usize, x: &[Complex64], out: &mut [Complex64]) {
        let z = &self.matrices[k];
        for (i, o) in out.iter_mut().enumerate() {
            let mut acc = Complex64::default();
            for (j, xj) in x.iter().enumerate() {
                acc += z[(i, j)] * xj;
            }
            *o = acc;
        }
    }
}
