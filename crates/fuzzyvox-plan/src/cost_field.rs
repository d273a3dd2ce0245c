//! The cost field: a planning region of a map turned into what a planner needs per voxel,
//! built in full from any map (kept current by [`CostField::update`]).

use fuzzyvox_core::error::Result;
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_core::storage::{BLOCK_CELLS, BlockKey, Resolution, VoxelKey};
use rayon::prelude::*;

use crate::blocker::{Blocker, NearestBlocked};
use crate::config::PlannerConfig;
use crate::edt::squared_distance_transform;
use crate::layers::{Scratch, VoxelBox, block_parts, layers};
use crate::least_rate::LeastRate;
use crate::region::PlanningRegion;
use crate::rules::{Rules, Voxel, is_blocked};

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
///   (plus the unknown cost for unknown voxels under [`UnknownPolicy::Cost`](crate::UnknownPolicy::Cost)); a step of length
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

    /// Reads the class, safety and stamp of every voxel of `parts` (blocks sorted by
    /// [`block_parts`]) into the field, in place and in parallel by layers of blocks; the rest
    /// of each voxel's entries are left for the caller to derive.
    fn fill(&mut self, map: &dyn VoxelMap, parts: &[(BlockKey, VoxelBox)]) {
        let (region, measures) = (*self.region(), *map.measure_config());
        layers(&region, &mut self.voxels, self.stamps.as_deref_mut(), parts)
            .into_par_iter()
            .for_each_init(Scratch::new, |scratch, layer| {
                layer.fill(map, &region, &measures, scratch)
            });
    }

    /// The rules that give a voxel's traversability and rate.
    pub(super) fn rules(&self) -> Rules {
        Rules::new(
            self.config,
            self.required_clearance() as f32,
            self.config.preferred_clearance.max(1e-9) as f32,
        )
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

    /// The rates of `len` voxels from dense index `first` on (a row of the region along x).
    pub(crate) fn rates_of_row(&self, first: usize, len: usize) -> impl Iterator<Item = f32> + '_ {
        self.voxels[first..first + len].iter().map(|v| v.rate)
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
