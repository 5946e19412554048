//! Order cuts of a speed sweep: for every point of the branch, the amplitude and phase of each
//! excitation order (the scene's load orders and mesh orders, as multiples of the reference
//! speed) of the reported DOFs (`--dofs`, [`crate::analysis::reported_dofs`]) and every element
//! coordinate, and the fraction of the
//! period each contact spends open: `order_cuts.csv`; for one chosen output (`--output`, by
//! default the first gear stage's transmission error, else the DOF that moves most) the order
//! cuts `order_cuts.svg` and the waterfall of its spectrum over speed `waterfall.svg`.

use crate::analysis::{Shown, SweepAnalysis};
use crate::continuation::{Branch, BranchPoint};
use crate::report::csv_number;
use crate::report::{line_plot, waterfall_plot, Axis, ElementOutput, Series, Slice, Waterfall};
use crate::scene::Scene;
use std::path::Path;

/// What `shown` is on `branch`: a function from (point, its element outputs, harmonic k) to
/// the amplitude, its name and unit.
#[allow(clippy::type_complexity)]
fn shown_amplitude<'a>(
    scene: &'a Scene,
    branch: &'a Branch,
    shown: Shown,
) -> (
    Box<dyn Fn(&BranchPoint, &[ElementOutput], usize) -> f64 + 'a>,
    String,
    &'static str,
) {
    let n = branch.dofs.len();
    let dof = |i: usize| -> (
        Box<dyn Fn(&BranchPoint, &[ElementOutput], usize) -> f64>,
        String,
    ) {
        (
            Box::new(move |p: &BranchPoint, _: &[ElementOutput], k: usize| {
                p.harmonics[k * n + i].norm()
            }),
            format!("DOF {}", branch.dofs[i]),
        )
    };
    match shown {
        Shown::Element(s) => {
            let e = &scene.model.elements()[s];
            match e.gear_stage() {
                Some(stage) => (
                    Box::new(move |_, o: &[ElementOutput], k| {
                        1e6 * o[s].coordinate.harmonics[k].norm()
                    }),
                    format!("transmission error of {}", e.name()),
                    if stage.base_radii.is_some() {
                        "µm"
                    } else {
                        "µrad"
                    },
                ),
                None => (
                    Box::new(move |_, o: &[ElementOutput], k| o[s].coordinate.harmonics[k].norm()),
                    format!("coordinate of {}", e.name()),
                    "m or rad",
                ),
            }
        }
        Shown::Dof(i) => {
            let (f, name) = dof(i);
            (f, name, "rad or m")
        }
        Shown::LargestDof => {
            let moves = |i: usize| {
                branch
                    .points
                    .iter()
                    .map(|p| {
                        (1..=branch.harmonics)
                            .map(|k| p.harmonics[k * n + i].norm())
                            .sum::<f64>()
                    })
                    .fold(0.0f64, f64::max)
            };
            let top = (0..n)
                .max_by(|&a, &b| moves(a).total_cmp(&moves(b)))
                .unwrap_or(0);
            let (f, name) = dof(top);
            (f, format!("largest response ({name})"), "rad or m")
        }
    }
}

/// Writes `order_cuts.csv`, `order_cuts.svg` and `waterfall.svg` of the sweep `a` into `dir`:
/// columns for the reported DOFs (and every element), the plots of the shown output.
pub(super) fn write(
    dir: &Path,
    scene: &Scene,
    a: &SweepAnalysis,
    warnings: &mut Vec<String>,
) -> anyhow::Result<()> {
    let (branch, basis, outputs) = (&a.branch, &a.basis, &a.outputs[..]);
    let speed = |w: f64| a.speed(w);
    let orders = crate::analysis::excitation_orders(scene, basis);
    csv_of(
        &dir.join("order_cuts.csv"),
        scene,
        branch,
        outputs,
        &a.reported,
        &orders,
        speed,
    )?;
    let (amplitude, what, unit) = shown_amplitude(scene, branch, a.shown);
    let title = |kind: &str| format!("{kind} of the {what}: {}", scene.file);
    let speed_axis = format!("speed ({})", scene.speed_unit);
    let points = || branch.points.iter().zip(outputs);
    if branch.points.len() < 2 {
        return Ok(());
    }
    let series: Vec<Series> = orders
        .iter()
        .map(|&(o, k)| {
            let curve = points().map(|(p, out)| (speed(p.omega), amplitude(p, out, k)));
            Series::line(format!("order {o}"), curve.collect())
        })
        .collect();
    if !series.is_empty() {
        let y = Axis::auto(format!("amplitude ({unit})"));
        let plot = line_plot(
            &dir.join("order_cuts.svg"),
            &title("Order cuts"),
            &Axis::linear(&speed_axis),
            &y,
            &series,
        );
        super::plot_warning(warnings, plot);
    }
    // The waterfall's orders: up to twice the highest excitation harmonic (at least 4).
    let top_k = orders.iter().map(|o| o.1).max().unwrap_or(1);
    let stems = (2 * top_k).max(4).min(branch.harmonics);
    let order_of =
        |k: usize| crate::analysis::order_of(k, scene.fundamental_order, basis.subharmonic());
    let slices: Vec<Slice> = points()
        .map(|(p, out)| Slice {
            speed: speed(p.omega),
            amplitudes: (1..=stems)
                .map(|k| (order_of(k), amplitude(p, out, k)))
                .collect(),
        })
        .collect();
    if stems > 0 {
        let highlight: Vec<f64> = orders.iter().map(|o| o.0).collect();
        let waterfall = Waterfall {
            title: &title("Waterfall"),
            speed_label: &speed_axis,
            unit,
            range_db: 60.0,
            highlight: &highlight,
        };
        let plot = waterfall_plot(&dir.join("waterfall.svg"), &waterfall, &slices);
        super::plot_warning(warnings, plot);
    }
    Ok(())
}

/// `order_cuts.csv`: at every point the amplitude and phase of each excitation order of the
/// `dofs` and every element coordinate, and the open fraction of every contact.
fn csv_of(
    path: &Path,
    scene: &Scene,
    branch: &Branch,
    outputs: &[Vec<ElementOutput>],
    dofs: &[usize],
    orders: &[(f64, usize)],
    speed: impl Fn(f64) -> f64,
) -> anyhow::Result<()> {
    let n = branch.dofs.len();
    let mut w = csv::Writer::from_path(path)?;
    let mut header = vec![scene.speed_unit.to_string()];
    let dof_columns = dofs.len();
    let elements = scene.model.elements();
    let names: Vec<String> = dofs
        .iter()
        .map(|&i| branch.dofs[i].clone())
        .chain(elements.iter().map(|e| format!("u({})", e.name())))
        .collect();
    for name in &names {
        for (o, _) in orders {
            header.push(format!("amp_{name}_order_{o}"));
            header.push(format!("phase_deg_{name}_order_{o}"));
        }
    }
    let contacts: Vec<usize> = (0..elements.len())
        .filter(|&i| !elements[i].law().kinks().is_empty())
        .collect();
    header.extend(
        contacts
            .iter()
            .map(|&i| format!("open_{}", elements[i].name())),
    );
    w.write_record(&header)?;
    for (p, outputs) in branch.points.iter().zip(outputs) {
        let mut row = vec![csv_number(speed(p.omega))];
        let harmonic_of = |name: usize, k: usize| {
            if name < dof_columns {
                p.harmonics[k * n + dofs[name]]
            } else {
                outputs[name - dof_columns].coordinate.harmonics[k]
            }
        };
        for name in 0..names.len() {
            for &(_, k) in orders {
                let x = harmonic_of(name, k);
                row.push(csv_number(x.norm()));
                // q = Re(Q e^{ikθ}) = |Q| cos(kθ + arg Q).
                row.push(csv_number(x.arg().to_degrees()));
            }
        }
        for &i in &contacts {
            let open = outputs[i].states.iter().find(|(s, _)| s == "open");
            row.push(open.map_or(String::new(), |(_, f)| csv_number(*f)));
        }
        w.write_record(&row)?;
    }
    Ok(w.flush()?)
}
