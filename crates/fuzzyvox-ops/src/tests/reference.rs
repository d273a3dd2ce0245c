//! Pins every family to its textbook definition.
//!
//! The algebraic laws would pass just as well for the wrong family, so here
//! each operator is compared with the defining formula from Klement, Mesiar &
//! Pap (2000), evaluated naively in `f64`. The naive forms are only accurate
//! for moderate parameters and inputs away from 0 and 1, which is the range
//! sampled; the tolerance [`REFERENCE_TOL`] = 1e-5 absorbs the final `f32`
//! rounding with a wide margin.

use proptest::prelude::*;

use super::{log_uniform, operators};
use crate::Family;

const REFERENCE_TOL: f64 = 1e-5;

/// The t-norm exactly as written in the literature.
fn textbook_t(family: Family, x: f64, y: f64) -> f64 {
    match family {
        Family::Minimum => x.min(y),
        Family::Product => x * y,
        Family::Lukasiewicz => (x + y - 1.0).max(0.0),
        Family::Drastic => {
            if x.max(y) == 1.0 {
                x.min(y)
            } else {
                0.0
            }
        }
        Family::NilpotentMinimum => {
            if x + y > 1.0 {
                x.min(y)
            } else {
                0.0
            }
        }
        Family::Hamacher { gamma } => x * y / (gamma + (1.0 - gamma) * (x + y - x * y)),
        Family::Einstein => x * y / (2.0 - (x + y - x * y)),
        Family::Yager { p } => {
            (1.0 - ((1.0 - x).powf(p) + (1.0 - y).powf(p)).powf(1.0 / p)).max(0.0)
        }
        Family::Frank { s } => (1.0 + (s.powf(x) - 1.0) * (s.powf(y) - 1.0) / (s - 1.0)).log(s),
        Family::Dombi { lambda } => {
            let sum = ((1.0 - x) / x).powf(lambda) + ((1.0 - y) / y).powf(lambda);
            1.0 / (1.0 + sum.powf(1.0 / lambda))
        }
        Family::SchweizerSklar { p: 0.0 } => x * y,
        Family::SchweizerSklar { p } => (x.powf(p) + y.powf(p) - 1.0).max(0.0).powf(1.0 / p),
        Family::AczelAlsina { p } => (-((-x.ln()).powf(p) + (-y.ln()).powf(p)).powf(1.0 / p)).exp(),
    }
}

/// The t-conorm: its own closed form where the literature gives one, the
/// De Morgan dual of [`textbook_t`] otherwise.
fn textbook_s(family: Family, x: f64, y: f64) -> f64 {
    match family {
        Family::Minimum => x.max(y),
        Family::Product => x + y - x * y,
        Family::Lukasiewicz => (x + y).min(1.0),
        Family::Hamacher { gamma } => {
            (x + y + (gamma - 2.0) * x * y) / (1.0 + (gamma - 1.0) * x * y)
        }
        Family::Einstein => (x + y) / (1.0 + x * y),
        Family::Yager { p } => (x.powf(p) + y.powf(p)).powf(1.0 / p).min(1.0),
        _ => 1.0 - textbook_t(family, 1.0 - x, 1.0 - y),
    }
}

fn moderate_family() -> impl Strategy<Value = Family> {
    prop_oneof![
        prop::sample::select(vec![
            Family::Minimum,
            Family::Product,
            Family::Lukasiewicz,
            Family::Drastic,
            Family::NilpotentMinimum,
            Family::Einstein,
        ]),
        (0.0..10.0).prop_map(|gamma| Family::Hamacher { gamma }),
        log_uniform(0.3, 5.0).prop_map(|p| Family::Yager { p }),
        // The textbook Frank formula loses digits as s -> 1.
        prop_oneof![log_uniform(0.01, 0.95), log_uniform(1.05, 100.0)]
            .prop_map(|s| Family::Frank { s }),
        log_uniform(0.3, 5.0).prop_map(|lambda| Family::Dombi { lambda }),
        (-5.0..5.0).prop_map(|p| Family::SchweizerSklar { p }),
        log_uniform(0.3, 5.0).prop_map(|p| Family::AczelAlsina { p }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    #[test]
    fn operators_match_textbook_formulas(
        family in moderate_family(),
        x in 0.01f32..=0.99,
        y in 0.01f32..=0.99,
    ) {
        let (t, s) = operators(family)?;
        let (x64, y64) = (f64::from(x), f64::from(y));
        let (expected_t, expected_s) = (textbook_t(family, x64, y64), textbook_s(family, x64, y64));
        let (got_t, got_s) = (f64::from(t.apply(x, y)), f64::from(s.apply(x, y)));
        prop_assert!(
            (got_t - expected_t).abs() <= REFERENCE_TOL,
            "{family}: T({x}, {y}) = {got_t}, textbook {expected_t}"
        );
        prop_assert!(
            (got_s - expected_s).abs() <= REFERENCE_TOL,
            "{family}: S({x}, {y}) = {got_s}, textbook {expected_s}"
        );
    }
}
