//! The kink-aware quadrature on contact laws: a force jump (contact damping), independence of
//! the units of the coordinate, and a Jacobian that is the derivative of the corrected residual.

use hbal::continuation::{BranchStop, Continuation};
use hbal::force::{Backlash, MeshProfile};
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};

/// `x'' + 0.1 x' + (1 + 0.2 cos θ) g(x) + c x' [|x| > b] = s (0.1 + 0.05 cos θ)`, half
/// backlash `b = s`: the coordinate scaled by `s`.
fn pair(c: f64, s: f64) -> Model {
    Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .damping(nalgebra::DMatrix::from_element(1, 1, 0.1))
        .element(
            "contact",
            &[("x", 1.0)],
            Backlash::new(
                s,
                MeshProfile::Cosine {
                    mean: 1.0,
                    amplitude: 0.2,
                },
            )
            .with_contact_damping(c),
        )
        .load("x", 0, 0.1 * s, 0.0)
        .load("x", 1, 0.05 * s, 0.0)
        .build()
        .unwrap()
}

/// With contact damping the force jumps where the contact closes; the Jacobian carries the
/// moving jump, so Newton converges quadratically and a sweep takes a few points (before: the
/// 2000-point limit with steps of 1e-5).
#[test]
fn contact_damping_sweeps_in_a_few_points() {
    let model = pair(0.05, 1.0);
    let branch = Continuation {
        stability: None,
        ..Continuation::default()
    }
    .run(&model, HarmonicBasis::new(1.2, 16).unwrap(), 0.9, |_| {})
    .unwrap();
    assert_eq!(branch.stop, BranchStop::Reached);
    assert!(branch.points.len() < 60, "{} points", branch.points.len());
    // The Jacobian against central differences of the corrected residual.
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.9, 16).unwrap()).unwrap();
    let layout = hb.layout();
    let mut x = vec![0.0; layout.len()];
    layout.pack(&branch.points.last().unwrap().harmonics, &mut x);
    let (worst, amax) = crate::common::jacobian_against_differences(&hb, &x, 1e-6);
    assert!(worst < 1e-5 * amax, "|J - FD| = {worst:e}, |J| = {amax}");
}

/// The correction does not depend on the units of the coordinate: the pair with backlash,
/// loads and coordinate scaled by 1e-7 gives the same solution divided by 1e-7 (before: 2e-4
/// off at 1e-6, no convergence at 1e-7).
#[test]
fn quadrature_is_independent_of_the_units() {
    let solve = |s: f64| {
        let model = pair(0.0, s);
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.0, 32).unwrap()).unwrap();
        let sol = Newton::new()
            .with_tolerance(1e-12)
            .unwrap()
            .solve(&hb, &mut hb.workspace())
            .unwrap();
        assert!(sol.is_converged(), "scale {s}: {}", sol.termination);
        sol.harmonics().iter().map(|q| q / s).collect::<Vec<_>>()
    };
    let (one, small) = (solve(1.0), solve(1e-7));
    let d = hbal::compare::relative_error(&small, &one, 1, 32);
    assert!(d < 1e-8, "{d}");
}
