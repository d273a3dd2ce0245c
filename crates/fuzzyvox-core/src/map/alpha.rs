use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::counts::VoxelCounts;
use super::logodds::{LogOddsConfig, LogOddsMap, logodds};
use super::logodds::{SETS_GROUP_POINTS, check_scans};
use super::{VoxelMap, VoxelMapMut};
use crate::error::{Error, Result};
use crate::integrate::{
    BlockLevels, Checked, DepthFrame, IntegrationOptions, IntegrationStats, PointCloud,
    check_octomap_scan, scan_groups, scan_levels, walk_scan,
};
use crate::measures::{MeasureConfig, Memberships, VoxelClass};
use crate::storage::{BLOCK_CELLS, BlockKey, KeyBox, Resolution, VoxelKey};

/// Parameters of the alpha-cut map.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AlphaConfig {
    /// The standard method's parameters (unscaled; the map scales hit and miss itself).
    pub logodds: LogOddsConfig,
    /// Number of nested confidence cuts `N_t` (default 10).
    pub cuts: u32,
}

impl AlphaConfig {
    /// The default number of confidence cuts.
    pub const DEFAULT_CUTS: u32 = 10;

    /// OctoMap's defaults with [`AlphaConfig::DEFAULT_CUTS`] cuts at `resolution` metres.
    pub fn new(resolution: f64) -> Result<Self> {
        Ok(Self {
            logodds: LogOddsConfig::new(resolution)?,
            cuts: Self::DEFAULT_CUTS,
        })
    }

    /// Checks the log-odds parameters and that `cuts` lies in 1..=1000.
    pub fn validate(self) -> Result<Self> {
        self.logodds.validate()?;
        if !(1..=1000).contains(&self.cuts) {
            return Err(Error::InvalidParameter {
                name: "cuts",
                value: f64::from(self.cuts),
                expected: "between 1 and 1000 confidence cuts",
            });
        }
        Ok(self)
    }

    /// The probability scaled for `cuts` cuts: `p* = 1 / (1 + exp(-(1/N_t) logit(p)))`, so that
    /// `N_t` updates with `p*` equal one update with `p`.
    pub fn scaled(p: f64, cuts: u32) -> f64 {
        let logit = (p / (1.0 - p)).ln();
        1.0 / (1.0 + (-logit / f64::from(cuts)).exp())
    }

    /// How many of the nested cuts a point of confidence `c` (in `[0, 1]`, that is `C / 100`)
    /// belongs to: `floor(c · N_t)`, with a tolerance of 1e-6 so that a decimal confidence such
    /// as 0.7, stored as 0.69999999, still reaches its cut.
    pub fn cuts_of(&self, c: f32) -> u32 {
        let n = (f64::from(c) * f64::from(self.cuts) + 1e-6).floor();
        (n.max(0.0) as u32).min(self.cuts)
    }
}

/// The alpha-cut map (UFOMap-alpha): a log-odds map that inserts each scan as `N_t` nested
/// confidence cuts. Cut `k` (1..=`N_t`) holds the points with confidence `C >= 100 k / N_t` and
/// is inserted as its own scan with hit and miss probabilities scaled by
/// [`AlphaConfig::scaled`] (0.7 → 0.521, 0.4 → 0.490 for 10 cuts). A point of confidence 100
/// is in every cut, so it changes the map as one standard insertion does; a point of
/// confidence 30 counts as three tenths of one.
///
/// The rays are walked once per scan, not once per cut: each voxel records the highest cut
/// of a ray through it and of an end point in it, and cut `k`'s scan is the voxels of level `k`
/// and up. Voxels do not interact, so each voxel then takes its cuts' updates in order, hits
/// first ([`LogOddsMap::apply_levels`]); a test checks the cells bit for bit against
/// inserting every cut as its own scan.
///
/// A cloud without confidences is inserted at full confidence.
#[derive(Clone, Debug)]
pub struct AlphaCutMap {
    config: AlphaConfig,
    inner: LogOddsMap,
}

impl AlphaCutMap {
    /// An empty map.
    pub fn new(config: AlphaConfig) -> Result<Self> {
        let config = config.validate()?;
        Ok(Self::from_parts(config, LogOddsMap::new(config.logodds)?))
    }

    pub(crate) fn from_parts(config: AlphaConfig, mut inner: LogOddsMap) -> Self {
        let p = &config.logodds;
        inner.set_updates(
            logodds(AlphaConfig::scaled(p.prob_hit, config.cuts)),
            logodds(AlphaConfig::scaled(p.prob_miss, config.cuts)),
        );
        Self { config, inner }
    }

    /// The map's configuration.
    pub fn config(&self) -> &AlphaConfig {
        &self.config
    }

    /// The log-odds map that holds the cells.
    pub fn log_odds(&self) -> &LogOddsMap {
        &self.inner
    }
}

impl VoxelMap for AlphaCutMap {
    fn resolution(&self) -> Resolution {
        self.inner.resolution()
    }

    fn measure_config(&self) -> &MeasureConfig {
        self.inner.measure_config()
    }

    fn memberships_at(&self, key: VoxelKey) -> Memberships {
        self.inner.memberships_at(key)
    }

    fn block_memberships(&self, key: BlockKey, out: &mut [Memberships; BLOCK_CELLS]) {
        self.inner.block_memberships(key, out);
    }

    fn block_stamps(&self, key: BlockKey, out: &mut [u64; BLOCK_CELLS]) -> bool {
        self.inner.block_stamps(key, out)
    }

    fn memberships_of_stamps(&self, stamps: &[u64], out: &mut [Memberships]) {
        self.inner.memberships_of_stamps(stamps, out);
    }

    fn counts(&self) -> VoxelCounts {
        self.inner.counts()
    }

    fn any_in_box(&self, region: &KeyBox, class: VoxelClass) -> bool {
        self.inner.any_in_box(region, class)
    }

    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes()
    }

    fn cells(&self) -> Box<dyn Iterator<Item = (VoxelKey, Memberships)> + '_> {
        self.inner.cells()
    }

    fn write_version(&self) -> Option<u64> {
        self.inner.write_version()
    }

    fn changed_blocks_since(&self, version: u64) -> Option<Vec<BlockKey>> {
        self.inner.changed_blocks_since(version)
    }
}

impl VoxelMapMut for AlphaCutMap {
    fn integrate_cloud(
        &mut self,
        cloud: &PointCloud,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats> {
        // One walk of the rays records, per voxel, the highest cut of a ray through it and of
        // an end point in it; cut k's scan is then the voxels of level k and up (the same sets
        // as inserting the points of cut k and up as their own scan), applied in order.
        let resolution = self.inner.resolution();
        // At most `cuts` (validated to 1..=1000) levels, so the conversion never saturates.
        let (levels, mut stats) = scan_levels(cloud, &resolution, options, |i| {
            u16::try_from(self.config.cuts_of(cloud.confidence_of(i))).unwrap_or(u16::MAX)
        })?;
        stats.voxels_updated = self.inner.apply_levels(&levels);
        Ok(stats)
    }

    fn integrate_clouds(
        &mut self,
        clouds: &[PointCloud],
        options: &IntegrationOptions,
    ) -> Result<Vec<IntegrationStats>> {
        let resolution = self.inner.resolution();
        check_scans(clouds, |c| check_octomap_scan(c, &resolution, options))?;
        let mut all = Vec::with_capacity(clouds.len());
        for group in scan_groups(clouds, SETS_GROUP_POINTS) {
            let walked = group
                .par_iter()
                .map(|cloud| {
                    walk_scan::<BlockLevels>(cloud, &resolution, options, Checked::Yes, |i| {
                        u16::try_from(self.config.cuts_of(cloud.confidence_of(i)))
                            .unwrap_or(u16::MAX)
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            for (levels, mut stats) in walked {
                stats.voxels_updated = self.inner.apply_levels(&levels);
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn scaled_probabilities_match_the_paper() {
        assert!((AlphaConfig::scaled(0.7, 10) - 0.521).abs() < 5e-4);
        assert!((AlphaConfig::scaled(0.4, 10) - 0.490).abs() < 5e-4);
        // N_t scaled updates add up to one standard update.
        let one = (0.7f64 / 0.3).ln();
        let scaled = AlphaConfig::scaled(0.7, 10);
        assert!((10.0 * (scaled / (1.0 - scaled)).ln() - one).abs() < 1e-12);
    }

    #[test]
    fn cut_membership() {
        let c = AlphaConfig::new(0.1).unwrap();
        assert_eq!(c.cuts_of(1.0), 10);
        assert_eq!(c.cuts_of(0.7), 7);
        assert_eq!(c.cuts_of(0.69), 6);
        assert_eq!(c.cuts_of(0.05), 0);
        assert_eq!(c.cuts_of(0.0), 0);
    }

    #[test]
    fn full_confidence_equals_one_standard_insertion() {
        let points: Vec<_> = (0..40)
            .map(|i| {
                let a = f64::from(i) * 0.15;
                Point3::new(2.0 * a.cos(), 2.0 * a.sin(), 0.3 * a - 1.0)
            })
            .collect();
        let cloud = PointCloud::new(Point3::new(0.01, 0.02, 0.03), points.clone())
            .unwrap()
            .with_confidence(vec![1.0; 40])
            .unwrap();
        let mut alpha = AlphaCutMap::new(AlphaConfig::new(0.1).unwrap()).unwrap();
        alpha
            .integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        let mut standard = LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap();
        standard
            .integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        let cells: Vec<_> = standard
            .grid()
            .cells()
            .filter(|(_, c)| c.is_observed())
            .collect();
        assert!(cells.len() > 100);
        assert_eq!(alpha.cells().count(), cells.len());
        for (key, cell) in cells {
            let a = alpha.log_odds().log_odds_at(key);
            // Ten single-precision additions of logit(p)/10 against one of logit(p).
            assert!(
                (a.0 - cell.0).abs() < 1e-5,
                "{key:?}: {} vs {}",
                a.0,
                cell.0
            );
            assert_eq!(alpha.class_at(key), standard.class_at(key));
        }
        // A point of confidence 0.3 moves its voxel three tenths of the way.
        let weak = PointCloud::new(Point3::origin(), vec![Point3::new(1.05, 0.05, 0.05)])
            .unwrap()
            .with_confidence(vec![0.3])
            .unwrap();
        let mut alpha = AlphaCutMap::new(AlphaConfig::new(0.1).unwrap()).unwrap();
        alpha
            .integrate_cloud(&weak, &IntegrationOptions::default())
            .unwrap();
        let key = alpha
            .resolution()
            .key_of(&Point3::new(1.05, 0.05, 0.05))
            .unwrap();
        let expected = 0.3 * logodds(0.7);
        assert!((alpha.log_odds().log_odds_at(key).0 - expected).abs() < 1e-5);
    }

    /// The one-walk insertion against the definition: each cut inserted as its own scan of the
    /// points of that cut and up. Mixed confidences, rays clipped at `max_range`, several
    /// scans into the same map, NaN points: the two maps hold the same cells, bit for bit.
    #[test]
    fn one_walk_equals_one_scan_per_cut() {
        let config = AlphaConfig::new(0.1).unwrap();
        let mut fast = AlphaCutMap::new(config).unwrap();
        let mut reference = AlphaCutMap::new(config).unwrap();
        let options = IntegrationOptions {
            max_range: Some(2.5),
        };
        for scan in 0..4u32 {
            let mut points: Vec<_> = (0..600u32)
                .map(|i| {
                    let a = f64::from(i * 7 + scan * 13) * 0.0137;
                    let r = 0.8 + f64::from((i * 31 + scan) % 29) * 0.1;
                    Point3::new(r * a.cos(), r * a.sin(), 0.4 * (3.0 * a).sin())
                })
                .collect();
            points[17] = Point3::new(f64::NAN, 0.0, 0.0);
            let confidence: Vec<f32> = (0..600u32)
                .map(|i| ((i * 37 + scan * 11) % 101) as f32 / 100.0)
                .collect();
            let origin = Point3::new(0.03 * f64::from(scan), 0.02, 0.01);
            let cloud = PointCloud::new(origin, points)
                .unwrap()
                .with_confidence(confidence)
                .unwrap();
            let stats = fast.integrate_cloud(&cloud, &options).unwrap();
            let cuts: Vec<u32> = (0..cloud.len())
                .map(|i| config.cuts_of(cloud.confidence_of(i)))
                .collect();
            let mut updated = 0;
            for k in 1..=config.cuts {
                updated += reference
                    .inner
                    .integrate_selected(&cloud, &options, |i| cuts[i] >= k)
                    .unwrap()
                    .voxels_updated;
            }
            assert_eq!(stats.voxels_updated, updated);
            assert_eq!(stats.skipped, 1);
            assert!(stats.clipped > 0);
        }
        let a: Vec<_> = fast.log_odds().grid().cells().collect();
        let b: Vec<_> = reference.log_odds().grid().cells().collect();
        assert!(a.iter().filter(|(_, c)| c.is_observed()).count() > 1000);
        assert_eq!(a.len(), b.len());
        for ((ka, ca), (kb, cb)) in a.iter().zip(&b) {
            assert_eq!(ka, kb);
            assert_eq!(ca.0.to_bits(), cb.0.to_bits(), "{ka:?}");
        }
        assert_eq!(fast.counts(), reference.counts());
    }
}
