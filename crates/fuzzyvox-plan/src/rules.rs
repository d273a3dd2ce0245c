//! What a cost field knows of one voxel ([`Voxel`]), and the rules that turn a voxel's class,
//! safety and clearance into whether it is blocked or traversable and what it costs
//! ([`Rules`], [`is_blocked`]).

use fuzzyvox_core::measures::VoxelClass;

use crate::config::{PlannerConfig, UnknownPolicy};

/// What the field knows of one voxel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Voxel {
    pub(super) safety: f32,
    pub(super) clearance: f32,
    /// Cost per metre (infinite when not traversable).
    pub(super) rate: f32,
    pub(super) class: VoxelClass,
    pub(super) traversable: bool,
}

/// The rules that turn a voxel's class, safety and clearance into whether it is blocked or
/// traversable and what it costs, with the configuration's derived figures computed once.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rules {
    config: PlannerConfig,
    /// [`CostField::required_clearance`](crate::CostField::required_clearance).
    required: f32,
    /// The preferred clearance (never 0).
    preferred: f32,
}

impl Rules {
    /// The rules of `config`, with the field's required clearance and its preferred clearance
    /// (never 0).
    pub(super) fn new(config: PlannerConfig, required: f32, preferred: f32) -> Self {
        Self {
            config,
            required,
            preferred,
        }
    }

    /// Whether a voxel of this class and safety is blocked ([`is_blocked`]).
    #[inline]
    pub(super) fn blocked(&self, class: VoxelClass, safety: f32) -> bool {
        is_blocked(class, safety, &self.config)
    }

    /// Whether a voxel of this class, safety and clearance is traversable, and its rate.
    #[inline]
    pub(super) fn entry(&self, class: VoxelClass, safety: f32, clearance: f32) -> (bool, f32) {
        let config = &self.config;
        let traversable = !self.blocked(class, safety) && clearance >= self.required;
        let rate = if traversable {
            let unknown = match (class, config.unknown) {
                (VoxelClass::Unknown, UnknownPolicy::Cost(c)) => c,
                _ => 0.0,
            };
            1.0 + config.safety_weight * (1.0 - safety)
                + config.clearance_weight * (1.0 - clearance / self.preferred).max(0.0)
                + unknown
        } else {
            f32::INFINITY
        };
        (traversable, rate)
    }
}

impl Voxel {
    pub(super) const UNKNOWN: Self = Self {
        safety: 0.0,
        clearance: 0.0,
        rate: f32::INFINITY,
        class: VoxelClass::Unknown,
        traversable: false,
    };
}

/// Whether a voxel of `class` and `safety` is blocked under `config` (occupied, ambiguous, free
/// with safety below the threshold, or unknown while unknown space is forbidden).
pub fn is_blocked(class: VoxelClass, safety: f32, config: &PlannerConfig) -> bool {
    match class {
        VoxelClass::Occupied | VoxelClass::Ambiguous => true,
        VoxelClass::Unknown => !matches!(config.unknown, UnknownPolicy::Cost(_)),
        VoxelClass::Free => safety < config.safety_threshold,
    }
}
