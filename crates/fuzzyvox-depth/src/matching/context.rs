//! What every band of the matcher shares and keeps: the read-only [`Context`] of a match
//! (sizes, parameters, the per-best-cost thresholds), a band's working memory ([`Band`]), a
//! pixel's match in integers ([`Found`]), and which columns and disparities are searchable.

use crate::census::{CENSUS_MAX_COST, CensusCode, CensusImage};
use crate::params::MatchParams;

/// Disparities per step of the cost loop: sixteen `u8` lanes, one SSE register.
pub(super) const LANES: usize = 16;

/// Bytes of one census string.
pub(super) const CODE_BYTES: usize = std::mem::size_of::<CensusCode>();

/// Everything a band needs, shared read-only between threads.
pub(super) struct Context<'a> {
    pub(super) left: &'a CensusImage,
    pub(super) right: &'a CensusImage,
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) disparities: usize,
    /// `disparities` rounded up to whole steps of [`LANES`]: the length of every pixel's column
    /// of costs and sums. Padding lanes cost 0 and their window sums are held at `i16::MAX`, so
    /// that they never win and never lower the right image's least costs.
    pub(super) stride: usize,
    pub(super) min_disparity: isize,
    pub(super) radius_x: usize,
    pub(super) radius_y: usize,
    pub(super) params: &'a MatchParams,
    /// For every possible best cost `b`: the range threshold `b · (1 + tolerance)` and the
    /// uniqueness bound `ceil(b · 100 / (100 - ratio))` (0 when the test is off; a rival costs
    /// strictly less), so the per-pixel loop needs no division.
    pub(super) thresholds: Vec<(i16, i16)>,
    /// Per lane of a column: all ones for a searched disparity, zero for padding.
    pub(super) keep: Vec<u8>,
}

/// The per-best-cost thresholds of [`Context`].
pub(super) fn thresholds(params: &MatchParams) -> Vec<(i16, i16)> {
    let largest = params.window_width * params.window_height * u32::from(CENSUS_MAX_COST);
    (0..=largest)
        .map(|best| {
            let range = (best as f32 * (1.0 + params.range_tolerance)).min(32766.0) as i16;
            let unique = if params.uniqueness_ratio > 0 {
                (best * 100)
                    .div_ceil(100 - params.uniqueness_ratio)
                    .min(i16::MAX as u32) as i16
            } else {
                0
            };
            (range, unique)
        })
        .collect()
}

/// A band's working memory, allocated once per band.
pub(super) struct Band {
    /// The right row's census strings split into byte planes, each reversed (right column `xr`
    /// at index `stride + width - 1 - xr`) so that increasing disparities read increasing
    /// addresses, with `stride` zeros on both sides so that border columns read in bounds.
    pub(super) planes: [Vec<u8>; CODE_BYTES],
    /// The costs of the window's rows, one `width × stride` slot per row.
    pub(super) ring: Vec<u8>,
    /// Per pixel and disparity, the sum of the ring's costs: the window's column sums.
    pub(super) vertical: Vec<i16>,
    /// The current row's window sums.
    pub(super) sums: Vec<i16>,
    /// The right image's least window sum per right column `xr`, at index
    /// `width - 1 - xr - min_disparity` (mirrored, so that a pixel's increasing disparities walk
    /// increasing indices and the update vectorises).
    pub(super) right_cost: Vec<i16>,
    /// One column of costs, for the border columns whose disparities are not all searchable.
    pub(super) column: Vec<u8>,
    /// One column of window sums, for the same border columns.
    pub(super) border: Vec<i16>,
    /// The current row's matches.
    pub(super) found: Vec<Found>,
    /// The current row's least window sum per pixel.
    pub(super) least: Vec<i16>,
}

/// A pixel's match in integers: absolute disparities (`min_disparity` included) of the winner
/// and of the cost-curve range, and the window sums for the parabola.
#[derive(Clone, Copy)]
pub(super) struct Found {
    pub(super) disparity: i32,
    pub(super) low: i32,
    pub(super) high: i32,
    pub(super) sums: [i32; 3],
}

impl Found {
    /// No match.
    pub(super) const NONE: Self = Self {
        disparity: i32::MIN,
        low: 0,
        high: 0,
        sums: [0; 3],
    };
}

/// The columns `[lo, hi)` whose disparities are all searchable (`x - dmin` in `nd - 1 .. w`).
pub(super) fn full_columns(ctx: &Context) -> (usize, usize) {
    let (w, dmin) = (ctx.width as isize, ctx.min_disparity);
    let lo = (ctx.disparities as isize - 1 + dmin).clamp(0, w);
    let hi = (w + dmin).clamp(lo, w);
    (lo as usize, hi as usize)
}

/// Disparity indices `[lo, hi)` whose right pixel lies inside the image at column `x`.
pub(super) fn valid_range(ctx: &Context, x: usize) -> (usize, usize) {
    let first_right = x as isize - ctx.min_disparity;
    let hi = (first_right + 1).clamp(0, ctx.disparities as isize) as usize;
    let lo = (first_right - ctx.width as isize + 1).clamp(0, hi as isize) as usize;
    (lo, hi)
}
