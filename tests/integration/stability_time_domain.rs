//! Stability labels against long time integration, for every scene in `examples/scenes/` at
//! three speeds around its own (0.97, 1 and 1.03 times): the time-domain reference starts on the
//! orbit the multipliers belong to, kicked by 1e-3 of its size, and integrates until it is
//! periodic again. A stable orbit is found again (state at a period end within 1e-4 of the
//! orbit's start, relative to the state scales); an unstable one is left for another orbit.
//! On a free-free model the kick is M-orthogonal to the rigid-body modes (those are neutral).

use hbal::continuation::{solve_robustly, Continuation};
use hbal::scene::Scene;
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, HarmonicBasis};
use std::path::Path;

#[test]
fn stability_labels_agree_with_time_integration_for_every_scene() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("toml" | "json")
            )
        })
        .collect();
    files.sort();
    assert!(files.len() >= 9, "{files:?}");
    let mut unstable_seen = 0;
    for file in files {
        let scene = Scene::load(&file).unwrap();
        let model = &scene.model;
        // Hysteretic damping has no time-domain form: no multipliers, no time integration
        // (tests/integration/hysteretic.rs).
        if model.has_hysteretic_damping() {
            continue;
        }
        let n = model.n_dofs();
        for factor in [0.97, 1.0, 1.03] {
            let omega = scene.basis.omega() * factor;
            let basis = HarmonicBasis::new(omega, scene.basis.harmonics())
                .unwrap()
                .with_samples(scene.basis.samples())
                .unwrap();
            let cont = Continuation {
                method: scene.method,
                ..Continuation::default()
            };
            let start = solve_robustly(model, basis, &cont).unwrap();
            let label = format!("{} at {factor} x speed ({})", file.display(), start.how);
            let sol = start.solution;
            assert!(sol.is_converged(), "{label}");
            let floquet = sol.stability(model).unwrap();
            let kick = 1e-3;
            let x0 = &floquet.orbit_start;
            let mut dq: Vec<f64> = (0..n)
                .map(|i| x0[i] * kick + kick * sol.max_abs(i))
                .collect();
            let mut dv: Vec<f64> = (0..n).map(|i| x0[n + i] * kick).collect();
            // A free-free model: the kick leaves the rigid-body modes alone (a rigid kick is
            // neutral, it shifts or drifts the orbit for ever, see src/model/rigid.rs).
            let rigid = HarmonicBalance::new(model, basis)
                .ok()
                .and_then(|hb| hb.rigid_modes().cloned());
            if let Some(rigid) = &rigid {
                rigid.project_motion(&mut dq);
                rigid.project_motion(&mut dv);
            }
            let q: Vec<f64> = (0..n).map(|i| x0[i] + dq[i]).collect();
            let v: Vec<f64> = (0..n).map(|i| x0[n + i] + dv[i]).collect();
            let td = TimeSimulation {
                rtol: 1e-9,
                steady_tolerance: 1e-7,
                max_periods: 3000,
                samples: (4 * basis.harmonics() + 4).next_power_of_two(),
                initial: Some((q, v)),
                ..TimeSimulation::default()
            }
            .run(model, omega)
            .unwrap();
            // The state one period after the steady state against the orbit's start. A motion
            // held only by damping to ground keeps the position the decaying speed kick left
            // (a neutral shift along the orbit family): measured without it.
            let mut shift: Vec<f64> = (0..n).map(|i| td.end_state[i] - x0[i]).collect();
            if let Some(rigid) = &rigid {
                rigid.project_motion(&mut shift);
            }
            let distance = (0..2 * n)
                .map(|i| match i < n {
                    true => shift[i].abs() / td.state_scale[i],
                    false => (td.end_state[i] - x0[i]).abs() / td.state_scale[i],
                })
                .fold(0.0, f64::max);
            let found_again = td.converged && distance < 1e-4;
            assert_eq!(
                floquet.is_stable(),
                found_again,
                "{label}: max |μ| {}, time domain {:?} after {} periods, distance {distance:e}",
                floquet.max_abs(),
                td.stop,
                td.periods
            );
            if !floquet.is_stable() {
                eprintln!("unstable: {label}: max |μ| {}", floquet.max_abs());
            }
            // The clutch damper with friction hysteresis lies in its Neimark–Sacker window at
            // its scene speed (1040 to 1300 rpm): unstable, as the time domain confirms above.
            unstable_seen += usize::from(!floquet.is_stable() && model.memory_element().is_none());
        }
    }
    // From their linear starts these orbits (laws without memory) are stable but for one: the chain at its scene
    // speed 1.36, past its branch point, where Newton keeps the symmetry of the linear start
    // and lands on the (unstable) symmetric orbit; time integration agrees. Unstable orbits
    // are checked against independent references in tests/integration/floquet_references.rs.
    assert!(unstable_seen <= 1, "{unstable_seen} unstable orbits");
}
