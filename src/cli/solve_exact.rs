//! The exact piecewise solution's time series for `hbal solve --out` (its multipliers, those
//! of the exact monodromy matrix, and its extremes, those of the closed form, come from the
//! library).

use hbal::solve::piecewise::ExactSolution;

/// The exact time series for `--out`, resolving the fastest natural motion (at 60 rpm the
/// two-shaft model's ringing after every jump, which the harmonics 0..32 do not hold); `None`
/// for a period multiple ν > 1 (the files span ν excitation periods).
pub(crate) fn time_series(exact: &ExactSolution) -> Option<Vec<Vec<f64>>> {
    let basis = exact.solution.basis();
    (basis.subharmonic() == 1)
        .then(|| exact.time_series(exact.resolving_points().max(basis.samples())))
}
