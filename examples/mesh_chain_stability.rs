//! Stability at scale (issue 31, item 4): the 1000-DOF chain with 4 backlash meshes
//! (`hbal::catalog::MeshChain`, every mode in the excitation band at H = 32, Ω = 120 rad/s)
//! solved, then its leading Floquet multipliers by the Arnoldi iteration on the monodromy
//! action (what `FloquetMethod::Auto` picks there). Prints the times and the multipliers.
//!
//! `cargo run --release --example mesh_chain_stability [-- DOFS [SCENE.toml]]`;
//! `/usr/bin/time -v` gives the whole process's memory. With a scene path the chain is also
//! written as a scene (matrices in a directory next to it) for `hbal solve`.

use hbal::catalog::MeshChain;
use hbal::stability::FloquetOptions;
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Newton};
use std::time::Instant;

fn main() -> hbal::Result<()> {
    let dofs = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1000);
    let model = MeshChain {
        dofs,
        ..MeshChain::default()
    }
    .model()?;
    if let Some(path) = std::env::args().nth(2) {
        let settings = hbal::scene::export::SceneSettings::new(
            &format!("Mesh chain (hbal::catalog::MeshChain), {dofs} DOFs, 4 backlash meshes"),
            "rad_s",
            120.0,
            32,
        );
        hbal::scene::export::write_scene(&model, &settings, std::path::Path::new(&path))
            .map_err(|e| hbal::Error::invalid("scene", "path", f64::NAN, e.to_string()))?;
    }
    let basis = HarmonicBasis::new(120.0, 32)?;
    let started = Instant::now();
    let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed)?;
    let solution = Newton::new().solve(&hb, &mut hb.workspace())?;
    let solve = started.elapsed();
    println!(
        "{dofs} DOFs: solve {:.1} ms ({}, residual {:.1e})",
        solve.as_secs_f64() * 1e3,
        solution.termination,
        solution.residual()
    );
    let started = Instant::now();
    let floquet = FloquetOptions::default().compute(&model, &solution)?;
    let stability = started.elapsed();
    let r = floquet.reduction.as_ref();
    println!(
        "stability {:.2} s: {} (max |μ| = {:.6}), {} Krylov vectors, {} Runge–Kutta steps, multipliers to about {:.1e}",
        stability.as_secs_f64(),
        if floquet.is_stable() { "stable" } else { "unstable" },
        floquet.max_abs(),
        r.and_then(|r| r.krylov).map_or("no".into(), |k| k.to_string()),
        floquet.steps,
        r.and_then(|r| r.estimate).unwrap_or(f64::NAN),
    );
    for m in floquet.multipliers.iter().take(8) {
        println!("  μ = {:.6} {:+.6}i  |μ| = {:.6}", m.re, m.im, m.norm());
    }
    Ok(())
}
