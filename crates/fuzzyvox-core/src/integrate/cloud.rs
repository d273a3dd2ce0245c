use nalgebra::Point3;

use crate::error::{Error, Result};

/// An unordered set of 3D points in the world frame, measured from one sensor origin, with an
/// optional confidence in `[0, 1]` per point.
///
/// Points that are NaN or infinite are kept here and skipped (and counted) at integration, as
/// sensors report missing returns that way; the origin and the confidences are validated now.
#[derive(Clone, Debug, PartialEq)]
pub struct PointCloud {
    origin: Point3<f64>,
    points: Vec<Point3<f64>>,
    confidence: Option<Vec<f32>>,
    reliability: Option<Vec<f32>>,
}

impl PointCloud {
    /// A cloud of `points` seen from `origin`; the origin must be finite.
    pub fn new(origin: Point3<f64>, points: Vec<Point3<f64>>) -> Result<Self> {
        if let Some(value) = origin.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "sensor origin",
                value: *value,
            });
        }
        Ok(Self {
            origin,
            points,
            confidence: None,
            reliability: None,
        })
    }

    /// Attaches one confidence in `[0, 1]` per point.
    pub fn with_confidence(mut self, confidence: Vec<f32>) -> Result<Self> {
        check_unit_plane(
            "confidence per point",
            &confidence,
            self.points.len(),
            false,
        )?;
        self.confidence = Some(confidence);
        Ok(self)
    }

    /// Adds a reliability per point in `[0, 1]`: how likely the point is right at all, so how
    /// much its ray's free space can be trusted, whatever its confidence says about where the
    /// surface is. The dual evidence model ([`EvidenceKind::Dual`](crate::EvidenceKind)) weighs
    /// free evidence by it (1 for every point without it) and the paper's model by the
    /// confidence; a point of confidence 0 and reliability above 0 then only clears its ray.
    ///
    /// # Errors
    /// [`Error::SizeMismatch`] for a length other than the number of points,
    /// [`Error::InvalidConfidence`] for a value outside `[0, 1]` (NaN included).
    pub fn with_reliability(mut self, reliability: Vec<f32>) -> Result<Self> {
        check_unit_plane(
            "reliability per point",
            &reliability,
            self.points.len(),
            false,
        )?;
        self.reliability = Some(reliability);
        Ok(self)
    }

    /// The reliability per point, when set.
    pub fn reliability(&self) -> Option<&[f32]> {
        self.reliability.as_deref()
    }

    /// Reliability of point `i` (1 when the cloud has none).
    #[inline]
    pub fn reliability_of(&self, i: usize) -> f32 {
        self.reliability.as_ref().map_or(1.0, |r| r[i])
    }

    /// The sensor origin.
    pub fn origin(&self) -> Point3<f64> {
        self.origin
    }

    /// The points.
    pub fn points(&self) -> &[Point3<f64>] {
        &self.points
    }

    /// The per-point confidences, when given.
    pub fn confidence(&self) -> Option<&[f32]> {
        self.confidence.as_deref()
    }

    /// Confidence of point `i` (1 when none was given).
    #[inline]
    pub fn confidence_of(&self, i: usize) -> f32 {
        self.confidence.as_ref().map_or(1.0, |c| c[i])
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// Checks that `values` holds `expected` values in `[0, 1]` (NaN too when `nan_allowed`):
/// [`Error::SizeMismatch`] naming `what`, or [`Error::InvalidConfidence`] at the first bad value.
pub(super) fn check_unit_plane(
    what: &'static str,
    values: &[f32],
    expected: usize,
    nan_allowed: bool,
) -> Result<()> {
    if values.len() != expected {
        return Err(Error::SizeMismatch {
            what,
            expected,
            found: values.len(),
        });
    }
    let good = |v: f32| (0.0..=1.0).contains(&v) || (nan_allowed && v.is_nan());
    match values.iter().enumerate().find(|(_, v)| !good(**v)) {
        Some((index, &value)) => Err(Error::InvalidConfidence { index, value }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validates_origin_and_confidence() {
        let p = vec![Point3::new(1.0, 0.0, 0.0); 2];
        assert!(PointCloud::new(Point3::new(f64::NAN, 0.0, 0.0), p.clone()).is_err());
        let cloud = PointCloud::new(Point3::origin(), p).unwrap();
        assert!(cloud.clone().with_confidence(vec![0.5]).is_err());
        assert!(cloud.clone().with_confidence(vec![0.5, 1.5]).is_err());
        assert!(cloud.clone().with_confidence(vec![0.5, f32::NAN]).is_err());
        let ok = cloud.with_confidence(vec![0.5, 1.0]).unwrap();
        assert_eq!(ok.confidence_of(0), 0.5);
        assert_eq!(ok.reliability_of(0), 1.0);
        assert!(ok.clone().with_reliability(vec![0.5]).is_err());
        assert!(ok.clone().with_reliability(vec![0.5, f32::NAN]).is_err());
        let ok = ok.with_reliability(vec![0.25, 1.0]).unwrap();
        assert_eq!(ok.reliability_of(0), 0.25);
    }
}
