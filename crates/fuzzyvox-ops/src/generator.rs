//! Additive generators of the Archimedean t-conorms and confidence weighting.
//!
//! Every continuous Archimedean t-conorm can be written
//! `S(x, y) = g⁽⁻¹⁾(g(x) + g(y))` with a continuous, strictly increasing
//! `g: [0, 1] → [0, ∞]`, `g(0) = 0`, and the pseudo-inverse
//! `g⁽⁻¹⁾(t) = g⁻¹(min(t, g(1)))` (Klement, Mesiar & Pap 2000, Theorem 3.45 and
//! Corollary 5.5). The generator is `g(x) = f(1 - x)`, where `f` is the additive
//! generator of the dual t-norm. Strict families have `g(1) = ∞`; nilpotent
//! ones a finite `g(1)`, at which the pseudo-inverse saturates to 1.
//!
//! The generator measures evidence additively, which gives confidence
//! weighting a precise meaning: for `w = 1/n`, `g⁽⁻¹⁾(w · g(μ))` is the
//! membership that, combined with itself `n` times, reproduces `μ`. The
//! weighted form is computed per family in closed form where the generic
//! composition would overflow or lose precision.

use super::Family;
use super::frank;
use super::numeric::{logistic, logit, to_unit, unit};

/// `g(x)` for `x` in `[0, 1]`; `None` for the non-Archimedean families.
pub(crate) fn generator(family: Family, x: f64) -> Option<f64> {
    let value = match family {
        Family::Minimum | Family::Drastic | Family::NilpotentMinimum => return None,
        Family::Product => -(-x).ln_1p(),
        Family::Lukasiewicz => x,
        // f(x) = (1 - x) / x for γ = 0 (Klement et al., Example 3.43).
        Family::Hamacher { gamma: 0.0 } => x / (1.0 - x),
        // f(x) = ln((γ + (1 - γ)x) / x), so g(x) = ln(1 + γx / (1 - x)).
        Family::Hamacher { gamma } => hamacher_generator(x, gamma),
        Family::Einstein => hamacher_generator(x, 2.0),
        Family::Yager { p } => x.powf(p),
        Family::Frank { s } => frank::generator(x, s.ln()),
        // g(x) = (x / (1 - x))^λ.
        Family::Dombi { lambda } => (lambda * logit(x)).exp(),
        Family::SchweizerSklar { p: 0.0 } => -(-x).ln_1p(),
        // f(x) = (1 - x^p) / p, so g(x) = (1 - (1 - x)^p) / p.
        Family::SchweizerSklar { p } => -(p * (-x).ln_1p()).exp_m1() / p,
        // f(x) = (-ln x)^p.
        Family::AczelAlsina { p } => (-(-x).ln_1p()).powf(p),
    };
    // Folds -0.0 (from ln_1p(-0.0) and friends) into 0.
    Some(value.max(0.0))
}

/// The pseudo-inverse `g⁽⁻¹⁾(t)` for `t` in `[0, ∞]`; `None` for the
/// non-Archimedean families. The result lies in `[0, 1]` up to rounding.
pub(crate) fn generator_inverse(family: Family, t: f64) -> Option<f64> {
    let value = match family {
        Family::Minimum | Family::Drastic | Family::NilpotentMinimum => return None,
        Family::Product => -(-t).exp_m1(),
        Family::Lukasiewicz => t.min(1.0),
        Family::Hamacher { gamma: 0.0 } => 1.0 / (1.0 + 1.0 / t),
        // x / (1 - x) = (e^t - 1) / γ, written as e^{ln γ - t} / (1 - e^{-t}) so
        // that neither a huge γ nor a huge t overflows.
        Family::Hamacher { gamma } => 1.0 / (1.0 + (gamma.ln() - t).exp() / -(-t).exp_m1()),
        // g(x) = ln((1 + x) / (1 - x)) = 2 artanh(x).
        Family::Einstein => (t / 2.0).tanh(),
        Family::Yager { p } => t.powf(1.0 / p).min(1.0),
        Family::Frank { s } => frank::generator_inverse(t, s.ln()),
        Family::Dombi { lambda } => logistic(t.ln() / lambda),
        Family::SchweizerSklar { p: 0.0 } => -(-t).exp_m1(),
        // Past g(1) = 1/p the nilpotent members saturate.
        Family::SchweizerSklar { p } if p * t >= 1.0 => 1.0,
        Family::SchweizerSklar { p } => -((-p * t).ln_1p() / p).exp_m1(),
        Family::AczelAlsina { p } => -(-t.powf(1.0 / p)).exp_m1(),
    };
    Some(value)
}

/// Confidence-weighted membership `g⁽⁻¹⁾(w · g(μ))`, or `w · μ` for the
/// non-Archimedean families. `μ` and `w` are clamped into `[0, 1]`.
#[inline]
pub(crate) fn weighted(family: Family, mu: f32, w: f32) -> f32 {
    let (mu, w) = (unit(mu), unit(w));
    // w = 0 must give 0 even where g(μ) = ∞, and w = 1 must return μ exactly.
    if w == 0.0 || mu == 0.0 {
        return 0.0;
    }
    if w == 1.0 {
        return mu;
    }
    let (m, w64) = (f64::from(mu), f64::from(w));
    let value = match family {
        Family::Minimum | Family::Drastic | Family::NilpotentMinimum | Family::Lukasiewicz => {
            return w * mu;
        }
        // 1 - (1 - μ)^w.
        Family::Product => -(w64 * (-m).ln_1p()).exp_m1(),
        Family::SchweizerSklar { p: 0.0 } => -(w64 * (-m).ln_1p()).exp_m1(),
        // (w μ^p)^(1/p) = w^(1/p) μ; μ^p itself would underflow for large p.
        Family::Yager { p } => m * w64.powf(1.0 / p),
        // (w g)^(1/λ) in the logit domain: logit h = logit μ + ln(w) / λ.
        Family::Dombi { lambda } => logistic(logit(m) + w64.ln() / lambda),
        Family::SchweizerSklar { p } => schweizer_sklar(m, w64, p),
        // -ln(1 - h) = w^(1/p) · (-ln(1 - μ)).
        Family::AczelAlsina { p } => {
            let scale = w64.powf(1.0 / p);
            // Strict: g(1) = ∞ stays ∞ for any w > 0, even where w^(1/p)
            // underflows; below 1 an underflowed scale means no evidence.
            if mu == 1.0 {
                return 1.0;
            }
            if scale == 0.0 {
                return 0.0;
            }
            -(scale * (-m).ln_1p()).exp_m1()
        }
        Family::Hamacher { gamma } => hamacher(m, w64, gamma),
        Family::Einstein => hamacher(m, w64, 2.0),
        Family::Frank { .. } => generator(family, m)
            .and_then(|g| generator_inverse(family, w64 * g))
            .unwrap_or(w64 * m),
    };
    to_unit(value)
}

/// Hamacher generator `ln(1 + γa)` with odds `a = x / (1 - x)`, falling back
/// to `ln γ + ln a` where `γa` overflows (γ beyond ~1e300).
fn hamacher_generator(x: f64, gamma: f64) -> f64 {
    let odds = x / (1.0 - x);
    let c = gamma * odds;
    if c.is_finite() || odds.is_infinite() {
        c.ln_1p()
    } else {
        gamma.ln() + odds.ln()
    }
}

/// Hamacher weighting in terms of odds (γ = 2 is the Einstein sum).
///
/// With `a = μ / (1 - μ)` and `c = γa`, the weighted odds solve
/// `ln(1 + γ a_w) = w ln(1 + c)`, i.e. `a_w = expm1(w ln_1p(c)) / γ`. That
/// quotient is evaluated in the form that stays accurate at both ends of the
/// parameter range: a Taylor expansion when `c` is tiny (γ → 0, where the
/// generator degenerates to the γ = 0 one, `a`) and logarithms when `c`
/// overflows (huge γ).
fn hamacher(mu: f64, w: f64, gamma: f64) -> f64 {
    if mu >= 1.0 {
        return 1.0;
    }
    let a = mu / (1.0 - mu);
    let c = gamma * a;
    let a_w = if c <= 1e-8 {
        // expm1(w ln_1p(c)) / γ = w a (1 + (w - 1) c / 2) + O(c²); exact for γ = 0.
        w * a * (1.0 + (w - 1.0) * c / 2.0)
    } else if c.is_finite() {
        (w * c.ln_1p()).exp_m1() / gamma
    } else {
        (w * a.ln() + (w - 1.0) * gamma.ln()).exp()
    };
    1.0 / (1.0 + 1.0 / a_w)
}

/// Schweizer–Sklar weighting for `p ≠ 0`.
///
/// With `t = p ln(1 - μ)` the generator is `g = -expm1(t) / p`, so the weighted
/// exponent solves `expm1(t_w) = w · expm1(t)`, i.e.
/// `t_w = ln(1 + w · expm1(t))`, accurate for every `w` as long as `expm1(t)`
/// is finite. For `p < 0`, `t >= 0` can exceed the overflow threshold; there
/// `t_w = t + ln(w + (1 - w) e^{-t})`, where `t >= 700` dwarfs `ln w >= -104`
/// so nothing cancels.
fn schweizer_sklar(mu: f64, w: f64, p: f64) -> f64 {
    let t = p * (-mu).ln_1p();
    if t == f64::INFINITY {
        // μ = 1 of a strict member: g(μ) = ∞, so any w > 0 keeps it at 1.
        return 1.0;
    }
    let t_w = if t < 700.0 {
        (w * t.exp_m1()).ln_1p()
    } else {
        t + (w + (1.0 - w) * (-t).exp()).ln()
    };
    -(t_w / p).exp_m1()
}
