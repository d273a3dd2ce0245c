//! Grayscale images for matching: one `f32` plane, `NaN` where a pixel has no value (outside the
//! source image after rectification).

use crate::error::{Error, Result};

/// A grayscale image, row-major `f32` intensities in any range (census matching only compares
/// pixels, so 0–255 and 0–1 work alike); `NaN` marks a pixel without a value.
#[derive(Clone, Debug, PartialEq)]
pub struct GrayImage {
    width: u32,
    height: u32,
    pixels: Vec<f32>,
}

impl GrayImage {
    /// An image from a row-major plane of `width × height` values; the size must be non-zero.
    pub fn new(width: u32, height: u32, pixels: Vec<f32>) -> Result<Self> {
        let count = (width as usize) * (height as usize);
        if count == 0 {
            return Err(Error::Empty("image"));
        }
        if pixels.len() != count {
            return Err(Error::SizeMismatch {
                what: "image pixels (width × height)",
                expected: count,
                found: pixels.len(),
            });
        }
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    /// An image from 8-bit gray values.
    pub fn from_luma8(width: u32, height: u32, pixels: &[u8]) -> Result<Self> {
        Self::new(
            width,
            height,
            pixels.iter().map(|&p| f32::from(p)).collect(),
        )
    }

    /// An image from interleaved 8-bit RGB, converted with the Rec. 601 luma weights.
    pub fn from_rgb8(width: u32, height: u32, rgb: &[u8]) -> Result<Self> {
        let count = (width as usize) * (height as usize);
        if rgb.len() != 3 * count {
            return Err(Error::SizeMismatch {
                what: "RGB image bytes (3 × width × height)",
                expected: 3 * count,
                found: rgb.len(),
            });
        }
        let pixels = rgb
            .chunks_exact(3)
            .map(|p| 0.299 * f32::from(p[0]) + 0.587 * f32::from(p[1]) + 0.114 * f32::from(p[2]))
            .collect();
        Self::new(width, height, pixels)
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The row-major plane.
    pub fn pixels(&self) -> &[f32] {
        &self.pixels
    }

    /// The value at `(x, y)`, `None` outside the image.
    pub fn get(&self, x: u32, y: u32) -> Option<f32> {
        (x < self.width && y < self.height)
            .then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// Bilinear interpolation at `(x, y)` (pixel centres at integers); `NaN` when the point lies
    /// outside the image or touches a pixel without a value.
    pub fn sample_bilinear(&self, x: f64, y: f64) -> f32 {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        // Half a pixel of slack at the border, clamped, so that the border row itself samples.
        if !(x > -0.5 && y > -0.5 && x < w - 0.5 && y < h - 0.5) {
            return f32::NAN;
        }
        let x = x.clamp(0.0, w - 1.0);
        let y = y.clamp(0.0, h - 1.0);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as usize, y0 as usize);
        let x1 = (x0 + 1).min(self.width as usize - 1);
        let y1 = (y0 + 1).min(self.height as usize - 1);
        let stride = self.width as usize;
        let p = |xx: usize, yy: usize| self.pixels[yy * stride + xx];
        let top = p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx;
        let bottom = p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}
