//! The planes of a sweep ([`Sweep`]): their inverse depths, set so that no pixel of any view
//! moves more than one pixel between neighbours, the geometry that turns a plane index into
//! depth, and where a reference pixel lands in each other view ([`SweepView`]).

use fuzzyvox_core::error::{Error, Result, UnrectifiableReason};
use nalgebra::{Matrix3, Vector3};

use super::limits::{MAX_SWEEP_PIXELS, MAX_SWEEP_SIDE, MAX_SWEEP_VIEWS, PLANE_COUNT};
use crate::params::MAX_DISPARITIES;
use fuzzyvox_core::image::Frame;
use fuzzyvox_core::image::{MIN_BASELINE, StereoGeometry};

/// One other view of a sweep: where a reference pixel lands in it on each plane.
#[derive(Clone, Debug)]
pub(super) struct SweepView {
    /// `K_o R K_r⁻¹`, in single precision.
    pub(super) homography: [[f32; 3]; 3],
    /// `K_o t`.
    pub(super) translation: [f32; 3],
}

/// The planes of a sweep and the geometry that turns a plane index into depth.
#[derive(Clone, Debug)]
pub(crate) struct Sweep {
    /// The other views, in the order given.
    pub(super) views: Vec<SweepView>,
    /// Inverse depth of plane 0 (the farthest).
    pub(super) inverse_far: f64,
    /// Inverse-depth step between planes.
    pub(super) step: f64,
    /// Number of planes.
    pub(super) planes: u32,
}

impl Sweep {
    /// The planes covering depths `near ..= far` for `reference` seen from every view of
    /// `others`: the step is set by the view whose image moves fastest (the longest baseline),
    /// so that no pixel of any view moves more than one pixel between neighbouring planes.
    pub(crate) fn new(reference: &Frame, others: &[&Frame], near: f64, far: f64) -> Result<Self> {
        if !(near.is_finite() && near > 0.0 && far > near) {
            return Err(Error::InvalidParameter {
                name: "depth range",
                value: near,
                expected: "0 < near < far",
            });
        }
        if others.is_empty() {
            return Err(Error::Empty("other views of the plane sweep"));
        }
        if others.len() > MAX_SWEEP_VIEWS {
            return Err(Error::InvalidParameter {
                name: "other views of the plane sweep",
                value: others.len() as f64,
                expected: "1 to 16 other views",
            });
        }
        let (inverse_near, inverse_far) =
            (1.0 / near, if far.is_finite() { 1.0 / far } else { 0.0 });
        let mut rate: f64 = 0.0;
        let mut views = Vec::with_capacity(others.len());
        for other in others {
            let (view, view_rate) = SweepView::new(reference, other, inverse_near, inverse_far)?;
            rate = rate.max(view_rate);
            views.push(view);
        }
        let planes = (rate * (inverse_near - inverse_far)).ceil() + 1.0;
        if !(planes.is_finite() && planes <= f64::from(MAX_DISPARITIES)) {
            return Err(Error::InvalidParameter {
                name: PLANE_COUNT,
                value: planes,
                expected: "1 to 1024 planes (narrow the depth range or the baselines)",
            });
        }
        let planes = planes.max(2.0) as u32;
        let step = (inverse_near - inverse_far) / f64::from(planes - 1);
        Ok(Self {
            views,
            inverse_far,
            step,
            planes,
        })
    }

    /// The geometry that maps a (fractional) plane index to depth in the reference camera.
    pub(crate) fn geometry(&self, reference: &Frame) -> Result<StereoGeometry> {
        let fx = reference.intrinsics().fx();
        StereoGeometry::new(
            *reference.intrinsics(),
            *reference.world_from_camera(),
            1.0 / (self.step * fx),
            self.inverse_far / self.step,
        )
    }
}

impl SweepView {
    /// Where a reference pixel whose ray is `ray` (`M x̃`) lands in this view on the plane of
    /// inverse depth `inverse`, unrounded; `None` behind the view's camera. (The sweep's cost
    /// loop does the same, branch-free and rounded to the nearest pixel.)
    pub(super) fn landing(&self, ray: [f32; 3], inverse: f32) -> Option<(f32, f32)> {
        let b = self.translation.map(|t| t * inverse);
        let qz = ray[2] + b[2];
        (qz > 1e-6).then(|| ((ray[0] + b[0]) / qz, (ray[1] + b[1]) / qz))
    }

    /// The view of `other` from `reference` and the fastest image motion per unit of inverse
    /// depth over the swept range (sampled over a grid of pixels and depths).
    fn new(
        reference: &Frame,
        other: &Frame,
        inverse_near: f64,
        inverse_far: f64,
    ) -> Result<(Self, f64)> {
        let other_from_reference =
            other.world_from_camera().inverse() * reference.world_from_camera();
        let t = other_from_reference.translation.vector;
        if t.norm() <= MIN_BASELINE || !t.norm().is_finite() {
            return Err(Error::Unrectifiable {
                reason: UnrectifiableReason::ZeroBaseline { baseline: t.norm() },
            });
        }
        let kr = reference.intrinsics();
        let ko = other.intrinsics();
        if ko.width().max(ko.height()) > MAX_SWEEP_SIDE {
            return Err(Error::InvalidParameter {
                name: "image side of a plane-sweep view",
                value: f64::from(ko.width().max(ko.height())),
                expected: "at most 1,048,576 pixels",
            });
        }
        let pixels = u64::from(ko.width()) * u64::from(ko.height());
        if pixels > MAX_SWEEP_PIXELS {
            return Err(Error::InvalidParameter {
                name: "pixels of a plane-sweep view",
                value: pixels as f64,
                expected: "at most 2^31 - 1 pixels",
            });
        }
        let k_other = Matrix3::new(ko.fx(), 0.0, ko.cx(), 0.0, ko.fy(), ko.cy(), 0.0, 0.0, 1.0);
        let k_reference_inverse = Matrix3::new(
            1.0 / kr.fx(),
            0.0,
            -kr.cx() / kr.fx(),
            0.0,
            1.0 / kr.fy(),
            -kr.cy() / kr.fy(),
            0.0,
            0.0,
            1.0,
        );
        let m = k_other
            * other_from_reference.rotation.to_rotation_matrix().matrix()
            * k_reference_inverse;
        let b = k_other * t;
        let (w, h) = (f64::from(kr.width()), f64::from(kr.height()));
        // Where a pixel lands far outside the other image it costs nothing, and next to the
        // other camera's plane its motion grows without bound: only motion within the image
        // grown by its own size on every side counts.
        let (ow, oh) = (f64::from(ko.width()), f64::from(ko.height()));
        let near_image =
            |p: (f64, f64)| (-ow..2.0 * ow).contains(&p.0) && (-oh..2.0 * oh).contains(&p.1);
        let mut rate: f64 = 0.0;
        for (fx, fy) in
            (0..5).flat_map(|i| (0..5).map(move |j| (f64::from(i) / 4.0, f64::from(j) / 4.0)))
        {
            let a = m * Vector3::new(fx * (w - 1.0), fy * (h - 1.0), 1.0);
            let mut previous: Option<(f64, f64)> = None;
            const SAMPLES: u32 = 32;
            for s in 0..=SAMPLES {
                let inverse =
                    inverse_far + (inverse_near - inverse_far) * f64::from(s) / f64::from(SAMPLES);
                let q = a + b * inverse;
                if q.z <= 1e-12 {
                    previous = None;
                    continue;
                }
                let p = (q.x / q.z, q.y / q.z);
                if !near_image(p) {
                    previous = None;
                    continue;
                }
                if let Some(prev) = previous {
                    let moved = ((p.0 - prev.0).powi(2) + (p.1 - prev.1).powi(2)).sqrt();
                    rate = rate.max(moved * f64::from(SAMPLES) / (inverse_near - inverse_far));
                }
                previous = Some(p);
            }
        }
        let cast = |v: f64| v as f32;
        let view = Self {
            homography: std::array::from_fn(|r| std::array::from_fn(|c| cast(m[(r, c)]))),
            translation: [cast(b.x), cast(b.y), cast(b.z)],
        };
        Ok((view, rate))
    }
}

#[cfg(test)]
mod tests {
    use fuzzyvox_core::geometry::PinholeIntrinsics;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    use super::*;
    use crate::GrayImage;

    fn frame(image: GrayImage, k: PinholeIntrinsics, x: f64, z: f64) -> Frame {
        let pose = Isometry3::from_parts(Translation3::new(x, 0.0, z), UnitQuaternion::identity());
        Frame::new(image, k, pose, 0.0).unwrap()
    }

    #[test]
    fn plane_index_maps_to_the_swept_depths() {
        let k = PinholeIntrinsics::new(64, 48, 50.0, 50.0, 31.5, 23.5).unwrap();
        let image = GrayImage::new(64, 48, vec![0.5; 64 * 48]).unwrap();
        let a = frame(image.clone(), k, 0.0, 0.0);
        let b = frame(image, k, 0.0, -0.5);
        let sweep = Sweep::new(&a, &[&b], 2.0, 20.0).unwrap();
        let geometry = sweep.geometry(&a).unwrap();
        let near = geometry.depth(f64::from(sweep.planes - 1)).unwrap();
        let far = geometry.depth(0.0).unwrap();
        assert!((near - 2.0).abs() < 1e-9 && (far - 20.0).abs() < 1e-9);
        // Forward motion of 0.5 m: a corner pixel (about 40 px from the centre) moves
        // 40 · 0.5 · (1/2 - 1/20) ≈ 9 px over the range, so about ten planes.
        assert!((8..=14).contains(&sweep.planes), "{}", sweep.planes);
    }

    #[test]
    fn zero_baseline_and_bad_ranges_are_errors() {
        let k = PinholeIntrinsics::new(16, 16, 20.0, 20.0, 7.5, 7.5).unwrap();
        let image = GrayImage::new(16, 16, vec![0.5; 256]).unwrap();
        let a = frame(image.clone(), k, 0.0, 0.0);
        assert!(matches!(
            Sweep::new(&a, &[&a], 1.0, 10.0),
            Err(Error::Unrectifiable {
                reason: UnrectifiableReason::ZeroBaseline { .. }
            })
        ));
        let b = frame(image, k, 0.0, -1.0);
        assert!(Sweep::new(&a, &[&b], 10.0, 1.0).is_err());
        assert!(Sweep::new(&a, &[&b], f64::NAN, 1.0).is_err());
        // No views, too many, and a view wider than the sweep's pixel arithmetic allows.
        assert!(matches!(
            Sweep::new(&a, &[], 1.0, 10.0),
            Err(Error::Empty(_))
        ));
        let crowd = vec![&b; MAX_SWEEP_VIEWS + 1];
        assert!(Sweep::new(&a, &crowd, 1.0, 10.0).is_err());
        let side = MAX_SWEEP_SIDE + 1;
        let wide_k = PinholeIntrinsics::new(side, 1, 20.0, 20.0, 7.5, 0.0).unwrap();
        let wide = frame(
            GrayImage::new(side, 1, vec![0.5; side as usize]).unwrap(),
            wide_k,
            0.0,
            -1.0,
        );
        assert!(matches!(
            Sweep::new(&a, &[&wide], 1.0, 10.0),
            Err(Error::InvalidParameter { .. })
        ));
    }
}
