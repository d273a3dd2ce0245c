//! Observations and how they become per-scan evidence.
//!
//! An observation (a [`PointCloud`] with a sensor origin, or a [`DepthFrame`] of interval depth)
//! is first turned into [`ScanEvidence`]: for every voxel it reaches, the strongest occupied and
//! free evidence that this one scan gives it. A map then folds the scan's evidence into its
//! cells, once per voxel per scan, so that a thousand rays through the same voxel in one scan
//! count as one observation, as in OctoMap.
//!
//! Both integrators split their work into pieces of a fixed size and combine the pieces with
//! `max`, which is exact in floating point; the evidence, and hence the map, is the same bit for
//! bit for any number of threads.

mod batches;
mod cloud;
mod depth_image;
mod evidence;
mod footprint;
mod frustum;
mod octomap_walk;
mod points;
mod raywalk;
mod scan_sets;

pub(crate) use batches::scan_groups;
pub use cloud::PointCloud;
pub use depth_image::{DepthFrame, IntervalDepthImage};
pub use evidence::{
    Evidence, EvidenceKind, EvidenceModel, IntegrationOptions, IntegrationStats, ScanEvidence,
};
pub use frustum::depth_evidence;
pub use octomap_walk::walk_ray_octomap;
pub use points::cloud_evidence;
pub(crate) use points::{CloudScan, check_cloud, cloud_scan_checked};
pub use raywalk::{walk_ray, walk_ray_until};
pub use scan_sets::{
    BlockFlags, BlockLevels, CellMarks, ScanBlocks, ScanLevels, ScanSets, scan_levels, scan_sets,
};
pub(crate) use scan_sets::{Checked, check_octomap_scan, walk_scan};
