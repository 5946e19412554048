//! `hbal sweep --out` writes order cuts: per point, the amplitude and phase of every excitation
//! order of every DOF and element coordinate. They equal the harmonics of the same points in
//! the sweep's JSON.

use std::path::Path;

#[test]
fn order_cuts_equal_the_harmonics_of_the_points() {
    let dir = std::env::temp_dir().join(format!("hbal-order-cuts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/two_shaft_gear_pair.toml");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args([
            "sweep",
            scene.to_str().unwrap(),
            "--from",
            "2900",
            "--to",
            "3100",
            "--no-stability",
            "--json",
            "--harmonics",
            "48",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = doc["points"].as_array().unwrap();
    let mut reader = csv::Reader::from_path(dir.join("order_cuts.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), points.len());
    assert!(points.len() >= 3, "{} points", points.len());
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    // Orders 1 (the load) and 20 (the mesh) of both DOFs and of the mesh's coordinate.
    let (gear_20, pinion_1, mesh_20) = (
        column("amp_gear_order_20"),
        column("amp_pinion_order_1"),
        column("amp_u(mesh)_order_20"),
    );
    let phase_gear_20 = column("phase_deg_gear_order_20");
    for (row, p) in rows.iter().zip(points) {
        let speed: f64 = row[0].parse().unwrap();
        assert!((speed - p["speed"].as_f64().unwrap()).abs() < 1e-9 * speed);
        let harmonic = |dof: usize, k: usize| {
            let h = &p["harmonics"][dof][k];
            assert_eq!(h["order"], k);
            hbal::harmonic::from_cos_sin(h["cos"].as_f64().unwrap(), h["sin"].as_f64().unwrap())
        };
        let (g20, p1) = (harmonic(1, 20), harmonic(0, 1));
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-300);
        assert!(
            close(row[gear_20].parse().unwrap(), g20.norm()),
            "{} vs {}",
            &row[gear_20],
            g20.norm()
        );
        assert!(close(row[pinion_1].parse().unwrap(), p1.norm()));
        let phase: f64 = row[phase_gear_20].parse().unwrap();
        assert!((phase - g20.arg().to_degrees()).abs() < 1e-9);
        // The mesh coordinate u = 0.02 θ_pinion - 0.04 θ_gear, harmonic by harmonic.
        let u20 = harmonic(0, 20) * 0.02 - g20 * 0.04;
        let got: f64 = row[mesh_20].parse().unwrap();
        assert!(
            (got - u20.norm()).abs() <= 1e-12 * u20.norm(),
            "{got} vs {}",
            u20.norm()
        );
    }
    assert!(dir.join("order_cuts.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The backlash gear pair loses contact over part of its sweep: the reported range holds every
/// point whose orbit enters the backlash (counted on the orbit), and the largest open fraction
/// matches the count.
#[test]
fn sweep_reports_where_the_contact_opens() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/gear_backlash.toml");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args([
            "sweep",
            scene.to_str().unwrap(),
            "--from",
            "0.4",
            "--to",
            "1.6",
            "--no-stability",
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let loss = doc["contact_loss"].as_array().unwrap();
    assert_eq!(loss.len(), 1, "{loss:?}");
    let (from, to) = (
        loss[0]["from"].as_f64().unwrap(),
        loss[0]["to"].as_f64().unwrap(),
    );
    assert_eq!(loss[0]["element"], "contact");
    let mut largest: f64 = 0.0;
    for p in doc["points"].as_array().unwrap() {
        let h: Vec<hbal::num_complex::Complex64> = p["harmonics"][0]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                hbal::harmonic::from_cos_sin(c["cos"].as_f64().unwrap(), c["sin"].as_f64().unwrap())
            })
            .collect();
        let samples = 20000;
        let open = (0..samples)
            .filter(|j| {
                let t = std::f64::consts::TAU * *j as f64 / samples as f64;
                let x: f64 = h
                    .iter()
                    .enumerate()
                    .map(|(k, q)| {
                        (q * hbal::num_complex::Complex64::from_polar(1.0, k as f64 * t)).re
                    })
                    .sum();
                x.abs() <= 1.0
            })
            .count() as f64
            / samples as f64;
        let s = p["speed"].as_f64().unwrap();
        if open > 2e-3 {
            assert!(
                s >= from - 1e-12 && s <= to + 1e-12,
                "open {open} at {s} outside [{from}, {to}]"
            );
        }
        largest = largest.max(open);
    }
    let reported = loss[0]["max_open"].as_f64().unwrap();
    assert!((reported - largest).abs() < 2e-3, "{reported} vs {largest}");
}
