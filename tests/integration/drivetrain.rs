//! The drivetrain benchmark generator (`hbal::catalog::Drivetrain`): DOF counts, a valid
//! model, the full and the condensed formulation on the same periodic solution, closed-form
//! static twists, and clear errors.

use crate::common;
use hbal::catalog::drivetrain::{GearPair, Shaft};
use hbal::catalog::Drivetrain;
use hbal::compare::relative_error;
use hbal::{Error, Formulation, HarmonicBalance, HarmonicBasis, Model, Newton, Solution};

/// Engine speed of the solves (rpm): fundamental 104.7 rad/s, gas orders up to 133 Hz.
const RPM: f64 = 2000.0;

fn solve(model: &Model, basis: HarmonicBasis, formulation: Formulation) -> Solution {
    let hb = HarmonicBalance::with_formulation(model, basis, formulation).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-12)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{formulation:?}: {}", sol.termination);
    sol
}

#[test]
fn dof_count_is_the_requested_one() {
    for meshes in [1, 2, 4, 8, 16] {
        let base = Drivetrain::default().with_meshes(meshes).unwrap();
        let min = base.n_dofs();
        assert_eq!(min, 10 + 4 + 2 * (meshes - 1), "m = {meshes}");
        for n in [10, 30, 57, 100, 1000, 12_345, 100_000] {
            let d = base.clone().with_dofs(n);
            assert_eq!(d.n_dofs(), n.max(min), "m = {meshes}, n = {n}");
            if n <= 100 {
                assert_eq!(
                    d.model().unwrap().n_dofs(),
                    d.n_dofs(),
                    "m = {meshes}, n = {n}"
                );
            }
        }
    }
    // Segments follow the lengths: the 1.4 m propeller shaft gets about 1.4 / 0.25 times the
    // 0.25 m input shaft's.
    let d = Drivetrain::default().with_dofs(10_000);
    let ratio = d.propeller_shaft.segments as f64 / d.input_shaft.segments as f64;
    assert!((ratio - 1.4 / 0.25).abs() < 0.01, "{ratio}");
    let model = Drivetrain::default().with_dofs(1000).model().unwrap();
    assert_eq!(model.n_dofs(), 1000);
}

#[test]
fn the_model_is_a_valid_drivetrain() {
    let d = Drivetrain::default().with_dofs(60);
    let model = d.model().unwrap();
    let n = model.n_dofs();
    let (m, k) = (
        model.mass().to_dense(),
        model.structural_stiffness().to_dense(),
    );
    // Lumped inertias: a positive diagonal.
    for i in 0..n {
        assert!(m[(i, i)] > 0.0, "{}", model.dof_names()[i]);
        for j in 0..n {
            assert!(i == j || m[(i, j)] == 0.0);
            assert_eq!(k[(i, j)], k[(j, i)]);
        }
    }
    // The whole drivetrain turning rigidly (every DOF at its speed ratio) only strains the
    // ground spring, and the static loads do no work on it: they balance.
    let mut speed = vec![0.0; n];
    let mut s = 1.0;
    let ratios = d
        .gearbox
        .iter()
        .map(|st| st.pair.ratio())
        .chain([d.final_drive.ratio()]);
    let names = model.dof_names();
    let mut ratios = ratios.peekable();
    for (i, name) in names.iter().enumerate() {
        if name.starts_with("gear") || name == "carrier" {
            s /= ratios.next().unwrap();
        }
        speed[i] = s;
    }
    let k0 = model.k0().to_dense();
    let v = model.dof_index("vehicle").unwrap();
    for i in 0..n {
        let f: f64 = (0..n).map(|j| k0[(i, j)] * speed[j]).sum();
        let expected = if i == v {
            d.vehicle.ground_stiffness * s
        } else {
            0.0
        };
        assert!((f - expected).abs() < 1e-9 * k0.amax(), "{}: {f}", names[i]);
    }
    let work: f64 = model
        .loads()
        .iter()
        .filter(|l| l.order == 0)
        .map(|l| l.cos * speed[l.dof])
        .sum();
    assert!(work.abs() < 1e-12 * d.drive_torque, "{work}");
    assert!((s - 1.0 / d.total_ratio()).abs() < 1e-15);
    assert!((d.total_ratio() - 1.5 * 4.0 / 3.0 * 40.0 / 12.0).abs() < 1e-12);
    // Orders: gas harmonics 1..8, meshes 32, 32, 20, 12.
    assert_eq!(d.mesh_orders().unwrap(), [32, 32, 20, 12]);
    assert_eq!(d.max_order().unwrap(), 32);
    assert_eq!(model.max_order(), 32);
    assert_eq!(model.max_load_order(), 8);
    assert!((d.fundamental(6000.0) - 100.0 * std::f64::consts::PI).abs() < 1e-12);
}

/// The 4-cylinder engine excites, on a rigid crank, only the orders 2, 4: the four throws'
/// harmonic 4 (crank order 2) add up, harmonic 2 (order 1) cancels.
#[test]
fn firing_order_phases() {
    let model = Drivetrain::default().model().unwrap();
    let sum = |k: usize| -> (f64, f64) {
        model
            .loads()
            .iter()
            .filter(|l| l.order == k && model.dof_names()[l.dof].starts_with("throw"))
            .fold((0.0, 0.0), |(c, s), l| (c + l.cos, s + l.sin))
    };
    let t = 150.0 / 4.0;
    for k in 1..=8 {
        let (c, s) = sum(k);
        if k % 4 == 0 {
            let a = Drivetrain::default().engine.gas_orders[k - 1];
            assert!(
                (c - 4.0 * a * t).abs() < 1e-9 && s.abs() < 1e-9,
                "{k}: {c} {s}"
            );
        } else {
            assert!(c.abs() < 1e-9 && s.abs() < 1e-9, "{k}: {c} {s}");
        }
    }
}

/// Newton converges in both formulations at n = 30, H = 16 (teeth divided by 4: mesh
/// harmonics 8, 8, 5, 3) and they agree to 3e-10; the condensation has one coordinate per
/// mesh and the clutch.
#[test]
fn full_and_condensed_agree() {
    let d = Drivetrain::default().coarse_teeth(4).unwrap().with_dofs(30);
    assert_eq!(d.mesh_orders().unwrap(), [8, 8, 5, 3]);
    let model = d.model().unwrap();
    let h = 16;
    let basis = HarmonicBasis::new(d.fundamental(RPM), h).unwrap();
    let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap();
    assert_eq!(
        hb.unknown_names(),
        ["u(mesh1)", "u(mesh2)", "u(mesh3)", "u(mesh4)", "u(clutch)"]
    );
    assert_eq!(d.condensed_coordinates(), 5);
    let full = solve(&model, basis, Formulation::Full);
    let cond = solve(&model, basis, Formulation::Condensed);
    let diff = relative_error(cond.harmonics(), full.harmonics(), model.n_dofs(), h);
    // Both satisfy the exact Galerkin equations (2e-13, 3e-13 of the load); they differ by the
    // conditioning of the stiff meshes times Newton's 1e-12 (1.1e-10).
    for s in [&full, &cond] {
        let galerkin = common::galerkin::residual_relative_to_load;
        let r = galerkin(&model, basis.omega(), s.harmonics());
        assert!(r < 1e-11, "{r:.1e}");
    }
    assert!(diff < 3e-10, "condensed against full {diff:.1e}");
    // The tip-relief contacts open and close: the solution is not the linear one.
    assert!(full.stats.iterations >= 2, "{}", full.stats.iterations);

    // A linear clutch (no free angle) is no coordinate; one mesh less is one less.
    let mut linear = d.clone().with_meshes(3).unwrap();
    linear.clutch.free_angle = 0.0;
    let linear = linear.coarse_teeth(1).unwrap();
    assert_eq!(linear.condensed_coordinates(), 3);
    let model = linear.model().unwrap();
    let basis = HarmonicBasis::new(d.fundamental(RPM), 32).unwrap();
    let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap();
    assert_eq!(hb.unknown_names(), ["u(mesh1)", "u(mesh2)", "u(mesh3)"]);
}

/// The mean torque through a shaft is the drive torque times the ratios before it, whatever
/// the vibration (inertia and damping torques average out): its mean twist is `T L / (G Jp)`.
#[test]
fn static_twist_of_the_shafts() {
    let d = Drivetrain::default().coarse_teeth(4).unwrap().with_dofs(32);
    let model = d.model().unwrap();
    let basis = HarmonicBasis::new(d.fundamental(RPM), 8).unwrap();
    let sol = solve(&model, basis, Formulation::Condensed);
    let mean = |name: &str| sol.harmonic(model.dof_index(name).unwrap(), 0).re;
    let end = |name: &str, shaft: &Shaft| format!("{name}.{}", shaft.segments);
    let twist = mean("hub") - mean(&end("input", &d.input_shaft));
    let expected = d.input_shaft.twist(d.drive_torque);
    assert!(
        ((twist - expected) / expected).abs() < 1e-9,
        "input: {twist} vs {expected}"
    );
    // Shaft 1 carries T · i_1 from gear 1 to pinion 2.
    let s1 = &d.gearbox[0].shaft;
    let twist = mean("gear1") - mean(&end("shaft1", s1));
    let expected = s1.twist(d.drive_torque * d.gearbox[0].pair.ratio());
    assert!(
        ((twist - expected) / expected).abs() < 1e-9,
        "shaft 1: {twist} vs {expected}"
    );
    // The propeller shaft carries T times the gearbox ratio.
    let gearbox: f64 = d.gearbox.iter().map(|s| s.pair.ratio()).product();
    let prop_start = end("shaft3", &d.gearbox[2].shaft);
    let twist = mean(&prop_start) - mean(&end("prop", &d.propeller_shaft));
    let expected = d.propeller_shaft.twist(d.drive_torque * gearbox);
    assert!(
        ((twist - expected) / expected).abs() < 1e-9,
        "prop: {twist} vs {expected}"
    );
    // The loads balance, so the ground spring carries no mean torque.
    assert!(
        mean("vehicle").abs() < 1e-9 * mean("throw1").abs(),
        "{}",
        mean("vehicle")
    );
}

#[test]
fn bad_parameters_are_errors() {
    assert!(Drivetrain::default().with_meshes(0).is_err());
    let err = Drivetrain::default().coarse_teeth(3).unwrap_err();
    assert!(err.to_string().contains("divisible by 3"), "{err}");
    // A 17-tooth pinion on the countershaft (2/3 crank speed) meshes at crank order 11.33.
    let mut d = Drivetrain::default();
    d.gearbox[1].pair = GearPair::new(17, 32, 3e-3, 0.02);
    let err = d.model().unwrap_err();
    assert!(err.to_string().contains("drivetrain mesh 2"), "{err}");
    let mut d = Drivetrain::default();
    d.half_shafts[1].segments = 0;
    let err = d.model().unwrap_err();
    assert!(err.to_string().contains("right half shaft"), "{err}");
    let mut d = Drivetrain::default();
    d.engine.flywheel = -0.1;
    assert!(matches!(d.model(), Err(Error::InvalidParameter { .. })));
    let mut d = Drivetrain::default();
    d.engine.firing_order = [1, 3, 3, 2];
    assert!(d.model().unwrap_err().to_string().contains("firing_order"));
    d = Drivetrain::default();
    d.drive_torque = f64::NAN;
    assert!(d.model().is_err());
    // H below the mesh order is refused, naming the mesh.
    let d = Drivetrain::default();
    let model = d.model().unwrap();
    let basis = HarmonicBasis::new(d.fundamental(RPM), 16).unwrap();
    let err = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap_err();
    assert!(
        matches!(&err, Error::ElementOrderTooHigh { element, order: 32, .. } if element == "mesh1"),
        "{err}"
    );
}
