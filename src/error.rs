//! Errors of hbal: every variant names the place (element, DOF, harmonic, parameter) so that a
//! user can act on the message.

/// Result alias used throughout hbal.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What went wrong, and where.
///
/// Problems with the iteration itself (divergence, running out of iterations, a non-finite
/// iterate) are not errors: they are a [`Termination`](crate::Termination) of the returned
/// [`Solution`](crate::Solution), which keeps the last good iterate. Only where there is no
/// finite iterate at all (the start itself has no finite residual) a solve returns
/// [`Error::NonFinite`], naming where: no result ever holds NaN or infinity.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A parameter is non-finite or outside its physical range.
    #[error("{context}: parameter `{name}` must be {requirement}, got {value}")]
    InvalidParameter {
        /// Where the parameter lives, e.g. `element "mesh" (mesh_stiffness)`.
        context: String,
        /// The parameter's name as in a scene file.
        name: String,
        /// The offending value.
        value: f64,
        /// The rule it breaks, e.g. `finite and >= 0`.
        requirement: String,
    },
    /// An element or load names a DOF the model does not have.
    #[error("{context}: unknown DOF `{name}` (the model has: {known})")]
    UnknownDof {
        /// Where the name was used.
        context: String,
        /// The unknown name.
        name: String,
        /// The model's DOF names, comma separated.
        known: String,
    },
    /// An element's fields contradict each other (e.g. both or neither of two alternatives).
    #[error("{context}: {reason}")]
    InvalidElement {
        /// The element, e.g. ``element `mesh` ``.
        context: String,
        /// What is wrong, naming the fields.
        reason: String,
    },
    /// Options of an analysis that contradict each other or the scene.
    #[error("{option} {reason}")]
    InvalidOptions {
        /// The option, e.g. `--start`.
        option: String,
        /// What is wrong.
        reason: String,
    },
    /// Two DOFs share a name, or there are none.
    #[error("invalid DOF list: {reason}")]
    InvalidDofs {
        /// Why the list is rejected.
        reason: String,
    },
    /// A matrix or vector has the wrong size.
    #[error("{context}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Which matrix or vector.
        context: String,
        /// The size it must have.
        expected: String,
        /// The size it has.
        got: String,
    },
    /// The mass matrix is not symmetric positive definite.
    #[error("mass matrix is not symmetric positive definite: {reason}")]
    MassNotPositiveDefinite {
        /// What failed (asymmetry, a non-positive pivot, ...).
        reason: String,
    },
    /// N time samples cannot carry H harmonics.
    #[error("{samples} time samples cannot resolve {harmonics} harmonics: need N >= 2H+1 = {}", 2 * .harmonics + 1)]
    TooFewSamples {
        /// H.
        harmonics: usize,
        /// N.
        samples: usize,
    },
    /// A load has an order above the number of harmonics.
    #[error("load on DOF `{dof}` has order {order} but only {harmonics} harmonics are kept: {}", load_order_advice(*.order))]
    LoadOrderTooHigh {
        /// DOF of the load.
        dof: String,
        /// Harmonic order of the load.
        order: usize,
        /// H.
        harmonics: usize,
    },
    /// An element's time variation (a mesh order) lies above the number of harmonics: its
    /// response would be missing, or aliased onto lower harmonics.
    #[error("element `{element}` varies at order {order} (its mesh cycles per period) but only {harmonics} harmonics are kept: {}", order_advice(*.order))]
    ElementOrderTooHigh {
        /// The element.
        element: String,
        /// Its order.
        order: usize,
        /// H.
        harmonics: usize,
    },
    /// The dynamic stiffness `-(k Ω)² M + i k Ω D0 + K0` is singular at harmonic `k`:
    /// an undamped resonance (or, at k = 0, a rigid-body mode under a static load).
    #[error("dynamic stiffness is singular at harmonic {harmonic} (frequency {omega} rad/s, relative pivot {relative_pivot:.3e}): {hint}")]
    SingularDynamicStiffness {
        /// Harmonic index k.
        harmonic: usize,
        /// k Ω in rad/s.
        omega: f64,
        /// Smallest LU pivot relative to the matrix scale.
        relative_pivot: f64,
        /// What to change.
        hint: String,
    },
    /// A free-free model whose mean external loads do work on a rigid-body mode: the
    /// drivetrain would accelerate, so there is no periodic solution.
    #[error("the static loads do not balance: net torque {net:.6e} N m on the rigid-body mode (referred to DOF `{reference}`, loaded: {loaded}) (the drivetrain would accelerate: no periodic solution)")]
    UnbalancedStaticLoad {
        /// `rᵀ f_0`, with `r` scaled to turn `reference` by 1 rad.
        net: f64,
        /// The DOF that moves most in the mode.
        reference: String,
        /// The loaded DOFs of the mode with their mean loads.
        loaded: String,
    },
    /// A problem too large for memory (or time), refused before anything is allocated.
    #[error("{what} needs about {size}, more than the limit of {limit}: {advice}")]
    TooLarge {
        /// What would be built, with the sizes that decide it.
        what: String,
        /// Its estimated size.
        size: String,
        /// The limit.
        limit: String,
        /// What to lower.
        advice: String,
    },
    /// A computation produced NaN or infinity.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Which quantity.
        what: String,
    },
    /// The solver framework (argmin) reported an error.
    #[error("solver failed: {reason}")]
    Solver {
        /// argmin's message.
        reason: String,
    },
    /// An analysis that does not support laws with memory (hysteresis).
    #[error("{analysis} not available for laws with memory (element `{element}`)")]
    MemoryUnsupported {
        /// The analysis, e.g. `stability`.
        analysis: String,
        /// The element whose law has memory.
        element: String,
    },
    /// The time-domain reference integration failed.
    #[error("time integration failed: {reason}")]
    TimeIntegration {
        /// The integrator's reason.
        reason: String,
    },
    /// A failure along an analysis whose input was checked before it started (a sweep's
    /// later point: a singular dynamic stiffness, a failed setup): numerical, whatever the
    /// inner error's kind ([`Error::exit_code`]).
    #[error(transparent)]
    AfterCheck(Box<Error>),
    /// A scene that cannot be read or does not follow the schema (bad input).
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    /// An output directory or file that cannot be written, or a name that cannot be part of
    /// a file name there ([`crate::render`]; bad input: nothing is computed before it is
    /// checked).
    #[error("{0}")]
    Output(String),
    /// An analysis stopped by its caller (Ctrl-C in Python, a progress callback that raised)
    /// before it finished: nothing of it is reported.
    #[error("{what} cancelled")]
    Cancelled {
        /// The analysis, e.g. `the report`.
        what: String,
    },
}

impl Error {
    /// The exit code of the command-line contract: 1 for a numerical failure (a non-finite
    /// value, a failed solver or integration, a failure along a checked analysis), 2 for bad
    /// input (a model too large to set up is bad input wherever it is found).
    ///
    /// ```
    /// use hbal::Error;
    /// assert_eq!(Error::invalid("mass", "m", -1.0, ">= 0").exit_code(), 2);
    /// assert_eq!(Error::NonFinite { what: "residual".into() }.exit_code(), 1);
    /// let along = Error::AfterCheck(Box::new(Error::invalid("mass", "m", -1.0, ">= 0")));
    /// assert_eq!(along.exit_code(), 1);
    /// ```
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::NonFinite { .. }
            | Error::Solver { .. }
            | Error::TimeIntegration { .. }
            | Error::Cancelled { .. } => 1,
            Error::AfterCheck(inner) if matches!(**inner, Error::TooLarge { .. }) => 2,
            Error::AfterCheck(_) => 1,
            _ => 2,
        }
    }

    /// `self` as a failure along an analysis whose input was checked ([`Error::AfterCheck`]).
    pub fn after_check(self) -> Self {
        match self {
            Error::AfterCheck(_) => self,
            e => Error::AfterCheck(Box::new(e)),
        }
    }

    /// Shorthand for [`Error::InvalidParameter`].
    pub fn invalid(
        context: impl Into<String>,
        name: impl Into<String>,
        value: f64,
        requirement: impl Into<String>,
    ) -> Self {
        Error::InvalidParameter {
            context: context.into(),
            name: name.into(),
            value,
            requirement: requirement.into(),
        }
    }
}

/// Smallest magnitude of a nonzero number in a scene (and of a speed): smaller ones are
/// subnormal or round to zero in products (`1e-320` rad/s would make the period infinite).
pub const MIN_MAGNITUDE: f64 = 1e-100;

/// Largest magnitude of a number in a scene (and of a speed): a product of three such numbers
/// is still finite (`1e308` as a mass overflows the dynamic stiffness).
pub const MAX_MAGNITUDE: f64 = 1e100;

/// `true` if `value` is 0 or finite with a magnitude in
/// [[`MIN_MAGNITUDE`], [`MAX_MAGNITUDE`]].
pub fn in_magnitude_range(value: f64) -> bool {
    value == 0.0 || (MIN_MAGNITUDE..=MAX_MAGNITUDE).contains(&value.abs())
}

/// Checks that `value` is finite and `>= 0`.
pub(crate) fn check_non_negative(context: &str, name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(context, name, value, "finite and >= 0"))
    }
}

/// Checks that `value` is finite and `> 0`.
pub(crate) fn check_positive(context: &str, name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(context, name, value, "finite and > 0"))
    }
}

/// Checks that `value` is finite.
pub(crate) fn check_finite(context: &str, name: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(context, name, value, "finite"))
    }
}

/// What to do about a time order above H: raise H, or, beyond any basis, check the element.
fn order_advice(order: usize) -> String {
    if order <= crate::HarmonicBasis::MAX_HARMONICS / 4 {
        format!("raise H to at least {order}, better a few times that")
    } else {
        format!(
            "that is more than any harmonic basis holds (H <= {}): check the element's `teeth` \
             (mesh cycles per period of the fundamental), or make the mesh order the fundamental \
             (`fundamental.order`)",
            crate::HarmonicBasis::MAX_HARMONICS
        )
    }
}

/// What to do about a load order above H: raise H, or, beyond any basis, check the order.
fn load_order_advice(order: usize) -> String {
    if order <= crate::HarmonicBasis::MAX_HARMONICS {
        format!("raise H to at least {order}")
    } else {
        format!(
            "that is more than any harmonic basis holds (H <= {}): check the load's `order` \
             (a harmonic index of the fundamental)",
            crate::HarmonicBasis::MAX_HARMONICS
        )
    }
}
