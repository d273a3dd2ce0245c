//! # fuzzyvox
//!
//! Confidence-aware 3D mapping for small drones and other cameras whose depth is uncertain.
//!
//! fuzzyvox keeps two fuzzy membership degrees per voxel, how occupied (μO) and how free (μE),
//! aggregates evidence with t-conorms so that the order of observations does not matter, spreads
//! each depth measurement over the frustum and interval it really covers, and derives
//! ambiguity, indeterminacy, safety and a class for every voxel.
//!
//! This crate is the facade: it re-exports the workspace's library crates under one name (the
//! `fuzzyvox` command is its own crate, `fuzzyvox-cli`, and adds nothing to a library user's
//! build). The parts, each a crate usable on its own (see `docs/architecture.md`):
//! - [`ops`]: t-norms, t-conorms, complements and hedges;
//! - storage: sparse 8×8×8 blocks with `i32` keys ([`BlockGrid`], [`Resolution`]);
//! - integration of [`PointCloud`]s (exact ray walk) and [`DepthFrame`]s with depth intervals
//!   (projective frustum), into [`ScanEvidence`];
//! - the [`depth`] stage: motion stereo from posed images to interval depth with confidence;
//! - the dual-set [`FuzzyMap`] with its [`Measures`], merge, and crash-safe files;
//! - [`bag`]: robot recordings (ROS 1 bags, ROS 2 MCAP bags) as scans and posed frames.
//!
//! ```
//! use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelMap, VoxelMapMut};
//! use nalgebra::Point3;
//!
//! let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
//! let wall: Vec<_> = (0..50)
//!     .map(|i| Point3::new(3.0, -1.0 + 0.04 * f64::from(i), 0.5))
//!     .collect();
//! let cloud = PointCloud::new(Point3::origin(), wall)?.with_confidence(vec![0.8; 50])?;
//! map.integrate_cloud(&cloud, &IntegrationOptions::default())?;
//! let here = map.measures_at_point(&Point3::new(1.5, 0.02, 0.25))?;
//! assert!(here.safety > 0.0 && here.free > here.occupied);
//! # Ok::<(), fuzzyvox::Error>(())
//! ```

pub use fuzzyvox_bag as bag;
pub use fuzzyvox_core::{
    class, error, file, geometry, image, integrate, map, measures, ops, storage,
};
pub use fuzzyvox_depth as depth;
pub use fuzzyvox_eval as eval;
pub use fuzzyvox_figure as figure;
pub use fuzzyvox_fly as fly;
pub use fuzzyvox_io as io;
pub use fuzzyvox_plan as plan;
pub use fuzzyvox_sim as sim;
pub use fuzzyvox_view as view;

pub use fuzzyvox_core::{
    AlphaConfig, AlphaCutMap, AnyMap, BlockGrid, BlockKey, ClassThresholds, Complement, DepthFrame,
    Error, Evidence, EvidenceKind, EvidenceModel, Family, FormatError, FuzzyConfig, FuzzyMap,
    Hedge, IntegrationOptions, IntegrationStats, IntervalDepthImage, KeyBox, LogOddsConfig,
    LogOddsMap, MapKind, MapOptions, MeasureConfig, Measures, Memberships, PinholeIntrinsics,
    PointCloud, Resolution, Result, ScanEvidence, TConorm, TNorm, VoxelClass, VoxelCounts,
    VoxelKey, VoxelMap, VoxelMapMut, pose_from_matrix, validate_pose,
};
