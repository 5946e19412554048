//! Broyden's method on the torus (`hbal::torus::TorusBroyden`): the Newton–Krylov solution of
//! the rattling two-stage train and of the free-free drivetrain, without Jacobian products.

use crate::torus::two_stage_rippled;
use hbal::catalog::TwoStageTrain;
use hbal::torus::{
    Bases, IndexSet, NewtonKrylov, TorusBalance, TorusBroyden, TorusModel, TorusSolution,
    Truncation,
};

/// `(max |ΔU|, max |U|)` over the lines but the mean.
fn difference(a: &TorusSolution, b: &TorusSolution) -> (f64, f64) {
    let m = a.unknowns.len() / a.indices.len();
    let (mut diff, mut size) = (0.0f64, 0.0f64);
    for (x, y) in a.unknowns.iter().zip(&b.unknowns).skip(m) {
        diff = diff.max((x.0 - y.0).hypot(x.1 - y.1));
        size = size.max(x.0.hypot(x.1));
    }
    (diff, size)
}

/// The rattling train (the contact opens): Broyden reaches Newton–Krylov's solution to 1e-8.
#[test]
fn broyden_agrees_with_newton_krylov_where_the_contact_opens() {
    let model = two_stage_rippled([1, 1], 1, 1000.0);
    let bases = Bases::new(&[("mesh 1", 67.0), ("mesh 2", 19.0)]).unwrap();
    let tm = TorusModel::new(&model, bases)
        .bind_element("stage 2", "mesh 2")
        .unwrap();
    let set = IndexSet::new(tm.bases(), &[6, 6], Truncation::Box).unwrap();
    let hb = TorusBalance::new(tm, set, &[32, 32], 20.0).unwrap();
    let newton = NewtonKrylov::default().solve(&hb, None).unwrap();
    let broyden = TorusBroyden::default().solve(&hb, None).unwrap();
    assert!(
        broyden.converged,
        "{} after {}",
        broyden.relative_residual, broyden.iterations
    );
    assert_eq!(broyden.linear_iterations, 0, "no Jacobian products");
    let (diff, size) = difference(&newton, &broyden);
    assert!(diff <= 1e-8 * size, "{diff:e} of {size:e}");
    eprintln!(
        "Broyden {} steps, Newton-Krylov {} steps",
        broyden.iterations, newton.iterations
    );
}

/// The free-free drivetrain at 3000 rpm (three bases, backlash on both stages, stage 1 losing
/// contact at its third mesh harmonic):
/// Broyden converges to Newton–Krylov's solution.
#[test]
fn broyden_solves_the_drivetrain() {
    let model = TwoStageTrain::default().model().unwrap();
    let set = IndexSet::new(
        &TwoStageTrain::bases().unwrap(),
        &[8, 4, 4],
        Truncation::Box,
    )
    .unwrap();
    let hb = TorusBalance::new(
        TwoStageTrain::bind(&model).unwrap(),
        set,
        &[32, 16, 16],
        3000.0 * std::f64::consts::TAU / 60.0,
    )
    .unwrap();
    let newton = NewtonKrylov::default().solve(&hb, None).unwrap();
    let broyden = TorusBroyden::default().solve(&hb, None).unwrap();
    assert!(
        broyden.converged,
        "{} after {}",
        broyden.relative_residual, broyden.iterations
    );
    let (diff, size) = difference(&newton, &broyden);
    assert!(diff <= 1e-8 * size, "{diff:e} of {size:e}");
    eprintln!(
        "drivetrain: Broyden {} steps, Newton-Krylov {} steps ({} products)",
        broyden.iterations, newton.iterations, newton.linear_iterations
    );
}
