//! Plane-sweep matching in the original reference camera: for pairs that cannot be rectified
//! usefully (motion along the look direction puts the epipole inside the image), and for
//! several other views at once (multi-baseline stereo).
//!
//! Fronto-parallel planes at inverse depths `w_k = w_far + k · Δw` (`k = 0 .. K`) play the part
//! of disparities: a reference pixel `x` on plane `k` maps into the other image at
//! `π(M x̃ + w_k K_o t)`, where `M = K_o R K_r⁻¹` and `(R, t)` is `other_from_reference`. `Δw` is
//! chosen so that no pixel moves more than one pixel between neighbouring planes. Each plane's
//! cost is the census Hamming distance to the other image's nearest pixel, aggregated over the
//! same window as the row matcher. With several other views (Okutomi and Kanade's
//! multiple-baseline stereo) a pixel's cost on a plane is the mean distance over the views it
//! lands in, and the view that moves fastest (the longest baseline) sets `Δw`: the short
//! baselines keep the cost curve free of repeated minima, the long one makes it sharp, and one
//! plane step is one pixel of the longest baseline. Then winner-takes-all with a parabola
//! refinement, the uniqueness test and the cost-curve range follow, exactly as for rectified
//! pairs. Because `w` is affine in the plane index, depth is `1 / (w_far + k Δw)`, which is a
//! [`StereoGeometry`] with `baseline · f = 1 / Δw` and `doffs = w_far / Δw`: the interval and
//! confidence code of rectified pairs applies unchanged.
//!
//! Near the epipole the planes barely move a pixel: one plane step is one pixel only where the
//! image moves fastest, so a pixel that moves `m` pixels over the whole sweep keeps the same
//! nearest pixel, and so the same cost, for about `planes / m` planes in a row. Its minimum is
//! then a run of equal costs: the match is the run's middle, and the uniqueness test looks for
//! rivals more than one pixel *of that pixel's motion* beyond the run (not one plane, which
//! would find the run itself and drop every slow pixel). Its cost-curve range spans the run, so
//! its interval is as wide as one pixel of motion makes it and its confidence follows. A pixel
//! that moves less than [`MIN_SWEEP_MOTION`](limits::MIN_SWEEP_MOTION) pixels over the whole
//! depth range (the epipole itself) cannot be measured and gets no depth: the honest answer for
//! motion along the view. There is no left-right check (the other image has no sweep of its
//! own).
//!
//! Memory is bounded by a band of rows times the planes: the image is cut into bands of rows
//! that threads sweep independently (each band with a halo of half a window), keeping the
//! band's aggregated costs on every plane (at most 32 rows × width × 1024 planes × 2 bytes).
//!
//! This module is the front door ([`sweep_views`]); [`planes`] sets the planes, [`rays`],
//! [`costs`] and [`band`] sweep a band of rows through them, and [`limits`] holds the bounds.

use fuzzyvox_core::error::{Error, Result};
use rayon::prelude::*;

use crate::census::{CENSUS_MAX_COST, census_transform};
use crate::params::{DisparityMap, MatchParams};
use crate::texture::drop_textureless;
use fuzzyvox_core::image::Frame;

mod band;
mod costs;
mod limits;
mod planes;
mod rays;

use band::{PixelState, sweep_band};
use costs::{COST_SCALE, TaggedImage, tagged_codes};
pub use limits::{MAX_SWEEP_PIXELS, MAX_SWEEP_SIDE, MAX_SWEEP_VIEWS, PLANE_COUNT};
pub(crate) use planes::Sweep;

/// Rows per band of the sweep (plus a halo of half a window above and below).
const BAND_ROWS: usize = 32;

/// Matches `reference` against the sweep's other views (`others`, in the order the sweep was
/// made with) by plane sweep in the reference camera; the result's "disparity" is the
/// fractional plane index. Pixels of texture-less windows of the reference are not matched
/// ([`MatchParams::min_contrast`]).
pub(crate) fn sweep_views(
    reference: &Frame,
    others: &[&Frame],
    sweep: &Sweep,
    params: &MatchParams,
) -> Result<DisparityMap> {
    params.validate()?;
    if others.len() != sweep.views.len() {
        return Err(Error::SizeMismatch {
            what: "views of the plane sweep",
            expected: sweep.views.len(),
            found: others.len(),
        });
    }
    let left = tagged_codes(&census_transform(reference.image()));
    let right: Vec<TaggedImage> = others
        .iter()
        .map(|o| tagged_codes(&census_transform(o.image())))
        .collect();
    let (width, height) = (left.width, left.height);
    if width == 0 || height == 0 {
        return Err(Error::Empty("reference image"));
    }
    let bands: Vec<(usize, usize)> = (0..height)
        .step_by(BAND_ROWS)
        .map(|y0| (y0, (y0 + BAND_ROWS).min(height)))
        .collect();
    let states: Vec<Vec<PixelState>> = bands
        .par_iter()
        .map(|&(y0, y1)| sweep_band(sweep, &left, &right, params, y0, y1))
        .collect();
    let n = width * height;
    let mut map = DisparityMap {
        width: width as u32,
        height: height as u32,
        disparity: vec![f32::NAN; n],
        range_low: vec![f32::NAN; n],
        range_high: vec![f32::NAN; n],
        cost: vec![f32::NAN; n],
    };
    let max_cost =
        u32::from(CENSUS_MAX_COST) * COST_SCALE * params.window_width * params.window_height;
    let ratio = params.uniqueness_ratio;
    for (i, s) in states.iter().flatten().enumerate() {
        if s.best == u16::MAX
            || u32::from(s.best) >= max_cost
            || s.low > s.high
            || s.exclusion == u32::MAX
        {
            continue;
        }
        if ratio > 0 && u32::from(s.runner_up) * (100 - ratio) < u32::from(s.best) * 100 {
            continue;
        }
        // A run's middle; a single best plane is refined by a parabola through its neighbours.
        let mut offset = (s.run_end - s.best_plane) as f32 / 2.0;
        if s.run_end == s.best_plane && s.left != u16::MAX && s.right != u16::MAX {
            let (l, b, r) = (f32::from(s.left), f32::from(s.best), f32::from(s.right));
            let curvature = l + r - 2.0 * b;
            if curvature > 0.0 {
                offset = ((l - r) / (2.0 * curvature)).clamp(-0.5, 0.5);
            }
        }
        map.disparity[i] = s.best_plane as f32 + offset;
        map.range_low[i] = s.low as f32;
        map.range_high[i] = s.high as f32;
        map.cost[i] = f32::from(s.best) / max_cost as f32;
    }
    drop_textureless(reference.image(), params, &mut map);
    Ok(map)
}
