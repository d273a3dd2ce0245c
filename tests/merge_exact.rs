//! Exact order independence: the same observations give byte-identical fuzzy map files whatever
//! their order, however they are split into partial maps and merged, and on any number of
//! threads (the fixed-point levels of `map::Accumulator`).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{data_dir, room_scan};
use fuzzyvox::io::read_text_cloud;
use fuzzyvox::io::rgbd::RgbdFolder;
use fuzzyvox::{
    DepthFrame, EvidenceModel, FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelMapMut,
};
use nalgebra::Point3;

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

fn empty(resolution: f64, op: &str) -> FuzzyMap {
    let mut config = FuzzyConfig::new(resolution).unwrap();
    config.operator = fuzzyvox::TConorm::new(op.parse().unwrap()).unwrap();
    FuzzyMap::new(config).unwrap()
}

/// A map of `clouds` integrated in the given order.
fn map_of(clouds: &[&PointCloud], resolution: f64, op: &str) -> FuzzyMap {
    let mut map = empty(resolution, op);
    for cloud in clouds {
        map.integrate_cloud(cloud, &IntegrationOptions::default())
            .unwrap();
    }
    map
}

/// `n` parts of a cloud, each a contiguous share of its points, from the same origin.
fn split(cloud: &PointCloud, n: usize) -> Vec<PointCloud> {
    let points = cloud.points();
    let size = points.len().div_ceil(n);
    points
        .chunks(size)
        .map(|chunk| PointCloud::new(cloud.origin(), chunk.to_vec()).unwrap())
        .collect()
}

/// A fixed shuffle (Fisher-Yates with SplitMix64).
fn shuffled<T: Clone>(items: &[T], seed: u64) -> Vec<T> {
    let mut rng = common::Rng::new(seed);
    let mut out = items.to_vec();
    for i in (1..out.len()).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        out.swap(i, j);
    }
    out
}

/// Every order, split and thread count of `parts` gives the same bytes as `parts` in order.
fn assert_exact(parts: &[PointCloud], resolution: f64, op: &str) {
    let refs: Vec<&PointCloud> = parts.iter().collect();
    let serial = map_of(&refs, resolution, op).to_bytes();
    let reversed: Vec<&PointCloud> = refs.iter().rev().copied().collect();
    assert_eq!(
        map_of(&reversed, resolution, op).to_bytes(),
        serial,
        "{op}: reversed"
    );
    for seed in [1, 2, 3] {
        let order = shuffled(&refs, seed);
        assert_eq!(
            map_of(&order, resolution, op).to_bytes(),
            serial,
            "{op}: shuffle {seed}"
        );
    }
    // Partial maps of the halves, merged either way round.
    let (a, b) = refs.split_at(refs.len() / 2 + 1);
    let (left, right) = (map_of(a, resolution, op), map_of(b, resolution, op));
    let mut ab = left.clone();
    ab.merge(&right).unwrap();
    let mut ba = right;
    ba.merge(&left).unwrap();
    assert_eq!(ab.to_bytes(), serial, "{op}: merged halves");
    assert_eq!(ba.to_bytes(), serial, "{op}: merged halves, swapped");
    for threads in [1, 2, 8] {
        let bytes = in_pool(threads, || map_of(&refs, resolution, op).to_bytes());
        assert_eq!(bytes, serial, "{op}: {threads} threads");
    }
}

#[test]
fn synthetic_scans_give_identical_files_in_any_order_split_and_thread_count() {
    let scans: Vec<PointCloud> = (0..6u32)
        .map(|i| {
            let origin = Point3::new(0.3 * f64::from(i), -0.2 * f64::from(i), 0.5);
            room_scan(origin, 3_000, 100 + u64::from(i))
        })
        .collect();
    for op in [
        "product",
        "max",
        "lukasiewicz",
        "einstein",
        "dombi:2",
        "yager:2",
    ] {
        assert_exact(&scans, 0.1, op);
    }
}

#[test]
fn octomap_scan_in_eight_parts_gives_identical_files_in_any_order() {
    let Some(dir) = data_dir("octomap_scan_in_eight_parts_gives_identical_files_in_any_order")
    else {
        return;
    };
    let scan = read_text_cloud(&dir.join("octomap-samples/scan.dat"), Point3::origin()).unwrap();
    let parts = split(&scan, 8);
    assert_eq!(parts.len(), 8);
    assert_exact(&parts, 0.1, "product");
}

/// An empty map at 0.05 m with the evidence model `model`.
fn empty_with(model: EvidenceModel) -> FuzzyMap {
    FuzzyMap::new(FuzzyConfig::new(0.05).unwrap().with_evidence(model)).unwrap()
}

/// A map of the frames `range` of the folder.
fn frames_map(
    frames: &[DepthFrame],
    range: std::ops::Range<usize>,
    model: EvidenceModel,
) -> FuzzyMap {
    let mut map = empty_with(model);
    for frame in &frames[range] {
        map.integrate_depth(frame, &IntegrationOptions::default())
            .unwrap();
    }
    map
}

fn merged(mut a: FuzzyMap, b: &FuzzyMap) -> FuzzyMap {
    a.merge(b).unwrap();
    a
}

#[test]
fn rgbd_partial_maps_merge_to_identical_files_in_any_tree() {
    let Some(dir) = data_dir("rgbd_partial_maps_merge_to_identical_files_in_any_tree") else {
        return;
    };
    let folder = RgbdFolder::open(&dir.join("rgbd-7scenes-redkitchen")).unwrap();
    assert_eq!(folder.frames.len(), 50);
    let frames: Vec<DepthFrame> = (0..50)
        .map(|i| folder.read_kinect_frame(i).unwrap())
        .collect();
    // The default model, and the one for checked depth, whose end points are weighed by the
    // rays of their own image.
    for model in [EvidenceModel::default(), EvidenceModel::confirmed()] {
        let serial = frames_map(&frames, 0..50, model).to_bytes();
        // Five partial maps of ten frames each, merged in three different trees.
        let parts: Vec<FuzzyMap> = (0..5)
            .map(|i| frames_map(&frames, i * 10..i * 10 + 10, model))
            .collect();
        let chain = parts[1..].iter().fold(parts[0].clone(), merged);
        let balanced = merged(
            merged(parts[0].clone(), &parts[1]),
            &merged(parts[2].clone(), &merged(parts[3].clone(), &parts[4])),
        );
        let backwards = parts[..4].iter().rev().fold(parts[4].clone(), merged);
        assert_eq!(chain.to_bytes(), serial, "chain");
        assert_eq!(balanced.to_bytes(), serial, "balanced tree");
        assert_eq!(backwards.to_bytes(), serial, "backwards chain");
        // Uneven parts: odd frames and even frames.
        let mut odd = empty_with(model);
        let mut even = empty_with(model);
        for (i, frame) in frames.iter().enumerate() {
            let map = if i % 2 == 0 { &mut even } else { &mut odd };
            map.integrate_depth(frame, &IntegrationOptions::default())
                .unwrap();
        }
        assert_eq!(merged(odd, &even).to_bytes(), serial, "odd and even frames");
    }
}
