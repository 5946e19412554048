//! The periodic solution at the scene's speed: convergence, error estimate, stability, the
//! time series and spectrum, the DOF and element tables.

use super::{document, figure, num, percent, Inputs};
use hbal::report::{significant, HtmlReport};
use serde_json::Value;

/// Most rows of the DOF table (the DOFs with the largest max |q| of a larger model).
const MAX_DOF_ROWS: usize = 40;

pub(super) fn solve_section(r: &mut HtmlReport, i: &Inputs) {
    let scene = i.scene;
    r.heading(&format!(
        "Periodic solution at {} {}",
        crate::cli::speed_text(scene.basis.omega() / scene.omega_per_speed),
        scene.speed_unit
    ));
    let Some(doc) = document(r, i.solved, "solution") else {
        return;
    };
    let converged = doc["converged"].as_bool() == Some(true);
    r.status(
        converged,
        &format!(
            "{} ({}) after {} iteration{}",
            doc["termination"].as_str().unwrap_or("?"),
            doc["method"].as_str().unwrap_or("?"),
            doc["iterations"],
            if doc["iterations"] == 1 { "" } else { "s" }
        ),
    );
    let estimate = &doc["error_estimate"];
    let stability = &doc["stability"];
    let stability_text = if let Some(u) = stability["unavailable"].as_str() {
        u.to_string()
    } else if let Some(e) = stability["error"].as_str() {
        format!("failed: {e}")
    } else if stability.is_null() {
        "not computed".to_string()
    } else {
        format!(
            "{}, max |μ| = {} ({} neutral), orbit correction {}",
            if stability["stable"].as_bool() == Some(true) {
                "stable"
            } else {
                "UNSTABLE"
            },
            num(&stability["max_abs"]),
            stability["neutral"],
            num(&stability["orbit_correction"])
        )
    };
    r.facts(&[
        ("relative residual", num(&doc["residual"])),
        (
            "error estimate",
            match estimate["relative"].as_f64() {
                Some(e) => format!(
                    "{}{}, of harmonics 0..{} {} (against H = {}){}",
                    if estimate["lower_bound"].as_bool() == Some(true) {
                        "at least "
                    } else {
                        ""
                    },
                    significant(e, 2),
                    doc["harmonics"],
                    estimate["kept_harmonics"]
                        .as_f64()
                        .map_or("?".to_string(), |k| significant(k, 2)),
                    estimate["reference_harmonics"],
                    match doc["auto_harmonics"]["control"].as_str() {
                        Some("harmonics") => "; automatic harmonics on the harmonics 0..H",
                        Some(_) => "; automatic harmonics on the periodic solution",
                        None => "",
                    }
                ),
                None => estimate["error"]
                    .as_str()
                    .unwrap_or("none (not converged)")
                    .to_string(),
            },
        ),
        ("stability", stability_text),
        (
            "harmonics H, samples N",
            format!("{}, {}", doc["harmonics"], doc["samples"]),
        ),
        (
            "fundamental",
            format!("{} rad/s", num(&doc["fundamental_rad_s"])),
        ),
        (
            "solve time",
            format!(
                "{} ms",
                num(&(doc["solve_seconds"].as_f64().map(|s| s * 1e3)).into())
            ),
        ),
    ]);
    let prefix = if converged { "" } else { "not_converged_" };
    let dir = i.dir.join("solve");
    figure(r, &dir, &format!("{prefix}time_series.svg"), "One period");
    figure(
        r,
        &dir,
        &format!("{prefix}spectrum.svg"),
        "Amplitude spectrum over the harmonics",
    );
    dof_table(r, i, doc);
    element_table(r, doc);
}

fn dof_table(r: &mut HtmlReport, i: &Inputs, doc: &Value) {
    let orders: Vec<f64> = hbal::analysis::excitation_orders(i.scene, &i.scene.basis)
        .into_iter()
        .map(|o| o.0)
        .collect();
    let Some(dofs) = doc["dofs"].as_array() else {
        return;
    };
    let mut rows: Vec<(f64, Vec<String>)> = dofs
        .iter()
        .map(|d| {
            let amplitude = |o: f64| {
                d["harmonics"]
                    .as_array()
                    .and_then(|hs| {
                        hs.iter().find(|h| {
                            h["shaft_order"]
                                .as_f64()
                                .is_some_and(|x| (x - o).abs() <= 1e-9 * o.max(1.0))
                        })
                    })
                    .map_or("–".into(), |h| {
                        let (c, s) = (h["cos"].as_f64(), h["sin"].as_f64());
                        significant(c.unwrap_or(0.0).hypot(s.unwrap_or(0.0)), 4)
                    })
            };
            let mut row = vec![d["name"].as_str().unwrap_or("?").to_string()];
            row.push(num(&d["max_abs"]));
            row.extend(orders.iter().map(|&o| amplitude(o)));
            (d["max_abs"].as_f64().unwrap_or(0.0), row)
        })
        .collect();
    r.heading("DOFs");
    if rows.len() > MAX_DOF_ROWS {
        r.paragraph(&format!(
            "The {MAX_DOF_ROWS} of {} DOFs with the largest max |q| (all in solve/harmonics.csv).",
            rows.len()
        ));
        rows.sort_by(|a, b| b.0.total_cmp(&a.0));
        rows.truncate(MAX_DOF_ROWS);
    }
    let titles: Vec<String> = orders.iter().map(|o| format!("order {o}")).collect();
    let mut header = vec!["DOF", "max |q| (rad or m)"];
    header.extend(titles.iter().map(String::as_str));
    let rows: Vec<Vec<String>> = rows.into_iter().map(|r| r.1).collect();
    r.table(&header, &rows);
}

fn element_table(r: &mut HtmlReport, doc: &Value) {
    let Some(elements) = doc["elements"].as_array() else {
        return;
    };
    if elements.is_empty() {
        return;
    }
    r.heading("Elements");
    let rows: Vec<Vec<String>> = elements
        .iter()
        .map(|e| {
            let states: Vec<String> = e["states"]
                .as_array()
                .map(|s| {
                    s.iter()
                        .map(|s| {
                            format!(
                                "{} {}",
                                s["state"].as_str().unwrap_or("?"),
                                percent(&s["fraction"])
                            )
                        })
                        .collect()
                })
                .unwrap_or_default();
            vec![
                e["name"].as_str().unwrap_or("?").to_string(),
                e["type"].as_str().unwrap_or("?").to_string(),
                num(&e["coordinate"]["mean"]),
                num(&e["coordinate"]["peak_to_peak"]),
                num(&e["force"]["mean"]),
                format!("{} … {}", num(&e["force"]["min"]), num(&e["force"]["max"])),
                states.join(", "),
            ]
        })
        .collect();
    r.table(
        &[
            "element",
            "type",
            "u mean (m or rad)",
            "u peak to peak",
            "f mean (N or N m)",
            "f min … max",
            "contact states",
        ],
        &rows,
    );
    let stages: Vec<Vec<String>> = elements
        .iter()
        .filter(|e| e["gear_stage"].is_object())
        .map(|e| {
            let g = &e["gear_stage"];
            let te = g["te_unit"].as_str().unwrap_or("µm");
            vec![
                e["name"].as_str().unwrap_or("?").to_string(),
                format!("{} {te}", num(&g["te_mean"])),
                format!("{} {te}", num(&g["te_peak_to_peak"])),
                num(&g["force_mean"]),
                num(&g["dynamic_force"]),
                num(&g["dynamic_factor"]),
            ]
        })
        .collect();
    if !stages.is_empty() {
        r.table(
            &[
                "gear stage",
                "TE mean",
                "TE peak to peak",
                "mesh force mean (N)",
                "dynamic mesh force (N)",
                "dynamic factor",
            ],
            &stages,
        );
    }
}
