//! Why planning failed: [`PlanError`], and its conversion into the core's error.

use fuzzyvox_core::error::Error;

use crate::blocker::Blocker;

/// Why no path was found.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The start or goal lies outside the planning region.
    #[error("the {0} lies outside the planning region")]
    OutOfRegion(&'static str),
    /// The start voxel cannot be entered; the [`Blocker`] says why (outside the observed
    /// extent, unknown, occupied, ambiguous, low safety, or too close to a blocked voxel) and
    /// what would change it.
    #[error("the start is not safe: {0}")]
    StartUnsafe(Blocker),
    /// The goal voxel cannot be entered; the [`Blocker`] says why.
    #[error("the goal is not safe: {0}")]
    GoalUnsafe(Blocker),
    /// The goal is a voxel the caller asked the planner to avoid
    /// ([`plan_in_field_avoiding`](crate::plan_in_field_avoiding)).
    #[error("the goal is one of the voxels the planner was asked to avoid")]
    GoalAvoided,
    /// Start and goal are not connected through traversable voxels.
    #[error(
        "the goal is not connected to the start through safe space ({expanded} voxels searched)"
    )]
    Disconnected {
        /// Nodes expanded before the search ran out.
        expanded: usize,
    },
    /// The map or the configuration rejected the request.
    #[error(transparent)]
    Map(#[from] Error),
}

/// Into the core's error, for callers that handle every fuzzyvox error as one type: a map or
/// configuration error becomes itself again, any other reason [`Error::Plan`] (which
/// `downcast_ref::<PlanError>()` reads back).
impl From<PlanError> for Error {
    fn from(error: PlanError) -> Self {
        match error {
            PlanError::Map(error) => error,
            other => Error::Plan(Box::new(other)),
        }
    }
}

impl PlanError {
    /// Why the start or goal was refused, for [`PlanError::StartUnsafe`] and
    /// [`PlanError::GoalUnsafe`].
    pub fn blocker(&self) -> Option<&Blocker> {
        match self {
            Self::StartUnsafe(why) | Self::GoalUnsafe(why) => Some(why),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plan_errors_convert_into_the_core_error() {
        let disconnected: Error = PlanError::Disconnected { expanded: 7 }.into();
        let Error::Plan(inner) = &disconnected else {
            panic!("{disconnected:?}");
        };
        assert!(matches!(
            inner.downcast_ref::<PlanError>(),
            Some(PlanError::Disconnected { expanded: 7 })
        ));
        assert_eq!(
            disconnected.to_string(),
            PlanError::Disconnected { expanded: 7 }.to_string()
        );
        let map: Error = PlanError::Map(Error::Empty("cloud")).into();
        assert!(matches!(map, Error::Empty("cloud")), "{map:?}");
    }
}
