//! Cost of the Floquet stability in a run-up sweep of a large model: the same continuation
//! without stability, with the exact orbit's and with the HB orbit's ([`Orbit::Harmonic`]),
//! the stability's share per point, how many shooting periods a point needed, and how far the
//! HB orbit's multipliers are from the exact orbit's at every point. A Markdown table on
//! stdout.
//!
//! `cargo run --release --example stability_sweep [-- SCENE] [--from RPM] [--to RPM]
//! [--max-step S] [--repeat R]`
//!
//! Defaults: `examples/scenes/large/drivetrain_1000.toml` from 1000 to 3000 in the scene's
//! speed unit, the continuation's default largest step (1.0; 0.0075 gives about 600 points),
//! one run of each. Times are wall clock, the CPU time of every thread of the process and of
//! this thread (`/proc/thread-self`, on Linux; the machine may be shared), the medians over the
//! repeats. With a second core the sweep computes the points' stability on a worker thread
//! while this thread traces the next points, and the monodromy matrices are multiplied on a
//! third: the wall clock is what a user waits, the CPU of all threads the work. No error
//! estimate per point (the HB side of `hbal sweep --no-error-estimate`). With `DUMP` set in
//! the environment, every point's Ω, steps, orbit correction, `polished` and multipliers go to
//! stderr.

mod common;

use common::{cpu_ms, flag, median, process_cpu_ms};
use hbal::continuation::{Branch, Continuation};
use hbal::scene::Scene;
use hbal::stability::{FloquetOptions, Orbit};
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .iter()
        .find(|a| a.ends_with(".toml"))
        .cloned()
        .unwrap_or_else(|| "examples/scenes/large/drivetrain_1000.toml".into());
    let scene = Scene::load(Path::new(&path))?;
    let unit = scene.omega_per_speed;
    let from = flag(&args, "--from", 1000.0) * unit;
    let to = flag(&args, "--to", 3000.0) * unit;
    let repeat = flag(&args, "--repeat", 1.0_f64).max(1.0) as usize;
    let basis = scene.basis.with_omega(from)?;
    let run = |stability: Option<FloquetOptions>| -> Result<(f64, f64, f64, Branch), hbal::Error> {
        let (mut walls, mut cpus, mut all, mut last) = (Vec::new(), Vec::new(), Vec::new(), None);
        for _ in 0..repeat {
            let c = Continuation {
                max_step: flag(&args, "--max-step", 1.0),
                method: scene.method,
                stability,
                ..Continuation::default()
            };
            let start = Instant::now();
            let (cpu, process) = (cpu_ms(start), process_cpu_ms());
            let branch = c.run(&scene.model, basis, to, |_| {})?;
            cpus.push(cpu_ms(start) - cpu);
            all.push(process_cpu_ms() - process);
            walls.push(start.elapsed().as_secs_f64() * 1e3);
            last = Some(branch);
        }
        Ok((
            median(walls),
            median(cpus),
            median(all),
            last.expect("one run"),
        ))
    };
    let (wall_hb, cpu_hb, all_hb, plain) = run(None)?;
    let options = FloquetOptions {
        cutoff: flag(&args, "--cutoff", FloquetOptions::default().cutoff),
        ..FloquetOptions::default()
    };
    let harmonic = FloquetOptions {
        orbit: Orbit::Harmonic,
        ..options
    };
    let (wall, cpu, all, branch) = run(Some(options))?;
    let (wall_h, cpu_h, all_h, fast) = run(Some(harmonic))?;
    let points = branch.points.len();
    if std::env::var("DUMP").is_ok() {
        dump(&branch);
    }
    let steps: Vec<usize> = branch
        .points
        .iter()
        .filter_map(|p| p.floquet.as_ref().map(|f| f.steps))
        .collect();
    let first = steps.first().copied().unwrap_or(1).max(1) as f64;
    let estimated = branch
        .points
        .iter()
        .filter(|p| {
            p.floquet
                .as_ref()
                .and_then(|f| f.reduction.as_ref())
                .is_some_and(|r| r.estimate.is_some())
        })
        .count();
    let unpolished = branch
        .points
        .iter()
        .filter(|p| p.floquet.as_ref().is_some_and(|f| !f.polished))
        .count();
    println!("## Run-up sweep with stability: {path}\n");
    println!(
        "{} points with stability ({} without), Ω {:.1} → {:.1} rad/s, max step {}\n",
        points,
        plain.points.len(),
        from,
        to,
        flag(&args, "--max-step", 1.0)
    );
    println!(
        "| | wall ms | per point (wall) ms | all threads' CPU ms | per point (all threads' CPU) ms | main thread's CPU ms |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    let row = |what: &str, wall: f64, all: f64, cpu: f64, points: usize| {
        println!(
            "| {what} | {wall:.0} | {:.1} | {all:.0} | {:.1} | {cpu:.0} |",
            wall / points as f64,
            all / points as f64
        )
    };
    row(
        "continuation without stability",
        wall_hb,
        all_hb,
        cpu_hb,
        plain.points.len(),
    );
    row("with the exact orbit's stability", wall, all, cpu, points);
    row(
        "with the HB orbit's stability",
        wall_h,
        all_h,
        cpu_h,
        fast.points.len(),
    );
    row(
        "exact orbit's stability share (difference)",
        wall - wall_hb,
        all - all_hb,
        cpu - cpu_hb,
        points,
    );
    row(
        "HB orbit's stability share (difference)",
        wall_h - wall_hb,
        all_h - all_hb,
        cpu_h - cpu_hb,
        points,
    );
    // The HB orbit's multipliers against the exact orbit's at every point, and what the
    // points reported.
    let (mut worst, mut reported, mut on_hb) = (0.0_f64, 0.0_f64, 0);
    for (e, f) in branch.points.iter().zip(&fast.points) {
        if let (Some(e), Some(f)) = (&e.floquet, &f.floquet) {
            worst = worst.max(e.distance(f));
            reported = reported.max(f.orbit_difference.unwrap_or(0.0));
            on_hb += usize::from(f.orbit == Orbit::Harmonic);
        }
    }
    println!(
        "
HB orbit's multipliers at {on_hb} of {} points: at most {worst:.1e} from the exact orbit's at any point (reported: at most {reported:.1e}); the largest |μ| within {:.1e}",
        fast.points.len(),
        branch
            .points
            .iter()
            .zip(&fast.points)
            .filter_map(|(e, f)| Some((e.floquet.as_ref()?.max_abs() - f.floquet.as_ref()?.max_abs()).abs()))
            .fold(0.0, f64::max)
    );
    if let Some(r) = branch
        .points
        .first()
        .and_then(|p| p.floquet.as_ref())
        .and_then(|f| f.reduction.as_ref())
    {
        println!(
            "\nreduced basis at the first point: {} coordinates ({} modes below {:.0} rad/s, {} attachment), multipliers to about {:.1e} (against {} coordinates)",
            r.dofs,
            r.modes,
            r.cutoff,
            r.attachment,
            r.estimate.unwrap_or(f64::NAN),
            r.comparison_dofs.unwrap_or(0)
        );
    }
    let mean = steps.iter().sum::<usize>() as f64 / steps.len().max(1) as f64;
    println!(
        "\nintegration steps per point: first {first:.0}, mean {mean:.0} ({:.2} of the first), \
         max {}; {estimated} point(s) with the reduction's estimate; {unpolished} not polished",
        mean / first,
        steps.iter().max().unwrap_or(&0)
    );
    let max_mu = branch
        .points
        .iter()
        .filter_map(|p| p.floquet.as_ref().map(|f| f.max_abs()))
        .fold(0.0, f64::max);
    println!(
        "largest |μ| along the branch {max_mu:.9}; unstable points {}",
        branch
            .points
            .iter()
            .filter(|p| p.stable() == Some(false))
            .count()
    );
    Ok(())
}
#[allow(dead_code)]
fn dump(branch: &Branch) {
    for p in &branch.points {
        if let Some(f) = &p.floquet {
            let mu: Vec<String> = f
                .multipliers
                .iter()
                .map(|m| format!("{:.15e},{:.15e}", m.re, m.im))
                .collect();
            eprintln!(
                "{:.6} steps {} orbit {:?} difference {:?} corr {:.2e} polished {} mu {}",
                p.omega,
                f.steps,
                f.orbit,
                f.orbit_difference,
                f.orbit_correction,
                f.polished,
                mu.join(" ")
            );
        }
    }
}
