//! A long torsional chain with backlash meshes: many modes in the excitation band, the
//! stability benchmark at scale (issue 31, item 4).

use crate::error::Result;
use crate::force::{Backlash, MeshProfile};
use crate::model::Model;

/// `dofs` equal inertias in a line, the first grounded, neighbours joined by torsional springs,
/// `meshes` of the joints (evenly spaced) a backlash contact with a rectangular mesh stiffness
/// instead. Rayleigh damping `D = α M + β K` (the springs' K; by default 2 % of critical at the
/// lowest mode, 7 rad/s, and at 4000 rad/s); a mean torque on the last
/// inertia presses every mesh onto its drive flank, an alternating one on the first excites
/// it. With the defaults (1000 inertias of 1e-3 kg m², springs 2e4 N m/rad) the natural
/// frequencies reach `2√(k/J) ≈ 8944 rad/s`, below `3 H Ω` for H = 32 at Ω = 120 rad/s: every
/// mode lies in the band a reduced basis keeps.
///
/// ```
/// let model = hbal::catalog::MeshChain { dofs: 50, ..Default::default() }.model()?;
/// assert_eq!(model.n_dofs(), 50);
/// assert_eq!(model.elements().len(), 4);
/// # Ok::<(), hbal::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshChain {
    /// Number of inertias (at least `2 meshes + 1`).
    pub dofs: usize,
    /// Inertia of each (kg m²).
    pub inertia: f64,
    /// Torsional stiffness of each spring (N m/rad).
    pub stiffness: f64,
    /// Number of meshes.
    pub meshes: usize,
    /// Half backlash of each mesh (rad).
    pub half_backlash: f64,
    /// Mass-proportional damping α (1/s).
    pub alpha: f64,
    /// Stiffness-proportional damping β (s).
    pub beta: f64,
    /// Mean torque on the last inertia (N m).
    pub mean_torque: f64,
    /// Alternating torque (order 1) on the first inertia (N m).
    pub alternating_torque: f64,
}

impl Default for MeshChain {
    fn default() -> Self {
        Self {
            dofs: 1000,
            inertia: 1e-3,
            stiffness: 2e4,
            meshes: 4,
            half_backlash: 1e-4,
            alpha: 0.3,
            beta: 1e-5,
            mean_torque: 20.0,
            alternating_torque: 5.0,
        }
    }
}

impl MeshChain {
    /// The model.
    pub fn model(&self) -> Result<Model> {
        let n = self.dofs;
        if n < 2 * self.meshes + 1 {
            return Err(crate::Error::invalid(
                "mesh chain",
                "dofs",
                n as f64,
                format!(">= {} (twice the meshes plus one)", 2 * self.meshes + 1),
            ));
        }
        let names: Vec<String> = (0..n).map(|i| format!("j{i}")).collect();
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        // Joint i joins inertias i and i + 1; the meshes sit at evenly spaced joints.
        let mesh_joints: Vec<usize> = (1..=self.meshes)
            .map(|m| m * (n - 1) / (self.meshes + 1))
            .collect();
        let (k, c) = (self.stiffness, self.beta * self.stiffness);
        let mut stiffness = vec![(0, 0, k)];
        let mut damping = vec![(0, 0, c)];
        for i in (0..n - 1).filter(|i| !mesh_joints.contains(i)) {
            for (a, b, s) in [
                (i, i, 1.0),
                (i + 1, i + 1, 1.0),
                (i, i + 1, -1.0),
                (i + 1, i, -1.0),
            ] {
                stiffness.push((a, b, s * k));
                damping.push((a, b, s * c));
            }
        }
        damping.extend((0..n).map(|i| (i, i, self.alpha * self.inertia)));
        let mut builder = Model::builder(&refs)
            .mass_diagonal(&vec![self.inertia; n])
            .stiffness_triplets(&stiffness)
            .damping_triplets(&damping)
            .load(refs[n - 1], 0, -self.mean_torque, 0.0)
            .load(refs[0], 1, self.alternating_torque, 0.0);
        for (m, &i) in mesh_joints.iter().enumerate() {
            let profile = MeshProfile::Rectangular {
                one_tooth: k,
                two_tooth: 1.5 * k,
                contact_ratio: 1.5,
            };
            let law = Backlash::new(self.half_backlash, profile);
            builder = builder.element(
                &format!("mesh{m}"),
                &[(refs[i], 1.0), (refs[i + 1], -1.0)],
                law,
            );
        }
        builder.build()
    }
}
