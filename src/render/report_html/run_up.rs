//! The run-up: its points, folds and stability, where contact opens, the order cuts, the
//! waterfall and frequency responses.

use super::{figure, num, percent, result, Inputs};
use crate::analysis::SweepAnalysis;
use crate::continuation::BranchStop;
use crate::render::Part;
use crate::report::{significant, HtmlReport};

/// Frequency-response plots shown (of the first DOFs the sweep wrote plots of, its reported
/// DOFs; every one of those is in `sweep/`).
const FREQUENCY_RESPONSES: usize = 2;

pub(super) fn sweep_section(r: &mut HtmlReport, i: &Inputs, part: &Part<SweepAnalysis>) {
    let unit = i.scene.speed_unit;
    r.heading("Run-up");
    let Some(a) = result(r, part, "run-up") else {
        return;
    };
    let points = &a.branch.points;
    let unstable = points.iter().filter(|p| p.stable() == Some(false)).count();
    let largest = |f: fn(&crate::continuation::BranchPoint) -> Option<f64>| {
        points.iter().filter_map(f).fold(0.0f64, f64::max)
    };
    let worst = largest(|p| p.error_estimate);
    let kept = largest(|p| p.error_estimate_harmonics);
    r.status(
        a.branch.stop == BranchStop::Reached,
        &format!(
            "{} points from {} to {} {unit}: {}",
            points.len(),
            num(a.from),
            num(a.to),
            a.branch.stop
        ),
    );
    r.facts(&[
        ("folds", a.branch.folds().to_string()),
        ("unstable points", unstable.to_string()),
        (
            "largest error estimate",
            format!(
                "{}, of the harmonics 0..H {}",
                significant(worst, 2),
                significant(kept, 2)
            ),
        ),
        ("time", format!("{} s", num(a.seconds))),
    ]);
    if a.contact_loss.is_empty() {
        r.paragraph("No contact opens along the run-up.");
    } else {
        let rows: Vec<Vec<String>> = a
            .contact_loss
            .iter()
            .map(|c| {
                vec![
                    c.element.clone(),
                    num(c.from),
                    num(c.to),
                    percent(c.max_open),
                ]
            })
            .collect();
        let (from, to) = (format!("from ({unit})"), format!("to ({unit})"));
        r.table(
            &["contact opens", &from, &to, "largest open fraction"],
            &rows,
        );
    }
    let dir = i.dir.join("sweep");
    let cuts = "Order cuts: amplitude of each excitation order against speed";
    figure(r, &dir, "order_cuts.svg", cuts);
    figure(
        r,
        &dir,
        "waterfall.svg",
        "Waterfall: the spectrum at each speed",
    );
    for &d in a.reported.iter().take(FREQUENCY_RESPONSES) {
        let dof = &a.branch.dofs[d];
        figure(
            r,
            &dir,
            &format!("frequency_response_{dof}.svg"),
            &format!("Frequency response of {dof} (stable solid, unstable dashed)"),
        );
    }
    if a.reported.len() > FREQUENCY_RESPONSES {
        r.paragraph(&format!(
            "The frequency responses of the other {} DOFs are in sweep/.",
            a.reported.len() - FREQUENCY_RESPONSES
        ));
    }
}
