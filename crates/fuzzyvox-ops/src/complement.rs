//! Fuzzy complements (negations).
//!
//! A fuzzy complement `N: [0,1] → [0,1]` is decreasing with `N(0) = 1` and
//! `N(1) = 0`; the ones offered here are continuous, strictly decreasing and
//! involutive (`N(N(x)) = x`), i.e. strong negations (Klement, Mesiar & Pap
//! 2000, Definition 11.3; Klir & Yuan, *Fuzzy Sets and Fuzzy Logic*, 1995,
//! §3.2). fuzzyvox uses them to turn "occupied" into "free" memberships.

use serde::{Deserialize, Serialize};

use super::OperatorError;
use super::numeric::{to_unit, unit};

/// A fuzzy complement.
///
/// The variants are public so they can be written literally; call
/// [`Complement::new`] to validate a parameter that comes from a user. On an
/// unvalidated, out-of-range parameter [`Complement::apply`] still returns a
/// value in `[0, 1]`, but it is meaningless.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Complement {
    /// The standard complement `N(x) = 1 - x`.
    Standard,
    /// Sugeno's λ-complement `N(x) = (1 - x) / (1 + λx)`, `λ > -1`.
    /// `λ = 0` is the standard complement; `λ > 0` lowers the curve.
    Sugeno {
        /// The parameter `λ > -1`.
        lambda: f64,
    },
    /// Yager's complement `N(x) = (1 - x^w)^(1/w)`, `w > 0`.
    /// `w = 1` is the standard complement; `w > 1` raises the curve.
    Yager {
        /// The exponent `w > 0`.
        w: f64,
    },
}

impl Complement {
    /// Validates the parameter, returning the complement unchanged if it is
    /// finite and in range (`λ > -1` for Sugeno, `w > 0` for Yager).
    ///
    /// # Errors
    /// [`OperatorError::InvalidParameter`] otherwise.
    pub fn new(self) -> Result<Complement, OperatorError> {
        let invalid = |name, value, expected| {
            Err(OperatorError::InvalidParameter {
                name,
                value,
                expected,
            })
        };
        match self {
            Complement::Standard => Ok(self),
            Complement::Sugeno { lambda } if !(lambda.is_finite() && lambda > -1.0) => {
                invalid("lambda", lambda, "must be finite and > -1")
            }
            Complement::Yager { w } if !(w.is_finite() && w > 0.0) => {
                invalid("w", w, "must be finite and > 0")
            }
            Complement::Sugeno { .. } | Complement::Yager { .. } => Ok(self),
        }
    }

    /// Evaluates `N(x)`. The input is clamped into `[0, 1]` (NaN counts as 0);
    /// the result is in `[0, 1]` and never NaN, with `N(0) = 1` and `N(1) = 0`
    /// exactly.
    pub fn apply(&self, x: f32) -> f32 {
        let x = unit(x);
        match *self {
            Complement::Standard => 1.0 - x,
            Complement::Sugeno { lambda } => {
                let x = f64::from(x);
                to_unit((1.0 - x) / (1.0 + lambda * x))
            }
            Complement::Yager { w } => {
                // (1 - x^w)^(1/w) = exp(ln(-expm1(w ln x)) / w): exact at both
                // ends (ln 0 = -inf gives 1, ln 1 = 0 gives 0) and accurate for
                // x^w close to 1.
                let x = f64::from(x);
                to_unit(((-(w * x.ln()).exp_m1()).ln() / w).exp())
            }
        }
    }
}

impl Default for Complement {
    /// The standard complement `1 - x`.
    fn default() -> Complement {
        Complement::Standard
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unit_input() -> impl Strategy<Value = f32> {
        prop_oneof![1 => Just(0.0f32), 1 => Just(1.0f32), 8 => 0.0f32..=1.0]
    }

    fn complement() -> impl Strategy<Value = Complement> {
        prop_oneof![
            Just(Complement::Standard),
            (-0.9f64..50.0).prop_map(|lambda| Complement::Sugeno { lambda }),
            (0.2f64..10.0).prop_map(|w| Complement::Yager { w }),
        ]
    }

    #[test]
    fn exact_values() {
        assert_eq!(Complement::default().apply(0.25), 0.75);
        let sugeno = Complement::Sugeno { lambda: 1.0 };
        assert!((sugeno.apply(0.5) - 1.0 / 3.0).abs() < 1e-7);
        let yager = Complement::Yager { w: 2.0 };
        assert!((yager.apply(0.6) - 0.8).abs() < 1e-7);
        assert_eq!(Complement::Sugeno { lambda: 0.0 }.apply(0.3), 0.7);
    }

    #[test]
    fn validation() {
        assert_eq!(Complement::Standard.new(), Ok(Complement::Standard));
        assert!(Complement::Sugeno { lambda: -0.5 }.new().is_ok());
        for bad in [
            Complement::Sugeno { lambda: -1.0 },
            Complement::Sugeno { lambda: f64::NAN },
            Complement::Sugeno {
                lambda: f64::INFINITY,
            },
            Complement::Yager { w: 0.0 },
            Complement::Yager { w: f64::NAN },
        ] {
            assert!(
                matches!(bad.new(), Err(OperatorError::InvalidParameter { .. })),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn unvalidated_parameters_still_give_a_membership() {
        for bad in [
            Complement::Sugeno { lambda: -5.0 },
            Complement::Yager { w: -1.0 },
        ] {
            for x in [0.0, 0.1, 0.2, 0.5, 1.0, f32::NAN] {
                let y = bad.apply(x);
                assert!((0.0..=1.0).contains(&y), "{bad:?}({x}) = {y}");
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// N(0) = 1, N(1) = 0 exactly; outputs in [0, 1].
        #[test]
        fn boundary_and_range(n in complement(), x in unit_input()) {
            prop_assert_eq!(n.apply(0.0), 1.0);
            prop_assert_eq!(n.apply(1.0), 0.0);
            let y = n.apply(x);
            prop_assert!((0.0..=1.0).contains(&y), "{:?}({}) = {}", n, x, y);
        }

        /// x1 <= x2 implies N(x1) >= N(x2) (up to f32 rounding, 1e-6).
        #[test]
        fn decreasing(n in complement(), a in unit_input(), b in unit_input()) {
            let (x1, x2) = if a <= b { (a, b) } else { (b, a) };
            prop_assert!(n.apply(x1) + 1e-6 >= n.apply(x2));
        }

        /// N(N(x)) = x up to the f32 rounding of the intermediate N(x).
        ///
        /// Yager's curve is so flat near its ends that N(x) may round to
        /// exactly 0 or 1 (e.g. w = 9.6, x = 0.1: N(x) = 1 - 6e-11), and
        /// |N'| elsewhere amplifies one ulp by up to 1/(1 + λ) = 10 for
        /// Sugeno λ = -0.9. So N is evaluated over the f32 neighbourhood
        /// (two ulps each way) of N(x), and x must lie in the resulting range
        /// widened by 1e-5.
        #[test]
        fn involutive(n in complement(), x in unit_input()) {
            let y = n.apply(x);
            let (lo, hi) = (y.next_down().next_down().max(0.0), y.next_up().next_up().min(1.0));
            let (a, b, c) = (n.apply(lo), n.apply(y), n.apply(hi));
            let (min, max) = (a.min(b).min(c), a.max(b).max(c));
            prop_assert!(
                min - 1e-5 <= x && x <= max + 1e-5,
                "{:?}: {} -> {} -> [{}, {}]", n, x, y, min, max
            );
        }
    }
}
