//! What a voxel's two memberships mean: ambiguity, indeterminacy, safety, certainty,
//! contradiction and a class.
//!
//! Every map reports its cells as [`Memberships`] (the fuzzy map directly, the log-odds maps
//! through `μO = p`, `μE = 1 - p`), so every measure, query and planner runs on every map.

mod class;
mod compute;

pub use crate::class::VoxelClass;
pub use class::ClassThresholds;
pub use compute::{MeasureConfig, Measures, Memberships};
