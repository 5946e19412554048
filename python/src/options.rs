//! The command line's options as the analyses take them from Python: the solver overrides,
//! the formulation, point counts, the stability orbit and a start from a previous result.
//! Each problem is an `InputError` naming the option.

use crate::errors::InputError;
use hbal::analysis as an;
use hbal::scene::{HarmonicsOverride, Overrides};
use hbal::Formulation;
use pyo3::prelude::*;

/// The most points of a sweep (as `--points`, `--max-points` of the command line).
pub const MAX_SWEEP_POINTS: usize = 100_000;

pub fn invalid(option: &str, reason: impl std::fmt::Display) -> PyErr {
    InputError::new_err(format!("{option}: {reason}"))
}

/// The solver overrides (`--method`, `--harmonics`, `--samples`, `--tolerance`,
/// `--formulation`), applied to the scene where it is built (which checks them).
pub fn overrides(
    method: Option<String>,
    harmonics: Option<&Bound<'_, PyAny>>,
    samples: Option<usize>,
    tolerance: Option<f64>,
    formulation: Option<&str>,
) -> PyResult<Overrides> {
    let harmonics = harmonics
        .map(|h| -> PyResult<HarmonicsOverride> {
            let text = h.str()?.to_string();
            text.parse().map_err(|e| invalid("harmonics", e))
        })
        .transpose()?;
    if let Some(t) = tolerance {
        hbal::scene::check_tolerance(t).map_err(|e| invalid("tolerance", e))?;
    }
    Ok(Overrides {
        method,
        harmonics,
        samples,
        tolerance,
        formulation: formulation_of(formulation)?,
    })
}

pub fn formulation_of(name: Option<&str>) -> PyResult<Formulation> {
    name.unwrap_or("auto")
        .parse()
        .map_err(|e| invalid("formulation", e))
}

/// A point count from `min` to [`MAX_SWEEP_POINTS`].
pub fn points_in_range(option: &str, n: usize, min: usize) -> PyResult<usize> {
    if (min..=MAX_SWEEP_POINTS).contains(&n) {
        Ok(n)
    } else {
        Err(invalid(
            option,
            format!("must be {min} to {MAX_SWEEP_POINTS}, got {n}"),
        ))
    }
}

/// `exact` or `harmonic` (`--stability-orbit`).
pub fn orbit_of(name: &str) -> PyResult<hbal::stability::Orbit> {
    match name {
        "exact" => Ok(hbal::stability::Orbit::Exact),
        "harmonic" => Ok(hbal::stability::Orbit::Harmonic),
        other => Err(invalid(
            "stability_orbit",
            format!("expected `exact` or `harmonic`, got `{other}`"),
        )),
    }
}

/// The initial guess of a solve's record (`--start FILE`; `guess=` a result or its record).
pub fn start_of(
    guess: Option<&Bound<'_, PyAny>>,
    scene: &hbal::scene::Scene,
) -> PyResult<Option<an::StartRecord>> {
    let Some(g) = guess else { return Ok(None) };
    let record = if g.hasattr("record")? {
        g.getattr("record")?
    } else {
        g.clone()
    };
    let value = crate::value::to_value(&record, "guess")?;
    an::start_from_record(&value, scene).map(Some).map_err(|e| {
        invalid(
            "guess",
            format!("{e} (expected a solve's result or its record)"),
        )
    })
}

/// Refuses the options of `given` that are set: they apply to one fundamental only.
pub fn refuse_on_torus(given: &[(&str, bool)]) -> PyResult<()> {
    match given.iter().find(|g| g.1) {
        Some((name, _)) => Err(invalid(
            name,
            "applies to one fundamental; this scene is solved on several base frequencies",
        )),
        None => Ok(()),
    }
}
