//! Writes the drivetrain benchmark model (`hbal::catalog::Drivetrain`) as a scene file with its
//! matrices in Matrix Market files, as an FE program would export it, for `hbal solve` and
//! `hbal sweep`.
//!
//! `cargo run --release --example drivetrain_scene -- [--dofs N] [--rpm R] [--harmonics H] OUT.toml`
//!
//! Defaults: N = 1000 DOFs, 2000 rpm, H = 32. The scene's fundamental is half the crank speed
//! (`fundamental = { rpm = R, order = 0.5 }`), so `hbal sweep OUT.toml --from 800 --to 6000`
//! sweeps engine speed in rpm. The matrices go to the directory `OUT/` next to the file.

use hbal::catalog::Drivetrain;
use hbal::scene::export::{write_scene, SceneSettings};

fn value<T: std::str::FromStr>(args: &[String], flag: &str, default: T) -> Result<T, String> {
    match args.iter().position(|a| a == flag) {
        None => Ok(default),
        Some(i) => args
            .get(i + 1)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| format!("{flag} needs a number")),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dofs: usize = value(&args, "--dofs", 1000)?;
    let rpm: f64 = value(&args, "--rpm", 2000.0)?;
    let harmonics: usize = value(&args, "--harmonics", 32)?;
    let out = args
        .iter()
        .enumerate()
        .filter(|(i, a)| !a.starts_with("--") && (*i == 0 || !args[i - 1].starts_with("--")))
        .map(|(_, a)| a.clone())
        .next()
        .ok_or("usage: drivetrain_scene [--dofs N] [--rpm R] [--harmonics H] OUT.toml")?;
    let drivetrain = Drivetrain::default().with_dofs(dofs);
    let model = drivetrain.model()?;
    let mut settings = SceneSettings::new(
        &format!(
            "Drivetrain benchmark (hbal::catalog::Drivetrain), {} DOFs, {} meshes with backlash \
             and rectangular mesh stiffness, four-stroke engine at {rpm} rpm",
            model.n_dofs(),
            drivetrain.meshes()
        ),
        "rpm",
        rpm,
        harmonics,
    );
    settings.order = 0.5;
    settings.tolerance = Some(1e-10);
    write_scene(&model, &settings, std::path::Path::new(&out))?;
    println!(
        "wrote {out} ({} DOFs, {} elements, {} loads)",
        model.n_dofs(),
        model.elements().len(),
        model.loads().len()
    );
    Ok(())
}
