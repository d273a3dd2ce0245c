//! The parametric families of t-norms and their dual t-conorms.
//!
//! A [`Family`] names a matched pair `(T, S)` with `S(x, y) = 1 - T(1 - x, 1 - y)`;
//! [`TNorm`](super::TNorm) and [`TConorm`](super::TConorm) evaluate it. The
//! definitions follow Klement, Mesiar & Pap, *Triangular Norms* (Kluwer, 2000),
//! chapters 1 and 4 (the Hamacher, Yager, Frank, Dombi, Schweizer–Sklar and
//! Aczél–Alsina families, with their limits and additive generators).
//!
//! Families have a compact text form used on the command line and in
//! configuration files: `NAME` or `NAME:PARAM`, for example `product`,
//! `hamacher:0` or `frank:0.5`. [`Family`]'s `Display` prints the canonical form
//! and `FromStr` reads it back, together with a few aliases.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::OperatorError;

/// A family of fuzzy conjunctions (t-norms) and disjunctions (t-conorms).
///
/// Each variant fixes a t-norm `T`; its dual t-conorm is
/// `S(x, y) = 1 - T(1 - x, 1 - y)`. Parameters are validated by
/// [`Family::validate`] (and by [`TNorm::new`](super::TNorm::new) /
/// [`TConorm::new`](super::TConorm::new)); an unvalidated family may carry a
/// meaningless parameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Family {
    /// Gödel: `T = min(x, y)`, `S = max(x, y)`. Idempotent, not Archimedean.
    Minimum,
    /// `T = x·y`, `S = x + y - x·y` (probabilistic sum). Strict Archimedean.
    Product,
    /// Łukasiewicz: `T = max(x + y - 1, 0)`, `S = min(x + y, 1)` (bounded sum).
    /// Nilpotent Archimedean.
    Lukasiewicz,
    /// Drastic product: `T = min(x, y)` if `max(x, y) = 1`, else 0; `S = max(x, y)`
    /// if `min(x, y) = 0`, else 1. The smallest t-norm; not continuous.
    Drastic,
    /// Fodor's nilpotent minimum: `T = min(x, y)` if `x + y > 1`, else 0;
    /// `S = max(x, y)` if `x + y < 1`, else 1. Left-continuous, not Archimedean.
    NilpotentMinimum,
    /// Hamacher: `T = x·y / (γ + (1 - γ)(x + y - x·y))`, `γ >= 0`, with
    /// `T(0, 0) = 0`. `γ = 0` is the Hamacher product, `γ = 1` the product and
    /// `γ = 2` the Einstein product. Strict Archimedean.
    Hamacher {
        /// The parameter `γ >= 0`.
        gamma: f64,
    },
    /// Einstein product `T = x·y / (1 + (1 - x)(1 - y))` and Einstein sum
    /// `S = (x + y) / (1 + x·y)`; the Hamacher family at `γ = 2`.
    Einstein,
    /// Yager: `S = min((x^p + y^p)^(1/p), 1)`, `p > 0`. Nilpotent Archimedean;
    /// `p = 1` is Łukasiewicz, `p → ∞` tends to the minimum.
    Yager {
        /// The exponent `p > 0`.
        p: f64,
    },
    /// Frank: `T = log_s(1 + (s^x - 1)(s^y - 1) / (s - 1))`, `s > 0`, `s ≠ 1`.
    /// Strict Archimedean; `s → 1` tends to the product, `s → 0` to the
    /// minimum and `s → ∞` to Łukasiewicz. The only family that also
    /// satisfies `T(x, y) + S(x, y) = x + y`.
    Frank {
        /// The base `s > 0`, `s ≠ 1` (subnormal values are rejected).
        s: f64,
    },
    /// Dombi: `T = 1 / (1 + (((1 - x)/x)^λ + ((1 - y)/y)^λ)^(1/λ))`, `λ > 0`.
    /// Strict Archimedean; `λ = 1` is the Hamacher product.
    Dombi {
        /// The exponent `λ > 0`.
        lambda: f64,
    },
    /// Schweizer–Sklar: `T = max(x^p + y^p - 1, 0)^(1/p)` for `p ≠ 0`, the
    /// product for `p = 0`. Nilpotent for `p > 0`, strict for `p <= 0`;
    /// `p = 1` is Łukasiewicz and `p = -1` the Hamacher product.
    SchweizerSklar {
        /// Any finite exponent `p`.
        p: f64,
    },
    /// Aczél–Alsina: `T = exp(-((-ln x)^p + (-ln y)^p)^(1/p))`, `p > 0`.
    /// Strict Archimedean; `p = 1` is the product, `p → ∞` tends to the
    /// minimum.
    AczelAlsina {
        /// The exponent `p > 0`.
        p: f64,
    },
}

impl Family {
    /// Checks that the parameter (if any) is finite and inside the family's
    /// domain, returning the family unchanged when it is.
    ///
    /// # Errors
    /// [`OperatorError::InvalidParameter`] naming the parameter and its domain.
    pub fn validate(self) -> Result<Family, OperatorError> {
        let (valid, expected) = match self {
            Family::Minimum
            | Family::Product
            | Family::Lukasiewicz
            | Family::Drastic
            | Family::NilpotentMinimum
            | Family::Einstein => return Ok(self),
            Family::Hamacher { gamma } => {
                (gamma.is_finite() && gamma >= 0.0, "must be finite and >= 0")
            }
            Family::Yager { p } | Family::AczelAlsina { p } => {
                (p.is_finite() && p > 0.0, "must be finite and > 0")
            }
            // Subnormal bases are excluded: ln(s) of a subnormal makes
            // expm1(-ln s) overflow, and such a base is indistinguishable
            // from the minimum anyway.
            Family::Frank { s } => (
                s.is_finite() && s >= f64::MIN_POSITIVE && s != 1.0,
                "must be finite, > 0 (not subnormal) and != 1",
            ),
            Family::Dombi { lambda } => {
                (lambda.is_finite() && lambda > 0.0, "must be finite and > 0")
            }
            Family::SchweizerSklar { p } => (p.is_finite(), "must be finite"),
        };
        if valid {
            Ok(self)
        } else {
            Err(OperatorError::InvalidParameter {
                name: self.parameter_name().unwrap_or("parameter"),
                value: self.parameter().unwrap_or(f64::NAN),
                expected,
            })
        }
    }

    /// The canonical name used by `Display` and `FromStr` (without parameter).
    pub fn name(&self) -> &'static str {
        match self {
            Family::Minimum => "minimum",
            Family::Product => "product",
            Family::Lukasiewicz => "lukasiewicz",
            Family::Drastic => "drastic",
            Family::NilpotentMinimum => "nilpotent-minimum",
            Family::Hamacher { .. } => "hamacher",
            Family::Einstein => "einstein",
            Family::Yager { .. } => "yager",
            Family::Frank { .. } => "frank",
            Family::Dombi { .. } => "dombi",
            Family::SchweizerSklar { .. } => "schweizer-sklar",
            Family::AczelAlsina { .. } => "aczel-alsina",
        }
    }

    /// The name of the family's t-conorm: `maximum`, `probabilistic-sum`, `bounded-sum`,
    /// `drastic-sum`, `nilpotent-maximum`, and the family's own name for the parametric
    /// families and Einstein. `FromStr` accepts each of them.
    pub fn conorm_name(&self) -> &'static str {
        match self {
            Family::Minimum => "maximum",
            Family::Product => "probabilistic-sum",
            Family::Lukasiewicz => "bounded-sum",
            Family::Drastic => "drastic-sum",
            Family::NilpotentMinimum => "nilpotent-maximum",
            _ => self.name(),
        }
    }

    /// The family's parameter, or `None` for the non-parametric families.
    pub fn parameter(&self) -> Option<f64> {
        match *self {
            Family::Hamacher { gamma } => Some(gamma),
            Family::Yager { p } | Family::SchweizerSklar { p } | Family::AczelAlsina { p } => {
                Some(p)
            }
            Family::Frank { s } => Some(s),
            Family::Dombi { lambda } => Some(lambda),
            Family::Minimum
            | Family::Product
            | Family::Lukasiewicz
            | Family::Drastic
            | Family::NilpotentMinimum
            | Family::Einstein => None,
        }
    }

    /// The conventional name of the family's parameter (`"gamma"`, `"p"`,
    /// `"s"`, `"lambda"`), or `None` for the non-parametric families.
    pub fn parameter_name(&self) -> Option<&'static str> {
        match self {
            Family::Hamacher { .. } => Some("gamma"),
            Family::Yager { .. } | Family::SchweizerSklar { .. } | Family::AczelAlsina { .. } => {
                Some("p")
            }
            Family::Frank { .. } => Some("s"),
            Family::Dombi { .. } => Some("lambda"),
            Family::Minimum
            | Family::Product
            | Family::Lukasiewicz
            | Family::Drastic
            | Family::NilpotentMinimum
            | Family::Einstein => None,
        }
    }

    /// Whether the family has a continuous additive generator, i.e. is a
    /// continuous Archimedean t-norm (strict or nilpotent).
    ///
    /// Only these families support generator-based confidence weighting (see
    /// [`TConorm::weighted`](super::TConorm::weighted)). The minimum is
    /// idempotent, and the drastic product and nilpotent minimum are not
    /// continuous, so none of the three has one.
    pub fn is_archimedean(&self) -> bool {
        !matches!(
            self,
            Family::Minimum | Family::Drastic | Family::NilpotentMinimum
        )
    }

    /// One representative of every family, with default parameters:
    /// Hamacher `γ = 0`, Yager `p = 2`, Frank `s = 2`, Dombi `λ = 2`,
    /// Schweizer–Sklar `p = 2`, Aczél–Alsina `p = 2`. The defaults avoid the
    /// values at which a family coincides with another one in the list.
    pub fn catalogue() -> Vec<Family> {
        vec![
            Family::Minimum,
            Family::Product,
            Family::Lukasiewicz,
            Family::Drastic,
            Family::NilpotentMinimum,
            Family::Hamacher { gamma: 0.0 },
            Family::Einstein,
            Family::Yager { p: 2.0 },
            Family::Frank { s: 2.0 },
            Family::Dombi { lambda: 2.0 },
            Family::SchweizerSklar { p: 2.0 },
            Family::AczelAlsina { p: 2.0 },
        ]
    }
}

/// What a name on the command line refers to.
enum Named {
    /// A family without parameter.
    Fixed(Family),
    /// A parametric family, built from its parameter.
    Parametric(fn(f64) -> Family),
}

/// Resolves a lower-cased name or alias.
fn lookup(key: &str) -> Option<Named> {
    use Named::{Fixed, Parametric};
    Some(match key {
        "minimum" | "min" | "max" | "maximum" | "godel" | "gödel" => Fixed(Family::Minimum),
        "product" | "prod" | "probsum" | "probabilistic" | "probabilistic-sum" => {
            Fixed(Family::Product)
        }
        "lukasiewicz" | "łukasiewicz" | "bounded" | "bounded-sum" => Fixed(Family::Lukasiewicz),
        "drastic" | "drastic-sum" => Fixed(Family::Drastic),
        "nilpotent-minimum" | "nilpotent" | "nilpotent-maximum" => Fixed(Family::NilpotentMinimum),
        "einstein" => Fixed(Family::Einstein),
        "hamacher" => Parametric(|gamma| Family::Hamacher { gamma }),
        "yager" => Parametric(|p| Family::Yager { p }),
        "frank" => Parametric(|s| Family::Frank { s }),
        "dombi" => Parametric(|lambda| Family::Dombi { lambda }),
        "schweizer-sklar" => Parametric(|p| Family::SchweizerSklar { p }),
        "aczel-alsina" | "aczél-alsina" => Parametric(|p| Family::AczelAlsina { p }),
        _ => return None,
    })
}

impl FromStr for Family {
    type Err = OperatorError;

    /// Parses `NAME` or `NAME:PARAM` (case-insensitive, `_` accepted for `-`,
    /// surrounding whitespace ignored) and validates the parameter.
    fn from_str(text: &str) -> Result<Family, OperatorError> {
        let text = text.trim();
        let (raw_name, raw_param) = match text.split_once(':') {
            Some((name, param)) => (name.trim(), Some(param.trim())),
            None => (text, None),
        };
        let key = raw_name.to_lowercase().replace('_', "-");
        let named =
            lookup(&key).ok_or_else(|| OperatorError::UnknownOperator(raw_name.to_string()))?;
        match (named, raw_param) {
            (Named::Fixed(family), None) => Ok(family),
            (Named::Fixed(family), Some(param)) => Err(OperatorError::BadSyntax {
                name: family.name().to_string(),
                problem: format!("takes no parameter, but `{param}` was given"),
            }),
            (Named::Parametric(build), None) => {
                let family = build(0.0);
                Err(OperatorError::BadSyntax {
                    name: family.name().to_string(),
                    problem: format!(
                        "requires a parameter {}, written `{}:VALUE`",
                        family.parameter_name().unwrap_or("value"),
                        family.name()
                    ),
                })
            }
            (Named::Parametric(build), Some(param)) => {
                let value: f64 = param.parse().map_err(|_| OperatorError::BadSyntax {
                    name: build(0.0).name().to_string(),
                    problem: if param.is_empty() {
                        "has an empty parameter after `:`".to_string()
                    } else {
                        format!("has a parameter `{param}` that is not a number")
                    },
                })?;
                build(value).validate()
            }
        }
    }
}

/// Formats a parameter so that it parses back to the same `f64`; Rust's float
/// formatting is shortest-round-trip, and exponent notation keeps extreme
/// values short.
pub(super) fn write_parameter(f: &mut fmt::Formatter<'_>, value: f64) -> fmt::Result {
    let magnitude = value.abs();
    if magnitude != 0.0 && !(1e-4..1e6).contains(&magnitude) {
        write!(f, "{value:e}")
    } else {
        write!(f, "{value}")
    }
}

impl fmt::Display for Family {
    /// Writes the canonical `NAME` or `NAME:PARAM` form accepted by `FromStr`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())?;
        if let Some(value) = self.parameter() {
            f.write_str(":")?;
            write_parameter(f, value)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn aliases_resolve() {
        let cases = [
            ("min", Family::Minimum),
            ("MAX", Family::Minimum),
            ("Godel", Family::Minimum),
            ("probsum", Family::Product),
            ("Probabilistic", Family::Product),
            ("bounded", Family::Lukasiewicz),
            ("bounded-sum", Family::Lukasiewicz),
            ("bounded_sum", Family::Lukasiewicz),
            ("Łukasiewicz", Family::Lukasiewicz),
            ("nilpotent", Family::NilpotentMinimum),
            ("  einstein  ", Family::Einstein),
            ("Hamacher: 0.5", Family::Hamacher { gamma: 0.5 }),
            ("schweizer_sklar:-2", Family::SchweizerSklar { p: -2.0 }),
            ("aczel-alsina:1e-2", Family::AczelAlsina { p: 0.01 }),
            ("frank:1e6", Family::Frank { s: 1e6 }),
        ];
        for (text, expected) in cases {
            assert_eq!(text.parse::<Family>(), Ok(expected), "{text}");
        }
    }

    #[test]
    fn catalogue_covers_every_family_once_and_is_valid() {
        let catalogue = Family::catalogue();
        assert_eq!(catalogue.len(), 12);
        let mut names: Vec<_> = catalogue.iter().map(Family::name).collect();
        names.dedup();
        assert_eq!(names.len(), 12);
        for family in catalogue {
            assert_eq!(family.validate(), Ok(family));
            assert_eq!(family.to_string().parse::<Family>(), Ok(family));
        }
        let archimedean = Family::catalogue()
            .iter()
            .filter(|f| f.is_archimedean())
            .count();
        assert_eq!(archimedean, 9);
        assert!(!Family::Drastic.is_archimedean());
        assert!(Family::SchweizerSklar { p: 0.0 }.is_archimedean());
    }

    #[test]
    fn display_is_canonical() {
        assert_eq!(Family::Minimum.to_string(), "minimum");
        assert_eq!(Family::Hamacher { gamma: 0.0 }.to_string(), "hamacher:0");
        assert_eq!(Family::Frank { s: 0.5 }.to_string(), "frank:0.5");
        assert_eq!(Family::Frank { s: 1e-6 }.to_string(), "frank:1e-6");
        assert_eq!(Family::Frank { s: 1e300 }.to_string(), "frank:1e300");
        assert_eq!(
            Family::SchweizerSklar { p: -20.0 }.to_string(),
            "schweizer-sklar:-20"
        );
    }

    #[test]
    fn unknown_names_are_typed_errors() {
        for text in ["", "median", "hamacher-product", "yager2", ":2"] {
            assert!(
                matches!(
                    text.parse::<Family>(),
                    Err(OperatorError::UnknownOperator(_))
                ),
                "{text:?}"
            );
        }
        // The error lists every canonical name, so a user can pick one.
        let message = "median".parse::<Family>().unwrap_err().to_string();
        assert!(
            message.starts_with("unknown operator `median`"),
            "{message}"
        );
        for family in Family::catalogue() {
            let listed = match family.parameter_name() {
                Some(param) => format!("{}:{}", family.name(), param.to_uppercase()),
                None => family.name().to_string(),
            };
            assert!(message.contains(&listed), "{listed} missing from {message}");
        }
    }

    #[test]
    fn bad_syntax_is_a_typed_error() {
        let bad = |text: &str| match text.parse::<Family>() {
            Err(OperatorError::BadSyntax { name, problem }) => Some((name, problem)),
            _ => None,
        };
        let (name, problem) = bad("hamacher").expect("missing parameter");
        assert_eq!(name, "hamacher");
        assert!(problem.contains("requires a parameter gamma"), "{problem}");
        let (name, problem) = bad("min:2").expect("unexpected parameter");
        assert_eq!(name, "minimum");
        assert!(problem.contains("takes no parameter"), "{problem}");
        assert!(bad("yager:").expect("empty").1.contains("empty"));
        assert!(bad("yager:two").expect("unparsable").1.contains("`two`"));
        assert!(bad("yager:1:2").is_some());
        let message = "frank".parse::<Family>().unwrap_err().to_string();
        assert_eq!(
            message,
            "operator `frank` requires a parameter s, written `frank:VALUE`"
        );
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let invalid = [
            Family::Hamacher { gamma: -0.1 },
            Family::Hamacher {
                gamma: f64::INFINITY,
            },
            Family::Yager { p: 0.0 },
            Family::Yager { p: -1.0 },
            Family::Frank { s: 1.0 },
            Family::Frank { s: 0.0 },
            Family::Frank { s: -2.0 },
            Family::Frank { s: 1e-310 },
            Family::Frank { s: f64::INFINITY },
            Family::Dombi { lambda: 0.0 },
            Family::SchweizerSklar {
                p: f64::NEG_INFINITY,
            },
            Family::AczelAlsina { p: -0.5 },
        ];
        for family in invalid {
            match family.validate() {
                Err(OperatorError::InvalidParameter { name, value, .. }) => {
                    assert_eq!(Some(name), family.parameter_name());
                    assert_eq!(Some(value), family.parameter());
                }
                other => panic!("{family:?} gave {other:?}"),
            }
        }
        for text in [
            "hamacher:-1",
            "yager:nan",
            "frank:1",
            "dombi:inf",
            "schweizer-sklar:NaN",
        ] {
            assert!(
                matches!(
                    text.parse::<Family>(),
                    Err(OperatorError::InvalidParameter { .. })
                ),
                "{text}"
            );
        }
        let message = "yager:-1".parse::<Family>().unwrap_err().to_string();
        assert_eq!(
            message,
            "operator parameter p = -1 is invalid: must be finite and > 0"
        );
    }

    #[test]
    fn nan_parameters_are_rejected_for_every_parametric_family() {
        for family in Family::catalogue() {
            let Some(name) = family.parameter_name() else {
                continue;
            };
            let broken = format!("{}:NaN", family.name()).parse::<Family>();
            assert!(
                matches!(broken, Err(OperatorError::InvalidParameter { name: n, .. }) if n == name),
                "{family}"
            );
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Display and FromStr round-trip for every family over wide,
        /// log-uniform parameter ranges.
        #[test]
        fn display_round_trips(
            index in 0usize..12,
            magnitude in -12.0f64..12.0,
            mantissa in 1.0f64..10.0,
            negative in any::<bool>(),
        ) {
            let value = mantissa * 10f64.powf(magnitude);
            let family = match index {
                0 => Family::Minimum,
                1 => Family::Product,
                2 => Family::Lukasiewicz,
                3 => Family::Drastic,
                4 => Family::NilpotentMinimum,
                5 => Family::Hamacher { gamma: value },
                6 => Family::Einstein,
                7 => Family::Yager { p: value },
                8 => Family::Frank { s: value },
                9 => Family::Dombi { lambda: value },
                10 => Family::SchweizerSklar { p: if negative { -value } else { value } },
                _ => Family::AczelAlsina { p: value },
            };
            let text = family.to_string();
            prop_assert_eq!(text.parse::<Family>(), Ok(family), "{}", text);
            // The t-conorm's name reads back as the same family too.
            if let Ok(conorm) = crate::TConorm::new(family) {
                let text = conorm.to_string();
                prop_assert_eq!(text.parse::<Family>(), Ok(family), "{}", text);
            }
        }

        /// Arbitrary text never panics the parser.
        #[test]
        fn parser_never_panics(text in "\\PC{0,24}") {
            let _ = text.parse::<Family>();
        }
    }
}
