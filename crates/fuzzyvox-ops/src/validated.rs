//! What a t-norm and a t-conorm share: a [`Family`](crate::Family) whose parameter has been
//! validated, made from a family only through validation, and turned back into its family.

/// Declares an operator type holding one validated `family: Family`, with `new` (the only way
/// from a family, validating it), `from_validated` (for the dual of a valid operator),
/// `family`, `dual`, and the `TryFrom<Family>`/`From<_> for Family` pair serde goes through.
macro_rules! validated_family {
    ($(#[$doc:meta])* $operator:ident, $what:literal, dual: $dual:ident, $dual_doc:literal) => {
        $(#[$doc])*
        ///
        /// Serialises as its [`Family`]; deserialising validates the parameter.
        #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(try_from = "Family", into = "Family")]
        pub struct $operator {
            family: Family,
        }

        impl $operator {
            #[doc = concat!("Creates the ", $what, " of `family` after validating its parameter.")]
            ///
            /// # Errors
            /// [`OperatorError::InvalidParameter`] if the parameter is not finite or is
            /// outside the family's domain.
            pub fn new(family: Family) -> Result<$operator, OperatorError> {
                Ok($operator {
                    family: family.validate()?,
                })
            }

            /// Wraps a family that is already known to be valid (used by `dual`).
            pub(crate) fn from_validated(family: Family) -> $operator {
                $operator { family }
            }

            #[doc = concat!("The family this ", $what, " belongs to.")]
            pub fn family(&self) -> Family {
                self.family
            }

            #[doc = $dual_doc]
            pub fn dual(&self) -> $dual {
                $dual::from_validated(self.family)
            }
        }

        impl TryFrom<Family> for $operator {
            type Error = OperatorError;

            fn try_from(family: Family) -> Result<$operator, OperatorError> {
                $operator::new(family)
            }
        }

        impl From<$operator> for Family {
            fn from(operator: $operator) -> Family {
                operator.family
            }
        }
    };
}

pub(crate) use validated_family;
