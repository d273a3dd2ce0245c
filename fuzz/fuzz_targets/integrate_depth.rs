//! Interval depth image integration with arbitrary floats, intrinsics and poses, into one of
//! the three maps (the input chooses): construction fails with a typed error, or the
//! integration succeeds with memberships in [0, 1] or fails and leaves the map's bytes
//! unchanged.
#![no_main]

#[path = "../common/mod.rs"]
mod common;

use arbitrary::Arbitrary;
use common::{Metres, Operator, Pose, Resolution};
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, DepthFrame, FuzzyConfig, FuzzyMap, IntegrationOptions,
    IntervalDepthImage, LogOddsConfig, LogOddsMap, PinholeIntrinsics, PointCloud, VoxelMapMut,
};
use libfuzzer_sys::fuzz_target;
use nalgebra::Point3;

/// Farthest reach, in voxels, of a frame worth integrating here (see the skip below).
const REACH_VOXELS: f64 = 400.0;

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Pixel {
    /// Any four floats.
    Raw([f32; 4]),
    /// Depth in centimetres, the interval's half-widths in millimetres, confidence in 1/255.
    Sane {
        depth: u16,
        below: u8,
        above: u8,
        confidence: u8,
    },
}

impl Pixel {
    fn planes(self) -> [f32; 4] {
        match self {
            Pixel::Raw(v) => v,
            Pixel::Sane {
                depth,
                below,
                above,
                confidence,
            } => {
                let z = f32::from(depth) * 0.01;
                [
                    z - f32::from(below) * 1e-3,
                    z,
                    z + f32::from(above) * 1e-3,
                    f32::from(confidence) / 255.0,
                ]
            }
        }
    }
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Focal {
    Raw(f64),
    Pixels(u16),
}

impl Focal {
    fn value(self) -> f64 {
        match self {
            Focal::Raw(v) => v,
            Focal::Pixels(p) => f64::from(p) * 0.125,
        }
    }
}

#[derive(Arbitrary, Debug)]
struct Input {
    width: u8,
    height: u8,
    focal: [Focal; 2],
    centre: [Focal; 2],
    pose: Pose,
    pixels: Vec<Pixel>,
    resolution: Resolution,
    operator: Operator,
    max_range: Option<Metres>,
    /// Which map: fuzzy, log-odds or alpha-cut.
    model: u8,
}

fuzz_target!(|input: Input| {
    let (width, height) = (
        u32::from(input.width % 12) + 1,
        u32::from(input.height % 12) + 1,
    );
    let n = (width * height) as usize;
    let mut pixels = input.pixels.clone();
    pixels.resize(
        n,
        Pixel::Sane {
            depth: 300,
            below: 20,
            above: 30,
            confidence: 200,
        },
    );
    let mut planes = [vec![], vec![], vec![], vec![]];
    for pixel in &pixels {
        for (plane, value) in planes.iter_mut().zip(pixel.planes()) {
            plane.push(value);
        }
    }
    let [near, depth, far, confidence] = planes;
    let Ok(image) = IntervalDepthImage::new(width, height, near, depth, far, confidence) else {
        return;
    };
    let [fx, fy] = input.focal.map(Focal::value);
    let [cx, cy] = input.centre.map(Focal::value);
    let Ok(k) = PinholeIntrinsics::new(width, height, fx, fy, cx, cy) else {
        return;
    };
    let Ok(frame) = DepthFrame::new(k, input.pose.value(), image) else {
        return;
    };
    let options = IntegrationOptions {
        max_range: input.max_range.map(Metres::value),
    };
    let res = input.resolution.value();
    // Keep each input cheap, so the fuzzer explores more of them: skip frames whose farthest
    // valid pixel lies more than REACH_VOXELS away (their frustum is large but ordinary work;
    // absurd reaches are refused by the integrator's block limit and are covered by tests).
    let reach = frame
        .image()
        .far()
        .iter()
        .copied()
        .filter(|z| z.is_finite() && *z > 0.0)
        .fold(0.0f64, |a, z| a.max(f64::from(z)));
    let reach = options.max_range.map_or(reach, |max| reach.min(max));
    if reach / res > REACH_VOXELS {
        return;
    }
    // One map kind per input: three times the inputs per second.
    match input.model % 3 {
        0 => {
            if let (Ok(config), Some(operator)) = (FuzzyConfig::new(res), input.operator.tconorm())
            {
                let map = FuzzyMap::new(config.with_operator(operator)).expect("valid config");
                check(map, &frame, &options, |m| m.to_bytes());
            }
        }
        1 => {
            if let Ok(config) = LogOddsConfig::new(res) {
                let map = LogOddsMap::new(config).expect("valid config");
                check(map, &frame, &options, |m| m.to_bytes());
            }
        }
        _ => {
            if let Ok(config) = AlphaConfig::new(res) {
                let map = AlphaCutMap::new(config).expect("valid config");
                check(map, &frame, &options, |m| m.to_bytes());
            }
        }
    }
});

/// Integrates a small fixed scan, then the frame: an error must leave the bytes unchanged.
fn check<M: VoxelMapMut>(
    mut map: M,
    frame: &DepthFrame,
    options: &IntegrationOptions,
    bytes: impl Fn(&M) -> Vec<u8>,
) {
    let step = map.resolution().size();
    let seed = PointCloud::new(Point3::origin(), vec![Point3::new(4.0 * step, step, 0.0)])
        .expect("finite origin");
    map.integrate_cloud(&seed, &IntegrationOptions::default())
        .expect("a short scan integrates");
    let before = bytes(&map);
    match map.integrate_depth(frame, options) {
        Ok(stats) => {
            assert!(stats.integrated + stats.skipped <= frame.image().depth().len());
            for (_, m) in map.cells() {
                assert!((0.0..=1.0).contains(&m.occupied), "{m:?}");
                assert!((0.0..=1.0).contains(&m.free), "{m:?}");
            }
        }
        Err(_) => assert!(
            bytes(&map) == before,
            "a failed integration changed the map"
        ),
    }
}
