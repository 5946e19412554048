//! `hbal check`: validate a scene (parse it and build its harmonic-balance system) without
//! solving, and print a one-line summary.

use super::{load, Failure};
use std::path::Path;

pub(crate) fn check(path: &Path) -> Result<u8, Failure> {
    let scene = load(path, &super::SolverArgs::default())?;
    hbal::analysis::check(&scene).map_err(|e| super::failure(e, &scene.file))?;
    say!(
        "{}: ok ({} DOF(s), {} element(s), Ω = {:.6} rad/s (order {} of the {} speed), H = {}, \
         N = {}, solver {})",
        scene.file,
        scene.model.n_dofs(),
        scene.model.elements().len(),
        scene.basis.omega(),
        scene.fundamental_order,
        scene.speed_unit,
        scene.basis.harmonics(),
        scene.basis.samples(),
        scene.method.name()
    );
    Ok(0)
}
