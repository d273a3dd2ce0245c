//! The core of fuzzyvox: the maps and everything they are made of, with no dependency on the
//! depth stage, the planner, the simulator or any file format but the maps' own.
//!
//! - [`ops`] (re-exported from `fuzzyvox-ops`): t-norms, t-conorms, complements and hedges;
//! - [`error`]: the one error type of every fuzzyvox crate ([`Error`]);
//! - [`class`] and [`measures`]: a voxel's class, and the measures (ambiguity,
//!   indeterminacy, safety) derived from its two memberships;
//! - [`geometry`]: pinhole intrinsics and poses;
//! - [`image`]: grayscale images, posed [`Frame`]s and the [`StereoGeometry`] of a rectified
//!   pair, as file readers make them and the depth stage takes them;
//! - [`storage`]: sparse 8×8×8 blocks with `i32` keys ([`BlockGrid`], [`Resolution`]);
//! - [`integrate`]: [`PointCloud`]s (exact ray walk) and [`DepthFrame`]s with depth intervals
//!   (projective frustum), into [`ScanEvidence`];
//! - [`map`]: the dual-set [`FuzzyMap`], the log-odds and alpha-cut baselines, and the read and
//!   write traits every map implements ([`VoxelMap`], [`VoxelMapMut`]);
//! - [`file`](mod@file): the maps' native files (crash-safe writes, checked reads).
//!
//! ```
//! use fuzzyvox_core::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelMap, VoxelMapMut};
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
//! # Ok::<(), fuzzyvox_core::Error>(())
//! ```

pub use fuzzyvox_ops as ops;

pub mod class;
#[macro_use]
pub mod dispatch;
pub mod error;
pub mod file;
pub mod geometry;
pub mod image;
pub mod integrate;
pub mod map;
pub mod measures;
pub mod storage;

pub use error::{Error, FormatError, Result};
pub use geometry::{PinholeIntrinsics, pose_from_matrix, validate_pose};
pub use image::{Frame, GrayImage, StereoGeometry};
pub use integrate::{
    DepthFrame, Evidence, EvidenceKind, EvidenceModel, IntegrationOptions, IntegrationStats,
    IntervalDepthImage, PointCloud, ScanEvidence,
};
pub use map::{
    AlphaConfig, AlphaCutMap, AnyMap, FuzzyConfig, FuzzyMap, LogOddsConfig, LogOddsMap, MapKind,
    MapOptions, VoxelCounts, VoxelMap, VoxelMapMut,
};
pub use measures::{ClassThresholds, MeasureConfig, Measures, Memberships, VoxelClass};
pub use ops::{Complement, Family, Hedge, TConorm, TNorm};
pub use storage::{BlockGrid, BlockKey, KeyBox, Resolution, VoxelKey};
