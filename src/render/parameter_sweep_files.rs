//! The files of a parameter sweep (`hbal sweep --parameter ... --out DIR`): `branch.csv` and
//! one parameter-response plot per reported DOF.

use super::cannot_write;
use crate::analysis::ParameterSweepAnalysis;
use crate::error::Result;
use std::path::Path;

/// The files a parameter sweep writes for a model with the DOFs `dofs` (their names checked
/// as parts of file names, [`super::file_name_part`]).
pub fn parameter_sweep_files(dofs: &[String]) -> Result<Vec<String>> {
    let mut files = vec!["branch.csv".to_string()];
    for dof in dofs {
        super::file_name_part(dof, "DOF")?;
        files.push(format!("parameter_response_{dof}.svg"));
    }
    Ok(files)
}

/// Writes `branch.csv` and the plots of `a` into `dir`. A plot that cannot be drawn is a
/// warning in `warnings`.
pub fn write_parameter_sweep_files(
    dir: &Path,
    a: &ParameterSweepAnalysis,
    warnings: &mut Vec<String>,
) -> Result<()> {
    write(dir, a, warnings).map_err(|e| cannot_write(dir, e))
}

fn write(dir: &Path, a: &ParameterSweepAnalysis, warnings: &mut Vec<String>) -> anyhow::Result<()> {
    let (branch, name) = (&a.branch, &a.settings.parameter);
    std::fs::create_dir_all(dir)?;
    let csv =
        crate::report::branch_csv_of_dofs(branch, a.fundamental_order, &a.reported, name, |p| p);
    std::fs::write(dir.join("branch.csv"), csv)?;
    if branch.points.len() < 2 {
        return Ok(());
    }
    for &i in &a.reported {
        let dof = &branch.dofs[i];
        let plot = crate::report::branch_plot(
            &dir.join(format!("parameter_response_{dof}.svg")),
            branch,
            i,
            &format!("Response of {dof} against {name}"),
            name,
            |p| p,
        );
        super::plot_warning(warnings, plot);
    }
    Ok(())
}
