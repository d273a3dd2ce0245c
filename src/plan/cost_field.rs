use nalgebra::Point3;
use rayon::prelude::*;

use super::blocker::{Blocker, NearestBlocked};
use super::config::{PlannerConfig, UnknownPolicy};
use super::edt::squared_distance_transform;
use crate::error::{Error, Result};
use crate::map::VoxelMap;
use crate::measures::VoxelClass;
use crate::storage::{Resolution, VoxelKey};

/// Largest planning region, in voxels (a guard against absurd requests: 64 Mi voxels use about
/// 1 GiB of working memory).
const MAX_REGION_VOXELS: usize = 1 << 26;

/// An axis-aligned box of voxels to plan in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlanningRegion {
    min: VoxelKey,
    dims: [usize; 3],
}

impl PlanningRegion {
    /// The voxels from `a` to `b` (inclusive, in any order); at most 2^26 voxels.
    pub fn new(a: VoxelKey, b: VoxelKey) -> Result<Self> {
        let min = VoxelKey::new(a.x.min(b.x), a.y.min(b.y), a.z.min(b.z));
        let span = |lo: i32, hi: i32| (i64::from(hi) - i64::from(lo) + 1) as usize;
        let dims = [
            span(min.x, a.x.max(b.x)),
            span(min.y, a.y.max(b.y)),
            span(min.z, a.z.max(b.z)),
        ];
        let voxels = dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]);
        if voxels > MAX_REGION_VOXELS {
            return Err(Error::InvalidParameter {
                name: "planning region voxels",
                value: voxels as f64,
                expected: "a region of at most 2^26 voxels; plan between nearer points or at a coarser resolution",
            });
        }
        Ok(Self { min, dims })
    }

    /// The box around two points grown by `margin` metres on every side.
    pub fn around(
        resolution: &Resolution,
        a: &Point3<f64>,
        b: &Point3<f64>,
        margin: f64,
    ) -> Result<Self> {
        let lo = a.inf(b) - nalgebra::Vector3::repeat(margin);
        let hi = a.sup(b) + nalgebra::Vector3::repeat(margin);
        Self::new(resolution.key_of(&lo)?, resolution.key_of(&hi)?)
    }

    /// Size in voxels along x, y, z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The lowest key.
    pub fn min(&self) -> VoxelKey {
        self.min
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Whether the region holds no voxel (never, for a constructed region).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The dense index of `key` (x fastest), if inside.
    #[inline]
    pub fn index_of(&self, key: VoxelKey) -> Option<usize> {
        let x = i64::from(key.x) - i64::from(self.min.x);
        let y = i64::from(key.y) - i64::from(self.min.y);
        let z = i64::from(key.z) - i64::from(self.min.z);
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        (x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz)
            .then(|| (x + nx * (y + ny * z)) as usize)
    }

    /// The key at a dense index.
    #[inline]
    pub fn key_at(&self, index: usize) -> VoxelKey {
        let [nx, ny, _] = self.dims;
        VoxelKey::new(
            self.min.x + (index % nx) as i32,
            self.min.y + ((index / nx) % ny) as i32,
            self.min.z + (index / (nx * ny)) as i32,
        )
    }
}

/// A map region turned into what a planner needs per voxel: whether it may be entered, its
/// safety, its clearance, and the cost of moving through it.
///
/// - A voxel is **blocked** when it is occupied or ambiguous, when its safety is below the
///   threshold, or when it is unknown and unknown space is forbidden. Space outside the region
///   counts as blocked.
/// - **Clearance** is the exact Euclidean distance from the voxel's centre to the nearest blocked
///   voxel centre.
/// - A voxel is **traversable** when it is not blocked and its clearance is at least the vehicle
///   radius plus `√3 × resolution`. That margin covers half a blocked voxel and half a step, so
///   every point of a path whose steps join traversable voxels (or whose straight segments only
///   cross traversable voxels) keeps the vehicle radius from every blocked voxel.
/// - Entering a voxel costs, per metre, `1 + k (1 - S) + w max(0, 1 - clearance / preferred)`
///   (plus the unknown cost for unknown voxels under [`UnknownPolicy::Cost`]); a step of length
///   `l` between voxels costs `l` times the mean of their two rates, never less than `l`.
#[derive(Clone, Debug)]
pub struct CostField {
    region: PlanningRegion,
    resolution: Resolution,
    config: PlannerConfig,
    traversable: Vec<bool>,
    class: Vec<VoxelClass>,
    safety: Vec<f32>,
    clearance: Vec<f32>,
    rate: Vec<f32>,
    min_rate: f32,
}

impl CostField {
    /// Builds the field of `region` from any map.
    pub fn build(
        map: &dyn VoxelMap,
        region: PlanningRegion,
        config: PlannerConfig,
    ) -> Result<Self> {
        let config = config.validate()?;
        let resolution = map.resolution();
        let n = region.len();
        let measures: Vec<(f32, VoxelClass)> = (0..n)
            .into_par_iter()
            .map(|i| {
                let m = map.measures_at(region.key_at(i));
                (m.safety, m.class)
            })
            .collect();
        let blocked: Vec<bool> = measures
            .iter()
            .map(|&(safety, class)| is_blocked(class, safety, &config))
            .collect();
        let clearance = clearance_in_metres(&blocked, region.dims(), resolution.size());
        let required = (config.vehicle_radius + 3f64.sqrt() * resolution.size()) as f32;
        let unknown_cost = match config.unknown {
            UnknownPolicy::Cost(c) => c,
            UnknownPolicy::Forbid => 0.0,
        };
        let preferred = config.preferred_clearance.max(1e-9) as f32;
        let mut traversable = vec![false; n];
        let mut rate = vec![f32::INFINITY; n];
        for i in 0..n {
            let (safety, class) = measures[i];
            if blocked[i] || clearance[i] < required {
                continue;
            }
            traversable[i] = true;
            let unknown = if class == VoxelClass::Unknown {
                unknown_cost
            } else {
                0.0
            };
            rate[i] = 1.0
                + config.safety_weight * (1.0 - safety)
                + config.clearance_weight * (1.0 - clearance[i] / preferred).max(0.0)
                + unknown;
        }
        let min_rate = rate.iter().copied().fold(f32::INFINITY, f32::min).max(1.0);
        Ok(Self {
            region,
            resolution,
            config,
            traversable,
            class: measures.iter().map(|m| m.1).collect(),
            safety: measures.iter().map(|m| m.0).collect(),
            clearance,
            rate,
            min_rate,
        })
    }

    /// The region.
    pub fn region(&self) -> &PlanningRegion {
        &self.region
    }

    /// The voxel size.
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    /// The configuration the field was built with.
    pub fn config(&self) -> &PlannerConfig {
        &self.config
    }

    /// Whether the voxel at a dense index may be entered.
    #[inline]
    pub fn is_traversable(&self, index: usize) -> bool {
        self.traversable.get(index).copied().unwrap_or(false)
    }

    /// Whether the voxel at a dense index is blocked itself (occupied, ambiguous, free with
    /// safety below the threshold, or unknown while unknown space is forbidden); outside the
    /// region everything is blocked.
    pub fn is_blocked(&self, index: usize) -> bool {
        index >= self.region.len()
            || is_blocked(self.class(index), self.safety(index), &self.config)
    }

    /// Class of the voxel at a dense index ([`VoxelClass::Unknown`] outside the region).
    pub fn class(&self, index: usize) -> VoxelClass {
        self.class
            .get(index)
            .copied()
            .unwrap_or(VoxelClass::Unknown)
    }

    /// Why the voxel at a dense index may not be entered, or `None` when it may (or lies
    /// outside the region). Blocked voxels report their class, safety or the policy that
    /// blocks them; voxels that are not blocked themselves report their clearance, what the
    /// vehicle needs, and the nearest blocked voxel.
    pub fn blocker(&self, index: usize) -> Option<Blocker> {
        if index >= self.region.len() || self.is_traversable(index) {
            return None;
        }
        let safety = self.safety(index);
        if self.is_blocked(index) {
            return Some(match self.class(index) {
                VoxelClass::Occupied => Blocker::Occupied { safety },
                VoxelClass::Ambiguous => Blocker::Ambiguous { safety },
                VoxelClass::Unknown => Blocker::Unknown,
                VoxelClass::Free => Blocker::LowSafety {
                    safety,
                    threshold: self.config.safety_threshold,
                },
            });
        }
        let clearance = f64::from(self.clearance(index));
        let margin = 3f64.sqrt() * self.resolution.size();
        Some(Blocker::TooClose {
            clearance,
            required: self.config.vehicle_radius + margin,
            vehicle_radius: self.config.vehicle_radius,
            largest_radius: clearance - margin,
            nearest: self.nearest_blocked(index, clearance),
        })
    }

    /// The blocked voxel at `clearance` metres from the voxel at `index` (the first in index
    /// order when several are), or `None` when only the region's edge is that near. The
    /// distance transform gives the distance but not the voxel, so this searches the cube of
    /// that half-width: only failed requests call it.
    fn nearest_blocked(&self, index: usize, clearance: f64) -> Option<NearestBlocked> {
        let size = self.resolution.size();
        let reach = (clearance / size).ceil() as i64 + 1;
        let here = self.region.key_at(index);
        let lowest = self.region.min();
        let dims = self.region.dims();
        // The cube of half-width `reach` around the voxel, clipped to the region, as offsets.
        let span = |axis: usize, at: i32, min: i32| {
            let offset = i64::from(at) - i64::from(min);
            (-reach).max(-offset)..=reach.min(dims[axis] as i64 - 1 - offset)
        };
        let mut best: Option<(i64, usize)> = None;
        for dz in span(2, here.z, lowest.z) {
            for dy in span(1, here.y, lowest.y) {
                for dx in span(0, here.x, lowest.x) {
                    let squared = dx * dx + dy * dy + dz * dz;
                    if best.is_some_and(|(d, _)| squared >= d) {
                        continue;
                    }
                    // Inside the region by construction of the spans.
                    let key =
                        VoxelKey::new(here.x + dx as i32, here.y + dy as i32, here.z + dz as i32);
                    if let Some(other) = self.region.index_of(key)
                        && self.is_blocked(other)
                    {
                        best = Some((squared, other));
                    }
                }
            }
        }
        let (squared, other) = best?;
        let distance = (squared as f64).sqrt() * size;
        // The edge of the region (blocked by definition) may be nearer than any voxel inside.
        if distance > clearance + 1e-3 * size {
            return None;
        }
        Some(NearestBlocked {
            center: self.resolution.center(self.region.key_at(other)),
            class: self.class(other),
            safety: self.safety(other),
            distance,
        })
    }

    /// Safety of the voxel at a dense index.
    pub fn safety(&self, index: usize) -> f32 {
        self.safety.get(index).copied().unwrap_or(0.0)
    }

    /// Clearance (metres) of the voxel at a dense index.
    pub fn clearance(&self, index: usize) -> f32 {
        self.clearance.get(index).copied().unwrap_or(0.0)
    }

    /// Cost per metre of entering the voxel at a dense index (infinite when not traversable).
    #[inline]
    pub fn rate(&self, index: usize) -> f32 {
        self.rate.get(index).copied().unwrap_or(f32::INFINITY)
    }

    /// The lowest cost per metre of any traversable voxel (at least 1): every step of length `l`
    /// costs at least `l × min_rate`, which keeps A*'s distance heuristic consistent and tight.
    pub fn min_rate(&self) -> f32 {
        self.min_rate
    }

    /// Cost of a straight step of `length` metres between two voxels.
    #[inline]
    pub fn step_cost(&self, from: usize, to: usize, length: f32) -> f32 {
        length * 0.5 * (self.rate(from) + self.rate(to))
    }

    /// Number of traversable voxels.
    pub fn traversable_count(&self) -> usize {
        self.traversable.iter().filter(|t| **t).count()
    }
}

/// Whether a voxel of this class and safety is blocked under `config`.
/// Whether a voxel of `class` and `safety` is blocked under `config` (occupied, ambiguous, free
/// with safety below the threshold, or unknown while unknown space is forbidden).
pub fn is_blocked(class: VoxelClass, safety: f32, config: &PlannerConfig) -> bool {
    match class {
        VoxelClass::Occupied | VoxelClass::Ambiguous => true,
        VoxelClass::Unknown => !matches!(config.unknown, UnknownPolicy::Cost(_)),
        VoxelClass::Free => safety < config.safety_threshold,
    }
}

/// Clearance in metres to the nearest blocked voxel, with everything outside the grid blocked.
fn clearance_in_metres(blocked: &[bool], dims: [usize; 3], size: f64) -> Vec<f32> {
    let [nx, ny, nz] = dims;
    let padded = [nx + 2, ny + 2, nz + 2];
    let mut grid = vec![true; padded[0] * padded[1] * padded[2]];
    for z in 0..nz {
        for y in 0..ny {
            let from = nx * (y + ny * z);
            let to = 1 + padded[0] * ((y + 1) + padded[1] * (z + 1));
            grid[to..to + nx].copy_from_slice(&blocked[from..from + nx]);
        }
    }
    let squared = squared_distance_transform(&grid, padded);
    let mut clearance = vec![0.0; nx * ny * nz];
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let p = (x + 1) + padded[0] * ((y + 1) + padded[1] * (z + 1));
                clearance[x + nx * (y + ny * z)] = (f64::from(squared[p]).sqrt() * size) as f32;
            }
        }
    }
    clearance
}
