//! The record of a pass of the exponential flow ([`exponential`](super::exponential)) and the
//! monodromy matrix from it.
//!
//! The orbit and its monodromy matrix are separate: a pass integrates the state only and
//! records, per piece, its generator `Ã`, the number `m` of whole sub-steps `δ₀` and the last
//! part `τ`, and per crossing the factor of the saltation matrix of the force jump. The scaled
//! monodromy matrix of that orbit is then the product
//!
//! `Φ̃ = … S_k e^{Ã_k τ_k} E_k^{m_k} … S_1 e^{Ã_1 τ_1} E_1^{m_1}`
//!
//! (`E = e^{Ãδ₀}` by its ladder `E^{2^j}`, one product per set bit of `m`; `e^{Ãτ}` by the
//! Taylor polynomial of the kept `Ãⁱ/i!`; `S` the saltation matrices): the same products in the
//! same order as integrating `Φ̃` along the pass, so the same matrix to the last bit. Only the
//! orbits whose monodromy matrix is used pay for it: the shooting's Newton–chord iterations
//! ([`chord`](super::chord)) need it once per point.

use super::exponential::ExpFlow;
use super::kernels::product;
use super::pieces::saltation;
use crate::error::{Error, Result};
use nalgebra::DMatrix;

/// One factor of the monodromy matrix of a pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Step {
    /// `Φ̃ ← e^{Ãτ} E_δ₀^whole Φ̃` with the generator `state`.
    Piece {
        state: usize,
        whole: usize,
        tau: f64,
    },
    /// `δṽ += c M⁻¹ w_e (w̃_e·δq̃)` in every column: the saltation matrix of a force jump of
    /// element `e` ([`Pieces::cross_jump`](super::pieces::Pieces::cross_jump)).
    Jump { element: usize, factor: f64 },
}

impl ExpFlow<'_, '_> {
    /// The scaled monodromy matrix `Φ̃` of the pass that wrote `record`.
    pub(crate) fn monodromy(&mut self, record: &[Step]) -> Result<DMatrix<f64>> {
        let s2 = 2 * self.sys.len();
        let mut phi = DMatrix::identity(s2, s2);
        let (mut e_tau, mut tmp) = (DMatrix::zeros(s2, s2), DMatrix::zeros(s2, s2));
        for step in record {
            match *step {
                Step::Piece { state, whole, tau } => {
                    let state = &mut self.states[state];
                    state.advance(whole, &mut phi, &mut tmp);
                    if tau > 0.0 {
                        state.exp_short(tau, &mut e_tau, &mut self.work);
                        product(&e_tau, &phi, &mut tmp);
                        std::mem::swap(&mut phi, &mut tmp);
                    }
                }
                Step::Jump { element, factor } => {
                    let mw = self.mw[element].as_slice();
                    saltation(self.sys, element, factor, mw, phi.as_mut_slice());
                }
            }
        }
        if phi.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "monodromy matrix (exponential flow)".into(),
            });
        }
        Ok(phi)
    }
}
