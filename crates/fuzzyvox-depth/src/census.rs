//! Census transform (Zabih and Woodfill, ECCV 1994): each pixel becomes a bit string that says
//! which neighbours are darker than it. Matching costs are Hamming distances between strings,
//! which makes them robust to gain and bias differences between the two images.

use fuzzyvox_core::image::GrayImage;
use rayon::prelude::*;

/// Census window width (columns).
pub const CENSUS_WIDTH: usize = 9;
/// Census window height (rows).
pub const CENSUS_HEIGHT: usize = 7;
/// The census string of one pixel.
pub type CensusCode = u32;
/// Number of neighbours compared: the 31 of the 9 × 7 window on a checkerboard (`dx + dy` odd),
/// a sparse census that spans the same window as the dense 62-neighbour one at half the bits, so
/// that one string fits a `u32` and Hamming distances vectorise twice as wide.
pub const CENSUS_BITS: u32 = 31;
/// The largest Hamming distance between two census strings.
pub const CENSUS_MAX_COST: u8 = CENSUS_BITS as u8;

/// Whether window offset `(k, row)` (from the top-left corner) is one of the compared neighbours.
const fn sampled(k: usize, row: usize) -> bool {
    (k + row) % 2 == 1
}

/// A census-transformed image: one `u64` per pixel, and whether the pixel had a value.
#[derive(Clone, Debug)]
pub struct CensusImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major census strings.
    pub codes: Vec<CensusCode>,
    /// Row-major validity: the pixel's own value is not `NaN`.
    pub valid: Vec<bool>,
}

/// The compared neighbours in bit order, as (window row, window column): neighbour `i` of 31
/// lands at bit `30 - i` of the string.
const NEIGHBOURS: [(usize, usize); CENSUS_BITS as usize] = {
    let mut list = [(0, 0); CENSUS_BITS as usize];
    let (mut i, mut r) = (0, 0);
    while r < CENSUS_HEIGHT {
        let mut k = 0;
        while k < CENSUS_WIDTH {
            if sampled(k, r) {
                list[i] = (r, k);
                i += 1;
            }
            k += 1;
        }
        r += 1;
    }
    list
};

/// Pixels per block of the interior loop: sixteen byte lanes.
const BLOCK: usize = 16;

/// Columns of a block's window.
const SPAN: usize = BLOCK + CENSUS_WIDTH - 1;

/// The neighbours of each byte of the string, highest byte first (7, 8, 8 and 8 of them).
const PLANES: [std::ops::Range<usize>; 4] = [0..7, 7..15, 15..23, 23..31];

fuzzyvox_core::dispatched! {
    /// Census strings of the interior columns `start..start + out.len()` of one row (no clamping
    /// needed there), sixteen pixels at a time: the block's centres and the four bytes of its
    /// strings stay in SIMD registers while the 31 neighbours are compared, each comparison
    /// filling one bit of sixteen byte lanes. The last block overlaps the one before when the row
    /// is not a whole number of blocks (recomputing a string is harmless). Rows narrower than a
    /// block use the clamped loop. Compiled for AVX-512 and AVX2 as well, chosen at run time.
    fn interior_codes(
        rows: &[&[f32]; CENSUS_HEIGHT],
        centre: &[f32],
        out: &mut [CensusCode],
        start: usize,
    ) -> bool {
        let n = out.len();
        if n < BLOCK {
            return false;
        }
        let rx = CENSUS_WIDTH / 2;
        for block in (0..n).step_by(BLOCK) {
            let at = block.min(n - BLOCK);
            let Ok(centres) = <&[f32; BLOCK]>::try_from(&centre[at..at + BLOCK]) else {
                continue;
            };
            // The block's window, as fixed-size rows: the neighbour loads then need no checks.
            let from = start + at - rx;
            let window: [Option<&[f32; SPAN]>; CENSUS_HEIGHT] =
                std::array::from_fn(|r| rows[r].get(from..from + SPAN)?.try_into().ok());
            let mut bytes = [[0u8; BLOCK]; 4];
            for (plane, neighbours) in bytes.iter_mut().zip(PLANES) {
                for &(r, k) in &NEIGHBOURS[neighbours] {
                    let Some(Ok(values)) =
                        window[r].map(|row| <&[f32; BLOCK]>::try_from(&row[k..k + BLOCK]))
                    else {
                        continue;
                    };
                    // All-ones masks of the comparisons as `i32` (as wide as the `f32` lanes), then
                    // narrowed into the byte lanes: `plane = 2 plane + bit`.
                    let less: [i32; BLOCK] =
                        std::array::from_fn(|j| -i32::from(values[j] < centres[j]));
                    for j in 0..BLOCK {
                        plane[j] = (plane[j] << 1).wrapping_sub(less[j] as u8);
                    }
                }
            }
            let [b0, b1, b2, b3] = &bytes;
            for (j, code) in out[at..at + BLOCK].iter_mut().enumerate() {
                *code = CensusCode::from_be_bytes([b0[j], b1[j], b2[j], b3[j]]);
            }
        }
        true
}
}

/// Computes the 9 × 7 census transform. Neighbours beyond the border repeat the border pixel
/// (they then compare equal and give a 0 bit); `NaN` neighbours also give 0 bits.
pub fn census_transform(image: &GrayImage) -> CensusImage {
    let width = image.width() as usize;
    let height = image.height() as usize;
    let pixels = image.pixels();
    let mut codes: Vec<CensusCode> = vec![0; width * height];
    let (rx, ry) = (CENSUS_WIDTH / 2, CENSUS_HEIGHT / 2);
    let mut valid = vec![false; width * height];
    codes
        .par_chunks_mut(width)
        .zip(valid.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, (out, valid))| {
            for (v, p) in valid.iter_mut().zip(&pixels[y * width..(y + 1) * width]) {
                *v = !p.is_nan();
            }
            // The clamped source rows of the window, top to bottom.
            let rows: [&[f32]; CENSUS_HEIGHT] = std::array::from_fn(|k| {
                let yy = (y + k).saturating_sub(ry).min(height - 1);
                &pixels[yy * width..(yy + 1) * width]
            });
            let centre_row = rows[ry];
            // Interior pixels, whose window needs no clamping, in vectorised blocks; the clamped
            // loop below takes the rest (all of a row narrower than the window or a block).
            let interior = if width > 2 * rx {
                rx..width - rx
            } else {
                rx..rx
            };
            let interior = if !interior.is_empty()
                && interior_codes(
                    &rows,
                    &centre_row[interior.clone()],
                    &mut out[interior.clone()],
                    interior.start,
                ) {
                interior
            } else {
                rx..rx
            };
            // Border columns, clamped.
            for x in (0..width).filter(|x| !interior.contains(x)) {
                let centre = centre_row[x];
                let mut bits: CensusCode = 0;
                for (r, row) in rows.iter().enumerate() {
                    for k in (0..CENSUS_WIDTH).filter(|&k| sampled(k, r)) {
                        let xx = (x + k).saturating_sub(rx).min(width - 1);
                        bits = (bits << 1) | CensusCode::from(row[xx] < centre);
                    }
                }
                out[x] = bits;
            }
        });
    CensusImage {
        width,
        height,
        codes,
        valid,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The census by its definition, one pixel at a time with clamped neighbours.
    fn plain(image: &GrayImage) -> Vec<CensusCode> {
        let (w, h) = (image.width() as usize, image.height() as usize);
        let p = image.pixels();
        let mut codes = vec![0; w * h];
        for y in 0..h {
            for x in 0..w {
                let centre = p[y * w + x];
                let mut bits: CensusCode = 0;
                for &(r, k) in &NEIGHBOURS {
                    let yy = (y + r).saturating_sub(CENSUS_HEIGHT / 2).min(h - 1);
                    let xx = (x + k).saturating_sub(CENSUS_WIDTH / 2).min(w - 1);
                    bits = (bits << 1) | CensusCode::from(p[yy * w + xx] < centre);
                }
                codes[y * w + x] = bits;
            }
        }
        codes
    }

    #[test]
    fn blocks_match_the_definition() {
        // Widths around the window and the block (interior 0, 15, 16, 17, 33 and more), with
        // fractions, ties and missing values.
        for width in [1usize, 8, 9, 23, 24, 25, 41, 60] {
            let height = 9;
            let pixels: Vec<f32> = (0..width * height)
                .map(|i| match i % 37 {
                    5 => f32::NAN,
                    _ => ((i * 7919 + 13) % 50) as f32 * 0.5,
                })
                .collect();
            let image = GrayImage::new(width as u32, height as u32, pixels).unwrap();
            let census = census_transform(&image);
            assert_eq!(census.codes, plain(&image), "width {width}");
            assert!(!census.valid[5]);
            assert!(census.codes.iter().all(|&c| c < 1 << CENSUS_BITS));
        }
    }
}
