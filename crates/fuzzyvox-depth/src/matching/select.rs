//! Deciding rows: the window sums of a row by a running sum along it, then per pixel the
//! winner, the left-right and uniqueness checks and the cost-curve range, and last the row's
//! floats (the parabola's sub-pixel step).

use super::context::{Band, Context, Found, LANES, full_columns, valid_range};
use crate::scan::{min_lane, scan_column};

/// Window sums of row `y` from the vertical sums, then per pixel the winner, its checks and the
/// sub-pixel step, written into `out` (the row of the disparity, range-low and range-high
/// planes).
pub(super) fn select_row(ctx: &Context, y: usize, band: &mut Band, out: [&mut [f32]; 4]) {
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

fuzzyvox_core::dispatched! {
    /// One column of the running sum, `column = previous + add - sub`, sixteen lanes at a time.
    /// (Not inlined: inlined, the compiler loses track of `column` and `previous` being apart
    /// and compiles it one lane at a time.)
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
