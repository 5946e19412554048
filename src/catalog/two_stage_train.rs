//! The free-free two-stage car drivetrain of issue 34, whose engine orders and two meshes
//! share no short period: the torus's benchmark ([`crate::torus`]).

use crate::error::Result;
use crate::force::{Backlash, Flank, MeshProfile};
use crate::model::Model;
use crate::torus::{Bases, TorusModel};

/// A free-free drivetrain of 8 inertias: crank, flywheel, a clutch damper to the gearbox
/// input, stage 1 (23/67 teeth), the intermediate shaft, stage 2 (19/71 teeth) and the vehicle
/// behind the half shafts. A 4-stroke engine drives the crank with mean torque and orders 0.5,
/// 2 and 4; the road load balances the mean. Both meshes are rectangular one-/two-tooth
/// stiffnesses with backlash.
///
/// The speed Ω is the crank's (rad/s). The bases: `engine` at Ω/2 (order 0.5 is its harmonic
/// 1, order 4 its harmonic 8), `mesh 1` at 23 Ω, `mesh 2` at `19 · 23/67 Ω`. Their common
/// period is 134 crank revolutions: stage 1 meshes at harmonic 3082 of it, stage 2 at 874.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoStageTrain {
    /// Mean engine torque (N m).
    pub mean_torque: f64,
    /// Amplitudes of the engine orders 0.5, 2 and 4 (N m).
    pub orders: [f64; 3],
    /// Total backlash of each mesh (m, along the line of action).
    pub backlash: f64,
}

impl Default for TwoStageTrain {
    fn default() -> Self {
        Self {
            mean_torque: 150.0,
            orders: [25.0, 120.0, 40.0],
            backlash: 1e-4,
        }
    }
}

impl TwoStageTrain {
    /// Teeth of pinion 1, gear 1, pinion 2, gear 2.
    pub const TEETH: [u32; 4] = [23, 67, 19, 71];

    /// The bases' `(name, ratio)` over the crank speed.
    pub fn bases() -> Result<Bases> {
        let [z1, z2, z3, _] = Self::TEETH.map(f64::from);
        Bases::new(&[("engine", 0.5), ("mesh 1", z1), ("mesh 2", z3 * z1 / z2)])
    }

    /// The model: DOF angles positive in each shaft's running direction; the meshes'
    /// laws have one cycle per revolution of their base's angle.
    pub fn model(&self) -> Result<Model> {
        let module = [0.0025, 0.003];
        let [z1, z2, z3, z4] = Self::TEETH.map(f64::from);
        let r = [
            z1 * module[0] / 2.0,
            z2 * module[0] / 2.0,
            z3 * module[1] / 2.0,
            z4 * module[1] / 2.0,
        ];
        let mesh = |one: f64, two: f64, contact_ratio: f64| Backlash {
            half_backlash: 0.5 * self.backlash,
            stiffness: MeshProfile::Rectangular {
                one_tooth: one,
                two_tooth: two,
                contact_ratio,
            },
            teeth: 1,
            phase: 0.0,
            contact_damping: 800.0,
            flank: Flank::Drive,
        };
        let pairs = [
            (0, 1, 8e4, 8.0),   // crank - flywheel
            (1, 2, 900.0, 6.0), // clutch damper
            (2, 3, 2e4, 2.0),   // input shaft
            (4, 5, 4e4, 3.0),   // intermediate shaft
            (6, 7, 6e3, 20.0),  // half shafts
        ];
        let mut k = Vec::new();
        let mut d = Vec::new();
        for (a, b, ks, ds) in pairs {
            for (list, v) in [(&mut k, ks), (&mut d, ds)] {
                list.extend([(a, a, v), (a, b, -v), (b, a, -v), (b, b, v)]);
            }
        }
        let road = -self.mean_torque * (z2 / z1) * (z4 / z3);
        let [o05, o2, o4] = self.orders;
        Model::builder(&[
            "crank", "flywheel", "input", "pinion1", "gear1", "pinion2", "gear2", "vehicle",
        ])
        .mass_diagonal(&[0.15, 0.25, 0.012, 0.002, 0.009, 0.003, 0.016, 12.0])
        .stiffness_triplets(&k)
        .damping_triplets(&d)
        .element(
            "stage 1",
            &[("pinion1", r[0]), ("gear1", -r[1])],
            mesh(3e8, 5e8, 1.5),
        )
        .element(
            "stage 2",
            &[("pinion2", r[2]), ("gear2", -r[3])],
            mesh(4e8, 6.5e8, 1.6),
        )
        .load("crank", 0, self.mean_torque, 0.0)
        .load("vehicle", 0, road, 0.0)
        .load("crank", 1, o05, 0.0)
        .load("crank", 4, o2, 0.0)
        .load("crank", 8, 0.0, o4)
        .build()
    }

    /// `model` (from [`TwoStageTrain::model`]) on its bases: the engine orders on `engine`,
    /// each stage on its mesh.
    pub fn bind(model: &Model) -> Result<TorusModel<'_>> {
        let mut tm = TorusModel::new(model, Self::bases()?)
            .bind_element("stage 1", "mesh 1")?
            .bind_element("stage 2", "mesh 2")?;
        for l in 0..model.loads().len() {
            tm = tm.bind_load(l, "engine")?;
        }
        Ok(tm)
    }
}
