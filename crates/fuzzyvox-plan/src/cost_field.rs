use nalgebra::Point3;

use super::blocker::{Blocker, NearestBlocked};
use super::config::{PlannerConfig, UnknownPolicy};
use super::edt::squared_distance_transform;
use super::field_update::block_parts;
use super::least_rate::LeastRate;
use crate::error::{Error, Result};
use crate::map::VoxelMap;
use crate::measures::VoxelClass;
use crate::storage::{BLOCK_CELLS, BlockKey, Resolution, VoxelKey};

/// Largest planning region, in voxels (a guard against absurd requests: 64 Mi voxels use about
/// 1.5 GiB of working memory, 24 bytes a voxel with the map's stamps).
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

    /// The dense index of the voxel at region coordinates `[x, y, z]` (each from 0 to its
    /// dimension, unchecked).
    #[inline]
    pub fn index_at(&self, [x, y, z]: [i64; 3]) -> usize {
        let [nx, ny, _] = self.dims.map(|d| d as i64);
        (x + nx * (y + ny * z)) as usize
    }

    /// The region coordinates `[x, y, z]` of a dense index.
    #[inline]
    pub fn coordinates_at(&self, index: usize) -> [i64; 3] {
        let [nx, ny, _] = self.dims;
        [index % nx, (index / nx) % ny, index / (nx * ny)].map(|c| c as i64)
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
///   voxel centre, up to [`CostField::clearance_cap`] (the larger of the required and the
///   preferred clearance; larger distances read as the cap, which changes no decision).
/// - A voxel is **traversable** when it is not blocked and its clearance is at least the vehicle
///   radius plus `√3 × resolution`. That margin covers half a blocked voxel and half a step, so
///   every point of a path whose steps join traversable voxels (or whose straight segments only
///   cross traversable voxels) keeps the vehicle radius from every blocked voxel.
/// - Entering a voxel costs, per metre, `1 + k (1 - S) + w max(0, 1 - clearance / preferred)`
///   (plus the unknown cost for unknown voxels under [`UnknownPolicy::Cost`]); a step of length
///   `l` between voxels costs `l` times the mean of their two rates, never less than `l`.
#[derive(Clone, Debug, PartialEq)]
pub struct CostField {
    region: PlanningRegion,
    resolution: Resolution,
    config: PlannerConfig,
    /// Per voxel, dense index order (x fastest). One record per voxel rather than one array
    /// per entry: an update reads and writes a voxel's entries together, one cache line.
    pub(super) voxels: Vec<Voxel>,
    /// Per voxel, the stamp it was read with ([`VoxelMap::block_stamps`]), when the map keeps
    /// stamps: an update decodes only the voxels whose stamp changed.
    pub(super) stamps: Option<Vec<u64>>,
    /// The least rate of any voxel, kept as voxels change.
    pub(super) least: LeastRate,
}

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
    /// [`CostField::required_clearance`].
    required: f32,
    /// The preferred clearance (never 0).
    preferred: f32,
}

impl Rules {
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
    const UNKNOWN: Self = Self {
        safety: 0.0,
        clearance: 0.0,
        rate: f32::INFINITY,
        class: VoxelClass::Unknown,
        traversable: false,
    };
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
        let stamped = map.block_stamps(region.min().block(), &mut [0; BLOCK_CELLS]);
        let mut field = Self {
            region,
            resolution,
            config,
            voxels: vec![Voxel::UNKNOWN; n],
            stamps: stamped.then(|| vec![0; n]),
            least: LeastRate::scan::<f32>(&[], |r| *r),
        };
        // Every voxel of the region lies in one of the blocks of its box.
        let (lo, hi) = (region.min().block(), region.key_at(n - 1).block());
        let blocks = (lo.z..=hi.z).flat_map(|z| {
            (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| BlockKey::new(x, y, z)))
        });
        field.fill(map, &block_parts(&region, blocks));
        let whole = region.dims().map(|d| 0..d as i64);
        field.recompute_clearance(&whole);
        let rules = field.rules();
        for v in &mut field.voxels {
            (v.traversable, v.rate) = rules.entry(v.class, v.safety, v.clearance);
        }
        field.rescan_least_rate();
        Ok(field)
    }

    /// The clearance the vehicle needs: its radius plus `√3 × resolution`.
    pub fn required_clearance(&self) -> f64 {
        self.config.vehicle_radius + 3f64.sqrt() * self.resolution.size()
    }

    /// The largest clearance the field tells apart: the required or the preferred clearance,
    /// whichever is larger. Nothing the planner decides changes beyond it (a voxel that far
    /// from every blocked voxel is traversable and pays no clearance penalty), so clearances
    /// are exact up to this value and reported as this value beyond it; that keeps the effect
    /// of a changed voxel within this distance, which [`CostField::update`] relies on.
    pub fn clearance_cap(&self) -> f64 {
        self.required_clearance()
            .max(self.config.preferred_clearance)
    }

    /// Whole voxels within [`CostField::clearance_cap`] along one axis.
    pub(super) fn reach(&self) -> i64 {
        (self.clearance_cap() / self.resolution.size()).ceil() as i64
    }

    /// Recomputes the clearance of the voxels of `target` (ranges of region coordinates along
    /// x, y, z) from the current blocked voxels: an exact distance transform over `target`
    /// grown by [`CostField::reach`] on every side (space outside the region blocked), which
    /// holds every blocked voxel within the cap of any voxel of `target`. Distances are whole
    /// squared voxel counts, so the result does not depend on the box: a full build and an
    /// update give the same bits.
    pub(super) fn recompute_clearance(&mut self, target: &[std::ops::Range<i64>; 3]) {
        let dims = self.region.dims().map(|d| d as i64);
        let reach = self.reach();
        // The context box, in region coordinates; -1 and `dims` are the blocked ring outside.
        let context: [std::ops::Range<i64>; 3] = std::array::from_fn(|a| {
            (target[a].start - reach).max(-1)..(target[a].end + reach).min(dims[a] + 1)
        });
        let size = context.clone().map(|r| (r.end - r.start) as usize);
        let mut grid = Vec::with_capacity(size[0] * size[1] * size[2]);
        for z in context[2].clone() {
            for y in context[1].clone() {
                for x in context[0].clone() {
                    let inside =
                        x >= 0 && y >= 0 && z >= 0 && x < dims[0] && y < dims[1] && z < dims[2];
                    grid.push(
                        !inside || {
                            let v = &self.voxels[self.region.index_at([x, y, z])];
                            is_blocked(v.class, v.safety, &self.config)
                        },
                    );
                }
            }
        }
        let squared = squared_distance_transform(&grid, size);
        let (voxel, cap) = (self.resolution.size(), self.clearance_cap());
        for z in target[2].clone() {
            for y in target[1].clone() {
                for x in target[0].clone() {
                    let c = (x - context[0].start)
                        + size[0] as i64
                            * ((y - context[1].start) + size[1] as i64 * (z - context[2].start));
                    let i = self.region.index_at([x, y, z]);
                    self.voxels[i].clearance =
                        (f64::from(squared[c as usize]).sqrt() * voxel).min(cap) as f32;
                }
            }
        }
    }

    /// Sets whether the voxel at `index` is traversable and its rate under `rules` (the
    /// field's own, [`CostField::rules`]), from its class, safety and clearance, keeping the
    /// least rate.
    #[inline]
    pub(super) fn derive(&mut self, i: usize, rules: &Rules) {
        let v = self.voxels[i];
        let (traversable, rate) = rules.entry(v.class, v.safety, v.clearance);
        self.least.replace(v.rate, rate);
        (self.voxels[i].traversable, self.voxels[i].rate) = (traversable, rate);
    }

    /// The rules that give a voxel's traversability and rate.
    pub(super) fn rules(&self) -> Rules {
        Rules {
            config: self.config,
            required: self.required_clearance() as f32,
            preferred: self.config.preferred_clearance.max(1e-9) as f32,
        }
    }

    /// Finds the least rate again by scanning every voxel.
    pub(super) fn rescan_least_rate(&mut self) {
        self.least = LeastRate::scan(&self.voxels, |v| v.rate);
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
        self.voxels.get(index).is_some_and(|v| v.traversable)
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
        self.voxels
            .get(index)
            .map_or(VoxelClass::Unknown, |v| v.class)
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
            required: self.required_clearance(),
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
        self.voxels.get(index).map_or(0.0, |v| v.safety)
    }

    /// Clearance (metres) of the voxel at a dense index.
    pub fn clearance(&self, index: usize) -> f32 {
        self.voxels.get(index).map_or(0.0, |v| v.clearance)
    }

    /// Cost per metre of entering the voxel at a dense index (infinite when not traversable).
    #[inline]
    pub fn rate(&self, index: usize) -> f32 {
        self.voxels.get(index).map_or(f32::INFINITY, |v| v.rate)
    }

    /// The lowest cost per metre of any traversable voxel (at least 1): every step of length `l`
    /// costs at least `l × min_rate`, which keeps A*'s distance heuristic consistent and tight.
    pub fn min_rate(&self) -> f32 {
        self.least.value().max(1.0)
    }

    /// Cost of a straight step of `length` metres between two voxels.
    #[inline]
    pub fn step_cost(&self, from: usize, to: usize, length: f32) -> f32 {
        length * 0.5 * (self.rate(from) + self.rate(to))
    }

    /// Number of traversable voxels.
    pub fn traversable_count(&self) -> usize {
        self.voxels.iter().filter(|v| v.traversable).count()
    }
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
