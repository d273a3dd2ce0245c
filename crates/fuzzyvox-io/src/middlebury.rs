//! Middlebury stereo folders: `im0.png` (left), `im1.png` (right), `calib.txt`, and optionally
//! `disp0GT.pfm` (left disparity, `inf` where there is no ground truth). The images are already
//! rectified; `left(y, x)` matches `right(y, x - d)` and `Z = baseline · f / (d + doffs)`.

use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::geometry::PinholeIntrinsics;
use fuzzyvox_core::image::{GrayImage, StereoGeometry};
use nalgebra::Isometry3;

use super::gray::read_gray_image;
use super::pfm::{FloatImage, read_pfm};

/// The contents of a Middlebury `calib.txt`.
#[derive(Clone, Debug, PartialEq)]
pub struct MiddleburyCalib {
    /// Left camera matrix, row-major.
    pub cam0: [f64; 9],
    /// Right camera matrix, row-major.
    pub cam1: [f64; 9],
    /// `cx(right) - cx(left)` (px).
    pub doffs: f64,
    /// Baseline in metres (the file gives millimetres).
    pub baseline: f64,
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// The dataset's suggested number of disparities.
    pub ndisp: u32,
}

impl MiddleburyCalib {
    /// The rectified pair's geometry, with the left camera at the world origin.
    pub fn geometry(&self) -> Result<StereoGeometry> {
        let k = &self.cam0;
        let intrinsics = PinholeIntrinsics::new(self.width, self.height, k[0], k[4], k[2], k[5])?;
        StereoGeometry::new(intrinsics, Isometry3::identity(), self.baseline, self.doffs)
    }
}

/// Reads a Middlebury `calib.txt`.
pub fn read_calib(path: &Path) -> Result<MiddleburyCalib> {
    let bytes = super::bounded::read_small(path)?;
    calib_from(&bytes, path)
}

/// Parses the bytes of a Middlebury `calib.txt` held in memory; see [`read_calib`]. Errors name
/// the path `<memory>`.
pub fn parse_calib(bytes: &[u8]) -> Result<MiddleburyCalib> {
    calib_from(bytes, Path::new("<memory>"))
}

fn calib_from(bytes: &[u8], path: &Path) -> Result<MiddleburyCalib> {
    let parse_error = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes
            .iter()
            .take(e.valid_up_to())
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        parse_error(line, "not UTF-8 text (a binary file?)".into())
    })?;
    let mut values: std::collections::HashMap<String, (usize, String)> = Default::default();
    for (index, line) in text.lines().enumerate() {
        if let Some((key, value)) = line.split_once('=') {
            values.insert(
                key.trim().to_string(),
                (index + 1, value.trim().to_string()),
            );
        }
    }
    let get = |key: &str| {
        values
            .get(key)
            .ok_or_else(|| parse_error(0, format!("missing `{key}=`")))
    };
    let number = |key: &str| -> Result<f64> {
        let (line, value) = get(key)?;
        value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| parse_error(*line, format!("`{key}` is not a finite number")))
    };
    let matrix = |key: &str| -> Result<[f64; 9]> {
        let (line, value) = get(key)?;
        let numbers: Vec<f64> = value
            .trim_matches(|c| c == '[' || c == ']')
            .split(|c: char| c.is_whitespace() || c == ';')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| parse_error(*line, format!("`{key}` holds a non-number")))?;
        <[f64; 9]>::try_from(numbers)
            .map_err(|_| parse_error(*line, format!("`{key}` must hold 3×3 numbers")))
    };
    let integer = |key: &str| -> Result<u32> {
        let v = number(key)?;
        if v >= 0.0 && v.fract() == 0.0 && v <= f64::from(u32::MAX) {
            Ok(v as u32)
        } else {
            Err(parse_error(get(key)?.0, format!("`{key}` is not a count")))
        }
    };
    Ok(MiddleburyCalib {
        cam0: matrix("cam0")?,
        cam1: matrix("cam1")?,
        doffs: number("doffs")?,
        baseline: number("baseline")? * 1e-3,
        width: integer("width")?,
        height: integer("height")?,
        ndisp: integer("ndisp")?,
    })
}

/// A Middlebury pair with its calibration and, when present, ground truth.
#[derive(Clone, Debug)]
pub struct MiddleburyPair {
    /// `im0.png`.
    pub left: GrayImage,
    /// `im1.png`.
    pub right: GrayImage,
    /// `calib.txt`.
    pub calib: MiddleburyCalib,
    /// `disp0GT.pfm`, when the folder has it.
    pub ground_truth: Option<FloatImage>,
}

/// Reads a Middlebury folder; the images must have the calibrated size.
pub fn read_middlebury(dir: &Path) -> Result<MiddleburyPair> {
    let left = read_gray_image(&dir.join("im0.png"))?;
    let right = read_gray_image(&dir.join("im1.png"))?;
    let calib = read_calib(&dir.join("calib.txt"))?;
    for (what, image) in [("im0.png pixels", &left), ("im1.png pixels", &right)] {
        if image.width() != calib.width || image.height() != calib.height {
            return Err(Error::SizeMismatch {
                what,
                expected: calib.width as usize * calib.height as usize,
                found: image.pixels().len(),
            });
        }
    }
    let gt_path = dir.join("disp0GT.pfm");
    let ground_truth = if gt_path.exists() {
        let gt = read_pfm(&gt_path)?;
        if gt.width != calib.width || gt.height != calib.height {
            return Err(Error::SizeMismatch {
                what: "disp0GT.pfm pixels",
                expected: calib.width as usize * calib.height as usize,
                found: gt.data.len(),
            });
        }
        Some(gt)
    } else {
        None
    };
    Ok(MiddleburyPair {
        left,
        right,
        calib,
        ground_truth,
    })
}
