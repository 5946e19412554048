//! `hbal report`: the page holds the numbers of `hbal solve`, inlines its plots, needs nothing
//! from the network, and renders in a real browser (headless Chromium, where one is installed;
//! CI installs one and sets `HBAL_REQUIRE_BROWSER=1`). Bad input is refused before any work.

use crate::common;

use common::hbal;
use std::path::{Path, PathBuf};

fn scene(name: &str) -> String {
    format!("{}/examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn fresh_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The headless browser: `HBAL_BROWSER`, else the first of chromium, chromium-browser,
/// google-chrome on the PATH.
fn browser() -> Option<String> {
    if let Ok(b) = std::env::var("HBAL_BROWSER") {
        return Some(b);
    }
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|b| {
            std::process::Command::new(b)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
        .map(String::from)
}

/// Opens `page` in headless Chromium and returns the `<body>` attributes the page's render
/// check sets: (figures, figures with a layout box). `None` without a browser.
fn rendered_plots(page: &Path) -> Option<(usize, usize)> {
    let Some(browser) = browser() else {
        assert!(
            std::env::var("HBAL_REQUIRE_BROWSER").is_err(),
            "HBAL_REQUIRE_BROWSER is set but no chromium was found"
        );
        eprintln!("no headless browser (chromium): the render check is skipped");
        return None;
    };
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let out = std::process::Command::new("timeout")
        .args([
            "120",
            &browser,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
        ])
        .args(["--dump-dom", &url])
        .output()
        .expect("run the browser");
    let dom = String::from_utf8_lossy(&out.stdout);
    let attribute = |name: &str| -> usize {
        let key = format!("{name}=\"");
        let start = dom
            .find(&key)
            .unwrap_or_else(|| panic!("{name} not set: the page's script did not run\n{dom:.300}"))
            + key.len();
        dom[start..].split('"').next().unwrap().parse().unwrap()
    };
    Some((attribute("data-plots"), attribute("data-plots-rendered")))
}

#[test]
fn report_of_the_two_shaft_model_holds_the_solve_and_renders() {
    let dir = fresh_dir("report_two_shaft");
    let file = scene("two_shaft_6000rpm.toml");
    let out = hbal(&[
        "report",
        &file,
        "--from",
        "5000",
        "--to",
        "7000",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    // The numbers of `hbal solve`, to the 4 digits the page shows.
    let solved = hbal(&["solve", &file, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&solved.stdout).unwrap();
    let max_gear = doc["dofs"][0]["max_abs"].as_f64().unwrap();
    assert_eq!(doc["dofs"][0]["name"], "gear");
    assert!(
        html.contains(&format!(
            "<td>{}</td>",
            hbal::report::significant(max_gear, 4)
        )),
        "max |q| of gear {max_gear} in the DOF table"
    );
    let mu = doc["stability"]["max_abs"].as_f64().unwrap();
    assert!(html.contains(&format!("max |μ| = {}", hbal::report::significant(mu, 4))));
    for needle in [
        "converged (newton)",
        "Run-up",
        "Order cuts",
        "Waterfall",
        "Campbell",
        "<th>order 4</th>",
        "mean stiffness (Hz)",
        "[fundamental]",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
    // Self-contained: every plot inline, nothing fetched.
    let figures = html.matches("<figure><svg").count();
    assert_eq!(
        figures, 6,
        "time series, spectrum, order cuts, waterfall, FRF, Campbell"
    );
    for remote in ["src=\"http", "href=\"http", "<img", "<link", "@import"] {
        assert!(!html.contains(remote), "{remote}");
    }
    for bad in ["NaN", ">inf<", "null"] {
        assert!(!html.contains(bad), "{bad}");
    }
    // The parts' files stay next to it.
    for f in [
        "solve/harmonics.csv",
        "sweep/order_cuts.csv",
        "sweep/waterfall.svg",
        "modes/modes.csv",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    if let Some((plots, rendered)) = rendered_plots(&dir.join("report.html")) {
        assert_eq!(plots, figures);
        assert_eq!(rendered, figures, "every figure has a layout box");
    }
}

#[test]
fn report_of_the_free_free_drivetrain_shows_the_gear_stage() {
    let dir = fresh_dir("report_free_free");
    let out = hbal(&[
        "report",
        &scene("free_free_drivetrain.toml"),
        "--from",
        "1000",
        "--to",
        "3000",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    for needle in [
        "gear stage",
        "dynamic factor",
        "µm",
        "order 1.5",
        "Order cuts of the transmission error of mesh",
        "No contact opens along the run-up.",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
}

#[test]
fn report_refuses_bad_input_before_any_work() {
    // An unknown output: exit 2, the names listed, nothing written.
    let dir = fresh_dir("report_unknown_output");
    let out = hbal(&[
        "report",
        &scene("free_free_drivetrain.toml"),
        "--to",
        "3000",
        "--output",
        "gearbox",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--output `gearbox` is neither an element (clutch damper, mesh) nor a DOF (engine, flywheel"),
        "{err}"
    );
    assert!(!dir.exists());
    // An --out that cannot be a directory (under a file): exit 2 at once.
    let file = fresh_dir("report_out_is_a_file");
    std::fs::write(&file, "").unwrap();
    let out = hbal(&[
        "report",
        &scene("duffing.toml"),
        "--out",
        file.join("sub").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("cannot create the directory"), "{err}");
    assert!(
        !err.contains("report: solving"),
        "checked before the work: {err}"
    );
    // --from without --to.
    let out = hbal(&[
        "report",
        &scene("duffing.toml"),
        "--from",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--from needs --to"));
}

#[test]
fn a_dof_name_that_is_no_file_name_is_refused_and_nothing_lands_outside_out() {
    let base = fresh_dir("report_slash");
    std::fs::create_dir_all(&base).unwrap();
    let text = std::fs::read_to_string(scene("duffing.toml"))
        .unwrap()
        .replace("\"x\"", "\"../x\"")
        .replace("{ x = 1.0 }", "{ \"../x\" = 1.0 }");
    assert!(
        text.contains("../x"),
        "the Duffing scene names its DOF \"x\""
    );
    let file = base.join("slash.toml");
    std::fs::write(&file, text).unwrap();
    let out_dir = base.join("out");
    for args in [vec!["report", "--out"], vec!["sweep", "--to", "2", "--out"]] {
        let mut args: Vec<&str> = args;
        args.insert(1, file.to_str().unwrap());
        args.push(out_dir.to_str().unwrap());
        let out = hbal(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("DOF `../x` cannot be part of a file name in --out"),
            "{err}"
        );
    }
    let entries: Vec<_> = std::fs::read_dir(&base).unwrap().collect();
    assert_eq!(entries.len(), 1, "only the scene: nothing written");
}

#[test]
fn sweep_output_chooses_the_plotted_output() {
    let dir = fresh_dir("sweep_output");
    let out = hbal(&[
        "sweep",
        &scene("free_free_drivetrain.toml"),
        "--from",
        "1000",
        "--to",
        "2000",
        "--no-stability",
        "--output",
        "pinion",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let waterfall = std::fs::read_to_string(dir.join("waterfall.svg")).unwrap();
    assert!(waterfall.contains("Waterfall of the DOF pinion"));
    let cuts = std::fs::read_to_string(dir.join("order_cuts.svg")).unwrap();
    assert!(cuts.contains("Order cuts of the DOF pinion"));
}

/// A scene on several base frequencies gets its own report: the bases with their truncation
/// estimates, every element's labelled lines (the numbers of `hbal solve --json`), the run-up's
/// order cuts and waterfall, rendered in a real browser.
#[test]
fn report_of_a_torus_scene_holds_its_labelled_lines_and_renders() {
    let dir = fresh_dir("report_torus");
    let file = scene("two_stage_train_torus.toml");
    let out = hbal(&[
        "report",
        &file,
        "--from",
        "2000",
        "--to",
        "2100",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let solved = hbal(&["solve", &file, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&solved.stdout).unwrap();
    let top = &doc["elements"][0]["lines"][0];
    assert_eq!(top["label"], "3 stage1");
    let amplitude = format!("<td>{:.4e}</td>", top["amplitude"].as_f64().unwrap());
    assert!(html.contains(&amplitude), "{amplitude} in the stage1 table");
    for needle in [
        "Element stage1",
        "Element stage2",
        "3 stage1 − stage2",
        "truncation estimate",
        "Run-up",
        "Order cuts",
        "Waterfall",
        "Stability: not computed",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
    for f in [
        "solve/lines.csv",
        "solve/spectrum.svg",
        "sweep/order_cuts.csv",
        "sweep/waterfall.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    if let Some((plots, rendered)) = rendered_plots(&dir.join("report.html")) {
        assert_eq!((plots, rendered), (3, 3), "spectrum, order cuts, waterfall");
    }
}
