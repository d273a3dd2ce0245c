//! A window of a flight's recent frames, so that each new pair is matched together with the
//! earlier camera positions (multi-view depth, see [`depth_from_views`]).

use fuzzyvox_core::image::Frame;

use super::pipeline::{DepthParams, DepthResult, depth_from_pair, depth_from_views};
use super::sweep::{MAX_SWEEP_VIEWS, PLANE_COUNT};
use crate::MAX_DISPARITIES;
use fuzzyvox_core::error::{Error, Result};

/// Camera positions closer than this (metres) count as one and add no baseline.
const SAME_POSITION: f64 = 1e-6;

/// The frames of the last few camera positions of a flight.
///
/// [`ViewWindow::depth`] matches a new pair `(reference, other)` together with up to
/// `views - 2` earlier positions, newest first, by a multiple-baseline plane sweep; with no
/// earlier position (the first pair, or `views == 2`) the pair is matched on its own by
/// [`depth_from_pair`]. Earlier positions are left out, oldest first, while the longest baseline
/// would need more planes than a sweep has (see [`DepthResult::views`] for how many were used);
/// a pair that alone needs too many planes (a long baseline along the view) is swept over a
/// shorter range, its near end moved out until the planes fit, instead of giving no depth.
/// Both frames of every pair are remembered, whether or not the depth stage could use the pair.
#[derive(Clone, Debug)]
pub struct ViewWindow {
    views: usize,
    /// Remembered frames, oldest first.
    history: Vec<Frame>,
    /// Earlier positions left out so far because of the plane limit.
    dropped: usize,
}

impl ViewWindow {
    /// A window giving each depth image `views` camera views: 2 (each pair on its own) to
    /// `MAX_SWEEP_VIEWS + 1`.
    pub fn new(views: usize) -> Result<Self> {
        if !(2..=MAX_SWEEP_VIEWS + 1).contains(&views) {
            return Err(Error::InvalidParameter {
                name: "views",
                value: views as f64,
                expected: "2 to 17 camera views per depth image",
            });
        }
        Ok(Self {
            views,
            history: Vec::new(),
            dropped: 0,
        })
    }

    /// Camera views per depth image asked for.
    pub fn views(&self) -> usize {
        self.views
    }

    /// Earlier positions left out so far, over every pair since the window was made, because
    /// with them the longest baseline would need more planes than a sweep has.
    pub fn views_dropped(&self) -> usize {
        self.dropped
    }

    /// Forgets every remembered frame (a new flight, or a new phase of one).
    pub fn clear(&mut self) {
        self.history.clear();
    }

    /// Depth for the pair `(reference, other)` from it and the window's earlier positions (see
    /// the type's documentation); then remembers both frames.
    pub fn depth(
        &mut self,
        reference: Frame,
        other: Frame,
        params: &DepthParams,
    ) -> Result<DepthResult> {
        let (result, dropped) = self.match_views(&reference, &other, params);
        self.dropped += dropped;
        self.remember(reference, other);
        result
    }

    /// The depth that [`ViewWindow::depth`] would give the pair now, without remembering its
    /// frames or counting left-out views: to match one pair against the same earlier positions
    /// more than once (a benchmark), or to look before committing a pair to the window.
    pub fn preview(
        &self,
        reference: &Frame,
        other: &Frame,
        params: &DepthParams,
    ) -> Result<DepthResult> {
        self.match_views(reference, other, params).0
    }

    /// Remembers a pair's frames as earlier positions for the pairs that follow, without
    /// matching it (a window of two views remembers nothing).
    pub fn remember(&mut self, reference: Frame, other: Frame) {
        if self.views > 2 {
            self.history.push(other);
            self.history.push(reference);
            // Twice the views: enough distinct positions even when consecutive pairs share one.
            let excess = self.history.len().saturating_sub(2 * self.views);
            self.history.drain(..excess);
        }
    }

    /// The pair's depth and how many earlier positions had to be left out.
    fn match_views(
        &self,
        reference: &Frame,
        other: &Frame,
        params: &DepthParams,
    ) -> (Result<DepthResult>, usize) {
        let mut others = vec![other];
        let position = |f: &Frame| f.world_from_camera().translation.vector;
        for frame in self.history.iter().rev() {
            if others.len() == self.views - 1 {
                break;
            }
            let p = position(frame);
            let same = |f: &&Frame| (position(f) - p).norm() <= SAME_POSITION;
            if !same(&reference) && !others.iter().any(same) {
                others.push(frame);
            }
        }
        let mut dropped = 0;
        while others.len() > 1 {
            match depth_from_views(reference, &others, params) {
                Err(Error::InvalidParameter { name, .. }) if name == PLANE_COUNT => {
                    others.pop();
                    dropped += 1;
                }
                result => return (result, dropped),
            }
        }
        (pair_within_planes(reference, other, params), dropped)
    }
}

/// [`depth_from_pair`], and when the pair's sweep over the depth range would need more planes
/// than a sweep has (a long baseline along the view), the same pair swept over a shorter range:
/// the near end moved out until the planes fit. Pixels nearer than that get no depth (or are
/// left to the consistency check), instead of the whole frame getting none.
fn pair_within_planes(
    reference: &Frame,
    other: &Frame,
    params: &DepthParams,
) -> Result<DepthResult> {
    let mut params = params.clone();
    let mut result = depth_from_pair(reference, other, &params);
    // Each try shrinks the inverse-depth span by the planes' overshoot, and at least by half:
    // the image motion per unit of inverse depth is largest near the camera, so the planes
    // needed fall faster than the span once the nearest depths go.
    for _ in 0..12 {
        let needed = match &result {
            Err(Error::InvalidParameter { name, value, .. }) if *name == PLANE_COUNT => *value,
            _ => break,
        };
        let Some((near, far)) = params.depth_range else {
            break;
        };
        let inverse_far = if far.is_finite() { 1.0 / far } else { 0.0 };
        let fit = f64::from(MAX_DISPARITIES - 24) / (needed - 1.0).max(1.0);
        let inverse_near = inverse_far + (1.0 / near - inverse_far) * fit.min(0.5);
        if !(inverse_near.is_finite() && inverse_near > inverse_far) {
            break;
        }
        params.depth_range = Some((1.0 / inverse_near, far));
        result = depth_from_pair(reference, other, &params);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ForwardMotion, GrayImage};
    use fuzzyvox_core::geometry::PinholeIntrinsics;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    /// A frame at `x` on a line, looking along +z at a striped plane 5 m away.
    fn frame(x: f64) -> Frame {
        let k = PinholeIntrinsics::new(64, 48, 60.0, 60.0, 31.5, 23.5).unwrap();
        let pixels = (0..48)
            .flat_map(|_| {
                (0..64).map(move |u| {
                    // World x of the plane point seen at column u: x + (u - cx) / f · 5.
                    let world = x + (f64::from(u) - 31.5) / 60.0 * 5.0;
                    ((world * 7.0).sin() * 0.4 + 0.5) as f32
                })
            })
            .collect();
        let image = GrayImage::new(64, 48, pixels).unwrap();
        let pose =
            Isometry3::from_parts(Translation3::new(x, 0.0, 0.0), UnitQuaternion::identity());
        Frame::new(image, k, pose, x).unwrap()
    }

    /// A frame at `z` on the optical axis, looking along +z at a textured wall at z = 5 m.
    fn forward(z: f64) -> Frame {
        let k = PinholeIntrinsics::new(64, 48, 60.0, 60.0, 31.5, 23.5).unwrap();
        let pixels = (0..48)
            .flat_map(|v| {
                (0..64).map(move |u| {
                    let scale = (5.0 - z) / 60.0;
                    let (x, y) = ((f64::from(u) - 31.5) * scale, (f64::from(v) - 23.5) * scale);
                    ((x * 9.0).sin() * (y * 7.0).cos() * 0.4 + 0.5) as f32
                })
            })
            .collect();
        let image = GrayImage::new(64, 48, pixels).unwrap();
        let pose =
            Isometry3::from_parts(Translation3::new(0.0, 0.0, z), UnitQuaternion::identity());
        Frame::new(image, k, pose, z).unwrap()
    }

    fn params() -> DepthParams {
        DepthParams {
            depth_range: Some((2.0, 20.0)),
            forward_motion: ForwardMotion::PlaneSweep,
            ..DepthParams::default()
        }
    }

    #[test]
    fn window_adds_earlier_positions_up_to_its_size() {
        assert!(ViewWindow::new(1).is_err());
        assert!(ViewWindow::new(MAX_SWEEP_VIEWS + 2).is_err());
        let mut window = ViewWindow::new(4).unwrap();
        // A chain of pairs sharing positions, as a flight gives: (0.1, 0), (0.2, 0.1), ...
        let (mut used, mut weights) = (Vec::new(), Vec::new());
        for i in 1..=4 {
            let x = 0.1 * f64::from(i);
            let result = window.depth(frame(x), frame(x - 0.1), &params()).unwrap();
            used.push(result.views);
            weights.push(result.reuse_weight());
        }
        // The first pair alone, then one and two earlier positions (the shared one counts once).
        assert_eq!(used, vec![2, 3, 4, 4]);
        // Their weights when images sharing views are counted as pairs: 2 / views.
        assert_eq!(weights, vec![1.0, 2.0 / 3.0, 0.5, 0.5]);
        window.clear();
        let result = window.depth(frame(1.0), frame(0.9), &params()).unwrap();
        assert_eq!(result.views, 2);
        // A window of two views matches every pair on its own.
        let mut pairs = ViewWindow::new(2).unwrap();
        for i in 1..=3 {
            let x = 0.1 * f64::from(i);
            assert_eq!(
                pairs
                    .depth(frame(x), frame(x - 0.1), &params())
                    .unwrap()
                    .views,
                2
            );
        }
    }

    #[test]
    fn views_that_need_too_many_planes_are_left_out() {
        let mut window = ViewWindow::new(3).unwrap();
        let params = DepthParams {
            depth_range: Some((0.05, 1000.0)),
            ..params()
        };
        window.depth(frame(-1.0), frame(-1.1), &params).unwrap();
        // Over 5 cm to 1 km the pair's 0.1 m baseline needs 120 planes, the earlier position's
        // 1.1 m about 1,300: that view is left out.
        let result = window.depth(frame(0.1), frame(0.0), &params).unwrap();
        assert_eq!(result.views, 2);
        assert_eq!(window.views_dropped(), 1);
    }

    #[test]
    fn a_pair_that_needs_too_many_planes_is_swept_over_a_shorter_range() {
        // Moving 0.3 m towards the wall, a sweep from 0.5 mm to 1 km needs more planes than a
        // sweep has: the near end moves out until it fits, and the wall, 4.7 m away, still
        // gets depth about as a sweep over a sensible range gives it.
        let params = DepthParams {
            depth_range: Some((0.0005, 1000.0)),
            ..params()
        };
        let error = depth_from_pair(&forward(0.3), &forward(0.0), &params).unwrap_err();
        assert!(matches!(error, Error::InvalidParameter { name, .. } if name == PLANE_COUNT));
        let depths = |result: DepthResult| -> Vec<f32> {
            let mut depths: Vec<f32> = result
                .frame
                .image()
                .depth()
                .iter()
                .copied()
                .filter(|d| d.is_finite())
                .collect();
            depths.sort_by(f32::total_cmp);
            depths
        };
        let mut window = ViewWindow::new(2).unwrap();
        let shorter = depths(window.depth(forward(0.3), forward(0.0), &params).unwrap());
        let sensible = DepthParams {
            depth_range: Some((1.0, 20.0)),
            ..params.clone()
        };
        let plain = depths(depth_from_pair(&forward(0.3), &forward(0.0), &sensible).unwrap());
        assert!(
            shorter.len() >= plain.len() / 2,
            "{} of {}",
            shorter.len(),
            plain.len()
        );
        let median = shorter[shorter.len() / 2];
        assert!((median - 4.7).abs() < 0.2 * 4.7, "median depth {median}");
    }

    #[test]
    fn preview_matches_as_depth_would_and_changes_nothing() {
        let mut window = ViewWindow::new(4).unwrap();
        window.remember(frame(0.1), frame(0.0));
        window.remember(frame(0.2), frame(0.1));
        let remembered = window.history.len();
        // Depth as bits (NaN where a pixel has none).
        let bits = |r: &DepthResult| -> Vec<u32> {
            r.frame
                .image()
                .depth()
                .iter()
                .map(|d| d.to_bits())
                .collect()
        };
        let preview = window.preview(&frame(0.3), &frame(0.2), &params()).unwrap();
        assert_eq!(preview.views, 4);
        assert!(preview.frame.image().depth().iter().any(|d| d.is_finite()));
        // Previewing twice gives the same bits: the window did not change.
        let again = window.preview(&frame(0.3), &frame(0.2), &params()).unwrap();
        assert_eq!(bits(&preview), bits(&again));
        assert_eq!(window.history.len(), remembered);
        let committed = window.depth(frame(0.3), frame(0.2), &params()).unwrap();
        assert_eq!(bits(&preview), bits(&committed));
        assert_eq!(window.history.len(), remembered + 2);
        // A window of two views remembers nothing.
        let mut pairs = ViewWindow::new(2).unwrap();
        pairs.remember(frame(0.1), frame(0.0));
        assert!(pairs.history.is_empty());
    }
}
