use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::counts::VoxelCounts;
use super::{VoxelMap, VoxelMapMut};
use crate::error::{Error, Result, finite};
use crate::integrate::{
    BlockFlags, Checked, DepthFrame, IntegrationOptions, IntegrationStats, PointCloud, ScanLevels,
    ScanSets, check_octomap_scan, scan_groups, scan_sets, walk_scan,
};
use crate::measures::{MeasureConfig, Memberships, VoxelClass};
use crate::storage::{
    BLOCK_CELLS, Block, BlockGrid, BlockKey, CellBits, KeyBox, PackedGrid, Resolution, VoxelKey,
};

/// One log-odds cell: `ln(p / (1 - p))` of being occupied, NaN when never observed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogOdds(pub f32);

impl Default for LogOdds {
    fn default() -> Self {
        Self(f32::NAN)
    }
}

impl CellBits for LogOdds {
    #[inline]
    fn bits(&self) -> u64 {
        u64::from(self.0.to_bits())
    }
}

impl LogOdds {
    /// Whether any scan has updated this voxel.
    #[inline]
    pub fn is_observed(self) -> bool {
        !self.0.is_nan()
    }

    /// The occupancy probability, when observed.
    #[inline]
    pub fn probability(self) -> Option<f32> {
        self.is_observed().then(|| 1.0 / (1.0 + (-self.0).exp()))
    }

    /// The memberships every map reports: `μO = p`, `μE = 1 - p` when observed, both 0 when
    /// not.
    #[inline]
    pub fn memberships(self) -> Memberships {
        match self.probability() {
            Some(p) => Memberships {
                occupied: p,
                free: 1.0 - p,
            },
            None => Memberships::default(),
        }
    }
}

/// `ln(p / (1 - p))` computed as OctoMap does (in double precision, stored as `float`).
pub fn logodds(p: f64) -> f32 {
    (p / (1.0 - p)).ln() as f32
}

/// Parameters of the standard log-odds map; the defaults are OctoMap's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogOddsConfig {
    /// Voxel size.
    pub resolution: Resolution,
    /// Probability of a hit (0.7).
    pub prob_hit: f64,
    /// Probability of a miss (0.4).
    pub prob_miss: f64,
    /// Lower clamping probability (0.1192).
    pub clamp_min: f64,
    /// Upper clamping probability (0.971).
    pub clamp_max: f64,
    /// How measures and classes are computed from `μO = p`, `μE = 1 - p`; with the default
    /// thresholds a voxel is occupied exactly when `p > 0.5`.
    pub measures: MeasureConfig,
}

impl LogOddsConfig {
    /// OctoMap's defaults at `resolution` metres.
    pub fn new(resolution: f64) -> Result<Self> {
        Ok(Self {
            resolution: Resolution::new(resolution)?,
            prob_hit: 0.7,
            prob_miss: 0.4,
            clamp_min: 0.1192,
            clamp_max: 0.971,
            measures: MeasureConfig::default(),
        })
    }

    /// Checks every probability lies in `(0, 1)` and `clamp_min < clamp_max`.
    pub fn validate(self) -> Result<Self> {
        Resolution::new(self.resolution.size())?;
        for (name, value) in [
            ("prob_hit", self.prob_hit),
            ("prob_miss", self.prob_miss),
            ("clamp_min", self.clamp_min),
            ("clamp_max", self.clamp_max),
        ] {
            finite(name, value)?;
            if !(value > 0.0 && value < 1.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    expected: "a probability strictly between 0 and 1",
                });
            }
        }
        if self.clamp_min >= self.clamp_max {
            return Err(Error::InvalidParameter {
                name: "clamp_min",
                value: self.clamp_min,
                expected: "a lower clamp below clamp_max",
            });
        }
        self.measures.validate()?;
        Ok(self)
    }
}

/// The standard occupancy map with OctoMap's semantics: per scan, the voxels crossed by rays
/// (free) and the end-point voxels (hit; a voxel in both is hit) each get one update,
/// `+logit(prob_hit)` or `+logit(prob_miss)`, clamped to `[logit(clamp_min),
/// logit(clamp_max)]`. Rays are traversed exactly as OctoMap 1.9 traverses them, so on the same
/// scan the occupied and free voxel sets equal OctoMap's.
///
/// Confidence is ignored: that is what the standard method does. Depth images are inserted as
/// the point cloud of their `P0` depths, seen from the camera centre.
#[derive(Clone, Debug)]
pub struct LogOddsMap {
    config: LogOddsConfig,
    hit: f32,
    miss: f32,
    min: f32,
    max: f32,
    grid: PackedGrid<LogOdds>,
}

/// One cell's updates in a scan, shared by [`LogOddsMap::apply_sets`] and
/// [`LogOddsMap::apply_levels`].
#[derive(Clone, Copy)]
struct CellUpdates {
    hit: f32,
    miss: f32,
    min: f32,
    max: f32,
    measures: MeasureConfig,
}

impl CellUpdates {
    /// Gives cell `i` of `block` `hits` hit updates, then misses up to `total` updates, each an
    /// add then a clamp in single precision as OctoMap's `updateNodeLogOdds` does, and keeps the
    /// block's class counts current without reclassifying every cell. Returns whether the cell
    /// changed.
    #[inline(always)]
    fn apply(
        self,
        block: &mut Block<LogOdds>,
        classes: &mut ClassMemo,
        i: usize,
        hits: u16,
        total: u16,
    ) -> bool {
        let Some(cell) = block.cells.get_mut(i) else {
            return false;
        };
        let before = *cell;
        let mut current = if before.is_observed() { before.0 } else { 0.0 };
        for k in 1..=total {
            let update = if k <= hits { self.hit } else { self.miss };
            current = (current + update).clamp(self.min, self.max);
        }
        cell.0 = current;
        let from = classes.class(before, &self.measures);
        let to = classes.class(LogOdds(current), &self.measures);
        block.summary.moved(from, to);
        before.0.to_bits() != current.to_bits()
    }
}

/// The classes of the last few log-odds values classified: a scan gives most voxels of a block
/// one of a handful of values, so classification (an `exp` and the measures) runs once per
/// value rather than twice per update.
struct ClassMemo {
    entries: [(u32, VoxelClass); 8],
}

impl ClassMemo {
    fn new() -> Self {
        // NaN bits never come from an update, and unobserved cells are handled before the
        // table, so this placeholder never matches a real lookup with a wrong class.
        Self {
            entries: [(f32::NAN.to_bits() ^ 1, VoxelClass::Unknown); 8],
        }
    }

    #[inline]
    fn class(&mut self, value: LogOdds, measures: &MeasureConfig) -> VoxelClass {
        if !value.is_observed() {
            return VoxelClass::Unknown;
        }
        let bits = value.0.to_bits();
        let slot = ((bits ^ (bits >> 11) ^ (bits >> 19)) & 7) as usize;
        match self.entries[slot] {
            (cached, class) if cached == bits => class,
            _ => {
                let class = measures.classify(value.memberships());
                self.entries[slot] = (bits, class);
                class
            }
        }
    }
}

impl LogOddsMap {
    /// An empty map.
    pub fn new(config: LogOddsConfig) -> Result<Self> {
        let config = config.validate()?;
        Ok(Self::from_parts(config, BlockGrid::new()))
    }

    pub(crate) fn from_parts(config: LogOddsConfig, grid: BlockGrid<LogOdds>) -> Self {
        let measures = config.measures;
        let mut grid = PackedGrid::from_dense(&grid);
        grid.refresh_summaries(|c| measures.classify(c.memberships()));
        Self {
            hit: logodds(config.prob_hit),
            miss: logodds(config.prob_miss),
            min: logodds(config.clamp_min),
            max: logodds(config.clamp_max),
            config,
            grid,
        }
    }

    /// The map's configuration.
    pub fn config(&self) -> &LogOddsConfig {
        &self.config
    }

    /// The underlying block storage (read-only).
    pub fn grid(&self) -> &PackedGrid<LogOdds> {
        &self.grid
    }

    /// The log-odds cell at `key`.
    pub fn log_odds_at(&self, key: VoxelKey) -> LogOdds {
        self.grid.cell(key).unwrap_or_default()
    }

    /// The per-cell update that both appliers share.
    fn updates(&self) -> CellUpdates {
        CellUpdates {
            hit: self.hit,
            miss: self.miss,
            min: self.min,
            max: self.max,
            measures: self.config.measures,
        }
    }

    /// Applies one scan's sets: one clamped update per voxel. Returns the voxels updated.
    pub fn apply_sets(&mut self, sets: &ScanSets) -> usize {
        let updates = self.updates();
        self.grid
            .update_blocks(sets.blocks().collect(), |block, flags| {
                let (mut updated, mut changed) = (0, false);
                let mut classes = ClassMemo::new();
                for word in 0..flags.passed.len() {
                    let mut marked = flags.passed[word] | flags.hit[word];
                    while marked != 0 {
                        let bit = marked.trailing_zeros() as usize;
                        marked &= marked - 1;
                        let hit = flags.hit[word] & (1 << bit) != 0;
                        changed |=
                            updates.apply(block, &mut classes, word * 64 + bit, u16::from(hit), 1);
                        updated += 1;
                    }
                }
                (updated, changed)
            })
    }

    /// Applies a scan whose points carry levels as its nested cuts, cut 1 first: cut `k` is the
    /// scan of the points of level `k` and up (a voxel is hit in it when an end point of level
    /// `k` or more lies in it, else missed when such a ray passed through). Voxels do not
    /// interact, so each voxel takes its own run of updates (its hits, then its misses) and the
    /// map is bit for bit what applying the cuts' sets one after another gives, without
    /// building them. Returns the voxel updates summed over the cuts.
    pub fn apply_levels(&mut self, levels: &ScanLevels) -> usize {
        let updates = self.updates();
        self.grid
            .update_blocks(levels.blocks().collect(), |block, marks| {
                let (mut updated, mut changed) = (0, false);
                let mut classes = ClassMemo::new();
                for (i, (&passed, &hit)) in marks.passed.iter().zip(&marks.hit).enumerate() {
                    let cuts = passed.max(hit);
                    if cuts > 0 {
                        changed |= updates.apply(block, &mut classes, i, hit, cuts);
                        updated += usize::from(cuts);
                    }
                }
                (updated, changed)
            })
    }

    /// Integrates the points that `include` selects as one scan.
    pub(crate) fn integrate_selected(
        &mut self,
        cloud: &PointCloud,
        options: &IntegrationOptions,
        include: impl Fn(usize) -> bool + Sync,
    ) -> Result<IntegrationStats> {
        let (sets, mut stats) = scan_sets(cloud, &self.config.resolution, options, include)?;
        stats.voxels_updated = self.apply_sets(&sets);
        Ok(stats)
    }

    /// Voxel counts per class over the allocated blocks.
    pub fn counts(&self) -> VoxelCounts {
        VoxelCounts::of_packed(&self.grid)
    }

    /// Whether any voxel in `region` is of class `class` (voxels of unallocated blocks are
    /// unknown), answered from block summaries where possible.
    pub fn any_in_box(&self, region: &KeyBox, class: VoxelClass) -> bool {
        let measures = self.config.measures;
        self.grid
            .any_in_box(region, class, |c| measures.classify(c.memberships()))
    }

    /// Heap memory held by the map, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.grid.memory_bytes()
    }

    /// Changes the hit and miss log-odds (for the alpha-cut map's scaled probabilities).
    pub(crate) fn set_updates(&mut self, hit: f32, miss: f32) {
        self.hit = hit;
        self.miss = miss;
    }
}

impl VoxelMap for LogOddsMap {
    fn resolution(&self) -> Resolution {
        self.config.resolution
    }

    fn write_version(&self) -> Option<u64> {
        Some(self.grid.version())
    }

    fn changed_blocks_since(&self, version: u64) -> Option<Vec<BlockKey>> {
        Some(self.grid.changed_since(version))
    }

    fn measure_config(&self) -> &MeasureConfig {
        &self.config.measures
    }

    fn memberships_at(&self, key: VoxelKey) -> Memberships {
        self.log_odds_at(key).memberships()
    }

    fn block_memberships(&self, key: BlockKey, out: &mut [Memberships; BLOCK_CELLS]) {
        match self.grid.block(key) {
            Some(block) => {
                for (m, cell) in out.iter_mut().zip(block.iter()) {
                    *m = cell.memberships();
                }
            }
            None => out.fill(LogOdds::default().memberships()),
        }
    }

    fn block_stamps(&self, key: BlockKey, out: &mut [u64; BLOCK_CELLS]) -> bool {
        match self.grid.block(key) {
            Some(block) => {
                for (stamp, cell) in out.iter_mut().zip(block.iter()) {
                    *stamp = u64::from(cell.0.to_bits());
                }
            }
            None => out.fill(u64::from(LogOdds::default().0.to_bits())),
        }
        true
    }

    fn memberships_of_stamps(&self, stamps: &[u64], out: &mut [Memberships]) {
        for (m, stamp) in out.iter_mut().zip(stamps) {
            *m = LogOdds(f32::from_bits(*stamp as u32)).memberships();
        }
    }

    fn counts(&self) -> VoxelCounts {
        LogOddsMap::counts(self)
    }

    fn any_in_box(&self, region: &KeyBox, class: VoxelClass) -> bool {
        LogOddsMap::any_in_box(self, region, class)
    }

    fn memory_bytes(&self) -> usize {
        LogOddsMap::memory_bytes(self)
    }

    fn cells(&self) -> Box<dyn Iterator<Item = (VoxelKey, Memberships)> + '_> {
        Box::new(
            self.grid
                .cells()
                .filter(|(_, c)| c.is_observed())
                .map(|(k, c)| (k, c.memberships())),
        )
    }
}

impl VoxelMapMut for LogOddsMap {
    fn integrate_cloud(
        &mut self,
        cloud: &PointCloud,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats> {
        self.integrate_selected(cloud, options, |_| true)
    }

    fn integrate_clouds(
        &mut self,
        clouds: &[PointCloud],
        options: &IntegrationOptions,
    ) -> Result<Vec<IntegrationStats>> {
        let resolution = self.config.resolution;
        check_scans(clouds, |c| check_octomap_scan(c, &resolution, options))?;
        let mut all = Vec::with_capacity(clouds.len());
        for group in scan_groups(clouds, SETS_GROUP_POINTS) {
            let walked = group
                .par_iter()
                .map(|c| walk_scan::<BlockFlags>(c, &resolution, options, Checked::Yes, |_| 1))
                .collect::<Result<Vec<_>>>()?;
            for (sets, mut stats) in walked {
                stats.voxels_updated = self.apply_sets(&sets);
                all.push(stats);
            }
        }
        Ok(all)
    }

    fn integrate_depth(
        &mut self,
        frame: &DepthFrame,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats> {
        self.integrate_cloud(&frame.to_cloud()?, options)
    }
}

/// Most points in a group of scans walked side by side (their sets are two bits per voxel).
pub(crate) const SETS_GROUP_POINTS: usize = 1 << 20;

/// Runs `check` on every scan, in parallel, and returns the first scan's error in order.
pub(crate) fn check_scans(
    clouds: &[PointCloud],
    check: impl Fn(&PointCloud) -> Result<()> + Sync,
) -> Result<()> {
    let checks: Vec<Result<()>> = clouds.par_iter().map(&check).collect();
    checks.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn octomap_default_log_odds() {
        assert!((logodds(0.7) - 0.847_298).abs() < 1e-6);
        assert!((logodds(0.4) + 0.405_465).abs() < 1e-6);
        assert!((logodds(0.971) - 3.511_031).abs() < 1e-5);
        assert!((logodds(0.1192) + 2.000_028).abs() < 1e-5);
    }

    #[test]
    fn one_scan_marks_hits_and_misses_and_clamps_over_many() {
        let mut map = LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap();
        let end = Point3::new(1.05, 0.05, 0.05);
        let cloud = PointCloud::new(Point3::new(0.05, 0.05, 0.05), vec![end]).unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        let r = map.resolution();
        assert_eq!(map.log_odds_at(r.key_of(&end).unwrap()).0, logodds(0.7));
        let before = r.key_of(&Point3::new(0.55, 0.05, 0.05)).unwrap();
        assert_eq!(map.log_odds_at(before).0, logodds(0.4));
        assert!(
            !map.log_odds_at(r.key_of(&Point3::new(2.0, 0.0, 0.0)).unwrap())
                .is_observed()
        );
        for _ in 0..20 {
            map.integrate_cloud(&cloud, &IntegrationOptions::default())
                .unwrap();
        }
        assert_eq!(map.log_odds_at(r.key_of(&end).unwrap()).0, logodds(0.971));
        assert_eq!(map.log_odds_at(before).0, logodds(0.1192));
        let counts = map.counts();
        assert_eq!(counts.occupied, 1);
        assert_eq!(counts.free, 10);
    }
}
