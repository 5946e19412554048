//! `hbal solve` does not give up where the scene's solver fails from the linear solution: the
//! other solvers, the load homotopy and continuation in the speed follow (the output names the
//! path), and the orbit found is the one a long time integration from rest settles on.

use hbal::harmonic::from_cos_sin;
use hbal::num_complex::Complex64;
use hbal::scene::Scene;
use hbal::timesim::TimeSimulation;
use std::path::Path;

/// `hbal solve FILE --json` (default settings): exit code, the JSON and the harmonics.
fn solve(file: &str, extra: &[&str]) -> (i32, serde_json::Value, Vec<Complex64>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let mut args = vec!["solve", path.to_str().unwrap(), "--json", "--no-stability"];
    args.extend(extra);
    let out = crate::common::hbal(&args);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    let dofs = json["dofs"].as_array().unwrap();
    let h = dofs[0]["harmonics"].as_array().unwrap().len();
    let mut q = vec![Complex64::default(); h * dofs.len()];
    for (i, d) in dofs.iter().enumerate() {
        for (k, c) in d["harmonics"].as_array().unwrap().iter().enumerate() {
            q[k * dofs.len() + i] =
                from_cos_sin(c["cos"].as_f64().unwrap(), c["sin"].as_f64().unwrap());
        }
    }
    (out.status.code().unwrap(), json, q)
}

/// The scene's orbit found by a fallback, against a time integration from rest settled to
/// 1e-9: the relative distance of the harmonics 0..H.
fn check(file: &str) -> f64 {
    let (code, json, q) = solve(file, &[]);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["converged"], true);
    let how = json["found_by"].as_str().unwrap_or_default().to_string();
    assert!(
        how.contains("failed from the linear solution") && how.contains("found by"),
        "{how}"
    );
    let scene = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).unwrap();
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-9,
        samples: 512,
        ..TimeSimulation::default()
    }
    .run(&scene.model, scene.basis.omega())
    .unwrap();
    assert!(td.converged, "{:?}", td.stop);
    let n = scene.model.n_dofs();
    let h = q.len() / n - 1;
    let error = hbal::compare::model_relative_error(&scene.model, &q, &td.harmonics, h);
    eprintln!("{file}: {how}; against the time domain {error:.2e}");
    error
}

/// The backlash pair (the shared reference's model, Fa = 0.1) at 0.7 rad/s.
#[test]
fn backlash_pair_at_0_7_is_found_from_the_scene_alone() {
    let e = check("tests/data/globalised/backlash_pair_w0.7.toml");
    assert!(e < 1e-6, "{e:e}");
}

/// The 3-DOF backlash chain at 1.35 rad/s.
#[test]
fn backlash_chain_at_1_35_is_found_from_the_scene_alone() {
    let e = check("tests/data/globalised/backlash_chain_w1.35.toml");
    assert!(e < 1e-6, "{e:e}");
}

/// With automatic harmonics the first level is found the same way, and named.
#[test]
fn automatic_harmonics_go_past_a_failing_start() {
    let (code, json, _) = solve(
        "tests/data/globalised/backlash_pair_w0.7.toml",
        &["--harmonics", "auto"],
    );
    assert_eq!(code, 0, "{json}");
    let how = json["found_by"].as_str().unwrap_or_default();
    assert!(how.contains("speed homotopy"), "{how}");
    assert_eq!(json["auto_harmonics"]["reached"], true, "{json}");
}
