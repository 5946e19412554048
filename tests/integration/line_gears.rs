//! Rigid gears and modal damping in `[line]`: the reduced model is `Tᵀ M T` (and K, D) of the
//! full one, `θ_driven = θ_driving / i`; modal damping gives each elastic mode its ratio; bad
//! input names the field.

use hbal::scene::Scene;
use nalgebra::{DMatrix, DVector};

const HEAD: &str = "fundamental = { rpm = 1000 }\nharmonics = { count = 4 }\n\
    loads = [{ dof = \"motor\", order = 1, cos = 10.0 }]\n";

/// motor —k1— pinion ⟂ wheel (i = 3.7) —k2— drum, the drum damped to ground.
const LINE: &str = r#"
[line]
disks = [
  { name = "motor", inertia = 0.2 },
  { name = "pinion", inertia = 0.01 },
  { name = "wheel", inertia = 0.3 },
  { name = "drum", inertia = 4.0, damping = 15.0 },
]
shafts = [
  { from = "motor", to = "pinion", stiffness = 4e4, damping = 2.0 },
  { from = "wheel", to = "drum", stiffness = 9e4, damping = 3.0 },
]
gears = [{ driving = "pinion", driven = "wheel", ratio = 3.7 }]
"#;

fn line(extra: &str) -> Result<Scene, String> {
    Scene::from_str(&format!("{HEAD}{LINE}{extra}"), "line.toml").map_err(|e| e.to_string())
}

/// The full 4-angle matrices and `T` (4 × 3: motor, pinion, drum kept).
fn full_and_t() -> [DMatrix<f64>; 4] {
    let (k1, k2, c1, c2) = (4e4, 9e4, 2.0, 3.0);
    let m = DMatrix::from_diagonal(&DVector::from_vec(vec![0.2, 0.01, 0.3, 4.0]));
    let spring = |a: usize, b: usize, k: f64, x: &mut DMatrix<f64>| {
        x[(a, a)] += k;
        x[(b, b)] += k;
        x[(a, b)] -= k;
        x[(b, a)] -= k;
    };
    let mut k = DMatrix::zeros(4, 4);
    spring(0, 1, k1, &mut k);
    spring(2, 3, k2, &mut k);
    let mut d = DMatrix::zeros(4, 4);
    spring(0, 1, c1, &mut d);
    spring(2, 3, c2, &mut d);
    d[(3, 3)] += 15.0;
    let mut t = DMatrix::zeros(4, 3);
    t[(0, 0)] = 1.0;
    t[(1, 1)] = 1.0;
    t[(2, 1)] = 1.0 / 3.7;
    t[(3, 2)] = 1.0;
    [m, k, d, t]
}

#[test]
fn a_rigid_gear_reduces_the_line_by_its_constraint() {
    let s = line("").unwrap();
    assert_eq!(s.model.dof_names(), ["motor", "pinion", "drum"]);
    let [m, k, d, t] = full_and_t();
    let dense = s.model.dense("test").unwrap();
    for (name, got, full) in [
        ("M", &dense.mass, m),
        ("K", &dense.stiffness, k),
        ("D", &dense.damping, d),
    ] {
        let want = t.transpose() * full * &t;
        let scale = want.amax();
        assert!(
            (got - &want).amax() < 1e-15 * scale,
            "{name}:\n{got}\nvs\n{want}"
        );
    }
    // One rigid mode: the whole line turning with the gear's ratio, held by the drum damper.
    let f = hbal::analysis::linear_frequencies(&s).unwrap();
    assert_eq!(f.rigid, 1);
    // A chain of two gears and two pinions on one wheel (the second pinion follows the first).
    let two = Scene::from_str(
        &format!(
            "{HEAD}{}",
            LINE.replace(
                "gears = [",
                "gears = [{ driving = \"extra\", driven = \"wheel\", radii = [2.0, 7.4] }, "
            )
            .replace(
                "disks = [",
                "disks = [{ name = \"extra\", inertia = 0.02 },"
            )
        ),
        "two.toml",
    )
    .unwrap();
    // extra turns as the pinion (same ratio 3.7 onto the wheel): joined into it, its inertia added.
    assert_eq!(two.model.dof_names(), ["extra", "motor", "drum"]);
    let m2 = two.model.dense("test").unwrap().mass;
    assert!((m2[(0, 0)] - (0.02 + 0.01 + 0.3 / (3.7 * 3.7))).abs() < 1e-15);
}

/// A load on a removed disk acts on the disk it follows, times the factor (the same virtual
/// work); another table naming it is told where it went.
#[test]
fn loads_on_a_removed_disk_move_to_the_disk_it_follows() {
    let text = format!("{HEAD}{LINE}").replace(
        "loads = [{ dof = \"motor\", order = 1, cos = 10.0 }]",
        "loads = [{ dof = \"wheel\", order = 1, cos = 10.0, sin = -4.0 }]",
    );
    let s = Scene::from_str(&text, "moved.toml").unwrap();
    let l = &s.model.loads()[0];
    assert_eq!(s.model.dof_names()[l.dof], "pinion");
    assert_eq!((l.cos, l.sin), (10.0 * (1.0 / 3.7), -4.0 * (1.0 / 3.7)));
    let engine = text.replacen(
        "\n[line]",
        "\n[engine]\ndof = \"wheel\"\ncylinders = 1\norders = [{ order = 1, amplitude = 1.0 }]\n[line]",
        1,
    );
    let err = Scene::from_str(&engine, "engine.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("a rigid gear removed `wheel`") && err.contains("`pinion`"),
        "{err}"
    );
}

/// `modal_damping`: `Φᵀ D Φ = diag(2 ζ_r ω_r)` over the elastic modes, none on the rigid one.
#[test]
fn modal_damping_gives_each_mode_its_ratio() {
    let no_damping = LINE
        .replace(", damping = 2.0", "")
        .replace(", damping = 3.0", "")
        .replace(", damping = 15.0", "");
    for (ratios, zetas) in [("0.02", [0.02, 0.02]), ("[0.01, 0.05]", [0.01, 0.05])] {
        let text = format!("{HEAD}{no_damping}modal_damping = {ratios}\n");
        let s = Scene::from_str(&text, "modal.toml").unwrap();
        let dense = s.model.dense("test").unwrap();
        let (m, k, d) = (&dense.mass, &dense.stiffness, &dense.damping);
        let l = m.clone().cholesky().unwrap().l();
        let li = l.clone().try_inverse().unwrap();
        let e = (&li * k * li.transpose()).symmetric_eigen();
        let mut order: Vec<usize> = (0..3).collect();
        order.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
        for (j, &r) in order.iter().enumerate() {
            let phi = li.transpose() * e.eigenvectors.column(r);
            let modal = (phi.transpose() * d * &phi)[(0, 0)];
            let want = if j == 0 {
                0.0
            } else {
                2.0 * zetas[j - 1] * e.eigenvalues[r].sqrt()
            };
            assert!(
                (modal - want).abs() < 1e-9 * want.max(1.0),
                "{ratios} mode {j}: {modal} vs {want}"
            );
        }
    }
}

#[test]
fn bad_gears_and_modal_damping_are_named() {
    for (extra, replace, path, words) in [
        (
            "",
            ("ratio = 3.7", "ratio = -3.7"),
            "line.gears[0].ratio",
            "> 0",
        ),
        (
            "",
            ("ratio = 3.7", "ratio = nan"),
            "line.gears[0].ratio",
            "finite",
        ),
        (
            "",
            ("ratio = 3.7", "ratio = 3.7, radii = [1.0, 3.7]"),
            "line.gears[0]",
            "one of them",
        ),
        (
            "",
            ("driven = \"wheel\"", "driven = \"wheeel\""),
            "line.gears[0].driven",
            "unknown disk `wheeel`",
        ),
        (
            "",
            ("driven = \"wheel\"", "driven = \"pinion\""),
            "line.gears[0].driven",
            "with itself",
        ),
        (
            "",
            (
                "ratio = 3.7 }]",
                "ratio = 3.7 }, { driving = \"pinion\", driven = \"wheel\", ratio = 2.0 }]",
            ),
            "line.gears[1].ratio",
            "ratios disagree",
        ),
        (
            "",
            (
                "name = \"motor\", inertia = 0.2",
                "name = \"motor\", inertia = 0.0",
            ),
            "line.disks[0].inertia",
            "no inertia",
        ),
        (
            "modal_damping = -0.1\n",
            ("", ""),
            "line.modal_damping",
            ">= 0",
        ),
        (
            "modal_damping = [0.1]\n",
            ("", ""),
            "line.modal_damping",
            "2 elastic modes",
        ),
        (
            "modal_damping = 0.02\n[[elements]]\nname = \"s\"\ntype = \"linear_spring\"\nconnects = { motor = 1.0 }\nk = 1.0\n",
            ("", ""),
            "line.modal_damping",
            "1 element(s) that change its modes",
        ),
    ] {
        let text = format!("{HEAD}{}{extra}", LINE.replace(replace.0, replace.1));
        let text = if replace.0.is_empty() {
            format!("{HEAD}{LINE}{extra}")
        } else {
            text
        };
        let err = Scene::from_str(&text, "bad.toml").unwrap_err().to_string();
        assert!(
            err.contains(&format!("{path}:")) && err.contains(words),
            "{path}: {err}"
        );
    }
}
