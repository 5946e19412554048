//! The exact solution's error estimate: independent of the time unit, and a lower bound where
//! the work budget stops short of the ringing.

use super::tests::chain_in_time_unit;
use super::*;
use crate::force::{MeshDamping, MeshProfile, MeshStiffness};

#[test]
fn the_solution_and_its_estimate_do_not_depend_on_the_time_unit() {
    // The same motion in seconds, milliseconds and kiloseconds: the periodicity solve works in
    // (q, q̇/ω_s), so its pivots, and the rounding estimate made from them, are one (in
    // (q, q̇) they moved with the unit squared).
    let omega = 3e5;
    let solve = |c: f64| {
        PiecewiseExact::new()
            .solve_exact(
                &chain_in_time_unit(1.6, true, c),
                &HarmonicBasis::new(omega / c, 16).unwrap(),
            )
            .unwrap()
    };
    let seconds = solve(1.0);
    for c in [1e-3, 1e3] {
        let other = solve(c);
        let err = crate::compare::relative_error(
            other.solution.harmonics(),
            seconds.solution.harmonics(),
            2,
            16,
        );
        let (a, b) = (
            other.estimate.kept_harmonics,
            seconds.estimate.kept_harmonics,
        );
        eprintln!("unit x{c}: {err:.1e} apart, kept {a:.2e} against {b:.2e}");
        assert!(err < 1e-11, "x{c}: {err:.2e}");
        assert!(
            a <= 1.5 * b && b <= 1.5 * a,
            "x{c}: {a:.2e} against {b:.2e}"
        );
        let (a, b) = (other.estimate.relative, seconds.estimate.relative);
        assert!((a - b).abs() <= 1e-6 * b, "x{c}: {a:.3e} against {b:.3e}");
        assert_eq!(
            other.estimate.reference_harmonics,
            seconds.estimate.reference_harmonics
        );
    }
}

#[test]
fn an_estimate_cut_short_by_the_work_budget_says_it_is_a_lower_bound() {
    // 30 DOFs at 10 rad/s: the jumps ring up to order ~11000, the budget affords a few hundred
    // orders; the estimate counts what it computed and says that more may be missing.
    let n = 30;
    let names: Vec<String> = (0..n).map(|i| format!("d{i}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut k = vec![(0, 0, 4e5)];
    let mut d = vec![];
    for i in 1..n {
        k.extend([
            (i - 1, i - 1, 4e5),
            (i, i, 4e5),
            (i - 1, i, -4e5),
            (i, i - 1, -4e5),
        ]);
        d.push((i, i, 0.5));
    }
    let model = Model::builder(&names)
        .mass_diagonal(&vec![1e-3; n])
        .stiffness_triplets(&k)
        .damping_triplets(&d)
        .element(
            "mesh",
            &[("d0", 1.0)],
            MeshStiffness::new(
                1,
                MeshProfile::Rectangular {
                    one_tooth: 2e5,
                    two_tooth: 3.5e5,
                    contact_ratio: 1.5,
                },
                MeshDamping::Proportional(4e-6),
            ),
        )
        .load(names[n - 1], 0, 5.0, 0.0)
        .build()
        .unwrap();
    let basis = HarmonicBasis::new(10.0, 8).unwrap();
    let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
    let e = exact.estimate;
    assert!(e.lower_bound, "{e:?}");
    assert!(
        e.reference_harmonics >= 16 && e.reference_harmonics < 2000,
        "{e:?}"
    );
    assert!(e.relative > 1e-4 && e.relative.is_finite(), "{e:?}");
    // The chain at 6000 rad/s: the ringing is within reach, the estimate is whole.
    let basis = HarmonicBasis::new(6000.0, 8).unwrap();
    let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
    assert!(!exact.estimate.lower_bound, "{:?}", exact.estimate);
    assert!(exact.extremes().resolved);
}
