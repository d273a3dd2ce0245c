//! Extrinsic quality `Q_ABD` of a camera pair (the paper's eqs. 3–9): how well two poses suit
//! motion stereo. With `A` and `B` the look directions and `D` the baseline:
//!
//! - eq. 3: `cos∠AB = A·B / (|A||B|)`; eq. 4: `H_AB = max(cos∠AB, 0)` (the views must overlap);
//! - eqs. 5–6: `cos∠AD`, `cos∠BD` likewise;
//! - eqs. 7–8: `R_AD = sqrt(1 - cos²∠AD)`, `R_BD = sqrt(1 - cos²∠BD)` (the baseline should be
//!   across the views, not along them);
//! - eq. 9: `Q = min(H_AB, R_AD, R_BD)`.
//!
//! A sideways strafe gives `Q = 1`; motion along the look direction or views that do not face the
//! same way give `Q = 0`.

use nalgebra::{Isometry3, Vector3};

use fuzzyvox_core::error::Result;
use fuzzyvox_core::geometry::validate_pose;

/// The terms of `Q_ABD` for one pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtrinsicQuality {
    /// `H_AB` (eq. 4): alignment of the look directions.
    pub alignment: f64,
    /// `R_AD` (eq. 7): how far the baseline is from the first look direction.
    pub across_a: f64,
    /// `R_BD` (eq. 8): how far the baseline is from the second look direction.
    pub across_b: f64,
    /// `Q = min(H_AB, R_AD, R_BD)` (eq. 9), in `[0, 1]`.
    pub q: f64,
}

/// `Q_ABD` from two look directions and the baseline vector between the camera centres. A zero
/// baseline has no direction and gives `Q = 0` (no parallax, nothing to measure).
pub fn quality_from_vectors(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    d: &Vector3<f64>,
) -> ExtrinsicQuality {
    let cosine = |u: &Vector3<f64>, v: &Vector3<f64>| {
        let norms = u.norm() * v.norm();
        if norms > 0.0 && norms.is_finite() {
            Some((u.dot(v) / norms).clamp(-1.0, 1.0))
        } else {
            None
        }
    };
    // eqs. 3–4
    let alignment = cosine(a, b).map_or(0.0, |c| c.max(0.0));
    // eqs. 5–8; an undefined angle (zero vector) gives 0.
    let across = |u: &Vector3<f64>| cosine(u, d).map_or(0.0, |c| (1.0 - c * c).max(0.0).sqrt());
    let (across_a, across_b) = (across(a), across(b));
    // eq. 9
    ExtrinsicQuality {
        alignment,
        across_a,
        across_b,
        q: alignment.min(across_a).min(across_b),
    }
}

/// `Q_ABD` of two camera poses (`world_from_camera`; look direction = camera +z).
pub fn extrinsic_quality(
    world_from_a: &Isometry3<f64>,
    world_from_b: &Isometry3<f64>,
) -> Result<ExtrinsicQuality> {
    validate_pose(world_from_a)?;
    validate_pose(world_from_b)?;
    let a = world_from_a.rotation * Vector3::z();
    let b = world_from_b.rotation * Vector3::z();
    let d = world_from_b.translation.vector - world_from_a.translation.vector;
    Ok(quality_from_vectors(&a, &b, &d))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(a: [f64; 3], b: [f64; 3], d: [f64; 3]) -> f64 {
        quality_from_vectors(&a.into(), &b.into(), &d.into()).q
    }

    #[test]
    fn strafe_is_one() {
        assert!((q([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.3, 0.0, 0.0]) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn aligned_and_separated_is_high() {
        // 10° between the views, baseline mostly sideways.
        let b = [10f64.to_radians().sin(), 0.0, 10f64.to_radians().cos()];
        let value = q([0.0, 0.0, 1.0], b, [1.0, 0.0, 0.2]);
        assert!(value > 0.9, "{value}");
    }

    #[test]
    fn separated_along_the_look_direction_is_low() {
        let value = q([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.05, 0.0, 1.0]);
        assert!(value < 0.1, "{value}");
        assert_eq!(q([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]), 0.0);
    }

    #[test]
    fn not_aligned_is_zero() {
        assert_eq!(q([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), 0.0);
        assert_eq!(q([0.0, 0.0, 1.0], [0.0, 0.2, -1.0], [1.0, 0.0, 0.0]), 0.0);
    }

    #[test]
    fn zero_baseline_is_zero() {
        assert_eq!(q([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]), 0.0);
    }
}
