//! The depth stage on small posed image pairs with arbitrary poses, intrinsics and matching
//! parameters: `depth_from_pair` returns a depth frame or a typed error about the input, never a
//! panic, a size mismatch or an out-of-order interval (those would be its own bugs).
#![no_main]

#[path = "../common/mod.rs"]
mod common;

use arbitrary::Arbitrary;
use common::{Metres, Pose};
use fuzzyvox::depth::{
    DepthParams, ForwardMotion, Frame, GrayImage, IntervalMethod, IntervalParams, MatchParams,
    depth_from_pair,
};
use fuzzyvox::{Error, PinholeIntrinsics};
use libfuzzer_sys::fuzz_target;
use nalgebra::Isometry3;

#[derive(Arbitrary, Debug)]
struct Input {
    width: u8,
    height: u8,
    /// Pixels of the reference image (repeated to fill it).
    texture: Vec<u8>,
    /// Horizontal shift of the other image, in pixels.
    shift: u8,
    focal: u16,
    centre: [i16; 2],
    other: Pose,
    min_disparity: i8,
    num_disparities: u8,
    window: [u8; 2],
    uniqueness_ratio: u8,
    left_right_tolerance: Option<u8>,
    range_tolerance: f32,
    min_contrast: f32,
    fixed_delta: bool,
    /// Match forward-motion pairs by plane sweep instead of refusing them.
    plane_sweep: bool,
    delta: f32,
    confidence_slope: f64,
    depth_range: Option<(Metres, Metres)>,
}

fuzz_target!(|input: Input| {
    let (width, height) = (
        u32::from(input.width % 40) + 1,
        u32::from(input.height % 24) + 1,
    );
    let texture = if input.texture.is_empty() {
        vec![0, 255, 17, 90]
    } else {
        input.texture
    };
    let pixel = |x: u32, y: u32| {
        let i = (y * 97 + x * 31) as usize % texture.len();
        f32::from(texture[i]) / 255.0
    };
    let shift = u32::from(input.shift % 16);
    let mut reference = Vec::new();
    let mut other = Vec::new();
    for y in 0..height {
        for x in 0..width {
            reference.push(pixel(x, y));
            other.push(pixel(x + shift, y));
        }
    }
    let reference = GrayImage::new(width, height, reference).expect("non-empty image");
    let other = GrayImage::new(width, height, other).expect("non-empty image");
    let f = f64::from(input.focal) * 0.25;
    let (cx, cy) = (
        f64::from(input.centre[0]) * 0.25,
        f64::from(input.centre[1]) * 0.25,
    );
    let Ok(k) = PinholeIntrinsics::new(width, height, f, f, cx, cy) else {
        return;
    };
    let Ok(reference) = Frame::new(reference, k, Isometry3::identity(), 0.0) else {
        return;
    };
    let Ok(other) = Frame::new(other, k, input.other.value(), 1.0) else {
        return;
    };
    let delta = input.delta;
    let params = DepthParams {
        matching: MatchParams {
            min_disparity: i32::from(input.min_disparity),
            num_disparities: u32::from(input.num_disparities),
            window_width: u32::from(input.window[0] % 17),
            window_height: u32::from(input.window[1] % 17),
            uniqueness_ratio: u32::from(input.uniqueness_ratio),
            left_right_tolerance: input.left_right_tolerance.map(u32::from),
            range_tolerance: input.range_tolerance,
            min_contrast: input.min_contrast,
        },
        interval: IntervalParams {
            method: if input.fixed_delta {
                IntervalMethod::FixedDelta { delta }
            } else {
                IntervalMethod::CostCurve { delta }
            },
            confidence_slope: input.confidence_slope,
        },
        depth_range: input.depth_range.map(|(a, b)| (a.value(), b.value())),
        forward_motion: if input.plane_sweep {
            ForwardMotion::PlaneSweep
        } else {
            ForwardMotion::Reject
        },
    };
    match depth_from_pair(&reference, &other, &params) {
        Ok(result) => {
            let image = result.frame.image();
            assert_eq!(image.depth().len(), result.disparity.disparity.len());
            assert!(
                image
                    .confidence()
                    .iter()
                    .all(|c| c.is_nan() || (0.0..=1.0).contains(c))
            );
        }
        Err(error @ (Error::SizeMismatch { .. } | Error::IntervalOrder { .. })) => {
            panic!("the depth stage broke its own invariant: {error}")
        }
        Err(_) => {}
    }
});
