//! The free-free car drivetrain of `examples/scenes/car_drivetrain_two_stage.toml` (11 DOFs,
//! 4-cylinder engine orders 2, 4, 6, dual-mass flywheel, stages 23/37 and 19/43 with
//! rectangular mesh stiffness, final drive) at 2000 rpm, fundamental crank/37, mesh 1 at
//! harmonic 851. Harmonic balance at H = 1024 gets stage 1's transmission error 55 % low
//! (9.7 µm peak to peak against 21.4 µm) against the exact piecewise solution while its
//! whole-solution estimate says 1.5e-4: the per-quantity estimate sees it (worst quantity
//! stage 1's force, 0.50 of its range; the reference goes to 4H, where the mesh modes ring),
//! and automatic harmonics on the quantities hand over to the exact
//! solution. Release only (the exact solution takes about a minute): `.ci/run` runs it.

use hbal::compare::{quantity_errors, Quantity};
use hbal::scene::Scene;
use hbal::solve::{estimate_error, refined_solution, solve_auto, AutoHarmonics, Control, Method};
use hbal::{Formulation, HarmonicBalance, Newton};
use std::path::Path;

#[test]
#[ignore = "release: the exact piecewise solution of 2.6k stiffness jumps takes about a minute"]
fn transmission_error_is_estimated_per_quantity() {
    let s = Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/scenes/car_drivetrain_two_stage.toml"),
    )
    .unwrap();
    let (model, basis) = (&s.model, s.basis);
    assert_eq!(basis.harmonics(), 1024);
    let stage1 = model
        .elements()
        .iter()
        .position(|e| e.name() == "stage1")
        .unwrap();
    let hb = HarmonicBalance::with_formulation(model, basis, Formulation::Auto).unwrap();
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    let e = estimate_error(model, &sol).unwrap();
    // The whole solution looks fine; the worst quantity does not.
    let worst = e.worst_quantity.unwrap();
    eprintln!(
        "H = 1024: whole {:.1e}, worst {} {:.2e}",
        e.relative,
        worst.quantity.name(model),
        worst.error
    );
    assert!(e.relative < 1e-3, "{e:?}");
    assert!(worst.error > 0.1, "{worst:?}");
    // The mesh modes ring near harmonic 2300, beyond 2H = 2048: the estimate's reference
    // goes on to 4H, which holds them (against 2H it was a lower bound, 9.1e-2 for a true
    // 0.44).
    assert_eq!(e.reference_harmonics, 4096);
    assert!(!e.lower_bound, "{e:?}");

    // Automatic harmonics on the quantities: harmonic balance stops at the cap, the exact
    // piecewise solution answers.
    let auto = solve_auto(
        model,
        basis,
        &Method::Newton(Newton::new()),
        AutoHarmonics {
            max_harmonics: 1024,
            control: Control::Quantities,
            ..AutoHarmonics::default()
        },
    )
    .unwrap();
    assert!(auto.switched_to_exact && !auto.capped, "{:?}", auto.levels);
    let exact = auto.exact.unwrap();
    let x = exact.extremes();
    let (lo, hi) = x.elements[stage1].coordinate;
    let exact_pp = hi - lo;

    // Stage 1's transmission error: the estimate of its error against its true error, from
    // the exact closed form in time.
    let points = 1 << 15;
    let series = exact.time_series(points);
    let w = model.elements()[stage1].weights();
    let te_exact: Vec<f64> = (0..points)
        .map(|j| w.iter().map(|&(i, wi)| wi * series[i][j]).sum())
        .collect();
    let te_hb: Vec<f64> = (0..points)
        .map(|j| {
            let theta = std::f64::consts::TAU * j as f64 / points as f64;
            w.iter()
                .map(|&(i, wi)| wi * sol.displacement(i, theta))
                .sum()
        })
        .collect();
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let (mh, me) = (mean(&te_hb), mean(&te_exact));
    let true_error = te_hb
        .iter()
        .zip(&te_exact)
        .map(|(a, b)| ((a - mh) - (b - me)).abs())
        .fold(0.0, f64::max)
        / exact_pp;
    let fine = refined_solution(model, &sol).unwrap();
    let estimates = quantity_errors(
        model,
        fine.basis(),
        sol.harmonics(),
        fine.harmonics(),
        1 << 15,
    )
    .unwrap();
    let estimate = estimates
        .iter()
        .find(|q| q.quantity == Quantity::Coordinate(stage1))
        .unwrap();
    let hb_pp = te_hb.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
        - te_hb.iter().fold(f64::INFINITY, |m, &x| m.min(x));
    eprintln!(
        "stage 1 TE peak to peak: HB {:.3} µm, exact {:.3} µm; error estimate {:.2e}, true {true_error:.2e}",
        hb_pp * 1e6,
        exact_pp * 1e6,
        estimate.error
    );
    assert!(hb_pp < 0.6 * exact_pp);
    // Within a factor 3 of the true error.
    let ratio = estimate.error / true_error;
    assert!((1.0 / 3.0..=3.0).contains(&ratio), "{ratio}");
}
