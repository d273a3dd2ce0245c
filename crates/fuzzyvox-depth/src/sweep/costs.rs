//! The raw cost of a reference row on one plane: where each pixel lands in every other view,
//! the census distance to the nearest pixel there, and the mean over the views that see it,
//! all branch-free so that the loops vectorise.

use super::planes::Sweep;
use super::rays::RowRays;
use crate::census::{CENSUS_BITS, CENSUS_MAX_COST, CensusImage};

/// Raw costs are the mean census distance over the views that see a pixel, in units of an
/// eighth of a bit, so that a mean over several views keeps three bits of its fraction. The
/// largest raw cost, `31 · 8 = 248`, still fits a byte and a 15 × 15 window sum a `u16`.
pub(super) const COST_SCALE: u32 = 8;

impl Sweep {
    /// Raw costs of reference row `y` on plane `k`, written into `out` (one per column): the
    /// mean census distance over the views in which the pixel lands on a valid pixel, scaled by
    /// [`COST_SCALE`], or the largest cost where it lands in none. `reference` holds the row's
    /// tagged codes (see [`tagged_codes`]). Inlined into the band's sweep, which is compiled
    /// for several instruction sets.
    #[inline(always)]
    pub(super) fn row_costs(
        &self,
        rays: RowRays<'_>,
        k: u32,
        reference: &[u32],
        others: &[TaggedImage],
        scratch: &mut RowScratch,
        out: &mut [u8],
    ) {
        let inverse = (self.inverse_far + self.step * f64::from(k)) as f32;
        let RowScratch {
            landing,
            gathered,
            sums,
            counts,
        } = scratch;
        sums.fill(0);
        counts.fill(0);
        for (v, (view, other)) in self.views.iter().zip(others).enumerate() {
            let (xs, ys, zs) = rays.view(v);
            let b = view.translation.map(|v| v * inverse);
            let (w, h) = (other.width as f32, other.height as f32);
            let stride = other.width as u32;
            // The nearest pixel of every column, branch-free so that it vectorises; the
            // image's trailing invalid code where the pixel lands outside the image (or behind
            // the camera). Truncation equals floor for the non-negative values kept.
            let outside = other.codes.len().saturating_sub(1);
            for (((j, &ax), &ay), &az) in landing.iter_mut().zip(xs).zip(ys).zip(zs) {
                let qz = az + b[2];
                let inv = 1.0 / qz;
                let (u, v) = ((ax + b[0]) * inv + 0.5, (ay + b[1]) * inv + 0.5);
                let inside = qz > 1e-6 && u >= 0.0 && v >= 0.0 && u < w && v < h;
                let index = floor_small(v)
                    .wrapping_mul(stride)
                    .wrapping_add(floor_small(u));
                *j = if inside { index } else { outside as u32 };
            }
            // Clamped to the trailing code, every read is in bounds without a test, so the
            // loop becomes one gather per vector.
            if let Some(codes) = other.codes.get(..=outside) {
                for (g, &j) in gathered.iter_mut().zip(landing.iter()) {
                    *g = codes[(j as usize).min(outside)];
                }
            }
            // Distances where both codes are valid, again branch-free.
            for (((sum, count), &g), &c) in sums
                .iter_mut()
                .zip(counts.iter_mut())
                .zip(gathered.iter())
                .zip(reference)
            {
                let both = ((g | c) >> 31) ^ 1;
                *sum += ((c ^ g).count_ones() * both) as u16;
                *count += both as u16;
            }
        }
        for ((cost, &sum), &count) in out.iter_mut().zip(sums.iter()).zip(counts.iter()) {
            *cost = mean_cost(sum, count);
        }
    }
}

/// `2^23`: adding it to a float below `2^22` leaves its integer part in the mantissa.
const MAGIC: f32 = 8_388_608.0;

/// `floor(x)` for `0 <= x < 2^22`, anything for other `x`, without a branch: unlike `as`,
/// which must saturate, this vectorises. Views are at most [`MAX_SWEEP_SIDE`](super::MAX_SWEEP_SIDE) pixels a side.
#[inline(always)]
fn floor_small(x: f32) -> u32 {
    let nearest = (x + MAGIC) - MAGIC;
    let floor = if nearest > x { nearest - 1.0 } else { nearest };
    (floor + MAGIC).to_bits().wrapping_sub(MAGIC.to_bits())
}

/// Bit 31 of a tagged census code: the pixel has no code and matches nothing. Census strings
/// use the bits below it.
const INVALID: u32 = 1 << 31;
const _: () = assert!(CENSUS_BITS <= 31);

/// A census image with each pixel's validity folded into its code (see [`INVALID`]).
pub(super) struct TaggedImage {
    pub(super) width: usize,
    pub(super) height: usize,
    /// Row-major codes, and one more [`INVALID`] code after the last pixel, for the pixels
    /// that land outside the image.
    pub(super) codes: Vec<u32>,
}

/// The codes of `census` with invalid pixels tagged [`INVALID`], and the trailing invalid code.
pub(super) fn tagged_codes(census: &CensusImage) -> TaggedImage {
    TaggedImage {
        width: census.width,
        height: census.height,
        codes: census
            .codes
            .iter()
            .zip(&census.valid)
            .map(|(&code, &ok)| if ok { code } else { INVALID })
            .chain([INVALID])
            .collect(),
    }
}

/// `round(sum · COST_SCALE / count)`, or the largest cost when no view saw the pixel. In
/// floats, which vectorise where a division or a table lookup would not: the numerator is at
/// most `31 · 16 · 8 + 8 < 2^13` and the count at most
/// [`MAX_SWEEP_VIEWS`](super::MAX_SWEEP_VIEWS), so a quotient that
/// is not a whole number lies at least `1 / count` below the next one, far more than the float
/// division's rounding error, and truncating the float quotient gives the integer one.
#[inline(always)]
fn mean_cost(sum: u16, count: u16) -> u8 {
    let numerator = (u32::from(sum) * COST_SCALE + u32::from(count) / 2) as i32;
    // Divided by at least 1 and floored by `floor_small` (the mean is below 2^8, and every
    // step is one vector instruction: a saturating `as` would not vectorise); the truncation
    // to `u8` keeps the whole value.
    let quotient = numerator as f32 / f32::from(count.max(1));
    let mean = floor_small(quotient) as u8;
    if count > 0 {
        mean
    } else {
        (u32::from(CENSUS_MAX_COST) * COST_SCALE) as u8
    }
}

/// One row's scratch space for [`Sweep::row_costs`].
pub(super) struct RowScratch {
    landing: Vec<u32>,
    gathered: Vec<u32>,
    sums: Vec<u16>,
    counts: Vec<u16>,
}

impl RowScratch {
    pub(super) fn new(width: usize) -> Self {
        Self {
            landing: vec![0; width],
            gathered: vec![0; width],
            sums: vec![0; width],
            counts: vec![0; width],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::{MAX_SWEEP_SIDE, MAX_SWEEP_VIEWS};

    #[test]
    fn floor_small_is_floor_and_mean_cost_is_the_rounded_mean() {
        let mut x = 0.0f32;
        while x < 3000.0 {
            for y in [
                x,
                x.next_up(),
                (x + 0.5).next_down(),
                x + 0.5,
                (x + 1.0).next_down(),
            ] {
                assert_eq!(floor_small(y), y as u32, "{y}");
            }
            x += 0.999;
        }
        let edge = (MAX_SWEEP_SIDE as f32).next_down();
        assert_eq!(floor_small(edge), edge as u32);
        for count in 1..=MAX_SWEEP_VIEWS as u16 {
            for sum in 0..=u16::from(CENSUS_MAX_COST) * count {
                let exact = (u32::from(sum) * COST_SCALE + u32::from(count) / 2) / u32::from(count);
                assert_eq!(u32::from(mean_cost(sum, count)), exact, "{sum} / {count}");
            }
        }
        assert_eq!(
            u32::from(mean_cost(0, 0)),
            u32::from(CENSUS_MAX_COST) * COST_SCALE
        );
    }
}
