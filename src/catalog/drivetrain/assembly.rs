//! Assembly of a [`Drivetrain`] into a [`Model`]: lumped inertias, spring-damper triplets
//! (0-based DOF indices), mesh and clutch elements, loads.

use super::parts::{GearPair, Shaft};
use super::Drivetrain;
use crate::error::Result;
use crate::force::{Backlash, MeshDamping, MeshProfile, MeshStiffness};
use crate::model::{Model, ModelBuilder};

/// DOF names, the diagonal of M, and the K and D triplets, grown node by node.
#[derive(Debug, Default)]
struct Assembly {
    names: Vec<String>,
    inertia: Vec<f64>,
    stiffness: Vec<(usize, usize, f64)>,
    damping: Vec<(usize, usize, f64)>,
}

impl Assembly {
    /// A new DOF with inertia `j` (kg m²); returns its index.
    fn node(&mut self, name: String, j: f64) -> usize {
        self.names.push(name);
        self.inertia.push(j);
        self.names.len() - 1
    }

    /// Adds a stiffness and damping between DOFs `a` and `b`:
    /// `[k -k; -k k]` and `[c -c; -c c]` on rows and columns a, b.
    fn couple(&mut self, a: usize, b: usize, k: f64, c: f64) {
        for (triplets, v) in [(&mut self.stiffness, k), (&mut self.damping, c)] {
            if v != 0.0 {
                triplets.extend([(a, a, v), (b, b, v), (a, b, -v), (b, a, -v)]);
            }
        }
    }

    /// Adds a stiffness and damping from DOF `a` to ground.
    fn ground(&mut self, a: usize, k: f64, c: f64) {
        for (triplets, v) in [(&mut self.stiffness, k), (&mut self.damping, c)] {
            if v != 0.0 {
                triplets.push((a, a, v));
            }
        }
    }

    /// Discretises `shaft` from the existing DOF `from`: `e` new nodes `name.1..=name.e`, each
    /// segment of stiffness `e k` and damping `β e k` with its inertia `J/e` lumped half on
    /// each end. Returns the last node.
    fn shaft(&mut self, name: &str, from: usize, shaft: &Shaft, beta: f64) -> usize {
        let e = shaft.segments;
        let k = shaft.stiffness() * e as f64;
        let j = shaft.inertia() / e as f64;
        let mut prev = from;
        for i in 1..=e {
            let node = self.node(format!("{name}.{i}"), 0.5 * j);
            self.inertia[prev] += 0.5 * j;
            self.couple(prev, node, k, beta * k);
            prev = node;
        }
        prev
    }
}

/// A mesh to be added as elements: its number (from 1), pinion and gear DOFs, pair and mesh
/// harmonic.
struct Mesh<'a> {
    number: usize,
    pinion: usize,
    gear: usize,
    pair: &'a GearPair,
    order: usize,
}

/// Builds the model of `d` (parameters already checked).
pub(super) fn build(d: &Drivetrain) -> Result<Model> {
    let orders = d.mesh_orders()?;
    let beta = d.shaft_beta;
    let e = &d.engine;
    let mut a = Assembly::default();

    // Engine: damper ring on the pulley, crank sections between pulley, throws, flywheel.
    let ring = a.node("damper_ring".into(), e.damper_ring);
    let pulley = a.node("pulley".into(), e.pulley);
    a.couple(ring, pulley, e.damper_stiffness, e.damper_damping);
    let mut throws = [0; 4];
    let mut prev = pulley;
    for (c, t) in throws.iter_mut().enumerate() {
        *t = a.node(format!("throw{}", c + 1), e.throw);
        let k = if c == 0 {
            e.nose_stiffness
        } else {
            e.throw_stiffness
        };
        a.couple(prev, *t, k, beta * k);
        prev = *t;
    }
    let flywheel = a.node("flywheel".into(), e.flywheel);
    a.couple(
        prev,
        flywheel,
        e.flange_stiffness,
        beta * e.flange_stiffness,
    );

    // Clutch damper: idle stage (and the main stage if linear) in K.
    let cl = &d.clutch;
    let hub = a.node("hub".into(), cl.hub);
    let linear_main = if cl.is_nonlinear() {
        0.0
    } else {
        cl.main_stiffness
    };
    a.couple(flywheel, hub, cl.pre_stiffness + linear_main, cl.damping);

    // Gear train: each pinion sits on the last node of the shaft before it.
    let mut meshes = Vec::with_capacity(d.meshes());
    let mut at = a.shaft("input", hub, &d.input_shaft, beta);
    for (j, stage) in d.gearbox.iter().enumerate() {
        let p = &stage.pair;
        a.inertia[at] += p.disc_inertia(p.pinion_radius());
        let gear = a.node(format!("gear{}", j + 1), p.disc_inertia(p.gear_radius()));
        meshes.push(Mesh {
            number: j + 1,
            pinion: at,
            gear,
            pair: p,
            order: orders[j],
        });
        at = a.shaft(&format!("shaft{}", j + 1), gear, &stage.shaft, beta);
    }
    at = a.shaft("prop", at, &d.propeller_shaft, beta);
    let fd = &d.final_drive;
    a.inertia[at] += fd.disc_inertia(fd.pinion_radius());
    let carrier = a.node(
        "carrier".into(),
        fd.disc_inertia(fd.gear_radius()) + d.differential,
    );
    meshes.push(Mesh {
        number: d.meshes(),
        pinion: at,
        gear: carrier,
        pair: fd,
        order: orders[d.meshes() - 1],
    });

    // Half shafts, wheels, tyres, vehicle.
    let v = &d.vehicle;
    let left = a.shaft("left", carrier, &d.half_shafts[0], beta);
    let right = a.shaft("right", carrier, &d.half_shafts[1], beta);
    a.inertia[left] += v.wheel;
    a.inertia[right] += v.wheel;
    let vehicle = a.node("vehicle".into(), v.inertia());
    for wheel in [left, right] {
        a.couple(wheel, vehicle, v.tyre_stiffness, v.tyre_damping);
    }
    a.ground(vehicle, v.ground_stiffness, v.road_damping);

    let names: Vec<&str> = a.names.iter().map(String::as_str).collect();
    let mass: Vec<(usize, usize, f64)> = a
        .inertia
        .iter()
        .enumerate()
        .map(|(i, &j)| (i, i, j))
        .collect();
    let mut b = Model::builder(&names)
        .mass_triplets(&mass)
        .stiffness_triplets(&a.stiffness)
        .damping_triplets(&a.damping);
    for m in &meshes {
        b = add_mesh(b, &names, m);
    }
    if cl.is_nonlinear() {
        b = b.element(
            "clutch",
            &[(names[flywheel], 1.0), (names[hub], -1.0)],
            Backlash::new(
                cl.free_angle,
                MeshProfile::Constant {
                    stiffness: cl.main_stiffness,
                },
            ),
        );
    }
    b = add_loads(b, d, &names, &throws, vehicle);
    b.build()
}

/// The mesh stiffness and the tip-relief contact of `m`, both on `u = r_p θ_p - r_g θ_g`.
fn add_mesh(b: ModelBuilder, names: &[&str], m: &Mesh) -> ModelBuilder {
    let p = m.pair;
    let weights = [
        (names[m.pinion], p.pinion_radius()),
        (names[m.gear], -p.gear_radius()),
    ];
    let profile = MeshProfile::Rectangular {
        one_tooth: p.one_tooth * p.face_width,
        two_tooth: p.two_tooth * p.face_width,
        contact_ratio: p.contact_ratio,
    };
    // The mesh cycles once per tooth: `order` cycles per period of the fundamental.
    let teeth = u32::try_from(m.order).unwrap_or(u32::MAX);
    let b = b.element(
        &format!("mesh{}", m.number),
        &weights,
        MeshStiffness::new(teeth, profile, MeshDamping::Proportional(p.mesh_beta)),
    );
    if p.relief_stiffness == 0.0 {
        return b;
    }
    b.element(
        &format!("relief{}", m.number),
        &weights,
        Backlash::new(
            p.tip_relief,
            MeshProfile::Constant {
                stiffness: p.relief_stiffness * p.face_width,
            },
        ),
    )
}

/// Static drive torque and gas-torque harmonics on the throws, the balancing load at the
/// vehicle.
fn add_loads(
    mut b: ModelBuilder,
    d: &Drivetrain,
    names: &[&str],
    throws: &[usize; 4],
    vehicle: usize,
) -> ModelBuilder {
    let per_cylinder = d.drive_torque / 4.0;
    for (c, &t) in throws.iter().enumerate() {
        b = b.load(names[t], 0, per_cylinder, 0.0);
        // Validated: every cylinder appears in the firing order.
        let alpha = d.engine.firing_angle(c + 1).unwrap_or(0.0);
        for (j, a) in d.engine.gas_orders.iter().enumerate() {
            // a (T/4) cos(k(θ - α/2)) = A cos φ cos kθ + A sin φ sin kθ, φ = k α / 2.
            let k = j + 1;
            let phi = k as f64 * alpha / 2.0;
            let amp = a * per_cylinder;
            b = b.load(names[t], k, amp * phi.cos(), amp * phi.sin());
        }
    }
    b.load(names[vehicle], 0, -d.drive_torque * d.total_ratio(), 0.0)
}
