//! `hbal solve` of a scene on several base frequencies ([`hbal::analysis::torus_solve`]): the
//! bases with their truncation estimates, the strongest labelled lines of every element
//! coordinate and force and each DOF's RMS, or the JSON; `--out` writes `lines.csv` (every
//! line of every DOF, element coordinate and element force) and `spectrum.svg`.

use super::Failure;
use hbal::analysis::{Spectrum, TorusSolveAnalysis, TorusSolveSettings};
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
        hbal::render::prepare_out(dir, &hbal::render::torus_solve_files())
            .map_err(|e| super::failure(e, &scene.file))?;
    }
    let a = hbal::analysis::torus_solve(scene, &TorusSolveSettings::default())
        .map_err(|e| super::failure(e, &scene.file))?;
    if json {
        say!("{}", a.to_json());
    } else {
        print(scene, &a);
    }
    if let Some(dir) = out {
        let mut warnings = Vec::new();
        hbal::render::write_torus_solve_files(dir, scene, &a, &mut warnings)
            .map_err(|e| super::failure(e, &scene.file))?;
        super::print_warnings(&warnings);
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
