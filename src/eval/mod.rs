//! Evaluation of maps against ground truth: the quantitative metrics the paper could not give.
//!
//! [`GroundTruth`] holds, for a resolution, the voxels that meet the true scene geometry and
//! the region the cameras could observe (from the "gold standard": true depth inserted with the
//! standard method). [`evaluate`] compares any map with it: occupied precision, recall and F1;
//! holes (truly occupied voxels the map calls free); spurious occupied voxels in the truly
//! unknown region (behind walls, in the sky); and the Chamfer distance from occupied voxel
//! centres to the true surface.

mod experiment;
mod figures;
mod metrics;
mod rgbd;
mod truth;

pub use experiment::{ExperimentConfig, ExperimentReport, MapReport, run_experiment};
pub use figures::top_down_png;
pub use metrics::{MapMetrics, evaluate};
pub use rgbd::{DepthAgreement, DepthCheckConfig, DepthErrors, HoldoutSplit};
pub use truth::{GroundTruth, gold_standard};
