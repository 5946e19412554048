//! The AFT of an element that is affine on its pieces while its coordinate crosses a kink:
//! the exact Galerkin harmonics from the jumps of its coefficients (see
//! [`crate::harmonic::kinks::exact`]) instead of the corrected trapezoid rule, and the exact
//! spectra of `∂f/∂u`, `∂f/∂u̇` for the Jacobian.

use super::aft::ActiveElement;
use super::{AftBuffers, HarmonicBalance};
use crate::force::{ForceLaw, LinearPart};

impl HarmonicBalance<'_> {
    /// With the samples `ws.u`, `ws.du`, the local harmonics `ws.uk` and the crossings
    /// `ws.edges` of `act` (law `law`, the element's own, not its band-limited copy): writes the
    /// exact harmonics of its rest `f - f0 - k0 u - d0 u̇` into `ws.uk` and the Jacobian spectra
    /// into `ws.spec_u`, `ws.spec_du`, and returns `true`; returns `false` (nothing usable
    /// written, `ws.uk` intact) where the basis has fewer than `4H + 1` samples or the law does
    /// not agree with its pieces along this orbit.
    pub(super) fn exact_kinks_into(
        &self,
        act: &ActiveElement,
        law: &dyn ForceLaw,
        lin: &LinearPart,
        ws: &mut AftBuffers,
    ) -> bool {
        let (h, samples) = (self.basis.harmonics(), self.basis.samples());
        if samples <= 4 * h {
            return false;
        }
        let omega = self.basis.fundamental();
        if !ws.pieces.collect(
            law,
            &ws.edges,
            &act.time_breaks,
            &ws.uk,
            omega,
            self.basis.subharmonic(),
            samples,
        ) {
            return false;
        }
        law.force_batch(&self.thetas, &ws.u, &ws.du, &mut ws.ge);
        ws.force_evaluations += samples + 6 * ws.pieces.breaks.len() + 2;
        if !ws.pieces.agrees_with(&ws.ge, &ws.u, &ws.du) {
            return false;
        }
        ws.pieces
            .fourier_into(2 * h, [&mut ws.spec_u, &mut ws.spec_du, &mut ws.spec_e]);
        self.aft
            .synthesize_bins_into(&ws.spec_u[..=2 * h], &mut ws.gu, &mut ws.aft);
        self.aft
            .synthesize_bins_into(&ws.spec_du[..=2 * h], &mut ws.gdu, &mut ws.aft);
        self.aft
            .synthesize_bins_into(&ws.spec_e[..=2 * h], &mut ws.ge, &mut ws.aft);
        for j in 0..samples {
            let (u, du) = (ws.u[j], ws.du[j]);
            ws.f[j] = (ws.gu[j] - lin.stiffness) * u + (ws.gdu[j] - lin.damping) * du + ws.ge[j]
                - lin.offset;
        }
        self.aft.analyze_into(&mut ws.f, &mut ws.uk, &mut ws.aft);
        ws.ffts += 4;
        ws.spec_u[0].re -= lin.stiffness;
        ws.spec_du[0].re -= lin.damping;
        ws.pieces.add_pulses(&mut ws.spec_u);
        true
    }
}
