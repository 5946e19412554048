//! A [`Model`] on several base frequencies: each element's law and each load follows the
//! angle `θ_b = ω_b t` of one base.

use super::Bases;
use crate::error::{Error, Result};
use crate::model::Model;

/// A model whose elements and loads are bound to [`Bases`]: an element's law
/// `f(θ_b, u, u̇)` sees the angle of its base (a mesh stiffness on the mesh's base with one
/// cycle per revolution, or on a shaft's base with its teeth); a load of order `o` on base b is
/// `c cos(o θ_b) + s sin(o θ_b)`. Everything starts on the first base.
///
/// ```
/// use hbal::{force::LinearSpring, torus::{Bases, TorusModel}, Model};
/// let model = Model::builder(&["x"]).mass_diagonal(&[1.0])
///     .element("spring", &[("x", 1.0)], LinearSpring::new(1.0, 0.1))
///     .load("x", 1, 1.0, 0.0).load("x", 1, 0.5, 0.0).build().unwrap();
/// let bases = Bases::new(&[("a", 1.0), ("b", 2f64.sqrt())]).unwrap();
/// let tm = TorusModel::new(&model, bases).bind_load(1, "b").unwrap();
/// assert_eq!(tm.load_base(1), 1);
/// assert!(TorusModel::new(&model, tm.bases().clone()).bind_element("spring", "c").is_err());
/// ```
#[derive(Debug, Clone)]
pub struct TorusModel<'m> {
    model: &'m Model,
    bases: Bases,
    element_base: Vec<usize>,
    load_base: Vec<usize>,
}

impl<'m> TorusModel<'m> {
    /// `model` on `bases`, every element and load on the first base.
    pub fn new(model: &'m Model, bases: Bases) -> Self {
        Self {
            model,
            bases,
            element_base: vec![0; model.elements().len()],
            load_base: vec![0; model.loads().len()],
        }
    }

    /// Binds the element called `element` to the base called `base`.
    pub fn bind_element(mut self, element: &str, base: &str) -> Result<Self> {
        let b = self.base(&format!("element `{element}`"), base)?;
        let Some(e) = self
            .model
            .elements()
            .iter()
            .position(|e| e.name() == element)
        else {
            return Err(Error::InvalidElement {
                context: format!("torus binding of element `{element}`"),
                reason: format!(
                    "the model has no such element (it has: {})",
                    list(self.model.elements().iter().map(|e| e.name()))
                ),
            });
        };
        self.element_base[e] = b;
        Ok(self)
    }

    /// Binds load number `load` (its position in [`Model::loads`]) to the base called `base`.
    pub fn bind_load(mut self, load: usize, base: &str) -> Result<Self> {
        let b = self.base(&format!("load {load}"), base)?;
        if load >= self.load_base.len() {
            return Err(Error::InvalidElement {
                context: format!("torus binding of load {load}"),
                reason: format!("the model has {} loads", self.load_base.len()),
            });
        }
        self.load_base[load] = b;
        Ok(self)
    }

    fn base(&self, what: &str, name: &str) -> Result<usize> {
        self.bases.index(name).ok_or_else(|| Error::InvalidElement {
            context: format!("torus binding of {what}"),
            reason: format!(
                "no base `{name}` (the bases are: {})",
                list(self.bases.names().iter().map(String::as_str))
            ),
        })
    }

    /// The model.
    pub fn model(&self) -> &'m Model {
        self.model
    }

    /// The bases.
    pub fn bases(&self) -> &Bases {
        &self.bases
    }

    /// The base of element `e`.
    pub fn element_base(&self, e: usize) -> usize {
        self.element_base[e]
    }

    /// The base of load `l`.
    pub fn load_base(&self, l: usize) -> usize {
        self.load_base[l]
    }
}

fn list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    names
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}
