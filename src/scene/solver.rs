//! The scene's `[solver]` table: the method and its options.

use super::{Scene, SceneError};
use crate::solve::{Anderson, Broyden, FixedPoint, Method, Newton, PiecewiseExact};
use serde::Deserialize;

/// Names of the solver methods.
pub const METHODS: [&str; 5] = [
    "fixed_point",
    "newton",
    "broyden",
    "anderson",
    "piecewise_exact",
];

/// Solver settings; unset fields take the method's defaults.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SolverSpec {
    method: Option<String>,
    gamma: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<usize>,
    depth: Option<usize>,
}

/// Smallest relative residual tolerance of a scene (and of `--tolerance`): the residual stops
/// at rounding, about 1e-16, so a smaller tolerance is never met.
pub const MIN_TOLERANCE: f64 = 1e-15;

/// Largest `solver.max_iterations` of a scene.
pub const MAX_ITERATIONS: usize = 1_000_000;

/// Checks a scene's relative residual tolerance: in [[`MIN_TOLERANCE`], 1). (The library
/// accepts 0, for a fixed number of iterations.)
pub fn check_tolerance(tolerance: f64) -> Result<(), String> {
    if tolerance.is_finite() && (MIN_TOLERANCE..1.0).contains(&tolerance) {
        Ok(())
    } else {
        Err(format!(
            "must be in [{MIN_TOLERANCE:e}, 1) (the relative residual stops at rounding, about \
             1e-16), got {tolerance}"
        ))
    }
}

impl SolverSpec {
    /// The method, optionally overriding the name.
    pub(super) fn method(&self, name: Option<&str>) -> Result<Method, (String, String)> {
        let requested = name;
        let name = name.or(self.method.as_deref()).unwrap_or("newton");
        let e = |field: &str, x: crate::Error| (format!("solver.{field}"), x.to_string());
        if let Some(t) = self.tolerance {
            check_tolerance(t).map_err(|m| ("solver.tolerance".to_string(), m))?;
        }
        if let Some(m) = self.max_iterations {
            if !(1..=MAX_ITERATIONS).contains(&m) {
                return Err((
                    "solver.max_iterations".into(),
                    format!("must be in 1..={MAX_ITERATIONS}, got {m}"),
                ));
            }
        }
        let method = match name {
            "fixed_point" => {
                let mut o = FixedPoint::new();
                if let Some(g) = self.gamma {
                    o = o.with_gamma(g).map_err(|x| e("gamma", x))?;
                }
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::FixedPoint(o)
            }
            "newton" => {
                let mut o = Newton::new();
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::Newton(o)
            }
            "broyden" => {
                let mut o = Broyden::new();
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::Broyden(o)
            }
            "anderson" => {
                let mut o = Anderson::new();
                if let Some(g) = self.gamma {
                    o = o.with_gamma(g).map_err(|x| e("gamma", x))?;
                }
                if let Some(d) = self.depth {
                    o = o.with_depth(d).map_err(|x| e("depth", x))?;
                }
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::Anderson(o)
            }
            "piecewise_exact" => {
                // No iteration: the options of the iterative methods mean nothing here. A
                // scene that names this method and sets them is refused; a scene whose own
                // method they belong to can still be run with `--method piecewise_exact`.
                let overridden = requested.is_some_and(|n| Some(n) != self.method.as_deref());
                let unused = [
                    ("gamma", self.gamma.is_some()),
                    ("tolerance", self.tolerance.is_some()),
                    ("max_iterations", self.max_iterations.is_some()),
                    ("depth", self.depth.is_some()),
                ];
                if let Some((field, _)) = unused.iter().find(|(_, set)| *set && !overridden) {
                    return Err((
                        format!("solver.{field}"),
                        "not used by method `piecewise_exact` (an exact solution, no iteration): remove it".into(),
                    ));
                }
                Method::PiecewiseExact(PiecewiseExact::new())
            }
            other => {
                return Err((
                    "solver.method".into(),
                    format!("unknown method `{other}` (one of: {})", METHODS.join(", ")),
                ))
            }
        };
        Ok(method)
    }
}

impl Scene {
    /// The scene's solver settings applied to another method (for `--method` and `compare`);
    /// options meaningless for that method (γ for Newton) are ignored.
    pub fn method_named(&self, name: &str) -> Result<Method, SceneError> {
        let spec = SolverSpec {
            method: None,
            ..self.solver.clone()
        };
        let spec = match name {
            "newton" | "broyden" => SolverSpec {
                gamma: None,
                depth: None,
                ..spec
            },
            "fixed_point" => SolverSpec {
                depth: None,
                ..spec
            },
            _ => spec,
        };
        spec.method(Some(name))
            .map_err(|(path, message)| SceneError {
                file: self.file.clone(),
                position: None,
                path: Some(if name_is_known(name) {
                    path
                } else {
                    "--method".into()
                }),
                message,
            })
    }
}

fn name_is_known(name: &str) -> bool {
    METHODS.contains(&name)
}
