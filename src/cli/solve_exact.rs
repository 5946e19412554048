//! What `hbal solve` does differently for the exact piecewise solution: its multipliers are
//! those of the exact monodromy matrix, its extremes those of the closed form in time.

use hbal::report::ElementOutput;
use hbal::solve::piecewise::{ExactExtremes, ExactSolution};

/// The element outputs with the exact extremes and mean forces where there are some.
pub(crate) fn element_outputs(
    outputs: Vec<ElementOutput>,
    extremes: Option<&ExactExtremes>,
) -> Vec<ElementOutput> {
    match extremes {
        Some(x) => outputs
            .into_iter()
            .zip(&x.elements)
            .map(|(o, e)| o.with_exact(e))
            .collect(),
        None => outputs,
    }
}

/// The exact time series for `--out`, resolving the fastest natural motion (at 60 rpm the
/// two-shaft model's ringing after every jump, which the harmonics 0..32 do not hold); `None`
/// for a period multiple ν > 1 (the files span ν excitation periods).
pub(crate) fn time_series(exact: &ExactSolution) -> Option<Vec<Vec<f64>>> {
    let basis = exact.solution.basis();
    (basis.subharmonic() == 1)
        .then(|| exact.time_series(exact.resolving_points().max(basis.samples())))
}
