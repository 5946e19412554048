//! HB against the time-domain reference: DOP853 at rtol 1e-12, started on the HB orbit's
//! state at t = 0 and run until successive periods agree to 1e-11; the error is
//! [`relative_error`] over harmonics 0..=2H (the HB solution has none above H, so its
//! truncation counts).

use hbal::compare::relative_error;
use hbal::num_complex::Complex64;
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};

/// The state `(q, q̇)` at θ = 0 of harmonics `x` (harmonic-major, `n` DOFs, fundamental ω).
pub fn state_at_zero(x: &[Complex64], n: usize, omega: f64) -> (Vec<f64>, Vec<f64>) {
    let h = x.len() / n - 1;
    let q = (0..n)
        .map(|i| (0..=h).map(|k| x[k * n + i].re).sum())
        .collect();
    let v = (0..n)
        .map(|i| {
            (1..=h)
                .map(|k| (x[k * n + i] * Complex64::new(0.0, k as f64 * omega)).re)
                .sum()
        })
        .collect();
    (q, v)
}

/// HB (Newton to 1e-12) with `h` harmonics at `omega`.
pub fn hb(model: &Model, omega: f64, h: usize) -> Vec<Complex64> {
    let hb = HarmonicBalance::new(model, HarmonicBasis::new(omega, h).unwrap()).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-12)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    sol.harmonics().to_vec()
}

/// The time-domain reference started on the state of `x`; its harmonics.
pub fn time_domain(model: &Model, omega: f64, x: &[Complex64]) -> Vec<Complex64> {
    time_domain_to(model, omega, x, 1e-11)
}

/// The same, run until successive periods agree to `steady` (relative).
pub fn time_domain_to(model: &Model, omega: f64, x: &[Complex64], steady: f64) -> Vec<Complex64> {
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: steady,
        initial: Some(state_at_zero(x, model.n_dofs(), omega)),
        max_periods: 5000,
        ..TimeSimulation::default()
    }
    .run(model, omega)
    .unwrap();
    assert!(td.converged, "{:?} after {} periods", td.stop, td.periods);
    td.harmonics
}

/// HB with `h` harmonics against the time domain: the relative error over 0..=2H.
pub fn error_against_time_domain(model: &Model, omega: f64, h: usize) -> f64 {
    let x = hb(model, omega, h);
    let td = time_domain(model, omega, &x);
    relative_error(&x, &td, model.n_dofs(), 2 * h)
}
