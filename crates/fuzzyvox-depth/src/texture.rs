//! The texture test: pixels whose matching window holds too little contrast are not matched.
//!
//! A texture-less window (a clear sky, a blank wall, a saturated patch) matches every
//! disparity about equally well, and census costs, which ignore brightness offsets, do worse
//! than that on a smooth gradient: a ramp shifted by any disparity is the same ramp plus an
//! offset, so the cost curve's minimum lands wherever the gradient's slight curvature and the
//! sensor noise put it, often with a sharp, unique-looking minimum. In the closed-loop flights a
//! camera that looked at the sky measured thousands of sky pixels at 1-2 m with confidence up
//! to 0.9 (`docs/depth.md`). The test measures each window's contrast as its standard
//! deviation over its mean (scale-free: images in 0-1 and 0-255 behave alike) and drops the
//! pixel when the contrast is below [`MatchParams::min_contrast`]. OpenCV's block matcher has
//! the same safeguard (`textureThreshold`) on an absolute scale.

use fuzzyvox_core::image::GrayImage;
use rayon::prelude::*;

use super::params::{DisparityMap, MatchParams};

/// Rows per task of [`textureless`]. Fixed, not derived from the thread count, so that every
/// row's sums are added in the same order whatever the number of threads.
const CHUNK_ROWS: usize = 16;

/// Whether each pixel's `window_width × window_height` window (clamped at the borders, `NaN`
/// pixels left out) has a contrast, standard deviation over mean magnitude, below
/// `min_contrast`. A window with no valid pixel, or with zero mean and zero spread, is
/// texture-less. Row-major, one entry per pixel; all `false` when `min_contrast` is 0.
///
/// Runs on chunks of rows in parallel: each chunk keeps the window's column sums of count, sum
/// and sum of squares (`f64`), slides them down its rows, and takes each row's window sums as
/// differences of a running sum along the row. The test itself needs no division or root:
/// `spread >= min · |mean|` is `n q - s² >= min² s²` for `n` values of sum `s` and sum of
/// squares `q`.
pub fn textureless(image: &GrayImage, params: &MatchParams) -> Vec<bool> {
    let (width, height) = (image.width() as usize, image.height() as usize);
    let min = f64::from(params.min_contrast);
    let mut flat = vec![false; width * height];
    if min <= 0.0 || width == 0 {
        return flat;
    }
    let window = Window {
        pixels: image.pixels(),
        width,
        height,
        rx: params.window_width as usize / 2,
        ry: params.window_height as usize / 2,
        min_squared: min * min,
    };
    flat.par_chunks_mut(CHUNK_ROWS * width)
        .enumerate()
        .for_each(|(chunk, out)| chunk_rows(&window, chunk * CHUNK_ROWS, out));
    flat
}

/// What the chunks of [`textureless`] share.
struct Window<'a> {
    pixels: &'a [f32],
    width: usize,
    height: usize,
    rx: usize,
    ry: usize,
    min_squared: f64,
}

/// Count, sum and sum of squares of some pixel values.
#[derive(Clone, Copy, Default)]
struct Moments {
    count: f64,
    sum: f64,
    squares: f64,
}

impl Moments {
    /// Adds (`sign` 1) or takes out (`sign` -1) one value; `NaN` values count as nothing.
    /// Branch-free, so that loops over a row vectorise.
    #[inline(always)]
    fn add(&mut self, value: f32, sign: f64) {
        let (v, weight) = if value.is_nan() {
            (0.0, 0.0)
        } else {
            (f64::from(value), sign)
        };
        self.count += weight;
        self.sum += weight * v;
        self.squares += weight * v * v;
    }

    /// `self - other`.
    #[inline(always)]
    fn minus(self, other: Self) -> Self {
        Self {
            count: self.count - other.count,
            sum: self.sum - other.sum,
            squares: self.squares - other.squares,
        }
    }

    /// Whether these values have a contrast below the bound (no values: yes).
    #[inline(always)]
    fn flat(self, min_squared: f64) -> bool {
        // n² · variance; `!(a >= b)` so that a zero-over-zero window counts as texture-less.
        let spread = (self.count * self.squares - self.sum * self.sum).max(0.0);
        self.count < 0.5 || !(spread >= min_squared * self.sum * self.sum && spread > 0.0)
    }
}

fuzzyvox_core::dispatched! {
    /// The verdicts of rows `y0 ..` of `window`, as many as `out` holds. Compiled for AVX-512 and
    /// AVX2 as well, chosen at run time.
    fn chunk_rows(window: &Window, y0: usize, out: &mut [bool]) {
        let (w, h) = (window.width, window.height);
        let row = |y: usize| window.pixels.get(y * w..(y + 1) * w).unwrap_or_default();
        // The window's column sums, rows `y0 - ry ..= y0 + ry` clamped to the image (clamped
        // rows are left out, not repeated).
        let mut columns = vec![Moments::default(); w];
        for y in y0.saturating_sub(window.ry)..(y0 + window.ry + 1).min(h) {
            for (c, &v) in columns.iter_mut().zip(row(y)) {
                c.add(v, 1.0);
            }
        }
        let mut running = vec![Moments::default(); w + 1];
        for (y, out) in (y0..).zip(out.chunks_exact_mut(w)) {
            // Running sums along the row: `running[x]` holds columns `0..x`.
            let mut total = Moments::default();
            for (r, c) in running.iter_mut().skip(1).zip(&columns) {
                total.count += c.count;
                total.sum += c.sum;
                total.squares += c.squares;
                *r = total;
            }
            for (x, flat) in out.iter_mut().enumerate() {
                let (x0, x1) = (x.saturating_sub(window.rx), (x + window.rx + 1).min(w));
                let at = |x: usize| running.get(x).copied().unwrap_or_default();
                *flat = at(x1).minus(at(x0)).flat(window.min_squared);
            }
            // Slide the column sums down one row.
            if let Some(leaving) = y.checked_sub(window.ry) {
                for (c, &v) in columns.iter_mut().zip(row(leaving)) {
                    c.add(v, -1.0);
                }
            }
            if y + window.ry + 1 < h {
                for (c, &v) in columns.iter_mut().zip(row(y + window.ry + 1)) {
                    c.add(v, 1.0);
                }
            }
        }
}
}

/// Clears the match of every pixel of `map` that [`textureless`] marks in `image` (the image
/// the map was matched in).
pub(crate) fn drop_textureless(image: &GrayImage, params: &MatchParams, map: &mut DisparityMap) {
    if params.min_contrast <= 0.0 {
        return;
    }
    let flat = textureless(image, params);
    for (i, _) in flat.iter().enumerate().filter(|(_, f)| **f) {
        map.disparity[i] = f32::NAN;
        map.range_low[i] = f32::NAN;
        map.range_high[i] = f32::NAN;
        map.cost[i] = f32::NAN;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(min_contrast: f32) -> MatchParams {
        MatchParams {
            window_width: 3,
            window_height: 3,
            min_contrast,
            ..MatchParams::default()
        }
    }

    #[test]
    fn a_smooth_sky_is_textureless_and_a_pattern_is_not() {
        // Left half: a sky-like ramp of 0.001 per row around 0.8 (contrast about 0.001);
        // right half: a checkerboard of 0.3 and 0.5.
        let (w, h) = (8u32, 6u32);
        let pixels: Vec<f32> = (0..h)
            .flat_map(|y| {
                (0..w).map(move |x| {
                    if x < 4 {
                        0.8 + 0.001 * y as f32
                    } else if (x + y) % 2 == 0 {
                        0.3
                    } else {
                        0.5
                    }
                })
            })
            .collect();
        let image = GrayImage::new(w, h, pixels).unwrap();
        let flat = textureless(&image, &params(0.005));
        assert!(flat[2 * 8 + 1], "the ramp's interior");
        assert!(!flat[2 * 8 + 6], "the checkerboard");
        // The same image scaled to 0-255 gives the same answer.
        let scaled = GrayImage::new(w, h, image.pixels().iter().map(|v| v * 255.0).collect());
        assert_eq!(textureless(&scaled.unwrap(), &params(0.005)), flat);
        // Off: nothing is texture-less.
        assert!(!textureless(&image, &params(0.0)).contains(&true));
    }

    /// The test by its definition, one window at a time.
    fn plain(image: &GrayImage, params: &MatchParams) -> Vec<bool> {
        let (w, h) = (image.width() as usize, image.height() as usize);
        let (rx, ry) = (
            params.window_width as usize / 2,
            params.window_height as usize / 2,
        );
        let mut flat = vec![false; w * h];
        for y in 0..h {
            for x in 0..w {
                let values: Vec<f64> = (y.saturating_sub(ry)..(y + ry + 1).min(h))
                    .flat_map(|yy| {
                        (x.saturating_sub(rx)..(x + rx + 1).min(w)).map(move |xx| (yy, xx))
                    })
                    .map(|(yy, xx)| image.pixels()[yy * w + xx])
                    .filter(|v| !v.is_nan())
                    .map(f64::from)
                    .collect();
                let n = values.len() as f64;
                let mean = values.iter().sum::<f64>() / n;
                let spread = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
                flat[y * w + x] = values.is_empty()
                    || !(spread >= f64::from(params.min_contrast) * mean.abs() && spread > 0.0);
            }
        }
        flat
    }

    #[test]
    fn chunks_of_rows_give_the_definition() {
        // Heights across several chunks, windows of several shapes, missing values, and
        // contrasts on both sides of the bound.
        let mut state = 7u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for (w, h, window) in [
            (1u32, 1u32, 3u32),
            (7, 40, 9),
            (33, 17, 5),
            (20, 50, 15),
            (5, 3, 1),
        ] {
            let pixels: Vec<f32> = (0..w * h)
                .map(|i| {
                    let v = next();
                    if i % 23 == 4 {
                        f32::NAN
                    } else if i / w < h / 2 {
                        0.5 + 0.002 * v
                    } else {
                        v
                    }
                })
                .collect();
            let image = GrayImage::new(w, h, pixels).unwrap();
            let params = MatchParams {
                window_width: window,
                window_height: (window + 2).min(15),
                min_contrast: 0.002,
                ..MatchParams::default()
            };
            let fast = textureless(&image, &params);
            assert_eq!(fast, plain(&image, &params), "{w}x{h}, window {window}");
            if w * h > 100 {
                assert!(fast.contains(&true) && fast.contains(&false), "{w}x{h}");
            }
        }
    }

    #[test]
    fn windows_without_values_are_textureless() {
        let mut pixels = vec![f32::NAN; 25];
        pixels[24] = 0.5;
        let image = GrayImage::new(5, 5, pixels).unwrap();
        let flat = textureless(&image, &params(0.005));
        // No value at all, and a single value (no spread), both.
        assert!(flat[0] && flat[24]);
        let zeros = GrayImage::new(3, 3, vec![0.0; 9]).unwrap();
        assert!(textureless(&zeros, &params(0.005)).iter().all(|&f| f));
    }

    #[test]
    fn dropped_pixels_lose_their_match() {
        let image = GrayImage::new(4, 1, vec![0.5, 0.5, 0.5, 0.5]).unwrap();
        let mut map = DisparityMap {
            width: 4,
            height: 1,
            disparity: vec![3.0; 4],
            range_low: vec![2.0; 4],
            range_high: vec![4.0; 4],
            cost: vec![0.1; 4],
        };
        drop_textureless(&image, &params(0.005), &mut map);
        assert!(map.disparity.iter().all(|d| d.is_nan()));
        assert!(map.cost.iter().all(|c| c.is_nan()));
    }
}
