//! Issue 31, item 4: the 1000-DOF chain with 4 backlash meshes (`hbal::catalog::MeshChain`,
//! every mode in the excitation band at H = 32, Ω = 120 rad/s) built, solved and its leading
//! Floquet multipliers computed (`FloquetMethod::Auto` picks the Arnoldi iteration on the
//! monodromy action): target < 10 s and < 500 MB as a whole process. Before the Arnoldi
//! iteration the dense monodromy took 847 s and 3.1 GB; the whole process's memory is
//! measured by `/usr/bin/time -v cargo run --release --example mesh_chain_stability`.

use criterion::{criterion_group, criterion_main, Criterion};
use hbal::catalog::MeshChain;
use hbal::stability::FloquetOptions;
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Newton};
use std::hint::black_box;
use std::time::Duration;

fn mesh_chain_stability(c: &mut Criterion) {
    let run = || {
        let model = MeshChain::default().model().unwrap();
        let basis = HarmonicBasis::new(120.0, 32).unwrap();
        let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap();
        let solution = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
        FloquetOptions::default()
            .compute(&model, &solution)
            .unwrap()
    };
    let floquet = run();
    println!(
        "mesh chain 1000 DOFs: {} (max |μ| = {:.6}), {:?} Krylov vectors, to about {:.1e}",
        if floquet.is_stable() {
            "stable"
        } else {
            "unstable"
        },
        floquet.max_abs(),
        floquet.reduction.as_ref().and_then(|r| r.krylov),
        floquet
            .reduction
            .as_ref()
            .and_then(|r| r.estimate)
            .unwrap_or(f64::NAN)
    );
    let mut g = c.benchmark_group("stability_at_scale");
    g.sample_size(10).measurement_time(Duration::from_secs(40));
    g.bench_function("mesh_chain_1000dof_solve_and_stability", |b| {
        b.iter(|| black_box(run()))
    });
}

criterion_group!(benches, mesh_chain_stability);
criterion_main!(benches);
