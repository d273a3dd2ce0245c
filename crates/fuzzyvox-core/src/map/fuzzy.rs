use rayon::prelude::*;

use super::config::FuzzyConfig;
use super::counts::VoxelCounts;
use super::levels::{Accumulator, Levels};
use super::logodds::check_scans;
use super::{VoxelMap, VoxelMapMut};
use crate::error::{Error, Result};
use crate::integrate::{
    BlockFlags, Checked, CloudScan, DepthFrame, Evidence, IntegrationOptions, IntegrationStats,
    PointCloud, ScanEvidence, check_cloud, cloud_scan_checked, depth_evidence, scan_groups,
};
use crate::measures::{MeasureConfig, Memberships, VoxelClass};
use crate::ops::TConorm;
use crate::storage::{
    BLOCK_CELLS, Block, BlockGrid, BlockKey, KeyBox, PackedGrid, Resolution, VoxelKey,
};

/// One block of a [`CloudScan::Uniform`]: its occupied evidence and its cleared voxels, each
/// when the scan reached the block.
struct UniformSource<'a> {
    occupied: Option<&'a Block<Evidence>>,
    passed: Option<&'a BlockFlags>,
}

/// Applies `S` between a cell and the evidence `(o, e)`; whether the cell received any.
#[inline(always)]
fn fold_cell(acc: &Accumulator, cell: &mut Levels, memo: &mut LevelMemo, o: f32, e: f32) -> bool {
    if o <= 0.0 && e <= 0.0 {
        return false;
    }
    if o > 0.0 {
        cell.occupied = acc.accumulate_level(cell.occupied, memo.level(acc, o));
    }
    if e > 0.0 {
        cell.free = acc.accumulate_level(cell.free, memo.level(acc, e));
    }
    true
}

/// The dual-set fuzzy map: two independent membership degrees per voxel, how occupied (μO)
/// and how free (μE), each aggregated from evidence with a t-conorm `S`:
/// `μO ← S(μO, o)`, `μE ← S(μE, e)`.
///
/// Because every t-conorm is commutative and associative, the map does not depend on the order
/// of observations, and two maps of the same area [`merge`](FuzzyMap::merge) exactly: the map
/// stores each membership as a fixed-point level of the t-conorm's generator
/// ([`Accumulator`]), so the same observations give the same map bit for bit, whatever their
/// order, however they are split into merged partial maps and on any number of threads.
///
/// ```
/// use fuzzyvox_core::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelClass, VoxelMap, VoxelMapMut};
/// use nalgebra::Point3;
///
/// let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
/// let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(2.0, 0.05, 0.05)])?;
/// map.integrate_cloud(&cloud, &IntegrationOptions::default())?;
/// assert_eq!(map.class_at_point(&Point3::new(2.0, 0.05, 0.05))?, VoxelClass::Occupied);
/// assert_eq!(map.class_at_point(&Point3::new(1.0, 0.05, 0.05))?, VoxelClass::Free);
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct FuzzyMap {
    config: FuzzyConfig,
    accumulator: Accumulator,
    grid: PackedGrid<Levels>,
}

impl FuzzyMap {
    /// An empty map.
    pub fn new(config: FuzzyConfig) -> Result<Self> {
        let config = config.validate()?;
        Ok(Self {
            accumulator: Accumulator::new(config.operator),
            config,
            grid: PackedGrid::new(),
        })
    }

    /// The map's configuration.
    pub fn config(&self) -> &FuzzyConfig {
        &self.config
    }

    /// The aggregation operator.
    pub fn operator(&self) -> TConorm {
        self.config.operator
    }

    /// How the map stores and accumulates memberships (levels of the operator's generator).
    pub fn accumulator(&self) -> &Accumulator {
        &self.accumulator
    }

    /// The underlying block storage (read-only): each voxel's [`Levels`], which
    /// [`Accumulator::memberships`] reads as memberships.
    pub fn grid(&self) -> &PackedGrid<Levels> {
        &self.grid
    }

    /// Folds one scan's evidence into the map: one `S` per voxel and membership. Returns the
    /// number of voxels that received evidence.
    ///
    /// Within one scan a voxel that holds an end point is not also cleared by the rays that
    /// graze it: the scan's free evidence is "free and not occupied", `e · (1 - o)` (product
    /// t-norm with the standard complement). This is the fuzzy form of OctoMap's rule that a
    /// voxel both hit and passed in one scan counts as hit; conflict between *different* scans
    /// still shows as ambiguity.
    pub fn apply_evidence(&mut self, evidence: &ScanEvidence) -> usize {
        self.fold(evidence, |e: &Evidence| {
            (e.occupied, e.free * (1.0 - e.occupied))
        })
    }

    /// Folds one scan of a cloud into the map, as [`FuzzyMap::apply_evidence`] folds the
    /// same scan's evidence.
    fn apply_scan(&mut self, scan: &CloudScan) -> usize {
        let (occupied, passed, free) = match scan {
            CloudScan::Evidence(evidence) => return self.apply_evidence(evidence),
            CloudScan::Uniform {
                occupied,
                passed,
                free,
            } => (occupied, passed, *free),
        };
        // One source per block that either part reached, so that the blocks are allocated
        // and written exactly as by the scan's evidence.
        let both = occupied.blocks().map(|(key, block)| {
            let source = UniformSource {
                occupied: Some(block),
                passed: passed.block(key),
            };
            (key, source)
        });
        let passed_only = passed
            .blocks()
            .filter(|(key, _)| occupied.block(*key).is_none())
            .map(|(key, flags)| {
                let source = UniformSource {
                    occupied: None,
                    passed: Some(flags),
                };
                (key, source)
            });
        let sources: Vec<(BlockKey, UniformSource<'_>)> = both.chain(passed_only).collect();
        let acc = self.accumulator;
        let sources = sources.iter().map(|(key, s)| (*key, s)).collect();
        self.update_cells(sources, |cell, s: &UniformSource<'_>, i, memo| {
            let o = s.occupied.map_or(0.0, |b| b.cells[i].occupied);
            let e = if s.passed.is_some_and(|f| f.get(i).0) {
                free
            } else {
                0.0
            };
            // As `apply_evidence`: free and not occupied.
            fold_cell(&acc, cell, memo, o, e * (1.0 - o))
        })
    }

    /// Merges another map of the same resolution and operator into this one, cell by cell with
    /// `S`. The result equals inserting both maps' observations into one map, in any order.
    pub fn merge(&mut self, other: &FuzzyMap) -> Result<()> {
        if self.config.resolution != other.config.resolution {
            return Err(Error::Incompatible(format!(
                "resolutions differ ({} m and {} m)",
                self.config.resolution.size(),
                other.config.resolution.size()
            )));
        }
        if self.config.operator != other.config.operator {
            return Err(Error::Incompatible(format!(
                "operators differ ({} and {})",
                self.config.operator.family(),
                other.config.operator.family()
            )));
        }
        let acc = self.accumulator;
        let blocks: Vec<(BlockKey, Block<Levels>)> = other
            .grid
            .blocks()
            .map(|(key, block)| (key, block.unpack()))
            .collect();
        let sources = blocks.iter().map(|(key, block)| (*key, block)).collect();
        self.update(sources, |cell, s: &Levels, _| {
            if *s == Levels::default() {
                return false;
            }
            cell.occupied = acc.combine(cell.occupied, s.occupied);
            cell.free = acc.combine(cell.free, s.free);
            true
        });
        Ok(())
    }

    /// Applies `S` between every cell and the evidence `(o, e)` of the matching cell of
    /// `source`, in parallel over blocks (see [`BlockGrid::update_from`]).
    pub(super) fn fold<C: Copy + Default + Sync>(
        &mut self,
        source: &BlockGrid<C>,
        evidence_of: impl Fn(&C) -> (f32, f32) + Sync,
    ) -> usize {
        let acc = self.accumulator;
        self.update(source.blocks().collect(), |cell, s, memo| {
            let (o, e) = evidence_of(s);
            fold_cell(&acc, cell, memo, o, e)
        })
    }

    /// Updates every cell with the matching cell of `source` (`update` says whether the cell
    /// received anything), in parallel over blocks, keeping the blocks' class counts current
    /// and marking only blocks whose levels changed. Returns the number of cells updated.
    fn update<C: Copy + Default + Sync>(
        &mut self,
        sources: Vec<(BlockKey, &Block<C>)>,
        update: impl Fn(&mut Levels, &C, &mut LevelMemo) -> bool + Sync,
    ) -> usize {
        self.update_cells(sources, |cell, source: &Block<C>, i, memo| {
            update(cell, &source.cells[i], memo)
        })
    }

    /// [`FuzzyMap::update`] from any per-block source: `update` reads cell `i` of its
    /// block's source itself.
    fn update_cells<S: Sync>(
        &mut self,
        sources: Vec<(BlockKey, &S)>,
        update: impl Fn(&mut Levels, &S, usize, &mut LevelMemo) -> bool + Sync,
    ) -> usize {
        let acc = self.accumulator;
        let measures = self.config.measures;
        self.grid.update_blocks(sources, |block, source| {
            let mut updated = 0;
            let mut changed = false;
            // Cells of a block often hold the same levels (space a scan cleared once): classify
            // each distinct pair once in a row.
            let mut classes = ClassMemo::new(&acc, &measures);
            let mut levels = LevelMemo::default();
            for (i, cell) in block.cells.iter_mut().enumerate() {
                let before = *cell;
                if !update(cell, source, i, &mut levels) {
                    continue;
                }
                updated += 1;
                if *cell != before {
                    changed = true;
                    // Keep the block's class counts current without reclassifying every cell.
                    let from = classes.of(before);
                    block.summary.moved(from, classes.of(*cell));
                }
            }
            (updated, changed)
        })
    }

    /// Voxel counts per class over the allocated blocks, from the block summaries.
    pub fn counts(&self) -> VoxelCounts {
        VoxelCounts::of_packed(&self.grid)
    }

    /// Whether any voxel in `region` is of class `class` (voxels of unallocated blocks are
    /// unknown), answered from block summaries where possible.
    pub fn any_in_box(&self, region: &KeyBox, class: VoxelClass) -> bool {
        let (acc, measures) = (self.accumulator, self.config.measures);
        self.grid
            .any_in_box(region, class, |l| measures.classify(acc.memberships(*l)))
    }

    /// Heap memory held by the map, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.grid.memory_bytes()
    }

    /// Rebuilds a map from its configuration and storage (used by the file reader, which has
    /// validated both).
    pub(crate) fn from_parts(config: FuzzyConfig, grid: BlockGrid<Levels>) -> Self {
        let (acc, measures) = (Accumulator::new(config.operator), config.measures);
        let mut grid = PackedGrid::from_dense(&grid);
        grid.refresh_summaries(|l| measures.classify(acc.memberships(*l)));
        Self {
            config,
            accumulator: acc,
            grid,
        }
    }
}

/// Most points in a group of scans walked side by side (each scan's evidence holds two `f32`
/// per voxel its rays reach, so groups stay smaller than the log-odds map's).
const EVIDENCE_GROUP_POINTS: usize = 1 << 18;

/// The level of the last evidence value seen (a scan gives many voxels of a block the same
/// evidence), computed again only for another value.
#[derive(Default)]
struct LevelMemo {
    last: Option<(u32, u32)>,
}

impl LevelMemo {
    #[inline]
    fn level(&mut self, acc: &Accumulator, evidence: f32) -> u32 {
        let bits = evidence.to_bits();
        match self.last {
            Some((seen, level)) if seen == bits => level,
            _ => {
                let level = acc.evidence_level(evidence);
                self.last = Some((bits, level));
                level
            }
        }
    }
}

/// The classes of the last two level pairs seen: `measures.classify` of their memberships,
/// decoded only for a pair not seen just before.
struct ClassMemo<'a> {
    acc: &'a Accumulator,
    measures: &'a MeasureConfig,
    recent: [Option<(Levels, VoxelClass)>; 2],
}

impl<'a> ClassMemo<'a> {
    fn new(acc: &'a Accumulator, measures: &'a MeasureConfig) -> Self {
        Self {
            acc,
            measures,
            recent: [None; 2],
        }
    }

    #[inline]
    fn of(&mut self, levels: Levels) -> VoxelClass {
        for (seen, class) in self.recent.iter().flatten() {
            if *seen == levels {
                return *class;
            }
        }
        let class = self.measures.classify(self.acc.memberships(levels));
        self.recent = [Some((levels, class)), self.recent[0]];
        class
    }
}

impl VoxelMap for FuzzyMap {
    fn counts(&self) -> VoxelCounts {
        FuzzyMap::counts(self)
    }

    fn any_in_box(&self, region: &KeyBox, class: VoxelClass) -> bool {
        FuzzyMap::any_in_box(self, region, class)
    }

    fn memory_bytes(&self) -> usize {
        FuzzyMap::memory_bytes(self)
    }

    fn cells(&self) -> Box<dyn Iterator<Item = (VoxelKey, Memberships)> + '_> {
        let acc = self.accumulator;
        Box::new(
            self.grid
                .cells()
                .filter(|(_, l)| *l != Levels::default())
                .map(move |(k, l)| (k, acc.memberships(l))),
        )
    }

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
        self.grid
            .cell(key)
            .map_or_else(Memberships::default, |l| self.accumulator.memberships(l))
    }

    fn block_memberships(&self, key: BlockKey, out: &mut [Memberships; BLOCK_CELLS]) {
        match self.grid.block(key) {
            Some(block) => self
                .accumulator
                .memberships_into(&block.unpack().cells, out),
            None => out.fill(Memberships::default()),
        }
    }

    fn block_stamps(&self, key: BlockKey, out: &mut [u64; BLOCK_CELLS]) -> bool {
        match self.grid.block(key) {
            Some(block) => {
                for (stamp, levels) in out.iter_mut().zip(block.iter()) {
                    *stamp = levels.packed();
                }
            }
            None => out.fill(Levels::default().packed()),
        }
        true
    }

    fn memberships_of_stamps(&self, stamps: &[u64], out: &mut [Memberships]) {
        for (m, stamp) in out.iter_mut().zip(stamps) {
            *m = self.accumulator.memberships(Levels::unpacked(*stamp));
        }
    }
}

impl VoxelMapMut for FuzzyMap {
    fn integrate_cloud(
        &mut self,
        cloud: &PointCloud,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats> {
        let c = &self.config;
        let (scan, mut stats) = cloud_scan_checked(
            cloud,
            &c.resolution,
            &c.evidence,
            &c.operator,
            options,
            Checked::No,
        )?;
        stats.voxels_updated = self.apply_scan(&scan);
        Ok(stats)
    }

    fn integrate_clouds(
        &mut self,
        clouds: &[PointCloud],
        options: &IntegrationOptions,
    ) -> Result<Vec<IntegrationStats>> {
        let c = self.config;
        check_scans(clouds, |cloud| check_cloud(cloud, &c.resolution, options))?;
        let mut all = Vec::with_capacity(clouds.len());
        for group in scan_groups(clouds, EVIDENCE_GROUP_POINTS) {
            let evidence = group
                .par_iter()
                .map(|cloud| {
                    cloud_scan_checked(
                        cloud,
                        &c.resolution,
                        &c.evidence,
                        &c.operator,
                        options,
                        Checked::Yes,
                    )
                })
                .collect::<Result<Vec<_>>>()?;
            for (scan, mut stats) in evidence {
                stats.voxels_updated = self.apply_scan(&scan);
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
        let c = &self.config;
        let (evidence, mut stats) =
            depth_evidence(frame, &c.resolution, &c.evidence, &c.operator, options)?;
        stats.voxels_updated = self.apply_evidence(&evidence);
        Ok(stats)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{EvidenceModel, cloud_evidence};
    use nalgebra::Point3;

    /// Points around `origin` at 0.3-25 m, a few of them not finite.
    fn cloud(origin: Point3<f64>, n: usize, seed: u64) -> PointCloud {
        let mut state = seed;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        };
        let points = (0..n)
            .map(|i| {
                if i % 97 == 13 {
                    return Point3::new(f64::NAN, 0.0, 1.0);
                }
                let (a, b, r) = (
                    next() * std::f64::consts::TAU,
                    next() * 2.0 - 1.0,
                    0.3 + next() * 24.7,
                );
                let h = (1.0 - b * b).sqrt();
                origin + nalgebra::Vector3::new(h * a.cos(), h * a.sin(), b) * r
            })
            .collect();
        PointCloud::new(origin, points).unwrap()
    }

    /// Whether `scan` takes the bit-recorded path.
    fn is_uniform(scan: &PointCloud, c: &FuzzyConfig, options: &IntegrationOptions) -> bool {
        let (form, _) = cloud_scan_checked(
            scan,
            &c.resolution,
            &c.evidence,
            &c.operator,
            options,
            Checked::No,
        )
        .unwrap();
        matches!(form, CloudScan::Uniform { .. })
    }

    /// A cloud whose points share one weight is folded from bits for its cleared voxels; the
    /// map equals, byte for byte, the map folded from the same scan's evidence, with and without
    /// a maximum range (rays cut there only clear), for confident, clearing-only and
    /// marking-only weights, under two operators.
    #[test]
    fn uniform_clouds_give_the_maps_of_their_evidence() {
        let weights: [(Option<f32>, Option<f32>); 4] = [
            (None, None),
            (Some(0.6), None),
            (Some(0.0), Some(0.8)),
            (Some(0.5), Some(0.0)),
        ];
        for family in [crate::ops::Family::Product, crate::ops::Family::Minimum] {
            let operator = TConorm::new(family).unwrap();
            for (confidence, reliability) in weights {
                for max_range in [None, Some(8.0)] {
                    let config = FuzzyConfig {
                        operator,
                        ..FuzzyConfig::new(0.1).unwrap()
                    }
                    .with_evidence(EvidenceModel::dual());
                    let options = IntegrationOptions { max_range };
                    let mut fast = FuzzyMap::new(config).unwrap();
                    let mut reference = FuzzyMap::new(config).unwrap();
                    for (k, origin) in [Point3::new(0.0, 0.0, 0.0), Point3::new(1.3, -0.4, 0.2)]
                        .into_iter()
                        .enumerate()
                    {
                        let mut scan = cloud(origin, 3000, 7 + k as u64);
                        let n = scan.len();
                        if let Some(c) = confidence {
                            scan = scan.with_confidence(vec![c; n]).unwrap();
                        }
                        if let Some(r) = reliability {
                            scan = scan.with_reliability(vec![r; n]).unwrap();
                        }
                        let c = &config;
                        assert!(is_uniform(&scan, c, &options));
                        let a = fast.integrate_cloud(&scan, &options).unwrap();
                        let (evidence, b) = cloud_evidence(
                            &scan,
                            &c.resolution,
                            &c.evidence,
                            &c.operator,
                            &options,
                        )
                        .unwrap();
                        let updated = reference.apply_evidence(&evidence);
                        assert_eq!(a.voxels_updated, updated);
                        assert_eq!(
                            (a.integrated, a.skipped, a.clipped),
                            (b.integrated, b.skipped, b.clipped)
                        );
                    }
                    // Each weight gives what it should: occupied evidence from a confidence,
                    // free evidence from a reliability.
                    let seen = |f: fn(&Memberships) -> f32| {
                        VoxelMap::cells(&fast).filter(|(_, m)| f(m) > 0.0).count()
                    };
                    assert_eq!(seen(|m| m.occupied) > 0, confidence != Some(0.0));
                    assert_eq!(seen(|m| m.free) > 0, reliability != Some(0.0));
                    assert_eq!(fast.to_bytes(), reference.to_bytes());
                }
            }
        }
    }

    /// Points of different weights keep the per-voxel evidence.
    #[test]
    fn clouds_of_mixed_weights_keep_their_evidence() {
        let config = FuzzyConfig::new(0.1).unwrap();
        let scan = cloud(Point3::origin(), 500, 3);
        let n = scan.len();
        let scan = scan
            .with_confidence((0..n).map(|i| (i % 5) as f32 / 4.0).collect())
            .unwrap();
        assert!(!is_uniform(&scan, &config, &IntegrationOptions::default()));
    }
}
