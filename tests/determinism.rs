//! The depth stage gives the same result, bit for bit, for any number of threads: the depth
//! frame's P-, P0, P+ and confidence planes, its camera and pose, the disparities behind them,
//! and the maps built from it. (Map integration alone is covered for every map kind in
//! `baselines.rs` and `fuzzy_map.rs`.)

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::depth::{
    DepthParams, DepthResult, Frame, GrayImage, depth_from_pair, depth_from_views,
};
use fuzzyvox::sim::render;
use fuzzyvox::sim::scenario;
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, AnyMap, FuzzyConfig, FuzzyMap, IntegrationOptions, LogOddsConfig,
    LogOddsMap,
};

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

fn bits64(values: impl IntoIterator<Item = f64>) -> Vec<u64> {
    values.into_iter().map(f64::to_bits).collect()
}

/// Everything the depth stage outputs, as bits.
fn fingerprint(result: &DepthResult) -> Vec<Vec<u64>> {
    let image = result.frame.image();
    let planes = [
        image.near(),
        image.depth(),
        image.far(),
        image.confidence(),
        &result.disparity.disparity,
        &result.disparity.range_low,
        &result.disparity.range_high,
    ];
    let mut out: Vec<Vec<u64>> = planes
        .iter()
        .map(|p| bits(p).into_iter().map(u64::from).collect())
        .collect();
    let pose = result.frame.world_from_camera();
    out.push(bits64(
        pose.translation
            .vector
            .iter()
            .chain(pose.rotation.coords.iter())
            .copied(),
    ));
    let k = result.frame.intrinsics();
    out.push(bits64([k.fx(), k.fy(), k.cx(), k.cy()]));
    out.push(vec![
        u64::from(k.width()),
        u64::from(k.height()),
        result.quality.to_bits(),
    ]);
    out
}

#[test]
fn depth_from_pair_is_identical_for_1_2_and_8_threads() {
    let wall = scenario::wall().unwrap();
    let frames: Vec<(Frame, Frame)> = [0, 3]
        .into_iter()
        .map(|index| {
            let (reference, other) = wall.pairs[index];
            let frame = |pose, side: u64| {
                let view = render(&wall.scene, &wall.intrinsics, &pose, 40 + side, 160.0);
                let image = GrayImage::new(view.width, view.height, view.image).unwrap();
                Frame::new(image, wall.intrinsics, pose, side as f64).unwrap()
            };
            (frame(reference, 0), frame(other, 1))
        })
        .collect();
    let run = |threads: usize| {
        in_pool(threads, || {
            frames
                .iter()
                .map(|(reference, other)| {
                    depth_from_pair(reference, other, &DepthParams::default()).unwrap()
                })
                .collect::<Vec<_>>()
        })
    };
    let one = run(1);
    for result in &one {
        let valid = result.frame.image().valid_pixels();
        assert!(
            valid > 10_000,
            "only {valid} valid pixels: the pair should match"
        );
    }
    let reference: Vec<_> = one.iter().map(fingerprint).collect();
    for threads in [2, 8] {
        let other: Vec<_> = run(threads).iter().map(fingerprint).collect();
        assert_eq!(other, reference, "{threads} threads");
    }

    // The maps built from those frames are identical too.
    let build = |threads: usize| -> Vec<Vec<u8>> {
        in_pool(threads, || {
            // The fuzzy map with the default model, and with the one for checked depth (end
            // points weighed by their image's rays).
            let confirmed = FuzzyConfig::new(0.2)
                .unwrap()
                .with_evidence(fuzzyvox::EvidenceModel::confirmed());
            let mut maps = [
                AnyMap::Fuzzy(FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap()),
                AnyMap::Fuzzy(FuzzyMap::new(confirmed).unwrap()),
                AnyMap::LogOdds(LogOddsMap::new(LogOddsConfig::new(0.2).unwrap()).unwrap()),
                AnyMap::Alpha(AlphaCutMap::new(AlphaConfig::new(0.2).unwrap()).unwrap()),
            ];
            let options = IntegrationOptions {
                max_range: Some(wall.max_range),
            };
            for map in &mut maps {
                for result in &one {
                    map.as_map_mut()
                        .integrate_depth(&result.frame, &options)
                        .unwrap();
                }
            }
            maps.iter().map(AnyMap::to_bytes).collect()
        })
    };
    let bytes = build(1);
    assert!(bytes.iter().all(|b| b.len() > 10_000));
    for threads in [2, 8] {
        assert_eq!(build(threads), bytes, "maps with {threads} threads");
    }
}

#[test]
fn depth_from_views_is_identical_for_1_2_and_8_threads() {
    // The wall's first three strafing pairs: a reference and five earlier positions.
    let wall = scenario::wall().unwrap();
    let frame = |pose, side: u64| {
        let view = render(&wall.scene, &wall.intrinsics, &pose, 50 + side, 160.0);
        let image = GrayImage::new(view.width, view.height, view.image).unwrap();
        Frame::new(image, wall.intrinsics, pose, side as f64).unwrap()
    };
    let (reference, _) = wall.pairs[2];
    let reference = frame(reference, 0);
    let others: Vec<Frame> = [(2, false), (1, true), (1, false), (0, true), (0, false)]
        .into_iter()
        .enumerate()
        .map(|(side, (index, first))| {
            let (a, b) = wall.pairs[index];
            frame(if first { a } else { b }, side as u64 + 1)
        })
        .collect();
    let others: Vec<&Frame> = others.iter().collect();
    let params = DepthParams {
        depth_range: Some((4.0, wall.max_range)),
        ..DepthParams::default()
    };
    let run = |threads: usize| {
        in_pool(threads, || {
            fingerprint(&depth_from_views(&reference, &others, &params).unwrap())
        })
    };
    let one = run(1);
    let valid = one[1]
        .iter()
        .filter(|d| f32::from_bits(**d as u32).is_finite())
        .count();
    assert!(valid > 10_000, "only {valid} pixels with a depth");
    for threads in [2, 8] {
        assert_eq!(run(threads), one, "{threads} threads");
    }
}
