//! The per-solve buffers: [`Workspace`] (harmonic vectors `Q`, `F_rest`, `Z Q`, the right-hand
//! side, the solve's statistics) and the [`AftBuffers`] of one AFT pass (local harmonics
//! `U_k`, samples `u(θ_j)`, `u̇(θ_j)`, `f`, `∂f/∂u`, `∂f/∂u̇`, their spectra, work counters).
//! Made once per solve by [`HarmonicBalance::workspace`]: no allocation while iterating.

use super::HarmonicBalance;
use crate::harmonic::AftScratch;
use crate::solution::SolveStats;
use num_complex::Complex64;

/// Buffers of one AFT pass and its work counters.
#[derive(Debug, Clone)]
pub struct AftBuffers {
    pub(super) aft: AftScratch,
    pub(super) uk: Vec<Complex64>,
    pub(super) u: Vec<f64>,
    pub(super) du: Vec<f64>,
    pub(super) f: Vec<f64>,
    pub(super) gu: Vec<f64>,
    pub(super) gdu: Vec<f64>,
    pub(super) spec_u: Vec<Complex64>,
    pub(super) spec_du: Vec<Complex64>,
    pub(super) jac_scratch: crate::jacobian::JacobianScratch,
    pub(super) crossings: Vec<crate::harmonic::kinks::Crossing>,
    /// Where the element coordinate crosses a kink.
    pub(super) edges: Vec<crate::harmonic::kinks::EdgeCrossing>,
    /// The breaks of a law affine on its pieces, and its coefficients' spectrum `E_m` and
    /// samples (see [`crate::harmonic::kinks::exact`]).
    pub(super) pieces: crate::harmonic::kinks::exact::PieceCoefficients,
    pub(super) spec_e: Vec<Complex64>,
    pub(super) ge: Vec<f64>,
    /// Sensitivities of the march of laws with memory (empty without them).
    pub(super) march: crate::harmonic::march::MarchBuffers,
    /// One local Jacobian column (laws with memory).
    pub(super) column: Vec<f64>,
    /// The tail correction's buffers (empty without one).
    pub(super) tail: super::tail::TailBuffers,
    /// Real FFTs done so far.
    pub ffts: usize,
    /// Force-law calls so far.
    pub force_evaluations: usize,
    /// Element evaluations whose contact crossings were integrated exactly (a law affine on
    /// its pieces, see [`crate::harmonic::kinks::exact`]) so far.
    pub exact_contacts: usize,
    /// Element evaluations with contact crossings that took the corrected trapezoid rule
    /// instead (other laws, fewer than 4H + 1 samples, or a law that did not agree with its
    /// pieces along the orbit) so far.
    pub approximate_contacts: usize,
}

/// Per-solve buffers: no allocation happens while iterating.
#[derive(Debug, Clone)]
pub struct Workspace {
    pub(crate) eval: AftBuffers,
    pub(crate) q: Vec<Complex64>,
    pub(crate) rest: Vec<Complex64>,
    pub(crate) rhs: Vec<Complex64>,
    pub(crate) zq: Vec<Complex64>,
    pub(crate) stats: SolveStats,
}

impl Workspace {
    /// The AFT buffers, for calling [`HarmonicBalance::rest_into`] directly.
    pub fn aft_buffers(&mut self) -> &mut AftBuffers {
        &mut self.eval
    }
}

impl HarmonicBalance<'_> {
    /// Buffers for one solve at a time.
    pub fn workspace(&self) -> Workspace {
        let (h, n, s) = (self.basis.harmonics(), self.n, self.basis.samples());
        let len = (h + 1) * n;
        Workspace {
            eval: AftBuffers {
                aft: self.aft.make_scratch(),
                uk: vec![Complex64::default(); h + 1],
                u: vec![0.0; s],
                du: vec![0.0; s],
                f: vec![0.0; s],
                gu: vec![0.0; s],
                gdu: vec![0.0; s],
                spec_u: vec![Complex64::default(); s / 2 + 1],
                spec_du: vec![Complex64::default(); s / 2 + 1],
                jac_scratch: crate::jacobian::JacobianScratch::new(h),
                crossings: Vec::with_capacity(16),
                edges: Vec::with_capacity(16),
                pieces: crate::harmonic::kinks::exact::PieceCoefficients {
                    breaks: Vec::with_capacity(64),
                    ..Default::default()
                },
                spec_e: vec![Complex64::default(); s / 2 + 1],
                ge: vec![0.0; s],
                march: if self.trig.is_empty() {
                    Default::default()
                } else {
                    crate::harmonic::march::MarchBuffers::new(s, 2 * h + 1)
                },
                column: vec![0.0; if self.trig.is_empty() { 0 } else { 2 * h + 1 }],
                tail: self.tail.as_ref().map(|t| t.buffers()).unwrap_or_default(),
                ffts: 0,
                force_evaluations: 0,
                exact_contacts: 0,
                approximate_contacts: 0,
            },
            q: vec![Complex64::default(); len],
            rest: vec![Complex64::default(); len],
            rhs: vec![Complex64::default(); len],
            zq: vec![Complex64::default(); len],
            stats: SolveStats::default(),
        }
    }
}
