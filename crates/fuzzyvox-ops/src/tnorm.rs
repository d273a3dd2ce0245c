//! Triangular norms: fuzzy conjunction.
//!
//! A t-norm `T: [0,1]² → [0,1]` is commutative, associative, monotone and has
//! 1 as neutral element (Klement, Mesiar & Pap 2000, Definition 1.1). In
//! fuzzyvox it combines memberships that must hold together, e.g. "occupied
//! *and* observed". The formulas are those of the families listed in
//! [`Family`]; the parametric ones are evaluated in `f64` through
//! overflow-free log-domain forms so that extreme parameters still yield a
//! value in `[0, 1]` rather than NaN.

use serde::{Deserialize, Serialize};

use super::numeric::{logistic, logit, ordered, p_norm, to_unit, unit};
use super::validated::validated_family;
use super::{Family, OperatorError, TConorm, frank};

validated_family!(
    /// A validated t-norm (fuzzy AND) of one [`Family`].
    TNorm,
    "t-norm",
    dual: TConorm,
    "The dual t-conorm `S(x, y) = 1 - T(1 - x, 1 - y)` of the same family."
);

impl TNorm {
    /// Evaluates `T(x, y)`.
    ///
    /// Inputs are clamped into `[0, 1]` (NaN counts as 0). The result is in
    /// `[0, 1]` and never NaN. The boundary laws `T(x, 1) = x` and
    /// `T(x, 0) = 0` hold exactly, and `T(x, y) == T(y, x)` bit for bit.
    #[inline]
    pub fn apply(&self, x: f32, y: f32) -> f32 {
        let (x, y) = (unit(x), unit(y));
        match self.family {
            Family::Minimum => x.min(y),
            Family::Product => x * y,
            Family::Lukasiewicz => {
                // `a - (1 - b)` instead of `a + b - 1` keeps `T(x, 1) = x` exact.
                let (a, b) = ordered(x, y);
                (a - (1.0 - b)).max(0.0)
            }
            Family::Drastic => {
                if x == 1.0 {
                    y
                } else if y == 1.0 {
                    x
                } else {
                    0.0
                }
            }
            Family::NilpotentMinimum => {
                // x + y > 1 tested as a > 1 - b with b = max(x, y): 1 - b is
                // exact in f32 whenever the test can succeed (b >= 0.5),
                // whereas x + y rounds (1e-10 + 1 == 1 would break T(x, 1) = x).
                let (a, b) = ordered(x, y);
                if a > 1.0 - b { a } else { 0.0 }
            }
            family => {
                // The boundary is answered exactly here, so the kernels only
                // ever see the open square, where all logarithms are finite.
                if x == 0.0 || y == 0.0 {
                    0.0
                } else if x == 1.0 {
                    y
                } else if y == 1.0 {
                    x
                } else {
                    to_unit(interior(family, f64::from(x), f64::from(y)))
                }
            }
        }
    }
}

impl Default for TNorm {
    /// The minimum (Gödel) t-norm, the largest t-norm.
    fn default() -> TNorm {
        TNorm {
            family: Family::Minimum,
        }
    }
}

/// `T(x, y)` in `f64` for `x, y` in the open interval `(0, 1)`.
///
/// Returns a value in `[0, 1]` up to rounding; the caller clamps.
pub(crate) fn interior(family: Family, x: f64, y: f64) -> f64 {
    match family {
        Family::Minimum => x.min(y),
        Family::Product => x * y,
        Family::Lukasiewicz => (x + y - 1.0).max(0.0),
        // Neither argument is 1 in the open square.
        Family::Drastic => 0.0,
        Family::NilpotentMinimum => {
            if x + y > 1.0 {
                x.min(y)
            } else {
                0.0
            }
        }
        Family::Hamacher { gamma } => {
            // γ + (1 - γ)(x + y - xy) rewritten as (x + y - xy) + γ(1-x)(1-y):
            // a sum of non-negative terms, free of cancellation for large γ.
            x * y / (x + y - x * y + gamma * (1.0 - x) * (1.0 - y))
        }
        Family::Einstein => x * y / (1.0 + (1.0 - x) * (1.0 - y)),
        Family::Yager { p } => 1.0 - p_norm(1.0 - x, 1.0 - y, p).min(1.0),
        Family::Frank { s } => frank::tnorm(x, y, s.ln()),
        Family::Dombi { lambda } => dombi(x, y, lambda),
        Family::SchweizerSklar { p } => schweizer_sklar(x, y, p),
        Family::AczelAlsina { p } => (-p_norm(-x.ln(), -y.ln(), p)).exp(),
    }
}

/// Dombi t-norm in the logit domain.
///
/// With `u = logit x`, `v = logit y`, the defining formula becomes
/// `logit T = min(u, v) - ln(1 + e^{-λ|u - v|}) / λ`, which cannot overflow
/// for any `λ > 0` and is exact at the diagonal.
pub(crate) fn dombi(x: f64, y: f64, lambda: f64) -> f64 {
    let (u, v) = (logit(x), logit(y));
    let spread = (-lambda * (u - v).abs()).exp().ln_1p() / lambda;
    logistic(u.min(v) - spread)
}

/// Schweizer–Sklar t-norm for `x, y` in `(0, 1]`, via `ln T`.
///
/// With `a = p ln x`, `b = p ln y`, `u = x^p + y^p - 1 = e^a + e^b - 1`:
/// - `p > 0`: `ln T = ln(u) / p`, and `T = 0` once `u <= 0` (nilpotent
///   region). Near `u = 1` (small `p`) `u` is formed as
///   `1 + (expm1(a) + expm1(b))` so the product limit `p → 0` stays exact;
///   for small `u` as `e^b + expm1(a)` with `a >= b`, whose terms nearly
///   cancel only where `u` itself is tiny. (Forming `1 + ...` there would
///   cost up to 1% of `u`, i.e. 1e-4 in `T`, for `p ≈ 20`.)
/// - `p < 0`: `a, b >= 0` can overflow, so with `M = max`, `m = min`:
///   `ln(e^a + e^b - 1) = M + ln(1 + e^{m-M}(1 - e^{-m}))`.
/// - `p = 0`: the product.
pub(crate) fn schweizer_sklar(x: f64, y: f64, p: f64) -> f64 {
    if p == 0.0 {
        return x * y;
    }
    let (a, b) = (p * x.ln(), p * y.ln());
    let ln_t = if p > 0.0 {
        // Both exponents are <= 0; `near` belongs to the argument nearer 1.
        let (far, near) = ordered(a, b);
        let sum = near.exp_m1() + far.exp_m1();
        let ln_u = if sum > -0.5 {
            sum.ln_1p()
        } else {
            let u = far.exp() + near.exp_m1();
            if u <= 0.0 {
                return 0.0;
            }
            u.ln()
        };
        ln_u / p
    } else {
        let (m, big) = ordered(a, b);
        (big + ((m - big).exp() * -(-m).exp_m1()).ln_1p()) / p
    };
    ln_t.exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::close;

    fn t(family: Family, x: f32, y: f32) -> f32 {
        TNorm::new(family)
            .map(|t| t.apply(x, y))
            .unwrap_or(f32::NAN)
    }

    #[test]
    fn exact_values() {
        assert_eq!(t(Family::Minimum, 0.3, 0.7), 0.3);
        assert_eq!(t(Family::Product, 0.5, 0.5), 0.25);
        assert!(close(t(Family::Lukasiewicz, 0.75, 0.5), 0.25));
        assert_eq!(t(Family::Lukasiewicz, 0.25, 0.5), 0.0);
        assert_eq!(t(Family::Drastic, 0.9, 0.9), 0.0);
        assert_eq!(t(Family::Drastic, 1.0, 0.4), 0.4);
        assert_eq!(t(Family::NilpotentMinimum, 0.6, 0.7), 0.6);
        assert_eq!(t(Family::NilpotentMinimum, 0.5, 0.5), 0.0);
        // Einstein product: 0.25 / (1 + 0.25) = 0.2.
        assert!(close(t(Family::Einstein, 0.5, 0.5), 0.2));
        // Hamacher product: 0.25 / (0.5 + 0.5 - 0.25) = 1/3.
        assert!(close(
            t(Family::Hamacher { gamma: 0.0 }, 0.5, 0.5),
            1.0 / 3.0
        ));
        // Yager p = 2: 1 - sqrt(0.5^2 + 0.5^2).
        assert!(close(
            t(Family::Yager { p: 2.0 }, 0.5, 0.5),
            1.0 - 0.5f32.sqrt()
        ));
        // Dombi λ = 1 and Schweizer–Sklar p = -1 are the Hamacher product.
        assert!(close(t(Family::Dombi { lambda: 1.0 }, 0.5, 0.5), 1.0 / 3.0));
        assert!(close(
            t(Family::SchweizerSklar { p: -1.0 }, 0.5, 0.5),
            1.0 / 3.0
        ));
        // Schweizer–Sklar p = 2: sqrt(0.64 + 0.81 - 1).
        assert!(close(
            t(Family::SchweizerSklar { p: 2.0 }, 0.8, 0.9),
            0.45f32.sqrt()
        ));
        // Aczél–Alsina p = 1 is the product.
        assert!(close(t(Family::AczelAlsina { p: 1.0 }, 0.4, 0.6), 0.24));
        // Frank s = e^2 at (0.5, 0.5): ln(1 + (e - 1)^2 / (e^2 - 1)) / 2.
        let e = std::f64::consts::E;
        let frank = ((1.0 + (e - 1.0).powi(2) / (e * e - 1.0)).ln() / 2.0) as f32;
        assert!(close(t(Family::Frank { s: e * e }, 0.5, 0.5), frank));
    }

    #[test]
    fn special_parameters_match_named_families() {
        let grid = [0.0, 0.1, 0.35, 0.5, 0.8, 0.99, 1.0];
        let pairs = [
            (Family::Hamacher { gamma: 1.0 }, Family::Product),
            (Family::Hamacher { gamma: 2.0 }, Family::Einstein),
            (Family::Yager { p: 1.0 }, Family::Lukasiewicz),
            (Family::SchweizerSklar { p: 1.0 }, Family::Lukasiewicz),
            (Family::SchweizerSklar { p: 0.0 }, Family::Product),
            (Family::SchweizerSklar { p: 1e-12 }, Family::Product),
            (Family::Frank { s: 1.0 + 1e-9 }, Family::Product),
            (Family::AczelAlsina { p: 1.0 }, Family::Product),
            (Family::Yager { p: 1e4 }, Family::Minimum),
            (Family::AczelAlsina { p: 1e4 }, Family::Minimum),
        ];
        for (family, named) in pairs {
            for x in grid {
                for y in grid {
                    let (a, b) = (t(family, x, y), t(named, x, y));
                    assert!(
                        (a - b).abs() < 1e-4,
                        "{family} vs {named} at ({x}, {y}): {a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn invalid_inputs_are_clamped() {
        let product = TNorm::new(Family::Product).unwrap_or_default();
        assert_eq!(product.apply(f32::NAN, 0.5), 0.0);
        assert_eq!(product.apply(2.0, 0.5), 0.5);
        assert_eq!(product.apply(-1.0, 0.5), 0.0);
        assert_eq!(product.apply(f32::INFINITY, f32::INFINITY), 1.0);
    }

    #[test]
    fn default_is_minimum_and_dual_keeps_family() {
        assert_eq!(TNorm::default().family(), Family::Minimum);
        let dombi = Family::Dombi { lambda: 3.0 };
        assert_eq!(TNorm::new(dombi).map(|t| t.dual().family()), Ok(dombi));
        assert_eq!(
            TNorm::new(dombi).map(|t| t.dual().dual().family()),
            Ok(dombi)
        );
    }

    #[test]
    fn new_rejects_invalid_parameters() {
        assert!(matches!(
            TNorm::new(Family::Dombi { lambda: f64::NAN }),
            Err(OperatorError::InvalidParameter { name: "lambda", .. })
        ));
    }
}
