//! What `hbal solve --json` and `hbal sweep --json` do, from the library: load a scene, solve
//! it (automatic harmonics, fallbacks, error estimate, stability, element outputs), sweep its
//! speed to 1.5 times through any folds, and print both results as JSON, one per line.
//!
//! `cargo run --release --example analyses [SCENE.toml]` (default: the two-shaft model).
use hbal::analysis::{solve, sweep, Silent, SolveSettings, SweepSettings};
use hbal::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let default = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/two_shaft_6000rpm.toml"
    );
    let path = std::env::args().nth(1).unwrap_or(default.into());
    let scene = Scene::load(path.as_ref())?;
    let solved = solve(&scene, &SolveSettings::default())?;
    println!("{}", serde_json::to_string(&solved)?);
    let to = 1.5 * scene.basis.omega() / scene.omega_per_speed;
    let swept = sweep(&scene, &SweepSettings::to(to), &mut Silent)?;
    println!("{}", serde_json::to_string(&swept)?);
    eprintln!(
        "{}: {:?} stable, {} sweep points to {to} {}: {}",
        scene.file,
        solved.stable(),
        swept.branch.points.len(),
        scene.speed_unit,
        swept.branch.stop
    );
    std::process::exit(solved.exit_code().max(swept.exit_code()).into());
}
