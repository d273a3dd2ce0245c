//! Costing rows: census Hamming costs of sixteen disparities at a time, and a row entering the
//! window (its costs into the band's ring, the vertical sums updated by the difference).

use super::context::{Band, CODE_BYTES, Context, LANES, full_columns, valid_range};
use crate::census::{CENSUS_MAX_COST, CensusCode};

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
        let bits = (b0 ^ q0[k]).count_ones()
            + (b1 ^ q1[k]).count_ones()
            + (b2 ^ q2[k]).count_ones()
            + (b3 ^ q3[k]).count_ones();
        costs[k] = bits as u8;
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
pub(super) fn enter_row(ctx: &Context, row: isize, band: &mut Band, slot: usize) {
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

fuzzyvox_core::dispatched! {
    /// Costs and enters consecutive columns whose disparities are all searchable: column `i` (of
    /// `codes`, `old` and `vertical`, `stride` lanes each) reads the planes from `start - i`.
    /// (Not inlined: on its own, the compiler knows that the slices do not overlap.)
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
}
