//! Consistency across views: a pixel's depth carried into the neighbouring depth images of the
//! same stream and kept only where they agree.
//!
//! One pair's match can be confidently wrong (a repeated texture, a reflection, an occlusion
//! edge), and on real footage such pixels become phantom surfaces in every map. Another depth
//! image of the same scene from a nearby position rarely makes the same mistake at the same
//! place: carried into it, a right depth lands on that image's own estimate of the same surface,
//! a wrong one lands in front of it (the neighbour sees through the phantom) or behind it.
//! [`check_consistency`] counts, per pixel, the neighbours that agree and the neighbours that
//! see through, keeps the pixels enough neighbours agree on, and scales their confidence by the
//! share of agreeing votes; [`ConsistencyFilter`] runs it over a stream, each image checked
//! against the images before and after it.

use std::collections::VecDeque;

use nalgebra::Point3;
use rayon::prelude::*;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::{DepthFrame, IntervalDepthImage};

/// The settings of [`check_consistency`] and [`ConsistencyFilter`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConsistencyParams {
    /// Neighbouring depth images on each side that a [`ConsistencyFilter`] checks an image
    /// against (0: the filter passes images through unchanged).
    pub neighbours: usize,
    /// Relative depth difference within which a neighbour agrees: the pixel's depth carried into
    /// the neighbour's camera and the neighbour's own depth there differ by at most this
    /// fraction of the carried depth.
    pub tolerance: f32,
    /// Agreeing neighbours a pixel needs to keep its depth. Default 1: a pixel that no
    /// neighbour confirms is dropped; a confirmed one keeps a confidence scaled by the share of
    /// voting neighbours that agree. On the shared HoloLens frames (0.05 m, four windows) 1
    /// rather than 2 keeps 29-60% more depth and lifts the fuzzy map's `within_2_voxels` by
    /// 0.007-0.045 (the log-odds map's falls by 0.01-0.06: it counts every kept depth alike).
    pub min_agreeing: usize,
    /// Smallest half-width of a kept pixel's interval, as a fraction of its depth: `[P-, P+]`
    /// is widened to at least `P0 · (1 ± floor)`. Depths within the tolerance count as the same
    /// surface, so an interval narrower than that claims more than the check can tell; on the
    /// shared real frames the cost curve's own intervals held the sensor's depth for 78% of the
    /// kept pixels, widened to ±5% for 91%.
    pub interval_floor: f32,
    /// The far end of the depth search (metres), when known: pixels within the tolerance of it
    /// are dropped whatever the votes. A match that stopped at the end of the search found no
    /// minimum inside it, and neighbours whose searches stopped there too agree without having
    /// seen a surface (on the shared 7-Scenes frames, 40% of the pixels the check kept were such
    /// pixels, at 2-3 times the true depth).
    pub search_far: Option<f64>,
}

impl Default for ConsistencyParams {
    fn default() -> Self {
        Self {
            neighbours: 4,
            tolerance: 0.03,
            min_agreeing: 1,
            interval_floor: 0.05,
            search_far: None,
        }
    }
}

impl ConsistencyParams {
    /// Checks the values: a tolerance and an interval floor in `(0, 1)` (a floor of 0
    /// allowed), at least one agreeing neighbour needed, and no more than the neighbours on
    /// both sides can give.
    pub fn validate(&self) -> Result<()> {
        if let Some(far) = self.search_far
            && !(far.is_finite() && far > 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "search_far",
                value: far,
                expected: "a finite positive depth in metres",
            });
        }
        if !(self.interval_floor >= 0.0 && self.interval_floor < 1.0) {
            return Err(Error::InvalidParameter {
                name: "interval_floor",
                value: f64::from(self.interval_floor),
                expected: "a fraction of the depth in [0, 1)",
            });
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(Error::InvalidParameter {
                name: "consistency tolerance",
                value: f64::from(self.tolerance),
                expected: "a relative depth difference in (0, 1)",
            });
        }
        if self.neighbours > 0 && !(1..=2 * self.neighbours).contains(&self.min_agreeing) {
            return Err(Error::InvalidParameter {
                name: "min_agreeing",
                value: self.min_agreeing as f64,
                expected: "1 to twice the neighbours on each side",
            });
        }
        Ok(())
    }
}

/// What [`check_consistency`] found, pixel by pixel and in total.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConsistencyVotes {
    /// Per pixel, the neighbours whose own depth agrees with the pixel's.
    pub agreeing: Vec<u8>,
    /// Per pixel, the neighbours that see farther than the pixel's depth where it lands: they
    /// see through the surface it claims.
    pub seeing_through: Vec<u8>,
    /// Pixels with depth before the check.
    pub checked: usize,
    /// Of those, the pixels kept.
    pub kept: usize,
}

/// Checks `target`'s pixels against `neighbours` (depth images of the same scene from other
/// positions) and returns the target with the pixels that fewer than `params.min_agreeing`
/// neighbours agree on removed (all planes NaN). A kept pixel's depth becomes the mean of its
/// own and the agreeing neighbours' depths (carried back along its ray), its interval is
/// widened to at least `±interval_floor` of that depth, and its confidence and reliability are
/// scaled by `agreeing / (agreeing + seeing_through)`.
///
/// A neighbour votes on a pixel when the pixel's depth `P0`, carried into the neighbour's camera,
/// lands in front of it and inside its image on a pixel with depth `d`: it agrees when
/// `|z - d| <= tolerance · z` (`z` the carried depth along the neighbour's axis), sees through
/// when `d > z · (1 + tolerance)`, and otherwise (something nearer hides the point from it)
/// does not vote.
pub fn check_consistency(
    target: &DepthFrame,
    neighbours: &[&DepthFrame],
    params: &ConsistencyParams,
) -> Result<(DepthFrame, ConsistencyVotes)> {
    params.validate()?;
    let image = target.image();
    let k = target.intrinsics();
    let width = image.width() as usize;
    let pixels = image.depth().len();
    let mut agreeing = vec![0u8; pixels];
    let mut seeing_through = vec![0u8; pixels];
    // Sum of the agreeing neighbours' depths, carried back along the pixel's ray.
    let mut agreeing_depth = vec![0f32; pixels];
    let tolerance = f64::from(params.tolerance);
    for neighbour in neighbours {
        let from_target = neighbour.world_from_camera().inverse() * target.world_from_camera();
        let kn = neighbour.intrinsics();
        let theirs = neighbour.image().depth();
        let their_width = neighbour.image().width() as usize;
        agreeing
            .par_chunks_mut(width)
            .zip(seeing_through.par_chunks_mut(width))
            .zip(agreeing_depth.par_chunks_mut(width))
            .enumerate()
            .for_each(|(y, ((agree_row, through_row), sum_row))| {
                let row = &image.depth()[y * width..(y + 1) * width];
                for (x, &depth) in row.iter().enumerate() {
                    if !(depth.is_finite() && depth > 0.0) {
                        continue;
                    }
                    let p = from_target * k.back_project(x as f64, y as f64, f64::from(depth));
                    let Some(d) = depth_at(kn, theirs, their_width, &p) else {
                        continue;
                    };
                    if (p.z - d).abs() <= tolerance * p.z {
                        agree_row[x] = agree_row[x].saturating_add(1);
                        sum_row[x] += (f64::from(depth) * d / p.z) as f32;
                    } else if d > p.z * (1.0 + tolerance) {
                        through_row[x] = through_row[x].saturating_add(1);
                    }
                }
            });
    }
    let mut near = image.near().to_vec();
    let mut depth = image.depth().to_vec();
    let mut far = image.far().to_vec();
    let mut confidence = image.confidence().to_vec();
    let mut reliability = image.reliability().map(<[f32]>::to_vec);
    let mut votes = ConsistencyVotes::default();
    for i in 0..pixels {
        if !(depth[i].is_finite() && depth[i] > 0.0) {
            continue;
        }
        votes.checked += 1;
        let (agree, through) = (usize::from(agreeing[i]), usize::from(seeing_through[i]));
        // Views whose search all stopped at its far end agree without having seen a surface.
        let at_far_end = params
            .search_far
            .is_some_and(|far| f64::from(depth[i]) >= far * (1.0 - tolerance));
        if agree >= params.min_agreeing.max(1) && !at_far_end {
            votes.kept += 1;
            let share = agree as f32 / (agree + through) as f32;
            confidence[i] *= share;
            if let Some(plane) = &mut reliability {
                plane[i] *= share;
            }
            // The mean of the pixel's own depth and the agreeing ones, inside a widened interval.
            let fused = (depth[i] + agreeing_depth[i]) / (agree + 1) as f32;
            depth[i] = fused;
            near[i] = near[i].min(fused * (1.0 - params.interval_floor));
            if far[i].is_finite() {
                far[i] = far[i].max(fused * (1.0 + params.interval_floor));
            }
        } else {
            for plane in [&mut near, &mut depth, &mut far, &mut confidence] {
                plane[i] = f32::NAN;
            }
            if let Some(plane) = &mut reliability {
                plane[i] = f32::NAN;
            }
        }
    }
    let mut checked =
        IntervalDepthImage::new(image.width(), image.height(), near, depth, far, confidence)?;
    if let Some(plane) = reliability {
        checked = checked.with_reliability(plane)?;
    }
    votes.agreeing = agreeing;
    votes.seeing_through = seeing_through;
    let frame = DepthFrame::new(*k, *target.world_from_camera(), checked)?;
    Ok((frame, votes))
}

/// The neighbour's depth at the pixel `p` (a point in its camera) lands on, when `p` is in front
/// of it and inside its image and that pixel has depth.
fn depth_at(
    k: &fuzzyvox_core::geometry::PinholeIntrinsics,
    depth: &[f32],
    width: usize,
    p: &Point3<f64>,
) -> Option<f64> {
    let (x, y) = k.pixel_of(p)?;
    let d = *depth.get(y as usize * width + x as usize)?;
    (d.is_finite() && d > 0.0).then_some(f64::from(d))
}

/// Totals of a [`ConsistencyFilter`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ConsistencyCounts {
    /// Images checked.
    pub images: usize,
    /// Pixels with depth before the check.
    pub checked: usize,
    /// Of those, the pixels kept.
    pub kept: usize,
}

/// [`check_consistency`] over a stream of depth images: each image is checked against up to
/// `params.neighbours` images before it and as many after it, so it leaves the filter once that
/// many later images have come in (or at [`ConsistencyFilter::finish`]). The neighbours are the
/// images as the depth stage made them, not as filtered. Each image carries a tag (a frame
/// number, say) back out with it.
#[derive(Clone, Debug)]
pub struct ConsistencyFilter<T> {
    params: ConsistencyParams,
    /// Images still needed: up to `neighbours` already sent out, then the waiting ones.
    images: VecDeque<(T, DepthFrame)>,
    /// How many of `images` have been sent out.
    sent: usize,
    counts: ConsistencyCounts,
}

impl<T: Clone> ConsistencyFilter<T> {
    /// A filter of these settings.
    pub fn new(params: ConsistencyParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            images: VecDeque::new(),
            sent: 0,
            counts: ConsistencyCounts::default(),
        })
    }

    /// The settings.
    pub fn params(&self) -> &ConsistencyParams {
        &self.params
    }

    /// What the filter has done so far.
    pub fn counts(&self) -> ConsistencyCounts {
        self.counts
    }

    /// Adds the next depth image; returns the images that are now checked, in stream order.
    pub fn push(&mut self, tag: T, frame: DepthFrame) -> Result<Vec<(T, DepthFrame)>> {
        self.images.push_back((tag, frame));
        let mut out = Vec::new();
        while self.images.len() - self.sent > self.params.neighbours {
            out.push(self.send_next()?);
        }
        Ok(out)
    }

    /// Checks and returns every image still waiting (the end of the stream).
    pub fn finish(&mut self) -> Result<Vec<(T, DepthFrame)>> {
        let mut out = Vec::new();
        while self.sent < self.images.len() {
            out.push(self.send_next()?);
        }
        Ok(out)
    }

    /// Checks the oldest waiting image against its neighbours and forgets what no later image
    /// needs.
    fn send_next(&mut self) -> Result<(T, DepthFrame)> {
        let at = self.sent;
        let n = self.params.neighbours;
        let (tag, frame) = &self.images[at];
        let result = if n == 0 {
            frame.clone()
        } else {
            let neighbours: Vec<&DepthFrame> = self
                .images
                .iter()
                .enumerate()
                .filter(|&(i, _)| i != at && i + n >= at && i <= at + n)
                .map(|(_, (_, f))| f)
                .collect();
            let (checked, votes) = check_consistency(frame, &neighbours, &self.params)?;
            self.counts.checked += votes.checked;
            self.counts.kept += votes.kept;
            checked
        };
        let tag = tag.clone();
        self.counts.images += 1;
        self.sent += 1;
        while self.sent > n {
            self.images.pop_front();
            self.sent -= 1;
        }
        Ok((tag, result))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::geometry::PinholeIntrinsics;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    const W: u32 = 40;
    const H: u32 = 30;

    /// A camera at `x` on a line looking along +z at a wall 5 m away: every pixel's depth is 5,
    /// with an interval of ±2% and confidence 0.8, except `wrong` pixels (indices), which claim
    /// a surface at 2 m.
    fn frame(x: f64, wrong: &[usize]) -> DepthFrame {
        let k = PinholeIntrinsics::new(W, H, 40.0, 40.0, 19.5, 14.5).unwrap();
        let n = (W * H) as usize;
        let mut depth = vec![5.0f32; n];
        for &i in wrong {
            depth[i] = 2.0;
        }
        let near = depth.iter().map(|d| d * 0.98).collect();
        let far = depth.iter().map(|d| d * 1.02).collect();
        let image = IntervalDepthImage::new(W, H, near, depth, far, vec![0.8; n]).unwrap();
        let pose =
            Isometry3::from_parts(Translation3::new(x, 0.0, 0.0), UnitQuaternion::identity());
        DepthFrame::new(k, pose, image).unwrap()
    }

    #[test]
    fn a_pixel_its_neighbour_views_see_through_loses_its_depth() {
        let centre = (15 * W + 20) as usize;
        let target = frame(0.0, &[centre]);
        let (left, right) = (frame(-0.1, &[]), frame(0.1, &[]));
        let params = ConsistencyParams::default();
        let (checked, votes) = check_consistency(&target, &[&left, &right], &params).unwrap();
        // Both neighbours see the wall at 5 m where the 2 m claim lands: they see through it.
        assert_eq!(votes.seeing_through[centre], 2);
        assert_eq!(votes.agreeing[centre], 0);
        assert!(checked.image().depth()[centre].is_nan());
        assert!(checked.image().confidence()[centre].is_nan());
        // A pixel of the wall both agree on keeps its depth and its full confidence, and its
        // interval widens to the ±5% floor.
        let wall = (15 * W + 21) as usize;
        assert_eq!(votes.agreeing[wall], 2);
        assert_eq!(checked.image().depth()[wall], 5.0);
        assert_eq!(checked.image().confidence()[wall], 0.8);
        assert_eq!(checked.image().near()[wall], 5.0 * 0.95);
        assert_eq!(checked.image().far()[wall], 5.0 * 1.05);
        assert_eq!(votes.checked, (W * H) as usize);
        assert!(votes.kept < votes.checked);
    }

    #[test]
    fn confidence_falls_with_the_share_of_views_that_see_through() {
        let centre = (15 * W + 20) as usize;
        // The target and one neighbour claim a surface at 2 m; where that neighbour's claim
        // lands, two others see the wall behind it. With two agreeing views needed, the pixel
        // goes; with one, it stays at a third of its confidence.
        let target = frame(0.0, &[centre]);
        let twin = frame(0.0, &[centre]);
        let others = [frame(-0.1, &[]), frame(0.1, &[])];
        let neighbours = [&twin, &others[0], &others[1]];
        let strict = ConsistencyParams {
            min_agreeing: 2,
            ..ConsistencyParams::default()
        };
        let (checked, _) = check_consistency(&target, &neighbours, &strict).unwrap();
        assert!(checked.image().depth()[centre].is_nan());
        let lenient = ConsistencyParams::default();
        let (checked, votes) = check_consistency(&target, &neighbours, &lenient).unwrap();
        assert_eq!(
            (votes.agreeing[centre], votes.seeing_through[centre]),
            (1, 2)
        );
        let confidence = checked.image().confidence()[centre];
        assert!((confidence - 0.8 / 3.0).abs() < 1e-6, "{confidence}");
    }

    #[test]
    fn the_filter_checks_each_image_against_both_sides_and_keeps_the_order() {
        let params = ConsistencyParams {
            neighbours: 1,
            min_agreeing: 1,
            ..ConsistencyParams::default()
        };
        let mut filter = ConsistencyFilter::new(params).unwrap();
        let mut out = Vec::new();
        for i in 0..4 {
            let ready = filter.push(i, frame(0.1 * f64::from(i), &[])).unwrap();
            // An image leaves once its later neighbour has come in.
            assert_eq!(ready.len(), usize::from(i > 0));
            out.extend(ready);
        }
        out.extend(filter.finish().unwrap());
        let tags: Vec<i32> = out.iter().map(|(t, _)| *t).collect();
        assert_eq!(tags, vec![0, 1, 2, 3]);
        assert!(filter.finish().unwrap().is_empty());
        assert_eq!(filter.counts().images, 4);
        // Every wall pixel another view sees is kept; the rest (the image's edge columns that
        // no neighbour sees) goes.
        assert!(filter.counts().kept > filter.counts().checked / 2);
        assert!(filter.counts().kept < filter.counts().checked);
        // No check at all: images pass through as they came.
        let mut none = ConsistencyFilter::new(ConsistencyParams {
            neighbours: 0,
            ..params
        })
        .unwrap();
        let image = frame(0.0, &[0]);
        let passed = none.push((), image.clone()).unwrap();
        assert_eq!(passed.len(), 1);
        assert_eq!(passed[0].1, image);
    }

    #[test]
    fn depths_at_the_far_end_of_the_search_go_however_many_views_agree() {
        // Every view claims the wall at 5 m; a search that ended at 5.1 m puts it at its end.
        let target = frame(0.0, &[]);
        let (left, right) = (frame(-0.1, &[]), frame(0.1, &[]));
        let ended = ConsistencyParams {
            search_far: Some(5.1),
            ..ConsistencyParams::default()
        };
        let (checked, votes) = check_consistency(&target, &[&left, &right], &ended).unwrap();
        assert_eq!(votes.kept, 0);
        assert!(checked.image().depth().iter().all(|d| d.is_nan()));
        let beyond = ConsistencyParams {
            search_far: Some(8.0),
            ..ended
        };
        let (_, votes) = check_consistency(&target, &[&left, &right], &beyond).unwrap();
        assert!(votes.kept > 0);
    }

    #[test]
    fn bad_settings_are_refused() {
        let ok = ConsistencyParams::default();
        assert!(ok.validate().is_ok());
        for bad in [
            ConsistencyParams {
                tolerance: f32::NAN,
                ..ok
            },
            ConsistencyParams {
                tolerance: 0.0,
                ..ok
            },
            ConsistencyParams {
                min_agreeing: 0,
                ..ok
            },
            ConsistencyParams {
                min_agreeing: 9,
                ..ok
            },
            ConsistencyParams {
                interval_floor: -0.1,
                ..ok
            },
            ConsistencyParams {
                search_far: Some(f64::INFINITY),
                ..ok
            },
        ] {
            assert!(ConsistencyFilter::<()>::new(bad).is_err(), "{bad:?}");
        }
    }
}
