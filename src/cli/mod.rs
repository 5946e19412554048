//! Shared pieces of the `hbal` subcommands: the `say!` macro, the `Failure` error with its
//! exit code, and scene loading with the command-line overrides (`--method`, `--harmonics`).
//! Each subcommand lives in its own file below.

use anyhow::Context;
use hbal::scene::Scene;
use hbal::HarmonicBasis;
use std::path::Path;

/// `println!` that ends the process quietly when stdout is closed (`hbal ... | head`).
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout(), $($t)*) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
        }
    }};
}

pub(crate) mod check;
pub(crate) mod compare;
pub(crate) mod parameter_sweep;
pub(crate) mod solve;
pub(crate) mod sweep;

/// An error with its exit code.
pub(crate) struct Failure {
    pub(crate) code: u8,
    pub(crate) error: anyhow::Error,
}

impl<E: Into<anyhow::Error>> From<E> for Failure {
    fn from(e: E) -> Self {
        Failure {
            code: 2,
            error: e.into(),
        }
    }
}

/// Loads the scene and applies the command-line overrides.
pub(crate) fn load(
    path: &Path,
    method: Option<&str>,
    harmonics: Option<usize>,
) -> Result<Scene, Failure> {
    let mut scene = Scene::load(path)?;
    if let Some(name) = method {
        scene.method = scene.method_named(name)?;
    }
    if let Some(h) = harmonics {
        let basis = HarmonicBasis::new(scene.basis.omega(), h)
            .with_context(|| format!("{}: --harmonics", scene.file))?;
        // Keep the scene's N where it can still carry H harmonics.
        scene.basis = basis.with_samples(scene.basis.samples()).unwrap_or(basis);
    }
    Ok(scene)
}
