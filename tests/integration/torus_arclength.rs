//! Pseudo-arclength continuation on the torus (`hbal::torus::TorusArclength`): through both
//! folds of the hardening Duffing oscillator as the one-frequency continuation finds them,
//! and with a second, incommensurate forcing.

use hbal::analysis::{sweep, Silent, SweepSettings};
use hbal::scene::Scene;
use hbal::torus::{TorusArclength, TorusBalance};

fn duffing() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/duffing.toml"
    ))
    .unwrap()
}

/// The largest Ω before the first fold and the smallest after it, by a parabola through the
/// three points around each turn.
fn fold_speeds(omegas: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 1..omegas.len() - 1 {
        let (a, b, c) = (omegas[i - 1], omegas[i], omegas[i + 1]);
        if (b - a) * (c - b) < 0.0 {
            // Vertex of the parabola through (−1, a), (0, b), (1, c).
            let (p, q) = ((a + c) / 2.0 - b, (c - a) / 2.0);
            out.push(b - q * q / (4.0 * p));
        }
    }
    out
}

/// One base (the Duffing scene forced onto the torus): the arclength passes both folds, at
/// the speeds of the one-frequency continuation's turning points.
#[test]
fn arclength_passes_the_duffing_folds_where_the_one_frequency_branch_turns() {
    let text = duffing().replace(
        "harmonics = { count = 7 }",
        "harmonics = { bases = \"torus\", caps = { shaft = 7 }, grid = { shaft = 32 } }",
    );
    let scene = Scene::from_str(&text, "duffing.toml").unwrap();
    let plan = scene.torus.as_ref().unwrap();
    let mut hb = TorusBalance::new(
        plan.bind(&scene.model).unwrap(),
        plan.index_set().unwrap(),
        &plan.samples,
        0.5,
    )
    .unwrap();
    let branch = TorusArclength {
        step: 0.01,
        max_step: 0.03,
        ..Default::default()
    }
    .run(&mut hb, 0.5, 2.6, |_| {})
    .unwrap();
    assert!(branch.reached, "{:?}", branch.stopped);
    assert_eq!(branch.folds, 2);
    assert!(branch
        .points
        .iter()
        .all(|p| p.converged && p.relative_residual <= 1e-10));
    let torus_folds = fold_speeds(&branch.points.iter().map(|p| p.omega).collect::<Vec<_>>());

    let one = Scene::from_str(&duffing(), "duffing.toml").unwrap();
    let settings = SweepSettings {
        from: Some(0.5),
        max_step: 0.05,
        ..SweepSettings::to(2.6)
    };
    let reference = sweep(&one, &settings, &mut Silent).unwrap();
    assert_eq!(reference.branch.folds(), 2);
    let one_folds = fold_speeds(
        &reference
            .branch
            .points
            .iter()
            .map(|p| p.omega)
            .collect::<Vec<_>>(),
    );
    assert_eq!(torus_folds.len(), 2, "{torus_folds:?}");
    eprintln!("folds: torus {torus_folds:?}, one fundamental {one_folds:?}");
    for (a, b) in torus_folds.iter().zip(&one_folds) {
        // Measured 2.2115438 and 1.1701621 on both (1e-9 and 2e-8 apart).
        assert!(
            (a - b).abs() < 1e-6 * b,
            "fold at {a} on the torus, {b} on one fundamental"
        );
    }
}

/// Two incommensurate forcings (1 and √2 times the speed): the quasi-periodic branch is
/// followed through the folds of the resonance the √2 forcing drives (measured at Ω = 0.868
/// and 0.768, 1188 points to 2 rad/s).
#[test]
fn arclength_follows_a_quasi_periodic_branch_through_its_folds() {
    // The second forcing on its own base: bind a load to it through the library.
    let model = hbal::Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.02))
        .element(
            "spring",
            &[("x", 1.0)],
            hbal::force::CubicSpring::new(1.0, 1.0),
        )
        .load("x", 1, 0.1, 0.0)
        .load("x", 1, 0.02, 0.0)
        .build()
        .unwrap();
    let bases = hbal::torus::Bases::new(&[("a", 1.0), ("b", 2f64.sqrt())]).unwrap();
    let tm = hbal::torus::TorusModel::new(&model, bases)
        .bind_load(1, "b")
        .unwrap();
    let set = hbal::torus::IndexSet::new(
        tm.bases(),
        &[7, 3],
        hbal::torus::Truncation::Diamond { total: 7 },
    )
    .unwrap();
    let mut hb = TorusBalance::new(tm, set, &[32, 16], 0.5).unwrap();
    let branch = TorusArclength {
        step: 0.01,
        max_step: 0.03,
        ..Default::default()
    }
    .run(&mut hb, 0.5, 2.0, |_| {})
    .unwrap();
    assert!(branch.reached, "{:?}", branch.stopped);
    assert_eq!(branch.folds, 2);
    assert!(branch.points.iter().all(|p| p.converged));
    let folds = fold_speeds(&branch.points.iter().map(|p| p.omega).collect::<Vec<_>>());
    eprintln!(
        "quasi-periodic folds {folds:?}, {} points",
        branch.points.len()
    );
}
