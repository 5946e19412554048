//! The run-up: its points, folds and stability, where contact opens, the order cuts, the
//! waterfall and frequency responses.

use super::{document, figure, num, percent, Inputs};
use crate::cli::report::Part;
use hbal::report::{significant, HtmlReport};

/// Frequency-response plots shown (of the first DOFs the sweep wrote plots of, its
/// `harmonics_dofs`; every one of those is in `sweep/`).
const FREQUENCY_RESPONSES: usize = 2;

pub(super) fn sweep_section(r: &mut HtmlReport, i: &Inputs, part: &Part) {
    let unit = i.scene.speed_unit;
    r.heading("Run-up");
    let Some(doc) = document(r, part, "run-up") else {
        return;
    };
    let points = doc["points"].as_array().map_or(&[][..], Vec::as_slice);
    let unstable = points.iter().filter(|p| p["stable"] == false).count();
    let largest = |key: &str| {
        points
            .iter()
            .filter_map(|p| p[key].as_f64())
            .fold(0.0f64, f64::max)
    };
    let (worst, kept) = (
        largest("error_estimate"),
        largest("error_estimate_harmonics"),
    );
    r.status(
        doc["reached"].as_bool() == Some(true),
        &format!(
            "{} points from {} to {} {unit}: {}",
            points.len(),
            num(&doc["from"]),
            num(&doc["to"]),
            doc["stop"].as_str().unwrap_or("?")
        ),
    );
    r.facts(&[
        ("folds", doc["folds"].to_string()),
        ("unstable points", unstable.to_string()),
        (
            "largest error estimate",
            format!(
                "{}, of the harmonics 0..H {}",
                significant(worst, 2),
                significant(kept, 2)
            ),
        ),
        ("time", format!("{} s", num(&doc["seconds"]))),
    ]);
    if let Some(losses) = doc["contact_loss"].as_array().filter(|l| !l.is_empty()) {
        let rows: Vec<Vec<String>> = losses
            .iter()
            .map(|c| {
                vec![
                    c["element"].as_str().unwrap_or("?").to_string(),
                    num(&c["from"]),
                    num(&c["to"]),
                    percent(&c["max_open"]),
                ]
            })
            .collect();
        let (from, to) = (format!("from ({unit})"), format!("to ({unit})"));
        r.table(
            &["contact opens", &from, &to, "largest open fraction"],
            &rows,
        );
    } else {
        r.paragraph("No contact opens along the run-up.");
    }
    let dir = i.dir.join("sweep");
    figure(
        r,
        &dir,
        "order_cuts.svg",
        "Order cuts: amplitude of each excitation order against speed",
    );
    figure(
        r,
        &dir,
        "waterfall.svg",
        "Waterfall: the spectrum at each speed",
    );
    let written: Vec<&str> = doc["harmonics_dofs"]
        .as_array()
        .map(|a| a.iter().filter_map(|v| v.as_str()).collect())
        .unwrap_or_else(|| {
            i.scene
                .model
                .dof_names()
                .iter()
                .map(String::as_str)
                .collect()
        });
    for dof in written.iter().take(FREQUENCY_RESPONSES) {
        figure(
            r,
            &dir,
            &format!("frequency_response_{dof}.svg"),
            &format!("Frequency response of {dof} (stable solid, unstable dashed)"),
        );
    }
    if written.len() > FREQUENCY_RESPONSES {
        r.paragraph(&format!(
            "The frequency responses of the other {} DOFs are in sweep/.",
            written.len() - FREQUENCY_RESPONSES
        ));
    }
}
