//! The natural frequencies (linearised on the periodic solution), the critical speeds and
//! the Campbell diagram.

use super::{document, figure, num, Inputs};
use hbal::report::HtmlReport;

pub(super) fn modes_section(r: &mut HtmlReport, i: &Inputs) {
    let unit = i.scene.speed_unit;
    r.heading("Natural frequencies and critical speeds");
    let Some(doc) = document(r, i.moded, "natural frequencies") else {
        return;
    };
    let modes = doc["modes"].as_array().map_or(&[][..], Vec::as_slice);
    r.paragraph(&format!(
        "{} modes ({} rigid-body), linearised on the periodic solution; one- and two-tooth bounds of time-varying meshes.",
        modes.len(),
        doc["rigid_modes"]
    ));
    let rows: Vec<Vec<String>> = modes
        .iter()
        .enumerate()
        .take(30)
        .map(|(k, m)| {
            vec![
                (k + 1).to_string(),
                num(&m["mean_hz"]),
                num(&m["lower_hz"]),
                num(&m["upper_hz"]),
            ]
        })
        .collect();
    r.table(
        &[
            "mode",
            "mean stiffness (Hz)",
            "one tooth (Hz)",
            "two teeth (Hz)",
        ],
        &rows,
    );
    let critical = doc["critical_speeds"]
        .as_array()
        .map_or(&[][..], Vec::as_slice);
    if !critical.is_empty() {
        let rows: Vec<Vec<String>> = critical
            .iter()
            .map(|c| vec![num(&c["speed"]), num(&c["order"]), c["mode"].to_string()])
            .collect();
        let speed = format!("critical speed ({unit})");
        r.table(&[&speed, "order", "mode"], &rows);
    }
    figure(r, &i.dir.join("modes"), "campbell.svg", "Campbell diagram");
}
