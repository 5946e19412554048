//! What each base's truncation lacks: the response on the first lines beyond its cap.
//!
//! A line `k` outside the set balances `G_k⁻¹ U_k + N_k(U) = 0` (the loads all lie inside), so
//! its response, to first order, is `ΔU_k = -G_k N_k(U)` with the rest `N_k` of the converged
//! solution, which the AFT gives at no extra sampling cost when the grid resolves one more
//! harmonic of the base (`N_b >= 2 H_b + 3`). Summed over the shell `|k_b| = H_b + 1` of each
//! base b (lines beyond the total degree of a diamond go to the base they reach furthest in),
//! `e_b = ‖ΔU‖ / ‖U_alternating‖` on the element coordinates (the transmission errors) says
//! which base needs more harmonics.

use super::balance::{TorusBalance, TorusWorkspace};
use super::grid::TorusFft;
use super::{IndexSet, Truncation};
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;

impl TorusBalance<'_> {
    /// `e_b` per base at the unknowns `u`; `None` for a base whose grid cannot resolve one more
    /// harmonic, and for every base where the set cannot grow (a combination of frequency
    /// zero just beyond the caps).
    pub fn truncation_estimates(
        &self,
        u: &[Complex64],
        ws: &mut TorusWorkspace,
    ) -> Result<Vec<Option<f64>>> {
        let (d, m) = (self.set.dims(), self.coordinates());
        let caps = self.set.caps();
        let samples = self.samples();
        let resolved: Vec<bool> = (0..d).map(|b| samples[b] >= 2 * caps[b] + 3).collect();
        if m == 0 {
            return Ok(resolved.iter().map(|&r| r.then_some(0.0)).collect());
        }
        let grown: Vec<usize> = (0..d).map(|b| caps[b] + usize::from(resolved[b])).collect();
        let truncation = match self.set.truncation() {
            Truncation::Box => Truncation::Box,
            Truncation::Diamond { total } => Truncation::Diamond { total: total + 1 },
        };
        let Ok(ext) = IndexSet::new(self.torus_model().bases(), &grown, truncation) else {
            return Ok(vec![None; d]);
        };
        let fft = TorusFft::new(&ext, samples)?;
        let mut scratch = fft.make_scratch();
        self.force_samples(u, false, ws)?;
        let mut rest = vec![Complex64::default(); ext.len() * m];
        for c in 0..m {
            let mut force = ws.force[c].clone();
            fft.analyze(&mut force, &mut scratch, |j, v| rest[j * m + c] = v);
        }
        let mut missing = vec![0.0; d];
        for j in 0..ext.len() {
            let k = ext.k(j);
            if self.set.contains_either_sign(k) {
                continue;
            }
            let b = (0..d)
                .max_by(|&a, &b| {
                    let reach = |i: usize| k[i].unsigned_abs() as f64 / (caps[i] as f64 + 0.5);
                    reach(a).total_cmp(&reach(b))
                })
                .unwrap_or(0);
            if !resolved[b] {
                continue;
            }
            let g = self.receptance(self.omega() * ext.ratio(j));
            let n_k = &rest[j * m..(j + 1) * m];
            for a in 0..m {
                let du: Complex64 = (0..m).map(|c| g[(a, c)] * n_k[c]).sum();
                missing[b] += du.norm_sqr();
            }
        }
        let alternating: f64 = u[m..].iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
        Ok((0..d)
            .map(|b| {
                resolved[b].then(|| {
                    if alternating > 0.0 {
                        missing[b].sqrt() / alternating
                    } else {
                        0.0
                    }
                })
            })
            .collect())
    }

    /// `G(ν) = Wᵀ Z(ν)⁻¹ W` at a line outside the set (zeros where `Z(ν)` is singular: a
    /// line on an undamped resonance has no finite first-order response to estimate).
    fn receptance(&self, nu: f64) -> DMatrix<Complex64> {
        let w = &self.w;
        let aug = self.augmentation.as_ref().filter(|_| nu == 0.0);
        let (z, _) = super::linear::dynamic_stiffness(&self.dense, nu, aug);
        let wc = w.map(|v| Complex64::new(v, 0.0));
        match z.lu().solve(&wc) {
            Some(x) => wc.transpose() * x,
            None => DMatrix::zeros(w.ncols(), w.ncols()),
        }
    }
}
