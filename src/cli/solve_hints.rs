//! The notes `hbal solve` adds where harmonic balance at a fixed H leaves the harmonics 0..H
//! above 1e-6 and something the scene does not use would do better: the tail correction of
//! a coefficient that jumps in time, or the exact piecewise solution of a linear scene.

use hbal::scene::Scene;
use hbal::solve::ErrorEstimate;
use hbal::HarmonicBalance;

/// Every note for the solution of `scene` with `estimate`; `hb` is the harmonic balance
/// that solved it at a fixed H (none for automatic harmonics and the exact method).
pub(crate) fn print(
    scene: &Scene,
    hb: Option<&HarmonicBalance>,
    estimate: Option<&Result<ErrorEstimate, String>>,
) {
    let Some(Ok(e)) = estimate else { return };
    if e.kept_harmonics <= 1e-6 {
        return;
    }
    if let Some(note) = hb.and_then(|hb| tail_correction(scene, hb)) {
        eprintln!(
            "note: {}: the harmonics 0..H are estimated {:.1e} off; {note}",
            scene.file, e.kept_harmonics
        );
    }
    if !matches!(scene.method, hbal::solve::Method::PiecewiseExact(_))
        && hbal::solve::PiecewiseExact::check(&scene.model).is_ok()
    {
        eprintln!(
            "note: {}: the harmonics 0..H are estimated {:.1e} off; this scene is linear with piecewise-constant coefficients: `--method piecewise_exact` gives them, and the extremes in time, exactly",
            scene.file, e.kept_harmonics
        );
    }
}

/// The note on the tail correction where it is left to its default (off at a fixed H) and
/// would apply at this H (a coefficient jumps in time, the harmonics above H are
/// mass-dominated).
fn tail_correction(scene: &Scene, hb: &HarmonicBalance) -> Option<String> {
    let unset = scene.basis.tail_correction_setting().is_none();
    (unset && hb.tail_correction_would_apply()).then(|| {
        format!(
            "a coefficient jumps in time and the harmonics above H = {} are mass-dominated: \
             `tail_correction = true` in [harmonics] (or `--harmonics auto:harmonics`) adds \
             their coupling to the kept ones (the two-shaft model at 6000 rpm: 2.7e-4 -> 8.9e-7 at \
             H = 32)",
            scene.basis.harmonics()
        )
    })
}
