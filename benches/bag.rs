//! Reading and inserting a robot recording against inserting the same clouds from a scan list:
//! the HoloLens recording's 80 depth clouds (1.1 million points) at 0.05 m into a log-odds map,
//! read from the ROS 1 bag, from the ROS 2 (MCAP) folder, and from a scan list of text clouds
//! written from the bag's scans (shortest round-trip decimals, so the clouds are identical).
//! Each iteration reads the input from disk and inserts it, as `fuzzyvox insert` does.
//!
//! Needs `FUZZYVOX_DATA`; without it the benchmark says so and skips.
//! Run: `FUZZYVOX_DATA=../shared/data cargo bench --bench bag`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use criterion::{Criterion, criterion_group, criterion_main};
use fuzzyvox::bag::{Bag, read_bag_scans};
use fuzzyvox::io::read_scan_list;
use fuzzyvox::{IntegrationOptions, LogOddsConfig, LogOddsMap, PointCloud, VoxelMapMut};

const TOPIC: &str = "/camera/depth/points";

fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("FUZZYVOX_DATA").map(PathBuf::from);
    if dir.is_none() {
        eprintln!("SKIPPED: FUZZYVOX_DATA is not set; this benchmark needs the shared data");
    }
    dir
}

/// Inserts scans 16 at a time, as `fuzzyvox insert` hands them over.
fn insert(scans: &[PointCloud]) -> LogOddsMap {
    let mut map = LogOddsMap::new(LogOddsConfig::new(0.05).unwrap()).unwrap();
    for chunk in scans.chunks(16) {
        map.integrate_clouds(chunk, &IntegrationOptions::default())
            .unwrap();
    }
    map
}

/// Writes `scans` as text clouds and a scan list in `dir`; returns the list.
fn write_scan_list(scans: &[PointCloud], dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut list = String::new();
    for (i, scan) in scans.iter().enumerate() {
        let mut text = String::new();
        for p in scan.points() {
            writeln!(text, "{} {} {}", p.x, p.y, p.z).unwrap();
        }
        let name = format!("cloud-{i:04}.xyz");
        std::fs::write(dir.join(&name), text).unwrap();
        let o = scan.origin();
        writeln!(list, "{name} {} {} {}", o.x, o.y, o.z).unwrap();
    }
    let path = dir.join("scans.list");
    std::fs::write(&path, list).unwrap();
    path
}

fn bag_against_scan_list(c: &mut Criterion) {
    let Some(dir) = data_dir() else { return };
    let ros1 = dir.join("robot-logs/hololens-000.bag");
    let ros2 = dir.join("robot-logs/hololens-000-mcap");
    let scans = read_bag_scans(&Bag::open(&ros1).unwrap(), TOPIC, "map").unwrap();
    let list = write_scan_list(
        &scans.scans,
        &Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench-bag"),
    );
    // The same clouds either way: the same map.
    let from_list = insert(&read_scan_list(&list).unwrap());
    let from_bag = insert(&scans.scans);
    assert_eq!(from_list.counts(), from_bag.counts());

    let mut group = c.benchmark_group("hololens_80_clouds_logodds_0.05m");
    group.sample_size(10);
    group.bench_function("scan_list", |b| {
        b.iter(|| insert(&read_scan_list(&list).unwrap()))
    });
    for (name, path) in [("ros1_bag", &ros1), ("ros2_mcap_folder", &ros2)] {
        group.bench_function(name, |b| {
            b.iter(|| {
                insert(
                    &read_bag_scans(&Bag::open(path).unwrap(), TOPIC, "map")
                        .unwrap()
                        .scans,
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bag_against_scan_list);
criterion_main!(benches);
