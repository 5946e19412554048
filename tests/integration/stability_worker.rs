//! A sweep with its points' stability on a worker thread ([`Continuation::stability_worker`])
//! gives the branch of one thread, bit for bit: the Duffing sweep through both folds, and a
//! sweep whose stability fails part-way (the worker has then seen points the tracer computed
//! ahead, which must not reach the branch).

use hbal::catalog::Duffing;
use hbal::continuation::{Branch, BranchStop, Continuation};
use hbal::stability::FloquetOptions;
use hbal::HarmonicBasis;
use std::time::Duration;

fn sweep(worker: bool, stability: FloquetOptions) -> Branch {
    let model = Duffing::default().model().unwrap();
    Continuation {
        stability: Some(stability),
        // Always (the Duffing points' stability is quick), or never.
        stability_worker: worker.then_some(Duration::ZERO),
        ..Continuation::default()
    }
    .run(&model, HarmonicBasis::new(2.6, 7).unwrap(), 0.5, |_| {})
    .unwrap()
}

/// Ω, max |q|, the multipliers and the fold flags of every point, and the stop.
fn assert_same(serial: &Branch, piped: &Branch) {
    assert_eq!(serial.stop, piped.stop);
    assert_eq!(serial.points.len(), piped.points.len());
    for (a, b) in serial.points.iter().zip(&piped.points) {
        assert_eq!(a.omega.to_bits(), b.omega.to_bits());
        assert_eq!(a.max_abs, b.max_abs);
        assert_eq!(a.fold, b.fold);
        assert_eq!(a.bifurcation, b.bifurcation);
        let mu =
            |p: &hbal::continuation::BranchPoint| p.floquet.as_ref().map(|f| f.multipliers.clone());
        assert_eq!(mu(a), mu(b), "Ω {}", a.omega);
    }
}

#[test]
fn worker_gives_the_serial_branch() {
    let serial = sweep(false, FloquetOptions::default());
    let piped = sweep(true, FloquetOptions::default());
    assert_eq!(serial.stop, BranchStop::Reached);
    assert_eq!(serial.folds(), 2);
    assert!(serial.points.len() > 50);
    assert_same(&serial, &piped);
}

/// The steps a period takes grow as Ω falls: a step limit that the first points meet and
/// later ones exceed (40 per period: the 12th point, Ω = 1.85) ends the branch at the first of
/// those, on the worker as on one thread.
#[test]
fn worker_stops_where_the_stability_fails() {
    let options = FloquetOptions {
        max_steps: 40,
        ..FloquetOptions::default()
    };
    let serial = sweep(false, options);
    let piped = sweep(true, options);
    assert!(
        matches!(serial.stop, BranchStop::StabilityFailed { omega, .. } if omega < 2.0),
        "{}",
        serial.stop
    );
    assert!(serial.points.len() >= 5, "{}", serial.points.len());
    assert!(serial.points.last().is_some_and(|p| p.floquet.is_none()));
    assert_same(&serial, &piped);
}
