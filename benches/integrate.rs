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

criterion_group!(
    benches,
    ray_integration,
    log_odds_integration,
    alpha_integration,
    projective_integration
);
criterion_main!(benches);
