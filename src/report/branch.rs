//! Branch reports: CSV and the frequency-response plot (stable solid, unstable dashed, folds
//! marked).

use super::csv_number;
use super::{line_plot, Axis, Series};
use crate::continuation::Branch;
use std::path::Path;

/// CSV of a branch: parameter, stability, fold and bifurcation marks, `max|q|` per DOF, the
/// amplitude `|Q_k|` of every DOF and order, the Floquet multipliers' moduli (`;`-separated,
/// empty without stability), then the point's relative residual, its truncation estimate, the
/// interpolated fold position (empty unless the point closes a fold) and whether a turning
/// point of the discretised branch ends here that the multipliers do not confirm
/// (`spurious_turn`), the located position of a bifurcation other than a fold (empty
/// unless the point closes one) and the point's error estimates, of the periodic solution and
/// of its harmonics 0..H (empty if not computed). `parameter(p)` maps the point's swept parameter and the fold position to
/// the parameter's unit (e.g. Ω to rpm). The amplitude columns `amp_<dof>_k<k>_order_<o>` name
/// the harmonic k and its order o = k/ν of the fundamental (ν the branch's period multiple);
/// [`branch_csv_orders`] states the fundamental's order of a reference shaft.
pub fn branch_csv(branch: &Branch, parameter_name: &str, parameter: impl Fn(f64) -> f64) -> String {
    branch_csv_orders(branch, 1.0, parameter_name, parameter)
}

/// [`branch_csv`] with harmonic k named as order `k · fundamental_order / ν` of the reference
/// shaft.
pub fn branch_csv_orders(
    branch: &Branch,
    fundamental_order: f64,
    parameter_name: &str,
    parameter: impl Fn(f64) -> f64,
) -> String {
    let every: Vec<usize> = (0..branch.dofs.len()).collect();
    branch_csv_of_dofs(branch, fundamental_order, &every, parameter_name, parameter)
}

/// [`branch_csv_orders`] with the amplitudes of the DOFs `amplitudes` only (indices into
/// `branch.dofs`; `max|q|` of every DOF): `hbal sweep --dofs`.
pub fn branch_csv_of_dofs(
    branch: &Branch,
    fundamental_order: f64,
    amplitudes: &[usize],
    parameter_name: &str,
    parameter: impl Fn(f64) -> f64,
) -> String {
    let nu = branch.subharmonic.max(1) as f64;
    let mut header: Vec<String> = [parameter_name, "stable", "fold", "bifurcation"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    header.extend(branch.dofs.iter().map(|d| format!("max_abs_{d}")));
    for d in amplitudes.iter().filter_map(|&i| branch.dofs.get(i)) {
        header.extend(
            (0..=branch.harmonics)
                .map(|k| format!("amp_{d}_k{k}_order_{}", k as f64 * fundamental_order / nu)),
        );
    }
    header.extend(
        [
            "multipliers_abs",
            "residual",
            "truncation",
            "fold_speed",
            "spurious_turn",
            "bifurcation_speed",
            "error_estimate",
            "error_estimate_harmonics",
        ]
        .iter()
        .map(|s| s.to_string()),
    );
    // The csv writer quotes a field that needs it (a DOF name with a comma or a quote).
    let mut w = csv::Writer::from_writer(Vec::new());
    let _ = w.write_record(&header);
    let n = branch.dofs.len();
    for p in &branch.points {
        let stable = match p.stable() {
            Some(true) => "stable",
            Some(false) => "unstable",
            None => "",
        };
        let mut row = vec![
            csv_number(parameter(p.parameter)),
            stable.to_string(),
            p.fold.to_string(),
            p.bifurcation.map(|b| format!("{b:?}")).unwrap_or_default(),
        ];
        row.extend(p.max_abs.iter().map(|m| csv_number(*m)));
        for &i in amplitudes.iter().filter(|&&i| i < n) {
            row.extend((0..=branch.harmonics).map(|k| csv_number(p.harmonics[k * n + i].norm())));
        }
        let mult: Vec<String> = p
            .floquet
            .iter()
            .flat_map(|f| f.multipliers.iter().map(|m| format!("{:.6e}", m.norm())))
            .collect();
        row.push(mult.join(";"));
        row.push(csv_number(p.residual));
        row.push(csv_number(p.truncation));
        row.push(match (p.fold, p.fold_omega) {
            (true, Some(w)) => csv_number(parameter(w)),
            _ => String::new(),
        });
        row.push(p.spurious_turn.to_string());
        row.push(
            p.bifurcation_omega
                .map(|w| csv_number(parameter(w)))
                .unwrap_or_default(),
        );
        for e in [p.error_estimate, p.error_estimate_harmonics] {
            row.push(e.map(csv_number).unwrap_or_default());
        }
        let _ = w.write_record(&row);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

/// The frequency-response plot of `max|q_dof|`: stable parts solid, unstable parts dashed,
/// folds as markers.
pub fn branch_plot(
    path: &Path,
    branch: &Branch,
    dof: usize,
    title: &str,
    x_label: &str,
    parameter: impl Fn(f64) -> f64,
) -> Result<(), Box<dyn std::error::Error>> {
    branches_plot(path, &[branch], dof, title, x_label, parameter)
}

/// The frequency-response plot of several branches (the first the main one, the others
/// switched from it): one colour per branch, stable parts solid, unstable parts dashed, folds
/// and the points where the switched branches leave as markers.
pub fn branches_plot(
    path: &Path,
    branches: &[&Branch],
    dof: usize,
    title: &str,
    x_label: &str,
    parameter: impl Fn(f64) -> f64,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut series: Vec<Series> = Vec::new();
    let mut folds: Vec<(f64, f64)> = Vec::new();
    let mut switches: Vec<(f64, f64)> = Vec::new();
    for (index, branch) in branches.iter().enumerate() {
        let name = match (&branch.origin, branch.subharmonic) {
            (None, _) => String::new(),
            (Some(_), nu) if nu > 1 => format!("period {nu}T, "),
            (Some(o), _) => format!("branch {}, ", if o.side < 0 { "-" } else { "+" }),
        };
        // Colours: the main branch 0 (stable) and 1 (unstable); switched branches 3, 4, ...
        let colors = if index == 0 {
            (0, 1)
        } else {
            (2 + index, 2 + index)
        };
        let (mut said_stable, mut said_unstable) = (false, false);
        let mut flush = |pts: Vec<(f64, f64)>, stable: Option<bool>, series: &mut Vec<Series>| {
            if pts.len() < 2 {
                return;
            }
            let s = match stable {
                Some(false) => {
                    let label = if said_unstable {
                        String::new()
                    } else {
                        format!("{name}unstable")
                    };
                    said_unstable = true;
                    Series::dashed(label, pts).with_color(colors.1)
                }
                _ => {
                    let label = if said_stable {
                        String::new()
                    } else {
                        format!("{name}stable")
                    };
                    said_stable = true;
                    Series::line(label, pts).with_color(colors.0)
                }
            };
            series.push(s);
        };
        let mut current: Vec<(f64, f64)> = Vec::new();
        let mut current_stable = None;
        // A switched branch starts at its bifurcation on the parent.
        if let Some(o) = branch.origin.as_ref().filter(|o| o.max_abs.len() > dof) {
            let at = (parameter(o.omega), o.max_abs[dof]);
            current.push(at);
            switches.push(at);
        }
        for p in &branch.points {
            let xy = (parameter(p.parameter), p.max_abs[dof]);
            let st = p.stable();
            if current_stable.is_some() && st != current_stable {
                // Close the segment at this point so the curve stays connected.
                current.push(xy);
                flush(std::mem::take(&mut current), current_stable, &mut series);
            }
            current_stable = st;
            current.push(xy);
        }
        flush(current, current_stable, &mut series);
        folds.extend(
            branch
                .points
                .iter()
                .filter(|p| p.fold)
                .map(|p| (parameter(p.parameter), p.max_abs[dof])),
        );
    }
    if !folds.is_empty() {
        series.push(Series::markers("fold", folds).with_color(2));
    }
    if !switches.is_empty() {
        series.push(Series::markers("branch point / period doubling", switches).with_color(3));
    }
    line_plot(
        path,
        title,
        &Axis::linear(x_label),
        &Axis::linear(format!("max |{}| (rad or m)", branches[0].dofs[dof])),
        &series,
    )
}
