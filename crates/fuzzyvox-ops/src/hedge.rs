//! Linguistic hedges.
//!
//! Zadeh's hedges reshape a membership function without moving its support:
//! *concentration* ("very", `μ²`) sharpens it and *dilation* ("somewhat",
//! `√μ`) widens it (Zadeh, "A fuzzy-set-theoretic interpretation of linguistic
//! hedges", J. Cybernetics 2(3), 1972). Both fix 0 and 1 and are increasing,
//! and they are inverse to each other on `[0, 1]`.

use serde::{Deserialize, Serialize};

use super::numeric::unit;

/// A linguistic hedge applied to a membership degree.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Hedge {
    /// "Very": `μ²`, lowers every partial membership.
    Concentration,
    /// "Somewhat": `√μ`, raises every partial membership.
    Dilation,
}

impl Hedge {
    /// Applies the hedge. The input is clamped into `[0, 1]` (NaN counts as 0);
    /// the result is in `[0, 1]`, never NaN, with 0 and 1 left unchanged.
    #[inline]
    pub fn apply(&self, x: f32) -> f32 {
        let x = unit(x);
        match self {
            Hedge::Concentration => x * x,
            Hedge::Dilation => x.sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn values() {
        assert_eq!(Hedge::Concentration.apply(0.5), 0.25);
        assert_eq!(Hedge::Dilation.apply(0.25), 0.5);
        assert_eq!(Hedge::Concentration.apply(1.5), 1.0);
        assert_eq!(Hedge::Dilation.apply(f32::NAN), 0.0);
        assert_eq!(Hedge::Dilation.apply(-0.5), 0.0);
        for hedge in [Hedge::Concentration, Hedge::Dilation] {
            assert_eq!(hedge.apply(0.0), 0.0);
            assert_eq!(hedge.apply(1.0), 1.0);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Range, order (very μ <= μ <= somewhat μ), monotonicity and mutual
        /// inversion (to 1e-6, f32 rounding).
        #[test]
        fn laws(x in 0.0f32..=1.0, y in 0.0f32..=1.0) {
            let (very, somewhat) = (Hedge::Concentration.apply(x), Hedge::Dilation.apply(x));
            prop_assert!((0.0..=1.0).contains(&very) && (0.0..=1.0).contains(&somewhat));
            prop_assert!(very <= x && x <= somewhat);
            let (lo, hi) = if x <= y { (x, y) } else { (y, x) };
            for hedge in [Hedge::Concentration, Hedge::Dilation] {
                prop_assert!(hedge.apply(lo) <= hedge.apply(hi));
            }
            prop_assert!((Hedge::Dilation.apply(very) - x).abs() < 1e-6);
            prop_assert!((Hedge::Concentration.apply(somewhat) - x).abs() < 1e-6);
        }
    }
}
