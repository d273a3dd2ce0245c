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
//!
//! This module is the front door ([`match_pair`]) and runs the bands; [`context`] holds what
//! they share, [`cost`] costs the rows entering the window and [`select`] decides each row.

use fuzzyvox_core::error::{Error, Result};
use rayon::prelude::*;

use crate::census::{CENSUS_MAX_COST, CensusImage, census_transform};
use crate::params::{DisparityMap, MatchParams};
use crate::texture::textureless;
use fuzzyvox_core::image::GrayImage;

mod context;
mod cost;
mod select;

use context::{Band, Context, Found, LANES, thresholds};
use cost::enter_row;
use select::select_row;

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
    let (flat, (mut left_census, right_census)) = rayon::join(
        || textureless(left, params),
        || rayon::join(|| census_transform(left), || census_transform(right)),
    );
    // Texture-less pixels are left out like pixels without a value: their decision affects no
    // other pixel's, so this equals matching them and dropping them afterwards.
    for (valid, flat) in left_census.valid.iter_mut().zip(flat) {
        *valid &= !flat;
    }
    Ok(match_census(&left_census, &right_census, params))
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
