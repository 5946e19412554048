//! `hbal.report`: the library's report ([`hbal::render::report`], `hbal report SCENE --out
//! DIR`): `report.html` with the solve, the run-up (with `to`) and the natural frequencies,
//! and their files in `out/solve`, `out/sweep`, `out/modes`; run with the GIL released, its
//! stages and the run-up's progress to the callback, Ctrl-C stopping the run-up.

use crate::options::overrides;
use crate::progress::PyProgress;
use crate::scene::SceneHandle;
use hbal::render::{ReportParts, ReportSettings};
use pyo3::prelude::*;
use std::path::PathBuf;

/// What a report returns to Python: the page's path, the exit code (0, or 1 where a part
/// failed: its page says why), the parts' failures, the plots that could not be drawn and
/// the library call's wall time (s).
type Returned = (String, u8, Vec<String>, Vec<String>, f64);

/// The report of `scene` into `out`.
#[pyfunction]
#[pyo3(signature = (scene, out, *, to=None, start=None, stability=true, output=None,
    max_step=None, max_points=None, points=None, method=None, harmonics=None, samples=None,
    tolerance=None, formulation=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn report<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SceneHandle>,
    out: PathBuf,
    to: Option<f64>,
    start: Option<f64>,
    stability: bool,
    output: Option<String>,
    max_step: Option<f64>,
    max_points: Option<usize>,
    points: Option<usize>,
    method: Option<String>,
    harmonics: Option<&Bound<'py, PyAny>>,
    samples: Option<usize>,
    tolerance: Option<f64>,
    formulation: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Returned> {
    let o = overrides(method, harmonics, samples, tolerance, formulation)?;
    let handle = scene.get();
    let p = handle.prepare(py, &o)?;
    let s: &hbal::scene::Scene = &p.scene;
    // The scene as the library read it (a Python law by its registry key).
    let text = toml::to_string(&handle.document)
        .or_else(|_| serde_json::to_string_pretty(&handle.document))
        .unwrap_or_default();
    let mut observer = PyProgress::new(progress);
    p.slot.stops(&observer.cancel);
    let settings = ReportSettings {
        from: start,
        to,
        stability,
        output,
        formulation: o.formulation,
        tolerance,
        max_step,
        max_points: max_points
            .map(|n| crate::options::points_in_range("max_points", n, 1))
            .transpose()?,
        points: points
            .map(|n| crate::options::points_in_range("points", n, 2))
            .transpose()?,
        cancel: observer.cancel.clone(),
    };
    let started = std::time::Instant::now();
    let result = py.detach(|| hbal::render::report(s, &text, &settings, &out, &mut observer));
    let seconds = started.elapsed().as_secs_f64();
    if let Some(e) = p.slot.take() {
        return Err(e);
    }
    observer.raise()?;
    let r = result.map_err(|e| p.error(py, e))?;
    crate::out::warn(py, &r.warnings)?;
    let mut errors: Vec<String> = r
        .errors()
        .iter()
        .map(|e| crate::errors::python_names(e))
        .collect();
    if let ReportParts::Periodic(parts) = &r.parts {
        if let Some(a) = &parts.solved.result {
            errors.splice(0..0, solve_failures(&s.file, a));
        }
    }
    let file = r.file.display().to_string();
    Ok((file, r.exit_code, errors, r.warnings, seconds))
}

/// What `hbal report` says of a marked solve on stderr.
fn solve_failures(file: &str, a: &hbal::analysis::SolveAnalysis) -> Vec<String> {
    let mut out = Vec::new();
    if !a.solution.is_converged() {
        out.push(format!(
            "{file}: the solve did not converge: {}",
            a.solution.termination
        ));
    }
    if let hbal::analysis::StabilityOutcome::Failed(e) = &a.stability {
        out.push(format!("{file}: stability computation failed: {e}"));
    }
    if a.auto.as_ref().is_some_and(|r| r.capped) {
        out.push(format!(
            "{file}: automatic harmonics: the estimated error is above the tolerance at the cap"
        ));
    }
    out
}
