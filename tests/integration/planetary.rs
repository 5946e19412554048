//! The planetary set element (`hbal::model::PlanetarySet`, scenes' `type = "planetary"`):
//! against the time-domain reference, its static load sharing and torque ratio, the
//! cancellation of sequential mesh phasing, on the torus with a motor ripple, and bad input.

use hbal::analysis::{solve, torus_solve, SolveSettings, TorusSolveSettings};
use hbal::num_complex::Complex64;
use hbal::scene::Scene;

fn scene_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/planetary_set.toml"
    ))
    .unwrap()
}

const RS: f64 = 0.02936539439955964;

/// The scene without the motor ripple, on one fundamental: the mesh.
fn mesh_only(text: &str) -> String {
    let t = text
        .replace("  { dof = \"motor\", order = 1, cos = 2.0 },\n", "")
        .replace("  { dof = \"motor\", order = 2, sin = 1.5 },\n", "")
        .replace(
            "fundamental = { rpm = 3000 }",
            "fundamental = { rpm = 3000, order = 18.489583333333332 }",
        )
        .replace("harmonics = { count = 8 }", "harmonics = { count = 12 }");
    assert!(
        !t.contains("order = 2, sin") && t.contains("count = 12"),
        "the scene changed"
    );
    t
}

/// The mesh-frequency response of the planetary set against the time-domain reference run to
/// steady state (started on the HB orbit; the free rotation's drift aside): every DOF's
/// harmonics to 1e-7 of the response.
#[test]
fn planetary_set_equals_the_time_domain_reference() {
    let scene = Scene::from_str(&mesh_only(&scene_text()), "planetary.toml").unwrap();
    assert!(scene.torus.is_none(), "the mesh is the fundamental");
    let (model, omega) = (&scene.model, scene.basis.omega());
    let x = crate::common::time_domain::hb(model, omega, 12);
    let td = crate::common::time_domain::time_domain_to(model, omega, &x, 1e-10);
    let e = hbal::compare::model_relative_error(model, &x, &td, 24);
    assert!(e < 1e-7, "HB against the time domain: {e:e}");
    // The analysis (Newton at the scene's tolerance) gives the same orbit.
    let a = solve(&scene, &SolveSettings::default()).unwrap();
    assert!(a.solution.is_converged());
    let n = model.n_dofs();
    let worst = (n..13 * n)
        .map(|i| (a.solution.harmonics()[i] - x[i]).norm())
        .fold(0.0, f64::max);
    let top = (n..13 * n).map(|i| x[i].norm()).fold(0.0, f64::max);
    assert!(worst < 1e-8 * top, "{worst:e} of {top:e}");
}

/// The mean forces: every sun mesh carries `T / (N r_s)`, every ring mesh the same (a planet
/// floats between them), and the carrier turns out `T (1 + z_r / z_s)` (the output's load
/// balances it, or the free-free balance would refuse the scene).
#[test]
fn planets_share_the_load_and_the_carrier_carries_the_ratio() {
    let scene = Scene::from_str(&scene_text(), "planetary.toml").unwrap();
    let plan = scene
        .torus
        .as_ref()
        .expect("motor ripple and mesh: the torus");
    assert_eq!(plan.bases.names(), ["shaft", "planetary"]);
    assert_eq!(
        plan.bindings.len(),
        6,
        "the six meshes follow the planetary base"
    );
    let a = torus_solve(&scene, &TorusSolveSettings::default()).unwrap();
    assert!(a.converged, "{}", a.relative_residual);
    let share = 50.0 / (3.0 * RS);
    for f in &a.forces {
        assert!(
            (f.mean - share).abs() < 1e-8 * share,
            "{}: {} vs {share}",
            f.name,
            f.mean
        );
    }
    // Sequential phasing: the sun meshes' first mesh harmonic a third of a cycle apart.
    let phase = |e: usize| {
        a.forces[e]
            .lines
            .iter()
            .find(|l| l.k == [0, 1])
            .unwrap()
            .phase
            .to_degrees()
    };
    for (e, want) in [(0, 0.0), (1, -120.0), (2, 120.0)] {
        let d = (phase(e) - phase(0) - want + 540.0).rem_euclid(360.0) - 180.0;
        assert!(
            d.abs() < 1e-6,
            "sun mesh {e}: {} vs {want}",
            phase(e) - phase(0)
        );
    }
}

/// Sequential phasing (z_s / N = 25/3 not whole) cancels the sun's rotation at the first
/// mesh harmonic; in-phase planets (24/72) excite it (Parker & Lin 2004).
#[test]
fn sequential_phasing_cancels_the_first_mesh_harmonic_on_the_sun() {
    let sun_line = |text: &str, l: usize| {
        let scene = Scene::from_str(&mesh_only(text), "planetary.toml").unwrap();
        assert!(scene.torus.is_none());
        let a = solve(&scene, &SolveSettings::default()).unwrap();
        assert!(a.solution.is_converged());
        a.solution.harmonic(1, l).norm()
    };
    let c = (20f64).to_radians().cos();
    let in_phase = scene_text()
        .replace("teeth = [25, 71]", "teeth = [24, 72]")
        .replace(
            "base_radii = [0.02936539439955964, 0.02701616284759487, 0.08339772009474937]",
            &format!("base_radii = [{}, {}, {}]", 0.03 * c, 0.03 * c, 0.09 * c),
        )
        .replace("cos = -192.0", "cos = -200.0");
    let sequential = (sun_line(&scene_text(), 1), sun_line(&scene_text(), 3));
    let in_phase = mesh_only(&in_phase).replace("order = 18.489583333333332", "order = 18.0");
    let scene = Scene::from_str(&in_phase, "p.toml").unwrap();
    let a = solve(&scene, &SolveSettings::default()).unwrap();
    let (first, third) = (
        a.solution.harmonic(1, 1).norm(),
        a.solution.harmonic(1, 3).norm(),
    );
    assert!(first > 1e-8, "{first:e}");
    // The first harmonic cancels to rounding; the third (3 z_s / N = 25, whole) does not
    // (measured 4.6e-10 rad, against 3.4e-8 rad for the in-phase set's first).
    assert!(sequential.0 < 1e-9 * first, "{sequential:?} vs {first:e}");
    assert!(
        sequential.1 > 1e-2 * third && sequential.1 > 1e6 * sequential.0,
        "{sequential:?} vs {third:e}"
    );
}

/// Forced onto the torus at the mesh's own order, the set shares the first base (equal
/// ratios) and its dependent mesh coordinates are solved in the receptance form: the same
/// harmonics as the one-frequency engine.
#[test]
fn the_torus_in_receptance_form_equals_the_one_frequency_engine() {
    let one_text = mesh_only(&scene_text());
    let one = Scene::from_str(&one_text, "p.toml").unwrap();
    let torus_text = one_text.replace(
        "harmonics = { count = 12 }",
        "harmonics = { bases = \"torus\", caps = { shaft = 12 }, grid = { shaft = 64 } }",
    );
    let torus = Scene::from_str(&torus_text, "p.toml").unwrap();
    assert_eq!(torus.torus.as_ref().unwrap().bases.names(), ["shaft"]);
    let t = torus_solve(&torus, &TorusSolveSettings::default()).unwrap();
    let s = solve(&one, &SolveSettings::default()).unwrap();
    assert!(t.converged);
    let n = one.model.n_dofs();
    let mut worst = 0.0f64;
    for (j, k) in t.solution.indices.iter().enumerate().skip(1) {
        for i in 0..n {
            let (re, im) = t.solution.harmonics[j * n + i];
            worst =
                worst.max((Complex64::new(re, im) - s.solution.harmonic(i, k[0] as usize)).norm());
        }
    }
    let scale = (n..13 * n)
        .map(|i| s.solution.harmonics()[i].norm())
        .fold(0.0, f64::max);
    assert!(scale > 1e-9, "{scale:e}");
    assert!(worst < 1e-9 * scale, "{worst:e} of {scale:e}");
}

#[test]
fn bad_planetary_input_names_the_field() {
    let text = scene_text();
    let cases = [
        (
            text.replace("teeth = [25, 71]", "teeth = [25, 70]"),
            "(z_s + z_r) / N = 95/3 must be whole",
        ),
        (
            text.replace(
                "\"planet2\", \"planet3\"]\nteeth",
                "\"planet2\", \"planet9\"]\nteeth",
            ),
            "elements[0].planets[2]: unknown DOF `planet9`",
        ),
        (
            text.replace("sun = \"sun\"", "sun = \"sun\"\nconnects = { sun = 1.0 }"),
            "elements[0].connects: a planetary set names its DOFs",
        ),
        (
            text.replace("teeth = [25, 71]", "teeth = [25, 71]\nbase = \"shaft\""),
            "elements[0].base: a gear stage or planetary set follows its own mesh",
        ),
        (
            text.replace("0.08339772009474937]", "0.02]"),
            "elements[0].base_radii[2]",
        ),
        (
            text.replace("carrier = \"carrier\"", "carrier = \"sun\""),
            "DOF `sun` is named twice",
        ),
    ];
    for (scene, want) in cases {
        assert_ne!(scene, text, "{want}");
        let err = Scene::from_str(&scene, "bad.toml").unwrap_err().to_string();
        assert!(err.contains(want), "{want}: {err}");
    }
}

/// `hbal modes` of the set on the torus: the mesh's order of the speed (18.49), not its
/// harmonic of its own base.
#[test]
fn modes_on_the_torus_name_the_mesh_order() {
    let text = scene_text()
        .replace("  { dof = \"motor\", order = 1, cos = 2.0 },\n", "")
        .replace("  { dof = \"motor\", order = 2, sin = 1.5 },\n", "");
    let scene = Scene::from_str(&text, "p.toml").unwrap();
    assert!(scene.torus.is_some());
    let a = hbal::analysis::modes(&scene, &hbal::analysis::ModesSettings::default()).unwrap();
    assert_eq!(a.orders.len(), 1, "{:?}", a.orders);
    assert!(
        (a.orders[0] - 25.0 * 71.0 / 96.0).abs() < 1e-12,
        "{:?}",
        a.orders
    );
}
