//! # fuzzyvox
//!
//! Confidence-aware 3D mapping for small drones and other cameras whose depth is uncertain.
//!
//! fuzzyvox keeps two fuzzy membership degrees per voxel, how occupied (μO) and how free (μE),
//! aggregates evidence with t-conorms so that the order of observations does not matter, spreads
//! each depth measurement over the frustum and interval it really covers, and derives
//! ambiguity, indeterminacy, safety and a class for every voxel.
//!
//! The parts, each usable on its own:
//! - [`ops`]: t-norms, t-conorms, complements and hedges;
//! - storage: sparse 8×8×8 blocks with `i32` keys ([`BlockGrid`], [`Resolution`]);
//! - integration of [`PointCloud`]s (exact ray walk) and [`DepthFrame`]s with depth intervals
//!   (projective frustum), into [`ScanEvidence`];
//! - the [`depth`] stage: motion stereo from posed images to interval depth with confidence;
//! - the dual-set [`FuzzyMap`] with its [`Measures`], merge, and crash-safe files.
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

#![deny(missing_docs)]
#![forbid(unsafe_code)]
// Bad input is an error, never a panic: the library may not unwrap, expect or panic outside its
// tests (tests, benches and examples may).
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::todo,
        clippy::unimplemented,
        clippy::unreachable
    )
)]

pub mod depth;
mod error;
pub mod eval;
pub mod figure;
pub mod fly;
pub mod geometry;
pub mod integrate;
pub mod io;
pub mod map;
pub mod measures;
pub mod ops;
pub mod plan;
pub mod sim;
pub mod storage;
pub mod view;

pub use error::{Error, FormatError, Result};
pub use geometry::{PinholeIntrinsics, pose_from_matrix, validate_pose};
pub use integrate::{
    DepthFrame, Evidence, EvidenceKind, EvidenceModel, IntegrationOptions, IntegrationStats,
    IntervalDepthImage, PointCloud, ScanEvidence,
};
pub use map::{
    AlphaConfig, AlphaCutMap, AnyMap, FuzzyConfig, FuzzyMap, LogOddsConfig, LogOddsMap,
    VoxelCounts, VoxelMap, VoxelMapMut,
};
pub use measures::{ClassThresholds, MeasureConfig, Measures, Memberships, VoxelClass};
pub use ops::{Complement, Family, Hedge, TConorm, TNorm};
pub use storage::{BlockGrid, BlockKey, KeyBox, Resolution, VoxelKey};
