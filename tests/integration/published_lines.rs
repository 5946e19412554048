//! The published shaft lines of issue 33 written as their users would (`examples/scenes`),
//! against the published values and independent computations (openTorsion 0.3.2, run on
//! the same data; its numbers are copied here).

use hbal::scene::Scene;
use hbal::{HarmonicBalance, HarmonicBasis};
use num_complex::Complex64;
use std::f64::consts::TAU;

fn scene(name: &str) -> Scene {
    Scene::load(&crate::common::cli::scenes_dir().join(name)).unwrap()
}

/// The elastic natural frequencies (cpm) of a linear scene.
fn frequencies_cpm(scene: &Scene) -> (Vec<f64>, usize) {
    let f = hbal::analysis::linear_frequencies(scene).unwrap();
    let cpm = f.mean.iter().skip(f.rigid).map(|hz| hz * 60.0).collect();
    (cpm, f.rigid)
}

/// The harmonics of the scene's model at `rpm` (its fundamental's unit).
fn solve_at(scene: &Scene, rpm: f64) -> Vec<Complex64> {
    let omega = rpm * scene.omega_per_speed;
    let basis = HarmonicBasis::new(omega, scene.basis.harmonics()).unwrap();
    let hb = HarmonicBalance::new(&scene.model, basis).unwrap();
    let sol = hbal::Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert!(sol.is_converged());
    sol.harmonics().to_vec()
}

/// Gunter & Chen Ex. 8.1: 177.7, 220.2 and 1282.6 cpm published; openTorsion's undamped
/// eigenvalues of the same line to 1e-10; the propeller shaft's 5th-order torque over the
/// run-up to openTorsion's forced response.
#[test]
fn marine_line_matches_the_published_frequencies_and_opentorsion() {
    let s = scene("marine_gunter_chen.toml");
    assert_eq!(
        s.model.n_dofs(),
        6,
        "four rigid gears remove four of ten angles"
    );
    let (cpm, rigid) = frequencies_cpm(&s);
    assert_eq!(rigid, 1, "the line floats free, held by damping only");
    for (f, published) in cpm.iter().zip([177.7, 220.2, 1282.6]) {
        assert!((f - published).abs() < 0.05, "{f} vs published {published}");
    }
    let opentorsion = [
        177.71115153050994,
        220.17628308503654,
        1282.584556972269,
        2496.867189096614,
        2883.382381455156,
    ];
    for (f, reference) in cpm.iter().zip(opentorsion) {
        assert!(
            (f - reference).abs() < 1e-10 * reference,
            "{f} vs {reference}"
        );
    }
    // The propeller shaft's torque k (θ_propeller − θ_bull), θ_bull = θ_lp_pinion / 9.4094, at
    // the blade-pass order: openTorsion's amplitudes (measured 1e-13 to 1e-11 apart; its modal
    // damping leaves the rigid mode 2ξ·3e-7 rad/s of damping, ours none).
    let (prop, pinion) = (
        s.model.dof_index("propeller").unwrap(),
        s.model.dof_index("lp_pinion").unwrap(),
    );
    let n = s.model.n_dofs();
    for (rpm, reference) in [
        (10.0, 3491.89025187238),
        (20.0, 18784.540242575407),
        (35.5, 470695.14307965024),
        (50.0, 81305.36669326261),
        (85.0, 48886.32815147898),
    ] {
        let q = solve_at(&s, rpm);
        let torque = 93321480.0 * (q[5 * n + prop] - q[5 * n + pinion] / 9.4094);
        let rel = (torque.norm() - reference).abs() / reference;
        assert!(
            rel < 1e-10,
            "{rpm} rpm: {} vs {reference} ({rel:.1e})",
            torque.norm()
        );
    }
    assert!((s.omega_per_speed - TAU / 60.0).abs() < 1e-15);
}
