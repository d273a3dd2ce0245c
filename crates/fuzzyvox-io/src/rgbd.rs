//! RGB-D frames in the 7-Scenes / 3DMatch layout: `frame-N.depth.png` (16-bit millimetres,
//! 0 = no reading), `frame-N.pose.txt` (4×4 `world_from_camera`, row-major) and
//! `camera-intrinsics.txt` (3×3 K).

use std::path::{Path, PathBuf};

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::geometry::{PinholeIntrinsics, pose_from_matrix};
use fuzzyvox_core::integrate::{DepthFrame, IntervalDepthImage};
use nalgebra::{Isometry3, Matrix4};

use crate::image_source::ImageSource;

/// A depth image in metres, row-major; 0 where the sensor gave no reading.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Depth along the optical axis in metres, row-major.
    pub depth: Vec<f32>,
}

/// Reads a 16-bit PNG of depth in millimetres.
pub fn read_depth_png_mm(path: &Path) -> Result<DepthImage> {
    depth_png_from(ImageSource::File(path))
}

/// Decodes a 16-bit PNG of depth in millimetres held in memory; see [`read_depth_png_mm`].
/// Errors name the path `<memory>`.
pub fn decode_depth_png_mm(bytes: &[u8]) -> Result<DepthImage> {
    depth_png_from(ImageSource::Memory(bytes))
}

fn depth_png_from(source: ImageSource<'_>) -> Result<DepthImage> {
    let decoded = source.decode("not a readable image")?;
    let image::DynamicImage::ImageLuma16(gray) = decoded else {
        return Err(Error::Parse {
            path: source.path().to_path_buf(),
            line: 0,
            message: format!(
                "expected a 16-bit grayscale depth image, found {:?}",
                decoded.color()
            ),
        });
    };
    let (width, height) = gray.dimensions();
    let depth = gray
        .into_raw()
        .into_iter()
        .map(|mm| f32::from(mm) * 1e-3)
        .collect();
    Ok(DepthImage {
        width,
        height,
        depth,
    })
}

/// Reads a whitespace-separated text matrix of `rows × cols` numbers.
fn read_matrix(path: &Path, rows: usize, cols: usize) -> Result<Vec<f64>> {
    let bytes = super::bounded::read_small(path)?;
    matrix_from(&bytes, path, rows, cols)
}

/// Parses a whitespace-separated text matrix of `rows × cols` numbers; `path` names it in errors.
fn matrix_from(bytes: &[u8], path: &Path, rows: usize, cols: usize) -> Result<Vec<f64>> {
    let parse_error = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut values = Vec::with_capacity(rows * cols);
    for (line_index, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = std::str::from_utf8(line)
            .map_err(|_| parse_error(line_index + 1, "not UTF-8 text (a binary file?)".into()))?;
        for field in line.split_whitespace() {
            let value: f64 = field
                .parse()
                .map_err(|_| parse_error(line_index + 1, format!("`{field}` is not a number")))?;
            // Stop early: a long file of numbers must not grow the vector without bound.
            if values.len() == rows * cols {
                return Err(parse_error(
                    line_index + 1,
                    format!("more than {rows}×{cols} numbers"),
                ));
            }
            values.push(value);
        }
    }
    if values.len() != rows * cols {
        return Err(parse_error(
            0,
            format!("expected {rows}×{cols} numbers, found {}", values.len()),
        ));
    }
    Ok(values)
}

/// Reads a `frame-N.pose.txt`: a row-major 4×4 `world_from_camera` matrix.
pub fn read_pose_txt(path: &Path) -> Result<Isometry3<f64>> {
    pose_from(read_matrix(path, 4, 4)?)
}

/// Parses the bytes of a `frame-N.pose.txt` held in memory; see [`read_pose_txt`]. Errors name
/// the path `<memory>`.
pub fn parse_pose_txt(bytes: &[u8]) -> Result<Isometry3<f64>> {
    pose_from(matrix_from(bytes, Path::new("<memory>"), 4, 4)?)
}

fn pose_from(values: Vec<f64>) -> Result<Isometry3<f64>> {
    let values: [f64; 16] = values.try_into().map_err(|v: Vec<f64>| {
        Error::InvalidPose(format!("expected 4×4 numbers, found {}", v.len()))
    })?;
    pose_from_matrix(&Matrix4::from_row_slice(&values))
}

/// Reads a `camera-intrinsics.txt` (row-major 3×3 K) for images of `width × height`.
pub fn read_intrinsics_txt(path: &Path, width: u32, height: u32) -> Result<PinholeIntrinsics> {
    intrinsics_from(&read_matrix(path, 3, 3)?, path, width, height)
}

/// Parses the bytes of a `camera-intrinsics.txt` held in memory; see [`read_intrinsics_txt`].
/// Errors name the path `<memory>`.
pub fn parse_intrinsics_txt(bytes: &[u8], width: u32, height: u32) -> Result<PinholeIntrinsics> {
    let path = Path::new("<memory>");
    intrinsics_from(&matrix_from(bytes, path, 3, 3)?, path, width, height)
}

fn intrinsics_from(k: &[f64], path: &Path, width: u32, height: u32) -> Result<PinholeIntrinsics> {
    let &[fx, skew, cx, zero_10, fy, cy, zero_20, zero_21, _] = k else {
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line: 0,
            message: format!("expected 3×3 numbers, found {}", k.len()),
        });
    };
    // Written so that NaN fails too.
    if ![skew, zero_10, zero_20, zero_21]
        .iter()
        .all(|v| v.abs() <= 1e-9)
    {
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line: 0,
            message: "K must be upper triangular without skew: [fx 0 cx; 0 fy cy; 0 0 1]".into(),
        });
    }
    PinholeIntrinsics::new(width, height, fx, fy, cx, cy)
}

/// Kinect (structured light) depth noise, σ in metres at depth `z` (Nguyen, Izadi and Lovell,
/// "Modeling Kinect Sensor Noise", 3DIMPVT 2012, axial model).
pub fn kinect_sigma(z: f32) -> f32 {
    0.0012 + 0.0019 * (z - 0.4) * (z - 0.4)
}

/// Turns a Kinect depth image into an interval depth image: `P± = z ± 2σ(z)` and confidence
/// `max(1 - 0.05 (P+ - P-), 0)` (the depth stage's `C = 100 - a (P+ - P-)` with `a = 5` per
/// metre, scaled to `[0, 1]`).
pub fn kinect_interval_image(depth: &DepthImage) -> Result<IntervalDepthImage> {
    IntervalDepthImage::from_depth(depth.width, depth.height, &depth.depth, |z| {
        let half = 2.0 * kinect_sigma(z);
        let near = (z - half).max(f32::MIN_POSITIVE);
        let far = z + half;
        (near, far, (1.0 - 0.05 * (far - near)).max(0.0))
    })
}

/// The files of one frame of an RGB-D folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RgbdFrameFiles {
    /// The frame number `N` of `frame-N.*`.
    pub number: u64,
    /// `frame-N.depth.png`.
    pub depth: PathBuf,
    /// `frame-N.pose.txt`.
    pub pose: PathBuf,
}

/// An RGB-D folder in the 7-Scenes / 3DMatch layout: its frames in order of their number, and
/// `camera-intrinsics.txt`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RgbdFolder {
    /// The folder.
    pub dir: PathBuf,
    /// `camera-intrinsics.txt`.
    pub intrinsics: PathBuf,
    /// Every `frame-N.depth.png` with its `frame-N.pose.txt`, by increasing `N`.
    pub frames: Vec<RgbdFrameFiles>,
}

impl RgbdFolder {
    /// Lists the frames of `dir`. Every `frame-N.depth.png` needs its `frame-N.pose.txt` (a
    /// missing one is an error, not a silently dropped frame), and the folder needs
    /// `camera-intrinsics.txt` and at least one frame.
    pub fn open(dir: &Path) -> Result<Self> {
        let io = |source| Error::Io {
            path: dir.to_path_buf(),
            source,
        };
        let mut frames = Vec::new();
        for entry in std::fs::read_dir(dir).map_err(io)? {
            let name = entry.map_err(io)?.file_name();
            let Some(name) = name.to_str() else { continue };
            let Some(number) = name
                .strip_prefix("frame-")
                .and_then(|rest| rest.strip_suffix(".depth.png"))
            else {
                continue;
            };
            let parsed: u64 = number.parse().map_err(|_| Error::Parse {
                path: dir.join(name),
                line: 0,
                message: format!("`{number}` is not a frame number"),
            })?;
            let pose = dir.join(format!("frame-{number}.pose.txt"));
            if !pose.is_file() {
                return Err(Error::Io {
                    path: pose,
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        format!("the pose of {name} is missing"),
                    ),
                });
            }
            frames.push(RgbdFrameFiles {
                number: parsed,
                depth: dir.join(name),
                pose,
            });
        }
        if frames.is_empty() {
            return Err(Error::Empty("RGB-D folder (frame-N.depth.png files)"));
        }
        frames.sort_by_key(|f| f.number);
        let intrinsics = dir.join("camera-intrinsics.txt");
        if !intrinsics.is_file() {
            return Err(Error::Io {
                path: intrinsics,
                source: std::io::Error::new(std::io::ErrorKind::NotFound, "no camera intrinsics"),
            });
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            intrinsics,
            frames,
        })
    }

    /// Reads frame `index` (position in [`Self::frames`]) as Kinect depth with its noise
    /// intervals ([`kinect_interval_image`]) and its pose.
    pub fn read_kinect_frame(&self, index: usize) -> Result<DepthFrame> {
        let files = self.frames.get(index).ok_or(Error::InvalidParameter {
            name: "frame index",
            value: index as f64,
            expected: "an index below the folder's frame count",
        })?;
        let depth = read_depth_png_mm(&files.depth)?;
        let intrinsics = read_intrinsics_txt(&self.intrinsics, depth.width, depth.height)?;
        let pose = read_pose_txt(&files.pose)?;
        DepthFrame::new(intrinsics, pose, kinect_interval_image(&depth)?)
    }
}
