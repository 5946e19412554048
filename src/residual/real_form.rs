//! The residual `R(x) = Z(Ω) Q + F_rest(Q) - F_split` in the real layout ([`RealLayout`]: per
//! harmonic the cosine and sine amplitudes `a_k`, `b_k` of `Q_k = a_k - i b_k`), fused with its
//! Jacobian `∂R/∂x = Z ⊕ ∂F_rest/∂x` (the block `[[A, B], [-B, A]]` of `Z_k = A + iB` per
//! harmonic, plus the AFT part), and the Parseval norm of a harmonic vector.

use super::{HarmonicBalance, Workspace};
use crate::error::Result;
use crate::harmonic::{Part, RealLayout};
use nalgebra::DMatrix;
use num_complex::Complex64;

impl HarmonicBalance<'_> {
    /// The real layout of the unknowns.
    pub fn layout(&self) -> RealLayout {
        RealLayout {
            n: self.n,
            h: self.basis.harmonics(),
        }
    }

    /// Fused residual and Jacobian in the real layout: `r ← R(x)`, and if `jac` is given,
    /// `jac ← ∂R/∂x = Z ⊕ ∂F_rest/∂x` (the block `[[A, B], [-B, A]]` of
    /// `Z_k = A + iB` for every harmonic, plus the AFT part). Both come from one AFT pass.
    pub fn residual_real_into(
        &self,
        x: &[f64],
        r: &mut [f64],
        mut jac: Option<&mut DMatrix<f64>>,
        ws: &mut Workspace,
    ) -> Result<()> {
        let layout = self.layout();
        layout.unpack(x, &mut ws.q);
        if let Some(j) = jac.as_deref_mut() {
            j.fill(0.0);
        }
        self.aft_into(&ws.q, &mut ws.rest, jac.as_deref_mut(), &mut ws.eval)?;
        let n = layout.n;
        for k in 0..=layout.h {
            let s = k * n..(k + 1) * n;
            self.z.apply(k, &ws.q[s.clone()], &mut ws.zq[s.clone()]);
            for i in s {
                ws.rhs[i] = ws.zq[i] + ws.rest[i] - self.f_split[i];
            }
        }
        layout.pack(&ws.rhs, r);
        if let Some(j) = jac {
            self.add_dynamic_stiffness_real(j);
        }
        Ok(())
    }

    /// `jac += Z` in the real layout: the block `[[A, B], [-B, A]]` of `Z_k = A + iB` per
    /// harmonic (`K0` alone at k = 0).
    pub fn add_dynamic_stiffness_real(&self, jac: &mut DMatrix<f64>) {
        let layout = self.layout();
        let n = layout.n;
        for k in 0..=layout.h {
            let z = self.z.matrix(k);
            let ca = RealLayout::block(k, Part::Cos) * n;
            let cb = RealLayout::block(k, Part::Sin) * n;
            for i in 0..n {
                for jj in 0..n {
                    let (a, b) = (z[(i, jj)].re, z[(i, jj)].im);
                    jac[(ca + i, ca + jj)] += a;
                    if k > 0 {
                        jac[(ca + i, cb + jj)] += b;
                        jac[(cb + i, ca + jj)] -= b;
                        jac[(cb + i, cb + jj)] += a;
                    }
                }
            }
        }
    }

    /// Parseval norm `sqrt(Σ_i [|X_0i|² + ½ Σ_k |X_ki|²])`: the RMS over one period, summed
    /// over DOFs.
    pub fn norm(&self, x: &[Complex64]) -> f64 {
        let n = self.n;
        let mut s = 0.0;
        for (idx, v) in x.iter().enumerate() {
            s += if idx < n {
                v.norm_sqr()
            } else {
                0.5 * v.norm_sqr()
            };
        }
        s.sqrt()
    }
}
