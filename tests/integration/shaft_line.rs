//! The shaft-line vocabulary (`[line]`, issue 33): disks and shafts build the same model as
//! the matrices written by hand, to the last bit; a shaft's stiffness from its geometry is
//! `G π (D⁴ − d⁴) / (32 L)`; bad input names the table and field (exit 2); `hbal check`
//! prints the assembled model's natural frequencies.

use crate::common;

use hbal::scene::Scene;

const SPEED: &str = "fundamental = { rpm = 1200 }\nharmonics = { count = 8 }\n\
    loads = [{ dof = \"engine\", order = 2, cos = 500.0 }]\n";

const LINE: &str = r#"
[line]
disks = [
  { name = "engine", inertia = 0.5 },
  { name = "flywheel", inertia = 1.25, damping = 0.75 },
  { name = "propeller", inertia = 3.0, damping = 40.0 },
]
shafts = [
  { from = "engine", to = "flywheel", stiffness = 2e5, damping = 4.0 },
  { from = "flywheel", to = "propeller", length = 1.5, outer_diameter = 0.1, inner_diameter = 0.04, shear_modulus = 8e10 },
]
"#;

/// The hollow shaft's stiffness, `G π (D⁴ − d⁴) / (32 L)`.
fn hollow() -> f64 {
    let fourth = |d: f64| (d * d) * (d * d);
    let polar = std::f64::consts::PI * (fourth(0.1) - fourth(0.04)) / 32.0;
    8e10 * polar / 1.5
}

#[test]
fn the_line_builds_the_matrices_written_by_hand() {
    let line = Scene::from_str(&format!("{SPEED}{LINE}"), "line.toml").unwrap();
    let (k1, k2) = (2e5, hollow());
    let matrices = format!(
        "{SPEED}dofs = [\"engine\", \"flywheel\", \"propeller\"]\n\
         mass = [[0.5, 0, 0], [0, 1.25, 0], [0, 0, 3.0]]\n\
         stiffness = [[{k1:?}, {m1:?}, 0], [{m1:?}, {s:?}, {m2:?}], [0, {m2:?}, {k2:?}]]\n\
         damping = [[4.0, -4.0, 0], [-4.0, {d:?}, 0], [0, 0, 40.0]]\n",
        m1 = -k1,
        m2 = -k2,
        s = k1 + k2,
        d = 0.75 + 4.0,
    );
    let hand = Scene::from_str(&matrices, "hand.toml").unwrap();
    assert_eq!(line.model.dof_names(), hand.model.dof_names());
    let (a, b) = (
        line.model.dense("test").unwrap(),
        hand.model.dense("test").unwrap(),
    );
    assert_eq!(a.mass, b.mass);
    assert_eq!(a.stiffness, b.stiffness);
    assert_eq!(a.damping, b.damping);
    // 8e10 π (1e-4 − 2.56e-6) / 48 N m/rad.
    assert!((k2 - 510_194.646_9).abs() < 1e-3, "{k2}");
    // The same solution to the last bit.
    let solve = |s: &Scene| {
        let hb = hbal::HarmonicBalance::new(&s.model, s.basis).unwrap();
        hbal::Newton::new().solve(&hb, &mut hb.workspace()).unwrap()
    };
    assert_eq!(solve(&line).harmonics(), solve(&hand).harmonics());
}

#[test]
fn check_prints_the_natural_frequencies_of_the_line() {
    let dir = common::cli::temp_dir("line");
    let path = dir.join("line.toml");
    std::fs::write(&path, format!("{SPEED}{LINE}")).unwrap();
    let out = common::hbal(&["check", path.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    // The generalised eigenvalues of (K, M) of the free line, by hand.
    let (j, k): ([f64; 3], [f64; 2]) = ([0.5, 1.25, 3.0], [2e5, hollow()]);
    let kk = hbal::nalgebra::DMatrix::from_row_slice(
        3,
        3,
        &[
            k[0],
            -k[0],
            0.0,
            -k[0],
            k[0] + k[1],
            -k[1],
            0.0,
            -k[1],
            k[1],
        ],
    );
    let m =
        hbal::nalgebra::DMatrix::from_fn(3, 3, |r, c| if r == c { 1.0 / j[r].sqrt() } else { 0.0 });
    let mut hz: Vec<f64> = (&m * kk * &m)
        .symmetric_eigenvalues()
        .iter()
        .map(|l| l.max(0.0).sqrt() / std::f64::consts::TAU)
        .collect();
    hz.sort_by(f64::total_cmp);
    let expected = format!(
        "natural frequencies (Hz): 0 (1 rigid), {:.6}, {:.6}",
        hz[1], hz[2]
    );
    assert!(stdout.contains(&expected), "{stdout}\nexpected {expected}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_lines_name_the_table_and_field() {
    let cases = [
        (
            "inertia = 0.5",
            "inertia = -0.5",
            "line.disks[0].inertia",
            "finite and >= 0",
        ),
        (
            "damping = 40.0 }",
            "damping = -1.0 }",
            "line.disks[2].damping",
            ">= 0",
        ),
        (
            "name = \"flywheel\"",
            "name = \"engine\"",
            "line.disks[1].name",
            "names another disk",
        ),
        (
            "to = \"flywheel\"",
            "to = \"gearbox\"",
            "line.shafts[0].to",
            "unknown disk `gearbox`",
        ),
        (
            "to = \"flywheel\"",
            "to = \"engine\"",
            "line.shafts[0].to",
            "ends where it starts",
        ),
        (
            "length = 1.5",
            "length = 0.0",
            "line.shafts[1].length",
            "finite and > 0",
        ),
        (
            "inner_diameter = 0.04",
            "inner_diameter = 0.2",
            "line.shafts[1].inner_diameter",
            "below the outer diameter",
        ),
        (
            "stiffness = 2e5,",
            "stiffness = 2e5, length = 1.0,",
            "line.shafts[0]",
            "give `stiffness`",
        ),
        ("stiffness = 2e5,", "", "line.shafts[0]", "give `stiffness`"),
        (
            "damping = 4.0 }",
            "damping = -4.0 }",
            "line.shafts[0].damping",
            ">= 0",
        ),
        (
            "{ name = \"engine\", inertia = 0.5 }",
            "{ name = \"engine\", inertia = 0.5, mass = 1 }",
            "line.disks[0].mass",
            "unknown field",
        ),
    ];
    for (from, to, path, what) in cases {
        assert!(LINE.contains(from), "{from}");
        let text = format!("{SPEED}{}", LINE.replacen(from, to, 1));
        let err = Scene::from_str(&text, "bad.toml").unwrap_err();
        assert_eq!(err.path.as_deref(), Some(path), "{to}: {err}");
        assert!(err.to_string().contains(what), "{to}: {err}");
    }
    // A scene field written after `[line]` belongs to it in TOML: the message says so.
    let late = format!("{LINE}fundamental = {{ rpm = 1200 }}\n");
    let err = Scene::from_str(&late, "late.toml").unwrap_err();
    assert_eq!(err.path.as_deref(), Some("line.fundamental"), "{err}");
    assert!(
        err.to_string()
            .contains("write `fundamental` before the `[line]` table"),
        "{err}"
    );
    // `line` and matrices together.
    let both = format!("{SPEED}dofs = [\"x\"]\n{LINE}");
    let err = Scene::from_str(&both, "both.toml").unwrap_err();
    assert_eq!(err.path.as_deref(), Some("line"), "{err}");
    assert!(err.to_string().contains("also gives `dofs`"), "{err}");
    // Exit code 2 from the CLI, before any work.
    let dir = common::cli::temp_dir("line-bad");
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        format!("{SPEED}{}", LINE.replace("length = 1.5", "length = -1.5")),
    )
    .unwrap();
    for cmd in ["check", "solve", "modes"] {
        let out = common::hbal(&[cmd, path.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd}: {stderr}");
        assert!(stderr.contains("line.shafts[1].length"), "{stderr}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A coupling is a stiffness and damping between two disks: the same model as a shaft with
/// them; its bad input is named in `couplings`.
#[test]
fn a_coupling_is_a_shaft_without_geometry() {
    let shaft = Scene::from_str(&format!("{SPEED}{LINE}"), "shaft.toml").unwrap();
    let text = format!("{SPEED}{LINE}").replace(
        "  { from = \"engine\", to = \"flywheel\", stiffness = 2e5, damping = 4.0 },\n",
        "",
    ) + "couplings = [{ from = \"engine\", to = \"flywheel\", stiffness = 2e5, damping = 4.0 }]\n";
    let coupling = Scene::from_str(&text, "coupling.toml").unwrap();
    let (a, b) = (
        shaft.model.dense("test").unwrap(),
        coupling.model.dense("test").unwrap(),
    );
    assert_eq!(a.stiffness, b.stiffness);
    assert_eq!(a.damping, b.damping);
    let bad = text.replace("stiffness = 2e5, damping = 4.0 }]", "stiffness = -2e5 }]");
    let err = Scene::from_str(&bad, "bad.toml").unwrap_err().to_string();
    assert!(
        err.contains("line.couplings[0].stiffness: must be finite and > 0"),
        "{err}"
    );
}
