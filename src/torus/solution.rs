//! A converged (or marked) quasi-periodic response: its lines `Q_k` at `ν_k = Ω k·r`.

use num_complex::Complex64;

/// The response `q(t) = Re Σ_k Q_k e^{i k·(ω t + φ)}` of every DOF, with the lines of the
/// index set, how it was found and how well it balances.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TorusSolution {
    /// The speed Ω (rad/s).
    pub omega: f64,
    /// The bases' names.
    pub bases: Vec<String>,
    /// The bases' ratios `r_b` (`ω_b = r_b Ω`).
    pub ratios: Vec<f64>,
    /// The DOF names.
    pub dofs: Vec<String>,
    /// The indices `k` (d integers each), `k = 0` first, by ascending frequency.
    pub indices: Vec<Vec<i32>>,
    /// `ν_k = Ω k·r` per index (rad/s).
    pub frequencies: Vec<f64>,
    /// `Q_k` line-major (`j n + i`).
    pub harmonics: Vec<(f64, f64)>,
    /// The condensed unknowns `U_k` (line-major over the element coordinates).
    pub unknowns: Vec<(f64, f64)>,
    /// `‖R‖ / max(‖L‖, ‖G⁻¹ U‖)` at the end.
    pub relative_residual: f64,
    /// Whether it reached the tolerance.
    pub converged: bool,
    /// Newton steps.
    pub iterations: usize,
    /// Jacobian-vector products of the Krylov solver.
    pub linear_iterations: usize,
    /// Per base, what its truncation lacks: the response on the first lines beyond its cap
    /// relative to the alternating response, on the element coordinates (see
    /// [`TorusBalance::truncation_estimates`](super::TorusBalance::truncation_estimates));
    /// `None` where the grid cannot resolve one more harmonic of the base.
    pub truncation: Vec<Option<f64>>,
}

impl TorusSolution {
    /// Number of DOFs.
    pub fn n_dofs(&self) -> usize {
        self.dofs.len()
    }

    /// `Q_k` of DOF `dof` at index `k` (d integers; `-k` gives the conjugate), zero for an
    /// index outside the set.
    pub fn harmonic(&self, dof: usize, k: &[i32]) -> Complex64 {
        let n = self.n_dofs();
        let neg: Vec<i32> = k.iter().map(|v| -v).collect();
        if let Some(j) = self.indices.iter().position(|i| i == k) {
            let (re, im) = self.harmonics[j * n + dof];
            return Complex64::new(re, im);
        }
        if let Some(j) = self.indices.iter().position(|i| *i == neg) {
            let (re, im) = self.harmonics[j * n + dof];
            return Complex64::new(re, -im);
        }
        Complex64::default()
    }

    /// `q_dof(t)` on the line `θ_b = ω_b t + φ_b` of the torus (`phases` one per base, the
    /// missing ones 0; the phase of a base is where its angle starts, a mesh phasing).
    pub fn value(&self, dof: usize, t: f64, phases: &[f64]) -> f64 {
        let n = self.n_dofs();
        self.indices
            .iter()
            .enumerate()
            .map(|(j, k)| {
                let angle: f64 = k
                    .iter()
                    .zip(&self.ratios)
                    .enumerate()
                    .map(|(b, (&kb, r))| {
                        let phase = phases.get(b).copied().unwrap_or(0.0);
                        kb as f64 * (r * self.omega * t + phase)
                    })
                    .sum();
                let (re, im) = self.harmonics[j * n + dof];
                (Complex64::new(re, im) * Complex64::from_polar(1.0, angle)).re
            })
            .sum()
    }

    /// The order `k·r` of the speed of line `j`.
    pub fn order(&self, j: usize) -> f64 {
        self.indices[j]
            .iter()
            .zip(&self.ratios)
            .map(|(&k, r)| k as f64 * r)
            .sum()
    }

    /// The lines `Σ w_i Q_{i,k}` of the coordinate with weights `(dof, w)`, line by line (a
    /// gear stage's transmission error with the element's weights).
    pub fn coordinate_lines(&self, weights: &[(usize, f64)]) -> Vec<Complex64> {
        let n = self.n_dofs();
        (0..self.indices.len())
            .map(|j| {
                weights.iter().fold(Complex64::default(), |acc, &(i, w)| {
                    let (re, im) = self.harmonics[j * n + i];
                    acc + Complex64::new(re, im) * w
                })
            })
            .collect()
    }

    /// The lines of DOF `dof` as `(k, ν_k, |Q_k|)`, strongest first (the mean excluded).
    pub fn lines(&self, dof: usize) -> Vec<(Vec<i32>, f64, f64)> {
        let n = self.n_dofs();
        let mut lines: Vec<_> = (1..self.indices.len())
            .map(|j| {
                let (re, im) = self.harmonics[j * n + dof];
                (self.indices[j].clone(), self.frequencies[j], re.hypot(im))
            })
            .collect();
        lines.sort_by(|a, b| b.2.total_cmp(&a.2));
        lines
    }
}
