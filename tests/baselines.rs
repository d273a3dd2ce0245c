//! The standard log-odds map and the alpha-cut map: OctoMap parity on real data, the shared
//! integration interface, thread-count independence and files.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{data_dir, room_scan, wall_frame};
use fuzzyvox::VoxelMapMut;
use fuzzyvox::io::read_text_cloud;
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, AnyMap, FuzzyConfig, FuzzyMap, IntegrationOptions, LogOddsConfig,
    LogOddsMap, VoxelClass, VoxelMap,
};
use nalgebra::Point3;

/// OctoMap 1.9.7's occupied and free finest-level voxel counts for `scan.dat` with the sensor
/// at the origin and default parameters (`../shared/REFERENCE.md`, and `scripts/bench-octomap`
/// reproduces them).
const OCTOMAP_SCAN_DAT: [(f64, usize, usize); 3] = [
    (0.2, 9_378, 117_825),
    (0.1, 23_537, 794_069),
    (0.05, 40_568, 3_855_241),
];

#[test]
fn log_odds_map_equals_octomap_on_the_laser_scan() {
    let Some(dir) = data_dir("log_odds_map_equals_octomap_on_the_laser_scan") else {
        return;
    };
    let cloud = read_text_cloud(&dir.join("octomap-samples/scan.dat"), Point3::origin()).unwrap();
    for (resolution, occupied, free) in OCTOMAP_SCAN_DAT {
        let mut map = LogOddsMap::new(LogOddsConfig::new(resolution).unwrap()).unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        let counts = map.counts();
        assert_eq!(
            (counts.occupied, counts.free, counts.ambiguous),
            (occupied, free, 0),
            "at {resolution} m"
        );
    }
}

fn maps(resolution: f64) -> Vec<AnyMap> {
    vec![
        AnyMap::Fuzzy(FuzzyMap::new(FuzzyConfig::new(resolution).unwrap()).unwrap()),
        AnyMap::LogOdds(LogOddsMap::new(LogOddsConfig::new(resolution).unwrap()).unwrap()),
        AnyMap::Alpha(AlphaCutMap::new(AlphaConfig::new(resolution).unwrap()).unwrap()),
    ]
}

#[test]
fn every_map_takes_the_same_observations_through_one_interface() {
    let scan = room_scan(Point3::new(0.5, -0.5, 0.2), 4000, 11);
    let frame = wall_frame(Point3::new(-1.0, 0.0, 0.5), 3.5);
    for mut map in maps(0.2) {
        let kind = map.kind().name();
        let view = map.as_map_mut();
        let stats = view
            .integrate_cloud(&scan, &IntegrationOptions::default())
            .unwrap();
        assert_eq!(stats.integrated, 4000, "{kind}");
        view.integrate_depth(&frame, &IntegrationOptions::default())
            .unwrap();
        let counts = view.counts();
        assert!(
            counts.occupied > 500 && counts.free > 5000,
            "{kind}: {counts:?}"
        );
        // The room's interior is free and its walls occupied in every map.
        assert_eq!(
            view.class_at(
                view.resolution()
                    .key_of(&Point3::new(1.0, 1.0, 0.5))
                    .unwrap()
            ),
            VoxelClass::Free,
            "{kind}"
        );
        // The wall at x = 4 m (its points scatter by ±2 cm across the voxel border there).
        let wall_hit = [3.95, 4.05].iter().any(|&x| {
            let m = view.measures_at(view.resolution().key_of(&Point3::new(x, 0.1, 0.5)).unwrap());
            m.occupied > m.free
        });
        assert!(wall_hit, "{kind}: the wall is not occupied");
        for (_, m) in view.cells() {
            assert!((0.0..=1.0).contains(&m.occupied) && (0.0..=1.0).contains(&m.free));
        }
    }
}

#[test]
fn saved_bytes_do_not_depend_on_the_thread_count_for_any_map() {
    let scans: Vec<_> = (0..3)
        .map(|i: u32| {
            room_scan(
                Point3::new(0.3 * f64::from(i), 0.1, 0.0),
                3000,
                u64::from(i),
            )
        })
        .collect();
    let frame = wall_frame(Point3::new(-1.0, 0.3, 0.5), 3.9);
    let build = |threads: usize| -> Vec<Vec<u8>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            maps(0.1)
                .into_iter()
                .map(|mut map| {
                    for scan in &scans {
                        map.as_map_mut()
                            .integrate_cloud(scan, &IntegrationOptions::default())
                            .unwrap();
                    }
                    map.as_map_mut()
                        .integrate_depth(&frame, &IntegrationOptions::default())
                        .unwrap();
                    map.to_bytes()
                })
                .collect()
        })
    };
    let one = build(1);
    for threads in [2, 4, 8] {
        assert_eq!(build(threads), one, "{threads} threads");
    }
}

#[test]
fn a_list_of_scans_gives_every_map_what_one_scan_at_a_time_gives_and_fails_whole() {
    // Scans of different sizes, from different origins, some of them sharing voxels.
    let scans: Vec<_> = (0..11u32)
        .map(|i| {
            let origin = Point3::new(0.25 * f64::from(i % 4), -0.2 * f64::from(i % 3), 0.1);
            room_scan(origin, 300 + 700 * (i as usize % 3), u64::from(i))
        })
        .collect();
    let options = IntegrationOptions::default();
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            for (mut one_by_one, mut batched) in maps(0.1).into_iter().zip(maps(0.1)) {
                let kind = one_by_one.kind().name();
                let mut expected = Vec::new();
                for scan in &scans {
                    expected.push(
                        one_by_one
                            .as_map_mut()
                            .integrate_cloud(scan, &options)
                            .unwrap(),
                    );
                }
                let stats = batched
                    .as_map_mut()
                    .integrate_clouds(&scans, &options)
                    .unwrap();
                assert_eq!(stats, expected, "{kind}, {threads} threads");
                assert_eq!(
                    batched.to_bytes(),
                    one_by_one.to_bytes(),
                    "{kind}, {threads} threads"
                );
                // A bad scan anywhere in the list: an error, and the map as it was.
                let mut bad = scans.clone();
                bad.insert(
                    7,
                    fuzzyvox::PointCloud::new(Point3::origin(), vec![Point3::new(1e12, 0.0, 0.0)])
                        .unwrap(),
                );
                assert!(
                    batched
                        .as_map_mut()
                        .integrate_clouds(&bad, &options)
                        .is_err(),
                    "{kind}"
                );
                assert_eq!(batched.to_bytes(), one_by_one.to_bytes(), "{kind}");
                assert!(
                    batched
                        .as_map_mut()
                        .integrate_clouds(&[], &options)
                        .unwrap()
                        .is_empty()
                );
            }
        });
    }
}

#[test]
fn baseline_maps_round_trip_through_files_and_reject_the_wrong_kind() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-baselines-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scan = room_scan(Point3::origin(), 2000, 5);
    for mut map in maps(0.2) {
        map.as_map_mut()
            .integrate_cloud(&scan, &IntegrationOptions::default())
            .unwrap();
        let path = dir.join(format!("{}.fvx", map.kind().name()));
        map.save(&path).unwrap();
        let loaded = AnyMap::load(&path).unwrap();
        assert_eq!(loaded.kind(), map.kind());
        assert_eq!(loaded.to_bytes(), map.to_bytes());
        assert_eq!(loaded.as_map().counts(), map.as_map().counts());
    }
    assert!(matches!(
        LogOddsMap::load(dir.join("fuzzy.fvx")),
        Err(fuzzyvox::Error::Format {
            reason: fuzzyvox::FormatError::WrongKind { .. },
            ..
        })
    ));
    assert!(FuzzyMap::load(dir.join("alpha.fvx")).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn alpha_cut_map_weights_points_by_confidence() {
    // The same wall seen with high and with low confidence: low confidence commits less.
    let wall: Vec<_> = (0..200)
        .map(|i| Point3::new(3.0, -1.0 + 0.01 * f64::from(i), 0.5))
        .collect();
    let insert = |c: f32| {
        let mut map = AlphaCutMap::new(AlphaConfig::new(0.1).unwrap()).unwrap();
        let cloud = fuzzyvox::PointCloud::new(Point3::origin(), wall.clone())
            .unwrap()
            .with_confidence(vec![c; wall.len()])
            .unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        map.memberships_at(
            map.resolution()
                .key_of(&Point3::new(3.05, 0.05, 0.55))
                .unwrap(),
        )
    };
    let (strong, weak, none) = (insert(1.0), insert(0.3), insert(0.05));
    assert!((strong.occupied - 0.7).abs() < 1e-4, "{strong:?}");
    assert!(
        weak.occupied > 0.5 && weak.occupied < strong.occupied,
        "{weak:?}"
    );
    // Below the first cut a point is not inserted at all.
    assert_eq!(none, fuzzyvox::Memberships::default());
}
