//! Depth intervals and confidence from disparities.
//!
//! `P0` is the depth of the best disparity. `P-` (near) and `P+` (far) come from a disparity
//! interval around it: the paper's fixed `d ± δ`, or the cost-curve range `[low - δ, high + δ]`
//! (every disparity whose cost is within the matcher's tolerance of the best, widened by `δ`).
//! Larger disparities are nearer, so `P-` uses the upper end. A far end at or beyond infinity
//! (`d + doffs <= 0`) leaves `P+` undefined and the pixel without confidence, as in the paper.
//!
//! Confidence (paper eq. 10): `C = max(100 - a (P+ - P-), 0) · Q`, stored divided by 100.

use fuzzyvox_core::image::StereoGeometry;

use super::params::DisparityMap;
use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::IntervalDepthImage;

/// How `P-` and `P+` are derived from the disparity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntervalMethod {
    /// The paper's fixed perturbation: `d ± δ` pixels.
    FixedDelta {
        /// `δ` in pixels (≥ 0).
        delta: f32,
    },
    /// The cost-curve range `[low - δ, high + δ]`.
    CostCurve {
        /// `δ` in pixels (≥ 0).
        delta: f32,
    },
}

impl IntervalMethod {
    fn delta(&self) -> f32 {
        match *self {
            Self::FixedDelta { delta } | Self::CostCurve { delta } => delta,
        }
    }
}

/// Interval and confidence settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntervalParams {
    /// How the interval is formed.
    pub method: IntervalMethod,
    /// `a` in eq. 10, confidence lost per metre of interval width (default 5).
    pub confidence_slope: f64,
}

impl Default for IntervalParams {
    fn default() -> Self {
        Self {
            method: IntervalMethod::CostCurve { delta: 1.0 },
            confidence_slope: 5.0,
        }
    }
}

impl IntervalParams {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        let delta = self.method.delta();
        if !(delta.is_finite() && delta >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "delta",
                value: f64::from(delta),
                expected: "a finite disparity perturbation >= 0 px",
            });
        }
        if !(self.confidence_slope.is_finite() && self.confidence_slope >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "confidence_slope",
                value: self.confidence_slope,
                expected: "a finite slope >= 0 per metre",
            });
        }
        Ok(())
    }
}

/// The confidence of eq. 10 in `[0, 1]`: `max(100 - a · width, 0) · Q / 100`.
pub fn confidence(width: f64, slope: f64, quality: f64) -> f32 {
    ((100.0 - slope * width).max(0.0) * quality.clamp(0.0, 1.0) / 100.0) as f32
}

/// Turns a disparity map into an interval depth image in the rectified reference camera, with
/// `quality` the pair's `Q_ABD`.
pub fn interval_image(
    disparities: &DisparityMap,
    geometry: &StereoGeometry,
    params: &IntervalParams,
    quality: f64,
) -> Result<IntervalDepthImage> {
    params.validate()?;
    let n = disparities.width as usize * disparities.height as usize;
    // The map's fields are public, so check that its planes agree before indexing them.
    for (what, plane) in [
        ("disparity plane", &disparities.disparity),
        ("range_low plane", &disparities.range_low),
        ("range_high plane", &disparities.range_high),
        ("cost plane", &disparities.cost),
    ] {
        if plane.len() != n {
            return Err(Error::SizeMismatch {
                what,
                expected: n,
                found: plane.len(),
            });
        }
    }
    let mut near = vec![f32::NAN; n];
    let mut depth = vec![f32::NAN; n];
    let mut far = vec![f32::NAN; n];
    let mut conf = vec![f32::NAN; n];
    let mut reliability = vec![f32::NAN; n];
    let delta = f64::from(params.method.delta());
    for i in 0..n {
        let d = f64::from(disparities.disparity[i]);
        let Some(z) = geometry.depth(d) else { continue };
        let (low, high) = match params.method {
            IntervalMethod::FixedDelta { .. } => (d - delta, d + delta),
            IntervalMethod::CostCurve { .. } => (
                f64::from(disparities.range_low[i]) - delta,
                f64::from(disparities.range_high[i]) + delta,
            ),
        };
        // The sub-pixel disparity may sit half a pixel outside the integer range; keep it inside
        // so that P- <= P0 <= P+ holds.
        let (low, high) = (low.min(d), high.max(d));
        let Some(z_near) = geometry.depth(high) else {
            continue;
        };
        depth[i] = z as f32;
        near[i] = (z_near as f32).min(depth[i]);
        reliability[i] = match_reliability(disparities.cost[i]);
        if let Some(z_far) = geometry.depth(low).filter(|z| z.is_finite()) {
            far[i] = (z_far as f32).max(depth[i]);
            conf[i] = confidence(z_far - z_near, params.confidence_slope, quality);
        } else {
            // P+ undefined: no confidence (paper).
            conf[i] = 0.0;
        }
    }
    IntervalDepthImage::new(
        disparities.width,
        disparities.height,
        near,
        depth,
        far,
        conf,
    )?
    .with_reliability(reliability)
}

/// Window costs (fractions of the largest) up to which a match counts as fully reliable, and
/// from which it counts as not reliable at all: see [`match_reliability`].
pub const RELIABLE_COST: (f32, f32) = (0.15, 0.30);

/// How likely a match that passed the matcher's uniqueness and left-right checks is right, for
/// the dual evidence model's free space: 1 up to a best window cost of 0.15 of the largest,
/// falling linearly to 0 at 0.30. Measured on the simulator (`examples/sim_depth_error.rs`,
/// `docs/concepts.md`): the true surface lies in front of `P-` for at most 0.25 % of pixels
/// below 0.15, but for 25 % (0.20–0.30) and 63 % (above 0.30) of the forward-motion plane
/// sweep's pixels, where the windows no longer agree (the ground at a grazing angle); it does
/// not rise as the pair's `Q_ABD` falls, which the interval's width and the confidence already
/// carry, so the reliability does not use it.
pub fn match_reliability(cost: f32) -> f32 {
    let (low, high) = RELIABLE_COST;
    if cost.is_nan() {
        return 0.0;
    }
    ((high - cost) / (high - low)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::geometry::PinholeIntrinsics;
    use nalgebra::Isometry3;

    fn geometry() -> StereoGeometry {
        let k = PinholeIntrinsics::new(3, 1, 100.0, 100.0, 1.0, 0.0).unwrap();
        StereoGeometry::new(k, Isometry3::identity(), 0.5, 0.0).unwrap()
    }

    fn map(d: [f32; 3], low: [f32; 3], high: [f32; 3]) -> DisparityMap {
        DisparityMap {
            width: 3,
            height: 1,
            disparity: d.to_vec(),
            range_low: low.to_vec(),
            range_high: high.to_vec(),
            cost: vec![0.1; 3],
        }
    }

    #[test]
    fn fixed_and_curve_intervals_and_confidence() {
        let g = geometry();
        let m = map(
            [10.0, 0.5, f32::NAN],
            [8.0, 0.0, f32::NAN],
            [12.0, 1.0, f32::NAN],
        );
        let fixed = IntervalParams {
            method: IntervalMethod::FixedDelta { delta: 1.0 },
            confidence_slope: 5.0,
        };
        let image = interval_image(&m, &g, &fixed, 0.8).unwrap();
        // Z = 50 / d: P0 = 5, P- = 50/11, P+ = 50/9.
        assert!((image.depth()[0] - 5.0).abs() < 1e-6);
        assert!((image.near()[0] - 50.0 / 11.0).abs() < 1e-5);
        assert!((image.far()[0] - 50.0 / 9.0).abs() < 1e-5);
        let width = 50.0 / 9.0 - 50.0 / 11.0;
        assert!(
            (image.confidence()[0] - ((100.0 - 5.0 * width) * 0.8 / 100.0) as f32).abs() < 1e-6
        );
        // d - δ <= 0: P+ undefined, no confidence.
        assert!(image.far()[1].is_nan() && image.confidence()[1] == 0.0);
        assert!(image.depth()[2].is_nan());
        let curve = IntervalParams::default();
        let image = interval_image(&m, &g, &curve, 1.0).unwrap();
        assert!((image.near()[0] - 50.0 / 13.0).abs() < 1e-5);
        assert!((image.far()[0] - 50.0 / 7.0).abs() < 1e-5);
    }

    #[test]
    fn reliability_follows_the_match_cost_not_the_interval() {
        assert_eq!(match_reliability(0.05), 1.0);
        assert_eq!(match_reliability(0.15), 1.0);
        assert!((match_reliability(0.225) - 0.5).abs() < 1e-6);
        assert_eq!(match_reliability(0.3), 0.0);
        assert_eq!(match_reliability(0.9), 0.0);
        assert_eq!(match_reliability(f32::NAN), 0.0);
        let g = geometry();
        // Pixel 1's far end lies at infinity: no P+ and no confidence, but a reliability.
        let image = interval_image(
            &map(
                [10.0, 0.5, f32::NAN],
                [8.0, 0.0, f32::NAN],
                [12.0, 1.0, f32::NAN],
            ),
            &g,
            &IntervalParams::default(),
            0.1,
        )
        .unwrap();
        let reliability = image.reliability().unwrap();
        assert_eq!(reliability[0], 1.0);
        assert_eq!(reliability[1], 1.0);
        assert!(image.far()[1].is_nan() && image.confidence()[1] == 0.0);
        assert!(reliability[2].is_nan());
    }

    #[test]
    fn inconsistent_maps_and_parameters_are_errors() {
        let g = geometry();
        let mut m = map([10.0; 3], [9.0; 3], [11.0; 3]);
        m.range_low.pop();
        assert!(matches!(
            interval_image(&m, &g, &IntervalParams::default(), 1.0),
            Err(Error::SizeMismatch { .. })
        ));
        let bad = IntervalParams {
            method: IntervalMethod::CostCurve { delta: -1.0 },
            confidence_slope: 5.0,
        };
        assert!(interval_image(&map([1.0; 3], [1.0; 3], [1.0; 3]), &g, &bad, 1.0).is_err());
    }
}
