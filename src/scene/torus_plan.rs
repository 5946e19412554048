//! The torus a scene describes ([`crate::torus`]): one base for the engine (or the reference
//! shaft) and one per gear stage or planetary set whose mesh stiffness varies, each at its
//! own order of the speed, with the caps, grid and truncation of its `harmonics` table
//! (whether the scene goes there: `torus_choice.rs`).

use super::fundamental::Speed;
use super::torus_choice::Mesh;
pub(super) use super::torus_choice::{choose, meshes, BasesChoice};
use crate::model::Model;
use crate::torus::{Bases, IndexSet, TorusModel, Truncation};
use serde_json::{Map, Value};

type FieldError = (String, String);

/// The bases before the model is built: names and ratios, and which element follows which.
#[derive(Debug, Clone)]
pub(super) struct Layout {
    names: Vec<String>,
    ratios: Vec<f64>,
    /// `(element name, base)` of every model element not on base 0.
    bindings: Vec<(String, usize)>,
    /// `(table name, order)` of every gear stage and planetary set: the order its meshes
    /// count against.
    orders: Vec<(String, f64)>,
    /// The first base's cap that `harmonics.count` stands for (the harmonics of one
    /// fundamental it covers), where given.
    count_cap: Option<usize>,
    why: String,
}

impl Layout {
    /// Base 0 is `engine` (with an engine table) or `shaft` at the order `f0` of the scene's
    /// fundamental without the meshes; each varying mesh gets its own base at its mesh order
    /// (meshes of equal order share one). Takes each element's `base` field out of its table.
    pub(super) fn new(
        elements: &mut [Map<String, Value>],
        meshes: &[Mesh],
        f0: f64,
        engine: bool,
        count_cap: Option<usize>,
        why: String,
    ) -> Result<Self, FieldError> {
        let first = if engine { "engine" } else { "shaft" };
        let mut layout = Layout {
            names: vec![first.to_string()],
            ratios: vec![f0],
            bindings: Vec::new(),
            orders: Vec::new(),
            count_cap,
            why,
        };
        for m in meshes {
            let same = layout
                .ratios
                .iter()
                .position(|r| (r - m.order).abs() <= 1e-12 * m.order);
            let b = match same {
                Some(b) => b,
                None if layout.names.contains(&m.name) => {
                    let other = if layout.names[0] == m.name {
                        "the engine's or shaft's base".to_string()
                    } else {
                        "the base of another gear stage or planetary set".to_string()
                    };
                    return Err((
                        format!("elements[{}].name", m.index),
                        format!(
                            "`{}` is also the name of {other}: give every stage its own name",
                            m.name
                        ),
                    ));
                }
                None => {
                    layout.names.push(m.name.clone());
                    layout.ratios.push(m.order);
                    layout.names.len() - 1
                }
            };
            layout.orders.push((m.name.clone(), layout.ratios[b]));
            for e in &m.elements {
                layout.bindings.push((e.clone(), b));
            }
        }
        if layout.names.len() > Bases::MAX {
            return Err((
                "harmonics.bases".into(),
                format!(
                    "the torus needs {} bases ({}), at most {} are supported: give the meshes of equal order the same teeth × shaft_order, or use `bases = \"one\"`",
                    layout.names.len(),
                    layout.names.join(", "),
                    Bases::MAX
                ),
            ));
        }
        for (i, e) in elements.iter_mut().enumerate() {
            let Some(v) = e.remove("base") else { continue };
            let at = format!("elements[{i}].base");
            if matches!(
                e.get("type").and_then(Value::as_str),
                Some("gear_stage" | "planetary")
            ) {
                return Err((
                    at,
                    "a gear stage or planetary set follows its own mesh; `base` is for the other elements".into(),
                ));
            }
            let name = v
                .as_str()
                .ok_or_else(|| (at.clone(), format!("must be the name of a base, got {v}")))?;
            let b = layout.names.iter().position(|n| n == name).ok_or_else(|| {
                (
                    at.clone(),
                    format!(
                        "no base `{name}` (the bases are: {})",
                        layout.names.join(", ")
                    ),
                )
            })?;
            let element = e
                .get("name")
                .and_then(Value::as_str)
                .map_or_else(|| format!("element {i}"), str::to_string);
            layout.bindings.push((element, b));
        }
        Ok(layout)
    }

    /// The order a gear stage counts its mesh against: its base's ratio, or `None` for an
    /// element on base 0.
    pub(super) fn stage_order(&self, element: &str) -> Option<f64> {
        self.orders
            .iter()
            .find(|(n, _)| n == element)
            .map(|&(_, r)| r)
    }

    /// The torus of the built `model` at the scene's `speed`: caps, grid and truncation from
    /// the `harmonics` table.
    pub(super) fn finish(
        self,
        harmonics: &super::harmonics::Harmonics,
        model: &Model,
        speed: &Speed,
    ) -> Result<TorusPlan, FieldError> {
        let names: Vec<(&str, f64)> = self
            .names
            .iter()
            .map(String::as_str)
            .zip(self.ratios.iter().copied())
            .collect();
        let bases =
            Bases::new(&names).map_err(|e| ("harmonics.bases".to_string(), e.to_string()))?;
        let known = |table: &std::collections::BTreeMap<String, usize>, field: &str| match table
            .keys()
            .find(|k| !self.names.contains(k))
        {
            Some(k) => Err((
                format!("harmonics.{field}.{k}"),
                format!("no base `{k}` (the bases are: {})", self.names.join(", ")),
            )),
            None => Ok(()),
        };
        known(&harmonics.caps, "caps")?;
        known(&harmonics.grid, "grid")?;
        // `count`'s harmonics, but below the first mesh's order: beyond it the first base
        // would repeat the mesh's lines (and meet them in a combination of frequency zero).
        let below_meshes = self.ratios[1..]
            .iter()
            .map(|r| {
                ((r / self.ratios[0]).ceil() as usize)
                    .saturating_sub(1)
                    .max(1)
            })
            .min()
            .unwrap_or(usize::MAX);
        let first = model
            .max_load_order()
            .max(4)
            .max(self.count_cap.unwrap_or(0).min(below_meshes));
        let caps: Vec<usize> = self
            .names
            .iter()
            .enumerate()
            .map(|(b, n)| {
                harmonics
                    .caps
                    .get(n)
                    .copied()
                    .unwrap_or(if b == 0 { first } else { 4 })
            })
            .collect();
        let mut samples = Vec::with_capacity(caps.len());
        for (n, &c) in self.names.iter().zip(&caps) {
            let least = 2 * c + 1;
            let s = harmonics
                .grid
                .get(n)
                .copied()
                .unwrap_or((2 * c + 3).next_power_of_two());
            if s < least {
                return Err((
                    format!("harmonics.grid.{n}"),
                    format!("must be at least 2 × cap + 1 = {least} (the cap of base `{n}` is {c}), got {s}"),
                ));
            }
            samples.push(s);
        }
        let truncation = harmonics
            .total
            .map_or(Truncation::Box, |total| Truncation::Diamond { total });
        let plan = TorusPlan {
            bases,
            bindings: self.bindings,
            caps,
            samples,
            truncation,
            rad_s_per_speed: speed.per_unit,
            speed: speed.speed,
            why: self.why,
            auto: harmonics.torus_auto()?,
            tolerance: crate::torus::NewtonKrylov::default().tolerance,
        };
        let set = plan
            .index_set()
            .map_err(|e| ("harmonics.caps".to_string(), e.to_string()))?;
        plan.grid_size()
            .map_err(|e| ("harmonics.grid".to_string(), e))?;
        plan.check_orders(model, &set)?;
        Ok(plan)
    }
}

/// A scene on several base frequencies: the bases, which element follows which, the index set
/// and the grid. Loads and elements not named in `bindings` follow base 0.
#[derive(Debug, Clone, PartialEq)]
pub struct TorusPlan {
    /// The bases; ratios are orders of the scene's speed (the reference shaft).
    pub bases: Bases,
    /// `(element, base)` of the elements on another base than the first.
    pub bindings: Vec<(String, usize)>,
    /// The cap of each base.
    pub caps: Vec<usize>,
    /// Grid points per base.
    pub samples: Vec<usize>,
    /// Box or diamond.
    pub truncation: Truncation,
    /// Ω (rad/s) per unit of the scene's speed: the bases turn at `Ω r_b`.
    pub rad_s_per_speed: f64,
    /// The scene's speed, in its unit.
    pub speed: f64,
    /// Why the scene is on the torus.
    pub why: String,
    /// Automatic caps (`harmonics.auto = true`): the caps above are the first level.
    pub auto: Option<crate::torus::AutoCaps>,
    /// Newton–Krylov's tolerance of the relative residual (`--tolerance`).
    pub tolerance: f64,
}

impl TorusPlan {
    /// The index set of the caps.
    pub fn index_set(&self) -> crate::Result<IndexSet> {
        IndexSet::new(&self.bases, &self.caps, self.truncation)
    }

    /// `model` (the scene's) with its elements on their bases.
    pub fn bind<'m>(&self, model: &'m Model) -> crate::Result<TorusModel<'m>> {
        let names = self.bases.names();
        self.bindings
            .iter()
            .try_fold(TorusModel::new(model, self.bases.clone()), |tm, (e, b)| {
                tm.bind_element(e, &names[*b])
            })
    }

    /// Every load's order and every law's time order is a line of `set`, or the error names
    /// the cap or the total that leaves it out.
    fn check_orders(&self, model: &Model, set: &IndexSet) -> Result<(), FieldError> {
        let tm = self
            .bind(model)
            .map_err(|e| ("elements".to_string(), e.to_string()))?;
        let d = self.bases.len();
        let loads = model
            .loads()
            .iter()
            .enumerate()
            .filter(|(_, l)| l.order > 0)
            .map(|(i, l)| {
                let what = format!(
                    "the load on `{}` at order {}",
                    model.dof_names()[l.dof],
                    l.order
                );
                (what, l.order, tm.load_base(i))
            });
        let laws = model.elements().iter().enumerate().filter_map(|(e, el)| {
            let z = el.law().time_order()?;
            Some((
                format!("element `{}`, which varies at order {z}", el.name()),
                z,
                tm.element_base(e),
            ))
        });
        for (what, order, b) in loads.chain(laws) {
            let mut k = vec![0i32; d];
            k[b] = i32::try_from(order).unwrap_or(i32::MAX);
            if set.contains_either_sign(&k) {
                continue;
            }
            let name = &self.bases.names()[b];
            return Err(if order > self.caps[b] {
                (
                    format!("harmonics.caps.{name}"),
                    format!(
                        "must be at least {order} for {what} of base `{name}`, got {}",
                        self.caps[b]
                    ),
                )
            } else {
                (
                    "harmonics.total".to_string(),
                    format!("must be at least {order} for {what} of base `{name}`"),
                )
            });
        }
        Ok(())
    }

    fn grid_size(&self) -> Result<(), String> {
        let points: f64 = self.samples.iter().map(|&s| s as f64).product();
        if points > crate::torus::MAX_GRID as f64 {
            return Err(format!(
                "{points} grid points, at most {}: lower the caps or the grid",
                crate::torus::MAX_GRID
            ));
        }
        Ok(())
    }
}
