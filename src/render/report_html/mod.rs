//! The page of `hbal report`: built from the typed results of the library's solve, sweep and
//! modes analyses and the SVG plots written from them, inlined. One file per section of the
//! page: the periodic solution, the run-up and the natural frequencies.

mod natural_frequencies;
mod run_up;
mod solution;

use super::report::Part;
use crate::analysis::{ModesAnalysis, SolveAnalysis, SweepAnalysis};
use crate::report::{significant, HtmlReport};
use crate::scene::Scene;
use std::path::Path;

/// Everything the page shows.
pub(super) struct Inputs<'a> {
    pub(super) scene: &'a Scene,
    pub(super) scene_text: &'a str,
    pub(super) dir: &'a Path,
    pub(super) solved: &'a Part<SolveAnalysis>,
    pub(super) swept: Option<&'a Part<SweepAnalysis>>,
    pub(super) moded: &'a Part<ModesAnalysis>,
}

/// A number with 4 significant digits, `–` where there is none (or it is not finite).
fn num(v: impl Into<Option<f64>>) -> String {
    v.into()
        .filter(|x| x.is_finite())
        .map_or("–".into(), |x| significant(x, 4))
}

/// A percentage with one decimal.
fn percent(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

/// The result of `part`, or `None` after a failed status `no {what}: {error}`.
fn result<'a, T>(r: &mut HtmlReport, part: &'a Part<T>, what: &str) -> Option<&'a T> {
    if part.result.is_none() {
        r.status(
            false,
            &format!("no {what}: {}", part.error.as_deref().unwrap_or("unknown")),
        );
    }
    part.result.as_ref()
}

/// Inlines `dir/file` as a figure, or says it is missing.
fn figure(r: &mut HtmlReport, dir: &Path, file: &str, caption: &str) {
    match std::fs::read_to_string(dir.join(file)) {
        Ok(svg) => {
            if let Err(e) = r.figure(&svg, caption) {
                r.paragraph(&e);
            }
        }
        Err(_) => r.paragraph(&format!("({caption}: no plot, {file} was not written)")),
    }
}

pub(super) fn build(i: &Inputs) -> String {
    let scene = i.scene;
    let unit = scene.speed_unit;
    let mut r = HtmlReport::new(&format!("hbal report: {}", scene.file));
    r.paragraph(&format!(
        "hbal {}; {} DOFs, {} elements; speeds in {unit}, orders of the reference shaft (the fundamental is order {}).",
        env!("CARGO_PKG_VERSION"),
        scene.model.n_dofs(),
        scene.model.elements().len(),
        scene.fundamental_order
    ));
    solution::solve_section(&mut r, i);
    if let Some(part) = i.swept {
        run_up::sweep_section(&mut r, i, part);
    }
    natural_frequencies::modes_section(&mut r, i);
    r.heading("Scene");
    r.details(&format!("{} (as read)", scene.file), i.scene_text);
    r.finish()
}
