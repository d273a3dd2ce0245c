//! Rectification of a general pair (Fusiello, Trucco and Verri, "A compact algorithm for
//! rectification of stereo pairs", Machine Vision and Applications 12, 2000): both cameras are
//! rotated about their centres so that the baseline becomes their common x axis, given one
//! focal length and one principal row, and both images are warped (bilinear) into these virtual
//! cameras. Corresponding points then share a row, and `left(y, x)` matches `right(y, x - d)`.

use fuzzyvox_core::image::{GrayImage, MIN_BASELINE, StereoGeometry};
use nalgebra::{Isometry3, Matrix3, Point2, Rotation3, UnitQuaternion, Vector3};
use rayon::prelude::*;

use fuzzyvox_core::error::{Error, Result, UnrectifiableReason};
use fuzzyvox_core::geometry::{PinholeIntrinsics, validate_pose};

/// A rectified pair: the virtual cameras and the maps from their pixels to the originals.
#[derive(Clone, Debug)]
pub struct Rectification {
    geometry: StereoGeometry,
    other: PinholeIntrinsics,
    /// Rectified pixel → original pixel, homogeneous, per camera.
    to_original: [Matrix3<f64>; 2],
}

/// Which camera of a pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The reference (left after rectification).
    Reference,
    /// The other camera (right after rectification).
    Other,
}

impl Rectification {
    /// Computes the rectifying rotation and virtual cameras of a pair. The rectified images have
    /// the reference image's size; the x axis points from the reference to the other camera, so
    /// the reference is always the left image.
    pub fn new(
        reference: &PinholeIntrinsics,
        world_from_reference: &Isometry3<f64>,
        other: &PinholeIntrinsics,
        world_from_other: &Isometry3<f64>,
    ) -> Result<Self> {
        validate_pose(world_from_reference)?;
        validate_pose(world_from_other)?;
        let unrectifiable = |reason| Error::Unrectifiable { reason };
        let c_ref = world_from_reference.translation.vector;
        let c_other = world_from_other.translation.vector;
        let offset = c_other - c_ref;
        let baseline = offset.norm();
        if baseline.is_nan() || baseline <= MIN_BASELINE {
            return Err(unrectifiable(UnrectifiableReason::ZeroBaseline {
                baseline,
            }));
        }
        // The epipoles: each centre seen from the other camera.
        for (camera, k, pose, seen) in [
            ("reference", reference, world_from_reference, c_other),
            ("other", other, world_from_other, c_ref),
        ] {
            if let Some((u, v)) = epipole_within(k, pose, &seen, 0.0) {
                return Err(unrectifiable(UnrectifiableReason::EpipoleInImage {
                    camera,
                    u,
                    v,
                }));
            }
        }
        // FTV: new x along the baseline, new y orthogonal to x and the (mean) old optical axis,
        // new z completing the right-handed frame.
        let x = offset / baseline;
        let axis =
            world_from_reference.rotation * Vector3::z() + world_from_other.rotation * Vector3::z();
        if axis.norm() < 1e-6 {
            return Err(unrectifiable(UnrectifiableReason::OppositeViews));
        }
        let y = axis.cross(&x);
        if y.norm() < 1e-9 {
            // Unreachable after the epipole test, kept so that no division by zero can happen.
            return Err(unrectifiable(UnrectifiableReason::EpipoleInImage {
                camera: "reference",
                u: reference.cx(),
                v: reference.cy(),
            }));
        }
        let y = y.normalize();
        let z = x.cross(&y);
        let world_from_rect = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
        let focal = 0.25 * (reference.fx() + reference.fy() + other.fx() + other.fy());
        let (width, height) = (reference.width(), reference.height());
        // Principal points that keep each image's centre at the centre of the rectified image;
        // the row is shared so that epipolar lines stay horizontal.
        let rect_from_camera =
            |pose: &Isometry3<f64>| world_from_rect.inverse() * pose.rotation.to_rotation_matrix();
        let centre_offset = |k: &PinholeIntrinsics, pose: &Isometry3<f64>| {
            let ray = rect_from_camera(pose)
                * Vector3::new(
                    (0.5 * (f64::from(k.width()) - 1.0) - k.cx()) / k.fx(),
                    (0.5 * (f64::from(k.height()) - 1.0) - k.cy()) / k.fy(),
                    1.0,
                );
            (focal * ray.x / ray.z, focal * ray.y / ray.z)
        };
        let (u_ref, v_ref) = centre_offset(reference, world_from_reference);
        let (u_other, v_other) = centre_offset(other, world_from_other);
        let half_w = 0.5 * (f64::from(width) - 1.0);
        let cy = 0.5 * (f64::from(height) - 1.0) - 0.5 * (v_ref + v_other);
        let rect_ref = PinholeIntrinsics::new(width, height, focal, focal, half_w - u_ref, cy)?;
        let rect_other = PinholeIntrinsics::new(width, height, focal, focal, half_w - u_other, cy)?;
        let to_original =
            |k_old: &PinholeIntrinsics, pose: &Isometry3<f64>, k_new: &PinholeIntrinsics| {
                let camera_from_rect = rect_from_camera(pose).inverse();
                matrix_of(k_old) * camera_from_rect.matrix() * inverse_of(k_new)
            };
        let homographies = [
            to_original(reference, world_from_reference, &rect_ref),
            to_original(other, world_from_other, &rect_other),
        ];
        let rotation = UnitQuaternion::from_rotation_matrix(&world_from_rect);
        let world_from_rect_ref = Isometry3::from_parts(c_ref.into(), rotation);
        let geometry = StereoGeometry::new(
            rect_ref,
            world_from_rect_ref,
            baseline,
            rect_other.cx() - rect_ref.cx(),
        )?;
        Ok(Self {
            geometry,
            other: rect_other,
            to_original: homographies,
        })
    }

    /// The rectified pair's geometry (reference camera, baseline, `doffs`).
    pub fn geometry(&self) -> &StereoGeometry {
        &self.geometry
    }

    /// The rectified other camera.
    pub fn other(&self) -> &PinholeIntrinsics {
        &self.other
    }

    /// Where an original pixel of camera `side` lands in its rectified image; `None` when it
    /// maps to infinity.
    pub fn rectify_point(&self, side: Side, original: Point2<f64>) -> Option<Point2<f64>> {
        let inverse = self.to_original[side as usize].try_inverse()?;
        let p = inverse * Vector3::new(original.x, original.y, 1.0);
        (p.z.abs() > 1e-12).then(|| Point2::new(p.x / p.z, p.y / p.z))
    }

    /// Warps camera `side`'s original image into its rectified image (bilinear; `NaN` where the
    /// rectified pixel sees outside the original image).
    pub fn warp(&self, side: Side, image: &GrayImage) -> Result<GrayImage> {
        let (width, height) = (
            self.geometry.reference().width(),
            self.geometry.reference().height(),
        );
        let h = self.to_original[side as usize];
        let mut pixels = vec![f32::NAN; width as usize * height as usize];
        pixels
            .par_chunks_mut(width as usize)
            .enumerate()
            .for_each(|(v, row)| {
                for (u, out) in row.iter_mut().enumerate() {
                    let p = h * Vector3::new(u as f64, v as f64, 1.0);
                    if p.z > 0.0 {
                        *out = image.sample_bilinear(p.x / p.z, p.y / p.z);
                    }
                }
            });
        GrayImage::new(width, height, pixels)
    }
}

/// The epipole `(u, v)` of the camera `k` at `pose` (the point `seen`, another camera's centre,
/// projected through it, in front or behind) when it lies inside the image grown by `margin`
/// times its width and height on every side; `None` otherwise, or when the centre lies in the
/// image plane's direction (epipole at infinity).
pub(crate) fn epipole_within(
    k: &PinholeIntrinsics,
    pose: &Isometry3<f64>,
    seen: &Vector3<f64>,
    margin: f64,
) -> Option<(f64, f64)> {
    let direction = pose.rotation.inverse() * (seen - pose.translation.vector);
    if direction.z.abs() <= 1e-12 * direction.norm() {
        return None;
    }
    let u = k.fx() * direction.x / direction.z + k.cx();
    let v = k.fy() * direction.y / direction.z + k.cy();
    let (w, h) = (f64::from(k.width()), f64::from(k.height()));
    let (mx, my) = (margin * w, margin * h);
    ((-0.5 - mx..w - 0.5 + mx).contains(&u) && (-0.5 - my..h - 0.5 + my).contains(&v))
        .then_some((u, v))
}

fn matrix_of(k: &PinholeIntrinsics) -> Matrix3<f64> {
    Matrix3::new(k.fx(), 0.0, k.cx(), 0.0, k.fy(), k.cy(), 0.0, 0.0, 1.0)
}

fn inverse_of(k: &PinholeIntrinsics) -> Matrix3<f64> {
    Matrix3::new(
        1.0 / k.fx(),
        0.0,
        -k.cx() / k.fx(),
        0.0,
        1.0 / k.fy(),
        -k.cy() / k.fy(),
        0.0,
        0.0,
        1.0,
    )
}
