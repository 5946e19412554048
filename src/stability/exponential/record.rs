//! The record of a pass of the exponential flow ([`exponential`](super::exp_flow)) and the
//! monodromy matrix from it.
//!
//! The orbit and its monodromy matrix are separate: a pass integrates the state only and
//! records, per piece, its generator `Ã`, the number `m` of whole sub-steps `δ₀` and the last
//! part `τ`, and per crossing the factor of the saltation matrix of the force jump. The scaled
//! monodromy matrix of that orbit is then the product
//!
//! `Φ̃ = … S_k e^{Ã_k τ_k} E_k^{m_k} … S_1 e^{Ã_1 τ_1} E_1^{m_1}`
//!
//! (`E^m = e^{Ãmδ₀}` and `e^{Ãτ}` per generator from its [`Propagator`], `S` the saltation
//! matrices), multiplied by the [`Assembler`] step by step in the pass's order. Only the
//! orbits whose monodromy matrix is used pay for it: the shooting's Newton–chord iterations
//! ([`chord`](crate::stability::shooting::chord)) need it once per point.

use super::exp_flow::ExpFlow;
use super::expm::ExpWork;
use super::generator::Core;
use super::kernels::product;
use super::pipeline::{Link, Message};
use super::propagator::Propagator;
use crate::error::{Error, Result};
use crate::stability::integrated::pieces::saltation;
use nalgebra::{DMatrix, DVector};
use std::collections::HashMap;
use std::sync::Arc;

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
    /// element `e` ([`Pieces::cross_jump`](crate::stability::integrated::pieces::Pieces::cross_jump)).
    Jump { element: usize, factor: f64 },
}

/// An element's weights `w̃_e` (sparse) and `M⁻¹ w_e`.
type Element = (Vec<(usize, f64)>, Vec<f64>);

/// The monodromy side of the exponential flow: the generators' [`Propagator`]s and the
/// product of a record's factors, step by step.
pub(crate) struct Assembler {
    propagators: Vec<Propagator>,
    /// Propagators kept from the last analysis, by their core's address.
    spare: HashMap<usize, Propagator>,
    /// `(w̃_e, M⁻¹ w_e)` per element (the saltation matrices).
    elements: Vec<Element>,
    work: ExpWork,
    phi: DMatrix<f64>,
    tmp: DMatrix<f64>,
    e_tau: DMatrix<f64>,
}

impl Assembler {
    /// For the `2n × 2n` monodromy matrix of a flow whose elements have the weights `weights`
    /// and `M⁻¹ w_e` = `mw`.
    pub(crate) fn new(s2: usize, weights: &[Vec<(usize, f64)>], mw: &[DVector<f64>]) -> Self {
        let elements = weights
            .iter()
            .zip(mw)
            .map(|(w, m)| (w.clone(), m.as_slice().to_vec()))
            .collect();
        Self {
            propagators: Vec::new(),
            spare: HashMap::new(),
            elements,
            work: ExpWork::new(s2),
            phi: DMatrix::identity(s2, s2),
            tmp: DMatrix::zeros(s2, s2),
            e_tau: DMatrix::zeros(s2, s2),
        }
    }

    /// With the propagators `spare` kept from the last analysis.
    pub(crate) fn with_spare(mut self, spare: HashMap<usize, Propagator>) -> Self {
        self.spare = spare;
        self
    }

    /// The propagators, for the next analysis (each trimmed).
    pub(crate) fn take_propagators(&mut self) -> Vec<Propagator> {
        let mut all = std::mem::take(&mut self.propagators);
        all.extend(self.spare.drain().map(|(_, p)| p));
        all.iter_mut().for_each(Propagator::trim);
        all
    }

    /// Generators known so far.
    pub(crate) fn generators(&self) -> usize {
        self.propagators.len()
    }

    /// The next generator (the flow's states in their order).
    pub(crate) fn add(&mut self, core: Arc<Core>) {
        self.propagators
            .push(super::kept::propagator(&mut self.spare, core));
    }

    /// `Φ̃ = I`: a new pass.
    pub(crate) fn begin(&mut self) {
        self.phi.fill_with_identity();
    }

    /// `Φ̃ ← F Φ̃` for the factor `F` of `step`.
    pub(crate) fn apply(&mut self, step: &Step) {
        match *step {
            Step::Piece { state, whole, tau } => {
                let p = &mut self.propagators[state];
                p.advance(whole, &mut self.phi, &mut self.tmp);
                if tau > 0.0 {
                    p.exp_short(tau, &mut self.e_tau, &mut self.work);
                    product(&self.e_tau, &self.phi, &mut self.tmp);
                    std::mem::swap(&mut self.phi, &mut self.tmp);
                }
            }
            Step::Jump { element, factor } => {
                let (w, mw) = &self.elements[element];
                saltation(w, factor, mw, self.phi.as_mut_slice());
            }
        }
    }

    /// `Φ̃` of the pass.
    pub(crate) fn finish(&self) -> Result<DMatrix<f64>> {
        if self.phi.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "monodromy matrix (exponential flow)".into(),
            });
        }
        Ok(self.phi.clone())
    }
}

impl ExpFlow<'_, '_> {
    /// Appends `step` to `record` (and sends it to a linked assembler).
    pub(crate) fn emit(&mut self, record: &mut Vec<Step>, step: Step) {
        if let Some(link) = &mut self.link {
            link.step(step);
        }
        record.push(step);
    }

    /// A pass begins.
    pub(crate) fn begin_pass(&mut self) {
        if let Some(link) = &mut self.link {
            link.begin();
        }
    }

    /// The pass has ended.
    pub(crate) fn end_pass(&mut self) {
        if let Some(link) = &mut self.link {
            link.send(Message::End);
        }
    }

    /// The scaled monodromy matrix `Φ̃` of the pass that wrote `record`: from the linked
    /// assembler, or by replaying the record.
    pub(crate) fn monodromy(&mut self, record: &[Step]) -> Result<DMatrix<f64>> {
        if let Some(link) = &mut self.link {
            return link.monodromy();
        }
        let assembler = &mut self.assembler;
        for state in &self.states[assembler.generators()..] {
            assembler.add(state.core.clone());
        }
        assembler.begin();
        for step in record {
            assembler.apply(step);
        }
        assembler.finish()
    }

    /// The assembler with every generator so far, for another thread (a placeholder stays).
    pub(crate) fn take_assembler(&mut self) -> Box<Assembler> {
        let placeholder = Box::new(Assembler::new(0, &[], &[]));
        let mut assembler = std::mem::replace(&mut self.assembler, placeholder);
        for state in &self.states[assembler.generators()..] {
            assembler.add(state.core.clone());
        }
        assembler
    }

    /// The assembler back from its thread.
    pub(crate) fn restore_assembler(&mut self, assembler: Box<Assembler>) {
        self.assembler = assembler;
    }

    /// Sends the generators and steps from now on to the assembler at the other end of `link`.
    pub(crate) fn link(&mut self, link: Link) {
        self.link = Some(Box::new(link));
    }

    pub(crate) fn unlink(&mut self) -> Option<Box<Link>> {
        self.link.take()
    }
}
