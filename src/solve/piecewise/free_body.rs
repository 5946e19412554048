//! Models that float free: the rigid-body motion separated exactly.
//!
//! With rigid-body modes `R` (n × p, `Rᵀ M R = I`, `K_p R = D_p R = 0` on every piece, `K_p`,
//! `D_p` symmetric) write `q = R c + y` with `Rᵀ M y = 0`. Then `c̈ = Rᵀ f(t)`: the loads alone
//! move the rigid body (no element acts on it), and a periodic `c` needs the mean loads to
//! balance, `Rᵀ F_0 = 0`; its harmonics are `C_k = -Rᵀ F_k / (kΩ)²`, `C_0 = 0` (the mean
//! rigid position zero, as harmonic balance has it). The flexible part obeys
//! `M ÿ + D_p ẏ + K_p y = Pᵀ f`, `Pᵀ = I - M R Rᵀ`, which is singular as it stands; with
//! `S = M R Rᵀ M` the shifted system `M ÿ + (D_p + δS) ẏ + (K_p + σS) y = Pᵀ f` has the same
//! solutions in the complement (`S y = 0` there) and is regular: its rigid part obeys
//! `c̈' + δ ċ' + σ c' = Rᵀ Pᵀ f = 0`, whose periodic solution is zero. So every piece gets
//! `K_p + σS`, `D_p + δS`, the loads `Pᵀ F_k`, and its steady state the rigid response
//! `R C_k` added; the matching and the closed-form harmonics are unchanged.
//!
//! `σ = ab`, `δ = a + b` with `b = 2a`, `a = max(ω_s, 40/T)`: the shift's multipliers
//! `e^{-aT}`, `e^{-bT}` are below `e^{-40}` and are dropped from the smallest end of the
//! list, the rigid body's own `2p` multipliers 1 counted as neutral.

use crate::error::{Error, Result};
use crate::model::{DenseMatrices, Model, RigidModes};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Largest relative `|Rᵀ K|`, `|Rᵀ D|` of a mode that counts as free on the left too.
const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// The rigid-body modes of a free-floating model and the shift that makes it regular.
pub(super) struct FreeBody {
    /// `R` (M-orthonormal) and `M R`.
    rigid: RigidModes,
    /// The shift's slower rate `a` (1/s); the other is `2a`.
    rate: f64,
}

impl FreeBody {
    /// The rigid-body modes of `model`, or `None` if it is grounded. An error if the mean
    /// loads do not balance (the model would accelerate away).
    /// The balance is checked at the speed `omega`; without it, where a static load follows
    /// the speed, not here.
    pub(super) fn find(
        model: &Model,
        dense: &DenseMatrices,
        omega: Option<f64>,
    ) -> Result<Option<Self>> {
        let Some(rigid) = crate::model::rigid::find_dense(model, dense) else {
            return Ok(None);
        };
        let mut mean = vec![0.0; model.n_dofs()];
        let statics = model.loads().iter().filter(|l| l.order == 0);
        let follows = statics.clone().any(|l| l.speed.is_some());
        for load in statics {
            mean[load.dof] += load.at(omega.unwrap_or(0.0)).0;
        }
        if omega.is_some() || !follows {
            rigid.check_balance(model, &mean)?;
        }
        if rigid.held() > 0 {
            return Err(Error::InvalidElement {
                context: "method `piecewise_exact`".into(),
                reason: "a rigid-body motion of the model is held only by damping to ground, so the rigid motion does not separate from the flexible one; use harmonic balance (newton, anderson)".into(),
            });
        }
        // The elements' couplings w k wᵀ are symmetric; the structural matrices must leave
        // the modes free from the left as well (Rᵀ K = 0).
        let modes = rigid.modes();
        let top = modes.amax();
        for (name, a) in [("stiffness", &dense.stiffness), ("damping", &dense.damping)] {
            let left = modes.transpose() * a;
            if left.amax() > SYMMETRY_TOLERANCE * a.amax().max(f64::MIN_POSITIVE) * top {
                return Err(Error::InvalidElement {
                    context: "method `piecewise_exact`".into(),
                    reason: format!("the model floats free and its {name} matrix is not symmetric in the rigid-body modes (Rᵀ K ≠ 0), so the rigid motion does not separate; use harmonic balance"),
                });
            }
        }
        Ok(Some(Self { rigid, rate: 1.0 }))
    }

    /// The number `p` of rigid-body modes.
    pub(super) fn count(&self) -> usize {
        self.rigid.len()
    }

    /// Sets the shift's rate from the highest natural frequency's estimate and the period.
    pub(super) fn set_rate(&mut self, highest_frequency: f64, period: f64) {
        self.rate = highest_frequency.max(40.0 / period);
    }

    /// Adds the shift `σ S`, `δ S` to a piece's `k`, `d`.
    pub(super) fn shift(&self, k: &mut DMatrix<f64>, d: &mut DMatrix<f64>) {
        let (a, b) = (self.rate, 2.0 * self.rate);
        let mass_modes = self.rigid.mass_modes();
        let s = mass_modes * mass_modes.transpose();
        *k += &s * (a * b);
        *d += &s * (a + b);
    }

    /// Splits the load harmonic `block` of `order` into the flexible part `Pᵀ F` (in place)
    /// and returns the rigid response `R C_k`, `C_k = -Rᵀ F_k / (kΩ)²` (zero at order 0).
    pub(super) fn split_load(
        &self,
        block: &mut [Complex64],
        order: usize,
        omega: f64,
    ) -> Vec<Complex64> {
        let mut rigid = vec![Complex64::new(0.0, 0.0); block.len()];
        if order > 0 {
            let w2 = (order as f64 * omega).powi(2);
            for r in self.rigid.modes().column_iter() {
                let f: Complex64 = r.iter().zip(block.iter()).map(|(ri, fi)| fi * *ri).sum();
                for (x, ri) in rigid.iter_mut().zip(r.iter()) {
                    *x -= f * *ri / w2;
                }
            }
        }
        self.rigid.project_load(block);
        rigid
    }
}
