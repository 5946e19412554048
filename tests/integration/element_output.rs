//! Element outputs against hand computations from the DOF harmonics: a gear stage's
//! transmission error and mesh force (static balance of the pinion), and a backlash contact's
//! contact-state fractions with contact loss.

use hbal::report::{element_outputs, ElementOutput, ElementReport};
use hbal::scene::Scene;
use hbal::{HarmonicBalance, HarmonicBasis, Newton, Solution};
use std::path::Path;

fn solve(scene: &Scene, omega: f64) -> Solution {
    let basis = HarmonicBasis::new(omega, scene.basis.harmonics()).unwrap();
    let hb = HarmonicBalance::new(&scene.model, basis).unwrap();
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    sol
}

fn scene(name: &str) -> Scene {
    Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/scenes")
            .join(name),
    )
    .unwrap()
}

/// The paper's two-shaft model (one DOF, `u = q`): the equation of motion
/// `M q̈ + f(t) = L(t)` gives every harmonic of the mesh force from the DOF harmonics by hand,
/// `F_k = L_k + (kΩ)² M Q_k`; its mean is the load L0 = 10 N m, and `u` is `q` itself.
#[test]
fn two_shaft_mesh_force_from_its_harmonics_by_hand() {
    let s = scene("two_shaft_6000rpm.toml");
    let sol = solve(&s, s.basis.omega());
    let out = element_outputs(&s.model, &sol).unwrap();
    assert_mesh_force_balances(&out[0], &sol);
}

/// A sweep's report reuses one harmonic balance for the tail correction's forces, moved from
/// speed to speed: the mesh force balances the equation of motion at each (a tail fitted at
/// another speed would leave a residual of the tail's size, 1e-4 of the force here).
#[test]
fn mesh_force_balances_at_every_speed_of_one_report() {
    let s = scene("two_shaft_6000rpm.toml");
    let mut report = ElementReport::new(&s.model);
    for factor in [1.0, 0.8, 1.3, 1.0] {
        let sol = solve(&s, factor * s.basis.omega());
        let out = report.outputs(&sol).unwrap();
        assert_mesh_force_balances(&out[0], &sol);
    }
}

/// `F_k = L_k + (kΩ)² M Q_k` for the two-shaft model's mesh (module documentation).
fn assert_mesh_force_balances(mesh: &ElementOutput, sol: &Solution) {
    assert_eq!(mesh.kind, "mesh_stiffness");
    let (m, omega) = (1e-3, sol.basis().omega());
    let load = |k: usize| match k {
        0 => 10.0,
        1 => 3.158273408348595,
        _ => 0.0,
    };
    let scale = mesh.force.harmonics[1].norm();
    for k in 0..=sol.basis().harmonics() {
        let q = sol.harmonic(0, k);
        assert!((mesh.coordinate.harmonics[k] - q).norm() <= 1e-15 * q.norm().max(1e-30));
        let by_hand = load(k) + (k as f64 * omega).powi(2) * m * q;
        assert!(
            (mesh.force.harmonics[k] - by_hand).norm() < 1e-9 * scale,
            "k {k}: {} vs {by_hand}",
            mesh.force.harmonics[k]
        );
    }
    assert!((mesh.force.mean() - 10.0).abs() < 1e-9);
}

/// The two-inertia gear pair: `u = r1 θ1 - r2 θ2` from the DOF harmonics; the mean mesh force
/// from the pinion's static balance `T - k_p θ̄1 - r1 f̄ = 0` (drive torque 20 N m, shaft
/// 1e4 N m/rad); the dynamic factor `f_max / f̄`.
#[test]
fn gear_stage_transmission_error_and_mesh_force_by_hand() {
    let s = scene("two_shaft_gear_pair.toml");
    let sol = solve(&s, s.basis.omega());
    let out = element_outputs(&s.model, &sol).unwrap();
    let mesh = &out[0];
    assert_eq!(mesh.kind, "gear_stage");
    let (r1, r2) = (0.02, 0.04);
    let h = sol.basis().harmonics();
    for k in 0..=h {
        let by_hand = sol.harmonic(0, k) * r1 - sol.harmonic(1, k) * r2;
        assert!(
            (mesh.coordinate.harmonics[k] - by_hand).norm() < 1e-15,
            "k {k}"
        );
    }
    let m = mesh.mesh.unwrap();
    assert_eq!(m.te_unit, "µm");
    let te_mean = 1e6 * (r1 * sol.harmonic(0, 0).re - r2 * sol.harmonic(1, 0).re);
    assert!(
        (m.te_mean - te_mean).abs() < 1e-9 * te_mean.abs(),
        "{} vs {te_mean}",
        m.te_mean
    );
    // The static balance of the pinion gives the mean mesh force.
    let f_static = (20.0 - 1e4 * sol.harmonic(0, 0).re) / r1;
    assert!(
        (m.force_mean - f_static).abs() < 1e-6 * f_static,
        "{} vs {f_static}",
        m.force_mean
    );
    // ... and the gear's: r2 f̄ = k_g θ̄2 - T_load with T_load = -40 N m.
    let f_gear = (4e4 * sol.harmonic(1, 0).re + 40.0) / r2;
    assert!(
        (m.force_mean - f_gear).abs() < 1e-6 * f_gear,
        "{} vs {f_gear}",
        m.force_mean
    );
    // The largest mesh force from the law on a fine series of the DOF harmonics, and the
    // dynamic factor against the static balance's mean force.
    let law = &s.model.elements()[0];
    let f_max = (0..20000)
        .map(|j| {
            let t = std::f64::consts::TAU * j as f64 / 20000.0;
            let u = r1 * sol.displacement(0, t) - r2 * sol.displacement(1, t);
            let du = r1 * sol.velocity(0, t) - r2 * sol.velocity(1, t);
            law.law().force(t, u, du)
        })
        .fold(f64::MIN, f64::max);
    assert!(
        (m.force_max - f_max).abs() < 2e-3 * f_max,
        "{} vs {f_max}",
        m.force_max
    );
    let kv = f_max / f_static;
    assert!(
        (m.dynamic_factor - kv).abs() < 2e-3 * kv,
        "{} vs {kv}",
        m.dynamic_factor
    );
    assert!(m.dynamic_factor > 1.0 && m.dynamic_force > 0.0);
    // The TE peak-to-peak from a fine time series of the harmonics.
    let fine: Vec<f64> = (0..20000)
        .map(|j| {
            let t = std::f64::consts::TAU * j as f64 / 20000.0;
            r1 * sol.displacement(0, t) - r2 * sol.displacement(1, t)
        })
        .collect();
    let p2p = fine.iter().cloned().fold(f64::MIN, f64::max)
        - fine.iter().cloned().fold(f64::MAX, f64::min);
    assert!(
        (m.te_peak_to_peak - 1e6 * p2p).abs() < 1e-3 * 1e6 * p2p,
        "{} vs {}",
        m.te_peak_to_peak,
        1e6 * p2p
    );
}

/// The backlash gear pair at W = 1.0 loses contact: the fractions of the period on the coast
/// flank, open and on the drive flank sum to one and match a count on the orbit.
#[test]
fn backlash_contact_states_with_contact_loss() {
    let s = scene("gear_backlash.toml");
    let sol = solve(&s, 1.0);
    let out = element_outputs(&s.model, &sol).unwrap();
    let c = &out[0];
    assert_eq!(c.kind, "backlash");
    let names: Vec<&str> = c.states.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["coast", "open", "drive"]);
    let total: f64 = c.states.iter().map(|(_, f)| f).sum();
    assert!((total - 1.0).abs() < 1e-12);
    let samples = 100_000;
    let mut count = [0usize; 3];
    for j in 0..samples {
        let x = sol.displacement(0, std::f64::consts::TAU * j as f64 / samples as f64);
        count[if x < -1.0 {
            0
        } else if x <= 1.0 {
            1
        } else {
            2
        }] += 1;
    }
    for (i, (name, f)) in c.states.iter().enumerate() {
        let by_count = count[i] as f64 / samples as f64;
        assert!((f - by_count).abs() < 1e-3, "{name}: {f} vs {by_count}");
    }
    assert!(
        c.states[1].1 > 0.05,
        "contact loss expected: {:?}",
        c.states
    );
    // No force while open: the force's minimum over the period is 0 or below (coast impacts).
    assert!(c.force.min <= 1e-12);
}

/// `hbal solve --json --out`: the elements in the JSON (harmonic and order, the gear stage's
/// mesh output) and in `elements.csv`, quoted where a name holds a comma.
#[test]
fn cli_writes_element_outputs() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/two_shaft_gear_pair.toml"),
    )
    .unwrap()
    .replace("name = \"mesh\"", "name = \"mesh, stage 1\"")
    .replace(
        "fundamental = { rpm = 3000 }",
        "fundamental = { rpm = 1500, order = 2 }",
    );
    let dir = std::env::temp_dir().join(format!("hbal-elements-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("pair.toml");
    std::fs::write(&scene, text).unwrap();
    let out_dir = dir.join("out");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args([
            "solve",
            scene.to_str().unwrap(),
            "--json",
            "--no-stability",
            "--out",
        ])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let e = &doc["elements"][0];
    assert_eq!(e["name"], "mesh, stage 1");
    assert_eq!(e["type"], "gear_stage");
    // Harmonic 20 of a fundamental of order 2 is order 40 of the 1500 rpm reference.
    let h20 = &e["force"]["harmonics"][20];
    assert_eq!(h20["harmonic"], 20);
    assert_eq!(h20["shaft_order"], 40.0);
    let m = &e["gear_stage"];
    assert_eq!(m["te_unit"], "µm");
    assert!(m["dynamic_factor"].as_f64().unwrap() > 1.0);
    let csv = std::fs::read_to_string(out_dir.join("elements.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("element,quantity,harmonic,shaft_order,cos,sin")
    );
    let first = lines.next().unwrap();
    assert!(first.starts_with("\"mesh, stage 1\",u,0,0,"), "{first}");
    let mut reader = csv::Reader::from_reader(csv.as_bytes());
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 2 * 65);
    assert!(rows
        .iter()
        .all(|r| r.len() == 6 && &r[0] == "mesh, stage 1"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Files of a solve that did not converge carry the status in their names and plot titles;
/// the plot titles name the scene and the speed.
#[test]
fn unconverged_outputs_say_so() {
    let dir = std::env::temp_dir().join(format!("hbal-unconverged-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/gear_backlash.toml"),
    )
    .unwrap()
    .replace("rad_s = 0.7", "rad_s = 1.0")
        + "\n[solver]\nmethod = \"fixed_point\"\nmax_iterations = 2\n";
    let text = text.replacen("[solver]\nmethod = \"newton\"\n", "", 1);
    let scene = dir.join("stuck.toml");
    std::fs::write(&scene, text).unwrap();
    let run = |out: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
            .args([
                "solve",
                scene.to_str().unwrap(),
                "--no-stability",
                "--no-fallback",
                "--out",
            ])
            .arg(dir.join(out))
            .output()
            .unwrap()
    };
    let out = run("stuck");
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "harmonics.csv",
        "elements.csv",
        "time_series.csv",
        "time_series.svg",
    ] {
        assert!(
            dir.join("stuck")
                .join(format!("not_converged_{f}"))
                .exists(),
            "{f}"
        );
        assert!(!dir.join("stuck").join(f).exists(), "{f}");
    }
    let svg = std::fs::read_to_string(dir.join("stuck/not_converged_time_series.svg")).unwrap();
    assert!(svg.contains("NOT CONVERGED"), "title");
    assert!(svg.contains("at 1 rad_s"), "speed in the title");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The exact piecewise solution at a fixed H (where harmonic balance leaves the tail
/// correction off by default): its mesh force still balances the equation of motion, with the
/// correction's part of the harmonics above H the exact solution has: `f_1 = L_1 + Ω² M Q_1`
/// on the one-DOF two-shaft model at 6000 rpm, H = 32 (3.2201; without that part 3.2198).
#[test]
fn the_exact_solutions_mesh_force_balances_the_equation_of_motion() {
    use hbal::catalog::TwoShaft;
    use hbal::solve::PiecewiseExact;
    use hbal::HarmonicBasis;
    let case = TwoShaft::new(6000.0);
    let model = case.model().unwrap();
    let basis = HarmonicBasis::new(case.mesh_omega(), 32).unwrap();
    let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
    let out = element_outputs(&model, &exact.solution).unwrap();
    let f1 = out[0].force.harmonics[1];
    let w = case.mesh_omega();
    let q1 = exact.solution.harmonics()[1];
    let l = model.loads().iter().find(|l| l.order == 1).unwrap();
    let load = hbal::num_complex::Complex64::new(l.cos, -l.sin);
    let balance = load + w * w * model.mass().get(0, 0) * q1;
    assert!(
        (f1 - balance).norm() < 1e-5 * balance.norm(),
        "{f1} against {balance}"
    );
}
