//! The matcher's parameters and its result.

pub use fuzzyvox_core::image::MAX_DISPARITIES;

use fuzzyvox_core::error::{Error, Result};

/// Largest supported aggregation window side; keeps window sums inside `i16`.
pub const MAX_WINDOW: u32 = 15;

/// The default [`MatchParams::min_contrast`]: 0.5 %. The simulator's sky has a window contrast
/// of 0.1-0.3 % (a brightness gradient and sensor noise), its textured surfaces 1.2 % and up
/// (5th percentile of the matched pixels in the closed-loop flights); an 8-bit image region
/// whose spread is under 0.6 grey levels at mid-grey is below it.
pub const DEFAULT_MIN_CONTRAST: f32 = 0.004;

/// Matching parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct MatchParams {
    /// Smallest disparity searched (pixels); may be negative.
    pub min_disparity: i32,
    /// Number of disparities searched, `min_disparity .. min_disparity + num_disparities`.
    pub num_disparities: u32,
    /// Aggregation window width (odd, at most [`MAX_WINDOW`]).
    pub window_width: u32,
    /// Aggregation window height (odd, at most [`MAX_WINDOW`]).
    pub window_height: u32,
    /// Uniqueness margin in percent, as OpenCV's `uniquenessRatio`: a match is dropped when a
    /// disparity more than one pixel away from the best costs less than
    /// `best · 100 / (100 - ratio)`. 0 disables the test.
    pub uniqueness_ratio: u32,
    /// Left-right check: the right image's best match must come back to within this many
    /// pixels; `None` disables the check.
    pub left_right_tolerance: Option<u32>,
    /// Relative tolerance of the cost-curve range: every disparity whose aggregated cost is at
    /// most `best · (1 + tolerance)` lies in the range.
    pub range_tolerance: f32,
    /// Texture test: a pixel whose aggregation window's contrast (standard deviation over the
    /// mean) is below this is not matched: a clear sky or a blank patch matches every
    /// disparity alike, and census finds confident false minima in its smooth gradients (see
    /// `texture.rs`). Scale-free, so 0-1 and 0-255 images behave alike; 0 disables the test.
    pub min_contrast: f32,
}

impl Default for MatchParams {
    fn default() -> Self {
        Self {
            min_disparity: 0,
            num_disparities: 64,
            window_width: 9,
            window_height: 9,
            uniqueness_ratio: 10,
            left_right_tolerance: Some(1),
            range_tolerance: 0.25,
            min_contrast: DEFAULT_MIN_CONTRAST,
        }
    }
}

impl MatchParams {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        if self.num_disparities == 0 || self.num_disparities > MAX_DISPARITIES {
            return Err(Error::InvalidParameter {
                name: "num_disparities",
                value: f64::from(self.num_disparities),
                expected: "1 to 1024 disparities",
            });
        }
        for (name, side) in [
            ("window_width", self.window_width),
            ("window_height", self.window_height),
        ] {
            if side % 2 == 0 || side > MAX_WINDOW {
                return Err(Error::InvalidParameter {
                    name,
                    value: f64::from(side),
                    expected: "an odd window side from 1 to 15",
                });
            }
        }
        if self.uniqueness_ratio >= 100 {
            return Err(Error::InvalidParameter {
                name: "uniqueness_ratio",
                value: f64::from(self.uniqueness_ratio),
                expected: "a percentage below 100",
            });
        }
        if !(self.min_contrast.is_finite() && self.min_contrast >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "min_contrast",
                value: f64::from(self.min_contrast),
                expected: "a finite contrast >= 0",
            });
        }
        if !(self.range_tolerance.is_finite() && self.range_tolerance >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "range_tolerance",
                value: f64::from(self.range_tolerance),
                expected: "a finite tolerance >= 0",
            });
        }
        Ok(())
    }
}

/// The matcher's result in the left (reference) image: per pixel the sub-pixel disparity and the
/// cost-curve disparity range `[low, high]` around it, all `NaN` where no match survived.
#[derive(Clone, Debug, PartialEq)]
pub struct DisparityMap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Sub-pixel disparity, row-major; `NaN` = no match.
    pub disparity: Vec<f32>,
    /// Lowest integer disparity whose cost is within the range tolerance of the best.
    pub range_low: Vec<f32>,
    /// Highest integer disparity whose cost is within the range tolerance of the best.
    pub range_high: Vec<f32>,
    /// The best match's window cost as a fraction of the largest possible (0: the windows
    /// agree in every census bit; about 0.5: unrelated patches); `NaN` = no match.
    pub cost: Vec<f32>,
}

impl DisparityMap {
    /// Fraction of pixels with a disparity.
    pub fn density(&self) -> f64 {
        let matched = self.disparity.iter().filter(|d| !d.is_nan()).count();
        matched as f64 / self.disparity.len().max(1) as f64
    }
}
