use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, finite};

/// A pinhole camera without distortion: focal lengths and principal point in pixels, and the
/// image size.
///
/// Pixel `(u, v)` has its centre at integer coordinates (the OpenCV convention), so the pixel
/// that a projected point falls in is `(u + 0.5).floor()`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PinholeIntrinsics {
    width: u32,
    height: u32,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
}

impl PinholeIntrinsics {
    /// Validated constructor: the size must be non-zero, all values finite and the focal lengths
    /// positive.
    ///
    /// ```
    /// use fuzzyvox_core::PinholeIntrinsics;
    /// let k = PinholeIntrinsics::new(640, 480, 585.0, 585.0, 320.0, 240.0).unwrap();
    /// assert!(PinholeIntrinsics::new(640, 480, -1.0, 585.0, 320.0, 240.0).is_err());
    /// # let _ = k;
    /// ```
    pub fn new(width: u32, height: u32, fx: f64, fy: f64, cx: f64, cy: f64) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::Empty("image size"));
        }
        for (name, value) in [("fx", fx), ("fy", fy)] {
            finite(name, value)?;
            if value <= 0.0 {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    expected: "a positive focal length in pixels",
                });
            }
        }
        finite("cx", cx)?;
        finite("cy", cy)?;
        Ok(Self {
            width,
            height,
            fx,
            fy,
            cx,
            cy,
        })
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Focal length along x, in pixels.
    pub fn fx(&self) -> f64 {
        self.fx
    }

    /// Focal length along y, in pixels.
    pub fn fy(&self) -> f64 {
        self.fy
    }

    /// Principal point x, in pixels.
    pub fn cx(&self) -> f64 {
        self.cx
    }

    /// Principal point y, in pixels.
    pub fn cy(&self) -> f64 {
        self.cy
    }

    /// Projects a point in the camera frame to pixel coordinates; `None` when the point is not
    /// in front of the camera.
    pub fn project(&self, point_in_camera: &Point3<f64>) -> Option<Point2<f64>> {
        if point_in_camera.z > 0.0 {
            let inv_z = 1.0 / point_in_camera.z;
            Some(Point2::new(
                self.fx * point_in_camera.x * inv_z + self.cx,
                self.fy * point_in_camera.y * inv_z + self.cy,
            ))
        } else {
            None
        }
    }

    /// The pixel that a camera-frame point projects into, when it lies inside the image.
    pub fn pixel_of(&self, point_in_camera: &Point3<f64>) -> Option<(u32, u32)> {
        let uv = self.project(point_in_camera)?;
        let u = (uv.x + 0.5).floor();
        let v = (uv.y + 0.5).floor();
        if u >= 0.0 && v >= 0.0 && u < f64::from(self.width) && v < f64::from(self.height) {
            Some((u as u32, v as u32))
        } else {
            None
        }
    }

    /// Back-projects pixel coordinates `(u, v)` at `depth` along the optical axis to a point in
    /// the camera frame.
    pub fn back_project(&self, u: f64, v: f64, depth: f64) -> Point3<f64> {
        Point3::new(
            (u - self.cx) / self.fx * depth,
            (v - self.cy) / self.fy * depth,
            depth,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn project_back_project_round_trip() {
        let k = PinholeIntrinsics::new(640, 480, 585.0, 580.0, 320.0, 240.0).unwrap();
        let p = k.back_project(100.25, 400.5, 2.5);
        let uv = k.project(&p).unwrap();
        assert!((uv.x - 100.25).abs() < 1e-9 && (uv.y - 400.5).abs() < 1e-9);
        assert_eq!(k.pixel_of(&p), Some((100, 401)));
    }

    #[test]
    fn points_behind_or_outside_do_not_project() {
        let k = PinholeIntrinsics::new(64, 48, 50.0, 50.0, 32.0, 24.0).unwrap();
        assert!(k.project(&Point3::new(0.0, 0.0, -1.0)).is_none());
        assert!(k.project(&Point3::new(0.0, 0.0, 0.0)).is_none());
        assert!(k.pixel_of(&Point3::new(10.0, 0.0, 1.0)).is_none());
    }

    #[test]
    fn invalid_intrinsics_are_rejected() {
        assert!(PinholeIntrinsics::new(0, 48, 50.0, 50.0, 32.0, 24.0).is_err());
        assert!(PinholeIntrinsics::new(64, 48, 0.0, 50.0, 32.0, 24.0).is_err());
        assert!(PinholeIntrinsics::new(64, 48, 50.0, f64::NAN, 32.0, 24.0).is_err());
        assert!(PinholeIntrinsics::new(64, 48, 50.0, 50.0, f64::INFINITY, 24.0).is_err());
    }
}
