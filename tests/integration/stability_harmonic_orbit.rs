//! The multipliers of the HB orbit itself ([`Orbit::Harmonic`]): against the independent
//! references of `tests/data/floquet/` they converge with H as the HB solution does; the
//! difference to the exact orbit's that the analysis measures and reports is the one there is;
//! a sweep measures it at its first point and every 32nd and reports it with every point;
//! laws that are not piecewise affine are shot onto the exact orbit.

use crate::common;

use common::floquet::{hausdorff, orbits, reference_multipliers, scene, solve_at};
use hbal::catalog::Duffing;
use hbal::continuation::Continuation;
use hbal::stability::{FloquetOptions, Orbit, ORBIT_CHECK_EVERY};
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};

fn harmonic() -> FloquetOptions {
    FloquetOptions {
        orbit: Orbit::Harmonic,
        ..FloquetOptions::default()
    }
}

/// The backlash chain's reference orbits (contact damping: saltation at every crossing) and the
/// two-shaft model's (a rectangular mesh stiffness): the HB orbit's multipliers approach the
/// reference's as H grows, the exact orbit's stay at the reference's, and the reported
/// difference is the measured one.
#[test]
fn the_hb_orbits_multipliers_converge_with_h_to_the_references() {
    let chain = scene("tests/data/floquet/chain_backlash.toml");
    let two_shaft = scene("examples/scenes/two_shaft_6000rpm.toml");
    let mut cases = Vec::new();
    for orbit in orbits("chain_backlash.json") {
        cases.push(("chain", &chain.model, orbit));
    }
    for orbit in orbits("two_shaft_6000rpm.json") {
        cases.push(("two-shaft", &two_shaft.model, orbit));
    }
    for (label, model, orbit) in &cases {
        let want = reference_multipliers(orbit);
        let mut errors = Vec::new();
        for h in [16, 32, 64, 128] {
            let sol = solve_at(label, model, orbit, h);
            let f = harmonic().compute(model, &sol).unwrap();
            let exact = FloquetOptions::default().compute(model, &sol).unwrap();
            assert_eq!(f.orbit, Orbit::Harmonic, "{label}");
            assert!(!f.polished);
            let e = hausdorff(&f.multipliers, &want);
            let d = f.distance(&exact);
            eprintln!(
                "{label} W = {} H = {h}: HB orbit {e:.2e} from the reference, exact orbit {:.2e}, reported {:.2e}, measured {d:.2e}, stable {} {}",
                orbit["W"],
                hausdorff(&exact.multipliers, &want),
                f.orbit_difference.unwrap(),
                f.is_stable(),
                exact.is_stable()
            );
            if *label == "two-shaft" {
                // No kinks: the pieces are the time jumps alone, whatever the orbit.
                assert!(d < 1e-12 && e < 1e-11, "{label} H {h}: {d:e} {e:e}");
            } else {
                // The reported difference is the measured one, and the error there is.
                assert_eq!(f.orbit_difference, Some(d));
                let exact_error = hausdorff(&exact.multipliers, &want);
                assert!(exact_error < 1e-2 * e, "{label} H {h}");
                assert!((d / e - 1.0).abs() < 0.05, "{label} H {h}: {d:e} {e:e}");
            }
            assert_eq!(f.is_stable(), exact.is_stable(), "{label} H {h}");
            errors.push(e);
        }
        if *label == "chain" {
            // H⁻³: a factor 8 per doubling (at least 5 asserted), 2e-5 or better at H = 128.
            for w in errors.windows(2) {
                assert!(w[1] < w[0] / 5.0, "{label}: {errors:?}");
            }
            assert!(errors[3] < 3e-5, "{label}: {errors:?}");
        }
    }
}

/// The backlash chain swept through its symmetry-breaking point (a real multiplier through +1
/// at W = 1.3455): with the HB orbit's stability the branch, every point's stability and the
/// located branch point are the exact orbit's; the points near the crossing and every 32nd
/// are the exact orbit's, the others carry the measured difference.
#[test]
fn a_sweep_with_the_hb_orbits_stability_finds_the_exact_branch_point() {
    let chain = scene("tests/data/floquet/chain_backlash.toml");
    let run = |options: FloquetOptions| {
        Continuation {
            stability: Some(options),
            ..Continuation::default()
        }
        .run(
            &chain.model,
            chain.basis.with_omega(1.2).unwrap(),
            1.5,
            |_| {},
        )
        .unwrap()
    };
    let exact = run(FloquetOptions::default());
    let fast = run(harmonic());
    assert_eq!(exact.points.len(), fast.points.len());
    let mut measurements = 0;
    let mut last = None;
    for (e, f) in exact.points.iter().zip(&fast.points) {
        assert_eq!(e.omega.to_bits(), f.omega.to_bits());
        let (fe, ff) = (e.floquet.as_ref().unwrap(), f.floquet.as_ref().unwrap());
        assert_eq!(fe.orbit, Orbit::Exact);
        assert_eq!(fe.is_stable(), ff.is_stable(), "W {}", e.omega);
        assert_eq!(e.bifurcation, f.bifurcation, "W {}", e.omega);
        match (e.bifurcation_omega, f.bifurcation_omega) {
            (Some(a), Some(b)) => assert!((a - b).abs() < 1e-9, "{a} {b}"),
            (a, b) => assert_eq!(a, b),
        }
        let reported = match ff.orbit {
            Orbit::Harmonic => ff.orbit_difference.unwrap(),
            Orbit::Exact => 0.0,
        };
        // Within the reported difference (a measurement at most 0.2 of multiplier movement
        // away, the larger of the last two), with a factor 2 of room.
        let d = fe.distance(ff);
        assert!(
            d <= 2.0 * reported + 1e-9,
            "W {}: {d:e} > {reported:e}",
            e.omega
        );
        if last != ff.orbit_difference {
            measurements += 1;
            last = ff.orbit_difference;
        }
    }
    let points = fast.points.len();
    eprintln!("{measurements} measurements on {points} points");
    let located = exact
        .points
        .iter()
        .filter(|p| p.bifurcation_omega.is_some());
    assert_eq!(located.count(), 2, "the branch point each way");
    assert!(measurements >= points / ORBIT_CHECK_EVERY, "{measurements}");
    assert!(measurements < points / 2, "{measurements} of {points}");
}

/// A cubic spring is not piecewise affine: the HB orbit's pieces do not apply, and the
/// analysis is the exact orbit's, to the bit.
#[test]
fn laws_that_are_not_piecewise_affine_get_the_exact_orbit() {
    let model = Duffing::default().model().unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.5, 7).unwrap()).unwrap();
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    let fast = harmonic().compute(&model, &sol).unwrap();
    let exact = FloquetOptions::default().compute(&model, &sol).unwrap();
    assert_eq!(fast.orbit, Orbit::Exact);
    assert_eq!(fast.orbit_difference, None);
    assert!(fast.polished);
    assert_eq!(fast.multipliers, exact.multipliers);
}

/// A period-1 orbit written with the harmonics of half the speed (ν = 2): the HB orbit's
/// pieces over both periods give the squares of the period-1 multipliers.
#[test]
fn over_two_periods_the_multipliers_are_squared() {
    let chain = scene("tests/data/floquet/chain_backlash.toml");
    let orbit = &orbits("chain_backlash.json")[0];
    let sol = solve_at("chain", &chain.model, orbit, 32);
    let n = chain.model.n_dofs();
    let basis = sol.basis();
    let mut q = vec![hbal::num_complex::Complex64::default(); (2 * 32 + 1) * n];
    for k in 0..=32 {
        for i in 0..n {
            q[2 * k * n + i] = sol.harmonic(i, k);
        }
    }
    let doubled = HarmonicBasis::new(basis.omega(), 64)
        .unwrap()
        .with_subharmonic(2)
        .unwrap();
    let names = sol.dof_names().to_vec();
    let sol2 = hbal::Solution::from_harmonics(doubled, names, q, 0.0).unwrap();
    let once = harmonic().compute(&chain.model, &sol).unwrap();
    let twice = harmonic().compute(&chain.model, &sol2).unwrap();
    assert_eq!(twice.orbit, Orbit::Harmonic);
    let squared: Vec<_> = once.multipliers.iter().map(|m| m * m).collect();
    let d = hausdorff(&twice.multipliers, &squared);
    assert!(d < 1e-10, "{d:e}");
}

/// `hbal sweep --stability-orbit harmonic` on the backlash chain through its branch point:
/// every point says whose multipliers it has and, for the HB orbit's, the measured difference;
/// the branch point lies where the exact orbit's sweep has it; bad combinations exit 2.
#[test]
fn the_cli_reports_whose_multipliers_a_point_has() {
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenes/chain_backlash.toml");
    let scene = scene.to_str().unwrap();
    let sweep = |extra: &[&str]| {
        let mut args = vec![
            "sweep",
            scene,
            "--from",
            "1.3",
            "--to",
            "1.4",
            "--no-error-estimate",
        ];
        args.extend_from_slice(extra);
        common::hbal(&args)
    };
    let run = |extra: &[&str]| -> serde_json::Value {
        let out = sweep(extra);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let fast = run(&["--stability-orbit", "harmonic", "--json"]);
    let exact = run(&["--json"]);
    let located = |doc: &serde_json::Value| -> Vec<f64> {
        let points = doc["points"].as_array().unwrap();
        points
            .iter()
            .filter_map(|p| p["bifurcation_speed"].as_f64())
            .collect()
    };
    let (a, b) = (located(&fast), located(&exact));
    assert_eq!(a.len(), 1, "{a:?}");
    assert!((a[0] - b[0]).abs() < 1e-9, "{a:?} {b:?}");
    for p in fast["points"].as_array().unwrap() {
        match p["stability_orbit"].as_str().unwrap() {
            "harmonic" => assert!(p["orbit_difference"].as_f64().unwrap() > 0.0),
            "exact" => assert!(p["orbit_difference"].is_null()),
            other => panic!("{other}"),
        }
    }
    for p in exact["points"].as_array().unwrap() {
        assert_eq!(p["stability_orbit"], "exact");
        assert!(p["orbit_difference"].is_null());
    }
    let text = sweep(&["--stability-orbit", "harmonic"]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("stability of the HB orbit at "), "{text}");
    for bad in [
        &["--stability-orbit", "harmonic", "--no-stability"][..],
        &[
            "--stability-orbit",
            "harmonic",
            "--parameter",
            "loads[0].cos",
        ][..],
        &["--stability-orbit", "hb"][..],
    ] {
        let out = sweep(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("stability-orbit"),
            "{bad:?}"
        );
    }
}

/// The coarse drivetrain (rectangular mesh stiffness and tip-relief contacts: time jumps and
/// kinks together) on its reduced basis: the reduction's estimate of the HB orbit's
/// multipliers compares them with the exact orbit's on the wider basis, so with the orbit's
/// measured difference it covers the distance to the dense exact orbit's.
#[test]
#[ignore = "heavy in a debug build (dense 100-DOF analyses, 14 s): CI runs it in release"]
fn on_a_reduced_basis_the_estimate_covers_the_orbit_and_the_basis() {
    use hbal::stability::FloquetMethod;
    for rpm in [1200.0, 2000.0, 3000.0] {
        let (model, sol) = common::floquet::drivetrain(100, rpm);
        let fast = harmonic().compute(&model, &sol).unwrap();
        let dense = FloquetOptions::default()
            .with_method(FloquetMethod::Dense)
            .compute(&model, &sol)
            .unwrap();
        let fast_dense = harmonic()
            .with_method(FloquetMethod::Dense)
            .compute(&model, &sol)
            .unwrap();
        assert_eq!(fast.orbit, Orbit::Harmonic);
        let estimate = fast.reduction.as_ref().unwrap().estimate.unwrap();
        let difference = fast.orbit_difference.unwrap();
        let actual = fast.distance(&dense);
        eprintln!(
            "{rpm} rpm: difference {difference:.2e}, estimate {estimate:.2e}, actual {actual:.2e}; dense HB orbit {:.2e} (reported {:.2e})",
            fast_dense.distance(&dense),
            fast_dense.orbit_difference.unwrap()
        );
        assert!(actual <= 3.0 * (estimate + difference), "{rpm}");
        // Dense: the measured difference is the distance to the dense exact orbit's.
        assert_eq!(
            fast_dense.orbit_difference,
            Some(fast_dense.distance(&dense))
        );
    }
}

/// Turning the time origin onto a kink crossing (and the load with it) moves no multiplier: a
/// root within rounding of 0 or 2π is crossed once, with its saltation (contact damping).
#[test]
fn a_crossing_at_the_period_boundary_counts_once() {
    use hbal::force::{Backlash, MeshProfile};
    let model = |c: f64, s: f64| {
        let law = Backlash::new(1.0, MeshProfile::Constant { stiffness: 20.0 })
            .with_contact_damping(0.05);
        Model::builder(&["x"])
            .mass_diagonal(&[1.0])
            .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.05))
            .stiffness(hbal::nalgebra::DMatrix::from_element(1, 1, 1.0))
            .element("contact", &[("x", 1.0)], law)
            .load("x", 1, c, s)
            .build()
            .unwrap()
    };
    let base_model = model(3.0, 0.0);
    let mut worst = 0.0_f64;
    for w in [1.25, 1.27, 1.29, 1.31] {
        let basis = HarmonicBasis::new(w, 32).unwrap();
        let sol = hbal::continuation::solve_robustly(&base_model, basis, &Continuation::default())
            .unwrap()
            .solution;
        assert!(sol.is_converged());
        worst = worst.max(turned_origins(&sol, &base_model, &model));
    }
    // Without the last window's take of every event left, a root within rounding of 2π was
    // dropped with its saltation: 9.7e-2.
    assert!(worst < 1e-9, "{worst:e}");
}

/// The largest distance of the multipliers of `sol` with its time origin turned onto each of
/// its kink crossings (within a few roundings either side) to those of `sol` itself.
fn turned_origins(
    sol: &hbal::Solution,
    base_model: &Model,
    model: &dyn Fn(f64, f64) -> Model,
) -> f64 {
    use hbal::num_complex::Complex64;
    use std::f64::consts::TAU;
    let q: Vec<Complex64> = (0..=32).map(|k| sol.harmonic(0, k)).collect();
    let u = |t: f64| -> f64 {
        q.iter()
            .enumerate()
            .map(|(k, z)| (z * Complex64::from_polar(1.0, k as f64 * t)).re)
            .sum()
    };
    // The crossings of both edges by bisection on a fine grid.
    let mut roots = Vec::new();
    for kink in [1.0, -1.0] {
        for j in 0..4096 {
            let (mut lo, mut hi) = (j as f64 * TAU / 4096.0, (j + 1) as f64 * TAU / 4096.0);
            let below = u(lo) < kink;
            if below == (u(hi) < kink) {
                continue;
            }
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if (u(mid) < kink) == below {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            roots.push(lo);
        }
    }
    assert_eq!(roots.len(), 4, "{roots:?}");
    let base = harmonic().compute(base_model, sol).unwrap();
    assert_eq!(base.orbit, Orbit::Harmonic);
    let mut worst = 0.0_f64;
    for &r in &roots {
        for ulps in -4..=4 {
            let th = r + ulps as f64 * 2.0 * f64::EPSILON;
            let turned: Vec<Complex64> = q
                .iter()
                .enumerate()
                .map(|(k, z)| z * Complex64::from_polar(1.0, k as f64 * th))
                .collect();
            let names = sol.dof_names().to_vec();
            let turned = hbal::Solution::from_harmonics(*sol.basis(), names, turned, 0.0).unwrap();
            let f = harmonic()
                .compute(&model(3.0 * th.cos(), -3.0 * th.sin()), &turned)
                .unwrap();
            worst = worst.max(hausdorff(&f.multipliers, &base.multipliers));
        }
    }
    worst
}
