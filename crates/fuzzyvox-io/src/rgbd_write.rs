//! Writers for the RGB-D folder layout that [`rgbd`](super::rgbd) reads: 16-bit millimetre
//! depth PNGs, 8-bit grayscale images, 4×4 pose files and `camera-intrinsics.txt`. The
//! simulator exports its frames this way, so simulated flights can be mapped like real ones.

use std::fmt::Write as _;
use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::file::write_atomic;
use fuzzyvox_core::geometry::PinholeIntrinsics;
use nalgebra::Isometry3;

fn encode_error(path: &Path, error: image::ImageError) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(error),
    }
}

fn check_size(what: &'static str, width: u32, height: u32, found: usize) -> Result<()> {
    let expected = width as usize * height as usize;
    if found != expected || expected == 0 {
        return Err(Error::SizeMismatch {
            what,
            expected,
            found,
        });
    }
    Ok(())
}

/// Writes depth in metres as a 16-bit PNG of millimetres; values that are not finite, not
/// positive or beyond 65.535 m become 0 ("no reading").
pub fn write_depth_png_mm(path: &Path, width: u32, height: u32, depth: &[f32]) -> Result<()> {
    check_size("depth pixels", width, height, depth.len())?;
    let raw: Vec<u16> = depth
        .iter()
        .map(|&d| {
            let mm = (f64::from(d) * 1000.0).round();
            if mm.is_finite() && mm > 0.0 && mm <= f64::from(u16::MAX) {
                mm as u16
            } else {
                0
            }
        })
        .collect();
    let image = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(width, height, raw).ok_or(
        Error::SizeMismatch {
            what: "depth pixels",
            expected: width as usize * height as usize,
            found: depth.len(),
        },
    )?;
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| encode_error(path, e))?;
    write_atomic(path, &bytes)
}

/// Writes intensities in `[0, 1]` (clamped; NaN as 0) as an 8-bit grayscale PNG.
pub fn write_gray_png(path: &Path, width: u32, height: u32, pixels: &[f32]) -> Result<()> {
    check_size("image pixels", width, height, pixels.len())?;
    let raw: Vec<u8> = pixels
        .iter()
        .map(|&v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    let image = image::GrayImage::from_raw(width, height, raw).ok_or(Error::SizeMismatch {
        what: "image pixels",
        expected: width as usize * height as usize,
        found: pixels.len(),
    })?;
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| encode_error(path, e))?;
    write_atomic(path, &bytes)
}

/// Writes a `world_from_camera` pose as four rows of a 4×4 matrix.
pub fn write_pose_txt(path: &Path, pose: &Isometry3<f64>) -> Result<()> {
    let m = pose.to_homogeneous();
    let mut text = String::new();
    for row in m.row_iter() {
        let row: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
        let _ = writeln!(text, "{}", row.join("\t"));
    }
    write_atomic(path, text.as_bytes())
}

/// Writes `camera-intrinsics.txt`: the 3×3 K, row-major.
pub fn write_intrinsics_txt(path: &Path, k: &PinholeIntrinsics) -> Result<()> {
    let text = format!(
        "{:.9e}\t{:.9e}\t{:.9e}\n{:.9e}\t{:.9e}\t{:.9e}\n{:.9e}\t{:.9e}\t{:.9e}\n",
        k.fx(),
        0.0,
        k.cx(),
        0.0,
        k.fy(),
        k.cy(),
        0.0,
        0.0,
        1.0
    );
    write_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgbd::{read_depth_png_mm, read_intrinsics_txt, read_pose_txt};
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn written_files_read_back() {
        let dir = std::env::temp_dir().join(format!("fuzzyvox-rgbd-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let depth = [1.234f32, f32::NAN, -1.0, 70.0, 0.0, 12.5];
        let path = dir.join("frame-000000.depth.png");
        write_depth_png_mm(&path, 3, 2, &depth).unwrap();
        let back = read_depth_png_mm(&path).unwrap();
        assert_eq!((back.width, back.height), (3, 2));
        let expected = [1.234, 0.0, 0.0, 0.0, 0.0, 12.5];
        assert!(
            back.depth
                .iter()
                .zip(expected)
                .all(|(a, b)| (a - b).abs() < 1e-6),
            "{:?}",
            back.depth
        );
        assert!(write_depth_png_mm(&path, 4, 2, &depth).is_err());
        let pose = Isometry3::from_parts(
            Translation3::new(1.0, -2.0, 3.5),
            UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3),
        );
        let pose_path = dir.join("frame-000000.pose.txt");
        write_pose_txt(&pose_path, &pose).unwrap();
        let read = read_pose_txt(&pose_path).unwrap();
        assert!((read.to_homogeneous() - pose.to_homogeneous()).abs().max() < 1e-8);
        let k = PinholeIntrinsics::new(3, 2, 100.0, 101.0, 1.0, 0.5).unwrap();
        let k_path = dir.join("camera-intrinsics.txt");
        write_intrinsics_txt(&k_path, &k).unwrap();
        assert_eq!(read_intrinsics_txt(&k_path, 3, 2).unwrap(), k);
        write_gray_png(
            &dir.join("frame-000000.color.png"),
            3,
            2,
            &[0.0, 0.5, 1.0, 2.0, f32::NAN, -1.0],
        )
        .unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
