//! The incremental planner: after any sequence of integrations, an updated cost field is bit for
//! bit the field a full build gives on the same map, for every map, policy and clearance.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::map::{AlphaConfig, AlphaCutMap, LogOddsConfig, LogOddsMap};
use fuzzyvox::plan::{CostField, Planner, PlannerConfig, PlanningRegion, UnknownPolicy};
use fuzzyvox::{
    FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelKey, VoxelMap, VoxelMapMut,
};
use nalgebra::{Point3, Vector3};

/// A small deterministic generator (SplitMix64), so that the scans differ per seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// A scan of a random box-shaped obstacle seen from a random origin, with some far points that
/// clear space (and so remove obstacles other scans put there).
fn scan(rng: &mut Rng) -> PointCloud {
    let origin = Point3::new(
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(0.5, 1.5),
    );
    let centre = Point3::new(
        rng.range(1.0, 5.0),
        rng.range(-2.0, 2.0),
        rng.range(0.0, 2.0),
    );
    let half = Vector3::new(
        rng.range(0.05, 0.6),
        rng.range(0.05, 0.8),
        rng.range(0.05, 0.8),
    );
    let mut points = Vec::new();
    for _ in 0..400 {
        let face = Vector3::new(
            rng.range(-half.x, half.x),
            rng.range(-half.y, half.y),
            rng.range(-half.z, half.z),
        );
        points.push(centre + face);
    }
    for _ in 0..60 {
        points.push(Point3::new(
            rng.range(5.0, 7.0),
            rng.range(-3.0, 3.0),
            rng.range(-0.5, 2.5),
        ));
    }
    PointCloud::new(origin, points).unwrap()
}

fn configs() -> Vec<PlannerConfig> {
    vec![
        PlannerConfig::default(),
        PlannerConfig {
            unknown: UnknownPolicy::Cost(2.0),
            vehicle_radius: 0.2,
            ..PlannerConfig::default()
        },
        PlannerConfig {
            unknown: UnknownPolicy::Cost(0.5),
            preferred_clearance: 1.7,
            safety_threshold: 0.5,
            ..PlannerConfig::default()
        },
    ]
}

/// Integrates scans one by one; after each, every planner's updated field must equal a fresh
/// build.
fn check(mut map: impl VoxelMapMut, seed: u64) {
    let mut rng = Rng(seed);
    // The region cuts through the scanned space, so changes meet its edges too.
    let region =
        PlanningRegion::new(VoxelKey::new(-4, -14, -3), VoxelKey::new(28, 12, 11)).unwrap();
    let mut planners: Vec<Planner> = configs()
        .into_iter()
        .map(|c| Planner::new(&map, region, c).unwrap())
        .collect();
    let mut flipped = 0;
    let mut partial = 0;
    for step in 0..12 {
        map.integrate_cloud(&scan(&mut rng), &IntegrationOptions::default())
            .unwrap();
        for planner in &mut planners {
            let update = planner.update(&map);
            assert!(!update.rebuilt);
            flipped += update.voxels_flipped;
            if update.clearance_voxels > 0 && update.clearance_voxels < region.len() {
                partial += 1;
            }
            let full = CostField::build(&map, region, *planner.field().config()).unwrap();
            assert!(
                *planner.field() == full,
                "seed {seed}, scan {step}: the updated field differs from a full build \
                 ({} of {} voxels differ in traversability)",
                (0..region.len())
                    .filter(|&i| planner.field().is_traversable(i) != full.is_traversable(i))
                    .count(),
                region.len()
            );
        }
    }
    // The check means something: voxels flipped, and updates stayed local.
    assert!(
        flipped > 0 && partial > 0,
        "flipped {flipped}, partial {partial}"
    );
}

#[test]
fn updated_fuzzy_fields_equal_full_builds() {
    for seed in 1..4 {
        check(FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap(), seed);
    }
}

/// A fuzzy map that reports which blocks changed but keeps no stamps, so that the field's
/// update decodes every voxel of the changed blocks (the path for such maps).
struct Unstamped(FuzzyMap);

impl VoxelMap for Unstamped {
    fn resolution(&self) -> fuzzyvox::Resolution {
        self.0.resolution()
    }
    fn measure_config(&self) -> &fuzzyvox::measures::MeasureConfig {
        VoxelMap::measure_config(&self.0)
    }
    fn memberships_at(&self, key: VoxelKey) -> fuzzyvox::Memberships {
        self.0.memberships_at(key)
    }
    fn block_memberships(
        &self,
        key: fuzzyvox::storage::BlockKey,
        out: &mut [fuzzyvox::Memberships; fuzzyvox::storage::BLOCK_CELLS],
    ) {
        self.0.block_memberships(key, out);
    }
    fn counts(&self) -> fuzzyvox::map::VoxelCounts {
        VoxelMap::counts(&self.0)
    }
    fn memory_bytes(&self) -> usize {
        VoxelMap::memory_bytes(&self.0)
    }
    fn cells(&self) -> Box<dyn Iterator<Item = (VoxelKey, fuzzyvox::Memberships)> + '_> {
        self.0.cells()
    }
    fn write_version(&self) -> Option<u64> {
        self.0.write_version()
    }
    fn changed_blocks_since(&self, version: u64) -> Option<Vec<fuzzyvox::storage::BlockKey>> {
        self.0.changed_blocks_since(version)
    }
}

impl VoxelMapMut for Unstamped {
    fn integrate_cloud(
        &mut self,
        cloud: &PointCloud,
        options: &IntegrationOptions,
    ) -> fuzzyvox::Result<fuzzyvox::IntegrationStats> {
        self.0.integrate_cloud(cloud, options)
    }
    fn integrate_depth(
        &mut self,
        frame: &fuzzyvox::DepthFrame,
        options: &IntegrationOptions,
    ) -> fuzzyvox::Result<fuzzyvox::IntegrationStats> {
        self.0.integrate_depth(frame, options)
    }
}

#[test]
fn updated_fields_of_a_map_without_stamps_equal_full_builds() {
    let map = Unstamped(FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap());
    assert!(!map.block_stamps(
        fuzzyvox::storage::BlockKey::new(0, 0, 0),
        &mut [0; fuzzyvox::storage::BLOCK_CELLS]
    ));
    check(map, 9);
}

#[test]
fn updated_log_odds_and_alpha_fields_equal_full_builds() {
    // Log-odds maps also turn occupied voxels free again: the "raise" case.
    for seed in 4..6 {
        check(
            LogOddsMap::new(LogOddsConfig::new(0.2).unwrap()).unwrap(),
            seed,
        );
        check(
            AlphaCutMap::new(AlphaConfig::new(0.2).unwrap()).unwrap(),
            seed,
        );
    }
}

#[test]
fn a_map_without_change_tracking_is_read_once() {
    // A read-only map never changes: updating costs nothing and changes nothing.
    let map = fuzzyvox::map::FunctionMap::new(fuzzyvox::Resolution::new(0.2).unwrap(), |key| {
        fuzzyvox::Memberships {
            occupied: if key.x == 3 { 0.9 } else { 0.0 },
            free: 0.9,
        }
    });
    let region = PlanningRegion::new(VoxelKey::new(0, -3, -3), VoxelKey::new(8, 3, 3)).unwrap();
    let mut planner = Planner::new(&map, region, PlannerConfig::default()).unwrap();
    let before = planner.field().clone();
    let update = planner.update(&map);
    assert_eq!(update.voxels_read, 0);
    assert!(*planner.field() == before);
    assert!(
        planner
            .plan(VoxelKey::new(0, 0, 0), VoxelKey::new(8, 0, 0))
            .is_err()
    );
}

#[test]
fn kept_paths_are_checked_against_the_current_field() {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
    let region = PlanningRegion::new(VoxelKey::new(-5, -20, -5), VoxelKey::new(30, 20, 8)).unwrap();
    let config = PlannerConfig {
        unknown: UnknownPolicy::Cost(1.0),
        ..PlannerConfig::default()
    };
    let mut planner = Planner::new(&map, region, config).unwrap();
    let path = planner
        .plan(VoxelKey::new(0, 0, 0), VoxelKey::new(25, 0, 0))
        .unwrap();
    assert!(planner.is_clear(&path.waypoints));
    // A wall across the straight path: the old path is no longer clear, a new one goes round.
    let wall: Vec<Point3<f64>> = (-8..=8)
        .flat_map(|y| {
            (-8..=8).map(move |z| Point3::new(3.0, 0.1 * f64::from(y), 0.1 * f64::from(z)))
        })
        .collect();
    map.integrate_cloud(
        &PointCloud::new(Point3::origin(), wall).unwrap(),
        &IntegrationOptions::default(),
    )
    .unwrap();
    planner.update(&map);
    assert!(!planner.is_clear(&path.waypoints));
    let around = planner
        .plan(VoxelKey::new(0, 0, 0), VoxelKey::new(25, 0, 0))
        .unwrap();
    assert!(planner.is_clear(&around.waypoints));
    assert!(around.length > path.length);
    assert!(!planner.is_clear(&[]));
}
