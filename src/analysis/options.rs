//! Checks of an analysis's options made once, before any work, the same way for every front
//! end and subcommand: a problem is bad input (`Error::InvalidOptions`, exit code 2), never a
//! failure found after a solve has run.

use crate::scene::Scene;
use crate::{Error, Result};

/// Checks the speed option `name` (`--from`, `--to`, in the scene's unit): finite, above 0 (or
/// 0 where `zero_allowed`), and its fundamental within 1e-100 to 1e100 rad/s.
///
/// ```
/// # use hbal::scene::Scene;
/// # let scene = Scene::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/duffing.toml"))).unwrap();
/// use hbal::analysis::check_speed;
/// assert!(check_speed(&scene, "--to", 2.0, false).is_ok());
/// assert!(check_speed(&scene, "--from", 0.0, true).is_ok());
/// for bad in [f64::NAN, f64::INFINITY, -1.0, 0.0, 1e300] {
///     let e = check_speed(&scene, "--to", bad, false).unwrap_err();
///     assert!(e.to_string().starts_with("--to must be a finite speed"), "{e}");
/// }
/// ```
pub fn check_speed(scene: &Scene, name: &str, value: f64, zero_allowed: bool) -> Result<()> {
    let fundamental = value * scene.omega_per_speed;
    let ok = value.is_finite()
        && ((zero_allowed && value == 0.0)
            || (value > 0.0 && crate::error::in_magnitude_range(fundamental)));
    if ok {
        return Ok(());
    }
    Err(Error::InvalidOptions {
        option: name.into(),
        reason: format!(
            "must be a finite speed {} ({}) whose fundamental is within 1e-100 to 1e100 rad/s, got {}",
            if zero_allowed { ">= 0" } else { "> 0" },
            scene.speed_unit,
            crate::report::significant(value, 6)
        ),
    })
}

/// Checks that a sweep of `scene` can start at `omega` (rad/s) with `formulation`: what a
/// solve at that speed would refuse as bad input (a load or mesh order above H, static loads
/// that do not balance, a singular static stiffness, a model too large for the dense
/// Jacobian the continuation's corrector uses, unless the model is linear time-invariant and
/// needs none) is refused before the sweep, not found at its first point. The exact piecewise method, which needs no harmonic balance, is not checked
/// here.
pub fn check_sweep_start(scene: &Scene, omega: f64, formulation: crate::Formulation) -> Result<()> {
    if matches!(scene.method, crate::solve::Method::PiecewiseExact(_)) {
        return Ok(());
    }
    let hb = harmonic_balance(scene, scene.basis.with_omega(omega)?, formulation)?;
    // A linear time-invariant model is swept by one solve per harmonic: no Jacobian.
    if scene.model.is_linear_time_invariant() {
        return Ok(());
    }
    crate::solve::check_dense_for_continuation(&hb)
}

/// Checks `scene` as a solve would before its first iteration (`hbal check`): its harmonic
/// balance builds at the scene's speed, with automatic harmonics at their first level (H
/// raised to the load and mesh orders).
/// Without an operating point (no `fundamental`, `harmonics`), only the model is checked.
/// A scene on several base frequencies builds its torus balance at its speed.
pub fn check(scene: &Scene) -> Result<()> {
    if !scene.operating_point {
        return Ok(());
    }
    if let Some(plan) = &scene.torus {
        let omega = plan.speed * plan.rad_s_per_speed;
        let tm = plan.bind(&scene.model)?;
        return crate::torus::TorusBalance::new(tm, plan.index_set()?, &plan.samples, omega)
            .map(|_| ());
    }
    harmonic_balance(scene, scene.basis, crate::Formulation::Auto).map(|_| ())
}

/// The natural frequencies of `scene`'s model for `hbal check`, where every law is linear in
/// the state (then they are the model's at every operating point; a nonlinear model's
/// depend on its orbit: `hbal modes`); `None` otherwise, above 300 DOFs, or where the
/// eigenproblem fails (a check does not fail on it).
pub fn linear_frequencies(scene: &Scene) -> Option<crate::report::NaturalFrequencies> {
    let model = &scene.model;
    let linear = model
        .elements()
        .iter()
        .all(|e| e.law().is_linear_in_state());
    if !linear || model.n_dofs() > 300 {
        return None;
    }
    let rest = vec![0.0; model.n_dofs()];
    crate::report::natural_frequencies_at(model, &rest, f64::INFINITY).ok()
}

/// The harmonic balance a solve of `scene` at `basis` starts with.
fn harmonic_balance(
    scene: &Scene,
    basis: crate::HarmonicBasis,
    formulation: crate::Formulation,
) -> Result<crate::HarmonicBalance<'_>> {
    let basis = match &scene.auto {
        Some(auto) => crate::solve::auto_first_basis(&scene.model, basis, auto)?,
        None => basis,
    };
    crate::HarmonicBalance::with_formulation(&scene.model, basis, formulation)
}
