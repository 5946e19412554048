//! The page of `hbal report`: built from the JSON documents of `solve`, `sweep` and `modes`
//! (the shapes documented in docs/scenes.md) and the SVG plots they wrote, inlined.

use super::report::Part;
use hbal::report::{significant, HtmlReport};
use hbal::scene::Scene;
use serde_json::Value;
use std::path::Path;

/// Everything the page shows.
pub(crate) struct Inputs<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) scene_text: &'a str,
    pub(crate) dir: &'a Path,
    pub(crate) solved: &'a Part,
    pub(crate) swept: Option<&'a Part>,
    pub(crate) moded: &'a Part,
}

/// Most rows of the DOF table (the DOFs with the largest max |q| of a larger model).
const MAX_DOF_ROWS: usize = 40;

/// Frequency-response plots shown (of the first DOFs; every one is in `sweep/`).
const FREQUENCY_RESPONSES: usize = 2;

/// A number of a JSON document with 4 significant digits, `–` where there is none.
fn num(v: &Value) -> String {
    v.as_f64().map_or("–".into(), |x| significant(x, 4))
}

/// A percentage with one decimal.
fn percent(v: &Value) -> String {
    v.as_f64()
        .map_or("–".into(), |x| format!("{:.1} %", 100.0 * x))
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

pub(crate) fn build(i: &Inputs) -> String {
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
    solve_section(&mut r, i);
    if let Some(part) = i.swept {
        sweep_section(&mut r, i, part);
    }
    modes_section(&mut r, i);
    r.heading("Scene");
    r.details(&format!("{} (as read)", scene.file), i.scene_text);
    r.finish()
}

fn solve_section(r: &mut HtmlReport, i: &Inputs) {
    let scene = i.scene;
    r.heading(&format!(
        "Periodic solution at {} {}",
        super::speed_text(scene.basis.omega() / scene.omega_per_speed),
        scene.speed_unit
    ));
    let Some(doc) = &i.solved.doc else {
        r.status(
            false,
            &format!(
                "no solution: {}",
                i.solved.error.as_deref().unwrap_or("unknown")
            ),
        );
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
                    "{} (against H = {})",
                    significant(e, 2),
                    estimate["reference_harmonics"]
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
    let orders: Vec<f64> = super::excitation_orders(i.scene, &i.scene.basis)
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

fn sweep_section(r: &mut HtmlReport, i: &Inputs, part: &Part) {
    let unit = i.scene.speed_unit;
    r.heading("Run-up");
    let Some(doc) = &part.doc else {
        r.status(
            false,
            &format!("no run-up: {}", part.error.as_deref().unwrap_or("unknown")),
        );
        return;
    };
    let points = doc["points"].as_array().map_or(&[][..], Vec::as_slice);
    let unstable = points.iter().filter(|p| p["stable"] == false).count();
    let worst = points
        .iter()
        .filter_map(|p| p["error_estimate"].as_f64())
        .fold(0.0f64, f64::max);
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
        ("largest error estimate", significant(worst, 2)),
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
    let dofs = i.scene.model.dof_names();
    for dof in dofs.iter().take(FREQUENCY_RESPONSES) {
        figure(
            r,
            &dir,
            &format!("frequency_response_{dof}.svg"),
            &format!("Frequency response of {dof} (stable solid, unstable dashed)"),
        );
    }
    if dofs.len() > FREQUENCY_RESPONSES {
        r.paragraph(&format!(
            "The frequency responses of the other {} DOFs are in sweep/.",
            dofs.len() - FREQUENCY_RESPONSES
        ));
    }
}

fn modes_section(r: &mut HtmlReport, i: &Inputs) {
    let unit = i.scene.speed_unit;
    r.heading("Natural frequencies and critical speeds");
    let Some(doc) = &i.moded.doc else {
        r.status(
            false,
            &format!(
                "no natural frequencies: {}",
                i.moded.error.as_deref().unwrap_or("unknown")
            ),
        );
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
