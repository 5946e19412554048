//! A model written as a scene (TOML + Matrix Market files) reads back to the same model: the
//! drivetrain benchmark's solution from the written scene equals the one from the generator's
//! model, and bad targets give errors that name the file.

use hbal::catalog::Drivetrain;
use hbal::compare::relative_error;
use hbal::scene::export::{write_scene, SceneSettings};
use hbal::scene::Scene;
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Model, Newton, Solution};

fn solve(model: &Model, basis: HarmonicBasis) -> Solution {
    let hb = HarmonicBalance::with_formulation(model, basis, Formulation::Condensed).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-11)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    sol
}

#[test]
fn the_drivetrain_scene_reads_back_to_the_same_solution() {
    let d = Drivetrain::default().coarse_teeth(4).unwrap().with_dofs(60);
    let model = d.model().unwrap();
    let dir = std::env::temp_dir().join(format!("hbal-scene-export-{}", std::process::id()));
    let file = dir.join("drivetrain.toml");
    let mut settings = SceneSettings::new("drivetrain", "rpm", 3000.0, 16);
    settings.order = 0.5;
    write_scene(&model, &settings, &file).unwrap();
    let scene = Scene::load(&file).unwrap();
    std::fs::remove_dir_all(&dir).ok();

    assert_eq!(scene.model.dof_names(), model.dof_names());
    assert_eq!(scene.model.elements().len(), model.elements().len());
    assert_eq!(scene.model.loads().len(), model.loads().len());
    for (a, b) in scene.model.elements().iter().zip(model.elements()) {
        assert_eq!(a.name(), b.name());
        let sorted = |w: &[(usize, f64)]| {
            let mut w = w.to_vec();
            w.sort_by_key(|&(i, _)| i);
            w
        };
        assert_eq!(sorted(a.weights()), sorted(b.weights()));
    }
    // Symmetric storage keeps the lower triangle: the matrices agree to the assembly's
    // rounding asymmetry.
    let k = model.structural_stiffness();
    let diff = scene
        .model
        .structural_stiffness()
        .iter()
        .map(|(i, j, v)| (v - k.get(i, j)).abs())
        .fold(0.0, f64::max);
    assert!(diff <= 1e-12 * k.amax(), "{diff:e}");
    assert_eq!(scene.model.mass().to_dense(), model.mass().to_dense());

    let omega = d.fundamental(3000.0);
    assert!((scene.basis.fundamental() - omega).abs() <= 1e-12 * omega);
    let basis = HarmonicBasis::new(omega, 16).unwrap();
    let (a, b) = (solve(&scene.model, basis), solve(&model, basis));
    let e = relative_error(a.harmonics(), b.harmonics(), model.n_dofs(), 16);
    assert!(e < 1e-10, "{e:e}");
    assert!(a.max_abs(0) > 1e-3);
}

#[test]
fn an_unwritable_target_names_the_file() {
    let model = Drivetrain::default().with_dofs(20).model().unwrap();
    let settings = SceneSettings::new("x", "rpm", 2000.0, 8);
    // A directory that cannot be created: its parent is a file.
    let blocker = std::env::temp_dir().join(format!("hbal-export-blocker-{}", std::process::id()));
    std::fs::write(&blocker, "").unwrap();
    let err = write_scene(&model, &settings, &blocker.join("scene.toml")).unwrap_err();
    std::fs::remove_file(&blocker).ok();
    let text = err.to_string();
    assert!(
        text.contains("hbal-export-blocker") && text.contains("cannot write"),
        "{text}"
    );
}
