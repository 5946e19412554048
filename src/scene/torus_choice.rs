//! The scene's choice between one fundamental and several base frequencies (a torus).
//!
//! `harmonics.bases = "auto"` (the default) keeps one fundamental wherever it holds the
//! meshes, as before, and takes the torus where it cannot: the engine and mesh orders have no
//! common fundamental, a mesh's order is not a harmonic of the fundamental the scene did not
//! fix itself, or a mesh's first harmonic lies above the harmonics the scene keeps and above
//! harmonic 64 (a long common period).

use super::fundamental::Speed;
use serde::Deserialize;
use serde_json::{Map, Value};

type FieldError = (String, String);

/// Mesh harmonics of the common fundamental up to which its period counts as short: there
/// one fundamental stays, and too few harmonics are an error to fix, not a reason for the
/// torus.
const SHORT_PERIOD: f64 = 64.0;

/// `harmonics.bases`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum BasesChoice {
    /// One fundamental where it holds every mesh, else the torus.
    #[default]
    Auto,
    /// One fundamental.
    One,
    /// A base per engine and varying mesh.
    Torus,
}

/// A gear stage or planetary set with a varying stiffness: where it is, its name, its mesh
/// order of the speed and the model elements it becomes.
#[derive(Debug, Clone)]
pub(super) struct Mesh {
    pub(super) index: usize,
    pub(super) name: String,
    pub(super) order: f64,
    pub(super) elements: Vec<String>,
}

/// The varying gear stages of the raw element tables.
pub(super) fn meshes(elements: &[Map<String, Value>]) -> Vec<Mesh> {
    elements
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let order = super::fundamental::stage_mesh_order(e)?;
            let name = e
                .get("name")
                .and_then(Value::as_str)
                .map_or_else(|| format!("element {i}"), str::to_string);
            let planets = e.get("planets").and_then(Value::as_array).map(Vec::len);
            let elements = match planets {
                Some(n) if e.get("type").and_then(Value::as_str) == Some("planetary") => {
                    let part = |kind: &str| -> Vec<String> {
                        (1..=n).map(|p| format!("{name} {kind} {p}")).collect()
                    };
                    [part("sun"), part("ring")].concat()
                }
                _ => vec![name.clone()],
            };
            Some(Mesh {
                index: i,
                name,
                order,
                elements,
            })
        })
        .collect()
}

/// Why the scene goes on the torus, or `None` for one fundamental. `one` is the fundamental
/// every order fits; `harmonics` the H the scene keeps on it (the cap of automatic H).
pub(super) fn choose(
    choice: BasesChoice,
    meshes: &[Mesh],
    one: &Result<Speed, FieldError>,
    harmonics: Option<usize>,
) -> Option<String> {
    match choice {
        BasesChoice::One => None,
        BasesChoice::Torus => Some("harmonics.bases = \"torus\"".into()),
        BasesChoice::Auto if meshes.is_empty() => None,
        BasesChoice::Auto => match one {
            Err(_) => Some(
                "the engine and mesh orders share no fundamental (none with a denominator up to 1000)"
                    .into(),
            ),
            Ok(speed) => {
                // A fundamental the scene chose itself stays: a mesh that is not its harmonic
                // is the stage's error to fix (or `bases = "torus"`).
                let off = meshes.iter().filter(|_| !speed.explicit).find(|m| {
                    let z = m.order / speed.order;
                    (z - z.round()).abs() > 1e-9 * z.max(1.0)
                });
                if let Some(m) = off {
                    return Some(format!(
                        "the mesh order {:.6} of `{}` is not a harmonic of the fundamental (order {:.6})",
                        m.order, m.name, speed.order
                    ));
                }
                let h = harmonics?;
                let worst = meshes
                    .iter()
                    .map(|m| (m, (m.order / speed.order).round()))
                    .max_by(|a, b| a.1.total_cmp(&b.1))?;
                (worst.1 > (h as f64).max(SHORT_PERIOD)).then(|| {
                    format!(
                        "gear stage `{}` meshes at harmonic {} of the common fundamental (order {:.6}), above the {h} harmonics kept on it",
                        worst.0.name, worst.1, speed.order
                    )
                })
            }
        },
    }
}
