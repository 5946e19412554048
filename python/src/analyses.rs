//! The analyses of `hbal.solve`, `hbal.sweep`, `hbal.parameter_sweep`, `hbal.modes` and
//! `hbal.compare`: the library's `hbal::analysis` functions with the command line's options,
//! run with the GIL released. Each returns `(record, exit_code, seconds)`: the analysis's serde form
//! (what `hbal ... --json` prints, as Python objects, bit for bit, built when first read) and the exit code of the
//! command-line contract (0, or 1 where the result is marked) and the library call's wall time.

use crate::options::{
    formulation_of, orbit_of, overrides, points_in_range, refuse_on_torus, start_of,
};
use crate::progress::PyProgress;
use crate::record::{Record, ToRecord};
use crate::scene::{Prepared, SceneHandle};
use hbal::analysis as an;
use hbal::render;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// What an analysis returns to Python: its record, its exit code and the wall time of the
/// library's call alone (s; what the binding adds around it is the rest of the Python call).
type Returned<'py> = (Bound<'py, Record>, u8, f64);

/// Runs `analysis` with the GIL released, timing it.
fn timed<T: Send>(py: Python<'_>, analysis: impl FnOnce() -> T + Send) -> (T, f64) {
    py.detach(|| {
        let start = std::time::Instant::now();
        let result = analysis();
        (result, start.elapsed().as_secs_f64())
    })
}

/// The record and exit code of an analysis, or its error (a Python law's failure first);
/// its files written into `out` by `write` where given ([`crate::out`]).
fn finish<'py, T: ToRecord + 'static>(
    py: Python<'py>,
    prepared: &Prepared<'_>,
    (result, seconds): (hbal::Result<T>, f64),
    exit_code: impl FnOnce(&T) -> u8,
    out: Option<&Path>,
    write: impl FnOnce(&T, &Path, &mut Vec<String>) -> hbal::Result<()> + Send,
) -> PyResult<Returned<'py>> {
    if let Some(e) = prepared.slot.take() {
        return Err(e);
    }
    let analysis = result.map_err(|e| prepared.error(py, e))?;
    let code = exit_code(&analysis);
    let a = &analysis;
    crate::out::write(py, prepared, out, |dir, w| write(a, dir, w))?;
    Ok((Bound::new(py, Record::new(analysis))?, code, seconds))
}

/// One periodic solution (`hbal solve`): on several base frequencies where the scene is.
#[pyfunction]
#[pyo3(signature = (scene, *, method=None, harmonics=None, samples=None, tolerance=None,
    formulation=None, stability=true, fallback=true, guess=None, out=None))]
#[allow(clippy::too_many_arguments)]
pub fn solve<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SceneHandle>,
    method: Option<String>,
    harmonics: Option<&Bound<'py, PyAny>>,
    samples: Option<usize>,
    tolerance: Option<f64>,
    formulation: Option<&str>,
    stability: bool,
    fallback: bool,
    guess: Option<&Bound<'py, PyAny>>,
    out: Option<PathBuf>,
) -> PyResult<Returned<'py>> {
    let o = overrides(method, harmonics, samples, tolerance, formulation)?;
    let p = scene.get().prepare(py, &o)?;
    let s: &hbal::scene::Scene = &p.scene;
    let out = out.as_deref();
    if s.torus.is_some() {
        refuse_on_torus(&[("fallback", !fallback), ("guess", guess.is_some())])?;
        crate::out::prepare(py, &p, out, &render::torus_solve_files())?;
        let settings = an::TorusSolveSettings { speed: None };
        let result = timed(py, || an::torus_solve(s, &settings));
        let write = |a: &_, dir: &Path, w: &mut _| render::write_torus_solve_files(dir, s, a, w);
        return finish(py, &p, result, |a| a.exit_code(), out, write);
    }
    crate::out::prepare(py, &p, out, &render::solve_files())?;
    let settings = an::SolveSettings {
        start: start_of(guess, s)?.map(|g| (g.harmonics, "guess".to_string())),
        stability,
        fallback,
        formulation: o.formulation,
    };
    let result = timed(py, || an::solve(s, &settings));
    let write = |a: &_, dir: &Path, w: &mut _| render::write_solve_files(s, a, dir, w).map(|_| ());
    finish(py, &p, result, |a| a.exit_code(), out, write)
}

/// A speed sweep (`hbal sweep --to`): through turning points with stability, or at evenly
/// spaced speeds on several base frequencies.
#[pyfunction]
#[pyo3(signature = (scene, to, *, start=None, harmonics=None, samples=None, tolerance=None,
    formulation=None, stability=true, stability_orbit="exact", max_points=None, max_step=0.5,
    points=101, all_branches=false, error_estimate=true, output=None, dofs=None, progress=None,
    guess=None, out=None))]
#[allow(clippy::too_many_arguments)]
pub fn sweep<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SceneHandle>,
    to: f64,
    start: Option<f64>,
    harmonics: Option<&Bound<'py, PyAny>>,
    samples: Option<usize>,
    tolerance: Option<f64>,
    formulation: Option<&str>,
    stability: bool,
    stability_orbit: &str,
    max_points: Option<usize>,
    max_step: f64,
    points: usize,
    all_branches: bool,
    error_estimate: bool,
    output: Option<String>,
    dofs: Option<String>,
    progress: Option<Py<PyAny>>,
    guess: Option<&Bound<'py, PyAny>>,
    out: Option<PathBuf>,
) -> PyResult<Returned<'py>> {
    let out = out.as_deref();
    // As the command line: the tolerance is checked with the scene's, and is the corrector's.
    let o = overrides(None, harmonics, samples, tolerance, formulation)?;
    let points = points_in_range("points", points, 2)?;
    let max_points = max_points
        .map(|n| points_in_range("max_points", n, 1))
        .transpose()?;
    let orbit = orbit_of(stability_orbit)?;
    let p = scene.get().prepare(py, &o)?;
    let s: &hbal::scene::Scene = &p.scene;
    let mut observer = PyProgress::new(progress);
    p.slot.stops(&observer.cancel);
    if s.torus.is_some() {
        refuse_on_torus(&[
            ("guess", guess.is_some()),
            ("all_branches", all_branches),
            ("max_points", max_points.is_some()),
            ("dofs", dofs.is_some()),
            ("stability_orbit", orbit != hbal::stability::Orbit::Exact),
            ("output", output.is_some()),
        ])?;
        let shown = render::torus_shown(s, None).map_err(|e| p.error(py, e))?;
        crate::out::prepare(py, &p, out, &render::torus_sweep_files())?;
        let settings = an::TorusSweepSettings {
            from: start,
            to,
            points,
        };
        let result = timed(py, || an::torus_sweep(s, &settings, &mut observer));
        observer.raise()?;
        let write = |a: &_, dir: &Path, w: &mut _| {
            render::write_torus_sweep_files(dir, s, a, shown.as_deref(), w)
        };
        return finish(py, &p, result, |a| a.exit_code(), out, write);
    }
    let guess = start_of(guess, s)?.map(|g| an::SweepStart {
        harmonics: g.harmonics,
        omega: g.omega,
        label: "guess".into(),
    });
    let settings = an::SweepSettings {
        from: start,
        start: guess,
        stability,
        orbit,
        max_points,
        max_step,
        points,
        all_branches,
        error_estimate,
        formulation: o.formulation,
        tolerance,
        output,
        dofs,
        cancel: observer.cancel.clone(),
        ..an::SweepSettings::to(to)
    };
    an::check_sweep(s, &settings).map_err(|e| p.error(py, e))?;
    if let Some(dir) = out {
        render::prepare_sweep_out(dir, s, settings.dofs.as_deref()).map_err(|e| p.error(py, e))?;
    }
    let result = timed(py, || an::sweep(s, &settings, &mut observer));
    // A law's failure first: it cancelled the sweep.
    if let Some(e) = p.slot.take() {
        return Err(e);
    }
    observer.raise()?;
    let write = |a: &_, dir: &Path, w: &mut _| render::write_sweep_files(dir, s, a, w);
    finish(py, &p, result, |a| a.exit_code(), out, write)
}

/// A sweep of one numeric scene field (`hbal sweep --parameter`).
#[pyfunction]
#[pyo3(signature = (scene, parameter, start, to, *, points=101, harmonics=None, samples=None,
    formulation=None, stability=true, dofs=None, progress=None, out=None))]
#[allow(clippy::too_many_arguments)]
pub fn parameter_sweep<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SceneHandle>,
    parameter: String,
    start: f64,
    to: f64,
    points: usize,
    harmonics: Option<&Bound<'py, PyAny>>,
    samples: Option<usize>,
    formulation: Option<&str>,
    stability: bool,
    dofs: Option<String>,
    progress: Option<Py<PyAny>>,
    out: Option<PathBuf>,
) -> PyResult<Returned<'py>> {
    let out = out.as_deref();
    let handle = scene.get();
    let mut observer = PyProgress::new(progress);
    let settings = an::ParameterSweepSettings {
        parameter,
        from: start,
        to,
        points: points_in_range("points", points, 2)?,
        stability,
        overrides: overrides(None, harmonics, samples, None, formulation)?,
        dofs,
        cancel: observer.cancel.clone(),
    };
    // Every value's scene is built from the document, inside this analysis's failure scope.
    let p = handle.prepare(py, &settings.overrides)?;
    p.slot.stops(&observer.cancel);
    let (doc, file) = (&handle.document, handle.file.as_str());
    an::check_parameter_sweep(doc, file, &settings).map_err(|e| p.error(py, e))?;
    // The DOF names of the scene make the file names.
    let files =
        render::parameter_sweep_files(p.scene.model.dof_names()).map_err(|e| p.error(py, e))?;
    crate::out::prepare(py, &p, out, &files)?;
    let result = timed(py, || {
        an::parameter_sweep(doc, file, &settings, &mut observer)
    });
    if let Some(e) = p.slot.take() {
        return Err(e);
    }
    observer.raise()?;
    let write = |a: &_, dir: &Path, w: &mut _| render::write_parameter_sweep_files(dir, a, w);
    finish(py, &p, result, |a| a.exit_code(), out, write)
}

/// Natural frequencies and mode shapes about the periodic solution, critical speeds
/// (`hbal modes`).
#[pyfunction]
#[pyo3(signature = (scene, *, start=None, to=None, max_hz=None, formulation=None, out=None))]
pub fn modes<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SceneHandle>,
    start: Option<f64>,
    to: Option<f64>,
    max_hz: Option<f64>,
    formulation: Option<&str>,
    out: Option<PathBuf>,
) -> PyResult<Returned<'py>> {
    let out = out.as_deref();
    let settings = an::ModesSettings {
        from: start,
        to,
        max_hz,
        formulation: formulation_of(formulation)?,
    };
    let p = scene
        .get()
        .prepare(py, &crate::scene::command_line_defaults())?;
    let s: &hbal::scene::Scene = &p.scene;
    crate::out::prepare(py, &p, out, &render::modes_files())?;
    let result = timed(py, || an::modes(s, &settings));
    let write = |a: &_, dir: &Path, w: &mut _| render::write_modes_files(dir, s, a, w).map(|_| ());
    finish(py, &p, result, an::ModesAnalysis::exit_code, out, write)
}

/// Every solver (or those of `methods`) and the time-domain reference (`hbal compare`).
#[pyfunction]
#[pyo3(signature = (scene, *, methods=None, harmonics=None, samples=None, tolerance=None,
    formulation=None, out=None))]
#[allow(clippy::too_many_arguments)]
pub fn compare<'py>(
    py: Python<'py>,
    scene: &Bound<'py, SceneHandle>,
    methods: Option<Vec<String>>,
    harmonics: Option<&Bound<'py, PyAny>>,
    samples: Option<usize>,
    tolerance: Option<f64>,
    formulation: Option<&str>,
    out: Option<PathBuf>,
) -> PyResult<Returned<'py>> {
    let out = out.as_deref();
    let o = overrides(None, harmonics, samples, None, formulation)?;
    if let Some(t) = tolerance {
        hbal::scene::check_tolerance(t).map_err(|e| crate::options::invalid("tolerance", e))?;
    }
    let p = scene.get().prepare(py, &o)?;
    let s: &hbal::scene::Scene = &p.scene;
    let settings = an::CompareSettings {
        methods,
        tolerance,
        formulation: o.formulation,
    };
    crate::out::prepare(py, &p, out, &render::compare_files())?;
    let result = timed(py, || an::compare(s, &settings));
    let write = |a: &_, dir: &Path, w: &mut _| render::write_compare_files(dir, a, w);
    finish(py, &p, result, |a| a.exit_code(), out, write)
}

/// Checks the scene as a solve would before its first iteration (`hbal check`).
#[pyfunction]
pub fn check(py: Python<'_>, scene: &Bound<'_, SceneHandle>) -> PyResult<()> {
    let p = scene
        .get()
        .prepare(py, &crate::scene::command_line_defaults())?;
    let s: &hbal::scene::Scene = &p.scene;
    py.detach(|| an::check(s)).map_err(|e| p.error(py, e))?;
    p.slot.take().map_or(Ok(()), Err)
}

/// Limits the threads of the analyses started on the calling thread (`hbal::limit_threads_here`):
/// a study's task sets 1, so that every analysis keeps to its core; returns the limit before.
#[pyfunction]
#[pyo3(signature = (limit=None))]
pub fn limit_threads_here(limit: Option<usize>) -> Option<usize> {
    hbal::limit_threads_here(limit)
}
