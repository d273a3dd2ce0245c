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

use super::params::{DisparityMap, MatchParams};

/// Whether each pixel's `window_width × window_height` window (clamped at the borders, `NaN`
/// pixels left out) has a contrast, standard deviation over mean magnitude, below
/// `min_contrast`. A window with no valid pixel, or with zero mean and zero spread, is
/// texture-less. Row-major, one entry per pixel; all `false` when `min_contrast` is 0.
pub fn textureless(image: &GrayImage, params: &MatchParams) -> Vec<bool> {
    let (width, height) = (image.width() as usize, image.height() as usize);
    let min = f64::from(params.min_contrast);
    if min <= 0.0 {
        return vec![false; width * height];
    }
    // Summed-area tables of count, sum and sum of squares, one row and column of zeros first.
    let stride = width + 1;
    let mut count = vec![0u32; stride * (height + 1)];
    let mut sum = vec![0f64; stride * (height + 1)];
    let mut squares = vec![0f64; stride * (height + 1)];
    for y in 0..height {
        let (mut c, mut s, mut q) = (0u32, 0f64, 0f64);
        for x in 0..width {
            let v = image.pixels()[y * width + x];
            if !v.is_nan() {
                let v = f64::from(v);
                c += 1;
                s += v;
                q += v * v;
            }
            let (above, here) = (y * stride + x + 1, (y + 1) * stride + x + 1);
            count[here] = count[above] + c;
            sum[here] = sum[above] + s;
            squares[here] = squares[above] + q;
        }
    }
    let (rx, ry) = (
        params.window_width as usize / 2,
        params.window_height as usize / 2,
    );
    let mut flat = vec![false; width * height];
    for y in 0..height {
        let (y0, y1) = (y.saturating_sub(ry), (y + ry + 1).min(height));
        for x in 0..width {
            let (x0, x1) = (x.saturating_sub(rx), (x + rx + 1).min(width));
            let corners = [(y1, x1, 1.0), (y0, x1, -1.0), (y1, x0, -1.0), (y0, x0, 1.0)];
            let (mut n, mut s, mut q) = (0i64, 0.0, 0.0);
            for (cy, cx, sign) in corners {
                let i = cy * stride + cx;
                n += sign as i64 * i64::from(count[i]);
                s += sign * sum[i];
                q += sign * squares[i];
            }
            flat[y * width + x] = if n == 0 {
                true
            } else {
                let n = n as f64;
                let mean = s / n;
                let spread = (q / n - mean * mean).max(0.0).sqrt();
                // `!(a >= b)` so that a zero-over-zero window counts as texture-less.
                !(spread >= min * mean.abs() && spread > 0.0)
            };
        }
    }
    flat
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
