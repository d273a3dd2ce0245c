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

/// Census strings of the interior columns `start..start + out.len()` of one row (no clamping
/// needed there), built as four byte planes: each neighbour is one pass over the row whose
/// comparisons fill sixteen byte lanes per instruction, then the planes are joined into `u32`
/// strings. The bit order equals the clamped loop's: neighbour `i` of 31 at bit `30 - i`.
fn interior_codes(
    rows: &[&[f32]; CENSUS_HEIGHT],
    centre: &[f32],
    out: &mut [CensusCode],
    start: usize,
) {
    let rx = CENSUS_WIDTH / 2;
    let n = out.len();
    // Neighbours in bit order, as (row, column offset) in the window.
    let neighbours = (0..CENSUS_HEIGHT).flat_map(|r| {
        (0..CENSUS_WIDTH)
            .filter(move |&k| sampled(k, r))
            .map(move |k| (r, k))
    });
    let mut planes = [vec![0u8; n], vec![0u8; n], vec![0u8; n], vec![0u8; n]];
    for (i, (r, k)) in neighbours.enumerate() {
        // Neighbour i lands in byte (30 - i) / 8 of the string, counted from the lowest.
        let plane = &mut planes[3 - (30 - i) / 8];
        let row = &rows[r][start + k - rx..start + k - rx + n];
        for ((code, &v), &c) in plane.iter_mut().zip(row).zip(centre) {
            *code = (*code << 1) | u8::from(v < c);
        }
    }
    let [p0, p1, p2, p3] = &planes;
    for ((((code, &a), &b), &c), &d) in out.iter_mut().zip(p0).zip(p1).zip(p2).zip(p3) {
        *code = CensusCode::from_be_bytes([a, b, c, d]);
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
            if interior_ok {
                interior_codes(&rows, centre, &mut out[interior.clone()], interior.start);
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
    CensusImage {
        width,
        height,
        codes,
        valid,
    }
}
