//! The files of a speed sweep (`hbal sweep --out DIR`): `branch.csv` (and `branch_1.csv`, ...
//! of the switched branches), the order cuts ([`super::order_cuts`]) and one
//! frequency-response SVG per reported DOF with every branch.

use super::{cannot_write, order_cuts};
use crate::analysis::SweepAnalysis;
use crate::continuation::{Branch, BranchStop};
use crate::error::Result;
use crate::scene::Scene;
use std::path::Path;

/// Writes the files of `a` (a sweep of `scene`) into `dir`. A plot that cannot be drawn is a
/// warning in `warnings`.
pub fn write_sweep_files(
    dir: &Path,
    scene: &Scene,
    a: &SweepAnalysis,
    warnings: &mut Vec<String>,
) -> Result<()> {
    write(dir, scene, a, warnings).map_err(|e| cannot_write(dir, e))
}

fn write(
    dir: &Path,
    scene: &Scene,
    a: &SweepAnalysis,
    warnings: &mut Vec<String>,
) -> anyhow::Result<()> {
    let speed = |w: f64| a.speed(w);
    let csv = |b: &Branch| {
        crate::report::branch_csv_of_dofs(b, a.fundamental_order, &a.reported, &a.unit, speed)
    };
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("branch.csv"), csv(&a.branch))?;
    order_cuts::write(dir, scene, a, warnings)?;
    for (i, b) in a.secondary.iter().enumerate() {
        std::fs::write(dir.join(format!("branch_{}.csv", i + 1)), csv(b))?;
    }
    if a.branch.points.len() < 2 {
        return Ok(());
    }
    let all: Vec<&Branch> = std::iter::once(&a.branch).chain(&a.secondary).collect();
    let stopped = match a.branch.stop {
        BranchStop::Reached => String::new(),
        ref stop => format!(" - STOPPED: {stop}"),
    };
    for &i in &a.reported {
        let dof = &a.branch.dofs[i];
        let plot = crate::report::branches_plot(
            &dir.join(format!("frequency_response_{dof}.svg")),
            &all,
            i,
            &format!("Frequency response of {dof}: {}{stopped}", a.file),
            &format!("speed ({})", a.unit),
            speed,
        );
        super::plot_warning(warnings, plot);
    }
    Ok(())
}
