//! The files of a solve (`hbal solve --out DIR`): `harmonics.csv` (every harmonic by index and
//! shaft order), `elements.csv` (every element's coordinate `u` and force `f`),
//! `time_series.csv` over one period, and the plots `time_series.svg` and `spectrum.svg` of the
//! DOFs that move most. The files of an unconverged iterate say so in their names
//! (`not_converged_...`) and plot titles.

use super::{cannot_write, speed_text};
use crate::analysis::{order_of, SolveAnalysis};
use crate::error::Result;
use crate::report::csv_number;
use crate::report::{line_plot, Axis, ElementOutput, Series};
use crate::scene::Scene;
use crate::Solution;
use std::path::Path;

/// The plots' title (scene, speed, status) and the file-name prefix of an unconverged solve.
struct OutputLabel {
    title: String,
    prefix: &'static str,
}

/// Writes the files of `a` (a solve of `scene`) into `dir`; returns the names written. A plot
/// that cannot be drawn is a warning in `warnings`.
///
/// ```
/// use hbal::analysis::{solve, SolveSettings};
/// let scene = hbal::scene::Scene::load(std::path::Path::new("examples/scenes/duffing.toml")).unwrap();
/// let a = solve(&scene, &SolveSettings::default()).unwrap();
/// let dir = std::env::temp_dir().join(format!("hbal-doc-solve-{}", std::process::id()));
/// let mut warnings = Vec::new();
/// let written = hbal::render::write_solve_files(&scene, &a, &dir, &mut warnings).unwrap();
/// assert_eq!(written[..3], ["harmonics.csv", "elements.csv", "time_series.csv"]);
/// assert!(dir.join("spectrum.svg").exists() && warnings.is_empty());
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_solve_files(
    scene: &Scene,
    a: &SolveAnalysis,
    dir: &Path,
    warnings: &mut Vec<String>,
) -> Result<Vec<String>> {
    let sol = &a.solution;
    let order = |k| order_of(k, scene.fundamental_order, sol.basis().subharmonic());
    let prefix = if sol.is_converged() {
        ""
    } else {
        "not_converged_"
    };
    let label = OutputLabel {
        title: format!(
            "{} at {} {}{}",
            scene.file,
            speed_text(sol.basis().omega() / scene.omega_per_speed),
            scene.speed_unit,
            if sol.is_converged() {
                String::new()
            } else {
                format!(" - NOT CONVERGED ({})", sol.termination)
            }
        ),
        prefix,
    };
    // The exact method's closed form resolves the fastest natural motion (at 60 rpm the
    // two-shaft model's ringing after every jump, which the harmonics 0..32 do not hold);
    // not for a period multiple ν > 1 (the files span ν excitation periods).
    let series = a.exact.as_ref().and_then(|exact| {
        let basis = exact.solution.basis();
        (basis.subharmonic() == 1)
            .then(|| exact.time_series(exact.resolving_points().max(basis.samples())))
    });
    let mut written = write_outputs(dir, sol, &label, order, series, warnings)
        .map_err(|e| cannot_write(dir, e))?;
    if let Ok(e) = &a.elements {
        element_csv(&dir.join(format!("{prefix}elements.csv")), e, order)
            .map_err(|e| cannot_write(dir, e))?;
        written.insert(1, format!("{prefix}elements.csv"));
    }
    Ok(written)
}

/// `elements.csv`: `element,quantity,harmonic,shaft_order,cos,sin` for the coordinate `u` and
/// the force `f` of every element (quoted where a name needs it); `order(k)` is harmonic k's
/// order of the scene's reference speed.
pub fn element_csv(
    path: &Path,
    outputs: &[ElementOutput],
    order: impl Fn(usize) -> f64,
) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    w.write_record([
        "element",
        "quantity",
        "harmonic",
        "shaft_order",
        "cos",
        "sin",
    ])?;
    for e in outputs {
        for (quantity, s) in [("u", &e.coordinate), ("f", &e.force)] {
            for (k, x) in s.harmonics.iter().enumerate() {
                let (c, sn) = crate::harmonic::cos_sin(*x);
                w.write_record([
                    e.name.clone(),
                    quantity.to_string(),
                    k.to_string(),
                    format!("{}", order(k)),
                    csv_number(c),
                    csv_number(sn),
                ])?;
            }
        }
    }
    w.flush()?;
    Ok(())
}

/// Writes harmonics.csv, time_series.csv and the plots of `sol` into `dir`; the time series
/// is `series` (`[dof][sample]` over one period) where given (the exact method's closed
/// form), else synthesised from the harmonics.
fn write_outputs(
    dir: &Path,
    sol: &Solution,
    label: &OutputLabel,
    order: impl Fn(usize) -> f64,
    series: Option<Vec<Vec<f64>>>,
    warnings: &mut Vec<String>,
) -> anyhow::Result<Vec<String>> {
    std::fs::create_dir_all(dir)?;
    let file = |name: &str| dir.join(format!("{}{name}", label.prefix));
    harmonics_csv(&file("harmonics.csv"), sol, &order)?;
    let series: Vec<Vec<f64>> = series.unwrap_or_else(|| {
        let points = sol.basis().samples().max(256);
        (0..sol.dof_names().len())
            .map(|i| sol.time_series(i, points))
            .collect()
    });
    time_series_csv(&file("time_series.csv"), sol, &series)?;
    let mut written = vec![
        format!("{}harmonics.csv", label.prefix),
        format!("{}time_series.csv", label.prefix),
    ];
    // A plot that cannot be drawn is a warning: the solve and its CSV files stand.
    let mut plotted =
        |name: &str, result: std::result::Result<(), Box<dyn std::error::Error>>| match result {
            Ok(()) => written.push(format!("{}{name}", label.prefix)),
            Err(e) => warnings.push(format!("{name}: {e}")),
        };
    let (shown, note) = plotted_dofs(sol, sol.basis().harmonics());
    let title = format!("{}: one period{note}", label.title);
    let plot = time_series_plot(&file("time_series.svg"), sol, &series, &shown, &title);
    plotted("time_series.svg", plot);
    let title = format!(
        "{}: amplitude spectrum (static part omitted){note}",
        label.title
    );
    if let Some(plot) = spectrum_plot(&file("spectrum.svg"), sol, &shown, &title, &order) {
        plotted("spectrum.svg", plot);
    }
    Ok(written)
}

/// `harmonics.csv`: every DOF's cos and sin of every harmonic with its shaft order.
fn harmonics_csv(path: &Path, sol: &Solution, order: impl Fn(usize) -> f64) -> anyhow::Result<()> {
    // CSV through the csv writer: a DOF name with a comma or a quote is quoted.
    let mut w = csv::Writer::from_path(path)?;
    w.write_record(["dof", "harmonic", "shaft_order", "cos", "sin"])?;
    for (i, name) in sol.dof_names().iter().enumerate() {
        for k in 0..=sol.basis().harmonics() {
            let (c, s) = sol.cos_sin(i, k);
            let row = [
                name.clone(),
                k.to_string(),
                order(k).to_string(),
                csv_number(c),
                csv_number(s),
            ];
            w.write_record(row)?;
        }
    }
    Ok(w.flush()?)
}

/// `time_series.csv`: t, θ and every DOF's `series` over one period.
fn time_series_csv(path: &Path, sol: &Solution, series: &[Vec<f64>]) -> anyhow::Result<()> {
    let period = sol.basis().period();
    let points = series.first().map_or(0, Vec::len);
    let mut w = csv::Writer::from_path(path)?;
    let mut header = vec!["t".to_string(), "theta".to_string()];
    header.extend(sol.dof_names().iter().cloned());
    w.write_record(&header)?;
    for j in 0..points {
        let frac = j as f64 / points as f64;
        let mut row = vec![
            csv_number(frac * period),
            csv_number(frac * std::f64::consts::TAU),
        ];
        row.extend(series.iter().map(|s| csv_number(s[j])));
        w.write_record(&row)?;
    }
    Ok(w.flush()?)
}

/// The time series of the `shown` DOFs over one period.
fn time_series_plot(
    path: &Path,
    sol: &Solution,
    series: &[Vec<f64>],
    shown: &[usize],
    title: &str,
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let period = sol.basis().period();
    let points = series.first().map_or(0, Vec::len);
    let names = sol.dof_names();
    let lines: Vec<Series> = shown
        .iter()
        .map(|&i| {
            let s = series[i].iter().enumerate();
            let xy = s
                .map(|(j, v)| (j as f64 / points as f64 * period, *v))
                .collect();
            Series::line(names[i].clone(), xy)
        })
        .collect();
    let (x, y) = (Axis::linear("t (s)"), Axis::linear("q (rad or m)"));
    line_plot(path, title, &x, &y, &lines)
}

/// The amplitude spectrum of the `shown` DOFs over the order of the reference shaft
/// (`order(k)` of harmonic k: the engine order where the scene's speed is the crankshaft's);
/// `None` for a static solution (every harmonic k >= 1 zero), which has none.
fn spectrum_plot(
    path: &Path,
    sol: &Solution,
    shown: &[usize],
    title: &str,
    order: &dyn Fn(usize) -> f64,
) -> Option<std::result::Result<(), Box<dyn std::error::Error>>> {
    let h = sol.basis().harmonics();
    // Amplitudes below 1e-13 of the largest are rounding noise: left out.
    let largest = shown
        .iter()
        .flat_map(|&i| (1..=h).map(move |k| sol.harmonic(i, k).norm()))
        .fold(0.0f64, f64::max);
    if h == 0 || largest <= 0.0 {
        return None;
    }
    let spectra: Vec<Series> = shown
        .iter()
        .map(|&i| {
            let ks = (1..=h).map(|k| (order(k), sol.harmonic(i, k).norm()));
            Series::markers(
                sol.dof_names()[i].clone(),
                ks.filter(|&(_, a)| a > 1e-13 * largest).collect(),
            )
        })
        .collect();
    let x = Axis::linear("order of the reference shaft");
    let y = Axis::log("|q_k| (rad or m)");
    Some(line_plot(path, title, &x, &y, &spectra))
}

/// Most DOFs a plot shows (a legend of a thousand names hides the data).
const MAX_PLOTTED_DOFS: usize = 8;

/// The DOFs the plots show: all of a small model, else the [`MAX_PLOTTED_DOFS`] with the
/// largest dynamic amplitude `Σ_{k≥1} |q̂_k|`, in model order, and a note for the title.
fn plotted_dofs(sol: &Solution, h: usize) -> (Vec<usize>, String) {
    let n = sol.dof_names().len();
    if n <= MAX_PLOTTED_DOFS {
        return ((0..n).collect(), String::new());
    }
    let amplitude = |i: usize| (1..=h).map(|k| sol.harmonic(i, k).norm()).sum::<f64>();
    let mut order: Vec<(usize, f64)> = (0..n).map(|i| (i, amplitude(i))).collect();
    order.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut shown: Vec<usize> = order.iter().take(MAX_PLOTTED_DOFS).map(|p| p.0).collect();
    shown.sort_unstable();
    (
        shown,
        format!(" ({MAX_PLOTTED_DOFS} of {n} DOFs: the largest dynamic amplitudes)"),
    )
}
