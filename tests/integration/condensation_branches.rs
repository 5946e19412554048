//! The exact condensation along branches: continuation and parameter sweeps give the same
//! points as the full formulation, the `--formulation` switch of the command line, and the
//! points after a turn are solutions at their own speed.

use crate::common;
use crate::condensation::chain;
use hbal::compare::relative_error;
use hbal::nalgebra::DMatrix;
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Model, Newton};

/// A sweep of the chain with stability in the condensed formulation: every point is the
/// full formulation's solution at its Ω (to 1e-8), both branches end at the same orbit with
/// the same multipliers. (The steps differ: the step length is measured in the unknowns.)
#[test]
fn condensed_continuation_equals_full() {
    let model = chain();
    let basis = HarmonicBasis::new(250.0, 12).unwrap();
    let run = |formulation| {
        hbal::continuation::Continuation {
            formulation,
            max_points: 60,
            ..Default::default()
        }
        .run(&model, basis, 300.0, |_| {})
        .unwrap()
    };
    let (full, cond) = (run(Formulation::Full), run(Formulation::Condensed));
    assert!(full.stop.is_normal_end() && cond.stop.is_normal_end());
    assert!(cond.points.len() > 5, "{} points", cond.points.len());
    for p in &cond.points {
        let hb = HarmonicBalance::new(&model, basis.with_omega(p.omega).unwrap()).unwrap();
        let sol = Newton::new()
            .with_tolerance(1e-13)
            .unwrap()
            .solve_from(&hb, &p.harmonics, &mut hb.workspace())
            .unwrap();
        let d = relative_error(&p.harmonics, sol.harmonics(), 7, 12);
        assert!(
            d < 1e-8,
            "condensed point at Ω = {}: {d:.1e} from the full solution",
            p.omega
        );
    }
    let (a, b) = (full.points.last().unwrap(), cond.points.last().unwrap());
    assert!((a.omega - b.omega).abs() < 1e-9 * a.omega);
    assert!(relative_error(&b.harmonics, &a.harmonics, 7, 12) < 1e-8);
    let (fa, fb) = (a.floquet.as_ref().unwrap(), b.floquet.as_ref().unwrap());
    assert!((fa.max_abs() - fb.max_abs()).abs() < 1e-6, "multipliers");
}

/// `hbal solve --formulation condensed|full`: the same max |q| per DOF; a bad value exits 2.
#[test]
fn cli_formulation_switch() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/chain_backlash.toml"
    );
    let max_abs = |f: &str| -> Vec<f64> {
        let out = common::hbal(&["solve", scene, "--formulation", f, "--json"]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        json["dofs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d["max_abs"].as_f64().unwrap())
            .collect()
    };
    let (full, cond) = (max_abs("full"), max_abs("condensed"));
    assert_eq!(full.len(), 3);
    for (a, b) in full.iter().zip(&cond) {
        assert!((a - b).abs() < 1e-9 * a.abs(), "{a} vs {b}");
    }
    let bad = common::hbal(&["solve", scene, "--formulation", "sparse"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("expected `full`, `condensed` or `auto`"));
}

/// A parameter sweep (the mesh's load amplitude here: the engine torque's first order) in the
/// condensed formulation gives the full formulation's points to 1e-10, all DOFs.
#[test]
fn condensed_parameter_sweep_equals_full() {
    let basis = HarmonicBasis::new(300.0, 12).unwrap();
    let build = |p: f64| {
        // The chain with its engine torque scaled by p (loads add up on a DOF).
        let model = chain();
        let names: Vec<&str> = model.dof_names().iter().map(String::as_str).collect();
        let mut builder = Model::builder(&names)
            .mass(model.mass().to_dense())
            .stiffness(model.structural_stiffness().to_dense())
            .damping(model.structural_damping().to_dense());
        for e in model.elements() {
            let w: Vec<(&str, f64)> = e.weights().iter().map(|&(i, w)| (names[i], w)).collect();
            let law: Box<dyn hbal::force::ForceLaw> =
                serde_json::from_value(serde_json::to_value(e.law()).unwrap()).unwrap();
            builder = builder.element_boxed(e.name(), &w, law);
        }
        for l in model.loads() {
            let s = if l.order == 1 { p } else { 1.0 };
            builder = builder.load(names[l.dof], l.order, s * l.cos, s * l.sin);
        }
        Ok((builder.build()?, basis))
    };
    let values = [0.5, 0.75, 1.0, 1.25];
    let sweep = |formulation| {
        hbal::continuation::parameter_sweep(&values, build, None, formulation, |_| {}).unwrap()
    };
    let (full, cond) = (sweep(Formulation::Full), sweep(Formulation::Condensed));
    assert_eq!(full.points.len(), 4);
    assert_eq!(cond.points.len(), 4);
    for (a, b) in full.points.iter().zip(&cond.points) {
        let d = relative_error(&b.harmonics, &a.harmonics, 7, 12);
        assert!(d < 1e-10, "at p = {}: {d:.1e}", a.parameter);
    }
    // The points differ: the engine's first harmonic grows with its load (2.5 times the load).
    let first = |k: usize| full.points[k].harmonics[7].norm();
    let ratio = first(3) / first(0);
    assert!(ratio > 1.5 && ratio < 4.0, "{ratio}");
}

/// A condensed sweep through the folds of a hardening three-mass chain (a cubic spring at the
/// first mass): every point, the ones right after a located turn too, is the full formulation's
/// solution at its Ω (locating a turn moves the condensation to other Ω; the point's DOFs are
/// recovered at its own).
#[test]
fn condensed_points_after_a_turn_are_solutions_at_their_speed() {
    let stiffness =
        DMatrix::from_row_slice(3, 3, &[2.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 1.0]);
    let model = Model::builder(&["x1", "x2", "x3"])
        .mass_diagonal(&[1.0, 1.0, 1.0])
        .damping(&stiffness * 0.02)
        .stiffness(stiffness)
        .element(
            "cubic",
            &[("x1", 1.0)],
            hbal::force::CubicSpring::new(0.0, 1.0),
        )
        .load("x1", 1, 0.05, 0.0)
        .build()
        .unwrap();
    let basis = HarmonicBasis::new(0.3, 5).unwrap();
    let branch = hbal::continuation::Continuation {
        formulation: Formulation::Condensed,
        stability: None,
        max_step: 0.2,
        ..Default::default()
    }
    .run(&model, basis, 0.8, |_| {})
    .unwrap();
    assert!(branch.stop.is_normal_end(), "{}", branch.stop);
    let turns = branch
        .points
        .iter()
        .filter(|p| p.fold_omega.is_some())
        .count();
    assert!(turns >= 2, "{turns} turns");
    for p in &branch.points {
        let hb = HarmonicBalance::with_formulation(
            &model,
            basis.with_omega(p.omega).unwrap(),
            Formulation::Full,
        )
        .unwrap();
        let sol = Newton::new()
            .with_tolerance(1e-13)
            .unwrap()
            .solve_from(&hb, &p.harmonics, &mut hb.workspace())
            .unwrap();
        let d = relative_error(&p.harmonics, sol.harmonics(), 3, 5);
        assert!(
            d < 1e-8,
            "point at Ω = {}: {d:.1e} from the full solution",
            p.omega
        );
    }
}
