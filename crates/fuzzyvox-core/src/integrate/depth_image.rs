use nalgebra::Isometry3;

use super::cloud::{PointCloud, check_unit_plane};
use crate::error::{Error, Result};
use crate::geometry::{PinholeIntrinsics, validate_pose};

/// A depth image with an interval and a confidence per pixel: `P-` (near), `P0` (depth), `P+`
/// (far), all depths along the optical axis in metres, and a confidence in `[0, 1]`.
///
/// A pixel is *valid* when its three depths are finite and positive and its confidence is a
/// number greater than zero; invalid pixels (NaN, infinite, zero or negative depth, missing
/// interval, NaN confidence) contribute nothing when integrated. Out-of-order intervals and
/// confidences outside `[0, 1]` are errors at construction.
///
/// An image may also carry a *reliability* per pixel ([`IntervalDepthImage::with_reliability`]):
/// how likely the measurement is right at all (for a stereo match: that it matched the right
/// point), as opposed to the confidence, which also says how narrow the interval is. The dual
/// evidence model ([`EvidenceKind::Dual`](crate::EvidenceKind)) weighs free space by it, and
/// uses pixels that have a reliability and a sound near bound `P-` even when their far bound
/// `P+` or their confidence is missing: such a pixel still says that the space in front of
/// `P-` is empty. Without a reliability plane every valid pixel counts as fully reliable (a
/// sensor's return, such as an RGB-D camera's).
#[derive(Clone, Debug, PartialEq)]
pub struct IntervalDepthImage {
    width: u32,
    height: u32,
    near: Vec<f32>,
    depth: Vec<f32>,
    far: Vec<f32>,
    confidence: Vec<f32>,
    reliability: Option<Vec<f32>>,
}

/// One pixel's interval, confidence and reliability as an integrator reads them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PixelInterval {
    pub near: f32,
    pub depth: f32,
    /// `P+`; infinite when the pixel has no far bound (dual model only).
    pub far: f32,
    /// 0 when the pixel has none (dual model only).
    pub confidence: f32,
    /// How likely the measurement is right, in `[0, 1]`.
    pub reliability: f32,
}

impl IntervalDepthImage {
    /// Builds an image from row-major planes of `width × height` values each.
    pub fn new(
        width: u32,
        height: u32,
        near: Vec<f32>,
        depth: Vec<f32>,
        far: Vec<f32>,
        confidence: Vec<f32>,
    ) -> Result<Self> {
        let pixels = (width as usize) * (height as usize);
        if pixels == 0 {
            return Err(Error::Empty("depth image"));
        }
        for (what, plane) in [
            ("near depth plane (P-)", &near),
            ("depth plane (P0)", &depth),
            ("far depth plane (P+)", &far),
            ("confidence plane", &confidence),
        ] {
            if plane.len() != pixels {
                return Err(Error::SizeMismatch {
                    what,
                    expected: pixels,
                    found: plane.len(),
                });
            }
        }
        let image = Self {
            width,
            height,
            near,
            depth,
            far,
            confidence,
            reliability: None,
        };
        for i in 0..pixels {
            let c = image.confidence[i];
            if !c.is_nan() && !(0.0..=1.0).contains(&c) {
                return Err(Error::InvalidConfidence { index: i, value: c });
            }
            let (n, d, f) = (image.near[i], image.depth[i], image.far[i]);
            if depth_valid(n) && depth_valid(d) && depth_valid(f) && !(n <= d && d <= f) {
                return Err(Error::IntervalOrder {
                    x: (i % width as usize) as u32,
                    y: (i / width as usize) as u32,
                    near: n,
                    depth: d,
                    far: f,
                });
            }
        }
        Ok(image)
    }

    /// Builds an image from a plain depth image and a sensor model that gives, for a depth `z`,
    /// the interval `(P-, P+)` and a confidence. Pixels with invalid depth stay invalid.
    ///
    /// ```
    /// use fuzzyvox_core::IntervalDepthImage;
    /// // Kinect-like noise: σ grows with z²; the interval is ±2σ.
    /// let depth = vec![1.0_f32, 2.0, 0.0, f32::NAN];
    /// let image = IntervalDepthImage::from_depth(2, 2, &depth, |z| {
    ///     let sigma = 0.0012 + 0.0019 * (z - 0.4).powi(2);
    ///     (z - 2.0 * sigma, z + 2.0 * sigma, 1.0)
    /// })
    /// .unwrap();
    /// assert_eq!(image.valid_pixels(), 2);
    /// ```
    pub fn from_depth(
        width: u32,
        height: u32,
        depth: &[f32],
        model: impl Fn(f32) -> (f32, f32, f32),
    ) -> Result<Self> {
        let mut near = vec![f32::NAN; depth.len()];
        let mut far = vec![f32::NAN; depth.len()];
        let mut confidence = vec![f32::NAN; depth.len()];
        for (i, &z) in depth.iter().enumerate() {
            if depth_valid(z) {
                let (n, f, c) = model(z);
                near[i] = n;
                far[i] = f;
                confidence[i] = c;
            }
        }
        Self::new(width, height, near, depth.to_vec(), far, confidence)
    }

    /// Adds a reliability plane (row-major, `width × height` values in `[0, 1]`; NaN for a
    /// pixel without one, which then gives no free evidence): how likely each pixel's
    /// measurement is right, whatever its interval's width. See the type's documentation.
    ///
    /// # Errors
    /// [`Error::SizeMismatch`] for a plane of the wrong size, [`Error::InvalidConfidence`] for
    /// a value outside `[0, 1]`.
    pub fn with_reliability(mut self, reliability: Vec<f32>) -> Result<Self> {
        check_unit_plane("reliability plane", &reliability, self.depth.len(), true)?;
        self.reliability = Some(reliability);
        Ok(self)
    }

    /// The reliability plane, row-major, when the image has one.
    pub fn reliability(&self) -> Option<&[f32]> {
        self.reliability.as_deref()
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The `P-` plane, row-major.
    pub fn near(&self) -> &[f32] {
        &self.near
    }

    /// The `P0` plane, row-major.
    pub fn depth(&self) -> &[f32] {
        &self.depth
    }

    /// The `P+` plane, row-major.
    pub fn far(&self) -> &[f32] {
        &self.far
    }

    /// The confidence plane, row-major.
    pub fn confidence(&self) -> &[f32] {
        &self.confidence
    }

    /// Whether pixel `index` (row-major) holds a depth: its `P0` is finite and positive,
    /// whatever its interval and confidence. `false` outside the image.
    #[inline]
    pub fn has_depth(&self, index: usize) -> bool {
        self.depth.get(index).is_some_and(|&z| depth_valid(z))
    }

    /// Number of valid pixels.
    pub fn valid_pixels(&self) -> usize {
        (0..self.depth.len())
            .filter(|&i| self.pixel(i).is_some())
            .count()
    }

    /// The interval of pixel `index` (row-major), when valid (the paper's pixels: all three
    /// depths and a confidence), with reliability 1 (the paper's model does not read it).
    #[inline]
    pub(crate) fn pixel(&self, index: usize) -> Option<PixelInterval> {
        let p = PixelInterval {
            near: self.near[index],
            depth: self.depth[index],
            far: self.far[index],
            confidence: self.confidence[index],
            reliability: 1.0,
        };
        (depth_valid(p.near) && depth_valid(p.depth) && depth_valid(p.far) && p.confidence > 0.0)
            .then_some(p)
    }

    /// Pixel `index` as the dual evidence model reads it: a sound near bound and depth
    /// (`P- <= P0`, both valid) and a reliability above zero are enough; a missing far bound
    /// becomes infinite and a missing confidence 0 (the pixel then only clears free space).
    /// Without a reliability plane, the valid pixels of [`IntervalDepthImage::pixel`] have
    /// reliability 1 and the others none.
    #[inline]
    pub(crate) fn dual_pixel(&self, index: usize) -> Option<PixelInterval> {
        let Some(plane) = &self.reliability else {
            return self.pixel(index);
        };
        let reliability = plane[index];
        let (near, depth) = (self.near[index], self.depth[index]);
        if !(reliability > 0.0 && depth_valid(near) && depth_valid(depth) && near <= depth) {
            return None;
        }
        let far = self.far[index];
        let confidence = self.confidence[index];
        let bounded = depth_valid(far);
        Some(PixelInterval {
            near,
            depth,
            far: if bounded { far } else { f32::INFINITY },
            confidence: if bounded && confidence > 0.0 {
                confidence
            } else {
                0.0
            },
            reliability,
        })
    }
}

#[inline]
fn depth_valid(z: f32) -> bool {
    z.is_finite() && z > 0.0
}

/// An interval depth image with the camera that took it.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthFrame {
    intrinsics: PinholeIntrinsics,
    world_from_camera: Isometry3<f64>,
    image: IntervalDepthImage,
}

impl DepthFrame {
    /// Ties an image to its camera: the image size must equal the intrinsics' size and the pose
    /// must be valid.
    pub fn new(
        intrinsics: PinholeIntrinsics,
        world_from_camera: Isometry3<f64>,
        image: IntervalDepthImage,
    ) -> Result<Self> {
        validate_pose(&world_from_camera)?;
        if image.width() != intrinsics.width() || image.height() != intrinsics.height() {
            return Err(Error::SizeMismatch {
                what: "depth image pixels (intrinsics width × height)",
                expected: intrinsics.width() as usize * intrinsics.height() as usize,
                found: image.width() as usize * image.height() as usize,
            });
        }
        Ok(Self {
            intrinsics,
            world_from_camera,
            image,
        })
    }

    /// The camera intrinsics.
    pub fn intrinsics(&self) -> &PinholeIntrinsics {
        &self.intrinsics
    }

    /// The camera pose.
    pub fn world_from_camera(&self) -> &Isometry3<f64> {
        &self.world_from_camera
    }

    /// The interval depth image.
    pub fn image(&self) -> &IntervalDepthImage {
        &self.image
    }

    /// Multiplies every pixel's confidence (and reliability) by `weight` in `(0, 1]`: the frame then counts as
    /// `weight` of an observation in the maps that weigh evidence by confidence (the fuzzy and
    /// alpha-cut maps; the log-odds map ignores confidence). For depth images that share their
    /// source views with others, see `DepthResult::reuse_weight` (`fuzzyvox-depth`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a weight that is not in `(0, 1]`; the frame is unchanged.
    pub fn scale_confidence(&mut self, weight: f32) -> Result<()> {
        if !(weight > 0.0 && weight <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "weight",
                value: f64::from(weight),
                expected: "a weight in (0, 1]",
            });
        }
        // In [0, 1] times (0, 1]: still in [0, 1]; NaN (no confidence) stays NaN.
        for c in &mut self.image.confidence {
            *c *= weight;
        }
        // An image without a reliability plane has reliability 1 on its valid pixels: the
        // scaled frame holds it as a plane of `weight` there.
        let image = &mut self.image;
        let plane = match image.reliability.take() {
            Some(mut plane) => {
                for r in &mut plane {
                    *r *= weight;
                }
                plane
            }
            None => (0..image.depth.len())
                .map(|i| {
                    if image.pixel(i).is_some() {
                        weight
                    } else {
                        f32::NAN
                    }
                })
                .collect(),
        };
        image.reliability = Some(plane);
        Ok(())
    }

    /// The frame as a point cloud for ray-based maps: every valid pixel back-projected at its
    /// `P0` depth into the world, seen from the camera centre, with its confidence.
    pub fn to_cloud(&self) -> Result<PointCloud> {
        let width = self.image.width() as usize;
        let mut points = Vec::new();
        let mut confidence = Vec::new();
        for index in 0..self.image.depth().len() {
            if let Some(p) = self.image.pixel(index) {
                let (u, v) = ((index % width) as f64, (index / width) as f64);
                let in_camera = self.intrinsics.back_project(u, v, f64::from(p.depth));
                points.push(self.world_from_camera * in_camera);
                confidence.push(p.confidence);
            }
        }
        let origin = nalgebra::Point3::from(self.world_from_camera.translation.vector);
        PointCloud::new(origin, points)?.with_confidence(confidence)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::unwrap_used)]
    fn a_pixel_has_depth_when_its_middle_depth_is_finite_and_positive() {
        let depth = vec![2.0, f32::NAN, 0.0, -1.0, f32::INFINITY, 5.0];
        let near: Vec<f32> = depth.iter().map(|z| z * 0.5).collect();
        let far: Vec<f32> = depth.iter().map(|z| z * 2.0).collect();
        let image = IntervalDepthImage::new(3, 2, near, depth, far, vec![0.0; 6]).unwrap();
        let has: Vec<bool> = (0..7).map(|i| image.has_depth(i)).collect();
        // Zero confidence does not matter; outside the image there is none.
        assert_eq!(has, [true, false, false, false, false, true, false]);
    }

    #[test]
    fn validates_sizes_order_and_confidence() {
        let ok = |n: f32, d: f32, f: f32, c: f32| {
            IntervalDepthImage::new(1, 1, vec![n], vec![d], vec![f], vec![c])
        };
        assert!(ok(1.0, 2.0, 3.0, 0.5).is_ok());
        assert!(matches!(
            ok(2.5, 2.0, 3.0, 0.5),
            Err(Error::IntervalOrder { .. })
        ));
        assert!(matches!(
            ok(1.0, 2.0, 3.0, 1.5),
            Err(Error::InvalidConfidence { .. })
        ));
        // NaN depth or confidence: an invalid pixel, not an error.
        assert_eq!(ok(f32::NAN, 2.0, 3.0, 0.5).unwrap().valid_pixels(), 0);
        assert_eq!(ok(1.0, 2.0, 3.0, f32::NAN).unwrap().valid_pixels(), 0);
        assert_eq!(ok(-1.0, 2.0, 3.0, 0.5).unwrap().valid_pixels(), 0);
        assert!(IntervalDepthImage::new(2, 1, vec![1.0], vec![1.0], vec![1.0], vec![1.0]).is_err());
        assert!(IntervalDepthImage::new(0, 0, vec![], vec![], vec![], vec![]).is_err());
    }

    #[test]
    fn reliability_planes_are_validated_and_read_by_the_dual_model_only() {
        let image = IntervalDepthImage::new(
            3,
            1,
            vec![1.0, 1.0, 1.0],
            vec![2.0, 2.0, 2.0],
            vec![3.0, f32::NAN, 3.0],
            vec![0.5, f32::NAN, 0.5],
        )
        .unwrap();
        assert!(matches!(
            image.clone().with_reliability(vec![1.0; 2]),
            Err(Error::SizeMismatch { .. })
        ));
        assert!(matches!(
            image.clone().with_reliability(vec![1.0, -0.5, 1.0]),
            Err(Error::InvalidConfidence { index: 1, .. })
        ));
        // Without a plane the dual model reads the paper's valid pixels, fully reliable.
        assert_eq!(image.dual_pixel(0).unwrap().reliability, 1.0);
        assert!(image.dual_pixel(1).is_none());
        let image = image.with_reliability(vec![0.8, 0.6, f32::NAN]).unwrap();
        // A pixel without P+ or confidence: infinite far bound, confidence 0.
        let p = image.dual_pixel(1).unwrap();
        assert!(p.far.is_infinite() && p.confidence == 0.0 && p.reliability == 0.6);
        // NaN reliability: no dual pixel, though the paper's model still reads it.
        assert!(image.dual_pixel(2).is_none() && image.pixel(2).is_some());
        assert!(image.pixel(1).is_none());
        // Scaling a frame's weight scales its reliability too.
        let k = PinholeIntrinsics::new(3, 1, 1.0, 1.0, 1.0, 0.0).unwrap();
        let mut frame = DepthFrame::new(k, Isometry3::identity(), image).unwrap();
        frame.scale_confidence(0.5).unwrap();
        assert_eq!(frame.image().reliability().unwrap()[0], 0.4);
    }

    #[test]
    fn frame_size_must_match_intrinsics() {
        let k = PinholeIntrinsics::new(2, 2, 1.0, 1.0, 1.0, 1.0).unwrap();
        let image = IntervalDepthImage::from_depth(1, 1, &[1.0], |z| (z, z, 1.0)).unwrap();
        assert!(DepthFrame::new(k, Isometry3::identity(), image).is_err());
    }
}
