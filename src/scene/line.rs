//! The shaft-line vocabulary: `[line]` with disks and shafts, as shaft-line tools write a
//! torsional model, expanded into the scene's `dofs`, `mass`, `stiffness` and `damping`
//! (triplets) before anything else is read, so that every other table (loads, the engine,
//! gear stages, every force law) names the disks as DOFs.
//!
//! ```toml
//! [line]
//! disks = [
//!   { name = "engine", inertia = 0.15 },
//!   { name = "propeller", inertia = 2.0, damping = 40.0 },  # damping to ground, N m s/rad
//! ]
//! shafts = [
//!   { from = "engine", to = "propeller", stiffness = 5e4, damping = 5.0 },
//!   # or from its geometry: k = G π (D⁴ − d⁴) / (32 L)
//!   { from = "engine", to = "propeller", length = 1.2, outer_diameter = 0.08,
//!     inner_diameter = 0.02, shear_modulus = 80e9 },
//! ]
//! ```
//!
//! A disk's `inertia` (kg m²) is its mass entry, its `damping` a damper to ground. A shaft
//! (or a coupling: the same element) between disks `from` and `to` adds its torsional
//! stiffness `k` and damping `c` to the four entries `(f, f), (t, t)` (+) and `(f, t), (t, f)`
//! (−). The expansion is exact: the model equals the same matrices written by hand.

use serde::Deserialize;
use serde_json::{json, Map, Value};

/// `[line]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Line {
    disks: Vec<Disk>,
    #[serde(default)]
    shafts: Vec<Shaft>,
    /// Couplings: a stiffness and damping between two disks (a shaft without geometry, and
    /// without the line's `loss_factor` unless its own).
    #[serde(default)]
    couplings: Vec<Coupling>,
    /// Rigid gear pairs, each removing one angle (see `line_gears.rs`).
    #[serde(default)]
    gears: Vec<super::line_gears::RigidGear>,
    /// The loss factor η of every shaft without its own: hysteretic damping `η k`
    /// (`c = η k / ω` at each harmonic's frequency ω).
    #[serde(default)]
    loss_factor: f64,
    /// Damping ratios of the undamped modes (see `line_modal.rs`).
    #[serde(default)]
    modal_damping: Option<super::line_modal::ModalDamping>,
}

/// One disk: a DOF with its inertia and an optional damper to ground.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Disk {
    name: String,
    inertia: f64,
    #[serde(default)]
    damping: f64,
}

/// One coupling between two disks.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Coupling {
    from: String,
    to: String,
    stiffness: f64,
    #[serde(default)]
    damping: f64,
    #[serde(default)]
    loss_factor: f64,
}

/// One shaft or coupling between two disks: its stiffness, or its geometry.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Shaft {
    from: String,
    to: String,
    stiffness: Option<f64>,
    #[serde(default)]
    damping: f64,
    /// Its loss factor η (default the line's `loss_factor`).
    loss_factor: Option<f64>,
    length: Option<f64>,
    outer_diameter: Option<f64>,
    inner_diameter: Option<f64>,
    shear_modulus: Option<f64>,
}

/// The fields `[line]` builds.
const BUILT: [&str; 5] = ["dofs", "mass", "stiffness", "damping", "hysteretic_damping"];

/// A disk a rigid gear removed: its name, the kept disk's and the factor, `θ = f θ_kept`.
pub(super) type Removed = (String, String, f64);

/// Replaces `line` in the document `doc` by `dofs`, `mass`, `stiffness` and `damping`, and
/// moves each load on a disk a rigid gear removed onto the disk it follows (times the factor
/// `f`: the same virtual work); returns the removed disks. Errors are `(field path,
/// message)`. A document without `line` is left as it is.
pub(super) fn expand(doc: &mut Value) -> Result<Vec<Removed>, (String, String)> {
    let Some(map) = doc.as_object_mut() else {
        return Ok(Vec::new());
    };
    let Some(value) = map.remove("line") else {
        return Ok(Vec::new());
    };
    if let Some(field) = BUILT.iter().find(|f| map.contains_key(**f)) {
        return Err((
            "line".into(),
            format!("`line` builds `dofs`, `mass`, `stiffness`, `damping` and `hysteretic_damping`, and the scene also gives `{field}`: give one or the other"),
        ));
    }
    let line: Line = serde_path_to_error::deserialize(value).map_err(|x| {
        let path = x.path().to_string();
        let message = x.into_inner().to_string();
        let path = super::field_path(path, &message);
        let path = if path == "." {
            "line".into()
        } else {
            format!("line.{path}")
        };
        (path.clone(), late_field_hint(&path, message))
    })?;
    let names = check_disks(&line.disks)?;
    let index = |field: String, name: &str| -> Result<usize, (String, String)> {
        names.iter().position(|n| n == name).ok_or_else(|| {
            (
                field,
                format!("unknown disk `{name}` (the line has: {})", names.join(", ")),
            )
        })
    };
    let joins = super::line_gears::join(&names, &line.gears)?;
    // The kept disks' new indices; every disk's (new index, factor).
    let kept: Vec<usize> = (0..names.len()).filter(|&i| joins[i].0 == i).collect();
    let at: Vec<(usize, f64)> = joins
        .iter()
        .map(|&(root, f)| (kept.iter().position(|&k| k == root).unwrap_or(0), f))
        .collect();
    let mut stiffness = Vec::new();
    let mut damping: Vec<Value> = Vec::new();
    let mut hysteretic: Vec<Value> = Vec::new();
    if !(line.loss_factor.is_finite() && line.loss_factor >= 0.0) {
        return Err((
            "line.loss_factor".into(),
            format!("must be finite and >= 0, got {}", line.loss_factor),
        ));
    }
    let mut inertia = vec![0.0; kept.len()];
    for (i, disk) in line.disks.iter().enumerate() {
        let (r, f) = at[i];
        inertia[r] += disk.inertia * f * f;
        if disk.damping != 0.0 {
            damping.push(json!([r + 1, r + 1, disk.damping * f * f]));
        }
    }
    let couplings: Vec<Shaft> = line
        .couplings
        .iter()
        .map(|c| Shaft {
            from: c.from.clone(),
            to: c.to.clone(),
            stiffness: Some(c.stiffness),
            damping: c.damping,
            loss_factor: Some(c.loss_factor),
            length: None,
            outer_diameter: None,
            inner_diameter: None,
            shear_modulus: None,
        })
        .collect();
    let joints = (line
        .shafts
        .iter()
        .enumerate()
        .map(|(s, x)| ("shafts", s, x)))
    .chain(
        couplings
            .iter()
            .enumerate()
            .map(|(s, x)| ("couplings", s, x)),
    );
    for (table, s, shaft) in joints {
        let at_field = |field: &str| format!("line.{table}[{s}].{field}");
        let (f, t) = (
            index(at_field("from"), &shaft.from)?,
            index(at_field("to"), &shaft.to)?,
        );
        if f == t {
            return Err((
                at_field("to"),
                format!("the shaft ends where it starts, at `{}`", shaft.to),
            ));
        }
        let k = shaft_stiffness(shaft, &at_field)?;
        if !(shaft.damping.is_finite() && shaft.damping >= 0.0) {
            return Err((
                at_field("damping"),
                format!("must be finite and >= 0, got {}", shaft.damping),
            ));
        }
        couple(&mut stiffness, at[f], at[t], k);
        if shaft.damping != 0.0 {
            couple(&mut damping, at[f], at[t], shaft.damping);
        }
        let eta = shaft.loss_factor.unwrap_or(line.loss_factor);
        if !(eta.is_finite() && eta >= 0.0) {
            return Err((
                at_field("loss_factor"),
                format!("must be finite and >= 0, got {eta}"),
            ));
        }
        if eta != 0.0 {
            couple(&mut hysteretic, at[f], at[t], eta * k);
        }
    }
    if let Some(r) = inertia.iter().position(|j| *j <= 0.0) {
        return Err((
            format!("line.disks[{}].inertia", kept[r]),
            format!("`{}` has no inertia, and no disk joined to it by a rigid gear has any: every angle of the line needs an inertia (M is singular)", names[kept[r]]),
        ));
    }
    let mass: Vec<Value> = inertia
        .iter()
        .enumerate()
        .map(|(r, j)| json!([r + 1, r + 1, j]))
        .collect();
    let removed: Vec<Removed> = (0..names.len())
        .filter(|&i| joins[i].0 != i)
        .map(|i| (names[i].clone(), names[joins[i].0].clone(), joins[i].1))
        .collect();
    let names: Vec<&String> = kept.iter().map(|&k| &names[k]).collect();
    if let (Some(_), Some(Value::Array(elements))) = (&line.modal_damping, map.get("elements")) {
        if !elements.is_empty() {
            return Err((
                "line.modal_damping".into(),
                format!("is built from the line's disks, shafts and rigid gears, and the scene has {} element(s) that change its modes: give the shafts' `damping` (or `loss_factor`) instead, or rigid `gears` for the gear stages", elements.len()),
            ));
        }
    }
    if let Some(ratios) = &line.modal_damping {
        let n = kept.len();
        let mass = nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_vec(inertia.clone()));
        let modal = super::line_modal::damping(ratios, &mass, &dense(&stiffness, n))?;
        for i in 0..n {
            for j in 0..n {
                if modal[(i, j)] != 0.0 {
                    damping.push(json!([i + 1, j + 1, modal[(i, j)]]));
                }
            }
        }
    }
    map.insert("dofs".into(), json!(names));
    map.insert("mass".into(), json!({ "triplets": mass }));
    for (field, entries) in [
        ("stiffness", stiffness),
        ("damping", damping),
        ("hysteretic_damping", hysteretic),
    ] {
        if !entries.is_empty() {
            map.insert(
                field.into(),
                Value::Object(Map::from_iter([("triplets".into(), Value::Array(entries))])),
            );
        }
    }
    move_loads(map, &removed);
    Ok(removed)
}

/// Each load on a removed disk moved onto the disk it follows, its amplitudes (`cos`, `sin`
/// or a speed table's `amplitude`) times the factor.
fn move_loads(map: &mut Map<String, Value>, removed: &[Removed]) {
    let Some(Value::Array(loads)) = map.get_mut("loads") else {
        return;
    };
    for load in loads.iter_mut().filter_map(|l| l.as_object_mut()) {
        let Some((_, kept, f)) = removed
            .iter()
            .find(|r| load.get("dof").and_then(Value::as_str) == Some(r.0.as_str()))
        else {
            continue;
        };
        load.insert("dof".into(), json!(kept));
        let scale = |v: &mut Value| {
            if let Some(x) = v.as_f64() {
                *v = json!(x * f);
            }
        };
        for field in ["cos", "sin"] {
            if let Some(v) = load.get_mut(field) {
                scale(v);
            }
        }
        if let Some(Value::Array(a)) = load.get_mut("speed").and_then(|s| s.get_mut("amplitude")) {
            a.iter_mut().for_each(scale);
        }
    }
}

/// Scene fields written after `[line]` in TOML belong to it: `message` with that said.
fn late_field_hint(path: &str, message: String) -> String {
    const SCENE_FIELDS: [&str; 7] = [
        "fundamental",
        "harmonics",
        "loads",
        "engine",
        "elements",
        "solver",
        "description",
    ];
    let field = path.trim_start_matches("line.");
    if SCENE_FIELDS.contains(&field) {
        format!("{message} (a scene field: in TOML, fields after `[line]` belong to it; write `{field}` before the `[line]` table)")
    } else {
        message
    }
}

/// The disks' names, checked: unique, with a positive inertia and a damping to ground >= 0.
fn check_disks(disks: &[Disk]) -> Result<Vec<String>, (String, String)> {
    if disks.is_empty() {
        return Err(("line.disks".into(), "at least one disk is required".into()));
    }
    let mut names: Vec<String> = Vec::with_capacity(disks.len());
    for (i, d) in disks.iter().enumerate() {
        let at = |field: &str| format!("line.disks[{i}].{field}");
        if d.name.trim().is_empty() || names.contains(&d.name) {
            let why = if d.name.trim().is_empty() {
                "must not be empty".to_string()
            } else {
                format!("`{}` names another disk already", d.name)
            };
            return Err((at("name"), why));
        }
        if !(d.inertia.is_finite() && d.inertia >= 0.0) {
            return Err((
                at("inertia"),
                format!("must be finite and >= 0 (kg m²), got {}", d.inertia),
            ));
        }
        if !(d.damping.is_finite() && d.damping >= 0.0) {
            return Err((
                at("damping"),
                format!("must be finite and >= 0 (N m s/rad), got {}", d.damping),
            ));
        }
        names.push(d.name.clone());
    }
    Ok(names)
}

/// The shaft's torsional stiffness: given, or `G π (D⁴ − d⁴) / (32 L)` from its geometry.
fn shaft_stiffness(shaft: &Shaft, at: &dyn Fn(&str) -> String) -> Result<f64, (String, String)> {
    let positive = |field: &str, v: f64| -> Result<f64, (String, String)> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err((at(field), format!("must be finite and > 0, got {v}")))
        }
    };
    let geometry = [shaft.length, shaft.outer_diameter, shaft.shear_modulus];
    match (shaft.stiffness, geometry) {
        (Some(k), [None, None, None]) if shaft.inner_diameter.is_none() => positive("stiffness", k),
        (None, [Some(l), Some(d_out), Some(g)]) => {
            let (l, d_out, g) = (positive("length", l)?, positive("outer_diameter", d_out)?, positive("shear_modulus", g)?);
            let d_in = shaft.inner_diameter.unwrap_or(0.0);
            if !(d_in.is_finite() && d_in >= 0.0 && d_in < d_out) {
                return Err((at("inner_diameter"), format!("must be >= 0 and below the outer diameter {d_out}, got {d_in}")));
            }
            // D⁴ as (D²)², the same bits wherever it is computed (`powi` may be folded).
            let fourth = |d: f64| (d * d) * (d * d);
            let polar = std::f64::consts::PI * (fourth(d_out) - fourth(d_in)) / 32.0;
            Ok(g * polar / l)
        }
        _ => Err((
            at("stiffness").trim_end_matches(".stiffness").to_string(),
            "give `stiffness` (N m/rad), or `length`, `outer_diameter` and `shear_modulus` (with `inner_diameter` for a hollow shaft), not both".into(),
        )),
    }
}

/// Adds `c` on `u = f_a θ_a − f_b θ_b` to 1-based triplets, with `(a, f_a)`, `(b, f_b)` the
/// two ends' DOFs (0-based) and factors: `c f_a²`, `c f_b²` and `−c f_a f_b` (exactly `c` and
/// `−c` where both factors are 1).
fn couple(entries: &mut Vec<Value>, (a, fa): (usize, f64), (b, fb): (usize, f64), c: f64) {
    let (a, b) = (a + 1, b + 1);
    let cross = -c * fa * fb;
    entries.extend([
        json!([a, a, c * fa * fa]),
        json!([b, b, c * fb * fb]),
        json!([a, b, cross]),
        json!([b, a, cross]),
    ]);
}

/// The dense n × n matrix of 1-based triplets `[row, column, value]` (repeats add up).
fn dense(entries: &[Value], n: usize) -> nalgebra::DMatrix<f64> {
    let mut a = nalgebra::DMatrix::zeros(n, n);
    for e in entries {
        if let (Some(i), Some(j), Some(v)) = (e[0].as_u64(), e[1].as_u64(), e[2].as_f64()) {
            a[(i as usize - 1, j as usize - 1)] += v;
        }
    }
    a
}
