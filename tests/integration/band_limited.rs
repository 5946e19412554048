//! A mesh stiffness that jumps between samples: with the band-limited profile the AFT is the
//! exact Galerkin projection, so HB converges like H^-3 whatever N, instead of O(1/N); with the
//! tail correction (the coupling through the harmonics above H) much faster.

use hbal::catalog::TwoShaft;
use hbal::compare::relative_error;
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};

/// The paper's two-shaft model at 6000 rpm with contact ratio 1.6 (jumps at 0 and 0.6 of the
/// mesh cycle: off the samples of every power-of-two N).
fn model() -> Model {
    TwoShaft::new(6000.0).model_with_contact_ratio(1.6).unwrap()
}

fn hb(model: &Model, h: usize, samples: Option<usize>) -> Vec<hbal::num_complex::Complex64> {
    solve(model, h, samples, true)
}

fn solve(
    model: &Model,
    h: usize,
    samples: Option<usize>,
    tail: bool,
) -> Vec<hbal::num_complex::Complex64> {
    let omega = TwoShaft::new(6000.0).mesh_omega();
    let mut basis = HarmonicBasis::new(omega, h)
        .unwrap()
        .with_tail_correction(tail);
    if let Some(n) = samples {
        basis = basis.with_samples(n).unwrap();
    }
    let hb = HarmonicBalance::new(model, basis).unwrap();
    assert_eq!(hb.tail_corrected(), tail);
    let sol = Newton::new()
        .with_tolerance(1e-12)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged());
    sol.harmonics().to_vec()
}

/// Against the time-domain reference (rtol 1e-12, restarted at every jump): without the tail
/// correction the error over harmonics 1..=32 falls like H^-3 (measured 3.0e-4, 3.5e-5, 4.4e-6
/// at H = 32, 64, 128; the sampled profile gave 2.0e-3, 4.9e-4 (H = 128) and 1.2e-4
/// (H = 512)); with it (the default) 8.7e-7, 1.1e-7 and 2.6e-8 (near the reference's own level).
#[test]
fn off_sample_jumps_converge_like_h_cubed() {
    let model = model();
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        ..TimeSimulation::default()
    }
    .run(&model, TwoShaft::new(6000.0).mesh_omega())
    .unwrap();
    assert!(td.converged);
    let error = |h, tail| relative_error(&solve(&model, h, None, tail), &td.harmonics, 1, 32);
    let corrected: Vec<f64> = [32, 64, 128].iter().map(|&h| error(h, true)).collect();
    eprintln!("with the tail correction {corrected:?}");
    assert!(corrected[0] < 1e-6, "{corrected:?}");
    assert!(corrected[1] < 2e-7 && corrected[2] < 5e-8, "{corrected:?}");
    let errors: Vec<f64> = [32, 64, 128].iter().map(|&h| error(h, false)).collect();
    eprintln!("errors {errors:?}");
    assert!(errors[2] < 5e-6, "{errors:?}");
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 6.0, "slower than H^-3: {errors:?}");
    }
}

/// The result does not depend on where the samples fall: N = 256 (jumps between samples) and
/// N = 320 (a multiple of 5: jumps on samples) give the same harmonics to 1e-9.
#[test]
fn band_limited_result_is_independent_of_the_samples() {
    let model = model();
    let (a, b) = (hb(&model, 32, Some(256)), hb(&model, 32, Some(320)));
    let d = relative_error(&a, &b, 1, 32);
    assert!(d < 1e-9, "{d}");
}
