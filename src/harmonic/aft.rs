//! Alternating frequency/time transforms on real FFTs (realfft), planned once.
//!
//! Synthesis: `x_j = Re Σ_{k=0}^{H} X_k e^{2πi jk/N}` with the half-spectrum
//! `(X_0, X_1/2, ..., X_H/2, 0, ...)` fed to the inverse real FFT (which does not normalise).
//! Analysis: `X_0 = F_0/N`, `X_k = 2 F_k / N` from the forward real FFT `F`.
//! Harmonics above H are discarded (they alias when N is small; see [`HarmonicBasis`]).

use super::HarmonicBasis;
use num_complex::Complex64;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::sync::Arc;

/// Planned forward and inverse real FFTs of length N. Shareable; cheap to clone.
#[derive(Clone)]
pub struct AftPlan {
    basis: HarmonicBasis,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
}

impl std::fmt::Debug for AftPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AftPlan")
            .field("basis", &self.basis)
            .finish()
    }
}

/// Caller-owned buffers for [`AftPlan`]: the half spectrum and the FFT scratch.
#[derive(Debug, Clone)]
pub struct AftScratch {
    spectrum: Vec<Complex64>,
    scratch: Vec<Complex64>,
}

impl AftPlan {
    /// Plans both transforms for `basis`.
    pub fn new(basis: HarmonicBasis) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        let n = basis.samples();
        Self {
            basis,
            forward: planner.plan_fft_forward(n),
            inverse: planner.plan_fft_inverse(n),
        }
    }

    /// The basis.
    pub fn basis(&self) -> &HarmonicBasis {
        &self.basis
    }

    /// Buffers for this plan.
    pub fn make_scratch(&self) -> AftScratch {
        let n = self.basis.samples();
        let len = self
            .forward
            .get_scratch_len()
            .max(self.inverse.get_scratch_len());
        AftScratch {
            spectrum: vec![Complex64::default(); n / 2 + 1],
            scratch: vec![Complex64::default(); len],
        }
    }

    /// Writes `x_j = Re Σ_k c_k X_k e^{ikθ_j}` into `out` (length N), where `c_k = scale(k)`;
    /// with `scale = |_| 1` it is the plain synthesis, with `scale = |k| i k Ω` the time
    /// derivative.
    pub fn synthesize_into(
        &self,
        harmonics: &[Complex64],
        scale: impl Fn(usize) -> Complex64,
        out: &mut [f64],
        s: &mut AftScratch,
    ) {
        let h = self.basis.harmonics();
        debug_assert_eq!(harmonics.len(), h + 1);
        s.spectrum.fill(Complex64::default());
        s.spectrum[0] = Complex64::new((harmonics[0] * scale(0)).re, 0.0);
        for (k, (bin, q)) in s.spectrum[1..=h]
            .iter_mut()
            .zip(&harmonics[1..])
            .enumerate()
        {
            *bin = q * scale(k + 1) * 0.5;
        }
        // For even N the last bin is the Nyquist bin, which must be real; N >= 2H+1 keeps it
        // empty. For odd N it is an ordinary harmonic.
        // The only error realfft reports is a wrong buffer length, ruled out by construction.
        let _ = self
            .inverse
            .process_with_scratch(&mut s.spectrum, out, &mut s.scratch);
    }

    /// Writes `x_j = Σ_{|m|<=M} c_m e^{imθ_j}` (`c_{-m} = conj c_m`) into `out` (length N)
    /// from the normalised coefficients `c_m = bins[m]`, `m = 0..=M` (`M <= N/2`, the
    /// inverse of [`AftPlan::spectrum_into`] for a band-limited signal).
    pub fn synthesize_bins_into(&self, bins: &[Complex64], out: &mut [f64], s: &mut AftScratch) {
        s.spectrum.fill(Complex64::default());
        let top = bins.len().min(s.spectrum.len());
        s.spectrum[..top].copy_from_slice(&bins[..top]);
        s.spectrum[0].im = 0.0;
        // For even N the last bin is the Nyquist bin, which must be real (with M < N/2, as
        // the exact contact path has, it is empty).
        if self.basis.samples() % 2 == 0 {
            if let Some(last) = s.spectrum.last_mut() {
                last.im = 0.0;
            }
        }
        let _ = self
            .inverse
            .process_with_scratch(&mut s.spectrum, out, &mut s.scratch);
    }

    /// Writes the harmonics `0..=H` of the samples `x` (length N, overwritten) into `out`.
    pub fn analyze_into(&self, x: &mut [f64], out: &mut [Complex64], s: &mut AftScratch) {
        let h = self.basis.harmonics();
        let inv_n = 1.0 / self.basis.samples() as f64;
        let _ = self
            .forward
            .process_with_scratch(x, &mut s.spectrum, &mut s.scratch);
        out[0] = Complex64::new(s.spectrum[0].re * inv_n, 0.0);
        for (o, bin) in out[1..=h].iter_mut().zip(&s.spectrum[1..=h]) {
            *o = bin * (2.0 * inv_n);
        }
    }

    /// Writes the normalised DFT bins `x̂_m = (1/N) Σ_j x_j e^{-imθ_j}`, `m = 0..=N/2`, of the
    /// samples `x` (length N, overwritten) into `out` (length N/2 + 1). Bins of other `m` follow
    /// from `x̂_{-m} = conj(x̂_m)` and periodicity in N.
    pub fn spectrum_into(&self, x: &mut [f64], out: &mut [Complex64], s: &mut AftScratch) {
        let inv_n = 1.0 / self.basis.samples() as f64;
        let _ = self.forward.process_with_scratch(x, out, &mut s.scratch);
        for v in out.iter_mut() {
            *v *= inv_n;
        }
    }
}
