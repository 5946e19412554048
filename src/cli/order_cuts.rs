//! Order cuts of a speed sweep: for every point of the branch, the amplitude and phase of each
//! excitation order (the scene's load orders and mesh orders, as multiples of the reference
//! speed) of every DOF (up to 50 DOFs) and every element coordinate, and the fraction of the period each
//! contact spends open: `order_cuts.csv`, and `order_cuts.svg` for the first gear stage's
//! transmission error (else the DOF that moves most).

use hbal::continuation::Branch;
use hbal::report::{element_outputs, line_plot, Axis, ElementOutput, Series};
use hbal::scene::Scene;
use hbal::{HarmonicBasis, Solution};
use std::path::Path;

/// Most DOFs with columns of their own in `order_cuts.csv`.
const MAX_DOF_COLUMNS: usize = 50;

/// Writes `order_cuts.csv` and `order_cuts.svg` for `branch` (computed on `basis`) into `dir`.
pub(crate) fn write(
    dir: &Path,
    scene: &Scene,
    branch: &Branch,
    basis: &HarmonicBasis,
    outputs: &[Vec<ElementOutput>],
    speed: impl Fn(f64) -> f64,
) -> anyhow::Result<()> {
    let orders = super::excitation_orders(scene, basis);
    let n = branch.dofs.len();
    let mut w = csv::Writer::from_path(dir.join("order_cuts.csv"))?;
    let mut header = vec![scene.speed_unit.to_string()];
    // Every DOF of a model of at most MAX_DOF_COLUMNS DOFs (a large model: its elements only).
    let dof_columns = if n <= MAX_DOF_COLUMNS { n } else { 0 };
    let names: Vec<String> = branch.dofs[..dof_columns]
        .iter()
        .cloned()
        .chain(
            scene
                .model
                .elements()
                .iter()
                .map(|e| format!("u({})", e.name())),
        )
        .collect();
    for name in &names {
        for (o, _) in &orders {
            header.push(format!("amp_{name}_order_{o}"));
            header.push(format!("phase_deg_{name}_order_{o}"));
        }
    }
    let contacts: Vec<usize> = (0..scene.model.elements().len())
        .filter(|&i| !scene.model.elements()[i].law().kinks().is_empty())
        .collect();
    for &i in &contacts {
        header.push(format!("open_{}", scene.model.elements()[i].name()));
    }
    w.write_record(&header)?;
    // The plotted output: the first gear stage's TE in µm, else the DOF that moves most.
    let stage = scene
        .model
        .elements()
        .iter()
        .position(|e| e.gear_stage().is_some());
    let mut curves: Vec<Vec<(f64, f64)>> = vec![Vec::new(); orders.len()];
    for (p, outputs) in branch.points.iter().zip(outputs) {
        let mut row = vec![format!("{:e}", speed(p.omega))];
        let harmonic_of = |name: usize, k: usize| {
            if name < dof_columns {
                p.harmonics[k * n + name]
            } else {
                outputs[name - dof_columns].coordinate.harmonics[k]
            }
        };
        for name in 0..names.len() {
            for &(_, k) in &orders {
                let x = harmonic_of(name, k);
                row.push(format!("{:e}", x.norm()));
                // q = Re(Q e^{ikθ}) = |Q| cos(kθ + arg Q).
                row.push(format!("{:e}", x.arg().to_degrees()));
            }
        }
        for &i in &contacts {
            let open = outputs[i]
                .states
                .iter()
                .find(|(s, _)| s == "open")
                .map_or(f64::NAN, |(_, f)| *f);
            row.push(if open.is_nan() {
                String::new()
            } else {
                format!("{open:e}")
            });
        }
        w.write_record(&row)?;
        for (c, &(_, k)) in curves.iter_mut().zip(&orders) {
            let a = match stage {
                Some(s) => 1e6 * outputs[s].coordinate.harmonics[k].norm(),
                None => {
                    let top = (0..n)
                        .max_by(|&a, &b| p.max_abs[a].total_cmp(&p.max_abs[b]))
                        .unwrap_or(0);
                    p.harmonics[k * n + top].norm()
                }
            };
            c.push((speed(p.omega), a));
        }
    }
    w.flush()?;
    let (what, unit) = match stage {
        Some(s) => (
            format!("transmission error of {}", scene.model.elements()[s].name()),
            "µm",
        ),
        None => ("largest response".to_string(), "rad or m"),
    };
    let series: Vec<Series> = curves
        .into_iter()
        .zip(&orders)
        .map(|(c, (o, _))| Series::line(format!("order {o}"), c))
        .collect();
    if branch.points.len() >= 2 && !series.is_empty() {
        line_plot(
            &dir.join("order_cuts.svg"),
            &format!("Order cuts of the {what}: {}", scene.file),
            &Axis::linear(format!("speed ({})", scene.speed_unit)),
            &Axis::log(format!("amplitude ({unit})")),
            &series,
        )
        .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    }
    Ok(())
}

/// A speed range over which a contact opens for part of the period.
#[derive(Debug, Clone, serde::Serialize)]
pub(crate) struct ContactLoss {
    pub(crate) element: String,
    pub(crate) from: f64,
    pub(crate) to: f64,
    /// The largest fraction of the period it is open.
    pub(crate) max_open: f64,
}

/// The ranges of consecutive points of `branch` where an element with an `open` state opens
/// (more than 0.1 % of the period), in the speed unit of `speed`.
pub(crate) fn contact_loss(
    scene: &Scene,
    branch: &Branch,
    outputs: &[Vec<ElementOutput>],
    speed: impl Fn(f64) -> f64,
) -> Vec<ContactLoss> {
    let has_open = |i: usize| {
        scene.model.elements()[i]
            .law()
            .state_names()
            .contains(&"open")
    };
    let contacts: Vec<usize> = (0..scene.model.elements().len())
        .filter(|&i| has_open(i))
        .collect();
    let mut out = Vec::new();
    if contacts.is_empty() {
        return out;
    }
    let mut open: Vec<Option<ContactLoss>> = vec![None; contacts.len()];
    for (p, outputs) in branch.points.iter().zip(outputs) {
        let s = speed(p.omega);
        for (slot, &i) in open.iter_mut().zip(&contacts) {
            let fraction = outputs[i]
                .states
                .iter()
                .find(|(n, _)| n == "open")
                .map_or(0.0, |(_, f)| *f);
            match (slot.as_mut(), fraction > 1e-3) {
                (Some(run), true) => {
                    run.from = run.from.min(s);
                    run.to = run.to.max(s);
                    run.max_open = run.max_open.max(fraction);
                }
                (None, true) => {
                    *slot = Some(ContactLoss {
                        element: outputs[i].name.clone(),
                        from: s,
                        to: s,
                        max_open: fraction,
                    })
                }
                (Some(_), false) => out.extend(slot.take()),
                (None, false) => {}
            }
        }
    }
    out.extend(open.into_iter().flatten());
    out
}

/// The element outputs of every point of `branch` (computed on `basis`), for the order cuts
/// and the contact-loss ranges.
pub(crate) fn point_outputs(
    scene: &Scene,
    branch: &Branch,
    basis: &HarmonicBasis,
) -> anyhow::Result<Vec<Vec<ElementOutput>>> {
    branch
        .points
        .iter()
        .map(|p| {
            let sol = Solution::from_harmonics(
                basis.with_omega(p.omega)?,
                branch.dofs.clone(),
                p.harmonics.clone(),
                p.residual,
            )?;
            Ok(element_outputs(&scene.model, &sol)?)
        })
        .collect()
}
