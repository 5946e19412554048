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

/// Elements with an offset are written as their law's fields plus `offset` and read back to
/// the same laws and the same solution.
#[test]
fn elements_with_an_offset_round_trip() {
    use hbal::force::{GapContact, LinearSpring, Offset, Stage, StopSpring};
    let model = Model::builder(&["a", "b"])
        .mass_diagonal(&[1.0, 0.5])
        .damping(hbal::nalgebra::DMatrix::from_diagonal_element(2, 2, 0.05))
        .element(
            "shaft",
            &[("a", 1.0), ("b", -1.0)],
            LinearSpring::new(2.0, 0.0),
        )
        .element(
            "preloaded",
            &[("b", 1.0)],
            Offset::new(-0.02, LinearSpring::new(3.0, 0.1)),
        )
        .element(
            "stop",
            &[("a", 1.0)],
            Offset::new(0.25, GapContact::new(0.5, 40.0).with_contact_damping(0.2)),
        )
        .element(
            "twice",
            &[("a", -1.0)],
            Offset::new(
                0.5,
                Offset::new(
                    0.25,
                    StopSpring::new(vec![Stage {
                        from: 0.1,
                        stiffness: 5.0,
                    }]),
                ),
            ),
        )
        .load("a", 1, 1.5, 0.0)
        .build()
        .unwrap();
    let dir = std::env::temp_dir().join(format!("hbal-export-offset-{}", std::process::id()));
    let file = dir.join("offsets.toml");
    write_scene(
        &model,
        &SceneSettings::new("offsets", "rad_s", 1.3, 24),
        &file,
    )
    .unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    let scene = Scene::load(&file).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(text.matches("offset = ").count(), 3, "{text}");
    assert!(!text.contains("law"), "{text}");
    for (a, b) in scene.model.elements().iter().zip(model.elements()) {
        assert_eq!(a.linear_part(), b.linear_part(), "{}", a.name());
        assert_eq!(a.law().kinks(), b.law().kinks(), "{}", a.name());
        for u in [-1.0, -0.3, 0.1, 0.6, 0.8, 1.2] {
            assert_eq!(
                a.law().force(0.3, u, 0.4),
                b.law().force(0.3, u, 0.4),
                "{} at {u}",
                a.name()
            );
        }
    }
    let basis = HarmonicBasis::new(1.3, 24).unwrap();
    let (a, b) = (solve(&scene.model, basis), solve(&model, basis));
    assert!(relative_error(a.harmonics(), b.harmonics(), 2, 24) < 1e-12);
    assert!(a.max_abs(0) > 0.75, "{}", a.max_abs(0)); // in contact with the stop at 0.75
}
