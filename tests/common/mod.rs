//! Helpers shared by the integration tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

use fuzzyvox::{DepthFrame, IntervalDepthImage, PinholeIntrinsics, PointCloud};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// The shared data folder from `FUZZYVOX_DATA`.
///
/// Unset: prints that the test is skipped and returns `None`. Set but missing: fails the test,
/// so that CI never passes silently without its data.
pub fn data_dir(test: &str) -> Option<PathBuf> {
    match std::env::var_os("FUZZYVOX_DATA") {
        None => {
            eprintln!("SKIPPED {test}: FUZZYVOX_DATA is not set (see README, Tests)");
            None
        }
        Some(dir) => {
            let dir = PathBuf::from(dir);
            assert!(
                dir.is_dir(),
                "FUZZYVOX_DATA={} is set but is not a directory",
                dir.display()
            );
            Some(dir)
        }
    }
}

/// A small deterministic pseudo-random generator (SplitMix64), so tests need no extra crate.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A scan of a room-like box (walls at ±4 m, floor and ceiling) from `origin`, with
/// confidences that fall with range.
pub fn room_scan(origin: Point3<f64>, rays: usize, seed: u64) -> PointCloud {
    let mut rng = Rng::new(seed);
    let mut points = Vec::with_capacity(rays);
    let mut confidence = Vec::with_capacity(rays);
    for _ in 0..rays {
        let theta = rng.uniform(0.0, std::f64::consts::TAU);
        let z = rng.uniform(-0.9, 0.9);
        let r = (1.0 - z * z).sqrt();
        let dir = Vector3::new(r * theta.cos(), r * theta.sin(), z);
        // Distance to the box [-4, 4] × [-4, 4] × [-1, 3].
        let mut t = f64::INFINITY;
        for axis in 0..3 {
            let (lo, hi) = if axis == 2 { (-1.0, 3.0) } else { (-4.0, 4.0) };
            let d = dir[axis];
            if d > 1e-9 {
                t = t.min((hi - origin[axis]) / d);
            } else if d < -1e-9 {
                t = t.min((lo - origin[axis]) / d);
            }
        }
        let noise = rng.uniform(-0.02, 0.02);
        points.push(origin + dir * (t + noise));
        confidence.push((1.0 - t / 12.0).clamp(0.05, 1.0) as f32);
    }
    PointCloud::new(origin, points)
        .unwrap()
        .with_confidence(confidence)
        .unwrap()
}

/// A 64×48 camera at `position` looking along +x (world) at a wall at x = `wall_x`, with a depth
/// interval that widens with range.
pub fn wall_frame(position: Point3<f64>, wall_x: f64) -> DepthFrame {
    let k = PinholeIntrinsics::new(64, 48, 40.0, 40.0, 31.5, 23.5).unwrap();
    // Camera z (forward) = world x, camera x (right) = world -y, camera y (down) = world -z.
    let rotation = UnitQuaternion::from_basis_unchecked(&[
        Vector3::new(0.0, -1.0, 0.0),
        Vector3::new(0.0, 0.0, -1.0),
        Vector3::new(1.0, 0.0, 0.0),
    ]);
    let pose = Isometry3::from_parts(Translation3::from(position.coords), rotation);
    let depth = (wall_x - position.x) as f32;
    let mut near = vec![depth - 0.05 * depth; 64 * 48];
    let mut far = vec![depth + 0.05 * depth; 64 * 48];
    let mut values = vec![depth; 64 * 48];
    let mut confidence = vec![0.9; 64 * 48];
    // A few invalid pixels, as real depth has.
    for i in (0..64 * 48).step_by(97) {
        values[i] = f32::NAN;
        near[i] = f32::NAN;
        far[i] = f32::NAN;
        confidence[i] = f32::NAN;
    }
    let image = IntervalDepthImage::new(64, 48, near, values, far, confidence).unwrap();
    DepthFrame::new(k, pose, image).unwrap()
}
