//! Loads that follow the speed ([`crate::model::SpeedLaw`]): the load harmonics `F(Ω)` built
//! again at every Ω of a sweep, and their share `-∂F/∂Ω` of `∂R/∂Ω`.
//!
//! In the full formulation `R = Z Q + F_rest(Q) - F_split`, so `∂R/∂Ω` gains `-∂F/∂Ω`. In the
//! condensed one `R = G⁻¹ U + R_rest(U) - G⁻¹ Wᵀ Z⁻¹ F`, so it gains
//! `-G_k⁻¹ Wᵀ Z_k⁻¹ ∂F_k/∂Ω` per harmonic (one solve with `Z_k` each).

use super::HarmonicBalance;
use crate::error::Result;
use crate::harmonic::from_cos_sin;
use num_complex::Complex64;

/// `F_ext` and `F_split` of the full model at one speed.
pub(super) type SpeedLoads = (Vec<Complex64>, Vec<Complex64>);

impl HarmonicBalance<'_> {
    /// `F_ext` of the full model at speed Ω (harmonic-major, `(H+1)` times the model's DOFs),
    /// the alternating part scaled by the load factor; `derivative` gives `∂F/∂Ω` instead.
    fn full_loads(&self, omega: f64, derivative: bool) -> Vec<Complex64> {
        let n = self.model.n_dofs();
        let h = self.basis.harmonics();
        let nu = self.basis.subharmonic();
        let mut f = vec![Complex64::default(); (h + 1) * n];
        for l in self.model.loads() {
            let (c, s) = if derivative {
                l.omega_derivative(omega)
            } else {
                l.at(omega)
            };
            let scale = if l.order == 0 { 1.0 } else { self.load_factor };
            f[l.order * nu * n + l.dof] += from_cos_sin(c, s) * scale;
        }
        f
    }

    /// The loads at Ω where some follow the speed (`None` where none does), with the static
    /// balance of a model that floats free checked against the new mean load; a table over
    /// speed is held at its ends outside its speeds (the continuation stops a branch that
    /// leaves it, and every analysis checks its range first). Nothing changes on an error.
    pub(super) fn speed_loads_at(&self, omega: f64) -> Result<Option<SpeedLoads>> {
        if !self.model.has_speed_dependent_loads() {
            return Ok(None);
        }
        let f_ext = self.full_loads(omega, false);
        let mut f_split = f_ext.clone();
        for e in self.model.elements() {
            e.scatter_add(
                Complex64::new(-e.linear_part().offset, 0.0),
                &mut f_split[..self.model.n_dofs()],
            );
        }
        if let Some(rigid) = &self.rigid {
            let mean: Vec<f64> = f_ext[..self.model.n_dofs()].iter().map(|v| v.re).collect();
            rigid.check_balance(self.model, &mean)?;
        }
        Ok(Some((f_ext, f_split)))
    }

    /// Installs loads from [`speed_loads_at`](Self::speed_loads_at) (before the condensation
    /// is refreshed, which recovers the condensed load from the full one).
    pub(super) fn install_speed_loads(&mut self, loads: Option<SpeedLoads>) {
        let Some((f_ext, f_split)) = loads else {
            return;
        };
        match self.condensed.as_mut() {
            Some(b) => b.1 = f_split,
            None => {
                self.f_ext = f_ext;
                self.f_split = f_split;
            }
        }
    }

    /// `rhs -= ∂(load term)/∂Ω` (module documentation); nothing for loads constant over
    /// speed.
    pub(super) fn subtract_load_derivative(&self, rhs: &mut [Complex64]) {
        if !self.model.has_speed_dependent_loads() {
            return;
        }
        let df = self.full_loads(self.basis.omega(), true);
        let Some(b) = self.condensed.as_deref() else {
            for (r, d) in rhs.iter_mut().zip(&df) {
                *r -= d;
            }
            return;
        };
        let (cond, m) = (&b.0, self.n);
        let rest = vec![Complex64::default(); rhs.len()];
        let u = cond.project(&cond.recover(&df, &rest));
        for k in 0..=self.basis.harmonics() {
            let g = self.z.matrix(k);
            for r in 0..m {
                let v: Complex64 = (0..m).map(|c| g[(r, c)] * u[k * m + c]).sum();
                rhs[k * m + r] -= v;
            }
        }
    }
}
