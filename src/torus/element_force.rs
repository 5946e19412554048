//! The force of every element as lines on the torus (a gear stage's mesh force): the law
//! sampled on the grid at the solution and analysed, as the balance sees it.

use super::{TorusBalance, TorusSolution};
use crate::error::Result;
use num_complex::Complex64;

impl TorusBalance<'_> {
    /// The lines `F_{e,k}` of every element's force `f_e(θ_b, u_e, u̇_e)` (in the model's
    /// element order; line-major over the index set) at the solution `sol` of this balance:
    /// a time-varying or nonlinear law from its samples on the grid (its band-limited form
    /// where it has one, as the balance uses it), a linear time-invariant one from
    /// `f0 + (k + iν d) U_k`.
    pub fn element_force_lines(&self, sol: &TorusSolution) -> Result<Vec<Vec<Complex64>>> {
        let u: Vec<Complex64> = sol
            .unknowns
            .iter()
            .map(|&(a, b)| Complex64::new(a, b))
            .collect();
        let model = self.torus_model().model();
        let mut out: Vec<Vec<Complex64>> = model
            .elements()
            .iter()
            .map(|e| {
                let lin = e.linear_part();
                sol.coordinate_lines(e.weights())
                    .into_iter()
                    .enumerate()
                    .map(|(j, q)| {
                        let nu = self.frequency(j);
                        let offset = if j == 0 { lin.offset } else { 0.0 };
                        q * Complex64::new(lin.stiffness, nu * lin.damping) + offset
                    })
                    .collect()
            })
            .collect();
        if u.is_empty() {
            return Ok(out);
        }
        let mut ws = self.workspace();
        for act in &self.active {
            let c = act.coordinate;
            let (mut x, mut dx) = (std::mem::take(&mut ws.u[c]), std::mem::take(&mut ws.du[c]));
            self.synthesize(&u, c, false, &mut x, &mut ws.fft);
            self.synthesize(&u, c, true, &mut dx, &mut ws.fft);
            (ws.u[c], ws.du[c]) = (x, dx);
            self.note_reach(&u, c, &mut ws);
            self.law_samples(act, &mut ws);
            let mut f = std::mem::take(&mut ws.fe);
            let target = &mut out[act.index];
            self.fft.analyze(&mut f, &mut ws.fft, |j, v| target[j] = v);
            ws.fe = f;
        }
        Ok(out)
    }
}
