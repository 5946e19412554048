//! Cost of large models: the drivetrain benchmark (`hbal::catalog::Drivetrain`) at 2000 rpm,
//! condensed onto its mesh and clutch coordinates, against the number of DOFs n, of meshes m
//! and of harmonics H. Markdown tables on stdout.
//!
//! `cargo run --release --example drivetrain [-- --max-dofs N]` (default N = 100000; the
//! model is sparse). The full formulation runs for comparison up to n = 20 (its dense Newton
//! LU has n(2H+1) unknowns: half a minute per iteration at n = 100).
//!
//! Times are medians of repeated runs (`hbal::report::median_time`, at least 3 runs in a
//! 0.5 s budget), or one run where one run takes longer than the budget. "HB build" is
//! `HarmonicBalance::with_formulation` (the sparse LU of every `Z_k` and the receptances);
//! "Newton" one converged point from the linear start (`Newton::new().solve`, tolerance
//! 1e-10), including the recovery of all n DOFs. Peak memory is the process's VmHWM, reset
//! before each row (`/proc/self/clear_refs`), in MiB.

use hbal::catalog::Drivetrain;
use hbal::compare::relative_error;
use hbal::report::median_time;
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Model, Newton, Solution};
use std::time::{Duration, Instant};

/// Engine speed (rpm).
const RPM: f64 = 2000.0;
/// Time budget of one median.
const BUDGET: Duration = Duration::from_millis(500);

/// The median of `f` over the budget, or its single time when one run exceeds the budget.
fn timed<T>(mut f: impl FnMut() -> T) -> (Duration, T) {
    let t = Instant::now();
    let first = f();
    let once = t.elapsed();
    if once > BUDGET {
        return (once, first);
    }
    median_time(BUDGET, f)
}

/// Resets the peak resident set size of this process (Linux >= 4.0; ignored elsewhere).
fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// The peak resident set size VmHWM in MiB, if the system tells.
fn peak_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn ms(d: Duration) -> String {
    format!("{:.3}", d.as_secs_f64() * 1e3)
}

/// One formulation on one model: build and solve times, the solution.
struct Run {
    build: Duration,
    newton: Duration,
    solution: Solution,
    unknowns: usize,
}

fn run(model: &Model, basis: HarmonicBasis, formulation: Formulation) -> hbal::Result<Run> {
    let (build, hb) = timed(|| HarmonicBalance::with_formulation(model, basis, formulation));
    let hb = hb?;
    let mut ws = hb.workspace();
    let (newton, solution) = timed(|| Newton::new().solve(&hb, &mut ws));
    Ok(Run {
        build,
        newton,
        solution: solution?,
        unknowns: hb.unknown_names().len(),
    })
}

fn status(s: &Solution) -> String {
    if s.is_converged() {
        format!("{}", s.stats.iterations)
    } else {
        format!("{} ({})", s.stats.iterations, s.termination)
    }
}

/// Cost against n (m = 4, H = 32), with the full formulation for n <= 20; a row that fails
/// shows the error and ends the table.
fn against_dofs(max_dofs: usize) -> hbal::Result<()> {
    println!("## Against n (m = 4 meshes, H = 32, {RPM} rpm)\n");
    println!("| n | model build ms | HB build ms (condensed) | Newton ms | iterations | peak MiB | full HB build ms | full Newton ms | full iterations | condensed vs full |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for n in [20, 100, 1000, 10_000, 100_000]
        .into_iter()
        .filter(|&n| n <= max_dofs)
    {
        match dofs_row(n) {
            Ok(row) => println!("{row}"),
            Err(e) => {
                let peak = peak_mib().map_or("-".into(), |p| format!("{p:.0}"));
                println!("| {n} | {e} (peak {peak} MiB) | | | | | | | | |");
                break;
            }
        }
    }
    println!();
    Ok(())
}

fn dofs_row(n: usize) -> hbal::Result<String> {
    reset_peak();
    let d = Drivetrain::default().with_dofs(n);
    let (t_model, model) = timed(|| d.model());
    let model = model?;
    let basis = HarmonicBasis::new(d.fundamental(RPM), 32)?;
    let cond = run(&model, basis, Formulation::Condensed)?;
    let peak = peak_mib().map_or("-".into(), |p| format!("{p:.0}"));
    let full = if n <= 20 {
        let full = run(&model, basis, Formulation::Full)?;
        let diff = relative_error(
            cond.solution.harmonics(),
            full.solution.harmonics(),
            model.n_dofs(),
            32,
        );
        format!(
            "{} | {} | {} | {diff:.1e}",
            ms(full.build),
            ms(full.newton),
            status(&full.solution)
        )
    } else {
        "- | - | - | -".into()
    };
    Ok(format!(
        "| {} | {} | {} | {} | {} | {peak} | {full} |",
        model.n_dofs(),
        ms(t_model),
        ms(cond.build),
        ms(cond.newton),
        status(&cond.solution)
    ))
}

/// Cost against the number of meshes m (n = 1000, H = 32).
fn against_meshes() -> hbal::Result<()> {
    println!("## Against m (n = 1000, H = 32, condensed)\n");
    println!("| m | coordinates | unknowns m(2H+1) | HB build ms | Newton ms | iterations |");
    println!("|---:|---:|---:|---:|---:|---:|");
    for m in [1, 2, 4, 8, 16] {
        let d = Drivetrain::default().with_meshes(m)?.with_dofs(1000);
        let model = d.model()?;
        let basis = HarmonicBasis::new(d.fundamental(RPM), 32)?;
        let r = run(&model, basis, Formulation::Condensed)?;
        println!(
            "| {m} | {} | {} | {} | {} | {} |",
            r.unknowns,
            r.unknowns * 65,
            ms(r.build),
            ms(r.newton),
            status(&r.solution)
        );
    }
    println!();
    Ok(())
}

/// Cost against H (n = 1000, m = 4): the default teeth (mesh harmonic 32, so H >= 32) and
/// the teeth divided by 4 (mesh harmonics 8, 8, 5, 3: every H).
fn against_harmonics() -> hbal::Result<()> {
    println!("## Against H (n = 1000, m = 4, condensed)\n");
    println!("| H | HB build ms | Newton ms | iterations | teeth / 4: HB build ms | Newton ms | iterations |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    let default = Drivetrain::default().with_dofs(1000);
    let coarse = default.clone().coarse_teeth(4)?;
    let (m_default, m_coarse) = (default.model()?, coarse.model()?);
    for h in [8, 16, 32, 64, 128, 256] {
        let basis = HarmonicBasis::new(default.fundamental(RPM), h)?;
        let cell = |model: &Model| match run(model, basis, Formulation::Condensed) {
            Ok(r) => format!(
                "{} | {} | {}",
                ms(r.build),
                ms(r.newton),
                status(&r.solution)
            ),
            Err(hbal::Error::ElementOrderTooHigh { order, .. }) => {
                format!("refused: mesh order {order} > H | - | -")
            }
            Err(e) => format!("error: {e} | - | -"),
        };
        println!("| {h} | {} | {} |", cell(&m_default), cell(&m_coarse));
    }
    println!();
    Ok(())
}

fn main() -> hbal::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let max_dofs = args
        .iter()
        .position(|a| a == "--max-dofs")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(100_000);
    let d = Drivetrain::default();
    println!(
        "# Drivetrain benchmark: fundamental {:.1} rad/s (half of {RPM} rpm), overall ratio {:.3}, mesh harmonics {:?}\n",
        d.fundamental(RPM),
        d.total_ratio(),
        d.mesh_orders()?
    );
    against_dofs(max_dofs)?;
    against_meshes()?;
    against_harmonics()?;
    Ok(())
}
