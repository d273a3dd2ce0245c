//! The dual-set fuzzy map's laws: order independence, exact merges, memberships in [0, 1],
//! thread-count independence, and what rays and frusta do to voxels.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{room_scan, wall_frame};
use fuzzyvox::VoxelMapMut;
use fuzzyvox::{
    EvidenceKind, EvidenceModel, Family, FuzzyConfig, FuzzyMap, IntegrationOptions, Memberships,
    TConorm, VoxelClass, VoxelMap,
};
use nalgebra::Point3;

fn config(family: Family) -> FuzzyConfig {
    FuzzyConfig::new(0.2)
        .unwrap()
        .with_operator(TConorm::new(family).unwrap())
}

fn scans() -> Vec<fuzzyvox::PointCloud> {
    [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, -1.5, 0.5),
        Point3::new(-2.0, 1.0, 1.0),
        Point3::new(2.5, 2.5, 0.0),
        Point3::new(-1.0, -2.0, 2.0),
    ]
    .into_iter()
    .enumerate()
    .map(|(i, o)| room_scan(o, 3000, i as u64))
    .collect()
}

fn build(config: FuzzyConfig, scans: &[&fuzzyvox::PointCloud]) -> FuzzyMap {
    let mut map = FuzzyMap::new(config).unwrap();
    for scan in scans {
        map.integrate_cloud(scan, &IntegrationOptions::default())
            .unwrap();
    }
    map
}

fn max_difference(a: &FuzzyMap, b: &FuzzyMap) -> f32 {
    assert_eq!(a.grid().block_count(), b.grid().block_count());
    a.cells()
        .map(|(key, m)| {
            let n = b.memberships_at(key);
            (m.occupied - n.occupied).abs().max((m.free - n.free).abs())
        })
        .fold(0.0, f32::max)
}

const FAMILIES: [Family; 5] = [
    Family::Product,
    Family::Minimum,
    Family::Lukasiewicz,
    Family::Dombi { lambda: 2.0 },
    Family::Hamacher { gamma: 0.5 },
];

#[test]
fn insertion_order_does_not_matter() {
    let scans = scans();
    for family in FAMILIES {
        let forward: Vec<_> = scans.iter().collect();
        let shuffled = vec![&scans[3], &scans[0], &scans[4], &scans[2], &scans[1]];
        let reversed: Vec<_> = scans.iter().rev().collect();
        let a = build(config(family), &forward);
        let b = build(config(family), &shuffled);
        let c = build(config(family), &reversed);
        assert!(a.counts().occupied > 100, "{family}: too little mapped");
        assert!(max_difference(&a, &b) < 1e-5, "{family}: shuffled differs");
        assert!(max_difference(&a, &c) < 1e-5, "{family}: reversed differs");
    }
}

#[test]
fn merge_equals_sequential_insertion() {
    let scans = scans();
    for family in FAMILIES {
        let all: Vec<_> = scans.iter().collect();
        let sequential = build(config(family), &all);
        let mut left = build(config(family), &all[..2]);
        let right = build(config(family), &all[2..]);
        left.merge(&right).unwrap();
        assert!(max_difference(&sequential, &left) < 1e-5, "{family}");
        // And the other way round.
        let mut right = build(config(family), &all[2..]);
        right.merge(&build(config(family), &all[..2])).unwrap();
        assert!(max_difference(&sequential, &right) < 1e-5, "{family}");
    }
}

#[test]
fn merge_rejects_incompatible_maps() {
    let mut a = FuzzyMap::new(config(Family::Product)).unwrap();
    let b = FuzzyMap::new(config(Family::Minimum)).unwrap();
    assert!(a.merge(&b).is_err());
    let c = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    assert!(a.merge(&c).is_err());
}

#[test]
fn memberships_stay_in_the_unit_interval() {
    let scans = scans();
    for family in [
        Family::Product,
        Family::Lukasiewicz,
        Family::Drastic,
        Family::Einstein,
        Family::Yager { p: 0.3 },
        Family::Frank { s: 100.0 },
        Family::AczelAlsina { p: 3.0 },
        Family::SchweizerSklar { p: -2.0 },
    ] {
        let mut map = FuzzyMap::new(config(family)).unwrap();
        for _ in 0..3 {
            for scan in &scans {
                map.integrate_cloud(scan, &IntegrationOptions::default())
                    .unwrap();
            }
            map.integrate_depth(
                &wall_frame(Point3::new(0.0, 0.0, 0.5), 3.9),
                &Default::default(),
            )
            .unwrap();
        }
        for (_, m) in map.cells() {
            assert!((0.0..=1.0).contains(&m.occupied), "{family}: {m:?}");
            assert!((0.0..=1.0).contains(&m.free), "{family}: {m:?}");
        }
    }
}

#[test]
fn saved_bytes_do_not_depend_on_the_thread_count() {
    let scans = scans();
    let frame = wall_frame(Point3::new(-1.0, 0.3, 0.5), 3.9);
    let bytes: Vec<Vec<u8>> = [1, 2, 4]
        .into_iter()
        .map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut map = FuzzyMap::new(config(Family::Product)).unwrap();
                for scan in &scans {
                    map.integrate_cloud(scan, &IntegrationOptions::default())
                        .unwrap();
                }
                map.integrate_depth(&frame, &IntegrationOptions::default())
                    .unwrap();
                map.to_bytes()
            })
        })
        .collect();
    assert!(bytes[0].len() > 10_000);
    assert_eq!(bytes[0], bytes[1], "1 vs 2 threads");
    assert_eq!(bytes[0], bytes[2], "1 vs 4 threads");
}

#[test]
fn save_load_round_trip() {
    let scans = scans();
    let map = build(config(Family::Dombi { lambda: 1.5 }), &[&scans[0]]);
    let dir = std::env::temp_dir().join(format!("fuzzyvox-roundtrip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("map.fvx");
    map.save(&path).unwrap();
    let loaded = FuzzyMap::load(&path).unwrap();
    assert_eq!(loaded.to_bytes(), map.to_bytes());
    assert_eq!(loaded.counts(), map.counts());
    assert_eq!(loaded.config(), map.config());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_ray_frees_its_path_and_occupies_its_end() {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let end = Point3::new(2.05, 0.05, 0.05);
    let cloud = fuzzyvox::PointCloud::new(Point3::new(0.05, 0.05, 0.05), vec![end]).unwrap();
    let stats = map.integrate_cloud(&cloud, &Default::default()).unwrap();
    assert_eq!(stats.integrated, 1);
    let end_m = map.memberships_at_point(&end).unwrap();
    assert!((end_m.occupied - 0.7).abs() < 1e-6, "{end_m:?}");
    assert_eq!(end_m.free, 0.0);
    for i in 0..18 {
        let p = Point3::new(0.05 + 0.1 * f64::from(i), 0.05, 0.05);
        let m = map.memberships_at_point(&p).unwrap();
        assert!(
            (m.free - 0.6).abs() < 1e-6 && m.occupied == 0.0,
            "{i}: {m:?}"
        );
    }
    // Beyond the end: nothing known.
    let behind = map
        .memberships_at_point(&Point3::new(2.5, 0.05, 0.05))
        .unwrap();
    assert_eq!(behind, Memberships::default());
}

#[test]
fn max_range_cuts_rays_and_only_clears() {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let cloud =
        fuzzyvox::PointCloud::new(Point3::origin(), vec![Point3::new(10.05, 0.05, 0.05)]).unwrap();
    let options = IntegrationOptions {
        max_range: Some(3.0),
    };
    let stats = map.integrate_cloud(&cloud, &options).unwrap();
    assert_eq!(stats.clipped, 1);
    assert_eq!(map.counts().occupied, 0);
    assert_eq!(
        map.class_at_point(&Point3::new(2.5, 0.0, 0.0)).unwrap(),
        VoxelClass::Free
    );
    assert_eq!(
        map.class_at_point(&Point3::new(5.0, 0.0, 0.0)).unwrap(),
        VoxelClass::Unknown
    );
}

#[test]
fn confidence_weights_evidence_as_fractional_observations() {
    // Two observations at confidence 0.5 equal one at confidence 1 (probabilistic sum): in the
    // paper's model for both sets; in the dual model for the occupied set, while free space
    // follows the reliability (1 for a cloud's points).
    let point = Point3::new(1.05, 0.05, 0.05);
    let weak = fuzzyvox::PointCloud::new(Point3::origin(), vec![point])
        .unwrap()
        .with_confidence(vec![0.5])
        .unwrap();
    let sure = fuzzyvox::PointCloud::new(Point3::origin(), vec![point]).unwrap();
    for model in [EvidenceModel::paper(), EvidenceModel::dual()] {
        let config = FuzzyConfig::new(0.1).unwrap().with_evidence(model);
        let mut half = FuzzyMap::new(config).unwrap();
        half.integrate_cloud(&weak, &Default::default()).unwrap();
        half.integrate_cloud(&weak, &Default::default()).unwrap();
        let mut full = FuzzyMap::new(config).unwrap();
        full.integrate_cloud(&sure, &Default::default()).unwrap();
        let end = half.memberships_at_point(&point).unwrap().occupied;
        assert!((end - full.memberships_at_point(&point).unwrap().occupied).abs() < 1e-5);
        let path = Point3::new(0.55, 0.05, 0.05);
        let (twice_half, once_full) = (
            half.memberships_at_point(&path).unwrap().free,
            full.memberships_at_point(&path).unwrap().free,
        );
        if model.kind == EvidenceKind::Paper {
            assert!(max_difference(&half, &full) < 1e-5);
        } else {
            // Two full-weight passes: more free than one.
            assert!(twice_half > once_full + 0.1, "{twice_half} {once_full}");
        }
    }
    // Confidence zero: nothing in the paper's model; in the dual model only free space.
    let zero = fuzzyvox::PointCloud::new(Point3::origin(), vec![point])
        .unwrap()
        .with_confidence(vec![0.0])
        .unwrap();
    let mut none = FuzzyMap::new(
        FuzzyConfig::new(0.1)
            .unwrap()
            .with_evidence(EvidenceModel::paper()),
    )
    .unwrap();
    none.integrate_cloud(&zero, &Default::default()).unwrap();
    assert_eq!(none.counts().occupied + none.counts().free, 0);
    let mut cleared = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    cleared.integrate_cloud(&zero, &Default::default()).unwrap();
    assert_eq!(cleared.counts().occupied, 0);
    assert!(cleared.counts().free > 0);
}

#[test]
fn frustum_frees_space_in_front_occupies_the_wall_and_leaves_behind_unknown() {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let frame = wall_frame(Point3::new(0.0, 0.0, 0.5), 3.0);
    let stats = map.integrate_depth(&frame, &Default::default()).unwrap();
    assert!(stats.integrated > 3000 && stats.skipped > 0);
    // One frame marks the voxels holding its most likely points with a full hit, and spreads
    // thin evidence over the rest of its ±5 % interval (in front of the wall, before P0).
    let wall = Point3::new(3.05, 0.05, 0.55);
    let once = map.memberships_at_point(&wall).unwrap();
    // k_O = 0.7 at confidence 0.9 under the probabilistic sum: 1 - 0.3^0.9.
    assert!(
        (once.occupied - (1.0 - 0.3f32.powf(0.9))).abs() < 1e-5,
        "{once:?}"
    );
    let before = map
        .memberships_at_point(&Point3::new(2.95, 0.05, 0.55))
        .unwrap();
    assert!(
        before.occupied > 0.05 && before.occupied < 0.3,
        "{before:?}"
    );
    assert_eq!(before.free, 0.0);
    for _ in 0..3 {
        map.integrate_depth(&frame, &Default::default()).unwrap();
    }
    let class = |x: f64| map.class_at_point(&Point3::new(x, 0.05, 0.55)).unwrap();
    assert_eq!(class(1.0), VoxelClass::Free);
    assert_eq!(class(2.0), VoxelClass::Free);
    assert_eq!(class(3.05), VoxelClass::Occupied);
    assert_eq!(class(3.6), VoxelClass::Unknown);
    assert_eq!(class(-0.5), VoxelClass::Unknown);
    // Outside the field of view (±38° horizontally): unknown.
    assert_eq!(
        map.class_at_point(&Point3::new(1.0, 1.5, 0.5)).unwrap(),
        VoxelClass::Unknown
    );
}

#[test]
fn a_depth_frame_scaled_to_half_weight_counts_as_half_an_observation() {
    // Two frames at half weight equal one at full weight (probabilistic sum), in the frustum
    // integration as in the point integrator; the standard map ignores the weight.
    let frame = wall_frame(Point3::new(0.0, 0.0, 0.5), 3.0);
    let mut halved = frame.clone();
    halved.scale_confidence(0.5).unwrap();
    let mut half = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    half.integrate_depth(&halved, &Default::default()).unwrap();
    half.integrate_depth(&halved, &Default::default()).unwrap();
    let mut full = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    full.integrate_depth(&frame, &Default::default()).unwrap();
    assert!(max_difference(&half, &full) < 1e-5);
    // One half-weight frame leaves the wall voxel below a full one's membership.
    let mut once = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    once.integrate_depth(&halved, &Default::default()).unwrap();
    let wall = Point3::new(3.05, 0.05, 0.55);
    let (weak, strong) = (
        once.memberships_at_point(&wall).unwrap().occupied,
        full.memberships_at_point(&wall).unwrap().occupied,
    );
    assert!(weak > 0.0 && weak < strong, "{weak} vs {strong}");
    let standard = |f: &fuzzyvox::DepthFrame| {
        let mut map =
            fuzzyvox::LogOddsMap::new(fuzzyvox::LogOddsConfig::new(0.1).unwrap()).unwrap();
        map.integrate_depth(f, &Default::default()).unwrap();
        map.cells().collect::<Vec<_>>()
    };
    assert_eq!(standard(&frame), standard(&halved));
    // Weights outside (0, 1] are refused and leave the frame as it was.
    let mut kept = frame.clone();
    for bad in [0.0, -0.5, 1.5, f32::NAN, f32::INFINITY] {
        assert!(matches!(
            kept.scale_confidence(bad),
            Err(fuzzyvox::Error::InvalidParameter { name: "weight", .. })
        ));
    }
    let bits = |f: &fuzzyvox::DepthFrame| -> Vec<u32> {
        f.image().confidence().iter().map(|c| c.to_bits()).collect()
    };
    assert_eq!(bits(&kept), bits(&frame));
}

#[test]
fn box_queries_agree_with_cell_scans() {
    let scans = scans();
    let map = build(config(Family::Product), &[&scans[0], &scans[1]]);
    let r = map.resolution();
    for (lo, hi) in [
        ([-1.0, -1.0, -0.5], [1.0, 1.0, 0.5]),
        ([3.5, -4.5, -1.5], [4.5, 4.5, 3.5]),
        ([-0.3, -0.3, -0.3], [0.3, 0.3, 0.3]),
        ([10.0, 10.0, 10.0], [11.0, 11.0, 11.0]),
    ] {
        let region =
            fuzzyvox::KeyBox::from_points(&r, &Point3::from(lo), &Point3::from(hi)).unwrap();
        for class in VoxelClass::ALL {
            let mut expected = false;
            for x in region.min.x..=region.max.x {
                for y in region.min.y..=region.max.y {
                    for z in region.min.z..=region.max.z {
                        expected |= map.class_at(fuzzyvox::VoxelKey::new(x, y, z)) == class;
                    }
                }
            }
            assert_eq!(map.any_in_box(&region, class), expected, "{lo:?} {class:?}");
        }
    }
}
