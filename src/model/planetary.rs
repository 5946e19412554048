//! A planetary gear set: sun, ring, carrier and `N` equally spaced planets, each planet in
//! mesh with the sun and the ring, all `2N` meshes at one mesh frequency with their phases.
//!
//! # Coordinates and signs
//!
//! The sun, ring and carrier angles are positive in the sun's running direction; each planet's
//! angle is its absolute spin, positive in its own running direction (opposite to the sun's
//! when the ring stands). With base radii `r_s`, `r_p`, `r_r` the mesh deflections along the
//! lines of action of planet n are
//!
//! `u_sn = r_s θ_s − r_p θ_n − (r_s + r_p) θ_c`,  `u_rn = r_r θ_r + r_p θ_n − (r_r − r_p) θ_c`,
//!
//! both positive when the sun drives (the torsional model of Lin & Parker, J. Sound Vib. 1999,
//! in absolute angles). A planet then carries equal forces from sun and ring, the sun's torque
//! is `r_s Σ f_sn`, the carrier's `(r_s + r_p) Σ f_sn + (r_r − r_p) Σ f_rn`. The carrier's
//! inertia must include the planets' orbital `N m_p a²`.
//!
//! # Mesh frequency and phasing
//!
//! Every mesh runs `z_s |Ω_s − Ω_c| = z_r |Ω_r − Ω_c|` cycles per second. Planet n sits
//! `ψ_n = 2π n / N` ahead of planet 0; its sun mesh lags by `z_s ψ_n` of the mesh cycle and its
//! ring mesh leads by `z_r ψ_n` (Parker & Lin, J. Mech. Des. 2004, in this sign convention),
//! and `ring_phase` shifts every ring mesh against the sun meshes. Equal spacing needs
//! `(z_s + z_r) / N` whole.

use crate::error::{check_finite, check_non_negative, Error, Result};
use crate::force::{Backlash, Flank, ForceLaw, MeshDamping, MeshProfile, MeshStiffness, MAX_TEETH};
use std::f64::consts::TAU;

/// One mesh of a planetary set: name suffix (`sun 1`), `(DOF, weight)` pairs, law.
pub type Mesh<'a> = (String, Vec<(&'a str, f64)>, Box<dyn ForceLaw>);

/// A planetary set (module documentation for the coordinates and phasing).
///
/// ```
/// use hbal::force::MeshProfile;
/// use hbal::model::PlanetarySet;
/// let k = MeshProfile::Constant { stiffness: 5e8 };
/// let set = PlanetarySet::new("sun", "ring", "carrier", &["p1", "p2", "p3"], [24, 72], [0.03, 0.03, 0.09], k.clone(), k);
/// assert_eq!(set.carrier_order(), 0.25); // ring fixed: 24 / (24 + 72)
/// assert_eq!(set.mesh_order_of_speed(), 18.0); // 24 × (1 − 0.25)
/// let meshes = set.meshes();
/// assert_eq!(meshes.len(), 6);
/// assert_eq!(meshes[1].0, "sun 2");
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanetarySet {
    /// DOF of the sun.
    pub sun: String,
    /// DOF of the ring.
    pub ring: String,
    /// DOF of the carrier.
    pub carrier: String,
    /// DOFs of the planets (absolute spins), in order around the carrier.
    pub planets: Vec<String>,
    /// Teeth of sun and ring `[z_s, z_r]`.
    pub teeth: [u32; 2],
    /// Base radii of sun, planet and ring `[r_s, r_p, r_r]`, m.
    pub base_radii: [f64; 3],
    /// Sun revolutions per revolution of the reference shaft (default 1).
    #[serde(default = "one")]
    pub sun_order: f64,
    /// Carrier revolutions per revolution of the reference shaft (default: a standing ring,
    /// `sun_order z_s / (z_s + z_r)`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carrier_order: Option<f64>,
    /// Stiffness over the mesh cycle of every sun-planet mesh, N/m.
    pub sun_stiffness: MeshProfile,
    /// Stiffness over the mesh cycle of every ring-planet mesh, N/m.
    pub ring_stiffness: MeshProfile,
    /// Mesh damping of every mesh (default none).
    #[serde(default)]
    pub damping: MeshDamping,
    /// Total backlash of every mesh along its line of action, m (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backlash: Option<f64>,
    /// Phase of the ring meshes against the sun meshes, rad of the mesh cycle (default 0).
    #[serde(default)]
    pub ring_phase: f64,
    /// The order of the fundamental (or base) the meshes count against (a scene sets it).
    #[serde(skip, default = "one")]
    pub fundamental_order: f64,
}

fn one() -> f64 {
    1.0
}

impl PlanetarySet {
    /// A set with a standing ring, no damping and no backlash.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        sun: &str,
        ring: &str,
        carrier: &str,
        planets: &[&str],
        teeth: [u32; 2],
        base_radii: [f64; 3],
        sun_stiffness: MeshProfile,
        ring_stiffness: MeshProfile,
    ) -> Self {
        Self {
            sun: sun.into(),
            ring: ring.into(),
            carrier: carrier.into(),
            planets: planets.iter().map(|p| p.to_string()).collect(),
            teeth,
            base_radii,
            sun_order: 1.0,
            carrier_order: None,
            sun_stiffness,
            ring_stiffness,
            damping: MeshDamping::default(),
            backlash: None,
            ring_phase: 0.0,
            fundamental_order: 1.0,
        }
    }

    /// Sets the backlash of every mesh (m).
    pub fn with_backlash(mut self, backlash: f64) -> Self {
        self.backlash = Some(backlash);
        self
    }

    /// Sets the mesh damping.
    pub fn with_damping(mut self, damping: MeshDamping) -> Self {
        self.damping = damping;
        self
    }

    /// The carrier's order of the reference speed.
    pub fn carrier_order(&self) -> f64 {
        let [zs, zr] = self.teeth.map(f64::from);
        self.carrier_order
            .unwrap_or(self.sun_order * zs / (zs + zr))
    }

    /// Mesh cycles per revolution of the reference shaft, `z_s |sun_order − carrier_order|`.
    pub fn mesh_order_of_speed(&self) -> f64 {
        f64::from(self.teeth[0]) * (self.sun_order - self.carrier_order()).abs()
    }

    /// Checks every field; `context` names the element.
    pub fn validate(&self, context: &str) -> Result<()> {
        let n = self.planets.len();
        if n == 0 {
            return Err(Error::InvalidElement {
                context: context.into(),
                reason: "`planets` names no planet DOF".into(),
            });
        }
        let mut names: Vec<&str> = vec![&self.sun, &self.ring, &self.carrier];
        names.extend(self.planets.iter().map(String::as_str));
        for (i, a) in names.iter().enumerate() {
            if names[..i].contains(a) {
                return Err(Error::InvalidElement { context: context.into(), reason: format!("DOF `{a}` is named twice (sun, ring, carrier and planets are different DOFs)") });
            }
        }
        for (i, &z) in self.teeth.iter().enumerate() {
            crate::force::check_teeth(&format!("{context} teeth[{i}]"), z)?;
        }
        let [zs, zr] = self.teeth;
        if zr <= zs || (zs + zr) % n as u32 != 0 {
            return Err(Error::InvalidElement {
                context: context.into(),
                reason: format!("teeth [{zs}, {zr}] with {n} equally spaced planets: the ring needs more teeth than the sun and (z_s + z_r) / N = {}/{n} must be whole", zs + zr),
            });
        }
        for (i, &r) in self.base_radii.iter().enumerate() {
            if !(r.is_finite() && r > 0.0) {
                return Err(Error::invalid(
                    context,
                    format!("base_radii[{i}]"),
                    r,
                    "finite and > 0 (m)",
                ));
            }
        }
        let [rs, rp, rr] = self.base_radii;
        // Meshing gears share one base pitch 2π r_b / z: sun and ring through the planet.
        let (ps, pr) = (rs / f64::from(zs), rr / f64::from(zr));
        if (ps - pr).abs() > 1e-3 * ps.max(pr) {
            return Err(Error::invalid(
                context,
                "base_radii[2]",
                rr,
                format!("{:.6e} m, the sun's base radius per tooth r_s / z_s = {ps:.6e} times the ring's {zr} teeth (sun and ring mesh with the same planets, so they share one base pitch)", ps * f64::from(zr)),
            ));
        }
        if rr <= rp {
            return Err(Error::invalid(
                context,
                "base_radii[2]",
                rr,
                format!("larger than the planet's {rp} (the ring's base radius)"),
            ));
        }
        check_finite(context, "sun_order", self.sun_order)?;
        check_finite(context, "ring_phase", self.ring_phase)?;
        if let Some(c) = self.carrier_order {
            check_finite(context, "carrier_order", c)?;
        }
        if !(self.fundamental_order.is_finite() && self.fundamental_order > 0.0) {
            return Err(Error::invalid(
                context,
                "fundamental_order",
                self.fundamental_order,
                "finite and > 0",
            ));
        }
        if let Some(b) = self.backlash {
            check_non_negative(context, "backlash", b)?;
        }
        self.sun_stiffness.validate(context)?;
        self.ring_stiffness.validate(context)?;
        self.damping.validate(context)?;
        self.mesh_cycles(context).map(|_| ())
    }

    /// Mesh cycles per period of the fundamental: a whole number where a stiffness varies.
    fn mesh_cycles(&self, context: &str) -> Result<u32> {
        let varies = self.sun_stiffness.time_order(1).is_some()
            || self.ring_stiffness.time_order(1).is_some();
        if !varies {
            return Ok(1);
        }
        let z = self.mesh_order_of_speed() / self.fundamental_order;
        let r = z.round();
        if !(r >= 1.0 && r <= f64::from(MAX_TEETH) && (z - r).abs() <= 1e-9 * z.max(1.0)) {
            return Err(Error::invalid(
                context,
                "sun_order",
                self.sun_order,
                format!("such that the mesh cycles per period of the fundamental, z_s |sun_order − carrier_order| / fundamental order = {z:.9}, are a whole number from 1 to {MAX_TEETH}"),
            ));
        }
        Ok(r as u32)
    }

    /// The `2N` meshes as `(name suffix, weights, law)`: `sun n` then `ring n` for n = 1..=N.
    /// Call [`PlanetarySet::validate`] first.
    pub fn meshes(&self) -> Vec<Mesh<'_>> {
        let [rs, rp, rr] = self.base_radii;
        let [zs, zr] = self.teeth.map(f64::from);
        let n = self.planets.len();
        let z = self.mesh_cycles("").unwrap_or(1);
        let law = |profile: &MeshProfile, phase: f64| -> Box<dyn ForceLaw> {
            let phase = phase.rem_euclid(TAU);
            match self.backlash {
                None => {
                    Box::new(MeshStiffness::new(z, profile.clone(), self.damping).with_phase(phase))
                }
                Some(b) => Box::new(Backlash {
                    half_backlash: 0.5 * b,
                    stiffness: profile.clone(),
                    teeth: z,
                    phase,
                    contact_damping: self.damping.value(profile.mean()),
                    flank: Flank::Drive,
                }),
            }
        };
        let mut out = Vec::with_capacity(2 * n);
        for (i, p) in self.planets.iter().enumerate() {
            let psi = TAU * i as f64 / n as f64;
            let w = vec![
                (self.sun.as_str(), rs),
                (p.as_str(), -rp),
                (self.carrier.as_str(), -(rs + rp)),
            ];
            out.push((
                format!("sun {}", i + 1),
                w,
                law(&self.sun_stiffness, -zs * psi),
            ));
        }
        for (i, p) in self.planets.iter().enumerate() {
            let psi = TAU * i as f64 / n as f64;
            let w = vec![
                (self.ring.as_str(), rr),
                (p.as_str(), rp),
                (self.carrier.as_str(), -(rr - rp)),
            ];
            out.push((
                format!("ring {}", i + 1),
                w,
                law(&self.ring_stiffness, zr * psi + self.ring_phase),
            ));
        }
        out
    }
}
