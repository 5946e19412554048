//! A change of the fundamental Ω and the derivative by it. `Z_k = -(kΩ/ν)² M + i (kΩ/ν) D0 + K0`
//! is rebuilt and refactored at a new Ω ([`HarmonicBalance::set_omega`], with the static
//! augmentation `Z_0 = K0 + s M R Rᵀ M` of a free-free model); `∂R/∂Ω` is
//! `(dZ_k/dΩ) Q_k + ∂F_rest/∂Ω` with `dZ_k/dΩ = -2(k/ν)²Ω M + i (k/ν) D0` and the rest moving
//! with Ω only through `u̇`. The scaling of the alternating load (a homotopy in the load
//! amplitude) lives here too: like Ω, a parameter of continuation.

use super::aft::scatter_add;
use super::{HarmonicBalance, Workspace};
use crate::error::{Error, Result};
use crate::harmonic::{DynamicStiffness, HarmonicBasis};
use num_complex::Complex64;

/// `Z_k` of a free-free model: `Z_0 = K0 + s M R Rᵀ M` (see [`crate::model::rigid`]).
fn free_dynamic_stiffness(
    basis: &HarmonicBasis,
    dense: &crate::model::DenseMatrices,
    rigid: &crate::model::RigidModes,
) -> Result<DynamicStiffness> {
    DynamicStiffness::of_model(basis, dense, Some(&rigid.augmentation()))
}

impl HarmonicBalance<'_> {
    /// `out ← ∂R/∂Ω` at `x` (real layout), analytic: `(dZ_k/dΩ) Q_k` with
    /// `dZ_k/dΩ = -2(k/ν)²Ω M + i (k/ν) D0` (harmonic k oscillates at kΩ/ν), plus the AFT of `(∂f/∂u̇ - d0) u̇/Ω` per element (the rest
    /// depends on Ω only through `u̇ = Σ i kΩ U_k e^{ikθ}`). For continuation in Ω.
    pub fn omega_derivative_real_into(
        &self,
        x: &[f64],
        out: &mut [f64],
        ws: &mut Workspace,
    ) -> Result<()> {
        let layout = self.layout();
        let (n, h) = (layout.n, layout.h);
        let omega = self.basis.omega();
        layout.unpack(x, &mut ws.q);
        if let Some(b) = self.condensed.as_deref() {
            let (cond, f_full) = (&b.0, &b.1);
            cond.omega_derivative(
                &self.z,
                &self.f_split,
                f_full,
                &ws.q,
                self.basis.subharmonic(),
                omega,
                &mut ws.rhs,
            );
        } else {
            self.dense_omega_derivative(&mut ws.rhs, &ws.q)?;
        }
        let b = &mut ws.eval;
        for act in &self.active {
            let e = &self.model.elements()[act.index];
            self.element_samples(act, &ws.q, b);
            if let Some(m) = self.law(act).memory() {
                self.memory_omega_derivative(act, m, b)?;
            } else {
                self.derivative_samples(act, b);
                let d0 = e.linear_part().damping;
                for ((f, g), du) in b.f.iter_mut().zip(&b.gdu).zip(&b.du) {
                    *f = (g - d0) * du / omega;
                }
            }
            self.samples(b).check("Ω-derivative", e.name(), &b.f)?;
            self.aft.analyze_into(&mut b.f, &mut b.uk, &mut b.aft);
            b.ffts += 3;
            for k in 0..=h {
                scatter_add(&act.weights, b.uk[k], &mut ws.rhs[k * n..(k + 1) * n]);
            }
        }
        self.subtract_load_derivative(&mut ws.rhs);
        layout.pack(&ws.rhs, out);
        Ok(())
    }

    /// `rhs ← (dZ_k/dΩ) Q_k` with the dense M, D0 of the full formulation.
    fn dense_omega_derivative(&self, rhs: &mut [Complex64], q: &[Complex64]) -> Result<()> {
        let Some(dense) = self.dense.as_deref() else {
            return Err(Error::Solver {
                reason: "no dense matrices for the Ω-derivative".into(),
            });
        };
        let (n, h) = (self.n, self.basis.harmonics());
        let omega = self.basis.omega();
        let nu = self.basis.subharmonic() as f64;
        let m = &dense.mass;
        for k in 0..=h {
            let kf = k as f64 / nu;
            for i in 0..n {
                let mut acc = Complex64::default();
                for j in 0..n {
                    let dz =
                        Complex64::new(-2.0 * kf * kf * omega * m[(i, j)], kf * dense.d0[(i, j)]);
                    acc += dz * q[k * n + j];
                }
                rhs[k * n + i] = acc;
            }
        }
        Ok(())
    }

    /// Builds and factors the dense `Z_k` of the full formulation (with the static
    /// augmentation of a free-free model, whose mean loads must balance).
    pub(super) fn factor_full(&mut self, mean_load: &[f64]) -> Result<()> {
        let (model, basis) = (self.model, self.basis);
        let dense = model.dense("full formulation")?;
        self.z = match DynamicStiffness::of_model(&basis, &dense, None) {
            Err(e @ Error::SingularDynamicStiffness { harmonic: 0, .. }) => {
                let Some(rigid) = crate::model::rigid::find_dense(model, &dense) else {
                    return Err(e);
                };
                rigid.check_balance(model, mean_load)?;
                let z = free_dynamic_stiffness(&basis, &dense, &rigid)?;
                self.rigid = Some(std::sync::Arc::new(rigid));
                z
            }
            z => z?,
        };
        self.dense = Some(Box::new(dense));
        Ok(())
    }

    /// Multiplies the alternating load (harmonics `k >= 1` of `F_ext`) by `factor`; the static
    /// load stays. For a homotopy in the load amplitude.
    pub fn scale_alternating_load(&mut self, factor: f64) {
        self.load_factor *= factor;
        let n = self.n;
        for v in self.f_ext[n..]
            .iter_mut()
            .chain(self.f_split[n..].iter_mut())
        {
            *v *= factor;
        }
        // The condensed formulation recovers all DOFs from the full load: scale it alike.
        let n_full = self.model.n_dofs();
        if let Some(b) = self.condensed.as_mut() {
            for v in b.1[n_full..].iter_mut() {
                *v *= factor;
            }
        }
    }

    /// Moves the discretisation to a new fundamental Ω (rebuilds and factors `Z_k`); for
    /// sweeps. Errors as [`HarmonicBalance::new`] on a singular `Z_k`.
    pub fn set_omega(&mut self, omega: f64) -> Result<()> {
        let basis = self.basis.with_omega(omega)?;
        let loads = self.speed_loads_at(omega)?;
        if self.condensed.is_some() {
            self.basis = basis;
            self.install_speed_loads(loads);
            self.condense()?;
            self.refit_tail();
            return Ok(());
        }
        let Some(dense) = self.dense.as_deref() else {
            return Err(Error::Solver {
                reason: "no dense matrices for the full formulation".into(),
            });
        };
        self.z = match &self.rigid {
            Some(rigid) => free_dynamic_stiffness(&basis, dense, rigid)?,
            None => DynamicStiffness::of_model(&basis, dense, None)?,
        };
        self.basis = basis;
        self.install_speed_loads(loads);
        self.refit_tail();
        Ok(())
    }

    /// The tail correction's receptance fitted again to the current factors.
    fn refit_tail(&mut self) {
        if let Some(mut tail) = self.tail.take() {
            tail.fit(self);
            self.tail = Some(tail);
        }
    }
}
