//! The condensed formulation of [`HarmonicBalance`]: unknowns on the element coordinates
//! (see [`crate::linear::condensation`]), the full harmonics recovered from them.

use super::HarmonicBalance;
use crate::error::{Error, Result};
use crate::harmonic::DynamicStiffness;
use crate::linear::Condensation;
use num_complex::Complex64;

impl HarmonicBalance<'_> {
    /// Condenses onto the element coordinates at the current basis (again after a change
    /// of Ω): `G_k⁻¹` becomes the dynamic stiffness and the condensed load the load. On an
    /// error after the first condensation (a singular `Z_k` at this Ω) the condensation is kept,
    /// so that [`HarmonicBalance::set_omega`] can move on to another Ω.
    pub(crate) fn condense(&mut self) -> Result<()> {
        let (mut cond, f_full) = match self.condensed.take() {
            Some(b) => {
                let (mut c, f) = *b;
                // Kept on an error (a singular Z_k at this Ω), so that another Ω can follow.
                if let Err(e) = c.refactor(&self.basis) {
                    self.condensed = Some(Box::new((c, f)));
                    return Err(e);
                }
                (c, f)
            }
            None => {
                let weights: Vec<(&str, &[(usize, f64)])> = self
                    .active
                    .iter()
                    .map(|a| {
                        let e = &self.model.elements()[a.index];
                        (e.name(), e.weights())
                    })
                    .collect();
                let (c, map) = Condensation::new(self.model, &self.basis, &weights)?;
                if c.is_empty() {
                    return Err(Error::Solver {
                        reason: "condensation: the model has no time-varying or nonlinear element to condense onto; use the full formulation".into(),
                    });
                }
                for (a, (coord, s)) in self.active.iter_mut().zip(map) {
                    a.weights = vec![(coord, s)];
                }
                self.names = c.names().to_vec();
                self.n = c.len();
                (c, std::mem::take(&mut self.f_split))
            }
        };
        let linear = match cond.linear_part(&f_full) {
            Ok(linear) => linear,
            Err(e) => {
                self.condensed = Some(Box::new((cond, f_full)));
                return Err(e);
            }
        };
        let z = match DynamicStiffness::from_matrices(linear.stiffness, self.basis.fundamental()) {
            Ok(z) => z,
            Err(e) => {
                self.condensed = Some(Box::new((cond, f_full)));
                return Err(e);
            }
        };
        self.z = z;
        self.f_ext = linear.load.clone();
        self.f_split = linear.load;
        self.condensed = Some(Box::new((cond, f_full)));
        Ok(())
    }

    /// The formulation.
    pub fn formulation(&self) -> crate::linear::Formulation {
        if self.condensed.is_some() {
            crate::linear::Formulation::Condensed
        } else {
            crate::linear::Formulation::Full
        }
    }

    /// `true` in the condensed formulation.
    pub fn is_condensed(&self) -> bool {
        self.condensed.is_some()
    }

    /// The names of the unknowns per harmonic: the DOFs, or `u(element)` when condensed.
    pub fn unknown_names(&self) -> &[String] {
        &self.names
    }

    /// The full harmonics (all n DOFs, harmonic-major) of the unknowns `x` (complex,
    /// `(H+1)` times [`unknown_names`](Self::unknown_names)): `x` itself in the full
    /// formulation, `Q_k = Z_k⁻¹ (F_k - W R_k(U))` when condensed.
    pub fn full_harmonics(
        &self,
        x: &[Complex64],
        ws: &mut super::AftBuffers,
    ) -> Result<Vec<Complex64>> {
        match &self.condensed {
            None => Ok(x.to_vec()),
            Some(b) => {
                let mut rest = vec![Complex64::default(); x.len()];
                self.rest_into(x, &mut rest, ws)?;
                Ok(b.0.recover(&b.1, &rest))
            }
        }
    }

    /// The unknowns of `q`, either unknowns already (`(H+1)` times the unknowns per harmonic:
    /// taken as they are) or full harmonics (`(H+1) n`: `U = Wᵀ Q` when condensed); `None` if
    /// `q` has neither length. With as many element coordinates as DOFs the two lengths agree
    /// and `q` is taken as unknowns: pass full harmonics to
    /// [`unknowns_of_full`](Self::unknowns_of_full).
    pub fn unknowns_of(&self, q: &[Complex64]) -> Option<Vec<Complex64>> {
        if q.len() == self.len() {
            return Some(q.to_vec());
        }
        self.unknowns_of_full(q)
    }

    /// The unknowns of the full harmonics `q` (`(H+1) n`, all DOFs): `q` itself, or
    /// `U = Wᵀ Q` when condensed; `None` if `q` has another length.
    pub fn unknowns_of_full(&self, q: &[Complex64]) -> Option<Vec<Complex64>> {
        let n = self.model.n_dofs();
        if q.len() != (self.basis.harmonics() + 1) * n {
            return None;
        }
        match &self.condensed {
            Some(b) => Some(b.0.project(q)),
            None => Some(q.to_vec()),
        }
    }
}
