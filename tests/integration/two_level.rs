//! The two-level map (Newton's Jacobian on the low harmonics, the per-harmonic step above)
//! against the plain solvers, the shared reference and a tight time-domain reference.

use crate::common;

use common::reference;
use hbal::catalog::TwoShaft;
use hbal::compare::relative_error;
use hbal::nalgebra::DMatrix;
use hbal::solve::coarse::{coarse_harmonics, highest_natural_frequency};
use hbal::timesim::TimeSimulation;
use hbal::{Anderson, HarmonicBalance, HarmonicBasis, Model};

/// The two-level map converges to the same fine-basis solution as the paper's map, in a
/// handful of steps where the paper's map needs 81, and that solution is the shared
/// reference to 6e-8 (H = 512).
#[test]
fn two_level_map_matches_the_plain_map_and_the_reference() {
    let reference = reference("seed_rect_6000rpm.json");
    let shaft = TwoShaft::new(6000.0);
    let model = shaft.model().unwrap();
    let hb =
        HarmonicBalance::new(&model, HarmonicBasis::new(reference.omega, 512).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let base = Anderson::new()
        .with_tolerance(1e-12)
        .unwrap()
        .with_max_iterations(500);
    let plain = base.solve(&hb, &mut ws).unwrap();
    let hc = coarse_harmonics(&model, hb.basis()).unwrap();
    assert_eq!(hc, 32, "1.5 ω_max / Ω = 11.6, at least 32");
    let two = base.with_coarse_harmonics(hc).solve(&hb, &mut ws).unwrap();
    assert!(plain.is_converged() && two.is_converged());
    assert!(
        two.stats.iterations <= 10 && plain.stats.iterations >= 40,
        "iterations {} (two-level) against {} (plain)",
        two.stats.iterations,
        plain.stats.iterations
    );
    let n = model.n_dofs();
    let same = relative_error(two.harmonics(), plain.harmonics(), n, 512);
    assert!(same < 1e-10, "two-level against plain {same:.1e}");
    let err = relative_error(two.harmonics(), &reference.harmonics, n, 32);
    assert!(err < 1e-7, "error against the reference {err:.2e}");
}

/// At 600 rpm the resonance sits at harmonic 77 of the mesh frequency: the plain map diverges
/// at H = 512, the two-level map with the Newton block up to 1.5 ω_max converges, and its
/// harmonics 0..32 match a time-domain reference (rtol 1e-12) to 1e-5, to 1e-7 with the tail
/// correction.
#[test]
fn two_level_map_at_600_rpm_reaches_1e5() {
    let shaft = TwoShaft::new(600.0);
    let model = shaft.model().unwrap();
    let omega = shaft.mesh_omega();
    let basis = HarmonicBasis::new(omega, 512)
        .unwrap()
        .with_tail_correction(true);
    let hb = HarmonicBalance::new(&model, basis).unwrap();
    let mut ws = hb.workspace();
    let base = Anderson::new()
        .with_tolerance(1e-12)
        .unwrap()
        .with_max_iterations(500);
    let plain = base.solve(&hb, &mut ws).unwrap();
    assert!(!plain.is_converged(), "the paper's map at 600 rpm");
    let hc = coarse_harmonics(&model, hb.basis()).unwrap();
    assert_eq!(hc, 116);
    let two = base.with_coarse_harmonics(hc).solve(&hb, &mut ws).unwrap();
    assert!(
        two.is_converged() && two.stats.iterations <= 30,
        "{}",
        two.termination
    );
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        samples: 4096,
        ..TimeSimulation::default()
    }
    .run(&model, omega)
    .unwrap();
    let err = relative_error(two.harmonics(), &td.harmonics, model.n_dofs(), 32);
    // 3.9e-6 without the tail correction (the H⁻³ truncation), 3.0e-9 with it.
    assert!(err < 1e-7, "error at 600 rpm {err:.2e}");
}

/// `ω_max` of a two-mass chain `m = 1, 2`, springs `k = 3` to ground and between:
/// `λ = (15 ± √153)/4` of `M⁻¹K` (trace 7.5, determinant 4.5).
#[test]
fn highest_natural_frequency_of_a_chain() {
    let model = Model::builder(&["a", "b"])
        .mass(DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 2.0]))
        .stiffness(DMatrix::from_row_slice(2, 2, &[6.0, -3.0, -3.0, 3.0]))
        .build()
        .unwrap();
    let w = highest_natural_frequency(&model).unwrap();
    let exact = ((15.0 + 153f64.sqrt()) / 4.0).sqrt();
    assert!((w - exact).abs() < 1e-12, "{w} against {exact}");
    // Ω = 1: 1.5 ω_max = 3.9 → 4 harmonics, raised to 32; none below H = 32.
    let basis = HarmonicBasis::new(1.0, 32).unwrap();
    assert_eq!(coarse_harmonics(&model, &basis), None);
    let basis = HarmonicBasis::new(1.0, 64).unwrap();
    assert_eq!(coarse_harmonics(&model, &basis), Some(32));
}

/// At 60 rpm the resonance sits at harmonic 771: the Newton block must reach 1.5 ω_max / Ω =
/// 1156 harmonics (2313 real unknowns, above the automatic choice's cap: 1.2 s, nearly all
/// its dense factorisation), and H = 2048 then matches a time-domain reference to 1e-5
/// (measured 5.9e-6). Release build: `cargo test --release --test integration -- --ignored two_level::`.
#[test]
#[ignore = "1.2 s in release: run by CI with --ignored"]
fn two_level_map_at_60_rpm_reaches_1e5() {
    let shaft = TwoShaft::new(60.0);
    let model = shaft.model().unwrap();
    let omega = shaft.mesh_omega();
    let hc = (1.5 * highest_natural_frequency(&model).unwrap() / omega).ceil() as usize;
    assert_eq!(hc, 1156);
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(omega, 2048).unwrap()).unwrap();
    let two = Anderson::new()
        .with_tolerance(1e-12)
        .unwrap()
        .with_max_iterations(500)
        .with_coarse_harmonics(hc)
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(
        two.is_converged() && two.stats.iterations <= 30,
        "{}",
        two.termination
    );
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        samples: 4096,
        ..TimeSimulation::default()
    }
    .run(&model, omega)
    .unwrap();
    let err = relative_error(two.harmonics(), &td.harmonics, model.n_dofs(), 32);
    assert!(err < 1e-5, "error at 60 rpm {err:.2e}");
}

/// With contact (the backlash pair at W = 1.0, contact loss), where the Jacobian changes with
/// the contact state: the two-level solve at H = 128 agrees with Newton on the whole basis to
/// 1e-10.
#[test]
fn two_level_map_with_contact_matches_newton() {
    let model = hbal::catalog::GearBacklash::default().model().unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.0, 128).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let newton = hbal::Newton::new()
        .with_tolerance(1e-12)
        .unwrap()
        .solve(&hb, &mut ws)
        .unwrap();
    let two = Anderson::new()
        .with_tolerance(1e-12)
        .unwrap()
        .with_coarse_harmonics(32)
        .solve(&hb, &mut ws)
        .unwrap();
    assert!(
        newton.is_converged() && two.is_converged(),
        "{}",
        two.termination
    );
    assert!(
        two.stats.iterations <= 30,
        "{} iterations",
        two.stats.iterations
    );
    let d = relative_error(two.harmonics(), newton.harmonics(), 1, 128);
    assert!(d < 1e-10, "two-level against Newton {d:.1e}");
}
