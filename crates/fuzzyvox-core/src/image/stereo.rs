//! The geometry of a rectified stereo pair: from disparity to depth and back.

use nalgebra::Isometry3;

use crate::error::{Error, Result, UnrectifiableReason};
use crate::geometry::{PinholeIntrinsics, validate_pose};

/// Largest supported number of disparities.
pub const MAX_DISPARITIES: u32 = 1024;

/// Camera centres closer than this (metres) count as the same point.
pub const MIN_BASELINE: f64 = 1e-9;

/// The geometry of a rectified pair: the reference (left) camera, and the other camera shifted
/// by `baseline` along the reference's x axis with the same focal length and principal row.
///
/// A match at disparity `d` lies at depth `Z = baseline · f / (d + doffs)`, where `doffs` is the
/// difference of the principal points' columns (other minus reference), as in Middlebury's
/// `calib.txt`.
#[derive(Clone, Debug, PartialEq)]
pub struct StereoGeometry {
    reference: PinholeIntrinsics,
    world_from_reference: Isometry3<f64>,
    baseline: f64,
    doffs: f64,
}

impl StereoGeometry {
    /// A rectified pair's geometry; `fx` must equal `fy` in `reference`, the baseline must be
    /// positive and finite and `doffs` finite.
    pub fn new(
        reference: PinholeIntrinsics,
        world_from_reference: Isometry3<f64>,
        baseline: f64,
        doffs: f64,
    ) -> Result<Self> {
        validate_pose(&world_from_reference)?;
        crate::error::finite("doffs", doffs)?;
        if !(baseline.is_finite() && baseline > MIN_BASELINE) {
            return Err(Error::Unrectifiable {
                reason: UnrectifiableReason::ZeroBaseline { baseline },
            });
        }
        Ok(Self {
            reference,
            world_from_reference,
            baseline,
            doffs,
        })
    }

    /// The rectified reference camera.
    pub fn reference(&self) -> &PinholeIntrinsics {
        &self.reference
    }

    /// The rectified reference camera's pose.
    pub fn world_from_reference(&self) -> &Isometry3<f64> {
        &self.world_from_reference
    }

    /// Baseline (m).
    pub fn baseline(&self) -> f64 {
        self.baseline
    }

    /// Principal point offset `cx(other) - cx(reference)` (px).
    pub fn doffs(&self) -> f64 {
        self.doffs
    }

    /// Depth along the optical axis for disparity `d`; `None` when `d + doffs <= 0` (at or
    /// beyond infinity).
    pub fn depth(&self, disparity: f64) -> Option<f64> {
        let shifted = disparity + self.doffs;
        (shifted > 0.0).then(|| self.baseline * self.reference.fx() / shifted)
    }

    /// Disparity of a point at depth `z > 0`.
    pub fn disparity(&self, depth: f64) -> f64 {
        self.baseline * self.reference.fx() / depth - self.doffs
    }

    /// The disparity search range `(min_disparity, num_disparities)` covering depths
    /// `near..=far` (`far` may be infinite).
    pub fn disparity_range(&self, near: f64, far: f64) -> Result<(i32, u32)> {
        if !(near.is_finite() && near > 0.0 && far > near) {
            return Err(Error::InvalidParameter {
                name: "depth range",
                value: near,
                expected: "0 < near < far",
            });
        }
        let high = self.disparity(near).ceil();
        let low = if far.is_finite() {
            self.disparity(far).floor()
        } else {
            (-self.doffs).floor()
        };
        let count = high - low + 1.0;
        if !(count >= 1.0 && count <= f64::from(MAX_DISPARITIES)) {
            return Err(Error::InvalidParameter {
                name: "disparity count for the depth range",
                value: count,
                expected: "1 to 1024 disparities",
            });
        }
        Ok((low as i32, count as u32))
    }
}
