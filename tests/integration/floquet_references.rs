//! Floquet multipliers against independent references (`tests/data/floquet/`, scipy DOP853
//! restarted at every stiffness jump and contact switch + Newton shooting, converged to about
//! 1e-10; see its README): the two-shaft model at 60, 600 and 6000 rpm, the backlash gear pair
//! in every regime (no impact, contact loss, double-sided impact, the three coexisting orbits at
//! W = 0.7 and 0.8) and the symmetric 3-DOF backlash chain on both sides of its
//! symmetry-breaking point. Moduli and complex multipliers within 1e-6.

use crate::common;

use common::floquet::{orbits, reference_multipliers, scene, solve_at};
use hbal::catalog::GearBacklash;
use hbal::stability::floquet;
use hbal::Model;
use serde_json::Value;

/// Solves `model` at the reference's W from its orbit, then checks the multipliers.
fn check(label: &str, model: &Model, orbit: &Value, h: usize) {
    let sol = solve_at(label, model, orbit, h);
    let f = floquet(model, &sol).unwrap();
    assert!(f.polished, "{label}: shooting did not converge: {f:?}");
    let want = reference_multipliers(orbit);
    assert_eq!(f.multipliers.len(), want.len(), "{label}");
    for (got, w) in f.multipliers.iter().zip(&want) {
        assert!(
            (got.norm() - w.norm()).abs() < 1e-6,
            "{label}: |μ| {} vs {}",
            got.norm(),
            w.norm()
        );
    }
    // The complex values too (a conjugate pair may come in either order).
    for w in &want {
        let nearest = f
            .multipliers
            .iter()
            .map(|g| (g - w).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 1e-6,
            "{label}: no multiplier near {w} in {:?}",
            f.multipliers
        );
    }
    assert_eq!(f.is_stable(), orbit["stable"].as_bool().unwrap(), "{label}");
}

#[test]
fn two_shaft_model_at_60_600_6000_rpm() {
    for rpm in [60, 600, 6000] {
        let scene = scene(&format!("examples/scenes/two_shaft_{rpm}rpm.toml"));
        for orbit in orbits(&format!("two_shaft_{rpm}rpm.json")) {
            check(&format!("two-shaft {rpm} rpm"), &scene.model, &orbit, 32);
        }
    }
}

#[test]
fn backlash_pair_in_every_regime() {
    for (file, fa) in [
        ("gear_backlash_Fa0.05.json", 0.05),
        ("gear_backlash_Fa0.1_W0.7.json", 0.1),
        ("gear_backlash_Fa0.3_double_sided.json", 0.3),
    ] {
        let model = GearBacklash {
            fa,
            ..GearBacklash::default()
        }
        .model()
        .unwrap();
        for orbit in orbits(file) {
            let label = format!("gear pair Fa {fa}, W {}, {}", orbit["W"], orbit["branch"]);
            check(&label, &model, &orbit, 32);
        }
    }
}

#[test]
fn backlash_chain_through_its_symmetry_breaking_point() {
    let scene = scene("tests/data/floquet/chain_backlash.toml");
    let all = orbits("chain_backlash.json");
    assert_eq!(all.len(), 4);
    for orbit in all {
        let label = format!("chain W {}, {}", orbit["W"], orbit["branch"]);
        check(&label, &scene.model, &orbit, 64);
    }
}
