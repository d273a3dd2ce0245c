//! Block matching along rows: census Hamming costs, box aggregation over a window, winner takes
//! all, parabola sub-pixel refinement, a uniqueness test, a left-right consistency check, and the
//! cost-curve disparity range that the interval stage turns into `P-` and `P+`.
//!
//! Layout and speed: costs are `u8` (at most 31) and window sums `i16` (at most 15 × 15 × 31 = 6975;
//! signed because SSE2, the baseline of x86-64, has a signed 16-bit `min` but no unsigned one),
//! stored with the disparity innermost so that every aggregation step is a straight loop over
//! contiguous disparities that the compiler vectorises. The image is split into bands of rows;
//! each band keeps a ring of horizontally aggregated rows and a running vertical sum, so the cost
//! volume is never stored whole. All arithmetic is on integers, so the result is the same for
//! any number of threads and any band split.

use rayon::prelude::*;

use super::census::{CENSUS_MAX_COST, CensusCode, CensusImage, census_transform};
use super::gray::GrayImage;
use super::scan::{min_value, scan_column};
use crate::error::{Error, Result};

use super::params::{DisparityMap, MatchParams};

#[derive(Clone, Copy)]
struct Cell {
    disparity: f32,
    low: f32,
    high: f32,
}

const NO_MATCH: Cell = Cell {
    disparity: f32::NAN,
    low: f32::NAN,
    high: f32::NAN,
};

/// Everything a band needs, shared read-only between threads.
struct Context<'a> {
    left: &'a CensusImage,
    right: &'a CensusImage,
    width: usize,
    height: usize,
    disparities: usize,
    min_disparity: isize,
    radius_x: usize,
    radius_y: usize,
    params: &'a MatchParams,
    /// For every possible best cost `b`: the range threshold `b · (1 + tolerance)` and the
    /// uniqueness bound `ceil(b · 100 / (100 - ratio))` (0 when the test is off; a rival costs
    /// strictly less), so the per-pixel loop needs no division.
    thresholds: Vec<(i16, i16)>,
}

/// Matches a rectified pair: `left(y, x)` corresponds to `right(y, x - d)`.
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
    Ok(match_census(&left_census, &right_census, params))
}

/// Matches two census images of equal size (checked by [`match_pair`]).
pub(crate) fn match_census(
    left: &CensusImage,
    right: &CensusImage,
    params: &MatchParams,
) -> DisparityMap {
    let (width, height) = (left.width, left.height);
    let ctx = Context {
        left,
        right,
        width,
        height,
        disparities: params.num_disparities as usize,
        min_disparity: params.min_disparity as isize,
        radius_x: params.window_width as usize / 2,
        radius_y: params.window_height as usize / 2,
        params,
        thresholds: thresholds(params),
    };
    // The band split only decides which thread computes a row; every row's sums are exact, so
    // the output does not depend on it. One band per thread: each band
    // re-aggregates the window's rows above it, so fewer bands do less work twice.
    let bands = rayon::current_num_threads().clamp(1, height);
    let band_rows = height.div_ceil(bands);
    let pixels = width * height;
    let (mut disparity, mut range_low, mut range_high) =
        (vec![0f32; pixels], vec![0f32; pixels], vec![0f32; pixels]);
    // Each band fills its own rows of the three planes, so the split into planes runs in
    // parallel too.
    disparity
        .par_chunks_mut(band_rows * width)
        .zip(range_low.par_chunks_mut(band_rows * width))
        .zip(range_high.par_chunks_mut(band_rows * width))
        .enumerate()
        .for_each(|(band, ((d, low), high))| {
            let y0 = band * band_rows;
            let y1 = (y0 + band_rows).min(height);
            match_band(&ctx, y0, y1, [d, low, high]);
        });
    DisparityMap {
        width: width as u32,
        height: height as u32,
        disparity,
        range_low,
        range_high,
    }
}

/// Bytes of one census string.
const CODE_BYTES: usize = std::mem::size_of::<CensusCode>();

/// Population count of each byte, branch-free in byte lanes (SSE2 has no byte popcount, and a
/// 32-bit `count_ones` vectorises four lanes wide with costly narrowing; this runs sixteen).
#[inline(always)]
fn popcount8(v: u8) -> u8 {
    let v = v - ((v >> 1) & 0x55);
    let v = (v & 0x33) + ((v >> 2) & 0x33);
    (v + (v >> 4)) & 0x0f
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

/// Census Hamming costs of image row `row` for every pixel and disparity, `x` major.
///
/// The right row is split into byte planes, each reversed so that increasing disparities read
/// increasing addresses; the distance is the sum of the four planes' byte popcounts, computed
/// sixteen disparities at a time.
fn cost_row(ctx: &Context, row: usize, costs: &mut [u8], planes: &mut [Vec<u8>; CODE_BYTES]) {
    const CHUNK: usize = 16;
    let (w, nd) = (ctx.width, ctx.disparities);
    let left = &ctx.left.codes[row * w..(row + 1) * w];
    let right = &ctx.right.codes[row * w..(row + 1) * w];
    for (p, plane) in planes.iter_mut().enumerate() {
        for (r, &code) in plane.iter_mut().zip(right.iter().rev()) {
            *r = (code >> (8 * p)) as u8;
        }
    }
    let [p0, p1, p2, p3] = planes;
    for (x, (&code, out)) in left.iter().zip(costs.chunks_exact_mut(nd)).enumerate() {
        let (lo, hi) = valid_range(ctx, x);
        if lo > 0 {
            out[..lo].fill(CENSUS_MAX_COST);
        }
        if hi < nd {
            out[hi.max(lo)..].fill(CENSUS_MAX_COST);
        }
        if hi <= lo {
            continue;
        }
        let [b0, b1, b2, b3] = code.to_le_bytes();
        // Right column x - dmin - d sits at reversed index w - 1 - x + dmin + d.
        let start = (w as isize - 1 - x as isize + ctx.min_disparity + lo as isize) as usize;
        let len = hi - lo;
        let (r0, r1, r2, r3) = (
            &p0[start..start + len],
            &p1[start..start + len],
            &p2[start..start + len],
            &p3[start..start + len],
        );
        let out = &mut out[lo..hi];
        let cost = |k: usize| {
            popcount8(b0 ^ r0[k])
                + popcount8(b1 ^ r1[k])
                + popcount8(b2 ^ r2[k])
                + popcount8(b3 ^ r3[k])
        };
        let full = len - len % CHUNK;
        for base in (0..full).step_by(CHUNK) {
            let block: &mut [u8; CHUNK] = match (&mut out[base..base + CHUNK]).try_into() {
                Ok(block) => block,
                Err(_) => continue,
            };
            let (q0, q1, q2, q3): (&[u8; CHUNK], &[u8; CHUNK], &[u8; CHUNK], &[u8; CHUNK]) = match (
                r0[base..base + CHUNK].try_into(),
                r1[base..base + CHUNK].try_into(),
                r2[base..base + CHUNK].try_into(),
                r3[base..base + CHUNK].try_into(),
            ) {
                (Ok(a), Ok(b), Ok(c), Ok(d)) => (a, b, c, d),
                _ => continue,
            };
            for k in 0..CHUNK {
                block[k] = popcount8(b0 ^ q0[k])
                    + popcount8(b1 ^ q1[k])
                    + popcount8(b2 ^ q2[k])
                    + popcount8(b3 ^ q3[k]);
            }
        }
        for (k, c) in out.iter_mut().enumerate().skip(full) {
            *c = cost(k);
        }
    }
}

/// Horizontal box sums of one cost row: `sums[x][d] = Σ_{|k| <= rx} costs[clamp(x + k)][d]`,
/// each column from the previous one by one addition and one subtraction.
fn horizontal_sums(ctx: &Context, costs: &[u8], sums: &mut [i16]) {
    let (w, nd, rx) = (ctx.width, ctx.disparities, ctx.radius_x);
    let column = |x: isize| {
        let x = x.clamp(0, w as isize - 1) as usize;
        &costs[x * nd..(x + 1) * nd]
    };
    let first = &mut sums[..nd];
    first.fill(0);
    for k in -(rx as isize)..=(rx as isize) {
        for (a, &c) in first.iter_mut().zip(column(k)) {
            *a += i16::from(c);
        }
    }
    for x in 1..w {
        let (done, rest) = sums.split_at_mut(x * nd);
        let previous = &done[(x - 1) * nd..];
        let add = column(x as isize + rx as isize);
        let sub = column(x as isize - rx as isize - 1);
        for (((s, &q), &p), &m) in rest[..nd].iter_mut().zip(previous).zip(add).zip(sub) {
            *s = q.wrapping_add(i16::from(p)).wrapping_sub(i16::from(m));
        }
    }
}

/// Horizontally aggregated costs of image row `row` (clamped to the image).
fn aggregated_row(ctx: &Context, row: isize, scratch: &mut Scratch, out: &mut [i16]) {
    let row = row.clamp(0, ctx.height as isize - 1) as usize;
    cost_row(ctx, row, &mut scratch.costs, &mut scratch.planes);
    horizontal_sums(ctx, &scratch.costs, out);
}

struct Scratch {
    costs: Vec<u8>,
    row: Vec<i16>,
    right_cost: Vec<i16>,
    /// One row of results.
    cells: Vec<Cell>,
    planes: [Vec<u8>; CODE_BYTES],
}

/// Matches rows `y0..y1` into `out` (those rows, row-major).
/// `out` holds the band's rows of the disparity, range-low and range-high planes.
fn match_band(ctx: &Context, y0: usize, y1: usize, mut out: [&mut [f32]; 3]) {
    let (w, nd) = (ctx.width, ctx.disparities);
    let plane = w * nd;
    let rows = 2 * ctx.radius_y + 1;
    let mut scratch = Scratch {
        costs: vec![0; plane],
        row: vec![0; plane],
        right_cost: vec![0; w],
        cells: vec![NO_MATCH; w],
        planes: std::array::from_fn(|_| vec![0; w]),
    };
    let mut ring: Vec<Vec<i16>> = (0..rows).map(|_| vec![0i16; plane]).collect();
    let mut vertical = vec![0i16; plane];
    let first = y0 as isize - ctx.radius_y as isize;
    // Prime the window of rows y0 - ry ..= y0 + ry; slot k holds logical row first + k (mod).
    for (k, slot) in ring.iter_mut().enumerate() {
        aggregated_row(ctx, first + k as isize, &mut scratch, slot);
        for (v, &s) in vertical.iter_mut().zip(slot.iter()) {
            *v = v.wrapping_add(s);
        }
    }
    for y in y0..y1 {
        let mut cells = std::mem::take(&mut scratch.cells);
        select_row(ctx, y, &vertical, &mut scratch, &mut cells);
        let span = (y - y0) * w..(y - y0 + 1) * w;
        let [d, low, high] = &mut out;
        for (((cell, d), low), high) in cells
            .iter()
            .zip(&mut d[span.clone()])
            .zip(&mut low[span.clone()])
            .zip(&mut high[span])
        {
            (*d, *low, *high) = (cell.disparity, cell.low, cell.high);
        }
        scratch.cells = cells;
        if y + 1 < y1 {
            // Slide the window down one row: the row leaving shares its slot with the row
            // entering (they are `rows` apart).
            let leaving = y as isize - ctx.radius_y as isize;
            let slot_index = (leaving - first) as usize % rows;
            let mut entering = std::mem::take(&mut scratch.row);
            aggregated_row(ctx, leaving + rows as isize, &mut scratch, &mut entering);
            let Some(slot) = ring.get_mut(slot_index) else {
                break;
            };
            for ((v, &s), &e) in vertical.iter_mut().zip(slot.iter()).zip(&entering) {
                *v = v.wrapping_add(e).wrapping_sub(s);
            }
            // The entering row takes the slot; the leaving one becomes the next scratch row.
            std::mem::swap(slot, &mut entering);
            scratch.row = entering;
        }
    }
}

/// Winner takes all on one row of window sums, with the checks and the sub-pixel step.
fn select_row(ctx: &Context, y: usize, sums: &[i16], scratch: &mut Scratch, out: &mut [Cell]) {
    let (w, nd, dmin) = (ctx.width, ctx.disparities, ctx.min_disparity);
    let params = ctx.params;
    // The right image's best costs, for the left-right check: for right column xr, the least
    // cost over left columns x = xr + dmin + d. Stored mirrored (slot w - 1 - xr) so that
    // increasing disparities walk increasing slots and the loop vectorises.
    if params.left_right_tolerance.is_some() {
        scratch.right_cost.fill(i16::MAX);
        for x in 0..w {
            let (lo, hi) = valid_range(ctx, x);
            if hi <= lo {
                continue;
            }
            let column = &sums[x * nd + lo..x * nd + hi];
            let start = (w as isize - 1 - x as isize + dmin + lo as isize) as usize;
            for (r, &c) in scratch.right_cost[start..start + (hi - lo)]
                .iter_mut()
                .zip(column)
            {
                *r = (*r).min(c);
            }
        }
    }
    for (x, cell) in out.iter_mut().enumerate() {
        *cell = NO_MATCH;
        if !ctx.left.valid[y * w + x] {
            continue;
        }
        let (lo, hi) = valid_range(ctx, x);
        let column = &sums[x * nd + lo..x * nd + hi];
        if column.is_empty() {
            continue;
        }
        let best_cost = min_value(column);
        // Thresholds in cost units, looked up (see `Context::thresholds`).
        let (range_threshold, unique_bound) = ctx
            .thresholds
            .get(best_cost.max(0) as usize)
            .copied()
            .unwrap_or((best_cost, 0));
        let scan = scan_column(column, best_cost, range_threshold, unique_bound);
        let best = scan.best;
        let best_d = lo + best;
        let xr = (x as isize - dmin - best_d as isize) as usize;
        if !ctx.right.valid[y * w + xr] {
            continue;
        }
        // Left-right check: the right pixel's best match must lie within the tolerance of this
        // one, i.e. one of the pairs (x + t, best_d + t), |t| <= tolerance, which all land on
        // the same right pixel, must reach the right pixel's least cost. (Ties in the right
        // image pass when any of the tied matches is close, which saves a second pass.)
        if let Some(tolerance) = params.left_right_tolerance {
            let target = scratch.right_cost[w - 1 - xr];
            let reach = tolerance.min(ctx.disparities as u32) as isize;
            let consistent = (-reach..=reach).any(|t| {
                let (xx, dd) = (x as isize + t, best_d as isize + t);
                xx >= 0
                    && (xx as usize) < w
                    && dd >= 0
                    && (dd as usize) < nd
                    && sums[xx as usize * nd + dd as usize] == target
            });
            if !consistent {
                continue;
            }
        }
        // Uniqueness: any disparity more than one pixel from the best under the bound, i.e.
        // more costs under it than the best and its two neighbours account for.
        let near = &column[best.saturating_sub(1)..(best + 2).min(column.len())];
        if scan.under_bound > near.iter().filter(|&&c| c < unique_bound).count() {
            continue;
        }
        // Cost-curve range: the span of all disparities within the tolerance of the best, so a
        // distant near-tie widens it (an ambiguous match is an uncertain one).
        let (low, high) = (scan.low, scan.high);
        let best_cost = best_cost as u32;
        // Parabola through the best cost and its two neighbours.
        let mut offset = 0.0f32;
        if best > 0 && best + 1 < column.len() {
            let (c0, c1, c2) = (
                f32::from(column[best - 1]),
                best_cost as f32,
                f32::from(column[best + 1]),
            );
            let curvature = c0 - 2.0 * c1 + c2;
            if curvature > 0.0 {
                offset = (0.5 * (c0 - c2) / curvature).clamp(-0.5, 0.5);
            }
        }
        let base = dmin as f32 + lo as f32;
        *cell = Cell {
            disparity: base + best as f32 + offset,
            low: base + low as f32,
            high: base + high as f32,
        };
    }
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
        };
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
                    };
                    let (lc, rc) = (census_transform(&left), census_transform(&right));
                    let fast = match_census(&lc, &rc, &params);
                    let slow = reference(&lc, &rc, &params);
                    let context = format!("{width}x{height}, {params:?}");
                    assert_eq!(bits(&fast.disparity), bits(&slow.disparity), "{context}");
                    assert_eq!(bits(&fast.range_low), bits(&slow.range_low), "{context}");
                    assert_eq!(bits(&fast.range_high), bits(&slow.range_high), "{context}");
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
