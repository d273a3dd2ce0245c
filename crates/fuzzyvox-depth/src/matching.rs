//! Block matching along rows: census Hamming costs, box aggregation over a window, winner takes
//! all, parabola sub-pixel refinement, a uniqueness test, a left-right consistency check, and the
//! cost-curve disparity range that the interval stage turns into `P-` and `P+`.
//!
//! Layout and speed: costs are `u8` (at most 31) and window sums `i16` (at most 15 × 15 × 31 =
//! 6975; signed because SSE2, the baseline of x86-64, has a signed 16-bit `min` but no unsigned
//! one), stored with the disparity innermost so that every step is a straight loop over
//! contiguous disparities that the compiler vectorises. The image is split into bands of rows,
//! one per thread. A band keeps the `u8` costs of the window's rows in a ring and their
//! column sums (vertical sums); a row entering the window is costed and added in the same loop
//! that takes out the row leaving it. Each output row then takes a running sum along its columns
//! (which also yields each pixel's least sum), folds the right image's least sums for the
//! left-right check, and decides pixel by pixel (`scan.rs` scans a pixel's sums); the floats of
//! the row come last, in one vectorised pass. The cost volume is never stored whole. All
//! arithmetic up to the sub-pixel step is on integers, so the result is the same for any number
//! of threads and any band split.

use fuzzyvox_core::image::GrayImage;
use rayon::prelude::*;

use super::census::{CENSUS_MAX_COST, CensusCode, CensusImage, census_transform};
use super::params::{DisparityMap, MatchParams};
use super::scan::{min_lane, scan_column};
use super::texture::drop_textureless;
use crate::error::{Error, Result};

/// Disparities per step of the cost loop: sixteen `u8` lanes, one SSE register.
const LANES: usize = 16;

/// Bytes of one census string.
const CODE_BYTES: usize = std::mem::size_of::<CensusCode>();

/// Everything a band needs, shared read-only between threads.
struct Context<'a> {
    left: &'a CensusImage,
    right: &'a CensusImage,
    width: usize,
    height: usize,
    disparities: usize,
    /// `disparities` rounded up to whole steps of [`LANES`]: the length of every pixel's column
    /// of costs and sums. Padding lanes cost 0 and their window sums are held at `i16::MAX`, so
    /// that they never win and never lower the right image's least costs.
    stride: usize,
    min_disparity: isize,
    radius_x: usize,
    radius_y: usize,
    params: &'a MatchParams,
    /// For every possible best cost `b`: the range threshold `b · (1 + tolerance)` and the
    /// uniqueness bound `ceil(b · 100 / (100 - ratio))` (0 when the test is off; a rival costs
    /// strictly less), so the per-pixel loop needs no division.
    thresholds: Vec<(i16, i16)>,
    /// Per lane of a column: all ones for a searched disparity, zero for padding.
    keep: Vec<u8>,
}

/// Matches a rectified pair: `left(y, x)` corresponds to `right(y, x - d)`. Pixels of
/// texture-less windows of `left` are not matched ([`MatchParams::min_contrast`]).
///
/// Errors: images of different sizes, empty images, invalid parameters.
pub fn match_pair(
    left: &GrayImage,
    right: &GrayImage,
    params: &MatchParams,
) -> Result<DisparityMap> {
    params.validate()?;
    if left.width() != right.width() || left.height() != right.height() {
        return Err(Error::SizeMismatch {
            what: "right image pixels (left width × height)",
            expected: left.pixels().len(),
            found: right.pixels().len(),
        });
    }
    let left_census = census_transform(left);
    let right_census = census_transform(right);
    let mut map = match_census(&left_census, &right_census, params);
    drop_textureless(left, params, &mut map);
    Ok(map)
}

/// Matches two census images of equal size (checked by [`match_pair`]).
pub(crate) fn match_census(
    left: &CensusImage,
    right: &CensusImage,
    params: &MatchParams,
) -> DisparityMap {
    let (width, height) = (left.width, left.height);
    let disparities = params.num_disparities as usize;
    let stride = disparities.next_multiple_of(LANES);
    let ctx = Context {
        left,
        right,
        width,
        height,
        disparities,
        stride,
        min_disparity: params.min_disparity as isize,
        radius_x: params.window_width as usize / 2,
        radius_y: params.window_height as usize / 2,
        params,
        thresholds: thresholds(params),
        keep: (0..stride)
            .map(|d| if d < disparities { u8::MAX } else { 0 })
            .collect(),
    };
    // The band split only decides which thread computes a row; every row's sums are exact, so
    // the output does not depend on it. One band per thread: each band re-costs the window's
    // rows above it, so fewer bands do less work twice.
    let bands = rayon::current_num_threads().clamp(1, height);
    let band_rows = height.div_ceil(bands);
    let pixels = width * height;
    let (mut disparity, mut range_low, mut range_high, mut cost) = (
        vec![0f32; pixels],
        vec![0f32; pixels],
        vec![0f32; pixels],
        vec![0f32; pixels],
    );
    // Each band fills its own rows of the four planes, so the split into planes runs in
    // parallel too.
    disparity
        .par_chunks_mut(band_rows * width)
        .zip(range_low.par_chunks_mut(band_rows * width))
        .zip(range_high.par_chunks_mut(band_rows * width))
        .zip(cost.par_chunks_mut(band_rows * width))
        .enumerate()
        .for_each(|(band, (((d, low), high), c))| {
            let y0 = band * band_rows;
            let y1 = (y0 + band_rows).min(height);
            match_band(&ctx, y0, y1, [d, low, high, c]);
        });
    let largest = (params.window_width * params.window_height * u32::from(CENSUS_MAX_COST)) as f32;
    for c in &mut cost {
        *c /= largest;
    }
    DisparityMap {
        width: width as u32,
        height: height as u32,
        disparity,
        range_low,
        range_high,
        cost,
    }
}

/// The per-best-cost thresholds of [`Context`].
fn thresholds(params: &MatchParams) -> Vec<(i16, i16)> {
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
struct Band {
    /// The right row's census strings split into byte planes, each reversed (right column `xr`
    /// at index `stride + width - 1 - xr`) so that increasing disparities read increasing
    /// addresses, with `stride` zeros on both sides so that border columns read in bounds.
    planes: [Vec<u8>; CODE_BYTES],
    /// The costs of the window's rows, one `width × stride` slot per row.
    ring: Vec<u8>,
    /// Per pixel and disparity, the sum of the ring's costs: the window's column sums.
    vertical: Vec<i16>,
    /// The current row's window sums.
    sums: Vec<i16>,
    /// The right image's least window sum per right column `xr`, at index
    /// `width - 1 - xr - min_disparity` (mirrored, so that a pixel's increasing disparities walk
    /// increasing indices and the update vectorises).
    right_cost: Vec<i16>,
    /// One column of costs, for the border columns whose disparities are not all searchable.
    column: Vec<u8>,
    /// One column of window sums, for the same border columns.
    border: Vec<i16>,
    /// The current row's matches.
    found: Vec<Found>,
    /// The current row's least window sum per pixel.
    least: Vec<i16>,
}

/// Matches rows `y0..y1` into `out`: the band's rows of the disparity, range-low and range-high
/// planes.
fn match_band(ctx: &Context, y0: usize, y1: usize, out: [&mut [f32]; 4]) {
    let (w, stride) = (ctx.width, ctx.stride);
    let rows = 2 * ctx.radius_y + 1;
    let mut band = Band {
        planes: std::array::from_fn(|_| vec![0; w + 2 * stride]),
        ring: vec![0; rows * w * stride],
        vertical: vec![0; w * stride],
        sums: vec![0; w * stride],
        right_cost: vec![i16::MAX; w + stride],
        column: vec![0; stride],
        border: vec![0; stride],
        found: vec![Found::NONE; w],
        least: vec![0; w],
    };
    // Prime the window of rows y0 - ry ..= y0 + ry; slot k holds row first + k (clamped). The
    // ring starts at zero, so entering a row only adds it.
    let first = y0 as isize - ctx.radius_y as isize;
    for slot in 0..rows {
        enter_row(ctx, first + slot as isize, &mut band, slot);
    }
    let [disparity, low, high, cost] = out;
    let rows_out = disparity
        .chunks_exact_mut(w)
        .zip(low.chunks_exact_mut(w))
        .zip(high.chunks_exact_mut(w))
        .zip(cost.chunks_exact_mut(w));
    for (y, (((disparity, low), high), cost)) in (y0..y1).zip(rows_out) {
        select_row(ctx, y, &mut band, [disparity, low, high, cost]);
        if y + 1 < y1 {
            // Slide the window down one row: the row leaving (y - ry, slot (y - y0) mod rows)
            // and the row entering (y + ry + 1) are `rows` apart and share the slot.
            let entering = (y + ctx.radius_y + 1) as isize;
            enter_row(ctx, entering, &mut band, (y - y0) % rows);
        }
    }
}

/// Population count of each byte's nibbles, branch-free in byte lanes (SSE2 has no byte
/// popcount); two of these add without overflow (at most 8 per nibble).
#[inline(always)]
fn nibble_counts(v: u8) -> u8 {
    let v = v - ((v >> 1) & 0x55);
    (v & 0x33) + ((v >> 2) & 0x33)
}

/// The byte total of two added [`nibble_counts`] (at most 16).
#[inline(always)]
fn byte_total(v: u8) -> u8 {
    (v & 0x0f) + (v >> 4)
}

/// Census Hamming costs of `LANES` disparities: the left string's bytes `code` against `LANES`
/// consecutive entries of the four reversed right planes. Sixteen disparities per SSE
/// instruction.
#[inline(always)]
fn chunk_costs(code: [u8; CODE_BYTES], q: [&[u8]; CODE_BYTES]) -> [u8; LANES] {
    let [b0, b1, b2, b3] = code;
    let [q0, q1, q2, q3] = q;
    let (q0, q1, q2, q3) = (&q0[..LANES], &q1[..LANES], &q2[..LANES], &q3[..LANES]);
    let mut costs = [0u8; LANES];
    for k in 0..LANES {
        let low = nibble_counts(b0 ^ q0[k]) + nibble_counts(b1 ^ q1[k]);
        let high = nibble_counts(b2 ^ q2[k]) + nibble_counts(b3 ^ q3[k]);
        costs[k] = byte_total(low) + byte_total(high);
    }
    costs
}

/// The four reversed right planes from index `start`, `len` entries each.
#[inline(always)]
fn plane_slices(planes: &[Vec<u8>; CODE_BYTES], start: usize, len: usize) -> [&[u8]; CODE_BYTES] {
    let [p0, p1, p2, p3] = planes;
    [
        &p0[start..start + len],
        &p1[start..start + len],
        &p2[start..start + len],
        &p3[start..start + len],
    ]
}

/// Costs one column whose disparities are all searchable and enters it: `vertical += cost -
/// old`, then `old = cost` (padding lanes cost 0 through `keep`). The costs stay in registers.
#[inline(always)]
fn enter_full_column<const PADDED: bool>(
    code: [u8; CODE_BYTES],
    q: [&[u8]; CODE_BYTES],
    keep: &[u8],
    old: &mut [u8],
    vertical: &mut [i16],
) {
    let [q0, q1, q2, q3] = q;
    let steps = old
        .chunks_exact_mut(LANES)
        .zip(vertical.chunks_exact_mut(LANES))
        .zip(keep.chunks_exact(LANES))
        .zip(q0.chunks_exact(LANES))
        .zip(q1.chunks_exact(LANES))
        .zip(q2.chunks_exact(LANES))
        .zip(q3.chunks_exact(LANES));
    for ((((((old, vertical), keep), q0), q1), q2), q3) in steps {
        // Fixed-size arrays: the compiler then keeps the sixteen costs in one register and
        // widens them into two registers of eight `i16` lanes.
        let (Ok(old), Ok(vertical), Ok(keep)) = (
            <&mut [u8; LANES]>::try_from(old),
            <&mut [i16; LANES]>::try_from(vertical),
            <&[u8; LANES]>::try_from(keep),
        ) else {
            continue;
        };
        let mut costs = chunk_costs(code, [q0, q1, q2, q3]);
        if PADDED {
            for k in 0..LANES {
                costs[k] &= keep[k];
            }
        }
        let change: [i16; LANES] = std::array::from_fn(|k| i16::from(costs[k]) - i16::from(old[k]));
        for k in 0..LANES {
            vertical[k] = vertical[k].wrapping_add(change[k]);
        }
        *old = costs;
    }
}

/// Costs image row `row` (clamped to the image) into ring slot `slot` and updates the vertical
/// sums by the difference between it and the row it replaces.
fn enter_row(ctx: &Context, row: isize, band: &mut Band, slot: usize) {
    let row = row.clamp(0, ctx.height as isize - 1) as usize;
    let (w, nd, stride) = (ctx.width, ctx.disparities, ctx.stride);
    let left = &ctx.left.codes[row * w..(row + 1) * w];
    let right = &ctx.right.codes[row * w..(row + 1) * w];
    for (p, plane) in band.planes.iter_mut().enumerate() {
        for (r, &code) in plane[stride..stride + w].iter_mut().zip(right.iter().rev()) {
            *r = (code >> (8 * p)) as u8;
        }
    }
    let Band {
        planes,
        ring,
        vertical,
        column,
        ..
    } = band;
    let ring = &mut ring[slot * w * stride..(slot + 1) * w * stride];
    // Right column x - dmin - d sits at plane index `start(x) + d`. With at least one
    // searchable disparity, `start .. start + stride` stays within one stride of the image's
    // plane indices, so the reads are in bounds.
    let start = |x: usize| stride as isize + w as isize - 1 - x as isize + ctx.min_disparity;
    let (full_lo, full_hi) = full_columns(ctx);
    if full_hi > full_lo {
        let [p0, p1, p2, p3] = &*planes;
        enter_full_columns(
            &left[full_lo..full_hi],
            [p0, p1, p2, p3],
            start(full_lo) as usize,
            &ctx.keep,
            &mut ring[full_lo * stride..full_hi * stride],
            &mut vertical[full_lo * stride..full_hi * stride],
        );
    }
    // The border columns: disparities whose right pixel lies outside the image cost the most.
    for x in (0..full_lo).chain(full_hi..w) {
        let (code, old) = (left[x], &mut ring[x * stride..(x + 1) * stride]);
        let vertical = &mut vertical[x * stride..(x + 1) * stride];
        let (lo, hi) = valid_range(ctx, x);
        if hi > lo {
            let [q0, q1, q2, q3] = plane_slices(planes, start(x) as usize, stride);
            let steps = column
                .chunks_exact_mut(LANES)
                .zip(q0.chunks_exact(LANES))
                .zip(q1.chunks_exact(LANES))
                .zip(q2.chunks_exact(LANES))
                .zip(q3.chunks_exact(LANES));
            // Only the chunks with a searchable disparity; the others are filled below.
            let chunks = (lo / LANES)..hi.div_ceil(LANES);
            for ((((costs, q0), q1), q2), q3) in steps.skip(chunks.start).take(chunks.len()) {
                costs.copy_from_slice(&chunk_costs(code.to_le_bytes(), [q0, q1, q2, q3]));
            }
        }
        column[..lo].fill(CENSUS_MAX_COST);
        column[hi..nd].fill(CENSUS_MAX_COST);
        column[nd..].fill(0);
        for ((v, o), &c) in vertical.iter_mut().zip(old.iter_mut()).zip(column.iter()) {
            *v = v.wrapping_add(i16::from(c)).wrapping_sub(i16::from(*o));
            *o = c;
        }
    }
}

/// Costs and enters consecutive columns whose disparities are all searchable: column `i` (of
/// `codes`, `old` and `vertical`, `stride` lanes each) reads the planes from `start - i`.
/// (Not inlined: on its own, the compiler knows that the slices do not overlap.)
#[inline(never)]
fn enter_full_columns(
    codes: &[CensusCode],
    planes: [&[u8]; CODE_BYTES],
    start: usize,
    keep: &[u8],
    old: &mut [u8],
    vertical: &mut [i16],
) {
    let stride = keep.len();
    // Padding lanes exist when the disparities are not a whole number of chunks.
    let padded = keep.contains(&0);
    let columns = old
        .chunks_exact_mut(stride)
        .zip(vertical.chunks_exact_mut(stride));
    for (i, (&code, (old, vertical))) in codes.iter().zip(columns).enumerate() {
        let at = start - i;
        let q = planes.map(|plane| &plane[at..at + stride]);
        if padded {
            enter_full_column::<true>(code.to_le_bytes(), q, keep, old, vertical);
        } else {
            enter_full_column::<false>(code.to_le_bytes(), q, keep, old, vertical);
        }
    }
}

/// Window sums of row `y` from the vertical sums, then per pixel the winner, its checks and the
/// sub-pixel step, written into `out` (the row of the disparity, range-low and range-high
/// planes).
fn select_row(ctx: &Context, y: usize, band: &mut Band, out: [&mut [f32]; 4]) {
    let (w, nd, stride, dmin) = (ctx.width, ctx.disparities, ctx.stride, ctx.min_disparity);
    let Band {
        vertical,
        sums,
        right_cost,
        border,
        found,
        least,
        ..
    } = band;
    horizontal_row(vertical, sums, right_cost, least, w, nd, ctx.radius_x);
    let reach = ctx
        .params
        .left_right_tolerance
        .map(|t| t.min(nd as u32) as usize);
    found.fill(Found::NONE);
    let left_valid = &ctx.left.valid[y * w..(y + 1) * w];
    let right_valid = &ctx.right.valid[y * w..(y + 1) * w];
    // One pixel: its window sums over whole chunks, indexed by disparity index, with padding
    // lanes and, at the border columns, disparities whose right pixel lies outside the image
    // at `i16::MAX`, which never wins, never lies in the range and is never a rival;
    // `[lo, hi)` the searchable disparities.
    let mut decide = |x: usize, column: &[i16], best_cost: i16, lo: usize, hi: usize| {
        let scan = scan_column(column, best_cost, &ctx.thresholds);
        let best_d = usize::from(scan.best);
        let xr = (x as isize - dmin - best_d as isize) as usize;
        if !right_valid.get(xr).copied().unwrap_or(false) {
            return;
        }
        // Left-right check: the right pixel's best match must lie within the tolerance of this
        // one, i.e. one of the pairs (x + t, d + t), |t| <= tolerance, which all land on the
        // same right pixel, must reach the right pixel's least sum. (Ties in the right image
        // pass when any of the tied matches is close, which saves a second pass.)
        if let Some(reach) = reach {
            let target = right_cost[w - 1 - x + best_d];
            let consistent = target == scan.best_cost
                || (1..=reach).any(|t| {
                    let at = |xx: usize, dd: usize| {
                        (xx < w && dd < nd).then(|| sums[xx * stride + dd]) == Some(target)
                    };
                    at(x.wrapping_sub(t), best_d.wrapping_sub(t)) || at(x + t, best_d + t)
                });
            if !consistent {
                return;
            }
        }
        // Uniqueness: any disparity more than one pixel from the best under the bound, i.e.
        // more sums under it than the best and its two neighbours account for.
        let at = |d: usize| column.get(d).copied().unwrap_or(i16::MAX);
        let (before, after) = (at(best_d.wrapping_sub(1)), at(best_d + 1));
        let near =
            1 + usize::from(before < scan.unique_bound) + usize::from(after < scan.unique_bound);
        if usize::from(scan.under_bound) > near {
            return;
        }
        // The decision, in integers; the floats follow for the whole row at once. The
        // parabola runs through the best sum and its two neighbours when both are searchable
        // (else three equal sums: no curvature, no offset).
        let (c0, c2) = if best_d > lo && best_d + 1 < hi {
            (before, after)
        } else {
            (scan.best_cost, scan.best_cost)
        };
        let disparity = dmin + best_d as isize;
        found[x] = Found {
            disparity: disparity as i32,
            low: (dmin + scan.low as isize) as i32,
            high: (dmin + scan.high as isize) as i32,
            sums: [c0, scan.best_cost, c2].map(i32::from),
        };
    };
    let (full_lo, full_hi) = full_columns(ctx);
    let full = sums[full_lo * stride..full_hi * stride].chunks_exact(stride);
    for ((x, column), _) in (full_lo..)
        .zip(full)
        .zip(&left_valid[full_lo..full_hi])
        .filter(|(_, v)| **v)
    {
        decide(x, column, least[x], 0, nd);
    }
    for x in (0..full_lo).chain(full_hi..w) {
        let (lo, hi) = valid_range(ctx, x);
        if !left_valid[x] || hi <= lo {
            continue;
        }
        border.fill(i16::MAX);
        border[lo..hi].copy_from_slice(&sums[x * stride + lo..x * stride + hi]);
        let best_cost = border[lo..hi].iter().copied().fold(i16::MAX, i16::min);
        decide(x, border, best_cost, lo, hi);
    }
    finish_row(found, out);
}

/// The window sums of one row (`sums`, `width × stride`) from the vertical sums, by a running
/// sum along the row with the border columns repeated, and the right image's least window sums
/// (`right_cost`, mirrored). Padding lanes hold `i16::MAX`.
/// (Not inlined: on its own, the compiler knows that the slices do not overlap and keeps every
/// step in SIMD registers.)
#[inline(never)]
fn horizontal_row(
    vertical: &[i16],
    sums: &mut [i16],
    right_cost: &mut [i16],
    least: &mut [i16],
    w: usize,
    nd: usize,
    rx: usize,
) {
    let stride = sums.len() / w;
    let vertical_at = |x: isize| {
        let x = x.clamp(0, w as isize - 1) as usize;
        &vertical[x * stride..(x + 1) * stride]
    };
    right_cost.fill(i16::MAX);
    let (first, rest) = sums.split_at_mut(stride);
    first.fill(0);
    for k in -(rx as isize)..=(rx as isize) {
        for (s, &v) in first.iter_mut().zip(vertical_at(k)) {
            *s = s.wrapping_add(v);
        }
    }
    // Padding lanes: the vertical sums there are 0, so they stay at `i16::MAX`.
    first[nd..].fill(i16::MAX);
    // Column x adds the vertical sums of column x + rx and takes out those of x - rx - 1, both
    // clamped to the image; in the middle of the row neither needs clamping, and they come
    // from two iterators instead.
    let clamped = |x: usize| !(rx + 1..w.saturating_sub(rx)).contains(&x);
    least[0] = first.iter().copied().fold(i16::MAX, i16::min);
    let mut previous: &[i16] = first;
    let mut columns = (1..).zip(rest.chunks_exact_mut(stride)).peekable();
    while let Some((x, column)) = columns.next_if(|(x, _)| clamped(*x)) {
        let add = vertical_at(x as isize + rx as isize);
        let sub = vertical_at(x as isize - rx as isize - 1);
        least[x] = slide(column, previous, add, sub);
        previous = column;
    }
    let middle = vertical
        .chunks_exact(stride)
        .skip(2 * rx + 1)
        .zip(vertical.chunks_exact(stride));
    let unclamped = w.saturating_sub(rx).saturating_sub(rx + 1);
    for ((x, column), (add, sub)) in columns.by_ref().take(unclamped).zip(middle) {
        least[x] = slide(column, previous, add, sub);
        previous = column;
    }
    for (x, column) in columns {
        let add = vertical_at(x as isize + rx as isize);
        let sub = vertical_at(x as isize - rx as isize - 1);
        least[x] = slide(column, previous, add, sub);
        previous = column;
    }
    // The right image's least sums, column by column into the mirrored array, whose window
    // moves by one lane per column. Consecutive columns would read what the previous one has
    // just stored one lane off, which the processor cannot forward from its store buffer;
    // columns eight apart move the window by exactly one register, so go in eight passes.
    for phase in 0..8.min(w) {
        for x in (phase..w).step_by(8) {
            let mirrored = &mut right_cost[w - 1 - x..w - 1 - x + stride];
            for (r, &s) in mirrored.iter_mut().zip(&sums[x * stride..(x + 1) * stride]) {
                *r = (*r).min(s);
            }
        }
    }
}

/// One column of the running sum, `column = previous + add - sub`, sixteen lanes at a time.
/// (Not inlined: inlined, the compiler loses track of `column` and `previous` being apart
/// and compiles it one lane at a time.)
#[inline(never)]
fn slide(column: &mut [i16], previous: &[i16], add: &[i16], sub: &[i16]) -> i16 {
    let mut least = [i16::MAX; LANES];
    let steps = column
        .chunks_exact_mut(LANES)
        .zip(previous.chunks_exact(LANES))
        .zip(add.chunks_exact(LANES))
        .zip(sub.chunks_exact(LANES));
    for (((column, previous), add), sub) in steps {
        let (Ok(column), Ok(previous), Ok(add), Ok(sub)) = (
            <&mut [i16; LANES]>::try_from(column),
            <&[i16; LANES]>::try_from(previous),
            <&[i16; LANES]>::try_from(add),
            <&[i16; LANES]>::try_from(sub),
        ) else {
            continue;
        };
        for k in 0..LANES {
            column[k] = previous[k].wrapping_add(add[k]).wrapping_sub(sub[k]);
            least[k] = least[k].min(column[k]);
        }
    }
    min_lane(least)
}

/// A pixel's match in integers: absolute disparities (`min_disparity` included) of the winner
/// and of the cost-curve range, and the window sums for the parabola.
#[derive(Clone, Copy)]
struct Found {
    disparity: i32,
    low: i32,
    high: i32,
    sums: [i32; 3],
}

impl Found {
    /// No match.
    const NONE: Self = Self {
        disparity: i32::MIN,
        low: 0,
        high: 0,
        sums: [0; 3],
    };
}

/// The floats of one row from its integer matches: the parabola's sub-pixel offset (the
/// vertex through the best sum and its neighbours, within half a pixel) and the four planes
/// (the best sum still unscaled),
/// `NaN` where no match. One pass over the row, which the compiler vectorises.
fn finish_row(found: &[Found], out: [&mut [f32]; 4]) {
    let [disparity, range_low, range_high, best_cost] = out;
    let planes = disparity
        .iter_mut()
        .zip(range_low.iter_mut())
        .zip(range_high)
        .zip(best_cost);
    for (found, (((disparity, low), high), cost)) in found.iter().zip(planes) {
        let [c0, c1, c2] = found.sums.map(|c| c as f32);
        let curvature = c0 - 2.0 * c1 + c2;
        let offset = if curvature > 0.0 {
            (0.5 * (c0 - c2) / curvature).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let matched = found.disparity != i32::MIN;
        *disparity = if matched {
            found.disparity as f32 + offset
        } else {
            f32::NAN
        };
        *low = if matched { found.low as f32 } else { f32::NAN };
        *high = if matched { found.high as f32 } else { f32::NAN };
        *cost = if matched { c1 } else { f32::NAN };
    }
}

/// The columns `[lo, hi)` whose disparities are all searchable (`x - dmin` in `nd - 1 .. w`).
fn full_columns(ctx: &Context) -> (usize, usize) {
    let (w, dmin) = (ctx.width as isize, ctx.min_disparity);
    let lo = (ctx.disparities as isize - 1 + dmin).clamp(0, w);
    let hi = (w + dmin).clamp(lo, w);
    (lo as usize, hi as usize)
}

/// Disparity indices `[lo, hi)` whose right pixel lies inside the image at column `x`.
fn valid_range(ctx: &Context, x: usize) -> (usize, usize) {
    let first_right = x as isize - ctx.min_disparity;
    let hi = (first_right + 1).clamp(0, ctx.disparities as isize) as usize;
    let lo = (first_right - ctx.width as isize + 1).clamp(0, hi as isize) as usize;
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plain reference matcher: the whole cost volume, window sums by explicit loops, and each
    /// pixel's decision written out from the documented rules.
    fn reference(left: &CensusImage, right: &CensusImage, params: &MatchParams) -> DisparityMap {
        let (w, h) = (left.width as isize, left.height as isize);
        let nd = params.num_disparities as isize;
        let dmin = params.min_disparity as isize;
        let (rx, ry) = (
            params.window_width as isize / 2,
            params.window_height as isize / 2,
        );
        let cost = |x: isize, y: isize, d: isize| -> i32 {
            let xr = x - dmin - d;
            if xr < 0 || xr >= w {
                return i32::from(CENSUS_MAX_COST);
            }
            let (l, r) = (
                left.codes[(y * w + x) as usize],
                right.codes[(y * w + xr) as usize],
            );
            (l ^ r).count_ones() as i32
        };
        let sum = |x: isize, y: isize, d: isize| -> i32 {
            let mut s = 0;
            for j in -ry..=ry {
                for k in -rx..=rx {
                    s += cost((x + k).clamp(0, w - 1), (y + j).clamp(0, h - 1), d);
                }
            }
            s
        };
        let table = thresholds(params);
        let n = (w * h) as usize;
        let mut out = DisparityMap {
            width: w as u32,
            height: h as u32,
            disparity: vec![f32::NAN; n],
            range_low: vec![f32::NAN; n],
            range_high: vec![f32::NAN; n],
            cost: vec![f32::NAN; n],
        };
        let largest =
            (params.window_width * params.window_height * u32::from(CENSUS_MAX_COST)) as f32;
        for y in 0..h {
            let sums: Vec<Vec<i32>> = (0..w)
                .map(|x| (0..nd).map(|d| sum(x, y, d)).collect())
                .collect();
            let valid_d = |x: isize, d: isize| (0..w).contains(&(x - dmin - d));
            // The right image's least cost per right column.
            let right_least = |xr: isize| {
                (0..w)
                    .flat_map(|x| (0..nd).map(move |d| (x, d)))
                    .filter(|&(x, d)| x - dmin - d == xr)
                    .map(|(x, d)| sums[x as usize][d as usize])
                    .min()
                    .unwrap()
            };
            for x in 0..w {
                let i = (y * w + x) as usize;
                if !left.valid[i] {
                    continue;
                }
                let ds: Vec<isize> = (0..nd).filter(|&d| valid_d(x, d)).collect();
                let Some(&lo) = ds.first() else { continue };
                let hi = ds[ds.len() - 1] + 1;
                let column = &sums[x as usize][lo as usize..hi as usize];
                let best_cost = *column.iter().min().unwrap();
                let best = column.iter().position(|&c| c == best_cost).unwrap();
                let (range, unique) = table[best_cost as usize];
                let (range, unique) = (i32::from(range), i32::from(unique));
                let low = column.iter().position(|&c| c <= range).unwrap();
                let high = column.iter().rposition(|&c| c <= range).unwrap();
                let best_d = lo + best as isize;
                let xr = x - dmin - best_d;
                if !right.valid[(y * w + xr) as usize] {
                    continue;
                }
                if let Some(tolerance) = params.left_right_tolerance {
                    let target = right_least(xr);
                    let t = tolerance as isize;
                    let consistent = (-t..=t).any(|t| {
                        (0..w).contains(&(x + t))
                            && (0..nd).contains(&(best_d + t))
                            && sums[(x + t) as usize][(best_d + t) as usize] == target
                    });
                    if !consistent {
                        continue;
                    }
                }
                let rival = column
                    .iter()
                    .enumerate()
                    .any(|(k, &c)| c < unique && k.abs_diff(best) > 1);
                if rival {
                    continue;
                }
                let mut offset = 0.0f32;
                if best > 0 && best + 1 < column.len() {
                    let (c0, c1, c2) = (
                        column[best - 1] as f32,
                        best_cost as f32,
                        column[best + 1] as f32,
                    );
                    let curvature = c0 - 2.0 * c1 + c2;
                    if curvature > 0.0 {
                        offset = (0.5 * (c0 - c2) / curvature).clamp(-0.5, 0.5);
                    }
                }
                let base = dmin as f32 + lo as f32;
                out.disparity[i] = base + best as f32 + offset;
                out.range_low[i] = base + low as f32;
                out.range_high[i] = base + high as f32;
                out.cost[i] = best_cost as f32 / largest;
            }
        }
        out
    }

    /// A textured pair: the right image is the left one shifted by a disparity that changes
    /// across the image, plus noise, with a few pixels without a value.
    fn pair(width: u32, height: u32, seed: u64) -> (GrayImage, GrayImage) {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        let (w, h) = (width as usize, height as usize);
        let texture: Vec<f32> = (0..(w + 40) * h).map(|_| (next() % 256) as f32).collect();
        let mut left = vec![0f32; w * h];
        let mut right = vec![0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let shift = 2 + x * 4 / w.max(1);
                left[y * w + x] = texture[y * (w + 40) + x + 20 - shift];
                right[y * w + x] = texture[y * (w + 40) + x + 20] + (next() % 7) as f32;
            }
        }
        for _ in 0..(w * h / 40) {
            let i = next() as usize % (w * h);
            left[i] = f32::NAN;
            let j = next() as usize % (w * h);
            right[j] = f32::NAN;
        }
        (
            GrayImage::new(width, height, left).unwrap(),
            GrayImage::new(width, height, right).unwrap(),
        )
    }

    #[test]
    fn matches_the_reference_bit_for_bit() {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let sizes = [(1, 1), (3, 2), (8, 5), (21, 9), (40, 13)];
        let disparities = [
            (0, 1),
            (0, 5),
            (0, 16),
            (-3, 17),
            (2, 33),
            (30, 8),
            (-50, 20),
        ];
        let windows = [(1, 1), (3, 5), (9, 9), (15, 15)];
        let checks = [
            (0, None, 0.0),
            (10, Some(1), 0.25),
            (50, Some(0), 2.0),
            (10, Some(3), 0.25),
        ];
        let mut case = 0u64;
        for &(width, height) in &sizes {
            for &(min_disparity, num_disparities) in &disparities {
                for &(window_width, window_height) in &windows {
                    let (uniqueness_ratio, left_right_tolerance, range_tolerance) =
                        checks[case as usize % checks.len()];
                    case += 1;
                    let (left, right) = pair(width, height, case);
                    let params = MatchParams {
                        min_disparity,
                        num_disparities,
                        window_width,
                        window_height,
                        uniqueness_ratio,
                        left_right_tolerance,
                        range_tolerance,
                        min_contrast: 0.0,
                    };
                    let (lc, rc) = (census_transform(&left), census_transform(&right));
                    let fast = match_census(&lc, &rc, &params);
                    let slow = reference(&lc, &rc, &params);
                    let context = format!("{width}x{height}, {params:?}");
                    assert_eq!(bits(&fast.disparity), bits(&slow.disparity), "{context}");
                    assert_eq!(bits(&fast.range_low), bits(&slow.range_low), "{context}");
                    assert_eq!(bits(&fast.range_high), bits(&slow.range_high), "{context}");
                    assert_eq!(bits(&fast.cost), bits(&slow.cost), "{context}");
                }
            }
        }
        // The pairs are matchable: the reference finds most pixels on the larger ones.
        let (left, right) = pair(40, 13, 99);
        let params = MatchParams {
            num_disparities: 16,
            ..MatchParams::default()
        };
        let map = reference(&census_transform(&left), &census_transform(&right), &params);
        assert!(map.density() > 0.5, "{}", map.density());
    }
}
