//! Census transform (Zabih and Woodfill, ECCV 1994): each pixel becomes a bit string that says
//! which neighbours are darker than it. Matching costs are Hamming distances between strings,
//! which makes them robust to gain and bias differences between the two images.

use rayon::prelude::*;

use super::gray::GrayImage;

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

/// Computes the 9 × 7 census transform. Neighbours beyond the border repeat the border pixel
/// (they then compare equal and give a 0 bit); `NaN` neighbours also give 0 bits.
pub fn census_transform(image: &GrayImage) -> CensusImage {
    let width = image.width() as usize;
    let height = image.height() as usize;
    let pixels = image.pixels();
    let mut codes: Vec<CensusCode> = vec![0; width * height];
    let (rx, ry) = (CENSUS_WIDTH / 2, CENSUS_HEIGHT / 2);
    codes
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, out)| {
            // The clamped source rows of the window, top to bottom.
            let rows: [&[f32]; CENSUS_HEIGHT] = std::array::from_fn(|k| {
                let yy = (y + k).saturating_sub(ry).min(height - 1);
                &pixels[yy * width..(yy + 1) * width]
            });
            let centre_row = rows[ry];
            // Interior pixels, whose window needs no clamping: one pass per neighbour over the
            // whole row, which the compiler vectorises.
            let interior = if width > 2 * rx {
                rx..width - rx
            } else {
                rx..rx
            };
            // (Images narrower than the window have no interior: `rx..rx` is empty and only the
            // clamped loop below runs; the slices are then never taken.)
            let interior_ok = !interior.is_empty();
            let centre = if interior_ok {
                &centre_row[interior.clone()]
            } else {
                &[][..]
            };
            let codes = if interior_ok {
                &mut out[interior.clone()]
            } else {
                &mut [][..]
            };
            for (r, row) in rows.iter().enumerate().filter(|_| interior_ok) {
                for k in (0..CENSUS_WIDTH).filter(|&k| sampled(k, r)) {
                    let neighbours = &row[interior.start + k - rx..interior.end + k - rx];
                    for ((code, &n), &c) in codes.iter_mut().zip(neighbours).zip(centre) {
                        *code = (*code << 1) | CensusCode::from(n < c);
                    }
                }
            }
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
    let valid = pixels.iter().map(|p| !p.is_nan()).collect();
    CensusImage {
        width,
        height,
        codes,
        valid,
    }
}
