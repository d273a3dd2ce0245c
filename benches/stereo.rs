//! Matching speed on the Middlebury motorcycle pair at its full 741×500 with 80 disparities
//! (census, costs, aggregation, checks and sub-pixel step; the images are loaded once), and the
//! census transform of the pair on its own.
//!
//! Needs `FUZZYVOX_DATA`; without it the benchmark says so and skips.
//! Run: `FUZZYVOX_DATA=../shared/data cargo bench --bench stereo` (set `RAYON_NUM_THREADS=2`
//! to compare with `scripts/bench-opencv-stereo.py`).

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use fuzzyvox::depth::{
    DepthParams, MatchParams, census_transform, depth_from_rectified, match_pair,
};
use fuzzyvox::io::middlebury::read_middlebury;

fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("FUZZYVOX_DATA").map(PathBuf::from);
    if dir.is_none() {
        eprintln!("SKIPPED: FUZZYVOX_DATA is not set; this benchmark needs the shared data");
    }
    dir
}

fn stereo(c: &mut Criterion) {
    let Some(dir) = data_dir() else { return };
    let pair = read_middlebury(&dir.join("middlebury-motorcycle")).expect("reading the pair");
    let geometry = pair.calib.geometry().expect("calibration");
    let matching = MatchParams {
        num_disparities: 80,
        ..MatchParams::default()
    };
    let mut group = c.benchmark_group("stereo_motorcycle_741x500_80d");
    group.sample_size(20);
    group.bench_function("census_pair", |b| {
        b.iter(|| (census_transform(&pair.left), census_transform(&pair.right)))
    });
    group.bench_function("match", |b| {
        b.iter(|| match_pair(&pair.left, &pair.right, &matching).expect("matching"))
    });
    let params = DepthParams {
        matching: matching.clone(),
        ..DepthParams::default()
    };
    group.bench_function("match_and_intervals", |b| {
        b.iter(|| {
            depth_from_rectified(&pair.left, &pair.right, &geometry, 1.0, &params).expect("depth")
        })
    });
    group.finish();
}

criterion_group!(benches, stereo);
criterion_main!(benches);
