//! From a pair of posed frames (or an already rectified pair) to a [`DepthFrame`] of intervals
//! and confidence in the rectified reference camera, ready for `integrate_depth`.

use std::time::Instant;

use super::frame::{Frame, SelectedPair};
use super::gray::GrayImage;
use super::interval::{IntervalParams, interval_image};
use super::matching::match_pair;
use super::params::{DisparityMap, MatchParams};
use super::quality::extrinsic_quality;
use super::rectify::{Rectification, Side, StereoGeometry};
use crate::error::Result;
use crate::integrate::DepthFrame;

/// Settings of the whole depth stage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DepthParams {
    /// Matching settings. Its disparity range is replaced when `depth_range` is set.
    pub matching: MatchParams,
    /// Interval and confidence settings.
    pub interval: IntervalParams,
    /// Depths to search, `(near, far)` in metres (`far` may be infinite); sets the disparity
    /// range from the pair's geometry.
    pub depth_range: Option<(f64, f64)>,
}

/// The depth stage's output for one pair.
#[derive(Clone, Debug)]
pub struct DepthResult {
    /// Interval depth and confidence in the rectified reference camera.
    pub frame: DepthFrame,
    /// The disparities behind it.
    pub disparity: DisparityMap,
    /// The rectified pair's geometry.
    pub geometry: StereoGeometry,
    /// The pair's `Q_ABD`.
    pub quality: f64,
    /// Wall time of the matching step (census, costs, aggregation, checks), in seconds.
    pub matching_seconds: f64,
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
        quality,
        matching_seconds,
    })
}

/// Depth from two posed frames: `Q_ABD`, rectification, matching and intervals. The output is in
/// the rectified `reference` camera (same centre, rotated so the baseline is its x axis).
///
/// Errors: invalid poses, pairs that cannot be rectified (zero baseline, epipole inside an
/// image, opposite views), invalid parameters.
pub fn depth_from_pair(
    reference: &Frame,
    other: &Frame,
    params: &DepthParams,
) -> Result<DepthResult> {
    let quality = extrinsic_quality(reference.world_from_camera(), other.world_from_camera())?;
    let rectification = Rectification::new(
        reference.intrinsics(),
        reference.world_from_camera(),
        other.intrinsics(),
        other.world_from_camera(),
    )?;
    let left = rectification.warp(Side::Reference, reference.image())?;
    let right = rectification.warp(Side::Other, other.image())?;
    depth_from_rectified(&left, &right, rectification.geometry(), quality.q, params)
}

/// Depth from a pair chosen by a [`PairSelector`](super::PairSelector).
pub fn depth_from_selected(pair: &SelectedPair, params: &DepthParams) -> Result<DepthResult> {
    depth_from_pair(&pair.reference, &pair.other, params)
}
