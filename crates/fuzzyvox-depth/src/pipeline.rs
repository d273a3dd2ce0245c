//! From a pair of posed frames (or an already rectified pair) to a [`DepthFrame`] of intervals
//! and confidence in the (rectified) reference camera, ready for `integrate_depth`.

use std::time::Instant;

use fuzzyvox_core::image::{Frame, GrayImage, StereoGeometry};

use super::frame::SelectedPair;
use super::interval::{IntervalParams, interval_image};
use super::matching::match_pair;
use super::params::{DisparityMap, MatchParams};
use super::quality::extrinsic_quality;
use super::rectify::{Rectification, Side, epipole_within};
use super::sweep::{Sweep, sweep_views};
use fuzzyvox_core::error::UnrectifiableReason;
use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::DepthFrame;

/// Settings of the whole depth stage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DepthParams {
    /// Matching settings. Its disparity range is replaced when `depth_range` is set.
    pub matching: MatchParams,
    /// Interval and confidence settings.
    pub interval: IntervalParams,
    /// Depths to search, `(near, far)` in metres (`far` may be infinite); sets the disparity
    /// range from the pair's geometry. The plane sweep needs it.
    pub depth_range: Option<(f64, f64)>,
    /// What [`depth_from_pair`] does with a pair whose epipole lies inside an image.
    pub forward_motion: ForwardMotion,
}

/// What to do with a pair that rectification refuses because one camera's centre projects
/// inside the other's image (motion along the look direction).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ForwardMotion {
    /// Refuse it with [`UnrectifiableReason::EpipoleInImage`].
    #[default]
    Reject,
    /// Match it by plane sweep in the original reference camera (see `docs/depth.md`): depth
    /// comes out where the image moves enough, with wide intervals near the epipole, and the
    /// confidence carries the pair's low `Q_ABD`. This is how the wall scenario's receding
    /// pairs reach the maps.
    PlaneSweep,
}

/// How a pair was matched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MatchMethod {
    /// Rectified and matched along rows.
    Rectified,
    /// Plane sweep in the original reference camera.
    PlaneSweep,
    /// Plane sweep in the original reference camera against several other views at once
    /// ([`depth_from_views`]).
    MultiView,
}

/// The depth stage's output for one pair.
#[derive(Clone, Debug)]
pub struct DepthResult {
    /// Interval depth and confidence in the rectified reference camera.
    pub frame: DepthFrame,
    /// The disparities behind it (for a plane sweep: fractional plane indices).
    pub disparity: DisparityMap,
    /// The geometry that turns those disparities into depth in the frame's camera.
    pub geometry: StereoGeometry,
    /// How the pair was matched.
    pub method: MatchMethod,
    /// The pair's `Q_ABD` (several views: the best between the reference and any of them).
    pub quality: f64,
    /// Camera views matched, the reference included: 2 for a pair.
    pub views: usize,
    /// Wall time of the matching step (census, costs, aggregation, checks), in seconds.
    pub matching_seconds: f64,
}

impl DepthResult {
    /// How much of an observation this depth image is worth when consecutive images of a flight
    /// share views: `2 / views`, 1 for a pair.
    ///
    /// In a flight matched pair by pair each camera position feeds two depth images (as one
    /// pair's reference and the next pair's other view); matched with `N - 2` earlier
    /// positions ([`ViewWindow`](super::ViewWindow)) it feeds `N`, and consecutive images,
    /// sharing most of their views, repeat each other's errors. An aggregation that treats
    /// observations as independent (the probabilistic sum) would count those errors `N / 2`
    /// times as often as with pairs. Scaling the image's confidence by this weight
    /// ([`DepthFrame::scale_confidence`](fuzzyvox_core::integrate::DepthFrame::scale_confidence))
    /// keeps every position's total weight what the paper's pairs give it.
    pub fn reuse_weight(&self) -> f32 {
        2.0 / self.views.max(2) as f32
    }
}

/// Depth from a rectified pair (`left(y, x)` matches `right(y, x - d)`) with known geometry.
pub fn depth_from_rectified(
    left: &GrayImage,
    right: &GrayImage,
    geometry: &StereoGeometry,
    quality: f64,
    params: &DepthParams,
) -> Result<DepthResult> {
    params.interval.validate()?;
    let mut matching = params.matching.clone();
    if let Some((near, far)) = params.depth_range {
        let (min, count) = geometry.disparity_range(near, far)?;
        matching.min_disparity = min;
        matching.num_disparities = count;
    }
    let start = Instant::now();
    let disparity = match_pair(left, right, &matching)?;
    let matching_seconds = start.elapsed().as_secs_f64();
    finish(
        disparity,
        geometry,
        quality,
        params,
        matching_seconds,
        MatchMethod::Rectified,
        2,
    )
}

/// Intervals and confidence from a disparity map.
fn finish(
    disparity: DisparityMap,
    geometry: &StereoGeometry,
    quality: f64,
    params: &DepthParams,
    matching_seconds: f64,
    method: MatchMethod,
    views: usize,
) -> Result<DepthResult> {
    let image = interval_image(&disparity, geometry, &params.interval, quality)?;
    let frame = DepthFrame::new(
        *geometry.reference(),
        *geometry.world_from_reference(),
        image,
    )?;
    Ok(DepthResult {
        frame,
        disparity,
        geometry: geometry.clone(),
        method,
        quality,
        views,
        matching_seconds,
    })
}

/// Depth from two posed frames: `Q_ABD`, rectification, matching and intervals. The output is in
/// the rectified `reference` camera (same centre, rotated so the baseline is its x axis), or,
/// for a forward-motion pair with [`ForwardMotion::PlaneSweep`], in the original reference
/// camera.
///
/// Errors: invalid poses, pairs that cannot be rectified (zero baseline, opposite views, and an
/// epipole inside an image unless the plane sweep is chosen), invalid parameters.
pub fn depth_from_pair(
    reference: &Frame,
    other: &Frame,
    params: &DepthParams,
) -> Result<DepthResult> {
    let quality = extrinsic_quality(reference.world_from_camera(), other.world_from_camera())?;
    if params.forward_motion == ForwardMotion::PlaneSweep && epipole_near_image(reference, other) {
        return depth_by_plane_sweep(reference, other, quality.q, params);
    }
    let rectification = match Rectification::new(
        reference.intrinsics(),
        reference.world_from_camera(),
        other.intrinsics(),
        other.world_from_camera(),
    ) {
        Err(Error::Unrectifiable {
            reason: UnrectifiableReason::EpipoleInImage { .. },
        }) if params.forward_motion == ForwardMotion::PlaneSweep => {
            return depth_by_plane_sweep(reference, other, quality.q, params);
        }
        other => other?,
    };
    let left = rectification.warp(Side::Reference, reference.image())?;
    let right = rectification.warp(Side::Other, other.image())?;
    depth_from_rectified(&left, &right, rectification.geometry(), quality.q, params)
}

/// How far outside an image (as a fraction of its width and height, on every side) an epipole
/// still sends a pair to the plane sweep under [`ForwardMotion::PlaneSweep`].
///
/// Rectification turns both cameras to look across the baseline; with the epipole just outside
/// the image (the vehicle flying nearly at what it looks at, pitching or turning) that warps the
/// images so far that matching along rows finds confident false matches. In the closed-loop
/// flights two such pairs, with the epipole 77 and 96 px below a 240 px image, gave 2,750 and
/// 1,870 pixels at under 2 m where the true surface lay beyond 20 m (`docs/depth.md`).
pub const SWEEP_EPIPOLE_MARGIN: f64 = 0.5;

/// Whether either camera's epipole lies within [`SWEEP_EPIPOLE_MARGIN`] of its image.
fn epipole_near_image(reference: &Frame, other: &Frame) -> bool {
    let (a, b) = (reference.world_from_camera(), other.world_from_camera());
    [(reference, a, b), (other, b, a)]
        .into_iter()
        .any(|(frame, pose, seen)| {
            epipole_within(
                frame.intrinsics(),
                pose,
                &seen.translation.vector,
                SWEEP_EPIPOLE_MARGIN,
            )
            .is_some()
        })
}

/// Depth from two posed frames by plane sweep in the original reference camera, whatever their
/// geometry (any baseline direction; see [`ForwardMotion::PlaneSweep`]). `params.depth_range`
/// is required; `quality` is the pair's `Q_ABD`.
pub fn depth_by_plane_sweep(
    reference: &Frame,
    other: &Frame,
    quality: f64,
    params: &DepthParams,
) -> Result<DepthResult> {
    sweep(
        reference,
        &[other],
        quality,
        params,
        MatchMethod::PlaneSweep,
    )
}

/// Depth in `reference`'s own camera from several other views at once: a multiple-baseline
/// plane sweep (see `docs/depth.md`). Each plane's cost is the mean census distance over the
/// views a pixel lands in; the longest baseline sets the plane step, so depth is as fine as that
/// baseline allows while the shorter ones keep the match unambiguous. The confidence carries the
/// best `Q_ABD` between the reference and any of the views. `params.depth_range` is required.
///
/// Errors: no other view or more than [`MAX_SWEEP_VIEWS`](super::MAX_SWEEP_VIEWS), invalid
/// poses, a view at the reference's position, a view larger than
/// [`MAX_SWEEP_SIDE`](super::MAX_SWEEP_SIDE) a side or [`MAX_SWEEP_PIXELS`](super::MAX_SWEEP_PIXELS)
/// in all, a depth range that needs more than 1024 planes for the longest baseline, invalid
/// parameters.
pub fn depth_from_views(
    reference: &Frame,
    others: &[&Frame],
    params: &DepthParams,
) -> Result<DepthResult> {
    let mut quality: f64 = 0.0;
    for other in others {
        let q = extrinsic_quality(reference.world_from_camera(), other.world_from_camera())?;
        quality = quality.max(q.q);
    }
    sweep(reference, others, quality, params, MatchMethod::MultiView)
}

/// The plane sweep behind [`depth_by_plane_sweep`] and [`depth_from_views`].
fn sweep(
    reference: &Frame,
    others: &[&Frame],
    quality: f64,
    params: &DepthParams,
    method: MatchMethod,
) -> Result<DepthResult> {
    params.interval.validate()?;
    let Some((near, far)) = params.depth_range else {
        return Err(Error::InvalidParameter {
            name: "depth_range",
            value: f64::NAN,
            expected: "a depth range (near, far) for the plane sweep",
        });
    };
    let sweep = Sweep::new(reference, others, near, far)?;
    let geometry = sweep.geometry(reference)?;
    let start = Instant::now();
    let disparity = sweep_views(reference, others, &sweep, &params.matching)?;
    let matching_seconds = start.elapsed().as_secs_f64();
    finish(
        disparity,
        &geometry,
        quality,
        params,
        matching_seconds,
        method,
        1 + others.len(),
    )
}

/// Depth from a pair chosen by a [`PairSelector`](super::PairSelector).
pub fn depth_from_selected(pair: &SelectedPair, params: &DepthParams) -> Result<DepthResult> {
    depth_from_pair(&pair.reference, &pair.other, params)
}
