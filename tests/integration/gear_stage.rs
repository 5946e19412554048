//! The `gear_stage` element: its sign convention (every angle positive in its running
//! direction, `u = r_b1 θ1 - r_b2 θ2`, drive torques positive, load torques negative) checked
//! on closed-form static solutions, its equality with the generic mesh element it builds, and
//! its bad input.

use crate::common;

use hbal::force::{MeshDamping, MeshProfile, MeshStiffness};
use hbal::model::GearStage;
use hbal::nalgebra::DMatrix;
use hbal::scene::Scene;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton, Solution};

fn solve(model: &Model, omega: f64, h: usize) -> Solution {
    let hb = HarmonicBalance::new(model, HarmonicBasis::new(omega, h).unwrap()).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-13)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    sol
}

/// A pinion (free) driving a gear held by a shaft of stiffness `k_g` to ground, with a
/// constant mesh stiffness `k` and drive torque `T`: the pinion's balance gives the mesh force
/// `f = T / r1`, the gear's `k_g θ2 = r2 f`, the mesh `u = r1 θ1 - r2 θ2 = f / k` (> 0: drive
/// flanks loaded), with backlash `u = B/2 + f/k`.
#[test]
fn static_mesh_force_and_transmission_error_have_the_documented_signs() {
    let (r1, r2, k, kg, t) = (0.02, 0.05, 4e8, 3e4, 50.0);
    for backlash in [None, Some(1e-4)] {
        let mut stage = GearStage::new(
            "pinion",
            "gear",
            [r1, r2],
            20,
            MeshProfile::Constant { stiffness: k },
        );
        if let Some(b) = backlash {
            stage = stage.with_backlash(b);
        }
        // The pinion is held by a very soft spring so the static problem is regular; it takes
        // a negligible part of T (checked in the tolerance).
        let soft = 1e-6;
        let model = Model::builder(&["pinion", "gear"])
            .mass_diagonal(&[1e-3, 6e-3])
            .stiffness(DMatrix::from_diagonal(&hbal::nalgebra::DVector::from_vec(
                vec![soft, kg],
            )))
            .gear_stage("mesh", stage)
            .load("pinion", 0, t, 0.0)
            .build()
            .unwrap();
        let sol = solve(&model, 100.0, 4);
        let (th1, th2) = (sol.harmonic(0, 0).re, sol.harmonic(1, 0).re);
        let f = t / r1;
        let u = r1 * th1 - r2 * th2;
        let expected_u = f / k + backlash.map_or(0.0, |b| 0.5 * b);
        assert!(th2 > 0.0, "the driven gear turns forward: {th2}");
        assert!(
            (th2 - r2 * f / kg).abs() < 1e-8 * th2,
            "{th2} vs {}",
            r2 * f / kg
        );
        assert!(
            u > 0.0 && (u - expected_u).abs() < 1e-8 * expected_u,
            "{u} vs {expected_u}"
        );
    }
}

/// A stage given by `ratio = i` acts on `u = θ1 - i θ2` with a torsional stiffness: the same
/// physics as base radii `(r, i r)` with the stiffness `k_t / r²`.
#[test]
fn ratio_form_equals_radii_form() {
    let (r, i, kt) = (0.03, 2.5, 2e5);
    let build = |stage: GearStage| {
        Model::builder(&["a", "b"])
            .mass_diagonal(&[2e-3, 1e-2])
            .stiffness(DMatrix::from_diagonal_element(2, 2, 1e3))
            .damping(DMatrix::from_diagonal_element(2, 2, 0.1))
            .gear_stage("mesh", stage)
            .load("a", 0, 10.0, 0.0)
            .load("a", 1, 2.0, 0.5)
            .build()
            .unwrap()
    };
    let cosine = |mean: f64| MeshProfile::Cosine {
        mean,
        amplitude: 0.2 * mean,
    };
    let mut torsional = GearStage::new("a", "b", [1.0, 1.0], 3, cosine(kt));
    torsional.base_radii = None;
    torsional.ratio = Some(i);
    let torsional = torsional.with_damping(MeshDamping::Proportional(1e-5));
    let linear = GearStage::new("a", "b", [r, i * r], 3, cosine(kt / (r * r)))
        .with_damping(MeshDamping::Proportional(1e-5));
    let (a, b) = (build(torsional), build(linear));
    assert_eq!(a.elements()[0].weights(), &[(0, 1.0), (1, -2.5)]);
    let (sa, sb) = (solve(&a, 150.0, 16), solve(&b, 150.0, 16));
    let scale = sa.max_abs(0);
    for (x, y) in sa.harmonics().iter().zip(sb.harmonics()) {
        assert!((x - y).norm() < 1e-11 * scale, "{x} vs {y}");
    }
}

/// The scene's gear stage builds exactly the generic element `connects = { pinion = r1,
/// gear = -r2 }` with the mesh law; the solutions agree to rounding.
#[test]
fn scene_gear_stage_equals_the_generic_mesh_element() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/two_shaft_gear_pair.toml"
    );
    let staged = Scene::load(std::path::Path::new(path)).unwrap();
    let e = &staged.model.elements()[0];
    assert_eq!(e.weights(), &[(0, 0.02), (1, -0.04)]);
    assert_eq!(e.gear_stage().unwrap().mesh_order(), Some(20));
    let text = std::fs::read_to_string(path).unwrap();
    let start = text.find("[[elements]]").unwrap();
    let end = text.find("[solver]").unwrap();
    let generic = format!(
        "{}[[elements]]\nname = \"mesh\"\ntype = \"mesh_stiffness\"\n\
         connects = {{ pinion = 0.02, gear = -0.04 }}\nteeth = 20\n\
         profile = {{ shape = \"rectangular\", one_tooth = 3e8, two_tooth = 5e8, contact_ratio = 1.6 }}\n\
         damping = {{ proportional = 2e-6 }}\n\n{}",
        &text[..start],
        &text[end..]
    );
    let plain = Scene::from_str(&generic, "generic.toml").unwrap();
    let law = plain.model.elements()[0].law();
    let expected = MeshStiffness::new(
        20,
        MeshProfile::Rectangular {
            one_tooth: 3e8,
            two_tooth: 5e8,
            contact_ratio: 1.6,
        },
        MeshDamping::Proportional(2e-6),
    );
    assert_eq!(format!("{law:?}"), format!("{expected:?}"));
    assert_eq!(format!("{:?}", e.law()), format!("{expected:?}"));
    let basis = HarmonicBasis::new(staged.basis.omega(), 32).unwrap();
    let solve_scene = |m: &Model| {
        let hb = HarmonicBalance::new(m, basis).unwrap();
        Newton::new().solve(&hb, &mut hb.workspace()).unwrap()
    };
    let (a, b) = (solve_scene(&staged.model), solve_scene(&plain.model));
    assert!(a.is_converged() && b.is_converged());
    let worst = a
        .harmonics()
        .iter()
        .zip(b.harmonics())
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-14 * a.max_abs(0), "{worst:e}");
    // The drive flank is loaded: the mean transmission error is positive.
    let u0 = 0.02 * a.harmonic(0, 0).re - 0.04 * a.harmonic(1, 0).re;
    assert!(u0 > 0.0, "{u0}");
}

/// A second stage behind a ratio 2.5 under an engine-speed fundamental runs at
/// `shaft_order = 0.4`: 20 teeth give mesh order 8; 21 teeth (8.4) are refused where the
/// stiffness varies with the mesh cycle, accepted where it is constant (no mesh order).
#[test]
fn shaft_order_sets_the_mesh_order() {
    let cosine = MeshProfile::Cosine {
        mean: 1e8,
        amplitude: 1e7,
    };
    let stage = GearStage::new("a", "b", [0.02, 0.05], 20, cosine).with_shaft_order(0.4);
    assert_eq!(stage.mesh_order(), Some(8));
    let mut bad = stage.clone();
    bad.teeth = 21;
    assert_eq!(bad.mesh_order(), None);
    let err = bad.validate("gear stage `s2`").unwrap_err().to_string();
    assert!(
        err.contains("shaft_order") && err.contains("21 x 0.4"),
        "{err}"
    );
    bad.stiffness = MeshProfile::Constant { stiffness: 1e8 };
    assert_eq!(bad.validate("gear stage `s2`"), Ok(()));
    // A constant stiffness builds its law with one cycle per period, whatever the teeth: a
    // whole mesh order above the resolvable 65536 (60000 x 3) is no error (review finding).
    let mut many = bad.clone();
    many.teeth = 60000;
    many.shaft_order = 3.0;
    assert_eq!(many.validate("gear stage `s3`"), Ok(()));
    let model = Model::builder(&["a", "b"])
        .mass_diagonal(&[1e-3, 6e-3])
        .stiffness(DMatrix::from_diagonal_element(2, 2, 1e4))
        .gear_stage("s3", many)
        .build();
    assert!(model.is_ok(), "{model:?}");
}

/// A true ratio (the marine line's 9.4094) with a constant mesh stiffness behind a first
/// stage (`shaft_order = 1/9.4094`, no whole mesh order): accepted, and the static solution
/// is the closed form. The pinion drives with `T` against a shaft `k_g` holding the gear:
/// `k_g θ2 = i T`, `θ1 − i θ2 = T / k` (torsional stiffness on the pinion side).
#[test]
fn a_true_ratio_with_constant_stiffness_is_accepted() {
    let (i, k, kg, t) = (9.4094, 5e6, 3e7, 40.0);
    let mut stage = GearStage::new(
        "a",
        "b",
        [1.0, 1.0],
        17,
        MeshProfile::Constant { stiffness: k },
    )
    .with_shaft_order(1.0 / 9.4094);
    stage.base_radii = None;
    stage.ratio = Some(i);
    assert_eq!(stage.mesh_order(), None);
    let soft = 1e-6;
    let model = Model::builder(&["a", "b"])
        .mass_diagonal(&[1e-2, 3.0])
        .stiffness(DMatrix::from_diagonal(&hbal::nalgebra::DVector::from_vec(
            vec![soft, kg],
        )))
        .gear_stage("reduction", stage)
        .load("a", 0, t, 0.0)
        .build()
        .unwrap();
    let sol = solve(&model, 50.0, 4);
    let (th1, th2) = (sol.harmonic(0, 0).re, sol.harmonic(1, 0).re);
    assert!((th2 - i * t / kg).abs() < 1e-8 * th2, "{th2}");
    assert!(
        ((th1 - i * th2) - t / k).abs() < 1e-8 * t / k,
        "{th1} {th2}"
    );
}

const GOOD: &str = r#"
dofs = ["pinion", "gear"]
mass = [[1e-3, 0.0], [0.0, 4e-3]]
stiffness = [[1e4, 0.0], [0.0, 4e4]]
fundamental = { rpm = 3000 }
harmonics = { count = 8, bases = "one" }
loads = [{ dof = "pinion", order = 0, cos = 20.0 }]
[[elements]]
name = "mesh"
type = "gear_stage"
driving = "pinion"
driven = "gear"
base_radii = [0.02, 0.04]
teeth = 2
stiffness = { shape = "constant", stiffness = 3e8 }
"#;

#[test]
fn bad_gear_stages_name_the_element_and_field() {
    assert!(Scene::from_str(GOOD, "good.toml").is_ok());
    let cases = [
        (
            "base_radii = [0.02, 0.04]",
            "base_radii = [0.02, -0.04]",
            "elements[0].base_radii[1]",
            "finite and > 0",
        ),
        (
            "base_radii = [0.02, 0.04]",
            "base_radii = [0.02, 0.04]\nratio = 2.0",
            "elements[0]",
            "exactly one of `base_radii` and `ratio`",
        ),
        (
            "base_radii = [0.02, 0.04]",
            "",
            "elements[0]",
            "exactly one of `base_radii` and `ratio`",
        ),
        (
            "driven = \"gear\"",
            "driven = \"pinion\"",
            "elements[0]",
            "same DOF `pinion`",
        ),
        (
            "driven = \"gear\"",
            "driven = \"wheel\"",
            "elements[0].driven",
            "unknown DOF `wheel`",
        ),
        (
            "stiffness = { shape = \"constant\", stiffness = 3e8 }",
            "stiffness = { shape = \"cosine\", mean = 3e8, amplitude = 3e7 }\nshaft_order = 0.3",
            "elements[0].shaft_order",
            "whole multiple",
        ),
        ("teeth = 2", "teeth = 0", "elements[0].teeth", "1..=65536"),
        (
            "teeth = 2",
            "teeth = 2\nbacklash = -1e-4",
            "elements[0].backlash",
            ">= 0",
        ),
        (
            "teeth = 2",
            "teeth = 2\nconnects = { pinion = 1.0 }",
            "elements[0].connects",
            "`driving` and `driven`",
        ),
        (
            "teeth = 2",
            "teeth = 2\nradius = 1.0",
            "elements[0].radius",
            "unknown field `radius`",
        ),
    ];
    for (from, to, path, what) in cases {
        let text = GOOD.replace(from, to);
        let err = Scene::from_str(&text, "bad.toml").unwrap_err();
        assert_eq!(err.path.as_deref(), Some(path), "{to}: {err}");
        assert!(err.to_string().contains(what), "{to}: {err}");
    }
    // Exit code 2 from the CLI.
    let dir = std::env::temp_dir().join(format!("hbal-gear-stage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.toml");
    std::fs::write(
        &p,
        GOOD.replace("teeth = 2", "teeth = 2\nshaft_order = 0.3")
            .replace(
                "shape = \"constant\", stiffness = 3e8",
                "shape = \"cosine\", mean = 3e8, amplitude = 3e7",
            ),
    )
    .unwrap();
    let out = common::hbal(&["check", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("elements[0].shaft_order"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Export writes a gear stage back as `type = "gear_stage"`; reading it gives the same stage.
#[test]
fn gear_stage_survives_scene_export() {
    let scene = Scene::from_str(
        &GOOD.replace("teeth = 2", "teeth = 2\nbacklash = 1e-4"),
        "g.toml",
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("hbal-gear-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("stage.toml");
    let settings = hbal::scene::export::SceneSettings::new("stage", "rpm", 3000.0, 8);
    hbal::scene::export::write_scene(&scene.model, &settings, &out).unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("type = \"gear_stage\""), "{text}");
    let back = Scene::load(&out).unwrap();
    assert_eq!(
        back.model.elements()[0].gear_stage(),
        scene.model.elements()[0].gear_stage()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A mesh order beyond any harmonic basis (4e9 teeth) is refused at once, with advice, and
/// allocates nothing on the way (it once aborted allocating 64 GB).
#[test]
fn absurd_tooth_counts_are_refused_with_advice() {
    let text = GOOD.replace("teeth = 2", "teeth = 4000000000").replace(
        "stiffness = { shape = \"constant\", stiffness = 3e8 }",
        "stiffness = { shape = \"rectangular\", one_tooth = 3e8, two_tooth = 5e8, contact_ratio = 1.5 }",
    );
    assert!(text.contains("rectangular"));
    let dir = std::env::temp_dir().join(format!("hbal-teeth-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("teeth.toml");
    std::fs::write(&p, text).unwrap();
    for cmd in ["check", "solve"] {
        let out = common::hbal(&[cmd, p.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd}: {err}");
        assert!(err.contains("more than any harmonic basis holds"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
