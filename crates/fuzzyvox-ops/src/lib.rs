//! Fuzzy aggregation operators: t-norms, t-conorms, complements and hedges.
//!
//! Voxel memberships in fuzzyvox are degrees in `[0, 1]`. They are combined
//! with a [`TNorm`] (fuzzy AND: both must hold), accumulated across
//! observations with its dual [`TConorm`] (fuzzy OR: evidence adds up),
//! negated with a [`Complement`] and reshaped with a [`Hedge`]. Conjunction and
//! disjunction come in matched pairs, the parametric [`Family`] of t-norms of
//! Klement, Mesiar & Pap, *Triangular Norms* (Kluwer, 2000), related by De
//! Morgan duality `S(x, y) = 1 - T(1 - x, 1 - y)`.
//!
//! For Archimedean families the t-conorm has an additive generator `g`, in
//! which evidence simply adds: `S(x, y) = g⁽⁻¹⁾(g(x) + g(y))`. This gives
//! observation confidence a precise meaning, [`TConorm::weighted`]: an
//! observation with confidence `w` counts as `w` of an observation.
//!
//! All operators take and return `f32`, clamp their inputs into `[0, 1]`
//! (NaN counts as 0) and never return NaN or a value outside `[0, 1]`, for any
//! valid parameter; parametric families are evaluated in `f64` with
//! overflow-free formulations.
//!
//! ```
//! use fuzzyvox_ops::{Family, TConorm};
//!
//! let s = TConorm::new("hamacher:0".parse::<Family>()?)?;
//! // Two observations at half confidence count as one full observation.
//! let half = s.weighted(0.8, 0.5);
//! assert!((s.apply(half, half) - 0.8).abs() < 1e-6);
//! // De Morgan duality links the conorm to its t-norm.
//! let t = s.dual();
//! assert!((s.apply(0.3, 0.6) - (1.0 - t.apply(0.7, 0.4))).abs() < 1e-6);
//! # Ok::<(), fuzzyvox_ops::OperatorError>(())
//! ```

mod complement;
mod family;
mod frank;
mod generator;
mod hedge;
pub(crate) mod numeric;
mod tconorm;
mod tnorm;
mod validated;

#[cfg(test)]
mod tests;

pub use complement::Complement;
pub use family::Family;
pub use hedge::Hedge;
pub use numeric::unit;
pub use tconorm::TConorm;
pub use tnorm::TNorm;

/// Errors from constructing or parsing an operator.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OperatorError {
    /// A family or complement parameter is NaN, infinite or out of range.
    #[error("operator parameter {name} = {value} is invalid: {expected}")]
    InvalidParameter {
        /// The parameter's name, e.g. `"gamma"` or `"p"`.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The accepted domain, e.g. `"must be finite and > 0"`.
        expected: &'static str,
    },
    /// The operator name is not one of the known families or aliases.
    #[error(
        "unknown operator `{0}`; expected one of: minimum, product, lukasiewicz, drastic, \
         nilpotent-minimum, hamacher:GAMMA, einstein, yager:P, frank:S, dombi:LAMBDA, \
         schweizer-sklar:P, aczel-alsina:P"
    )]
    UnknownOperator(String),
    /// The operator is known but its text form is malformed: a missing,
    /// unexpected, empty or unparsable parameter.
    #[error("operator `{name}` {problem}")]
    BadSyntax {
        /// The canonical name of the operator.
        name: String,
        /// What is wrong, phrased to follow the name.
        problem: String,
    },
}
