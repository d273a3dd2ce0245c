//! Numerically careful kernels for the Frank family.
//!
//! With `L = ln s`, the Frank t-norm is
//! `T(x, y) = ln(1 + (e^{xL} - 1)(e^{yL} - 1) / (e^L - 1)) / L`
//! (Klement, Mesiar & Pap 2000, Example 4.13). Written with `expm1`/`ln_1p`
//! it stays exact as `s → 1` (where it tends to the product), and ordering the
//! factors keeps every intermediate below `e^L`, so it cannot overflow for any
//! finite `s > 1`. For `s < 1` the direct formula would cancel catastrophically
//! (`1 + ratio` underflows towards `s`), so the reflection
//! `T_s(x, y) = x - T_{1/s}(x, 1 - y)` maps it onto `s > 1`. The dual
//! t-conorm follows from Frank's functional equation `T + S = x + y`.

use super::numeric::{log_add_exp, ordered};

/// Frank t-norm for `x, y` in `(0, 1)` and `l = ln s ≠ 0`.
pub(crate) fn tnorm(x: f64, y: f64, l: f64) -> f64 {
    // Sorting makes the reflected branch, which is not symmetric in floating
    // point, exactly commutative.
    let (x, y) = ordered(x, y);
    if l > 0.0 {
        direct(x, y, l)
    } else {
        x - direct(x, 1.0 - y, -l)
    }
}

/// Frank t-conorm for `x, y` in `(0, 1)`: `S = x + y - T`.
pub(crate) fn tconorm(x: f64, y: f64, l: f64) -> f64 {
    x + y - tnorm(x, y, l)
}

/// The defining formula for `l > 0`; every factor lies in `[0, e^l)`.
fn direct(x: f64, y: f64, l: f64) -> f64 {
    let ratio = (x * l).exp_m1() * ((y * l).exp_m1() / l.exp_m1());
    ratio.ln_1p() / l
}

/// Additive generator of the Frank t-conorm,
/// `g(x) = -ln((s^{1-x} - 1) / (s - 1))`, for `x` in `[0, 1]` and `l = ln s`.
///
/// With `q = (e^{-xL} - 1) / (e^{-L} - 1)` this is `g = -ln(1 - q)`. For
/// `s > 1`, `q` rounds to 1 long before `x` does, so `1 - q` is expanded
/// analytically as `e^{-xL} (e^{-(1-x)L} - 1) / (e^{-L} - 1)`, whose two
/// logarithmic terms are both non-negative.
pub(crate) fn generator(x: f64, l: f64) -> f64 {
    if l > 0.0 {
        x * l - ((-(1.0 - x) * l).exp_m1() / (-l).exp_m1()).ln()
    } else {
        let q = (-x * l).exp_m1() / (-l).exp_m1();
        -(-q).ln_1p()
    }
}

/// Inverse of [`generator`] for `y` in `[0, ∞]`; the result lies in `[0, 1]`
/// up to rounding.
///
/// Solving `g(x) = y` gives `x = -ln(e^{-y} + e^{-L}(1 - e^{-y})) / L`. For
/// `L <= 1` the `ln_1p` form is accurate; for larger `L` the two positive terms
/// are combined in the log domain so that values of `x` near 1 keep their
/// precision.
pub(crate) fn generator_inverse(y: f64, l: f64) -> f64 {
    let a = -(-y).exp_m1(); // 1 - e^{-y}, in [0, 1]
    if l <= 1.0 {
        -(a * (-l).exp_m1()).ln_1p() / l
    } else {
        -log_add_exp(-y, a.ln() - l) / l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Straightforward evaluation of the textbook formula, valid for moderate s.
    fn naive(x: f64, y: f64, s: f64) -> f64 {
        (1.0 + (s.powf(x) - 1.0) * (s.powf(y) - 1.0) / (s - 1.0)).ln() / s.ln()
    }

    #[test]
    fn matches_textbook_formula_for_moderate_bases() {
        for s in [0.01, 0.3, 0.9, 1.5, 2.0, 50.0, 1e4] {
            for &(x, y) in &[(0.2, 0.7), (0.5, 0.5), (0.9, 0.95), (0.05, 0.3)] {
                let (fast, slow) = (tnorm(x, y, f64::ln(s)), naive(x, y, s));
                assert!(
                    (fast - slow).abs() < 1e-12,
                    "s={s} x={x} y={y}: {fast} vs {slow}"
                );
            }
        }
    }

    #[test]
    fn limits_are_reached_smoothly() {
        // s -> 1: product.
        for l in [1e-9, -1e-9, 1e-15] {
            assert!((tnorm(0.3, 0.6, l) - 0.18).abs() < 1e-9);
        }
        // s -> 0: minimum; s -> inf: Lukasiewicz.
        assert!((tnorm(0.3, 0.6, f64::MIN_POSITIVE.ln()) - 0.3).abs() < 1e-2);
        assert!((tnorm(0.3, 0.9, f64::MAX.ln()) - 0.2).abs() < 1e-2);
        // Near-diagonal points near 1 for a tiny base keep their precision.
        let t = tnorm(0.9999, 0.9999, 1e-300f64.ln());
        assert!(t > 0.9997 && t < 0.9999, "{t}");
    }

    #[test]
    fn generator_round_trips() {
        for l in [-700.0, -13.8, -1.0, -1e-9, 1e-9, 0.5, 1.0, 2.0, 13.8, 700.0] {
            for x in [0.0, 1e-6, 0.1, 0.5, 0.9, 0.999_999] {
                let back = generator_inverse(generator(x, l), l);
                assert!((back - x).abs() < 1e-9, "l={l} x={x} back={back}");
            }
            assert_eq!(generator(0.0, l), 0.0);
            assert_eq!(generator(1.0, l), f64::INFINITY);
            assert_eq!(generator_inverse(0.0, l), 0.0);
            assert!((generator_inverse(f64::INFINITY, l) - 1.0).abs() < 1e-15);
        }
    }
}
