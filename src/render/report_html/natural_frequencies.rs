//! The natural frequencies (linearised on the periodic solution), the critical speeds and
//! the Campbell diagram.

use super::{figure, num, result, Inputs};
use crate::report::HtmlReport;

pub(super) fn modes_section(r: &mut HtmlReport, i: &Inputs) {
    let unit = i.scene.speed_unit;
    r.heading("Natural frequencies and critical speeds");
    let Some(a) = result(r, i.moded, "natural frequencies") else {
        return;
    };
    let Some(nf) = &a.natural else {
        let why = format!(
            "no natural frequencies: the operating point did not converge ({}): no linearisation",
            a.termination
        );
        r.status(false, &why);
        return;
    };
    r.paragraph(&format!(
        "{} modes ({} rigid-body), linearised on the periodic solution; one- and two-tooth bounds of time-varying meshes.",
        nf.mean.len(),
        nf.rigid
    ));
    let rows: Vec<Vec<String>> = (0..nf.mean.len().min(30))
        .map(|k| {
            vec![
                (k + 1).to_string(),
                num(nf.mean[k]),
                num(nf.lower.get(k).copied()),
                num(nf.upper.get(k).copied()),
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
    if !a.critical.is_empty() {
        let rows: Vec<Vec<String>> = a
            .critical
            .iter()
            .map(|c| vec![num(c.speed), num(c.order), c.mode.to_string()])
            .collect();
        let speed = format!("critical speed ({unit})");
        r.table(&[&speed, "order", "mode"], &rows);
    }
    figure(r, &i.dir.join("modes"), "campbell.svg", "Campbell diagram");
}
