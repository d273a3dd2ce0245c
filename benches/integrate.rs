//! Integration speed on real data: fuzzy, log-odds and alpha-cut ray integration of OctoMap's
//! `scan.dat`, and projective integration of one 640×480 7-Scenes depth frame.
//!
//! Needs `FUZZYVOX_DATA` (the shared data folder); without it the benchmarks say so and skip.
//! Run: `FUZZYVOX_DATA=../shared/data cargo bench --bench integrate`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::VoxelMapMut;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use fuzzyvox::integrate::scan_sets;
use fuzzyvox::io::read_text_cloud;
use fuzzyvox::io::rgbd::{
    kinect_interval_image, read_depth_png_mm, read_intrinsics_txt, read_pose_txt,
};
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, DepthFrame, FuzzyConfig, FuzzyMap, IntegrationOptions, LogOddsConfig,
    LogOddsMap, VoxelMap,
};
use nalgebra::Point3;

fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("FUZZYVOX_DATA").map(PathBuf::from);
    if dir.is_none() {
        eprintln!("SKIPPED: FUZZYVOX_DATA is not set; these benchmarks need the shared data");
    }
    dir
}

fn ray_integration(c: &mut Criterion) {
    let Some(dir) = data_dir() else { return };
    let cloud = read_text_cloud(&dir.join("octomap-samples/scan.dat"), Point3::origin())
        .expect("reading scan.dat");
    let mut group = c.benchmark_group("fuzzy_ray_scan_dat");
    group.sample_size(10);
    for resolution in [0.1, 0.05] {
        group.bench_function(format!("{resolution}m"), |b| {
            b.iter(|| {
                let mut map = FuzzyMap::new(FuzzyConfig::new(resolution).unwrap()).unwrap();
                map.integrate_cloud(&cloud, &IntegrationOptions::default())
                    .unwrap();
                map
            })
        });
    }
    group.finish();
}

fn log_odds_integration(c: &mut Criterion) {
    let Some(dir) = data_dir() else { return };
    let cloud = read_text_cloud(&dir.join("octomap-samples/scan.dat"), Point3::origin())
        .expect("reading scan.dat");
    let mut group = c.benchmark_group("logodds_ray_scan_dat");
    group.sample_size(10);
    for resolution in [0.1, 0.05] {
        group.bench_function(format!("{resolution}m"), |b| {
            b.iter(|| {
                let mut map = LogOddsMap::new(LogOddsConfig::new(resolution).unwrap()).unwrap();
                map.integrate_cloud(&cloud, &IntegrationOptions::default())
                    .unwrap();
                map
            })
        });
    }
    group.finish();
}

/// The alpha-cut map's insertion (one walk of the rays, then every cut applied) beside one
/// walk per cut, the definition it reproduces, on `scan.dat` with confidences spread evenly
/// over (0, 1] so that points fall in one to ten cuts.
fn alpha_integration(c: &mut Criterion) {
    let Some(dir) = data_dir() else { return };
    let cloud = read_text_cloud(&dir.join("octomap-samples/scan.dat"), Point3::origin())
        .expect("reading scan.dat");
    let confidence: Vec<f32> = (0..cloud.len())
        .map(|i| ((i * 37) % 100 + 1) as f32 / 100.0)
        .collect();
    let cloud = cloud
        .with_confidence(confidence)
        .expect("one confidence per point");
    let options = IntegrationOptions::default();
    let mut group = c.benchmark_group("alpha_ray_scan_dat");
    group.sample_size(10);
    for resolution in [0.1, 0.05] {
        let config = AlphaConfig::new(resolution).unwrap();
        group.bench_function(format!("one_walk/{resolution}m"), |b| {
            b.iter(|| {
                let mut map = AlphaCutMap::new(config).unwrap();
                map.integrate_cloud(&cloud, &options).unwrap();
                map
            })
        });
        let cuts: Vec<u32> = (0..cloud.len())
            .map(|i| config.cuts_of(cloud.confidence_of(i)))
            .collect();
        // The reference walks the same cuts into a plain log-odds map: the probabilities
        // differ from the alpha-cut map's scaled ones, the work does not.
        group.bench_function(format!("walk_per_cut/{resolution}m"), |b| {
            b.iter(|| {
                let mut map = LogOddsMap::new(LogOddsConfig::new(resolution).unwrap()).unwrap();
                let resolution = map.resolution();
                for k in 1..=config.cuts {
                    let (sets, _) =
                        scan_sets(&cloud, &resolution, &options, |i| cuts[i] >= k).unwrap();
                    map.apply_sets(&sets);
                }
                map
            })
        });
    }
    group.finish();
}

fn projective_integration(c: &mut Criterion) {
    let Some(dir) = data_dir() else { return };
    let scene = dir.join("rgbd-7scenes-redkitchen");
    let depth = read_depth_png_mm(&scene.join("frame-000150.depth.png")).expect("depth png");
    let k = read_intrinsics_txt(
        &scene.join("camera-intrinsics.txt"),
        depth.width,
        depth.height,
    )
    .expect("intrinsics");
    let pose = read_pose_txt(&scene.join("frame-000150.pose.txt")).expect("pose");
    let frame = DepthFrame::new(k, pose, kinect_interval_image(&depth).unwrap()).unwrap();
    let mut group = c.benchmark_group("fuzzy_frustum_640x480");
    for resolution in [0.05, 0.02] {
        group.bench_function(format!("{resolution}m"), |b| {
            b.iter(|| {
                let mut map = FuzzyMap::new(FuzzyConfig::new(resolution).unwrap()).unwrap();
                map.integrate_depth(&frame, &IntegrationOptions::default())
                    .unwrap();
                map
            })
        });
    }
    group.finish();
}

/// Point queries on scan.dat's 0.05 m maps: the class of 4096 voxels spread over the scan's
/// box (observed and unobserved ones alike), one `class_at` each; the time is for all 4096.
fn point_queries(c: &mut Criterion) {
    let Some(dir) = data_dir() else { return };
    let cloud = read_text_cloud(&dir.join("octomap-samples/scan.dat"), Point3::origin())
        .expect("reading scan.dat");
    let resolution = 0.05;
    let mut fuzzy = FuzzyMap::new(FuzzyConfig::new(resolution).unwrap()).unwrap();
    fuzzy
        .integrate_cloud(&cloud, &IntegrationOptions::default())
        .unwrap();
    let mut logodds = LogOddsMap::new(LogOddsConfig::new(resolution).unwrap()).unwrap();
    logodds
        .integrate_cloud(&cloud, &IntegrationOptions::default())
        .unwrap();
    // Keys spread over the box of the scan's end points, from a fixed sequence.
    let r = fuzzy.resolution();
    let keys_of: Vec<_> = cloud
        .points()
        .iter()
        .map(|p| r.key_of(p).unwrap())
        .collect();
    let lo = keys_of.iter().fold([i32::MAX; 3], |m, k| {
        [m[0].min(k.x), m[1].min(k.y), m[2].min(k.z)]
    });
    let hi = keys_of.iter().fold([i32::MIN; 3], |m, k| {
        [m[0].max(k.x), m[1].max(k.y), m[2].max(k.z)]
    });
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = |lo: i32, hi: i32| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        lo + ((state >> 33) % u64::from((hi - lo + 1) as u32)) as i32
    };
    let keys: Vec<_> = (0..4096)
        .map(|i| {
            // Every other key is an end point's voxel (observed), the rest anywhere in the box.
            if i % 2 == 0 {
                keys_of[(i * 21) % keys_of.len()]
            } else {
                fuzzyvox::VoxelKey::new(next(lo[0], hi[0]), next(lo[1], hi[1]), next(lo[2], hi[2]))
            }
        })
        .collect();
    let mut group = c.benchmark_group("point_query_scan_dat_0.05m");
    group.bench_function("fuzzy_class_at_4096", |b| {
        b.iter(|| {
            keys.iter()
                .filter(|k| fuzzy.class_at(**k) == fuzzyvox::VoxelClass::Occupied)
                .count()
        })
    });
    group.bench_function("logodds_class_at_4096", |b| {
        b.iter(|| {
            keys.iter()
                .filter(|k| logodds.class_at(**k) == fuzzyvox::VoxelClass::Occupied)
                .count()
        })
    });
    group.finish();
}

criterion_group!(
    benches,
    point_queries,
    ray_integration,
    log_odds_integration,
    alpha_integration,
    projective_integration
);
criterion_main!(benches);
