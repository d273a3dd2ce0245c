//! Extreme and absurd parameters.
//!
//! Every valid parameter, however far from sensible use, must give outputs in
//! `[0, 1]` and never NaN, and the laws that survive rounding (exact
//! boundaries, bitwise commutativity, monotonicity in each argument and of
//! the confidence weighting) must still hold.

use proptest::prelude::*;

use super::{
    MONOTONE_TOL, any_input, check_boundary, check_commutative, check_range, operators, unit_input,
};
use crate::Family;

/// Parameters at the edge of the useful range, then far beyond it.
fn extreme_family() -> impl Strategy<Value = Family> {
    prop::sample::select(vec![
        Family::Yager { p: 1e-3 },
        Family::Yager { p: 1e3 },
        Family::Dombi { lambda: 1e-3 },
        Family::Dombi { lambda: 100.0 },
        Family::AczelAlsina { p: 0.01 },
        Family::AczelAlsina { p: 50.0 },
        Family::SchweizerSklar { p: -50.0 },
        Family::SchweizerSklar { p: 50.0 },
        Family::SchweizerSklar { p: 1e-9 },
        Family::Frank { s: 1e-6 },
        Family::Frank { s: 1.0 - 1e-9 },
        Family::Frank { s: 1.0 + 1e-9 },
        Family::Frank { s: 1e6 },
        Family::Hamacher { gamma: 0.0 },
        Family::Hamacher { gamma: 1e3 },
        // Far beyond any sensible use.
        Family::Yager { p: 1e-300 },
        Family::Yager { p: 1e300 },
        Family::Dombi { lambda: 1e-300 },
        Family::Dombi { lambda: 1e300 },
        Family::AczelAlsina { p: 1e-300 },
        Family::AczelAlsina { p: 1e300 },
        Family::SchweizerSklar { p: -1e300 },
        Family::SchweizerSklar { p: 1e300 },
        Family::SchweizerSklar { p: 1e-300 },
        Family::Frank {
            s: f64::MIN_POSITIVE,
        },
        Family::Frank {
            s: 1.0 - f64::EPSILON / 2.0,
        },
        Family::Frank {
            s: 1.0 + f64::EPSILON,
        },
        Family::Frank { s: f64::MAX },
        Family::Hamacher { gamma: 5e-324 },
        Family::Hamacher { gamma: 1e-300 },
        Family::Hamacher { gamma: f64::MAX },
    ])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn outputs_in_unit_interval(
        f in extreme_family(), x in any_input(), y in any_input(), w in any_input(),
    ) {
        check_range(f, x, y, w)?;
    }

    #[test]
    fn boundary_and_commutativity(f in extreme_family(), x in unit_input(), y in unit_input()) {
        check_boundary(f, x)?;
        check_commutative(f, x, y)?;
    }

    #[test]
    fn monotone(f in extreme_family(), a in unit_input(), b in unit_input(), y in unit_input()) {
        let (t, s) = operators(f)?;
        let (x1, x2) = if a <= b { (a, b) } else { (b, a) };
        let pairs = [
            ("T(., y)", t.apply(x1, y), t.apply(x2, y)),
            ("S(., y)", s.apply(x1, y), s.apply(x2, y)),
            // y as the membership, x1 <= x2 as the confidences...
            ("weighted(y, .)", s.weighted(y, x1), s.weighted(y, x2)),
            // ...and the other way round.
            ("weighted(., y)", s.weighted(x1, y), s.weighted(x2, y)),
        ];
        for (name, low, high) in pairs {
            prop_assert!(
                low <= high + MONOTONE_TOL,
                "{f}: {name} not monotone at {x1} <= {x2}, y = {y}"
            );
        }
        prop_assert_eq!(s.weighted(x1, 1.0), x1);
        prop_assert_eq!(s.weighted(x1, 0.0), 0.0);
    }
}
