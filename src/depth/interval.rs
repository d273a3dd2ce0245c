//! Depth intervals and confidence from disparities.
//!
//! `P0` is the depth of the best disparity. `P-` (near) and `P+` (far) come from a disparity
//! interval around it: the paper's fixed `d ± δ`, or the cost-curve range `[low - δ, high + δ]`
//! (every disparity whose cost is within the matcher's tolerance of the best, widened by `δ`).
//! Larger disparities are nearer, so `P-` uses the upper end. A far end at or beyond infinity
//! (`d + doffs <= 0`) leaves `P+` undefined and the pixel without confidence, as in the paper.
//!
//! Confidence (paper eq. 10): `C = max(100 - a (P+ - P-), 0) · Q`, stored divided by 100.

use super::matching::DisparityMap;
use super::rectify::StereoGeometry;
use crate::error::{Error, Result};
use crate::integrate::IntervalDepthImage;

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
    let n = disparities.disparity.len();
    let mut near = vec![f32::NAN; n];
    let mut depth = vec![f32::NAN; n];
    let mut far = vec![f32::NAN; n];
    let mut conf = vec![f32::NAN; n];
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
    )
}
