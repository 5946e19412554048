//! `hbal solve` of a scene on several base frequencies ([`hbal::analysis::torus_solve`]): the
//! bases with their truncation estimates, the strongest labelled lines of every element
//! coordinate and force and each DOF's RMS, or the JSON; `--out` writes `lines.csv` (every
//! line of every DOF, element coordinate and element force) and `spectrum.svg`.

use super::Failure;
use anyhow::Context;
use hbal::analysis::{Spectrum, TorusSolveAnalysis, TorusSolveSettings};
use hbal::report::{line_plot, Axis, Series};
use hbal::scene::Scene;
use std::path::Path;

/// Lines printed per element in the summary.
const PRINTED_LINES: usize = 6;

/// The flags of `hbal solve` that have no meaning on the torus, refused by name.
pub(crate) fn refuse_flags(given: &[(&str, bool)]) -> Result<(), Failure> {
    match given.iter().find(|g| g.1) {
        Some((flag, _)) => Err(anyhow::anyhow!(
            "{flag} applies to scenes on one fundamental; this scene is solved on several base frequencies (the torus)"
        )
        .into()),
        None => Ok(()),
    }
}

/// Solves, prints and writes; the exit code of the analysis.
pub(crate) fn solve(scene: &Scene, json: bool, out: Option<&Path>) -> Result<u8, Failure> {
    if let Some(dir) = out {
        super::prepare_out(dir, &["lines.csv".into(), "spectrum.svg".into()])?;
    }
    let a = hbal::analysis::torus_solve(scene, &TorusSolveSettings::default())
        .map_err(|e| super::failure(e, &scene.file))?;
    if json {
        say!("{}", a.to_json());
    } else {
        print(scene, &a);
    }
    if let Some(dir) = out {
        write_files(dir, scene, &a)?;
        if !json {
            say!("  wrote lines.csv, spectrum.svg to {}", dir.display());
        }
    }
    if !a.converged {
        eprintln!(
            "error: {}: the solve did not converge (relative residual {:.1e})",
            scene.file, a.relative_residual
        );
    }
    if let Some(why) = &a.caps_stopped {
        eprintln!(
            "error: {}: automatic caps stopped above the tolerance: {why}",
            scene.file
        );
    }
    Ok(a.exit_code())
}

/// `lines.csv` and `spectrum.svg` into `dir`.
pub(crate) fn write_files(
    dir: &Path,
    scene: &Scene,
    a: &TorusSolveAnalysis,
) -> Result<(), Failure> {
    write_lines(&dir.join("lines.csv"), a)
        .with_context(|| format!("--out: cannot write {}", dir.display()))?;
    plot_spectrum(&dir.join("spectrum.svg"), scene, a);
    Ok(())
}

/// The summary.
fn print(scene: &Scene, a: &TorusSolveAnalysis) {
    say!(
        "{}: {} at {} {}",
        scene.file,
        scene.description.as_deref().unwrap_or(""),
        super::speed_text(a.speed),
        a.speed_unit
    );
    say!("  on several base frequencies (the torus): {}", a.why);
    say!("  base          order        Hz  cap  grid  truncation estimate");
    for b in &a.bases {
        say!(
            "  {:<10} {:>8} {:>9.2} {:>4} {:>5}  {}",
            b.name,
            super::speed_text(b.order),
            b.hz.unwrap_or(f64::NAN),
            b.cap,
            b.samples,
            b.estimate
                .map_or("not estimated".into(), |e| format!("{e:.1e}"))
        );
    }
    for l in &a.levels {
        say!(
            "  automatic caps: caps {:?}, {} lines, estimates {}",
            l.caps,
            l.lines,
            estimates(&l.estimates)
        );
    }
    say!(
        "  {} lines, Newton-Krylov {} (relative residual {:.1e}, {} steps)",
        a.lines,
        if a.converged {
            "converged"
        } else {
            "NOT CONVERGED"
        },
        a.relative_residual,
        a.solution.iterations
    );
    let hbal::torus::TorusStability::NotComputed { reason } = &a.stability;
    say!("  stability: {reason}");
    for (s, f) in a.elements.iter().zip(&a.forces) {
        print_spectrum("coordinate", s);
        print_spectrum("force", f);
    }
    say!("  DOF            mean         RMS  strongest line");
    for s in &a.dofs {
        say!(
            "  {:<12} {:>10.3e} {:>10.3e}  {}",
            s.name,
            s.mean,
            s.rms,
            s.lines.first().map_or(String::new(), |l| format!(
                "{} (order {})",
                l.label,
                super::speed_text(l.order)
            ))
        );
    }
}

fn estimates(e: &[Option<f64>]) -> String {
    e.iter()
        .map(|e| e.map_or("-".into(), |e| format!("{e:.1e}")))
        .collect::<Vec<_>>()
        .join(", ")
}

fn print_spectrum(what: &str, s: &Spectrum) {
    say!(
        "  element {} {what}: mean {:.4e}, RMS of the alternating part {:.4e}",
        s.name,
        s.mean,
        s.rms
    );
    say!("        order          Hz   amplitude  phase deg  line");
    for l in s.lines.iter().take(PRINTED_LINES) {
        say!(
            "    {:>9} {:>11.2} {:>11.4e} {:>10.1}  {}",
            super::speed_text(l.order),
            l.hz,
            l.amplitude,
            l.phase.to_degrees(),
            l.label
        );
    }
}

/// `lines.csv`: every line of every element coordinate and DOF.
fn write_lines(path: &Path, a: &TorusSolveAnalysis) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    let mut header = vec!["what".to_string(), "name".to_string(), "line".to_string()];
    header.extend(a.bases.iter().map(|b| format!("k_{}", b.name)));
    header.extend(["order", "hz", "amplitude", "phase_deg"].map(String::from));
    w.write_record(&header)?;
    let sol = &a.solution;
    for (what, name, q) in quantities(a) {
        for (j, (k, q)) in sol.indices.iter().zip(&q).enumerate() {
            let order = sol.order(j);
            let mut row = vec![
                what.to_string(),
                name.clone(),
                hbal::analysis::line_label(&sol.bases, k),
            ];
            row.extend(k.iter().map(|k| k.to_string()));
            row.push(format!("{order:e}"));
            row.push(format!("{:e}", order * sol.omega / std::f64::consts::TAU));
            row.push(format!("{:e}", q.norm()));
            row.push(format!("{:e}", q.arg().to_degrees()));
            w.write_record(&row)?;
        }
    }
    Ok(w.flush()?)
}

/// Every DOF's and element coordinate's lines, line by line.
fn quantities(
    a: &TorusSolveAnalysis,
) -> Vec<(&'static str, String, Vec<hbal::num_complex::Complex64>)> {
    let sol = &a.solution;
    let n = sol.n_dofs();
    let line = |j: usize, i: usize| {
        let (re, im) = sol.harmonics[j * n + i];
        hbal::num_complex::Complex64::new(re, im)
    };
    let mut out: Vec<_> = (0..n)
        .map(|i| {
            (
                "dof",
                sol.dofs[i].clone(),
                (0..sol.indices.len()).map(|j| line(j, i)).collect(),
            )
        })
        .collect();
    out.extend(
        a.element_lines
            .iter()
            .map(|(name, q)| ("element", name.clone(), q.clone())),
    );
    out.extend(
        a.force_lines
            .iter()
            .map(|(name, q)| ("force", name.clone(), q.clone())),
    );
    out
}

/// `spectrum.svg`: every element coordinate's lines over their order (log amplitude).
fn plot_spectrum(path: &Path, scene: &Scene, a: &TorusSolveAnalysis) {
    let series: Vec<Series> = a
        .element_lines
        .iter()
        .map(|(name, q)| {
            let mut points: Vec<(f64, f64)> = (1..q.len())
                .map(|j| (a.solution.order(j), q[j].norm()))
                .filter(|p| p.1 > 0.0)
                .collect();
            points.sort_by(|x, y| x.0.total_cmp(&y.0));
            Series::markers(name.clone(), points)
        })
        .collect();
    if series.iter().all(|s| s.points.is_empty()) {
        return;
    }
    let title = format!(
        "Lines of the element coordinates at {} {}: {}",
        super::speed_text(a.speed),
        a.speed_unit,
        scene.file
    );
    line_plot(
        path,
        &title,
        &Axis::linear(format!("order of the speed ({})", a.speed_unit)),
        &Axis::log("amplitude"),
        &series,
    )
    .unwrap_or_else(super::plot_warning);
}
