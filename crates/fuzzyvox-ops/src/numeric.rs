//! Small numerical helpers shared by the operator kernels.
//!
//! Every operator takes `f32` memberships, works in `f64` and hands back an
//! `f32` in `[0, 1]`. These helpers keep that contract in one place: inputs are
//! sanitised on the way in (NaN counts as 0), results are clamped on the way
//! out, and the log-domain building blocks avoid overflow and cancellation for
//! extreme family parameters.

/// Clamps a membership degree into `[0, 1]`; NaN is treated as 0 (no evidence).
#[inline]
pub fn unit(x: f32) -> f32 {
    if x >= 0.0 { x.min(1.0) } else { 0.0 }
}

/// Clamps an `f64` result into `[0, 1]` and narrows it to `f32`; NaN maps to 0
/// so that no NaN can ever leave an operator.
#[inline]
pub(crate) fn to_unit(x: f64) -> f32 {
    if x >= 0.0 { x.min(1.0) as f32 } else { 0.0 }
}

/// Returns the pair ordered as `(min, max)`.
///
/// Kernels whose floating-point evaluation is not symmetric in its arguments
/// sort them first, so that commutativity holds bit for bit.
#[inline]
pub(crate) fn ordered<T: PartialOrd>(x: T, y: T) -> (T, T) {
    if x <= y { (x, y) } else { (y, x) }
}

/// `ln(x / (1 - x))` for `x` in `(0, 1)`, accurate near both ends.
#[inline]
pub(crate) fn logit(x: f64) -> f64 {
    x.ln() - (-x).ln_1p()
}

/// `1 / (1 + e^-t)`, the inverse of [`logit`]; saturates cleanly at `±inf`.
#[inline]
pub(crate) fn logistic(t: f64) -> f64 {
    1.0 / (1.0 + (-t).exp())
}

/// `ln(e^a + e^b)` without overflow; `-inf` when both terms are `-inf`.
#[inline]
pub(crate) fn log_add_exp(a: f64, b: f64) -> f64 {
    let (lo, hi) = ordered(a, b);
    if hi == f64::NEG_INFINITY {
        return f64::NEG_INFINITY;
    }
    hi + (lo - hi).exp().ln_1p()
}

/// The `p`-norm `(a^p + b^p)^(1/p)` of two non-negative numbers, for `p > 0`.
///
/// Factoring out the larger argument, `max · (1 + r^p)^(1/p)` with
/// `r = min/max <= 1`, keeps `r^p` in `[0, 1]`: no overflow for large `p` and
/// no spurious underflow to zero for small arguments. The result is `+inf`
/// only when the true value overflows (or an argument is infinite).
pub(crate) fn p_norm(a: f64, b: f64, p: f64) -> f64 {
    let (lo, hi) = ordered(a, b);
    if hi <= 0.0 {
        return 0.0;
    }
    if hi == f64::INFINITY {
        return f64::INFINITY;
    }
    let r = lo / hi;
    hi * ((r.powf(p)).ln_1p() / p).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_clamps_and_removes_nan() {
        assert_eq!(unit(f32::NAN), 0.0);
        assert_eq!(unit(-1.0), 0.0);
        assert_eq!(unit(2.0), 1.0);
        assert_eq!(unit(0.25), 0.25);
        assert_eq!(to_unit(f64::NAN), 0.0);
        assert_eq!(to_unit(f64::INFINITY), 1.0);
        assert_eq!(to_unit(-0.5), 0.0);
    }

    #[test]
    fn logit_and_logistic_are_inverse() {
        for x in [1e-12, 0.1, 0.5, 0.9, 1.0 - 1e-12] {
            assert!((logistic(logit(x)) - x).abs() < 1e-15);
        }
        assert_eq!(logistic(f64::INFINITY), 1.0);
        assert_eq!(logistic(f64::NEG_INFINITY), 0.0);
    }

    #[test]
    fn log_add_exp_handles_extremes() {
        assert!((log_add_exp(0.0, 0.0) - std::f64::consts::LN_2).abs() < 1e-15);
        assert_eq!(log_add_exp(1000.0, 0.0), 1000.0);
        assert_eq!(
            log_add_exp(f64::NEG_INFINITY, f64::NEG_INFINITY),
            f64::NEG_INFINITY
        );
        assert_eq!(log_add_exp(f64::NEG_INFINITY, -3.0), -3.0);
    }

    #[test]
    fn p_norm_is_stable_for_extreme_exponents() {
        assert!((p_norm(3.0, 4.0, 2.0) - 5.0).abs() < 1e-12);
        // 0.4^1000 underflows, but the norm must still be max(a, b).
        assert!((p_norm(0.4, 0.3, 1000.0) - 0.4).abs() < 1e-12);
        // 2^(1/p) overflows: the norm saturates to +inf instead of NaN.
        assert_eq!(p_norm(0.5, 0.5, 1e-4), f64::INFINITY);
        assert_eq!(p_norm(0.0, 0.0, 2.0), 0.0);
    }
}
