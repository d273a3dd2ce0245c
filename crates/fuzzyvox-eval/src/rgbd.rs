//! Held-out evaluation on real depth: build a map from some frames, ray-cast it into frames it
//! has not seen, and compare the depth it predicts with the depth those frames measured.
//!
//! Real RGB-D sequences come without a scene model, so this is the fair test of a map there: a
//! map that erodes surfaces lets rays through them (too deep or no prediction), a map with
//! spurious voxels stops rays early (too shallow), and a good map predicts the next view.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use fuzzyvox_core::error::{Error, Result, finite};
use fuzzyvox_core::integrate::DepthFrame;
use fuzzyvox_core::map::{VoxelMap, cast_ray};
use fuzzyvox_core::measures::VoxelClass;

/// Which frames build the map and which are held out: every `every`-th frame (the 5th, 10th,
/// ... for `every = 5`) is held out, the others build.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct HoldoutSplit {
    /// Positions of the frames that build the map.
    pub build: Vec<usize>,
    /// Positions of the held-out frames.
    pub held_out: Vec<usize>,
}

impl HoldoutSplit {
    /// Splits `frames` frames, holding out every `every`-th; both parts must be non-empty.
    ///
    /// ```
    /// use fuzzyvox_eval::HoldoutSplit;
    /// let split = HoldoutSplit::new(10, 5)?;
    /// assert_eq!(split.held_out, vec![4, 9]);
    /// assert_eq!(split.build, vec![0, 1, 2, 3, 5, 6, 7, 8]);
    /// # Ok::<(), fuzzyvox_core::Error>(())
    /// ```
    pub fn new(frames: usize, every: usize) -> Result<Self> {
        if every < 2 {
            return Err(Error::InvalidParameter {
                name: "holdout",
                value: every as f64,
                expected: "hold out every K-th frame with K >= 2",
            });
        }
        let (held_out, build): (Vec<usize>, Vec<usize>) =
            (0..frames).partition(|i| i % every == every - 1);
        if held_out.is_empty() {
            return Err(Error::InvalidParameter {
                name: "holdout",
                value: every as f64,
                expected: "K no larger than the number of frames",
            });
        }
        Ok(Self { build, held_out })
    }
}

/// How predicted depth is compared with measured depth.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DepthCheckConfig {
    /// Use every `pixel_step`-th pixel in both directions (1: every pixel).
    pub pixel_step: u32,
    /// Rays are cast this far (metres along the ray); farther surfaces are not predicted.
    pub max_range: f64,
    /// Whether ambiguous voxels (both sets claim them) stop a ray as occupied ones do. Off by
    /// default: a ray stops at the first `Occupied` voxel, the class a planner treats as an
    /// obstacle in every map.
    pub stop_at_ambiguous: bool,
}

impl Default for DepthCheckConfig {
    fn default() -> Self {
        Self {
            pixel_step: 1,
            max_range: 8.0,
            stop_at_ambiguous: false,
        }
    }
}

impl DepthCheckConfig {
    /// Checks that the step is positive and the range finite and positive.
    pub fn validate(self) -> Result<Self> {
        if self.pixel_step == 0 {
            return Err(Error::InvalidParameter {
                name: "pixel_step",
                value: 0.0,
                expected: "a step of at least 1 pixel",
            });
        }
        finite("max_range", self.max_range)?;
        if self.max_range <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "max_range",
                value: self.max_range,
                expected: "a positive range in metres",
            });
        }
        Ok(self)
    }
}

/// Per-pixel depth errors of one map over held-out frames, accumulated frame by frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DepthErrors {
    /// Pixels with a measured depth (up to the cast range) that were checked.
    pub valid_pixels: usize,
    /// `predicted - measured` depth along the optical axis (metres) of every valid pixel
    /// whose ray met an occupied voxel, in pixel order: negative where the map stops the ray
    /// in front of the measured surface.
    pub errors: Vec<f32>,
}

impl DepthErrors {
    /// Casts a ray through `map` for every checked pixel of `frame` with a measured depth and
    /// records how far the depth of the first occupied voxel (the middle of the ray's chord
    /// through it, as depth along the optical axis) lies from the measured `P0`.
    ///
    /// Pixels are processed in parallel and their errors kept in pixel order, so the result is
    /// the same for any number of threads.
    pub fn add_frame(
        &mut self,
        map: &dyn VoxelMap,
        frame: &DepthFrame,
        config: &DepthCheckConfig,
    ) -> Result<()> {
        use rayon::prelude::*;
        let config = config.validate()?;
        let k = frame.intrinsics();
        let pose = frame.world_from_camera();
        let image = frame.image();
        let width = image.width() as usize;
        let step = config.pixel_step as usize;
        let origin = pose.translation.vector.into();
        let stop_at: &[VoxelClass] = if config.stop_at_ambiguous {
            &[VoxelClass::Occupied, VoxelClass::Ambiguous]
        } else {
            &[VoxelClass::Occupied]
        };
        let pixels: Vec<usize> = (0..image.height() as usize)
            .step_by(step)
            .flat_map(|v| (0..width).step_by(step).map(move |u| v * width + u))
            .filter(|&i| {
                let z = image.depth()[i];
                z.is_finite() && z > 0.0
            })
            .collect();
        let results: Vec<Result<Option<Option<f32>>>> = pixels
            .par_iter()
            .map(|&i| {
                let measured = f64::from(image.depth()[i]);
                let (u, v) = ((i % width) as f64, (i / width) as f64);
                // The ray through the pixel centre, with z = 1 in the camera frame: depth along
                // the optical axis is distance / |ray|.
                let in_camera = Vector3::new((u - k.cx()) / k.fx(), (v - k.cy()) / k.fy(), 1.0);
                let scale = in_camera.norm();
                if measured * scale > config.max_range {
                    return Ok(None);
                }
                let direction = pose.rotation * in_camera;
                let hit = cast_ray(map, &origin, &direction, config.max_range, stop_at)?;
                Ok(Some(hit.map(|h| (h.distance() / scale - measured) as f32)))
            })
            .collect();
        // Validate everything before changing the accumulator.
        let results: Vec<Option<Option<f32>>> = results.into_iter().collect::<Result<_>>()?;
        for r in results.into_iter().flatten() {
            self.valid_pixels += 1;
            self.errors.extend(r);
        }
        Ok(())
    }

    /// The summary at a map resolution of `resolution` metres.
    pub fn summary(&self, resolution: f64) -> DepthAgreement {
        let tolerance = 2.0 * resolution;
        let count = |keep: &dyn Fn(f64) -> bool| {
            self.errors.iter().filter(|&&e| keep(f64::from(e))).count()
        };
        let within = count(&|e| e.abs() <= tolerance);
        let near = count(&|e| e < -tolerance);
        let far = count(&|e| e > tolerance);
        let fraction = |n: usize| {
            if self.valid_pixels == 0 {
                f64::NAN
            } else {
                n as f64 / self.valid_pixels as f64
            }
        };
        DepthAgreement {
            valid_pixels: self.valid_pixels,
            predicted_pixels: self.errors.len(),
            predicted: fraction(self.errors.len()),
            median_abs_depth_error_m: median(self.errors.iter().map(|e| e.abs()).collect()),
            median_depth_error_m: median(self.errors.clone()),
            within_2_voxels: fraction(within),
            too_near: fraction(near),
            too_far: fraction(far),
        }
    }
}

/// The median of `values` (NaN when empty).
pub(super) fn median(mut values: Vec<f32>) -> f64 {
    values.sort_by(f32::total_cmp);
    match values.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => f64::from(values[n / 2]),
        n => 0.5 * (f64::from(values[n / 2 - 1]) + f64::from(values[n / 2])),
    }
}

/// How well a map predicts held-out depth.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DepthAgreement {
    /// Checked pixels with a measured depth.
    pub valid_pixels: usize,
    /// Of those, the pixels whose ray met an occupied voxel.
    pub predicted_pixels: usize,
    /// `predicted_pixels / valid_pixels`.
    pub predicted: f64,
    /// Median of `|predicted - measured|` depth over the predicted pixels (metres; NaN when
    /// none).
    pub median_abs_depth_error_m: f64,
    /// Median of `predicted - measured` over the predicted pixels (metres; negative: the map
    /// stops rays in front of the surfaces).
    pub median_depth_error_m: f64,
    /// Fraction of the valid pixels (predicted or not) whose predicted depth lies within two
    /// voxels of the measured depth: a pixel the map predicts nothing for counts as a miss.
    pub within_2_voxels: f64,
    /// Fraction of the valid pixels predicted more than two voxels too near (the ray stopped at
    /// a spurious or thickened surface).
    pub too_near: f64,
    /// Fraction predicted more than two voxels too far (the ray passed through the surface: an
    /// eroded or missing wall).
    pub too_far: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::integrate::{IntegrationOptions, IntervalDepthImage};
    use fuzzyvox_core::map::VoxelMapMut;
    use fuzzyvox_core::map::{FuzzyConfig, FuzzyMap};
    use fuzzyvox_core::{DepthFrame, PinholeIntrinsics};
    use fuzzyvox_io::rgbd::kinect_interval_image;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    /// A camera at `x` metres left of the origin looking along +z at a wall at z = 2 m.
    fn wall_frame(x: f64) -> DepthFrame {
        wall_frame_at(x, 2.0)
    }

    /// The same camera measuring a wall at `depth` metres.
    fn wall_frame_at(x: f64, depth: f32) -> DepthFrame {
        let k = PinholeIntrinsics::new(64, 48, 50.0, 50.0, 31.5, 23.5).unwrap();
        let pose =
            Isometry3::from_parts(Translation3::new(x, 0.0, 0.0), UnitQuaternion::identity());
        let depth = fuzzyvox_io::rgbd::DepthImage {
            width: 64,
            height: 48,
            depth: vec![depth; 64 * 48],
        };
        DepthFrame::new(k, pose, kinect_interval_image(&depth).unwrap()).unwrap()
    }

    #[test]
    fn split_holds_out_every_kth_frame() {
        let split = HoldoutSplit::new(12, 3).unwrap();
        assert_eq!(split.held_out, vec![2, 5, 8, 11]);
        assert_eq!(split.build.len(), 8);
        assert!(HoldoutSplit::new(12, 1).is_err());
        assert!(HoldoutSplit::new(3, 5).is_err());
    }

    #[test]
    fn a_map_of_the_wall_predicts_a_new_view_of_it() {
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.05).unwrap()).unwrap();
        for x in [-0.2, -0.1, 0.1, 0.2] {
            map.integrate_depth(&wall_frame(x), &IntegrationOptions::default())
                .unwrap();
        }
        let mut errors = DepthErrors::default();
        errors
            .add_frame(&map, &wall_frame(0.0), &DepthCheckConfig::default())
            .unwrap();
        let summary = errors.summary(0.05);
        assert_eq!(summary.valid_pixels, 64 * 48);
        assert!(summary.predicted > 0.95, "{summary:?}");
        assert!(summary.within_2_voxels > 0.95, "{summary:?}");
        assert!(summary.median_abs_depth_error_m < 0.05, "{summary:?}");
        let parts = summary.within_2_voxels + summary.too_near + summary.too_far;
        assert!((parts - summary.predicted).abs() < 1e-12, "{summary:?}");
        // A frame that measures the wall 0.5 m farther: the map stops every ray too near.
        let mut farther = DepthErrors::default();
        farther
            .add_frame(&map, &wall_frame_at(0.0, 2.5), &DepthCheckConfig::default())
            .unwrap();
        let summary = farther.summary(0.05);
        assert!(summary.too_near > 0.95, "{summary:?}");
        assert!(
            (summary.median_depth_error_m + 0.5).abs() < 0.05,
            "{summary:?}"
        );
        assert_eq!(summary.too_far, 0.0);
    }

    #[test]
    fn an_empty_map_predicts_nothing_and_counts_every_pixel_as_a_miss() {
        let map = FuzzyMap::new(FuzzyConfig::new(0.05).unwrap()).unwrap();
        let mut errors = DepthErrors::default();
        let config = DepthCheckConfig {
            pixel_step: 4,
            max_range: 5.0,
            ..DepthCheckConfig::default()
        };
        errors.add_frame(&map, &wall_frame(0.0), &config).unwrap();
        let summary = errors.summary(0.05);
        assert_eq!(summary.valid_pixels, 16 * 12);
        assert_eq!(summary.predicted_pixels, 0);
        assert_eq!(summary.within_2_voxels, 0.0);
        assert!(summary.median_abs_depth_error_m.is_nan());
    }

    #[test]
    fn pixels_beyond_the_cast_range_and_bad_configs_are_left_out() {
        let map = FuzzyMap::new(FuzzyConfig::new(0.05).unwrap()).unwrap();
        let mut errors = DepthErrors::default();
        let short = DepthCheckConfig {
            pixel_step: 1,
            max_range: 1.0,
            ..DepthCheckConfig::default()
        };
        errors.add_frame(&map, &wall_frame(0.0), &short).unwrap();
        assert_eq!(errors.valid_pixels, 0);
        for bad in [
            DepthCheckConfig {
                pixel_step: 0,
                ..DepthCheckConfig::default()
            },
            DepthCheckConfig {
                max_range: f64::NAN,
                ..DepthCheckConfig::default()
            },
        ] {
            assert!(errors.add_frame(&map, &wall_frame(0.0), &bad).is_err());
        }
        assert_eq!(errors, DepthErrors::default());
        // Invalid pixels are not checked.
        let k = PinholeIntrinsics::new(2, 1, 1.0, 1.0, 0.5, 0.0).unwrap();
        let image =
            IntervalDepthImage::from_depth(2, 1, &[f32::NAN, 0.0], |z| (z, z, 1.0)).unwrap();
        let frame = DepthFrame::new(k, Isometry3::identity(), image).unwrap();
        errors
            .add_frame(&map, &frame, &DepthCheckConfig::default())
            .unwrap();
        assert_eq!(errors.valid_pixels, 0);
    }
}
