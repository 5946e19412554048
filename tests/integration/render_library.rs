//! `hbal::render` from the library: the report's typed parts hold the analyses the page shows
//! (the solve's numbers are those of `analysis::solve`), the files land where the command
//! line puts them, and bad input is an error with exit code 2 before anything is written.

use hbal::analysis::{solve, Silent, SolveSettings};
use hbal::render::{report, ReportParts, ReportSettings};
use hbal::scene::Scene;
use std::path::Path;

fn load(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenes")
        .join(name);
    Scene::load(&path).expect("example scene")
}

#[test]
fn the_report_returns_the_analyses_its_page_shows() {
    let scene = load("gear_backlash.toml");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("render_library_report");
    let _ = std::fs::remove_dir_all(&dir);
    let settings = ReportSettings {
        to: Some(0.9),
        stability: true,
        ..ReportSettings::default()
    };
    let r = report(&scene, "", &settings, &dir, &mut Silent).expect("report");
    assert_eq!((r.exit_code, r.errors().len()), (0, 0), "{:?}", r.errors());
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    let ReportParts::Periodic(parts) = &r.parts else {
        panic!("a periodic scene");
    };
    let solved = parts.solved.result.as_ref().expect("the solve");
    // The same solve as the analysis on its own: the gear's harmonics to the bit.
    let alone = solve(
        &scene,
        &SolveSettings {
            stability: true,
            ..SolveSettings::default()
        },
    )
    .expect("solve");
    assert_eq!(solved.solution.harmonics(), alone.solution.harmonics());
    let swept = parts
        .swept
        .as_ref()
        .and_then(|p| p.result.as_ref())
        .expect("run-up");
    assert!(swept.branch.points.len() > 5);
    let moded = parts.moded.result.as_ref().expect("modes");
    assert!(moded.natural.is_some());
    let page = std::fs::read_to_string(&r.file).expect("report.html");
    // The page's DOF table shows the solve's max |x| and its order-1 amplitude, 4 digits.
    let n = solved.solution.dof_names().len();
    for value in [solved.max_abs[0], solved.solution.harmonics()[n].norm()] {
        let shown = hbal::report::significant(value, 4);
        assert!(
            page.contains(&format!("<td>{shown}</td>")),
            "{shown} not in the page"
        );
    }
    for f in [
        "solve/harmonics.csv",
        "sweep/branch.csv",
        "modes/campbell.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    assert!(page.contains("<svg"), "inlined plots");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_report_input_is_an_input_error_before_anything_is_written() {
    let scene = load("gear_backlash.toml");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("render_library_bad");
    let _ = std::fs::remove_dir_all(&dir);
    let cases = [
        (Some(0.5), None, None, "--from needs --to"),
        (None, Some(-1.0), None, "--to"),
        (None, None, Some("x"), "--output chooses the run-up's plots"),
        (None, Some(0.9), Some("nothing"), "nothing"),
    ];
    for (from, to, output, says) in cases {
        let settings = ReportSettings {
            from,
            to,
            output: output.map(String::from),
            ..ReportSettings::default()
        };
        let e = report(&scene, "", &settings, &dir, &mut Silent).expect_err(says);
        assert_eq!(e.exit_code(), 2, "{e}");
        assert!(e.to_string().contains(says), "{e}");
        assert!(!dir.exists(), "nothing written for `{says}`");
    }
}

/// The spectrum's x axis is the order of the reference shaft (issue 36): on the clutch damper
/// (fundamental = engine order 2, H = 24) it reaches order 48, past the harmonic index.
#[test]
fn the_spectrum_is_over_the_shaft_order() {
    let scene = load("clutch_damper_hysteresis.toml");
    let a = solve(&scene, &SolveSettings::default()).expect("solve");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("render_library_spectrum");
    let _ = std::fs::remove_dir_all(&dir);
    let mut warnings = Vec::new();
    hbal::render::write_solve_files(&scene, &a, &dir, &mut warnings).expect("files");
    let svg = std::fs::read_to_string(dir.join("spectrum.svg")).expect("spectrum.svg");
    assert!(svg.contains("order of the reference shaft"), "axis label");
    assert!(!svg.contains("harmonic k"));
    // A tick beyond H = 24: the axis spans the orders 2..48.
    let ticks: Vec<f64> = svg
        .split('>')
        .filter_map(|t| t.split('<').next()?.trim().parse::<f64>().ok())
        .collect();
    assert!(ticks.iter().any(|&t| t >= 40.0), "{ticks:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The CSV files read as an engineer expects (issue 36): a speed computed as `ω / (rad/s per
/// rpm)` is `6e3`, not `6.000000000000001e3`; a zero is `0`, never `-0e0`.
#[test]
fn csv_numbers_are_clean() {
    let scene = load("two_shaft_6000rpm.toml");
    let settings = hbal::analysis::SweepSettings {
        stability: false,
        max_points: Some(4),
        ..hbal::analysis::SweepSettings::to(6100.0)
    };
    let a = hbal::analysis::sweep(&scene, &settings, &mut Silent).expect("sweep");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("render_library_csv");
    let _ = std::fs::remove_dir_all(&dir);
    let mut warnings = Vec::new();
    hbal::render::write_sweep_files(&dir, &scene, &a, &mut warnings).expect("sweep files");
    let solved = solve(&scene, &SolveSettings::default()).expect("solve");
    hbal::render::write_solve_files(&scene, &solved, &dir, &mut warnings).expect("solve files");
    let branch = std::fs::read_to_string(dir.join("branch.csv")).expect("branch.csv");
    let first = branch.lines().nth(1).expect("a point");
    assert!(first.starts_with("6e3,"), "{first}");
    for file in [
        "branch.csv",
        "order_cuts.csv",
        "harmonics.csv",
        "time_series.csv",
        "elements.csv",
    ] {
        let text = std::fs::read_to_string(dir.join(file)).expect(file);
        for cell in text.lines().skip(1).flat_map(|l| l.split(',')) {
            assert!(!cell.starts_with("-0e") && cell != "-0", "{file}: {cell}");
            if let Some((mantissa, _)) = cell.split_once('e') {
                let digits = mantissa.chars().filter(char::is_ascii_digit).count();
                assert!(digits <= 15, "{file}: {cell}");
            }
        }
    }
    let harmonics = std::fs::read_to_string(dir.join("harmonics.csv")).expect("harmonics.csv");
    assert!(
        harmonics.lines().any(|l| l.ends_with(",0")),
        "the sin of harmonic 0 is 0"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The report's run-up resolution (issue 36): a smaller `max_step` gives more points, a bad one
/// is bad input before anything is written; a torus report takes `points` and refuses the
/// continuation's options.
#[test]
fn the_report_run_up_resolution_is_chosen() {
    let scene = load("gear_backlash.toml");
    let base = Path::new(env!("CARGO_TARGET_TMPDIR")).join("render_library_resolution");
    let _ = std::fs::remove_dir_all(&base);
    let points = |max_step: Option<f64>, dir: &str| {
        let settings = ReportSettings {
            to: Some(0.9),
            max_step,
            ..ReportSettings::default()
        };
        let r = report(&scene, "", &settings, &base.join(dir), &mut Silent).expect("report");
        let ReportParts::Periodic(parts) = &r.parts else {
            panic!("periodic")
        };
        let swept = parts
            .swept
            .as_ref()
            .and_then(|p| p.result.as_ref())
            .expect("run-up");
        swept.branch.points.len()
    };
    let (coarse, fine) = (points(None, "coarse"), points(Some(0.05), "fine"));
    assert!(fine > 3 * coarse, "{coarse} points at 0.5, {fine} at 0.05");
    for bad in [0.0, -1.0, f64::NAN] {
        let settings = ReportSettings {
            to: Some(0.9),
            max_step: Some(bad),
            ..ReportSettings::default()
        };
        let e = report(&scene, "", &settings, &base.join("bad"), &mut Silent).expect_err("bad");
        assert_eq!(e.exit_code(), 2, "{e}");
        assert!(e.to_string().contains("--max-step"), "{e}");
        assert!(!base.join("bad").exists());
    }
    let torus = load("two_stage_train_torus.toml");
    let settings = ReportSettings {
        to: Some(2100.0),
        max_step: Some(0.1),
        ..ReportSettings::default()
    };
    let e = report(&torus, "", &settings, &base.join("torus"), &mut Silent).expect_err("torus");
    assert!(e.to_string().contains("evenly spaced --points"), "{e}");
    let _ = std::fs::remove_dir_all(&base);
}
