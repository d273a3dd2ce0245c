//! Planning through the maps: safety queries, a cost field with exact clearance, and A* over the
//! implicit 26-connected voxel graph.
//!
//! Every map reports the same measures, so everything here runs on the fuzzy map and on both
//! baselines through [`VoxelMap`](fuzzyvox_core::VoxelMap).
//!
//! 1. [`PlannerConfig`] holds every threshold and the unknown-space policy in one value.
//! 2. [`queries`](SafetyQueries) answer "is this point safe for a vehicle of radius r", "where is
//!    the nearest safe voxel", "which voxels of this box are safe".
//! 3. [`CostField`] turns a map region into traversability, safety and clearance (an exact
//!    Euclidean distance transform to the nearest blocked voxel), and step costs
//!    `length × (1 + k (1 - S))` plus a clearance penalty.
//! 4. [`VoxelGraph`] exposes the field through petgraph's graph traits (no graph is built), so
//!    petgraph's own `astar` and `dijkstra` run on it; [`plan_path`] runs a dense-array A* with a
//!    consistent heuristic over the same graph, then shortcuts the path by line of sight and
//!    merges collinear waypoints. A start or goal it may not enter is refused with a
//!    [`Blocker`] that says why and which setting would change it.
//! 5. [`Planner`] owns a region's field and keeps it current as the map grows: it updates only
//!    around the blocks the map reports changed ([`VoxelMap::changed_blocks_since`](fuzzyvox_core::VoxelMap::changed_blocks_since)),
//!    with exactly the result of a full build, so a closed loop can replan every frame.

mod astar;
mod blocker;
mod config;
mod cost_field;
mod edt;
mod error;
mod field_update;
mod graph;
mod heuristic;
mod layers;
mod least_rate;
mod path;
mod plan_path;
mod planner;
mod queries;
mod region;
mod repair;
mod rules;
mod smooth;

pub use blocker::{Blocker, NearestBlocked, ObservedExtent};
pub use config::{PlannerConfig, UnknownPolicy};
pub use cost_field::CostField;
pub use edt::squared_distance_transform;
pub use error::PlanError;
pub use field_update::FieldUpdate;
pub use graph::{VoxelEdge, VoxelGraph};
pub use path::{Path, plan_in_field, plan_in_field_avoiding, plan_in_field_within};
pub use plan_path::plan_path;
pub use planner::Planner;
pub use queries::SafetyQueries;
pub use region::PlanningRegion;
pub use repair::repair_in_field;
pub use rules::is_blocked;
