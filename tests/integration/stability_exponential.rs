//! The exponential flow of the Floquet analysis ([`Integrator::Auto`] on models whose laws are
//! affine between their time jumps and kinks) against the independent references of
//! `tests/data/floquet/` and against the Runge–Kutta flow; its fallback on Runge–Kutta for
//! other laws; the reduction's estimate with the comparison's shortened shooting; and the
//! [`FloquetCache`] of a sweep.

use crate::common;

use common::floquet::{
    coarse_drivetrain, drivetrain, hausdorff, orbits, reference_multipliers, scene, solve_at,
};
use hbal::catalog::GearBacklash;
use hbal::continuation::Continuation;
use hbal::force::{Backlash, CubicSpring, MeshProfile};
use hbal::nalgebra::DMatrix;
use hbal::num_complex::Complex64;
use hbal::stability::{Floquet, FloquetCache, FloquetMethod, FloquetOptions, Integrator};
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Model, Newton};
use serde_json::Value;

fn with(integrator: Integrator, rtol: f64) -> FloquetOptions {
    FloquetOptions {
        integrator,
        rtol,
        ..FloquetOptions::default()
    }
}

/// Every reference orbit of the two-shaft model and the backlash pair: the exponential flow's
/// multipliers against scipy's (converged to about 1e-10) and against Runge–Kutta at the
/// default and at a tight tolerance.
#[test]
fn exponential_flow_against_the_references_and_runge_kutta() {
    let mut worst = (0.0_f64, 0.0_f64);
    let mut check = |label: &str, model: &Model, orbit: &Value, h: usize| {
        let (e, r) = against_reference(label, model, orbit, h);
        worst = (worst.0.max(e), worst.1.max(r));
    };
    for rpm in [60, 600, 6000] {
        let scene = scene(&format!("examples/scenes/two_shaft_{rpm}rpm.toml"));
        for orbit in orbits(&format!("two_shaft_{rpm}rpm.json")) {
            check(&format!("two-shaft {rpm} rpm"), &scene.model, &orbit, 32);
        }
    }
    let chain = scene("tests/data/floquet/chain_backlash.toml");
    for orbit in orbits("chain_backlash.json") {
        let label = format!("chain W {}, {}", orbit["W"], orbit["branch"]);
        check(&label, &chain.model, &orbit, 64);
    }
    eprintln!(
        "worst distance to the references: exponential {:.1e}, Runge-Kutta {:.1e}",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-7, "{:e}", worst.0);
}

/// The backlash gear pair's mesh stiffness varies as a cosine inside the mesh cycle: `Auto` is
/// the Runge–Kutta flow there, to the bit, and agrees with the reference.
#[test]
fn a_cosine_mesh_stiffness_falls_back_on_runge_kutta() {
    let model = GearBacklash {
        fa: 0.3,
        ..GearBacklash::default()
    }
    .model()
    .unwrap();
    for orbit in orbits("gear_backlash_Fa0.3_double_sided.json") {
        let sol = solve_at("gear pair Fa 0.3", &model, &orbit, 32);
        let auto = with(Integrator::Auto, 1e-8).compute(&model, &sol).unwrap();
        let rk = with(Integrator::RungeKutta, 1e-8)
            .compute(&model, &sol)
            .unwrap();
        assert_eq!(auto.multipliers, rk.multipliers);
        assert_eq!(auto.steps, rk.steps);
    }
}

/// The distances of the exponential and the Runge–Kutta multipliers (default rtol 1e-8) to the
/// reference's; both flows at rtol 1e-11 against each other.
fn against_reference(label: &str, model: &Model, orbit: &Value, h: usize) -> (f64, f64) {
    let sol = solve_at(label, model, orbit, h);
    let want = reference_multipliers(orbit);
    let exp = with(Integrator::Auto, 1e-8).compute(model, &sol).unwrap();
    let rk = with(Integrator::RungeKutta, 1e-8)
        .compute(model, &sol)
        .unwrap();
    let tight = with(Integrator::RungeKutta, 1e-11)
        .compute(model, &sol)
        .unwrap();
    assert!(exp.polished, "{label}");
    let (e, r) = (
        hausdorff(&exp.multipliers, &want),
        hausdorff(&rk.multipliers, &want),
    );
    // Both shootings polished to 1e-10: what is left is the integrators' own error.
    let exp_tight = with(Integrator::Auto, 1e-11).compute(model, &sol).unwrap();
    let against_tight = hausdorff(&exp_tight.multipliers, &tight.multipliers);
    eprintln!(
        "{label} W = {}: exponential {e:.1e}, Runge-Kutta {r:.1e} from the reference; both at 1e-11 {against_tight:.1e}; steps {} vs {}",
        orbit["W"], exp.steps, rk.steps
    );
    // Not the Runge–Kutta flow (whose steps are bounded by 1/ω_max, not a power of two).
    assert_ne!(exp.steps, rk.steps, "{label}");
    assert!(against_tight < 1e-9, "{label}: {against_tight:e}");
    assert_eq!(
        exp.is_stable(),
        orbit["stable"].as_bool().unwrap(),
        "{label}"
    );
    (e, r)
}

/// The backlash chain with contact damping: the force jumps by `c u̇` where the contact closes
/// or opens, and both flows apply the saltation matrix there. Exponential against Runge–Kutta,
/// both polished to 1e-10, on both sides of the symmetry-breaking point.
#[test]
fn contact_damping_saltation_agrees_with_runge_kutta() {
    let d = DMatrix::from_row_slice(
        3,
        3,
        &[0.1, -0.04, 0.0, -0.04, 0.1, -0.04, 0.0, -0.04, 0.06],
    );
    let k = DMatrix::from_row_slice(3, 3, &[2.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 1.0]);
    let contact =
        Backlash::new(1.0, MeshProfile::Constant { stiffness: 5.0 }).with_contact_damping(0.3);
    let model = Model::builder(&["x1", "x2", "x3"])
        .mass_diagonal(&[1.0, 1.0, 1.0])
        .damping(d)
        .stiffness(k)
        .element("contact", &[("x2", -1.0), ("x3", 1.0)], contact)
        .load("x1", 1, 1.0, 0.0)
        .build()
        .unwrap();
    for w in [1.2, 1.36, 1.5] {
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(w, 64).unwrap()).unwrap();
        let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
        assert!(sol.is_converged(), "W = {w}");
        let exp = with(Integrator::Auto, 1e-11).compute(&model, &sol).unwrap();
        let rk = with(Integrator::RungeKutta, 1e-11)
            .compute(&model, &sol)
            .unwrap();
        let d = hausdorff(&exp.multipliers, &rk.multipliers);
        eprintln!(
            "W = {w}: max |μ| {:.10} (exponential) {:.10} (Runge-Kutta), distance {d:.1e}, steps {} vs {}",
            exp.max_abs(),
            rk.max_abs(),
            exp.steps,
            rk.steps
        );
        assert!(exp.polished && rk.polished, "W = {w}");
        assert_ne!(exp.steps, rk.steps);
        assert!(d < 1e-8, "W = {w}: {d:e}");
    }
}

/// A Duffing oscillator is not piecewise affine: `Auto` is the Runge–Kutta flow, to the bit.
#[test]
fn a_cubic_spring_falls_back_on_runge_kutta() {
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .damping(DMatrix::from_element(1, 1, 0.02))
        .element("spring", &[("x", 1.0)], CubicSpring::new(1.0, 1.0))
        .load("x", 1, 0.1, 0.0)
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.5, 7).unwrap()).unwrap();
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    let auto = with(Integrator::Auto, 1e-8).compute(&model, &sol).unwrap();
    let rk = with(Integrator::RungeKutta, 1e-8)
        .compute(&model, &sol)
        .unwrap();
    assert_eq!(auto.multipliers, rk.multipliers);
    assert_eq!(auto.steps, rk.steps);
}

/// The estimate's comparison stops its shooting once its multipliers are known to 1 % of
/// their distance: against the fully polished analysis on the comparison basis (cut-off 6
/// H Ω instead of 3 H Ω) the estimate is within 2 %.
#[test]
fn the_shortened_comparison_gives_the_estimate_within_two_percent() {
    let (model, sol) = drivetrain(100, 2000.0);
    let reduced = FloquetOptions::default().with_method(FloquetMethod::Reduced);
    let f = reduced.compute(&model, &sol).unwrap();
    let info = f.reduction.clone().unwrap();
    let wide = FloquetOptions {
        cutoff: 6.0,
        estimate: false,
        ..reduced
    }
    .compute(&model, &sol)
    .unwrap();
    assert_eq!(
        Some(wide.reduction.as_ref().unwrap().dofs),
        info.comparison_dofs
    );
    let full = leading_distance(&f, &wide);
    let estimate = info.estimate.unwrap();
    eprintln!("estimate {estimate:.4e}, with the polished comparison {full:.4e}");
    assert!(full > 0.0);
    assert!(
        (estimate - full).abs() <= 0.02 * full,
        "{estimate:e} vs {full:e}"
    );
}

/// The distance of the leading multipliers (modulus at least half the largest, at most 8),
/// as [`hbal::stability::Reduction::estimate`] defines it.
fn leading_distance(a: &Floquet, b: &Floquet) -> f64 {
    let top = a.max_abs().max(b.max_abs());
    let one = |a: &[Complex64], b: &[Complex64]| {
        a.iter()
            .take(8)
            .filter(|m| m.norm() >= 0.5 * top)
            .map(|m| b.iter().map(|o| (m - o).norm()).fold(m.norm(), f64::min))
            .fold(0.0, f64::max)
    };
    one(&a.multipliers, &b.multipliers).max(one(&b.multipliers, &a.multipliers))
}

/// A cache carried from 2000 to 2020 rpm (modes, orbit correction) gives the multipliers of a
/// fresh analysis; a sweep computes the estimate at its first point only when the stability
/// does not change.
#[test]
fn the_sweep_cache_gives_the_fresh_answer() {
    let (model, first) = drivetrain(100, 2000.0);
    let (_, second) = drivetrain(100, 2020.0);
    let options = FloquetOptions {
        estimate: false,
        ..FloquetOptions::default()
    };
    let mut cache = FloquetCache::default();
    options.compute_with(&model, &first, &mut cache).unwrap();
    let cached = options.compute_with(&model, &second, &mut cache).unwrap();
    let fresh = options.compute(&model, &second).unwrap();
    let d = hausdorff(&cached.multipliers, &fresh.multipliers);
    eprintln!("cached vs fresh: {d:.1e}, max |μ| {:.9}", fresh.max_abs());
    assert!(cached.polished && fresh.polished);
    assert!(d < 1e-8, "{d:e}");
    assert!((cached.orbit_correction - fresh.orbit_correction).abs() < 1e-6);

    let d = coarse_drivetrain(100);
    let basis = HarmonicBasis::new(d.fundamental(2000.0), 8).unwrap();
    let branch = Continuation {
        max_step: 0.5,
        ..Continuation::default()
    }
    .run(&model, basis, d.fundamental(2200.0), |_| {})
    .unwrap();
    assert!(branch.points.len() >= 3, "{} points", branch.points.len());
    let estimated: Vec<bool> = branch
        .points
        .iter()
        .map(|p| {
            p.floquet
                .as_ref()
                .and_then(|f| f.reduction.as_ref())
                .is_some_and(|r| r.estimate.is_some())
        })
        .collect();
    let changes = branch
        .points
        .windows(2)
        .filter(|w| w[0].stable() != w[1].stable())
        .count();
    assert!(estimated[0]);
    assert_eq!(estimated.iter().filter(|&&e| e).count(), 1 + changes);
}

/// The 1000-DOF drivetrain scene (4 rectangular meshes, 4 tip-relief contacts, clutch): the
/// exponential flow against Runge–Kutta, both shootings polished to 1e-10. About 4 s in
/// release, run by CI (`cargo test --release --test integration -- --ignored stability_exponential::`).
#[test]
#[ignore]
fn the_large_scene_against_runge_kutta() {
    let scene = scene("examples/scenes/large/drivetrain_1000.toml");
    let hb =
        HarmonicBalance::with_formulation(&scene.model, scene.basis, Formulation::Auto).unwrap();
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    let options = |integrator| FloquetOptions {
        estimate: false,
        ..with(integrator, 1e-11)
    };
    let exp = options(Integrator::Auto)
        .compute(&scene.model, &sol)
        .unwrap();
    let rk = options(Integrator::RungeKutta)
        .compute(&scene.model, &sol)
        .unwrap();
    let d = hausdorff(&exp.multipliers, &rk.multipliers);
    eprintln!(
        "drivetrain_1000: max |μ| {:.12} (exponential) {:.12} (Runge-Kutta), distance {d:.1e}, steps {} vs {}",
        exp.max_abs(),
        rk.max_abs(),
        exp.steps,
        rk.steps
    );
    assert!(exp.polished && rk.polished);
    // 16 coordinates (11 modes below the cut-off, 5 element attachment modes): 32 multipliers.
    assert_eq!(exp.multipliers.len(), 32);
    assert!(d < 1e-9, "{d:e}");
    assert!((exp.max_abs() - 0.999608694356).abs() < 1e-11);
}
