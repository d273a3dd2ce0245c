//! How good the depth stage's own depth is, against a depth sensor's reading of the same scene:
//! each sensor pixel is carried into the depth image's camera (the sensor's camera need not be
//! the same, nor registered to it), the nearest reading per pixel kept, and every pixel with
//! both compared: the relative error of `P0`, and whether the sensor's depth lies inside
//! `[P-, P+]`. Summaries over all pixels and over the most confident half tell whether the
//! confidence ranks the depth as it should.

use nalgebra::Point3;
use serde::Serialize;

use super::rgbd::median;
use fuzzyvox_core::integrate::{DepthFrame, IntervalDepthImage};

/// One compared pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Comparison {
    confidence: f32,
    relative_error: f32,
    inside: bool,
}

/// Per-pixel comparisons of depth-stage images with sensor depth, accumulated image by image.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DepthStageErrors {
    compared: Vec<Comparison>,
    images: usize,
}

/// The summary of [`DepthStageErrors`]; fractions, 0.10 meaning 10%.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DepthStageSummary {
    /// Depth images compared.
    pub images: usize,
    /// Pixels with both an estimate and a sensor reading.
    pub pixels: usize,
    /// Median of `|P0 - z| / z` over them (`z` the sensor's depth).
    pub median_rel_error: f64,
    /// Fraction of them whose sensor depth lies in `[P-, P+]`.
    pub interval_coverage: f64,
    /// The median confidence, the threshold of the most confident half.
    pub median_confidence: f64,
    /// Pixels in the most confident half (confidence above the median).
    pub pixels_top50: usize,
    /// `median_rel_error` over the most confident half.
    pub median_rel_error_top50: f64,
    /// `interval_coverage` over the most confident half.
    pub interval_coverage_top50: f64,
    /// The distribution of `|P0 - z| / z` over all compared pixels.
    pub rel_error_quantiles: ErrorQuantiles,
}

/// Quantiles of a relative error, NaN when nothing was compared.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ErrorQuantiles {
    /// 10th percentile.
    pub p10: f64,
    /// 25th percentile.
    pub p25: f64,
    /// The median.
    pub p50: f64,
    /// 75th percentile.
    pub p75: f64,
    /// 90th percentile.
    pub p90: f64,
}

impl ErrorQuantiles {
    /// The quantiles of `values` (nearest rank on the sorted values).
    fn of(mut values: Vec<f32>) -> Self {
        values.sort_by(f32::total_cmp);
        let at = |q: f64| {
            if values.is_empty() {
                return f64::NAN;
            }
            let rank = (q * (values.len() - 1) as f64).round() as usize;
            f64::from(values[rank])
        };
        Self {
            p10: at(0.10),
            p25: at(0.25),
            p50: at(0.50),
            p75: at(0.75),
            p90: at(0.90),
        }
    }
}

/// One group of [`DepthStageErrors::by_confidence`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ConfidenceBin {
    /// Mean confidence of the group.
    pub confidence: f64,
    /// Pixels in it.
    pub pixels: usize,
    /// Median of `|P0 - z| / z`.
    pub median_rel_error: f64,
    /// Fraction whose true depth lies in `[P-, P+]`.
    pub interval_coverage: f64,
}

impl DepthStageErrors {
    /// Compares one depth-stage image with a sensor's depth (`sensor`'s `P0` is its reading;
    /// pixels without one are skipped). Where several readings land on one pixel of the
    /// estimate's camera, the nearest is the one that camera sees.
    pub fn add(&mut self, estimate: &DepthFrame, sensor: &DepthFrame) {
        let k = estimate.intrinsics();
        let (width, height) = (k.width() as usize, k.height() as usize);
        let mut nearest = vec![f32::INFINITY; width * height];
        let camera_from_sensor =
            estimate.world_from_camera().inverse() * sensor.world_from_camera();
        let ks = sensor.intrinsics();
        let readings = sensor.image();
        let sensor_width = readings.width() as usize;
        for (i, &z) in readings.depth().iter().enumerate() {
            if !(z.is_finite() && z > 0.0) {
                continue;
            }
            let (u, v) = ((i % sensor_width) as f64, (i / sensor_width) as f64);
            let z = f64::from(z);
            let in_sensor =
                Point3::new((u - ks.cx()) / ks.fx() * z, (v - ks.cy()) / ks.fy() * z, z);
            let p = camera_from_sensor * in_sensor;
            let Some((x, y)) = k.pixel_of(&p) else {
                continue;
            };
            let at = y as usize * width + x as usize;
            if let Some(slot) = nearest.get_mut(at) {
                *slot = slot.min(p.z as f32);
            }
        }
        self.add_aligned(estimate.image(), &nearest);
    }

    /// Compares a depth-stage image with true depths already in its camera, pixel for pixel
    /// (`truth` row-major like the image; non-finite or non-positive entries are skipped).
    pub fn add_aligned(&mut self, image: &IntervalDepthImage, truth: &[f32]) {
        for (i, &truth) in truth.iter().enumerate() {
            let depth = image.depth().get(i).copied().unwrap_or(f32::NAN);
            if !(truth.is_finite() && truth > 0.0 && depth.is_finite() && depth > 0.0) {
                continue;
            }
            let near = image.near().get(i).copied().unwrap_or(depth);
            let far = image.far().get(i).copied().unwrap_or(depth);
            let far = if far.is_finite() { far } else { f32::INFINITY };
            self.compared.push(Comparison {
                confidence: image.confidence().get(i).copied().unwrap_or_default(),
                relative_error: (depth - truth).abs() / truth,
                inside: near <= truth && truth <= far,
            });
        }
        self.images += 1;
    }

    /// Accuracy against confidence: the compared pixels sorted by confidence and cut into
    /// `bins` groups of equal size (fewer when there are fewer pixels), each with its mean
    /// confidence, median relative error and interval coverage. A confidence that ranks depth
    /// well gives errors that fall as confidence rises.
    pub fn by_confidence(&self, bins: usize) -> Vec<ConfidenceBin> {
        let mut sorted = self.compared.clone();
        sorted.sort_by(|a, b| a.confidence.total_cmp(&b.confidence));
        let bins = bins.clamp(1, sorted.len().max(1));
        (0..bins)
            .filter_map(|b| {
                let part = &sorted[b * sorted.len() / bins..(b + 1) * sorted.len() / bins];
                if part.is_empty() {
                    return None;
                }
                let (error, coverage) = figures(part);
                Some(ConfidenceBin {
                    confidence: part.iter().map(|c| f64::from(c.confidence)).sum::<f64>()
                        / part.len() as f64,
                    pixels: part.len(),
                    median_rel_error: error,
                    interval_coverage: coverage,
                })
            })
            .collect()
    }

    /// The summary so far (medians NaN when nothing was compared).
    pub fn summary(&self) -> DepthStageSummary {
        let confidences: Vec<f32> = self.compared.iter().map(|c| c.confidence).collect();
        let median_confidence = median(confidences);
        let top: Vec<Comparison> = self
            .compared
            .iter()
            .copied()
            .filter(|c| f64::from(c.confidence) > median_confidence)
            .collect();
        let (all_error, all_inside) = figures(&self.compared);
        let (top_error, top_inside) = figures(&top);
        DepthStageSummary {
            images: self.images,
            pixels: self.compared.len(),
            median_rel_error: all_error,
            interval_coverage: all_inside,
            median_confidence,
            pixels_top50: top.len(),
            median_rel_error_top50: top_error,
            interval_coverage_top50: top_inside,
            rel_error_quantiles: ErrorQuantiles::of(
                self.compared.iter().map(|c| c.relative_error).collect(),
            ),
        }
    }
}

/// Median relative error and interval coverage of `compared`.
fn figures(compared: &[Comparison]) -> (f64, f64) {
    let errors = compared.iter().map(|c| c.relative_error).collect();
    let inside = compared.iter().filter(|c| c.inside).count();
    let coverage = if compared.is_empty() {
        f64::NAN
    } else {
        inside as f64 / compared.len() as f64
    };
    (median(errors), coverage)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::geometry::PinholeIntrinsics;
    use nalgebra::{Isometry3, Translation3};

    fn frame(depth: f32, near: f32, far: f32, confidence: f32, x: f64) -> DepthFrame {
        let k = PinholeIntrinsics::new(8, 6, 10.0, 10.0, 4.0, 3.0).unwrap();
        let n = 48;
        let image = IntervalDepthImage::new(
            8,
            6,
            vec![near; n],
            vec![depth; n],
            vec![far; n],
            vec![confidence; n],
        )
        .unwrap();
        DepthFrame::new(
            k,
            Isometry3::from_parts(Translation3::new(x, 0.0, 0.0), Default::default()),
            image,
        )
        .unwrap()
    }

    #[test]
    fn compares_p0_and_intervals_with_the_sensor() {
        // A wall 2 m ahead, seen by the sensor; the estimate says 2.2 m with [1.9, 2.5].
        let sensor = frame(2.0, 2.0, 2.0, 1.0, 0.0);
        let mut errors = DepthStageErrors::default();
        errors.add(&frame(2.2, 1.9, 2.5, 0.8, 0.0), &sensor);
        let s = errors.summary();
        assert_eq!((s.images, s.pixels), (1, 48));
        assert!((s.median_rel_error - 0.1).abs() < 1e-6);
        assert_eq!(s.interval_coverage, 1.0);
        // A second, less confident image that misses: the top half is the confident one.
        errors.add(&frame(3.0, 2.8, 3.2, 0.2, 0.0), &sensor);
        let s = errors.summary();
        assert_eq!(s.pixels, 96);
        assert_eq!(s.pixels_top50, 48);
        assert!((s.median_rel_error_top50 - 0.1).abs() < 1e-6);
        assert_eq!(s.interval_coverage_top50, 1.0);
        assert_eq!(s.interval_coverage, 0.5);
        // Half the pixels are 10% off, half 50%: the quantiles say so.
        let q = s.rel_error_quantiles;
        assert!(
            (q.p10 - 0.1).abs() < 1e-6 && (q.p25 - 0.1).abs() < 1e-6,
            "{q:?}"
        );
        assert!(
            (q.p75 - 0.5).abs() < 1e-6 && (q.p90 - 0.5).abs() < 1e-6,
            "{q:?}"
        );
        // A sensor moved sideways still lands on the estimate's pixels (fewer of them).
        let mut moved = DepthStageErrors::default();
        moved.add(
            &frame(2.0, 1.9, 2.1, 0.5, 0.0),
            &frame(2.0, 2.0, 2.0, 1.0, 0.2),
        );
        let s = moved.summary();
        assert!(s.pixels > 0 && s.pixels < 48, "{}", s.pixels);
        assert!(s.median_rel_error < 1e-6);
        // Nothing compared.
        let empty = DepthStageErrors::default().summary();
        assert!(empty.median_rel_error.is_nan() && empty.interval_coverage.is_nan());
        assert!(empty.rel_error_quantiles.p90.is_nan());
    }
}
