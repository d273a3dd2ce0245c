//! Triangular conorms: fuzzy disjunction and evidence accumulation.
//!
//! A t-conorm `S: [0,1]² → [0,1]` is commutative, associative, monotone and has
//! 0 as neutral element; it is the De Morgan dual `S(x, y) = 1 - T(1 - x, 1 - y)`
//! of a t-norm (Klement, Mesiar & Pap 2000, Definition 1.13). fuzzyvox folds
//! repeated observations of a voxel into its membership with a t-conorm, so
//! [`TConorm::apply`] and [`TConorm::weighted`] sit in the map-integration
//! inner loop: the common families (max, probabilistic sum, bounded sum) use
//! direct `f32` formulas, the parametric ones `f64` kernels that stay finite
//! for extreme parameters.
//!
//! Archimedean t-conorms have an additive generator `g` with
//! `S(x, y) = g⁽⁻¹⁾(g(x) + g(y))`. [`TConorm::weighted`] uses it to give an
//! observation of confidence `w` exactly the weight of `w` observations: two
//! half-confidence observations of `μ` combine to one full observation of `μ`.

use serde::{Deserialize, Serialize};

use super::numeric::{logistic, logit, ordered, p_norm, to_unit, unit};
use super::validated::validated_family;
use super::{Family, OperatorError, TNorm, frank, generator, tnorm};

validated_family!(
    /// A validated t-conorm (fuzzy OR, evidence accumulation) of one [`Family`].
    TConorm,
    "t-conorm",
    dual: TNorm,
    "The dual t-norm `T(x, y) = 1 - S(1 - x, 1 - y)` of the same family."
);

impl TConorm {
    /// Evaluates `S(x, y) = 1 - T(1 - x, 1 - y)`.
    ///
    /// Inputs are clamped into `[0, 1]` (NaN counts as 0). The result is in
    /// `[0, 1]` and never NaN. `S(x, 0) = x` holds exactly, `S(x, 1) = 1`
    /// exactly except for the probabilistic sum (within one `f32` ulp), and
    /// `S(x, y) == S(y, x)` bit for bit.
    #[inline]
    pub fn apply(&self, x: f32, y: f32) -> f32 {
        let (x, y) = (unit(x), unit(y));
        match self.family {
            Family::Minimum => x.max(y),
            // x + y - xy keeps full relative precision for small memberships,
            // where evidence accumulation starts.
            Family::Product => (x + y - x * y).min(1.0),
            Family::Lukasiewicz => (x + y).min(1.0),
            Family::Drastic => {
                if x == 0.0 {
                    y
                } else if y == 0.0 {
                    x
                } else {
                    1.0
                }
            }
            Family::NilpotentMinimum => {
                // x + y < 1 tested exactly, as in the t-norm.
                let (a, b) = ordered(x, y);
                if a < 1.0 - b { b } else { 1.0 }
            }
            family => {
                // Answer the boundary exactly so the kernels only see the open
                // square, where every logarithm and ratio is finite.
                if x == 0.0 {
                    y
                } else if y == 0.0 {
                    x
                } else if x == 1.0 || y == 1.0 {
                    1.0
                } else {
                    to_unit(interior(family, f64::from(x), f64::from(y)))
                }
            }
        }
    }

    /// The additive generator `g(x)` of this t-conorm, with `g(0) = 0`, `g`
    /// strictly increasing and `S(x, y) = g⁽⁻¹⁾(g(x) + g(y))`.
    ///
    /// `x` is clamped into `[0, 1]`. `g(1)` is `+∞` for strict families and
    /// finite for nilpotent ones (bounded sum, Yager, Schweizer–Sklar `p > 0`).
    /// The generators used are `g(x) = f(1 - x)` for the t-norm generators `f`
    /// of Klement, Mesiar & Pap (2000), e.g. `-ln(1 - x)` for the probabilistic
    /// sum and `x` for the bounded sum. Returns `None` for the non-Archimedean
    /// families (minimum, drastic, nilpotent minimum).
    pub fn generator(&self, x: f32) -> Option<f64> {
        generator::generator(self.family, f64::from(unit(x)))
    }

    /// The pseudo-inverse `g⁽⁻¹⁾(y) = g⁻¹(min(y, g(1)))`, saturating at 1 for
    /// nilpotent families. `y` is clamped into `[0, ∞]` (NaN counts as 0).
    /// Returns `None` for the non-Archimedean families.
    pub fn generator_inverse(&self, y: f64) -> Option<f32> {
        let y = if y >= 0.0 { y } else { 0.0 };
        generator::generator_inverse(self.family, y).map(to_unit)
    }

    /// Confidence-weighted evidence `g⁽⁻¹⁾(w · g(μ))` for Archimedean families
    /// and `w · μ` for the others.
    ///
    /// `μ` and `w` are clamped into `[0, 1]`; `w = 0` gives 0 (even when
    /// `g(μ) = ∞`) and `w = 1` gives `μ` exactly. For Archimedean families the
    /// weight counts observations: `S(weighted(μ, ½), weighted(μ, ½)) = μ`.
    /// The result is monotone in both arguments, in `[0, 1]` and never NaN.
    #[inline]
    pub fn weighted(&self, mu: f32, w: f32) -> f32 {
        generator::weighted(self.family, mu, w)
    }
}

impl Default for TConorm {
    /// The probabilistic sum `x + y - xy`, which treats observations as
    /// independent evidence.
    fn default() -> TConorm {
        TConorm {
            family: Family::Product,
        }
    }
}

impl std::fmt::Display for TConorm {
    /// Writes the t-conorm's name, `NAME` or `NAME:PARAM` (`maximum`, `probabilistic-sum`,
    /// `dombi:2`, see [`Family::conorm_name`]); `Family`'s `FromStr` reads it back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.family.conorm_name())?;
        if let Some(value) = self.family.parameter() {
            f.write_str(":")?;
            super::family::write_parameter(f, value)?;
        }
        Ok(())
    }
}

/// `S(x, y)` in `f64` for `x, y` in the open interval `(0, 1)`.
///
/// Returns a value in `[0, 1]` up to rounding; the caller clamps.
pub(crate) fn interior(family: Family, x: f64, y: f64) -> f64 {
    match family {
        Family::Minimum => x.max(y),
        Family::Product => x + y - x * y,
        Family::Lukasiewicz => (x + y).min(1.0),
        // Neither argument is 0 in the open square.
        Family::Drastic => 1.0,
        Family::NilpotentMinimum => {
            if x + y < 1.0 {
                x.max(y)
            } else {
                1.0
            }
        }
        Family::Hamacher { gamma } => {
            // (x + y + (γ - 2)xy) / (1 + (γ - 1)xy) as sums of non-negative
            // terms, so large γ causes no cancellation.
            let xy = x * y;
            (x * (1.0 - y) + y * (1.0 - x) + gamma * xy) / ((1.0 - xy) + gamma * xy)
        }
        Family::Einstein => (x + y) / (1.0 + x * y),
        Family::Yager { p } => p_norm(x, y, p).min(1.0),
        Family::Frank { s } => frank::tconorm(x, y, s.ln()),
        Family::Dombi { lambda } => {
            // Mirror image of the t-norm's logit form.
            let (u, v) = (logit(x), logit(y));
            let spread = (-lambda * (u - v).abs()).exp().ln_1p() / lambda;
            logistic(u.max(v) + spread)
        }
        // Evaluated literally as the dual: near the saturation boundary of the
        // nilpotent members the value is so sensitive to its inputs that any
        // other rounding path would visibly break De Morgan duality.
        Family::SchweizerSklar { p } => 1.0 - tnorm::schweizer_sklar(1.0 - x, 1.0 - y, p),
        // 1 - exp(-‖(-ln(1-x), -ln(1-y))‖_p), with ln_1p and expm1 keeping
        // small memberships exact.
        Family::AczelAlsina { p } => -(-p_norm(-(-x).ln_1p(), -(-y).ln_1p(), p)).exp_m1(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::close;

    fn s(family: Family, x: f32, y: f32) -> f32 {
        TConorm::new(family)
            .map(|s| s.apply(x, y))
            .unwrap_or(f32::NAN)
    }

    #[test]
    fn exact_values() {
        assert_eq!(s(Family::Minimum, 0.3, 0.7), 0.7);
        assert_eq!(s(Family::Product, 0.5, 0.5), 0.75);
        assert_eq!(s(Family::Lukasiewicz, 0.5, 0.25), 0.75);
        assert_eq!(s(Family::Lukasiewicz, 0.5, 0.75), 1.0);
        assert_eq!(s(Family::Drastic, 0.1, 0.1), 1.0);
        assert_eq!(s(Family::Drastic, 0.0, 0.4), 0.4);
        assert_eq!(s(Family::NilpotentMinimum, 0.2, 0.3), 0.3);
        assert_eq!(s(Family::NilpotentMinimum, 0.5, 0.5), 1.0);
        // Einstein sum: (0.5 + 0.5) / (1 + 0.25) = 0.8.
        assert!(close(s(Family::Einstein, 0.5, 0.5), 0.8));
        // Hamacher γ = 0: (x + y - 2xy) / (1 - xy) = 0.5 / 0.75.
        assert!(close(
            s(Family::Hamacher { gamma: 0.0 }, 0.5, 0.5),
            2.0 / 3.0
        ));
        // Yager p = 2: the Euclidean norm, saturated at 1.
        assert!(close(s(Family::Yager { p: 2.0 }, 0.3, 0.4), 0.5));
        assert_eq!(s(Family::Yager { p: 2.0 }, 0.8, 0.9), 1.0);
    }

    #[test]
    fn hamacher_one_is_the_probabilistic_sum() {
        for x in [0.0, 0.1, 0.5, 0.77, 1.0] {
            for y in [0.0, 0.2, 0.5, 0.99, 1.0] {
                let (a, b) = (
                    s(Family::Hamacher { gamma: 1.0 }, x, y),
                    s(Family::Product, x, y),
                );
                assert!(close(a, b), "({x}, {y}): {a} vs {b}");
                let (a, b) = (
                    s(Family::Hamacher { gamma: 2.0 }, x, y),
                    s(Family::Einstein, x, y),
                );
                assert!(close(a, b), "({x}, {y}): {a} vs {b}");
            }
        }
    }

    #[test]
    fn generators_have_the_documented_closed_forms() {
        let product = TConorm::default();
        assert_eq!(product.generator(0.0), Some(0.0));
        assert!((product.generator(0.5).unwrap_or(0.0) - std::f64::consts::LN_2).abs() < 1e-12);
        assert_eq!(product.generator(1.0), Some(f64::INFINITY));
        assert_eq!(product.generator_inverse(f64::INFINITY), Some(1.0));
        let bounded = TConorm::new(Family::Lukasiewicz).unwrap_or_default();
        assert_eq!(bounded.generator(0.25), Some(0.25));
        assert_eq!(bounded.generator_inverse(3.0), Some(1.0));
        let yager = TConorm::new(Family::Yager { p: 3.0 }).unwrap_or_default();
        assert!((yager.generator(0.5).unwrap_or(0.0) - 0.125).abs() < 1e-12);
        for family in [Family::Minimum, Family::Drastic, Family::NilpotentMinimum] {
            let s = TConorm::new(family).unwrap_or_default();
            assert_eq!(s.generator(0.5), None);
            assert_eq!(s.generator_inverse(0.5), None);
        }
        assert_eq!(product.generator_inverse(f64::NAN), Some(0.0));
        assert_eq!(product.generator_inverse(-3.0), Some(0.0));
    }

    #[test]
    fn weighted_exact_values() {
        let product = TConorm::default();
        // Half of 0.75 under the probabilistic sum: 1 - sqrt(0.25) = 0.5.
        assert!(close(product.weighted(0.75, 0.5), 0.5));
        assert_eq!(product.weighted(1.0, 0.0), 0.0);
        assert_eq!(product.weighted(1.0, 0.5), 1.0);
        assert_eq!(product.weighted(0.3, 1.0), 0.3);
        assert_eq!(product.weighted(0.3, f32::NAN), 0.0);
        assert_eq!(product.weighted(0.3, 7.0), 0.3);
        let max = TConorm::new(Family::Minimum).unwrap_or_default();
        assert_eq!(max.weighted(0.5, 0.5), 0.25);
        let bounded = TConorm::new(Family::Lukasiewicz).unwrap_or_default();
        assert_eq!(bounded.weighted(0.5, 0.5), 0.25);
        // Nilpotent: a full membership weighted by w stays below 1.
        let yager = TConorm::new(Family::Yager { p: 2.0 }).unwrap_or_default();
        assert!(close(yager.weighted(1.0, 0.5), 0.5f32.sqrt()));
    }

    #[test]
    fn negative_zero_parameters_are_the_zero_members() {
        // -0.0 passes validation (it is >= 0) and must select the special
        // forms for γ = 0 and p = 0, not divide by zero.
        for (negative, positive) in [
            (
                Family::Hamacher { gamma: -0.0 },
                Family::Hamacher { gamma: 0.0 },
            ),
            (
                Family::SchweizerSklar { p: -0.0 },
                Family::SchweizerSklar { p: 0.0 },
            ),
        ] {
            let (a, b) = (
                TConorm::new(negative).unwrap_or_default(),
                TConorm::new(positive).unwrap_or_default(),
            );
            assert_eq!(a.family(), negative);
            for x in [0.0, 0.2, 0.7, 1.0] {
                assert_eq!(a.generator(x), b.generator(x));
                assert_eq!(a.weighted(x, 0.3), b.weighted(x, 0.3));
                assert_eq!(a.apply(x, 0.4), b.apply(x, 0.4));
                assert_eq!(a.dual().apply(x, 0.4), b.dual().apply(x, 0.4));
            }
        }
    }

    #[test]
    fn serde_validates() {
        // The serialised form is the family; an invalid one cannot be loaded.
        let tconorm = TConorm::new(Family::Frank { s: 3.0 }).unwrap_or_default();
        assert_eq!(Family::from(tconorm), Family::Frank { s: 3.0 });
        assert!(TConorm::try_from(Family::Frank { s: 1.0 }).is_err());
        assert!(TNorm::try_from(Family::Yager { p: -2.0 }).is_err());
        assert_eq!(TConorm::default().family(), Family::Product);
    }
}
