//! Depth from two images to a map: a rectified stereo pair → disparity → depth intervals with
//! confidence → a fuzzy map, and a PNG view of it.
//!
//! Without arguments it makes its own pair: a textured floor seen by a camera pair 10 cm apart
//! (disparity grows towards the bottom of the image, as for a real floor). With a Middlebury
//! folder (`im0.png`, `im1.png`, `calib.txt`) it uses that pair instead.
//!
//! Run: `cargo run --release --example depth_from_two_images [-- ../shared/data/middlebury-motorcycle]`

use fuzzyvox::VoxelMapMut;
use std::path::PathBuf;

use fuzzyvox::depth::{DepthParams, GrayImage, StereoGeometry, depth_from_rectified};
use fuzzyvox::figure::{View, ViewColor, write_view_png};
use fuzzyvox::io::middlebury::read_middlebury;
use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, PinholeIntrinsics, VoxelMap};
use nalgebra::Isometry3;

/// A rectified pair of a textured floor: row `y` of the left image matches the right image
/// `d(y)` pixels to the left, with `d` growing from 10 px at the top to 40 px at the bottom
/// (depth 3 m down to 0.75 m).
fn synthetic_pair() -> Result<(GrayImage, GrayImage, StereoGeometry, u32), fuzzyvox::Error> {
    let (width, height, focal, baseline) = (320u32, 240u32, 300.0, 0.1);
    // A smooth random texture: a few sines of incommensurate frequencies.
    let texture = |x: f64, y: f64| {
        let v = (0.31 * x).sin()
            + (0.17 * x + 0.9 * y).sin()
            + (0.53 * x - 0.37 * y).cos()
            + (0.071 * x * 0.93 + 1.7).sin();
        (128.0 + 30.0 * v) as f32
    };
    let disparity = |y: u32| 10.0 + 30.0 * f64::from(y) / f64::from(height - 1);
    let left: Vec<f32> = (0..height)
        .flat_map(|y| (0..width).map(move |x| texture(f64::from(x), f64::from(y))))
        .collect();
    // left(y, x) = right(y, x - d)  ⇔  right(y, x) = left(y, x + d).
    let right: Vec<f32> = (0..height)
        .flat_map(|y| (0..width).map(move |x| texture(f64::from(x) + disparity(y), f64::from(y))))
        .collect();
    let intrinsics = PinholeIntrinsics::new(
        width,
        height,
        focal,
        focal,
        f64::from(width) / 2.0,
        f64::from(height) / 2.0,
    )?;
    let geometry = StereoGeometry::new(intrinsics, Isometry3::identity(), baseline, 0.0)?;
    Ok((
        GrayImage::new(width, height, left)?,
        GrayImage::new(width, height, right)?,
        geometry,
        48,
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (left, right, geometry, disparities, resolution) = match std::env::args().nth(1) {
        Some(dir) => {
            let pair = read_middlebury(&PathBuf::from(dir))?;
            let geometry = pair.calib.geometry()?;
            (pair.left, pair.right, geometry, pair.calib.ndisp, 0.05)
        }
        None => {
            let (left, right, geometry, ndisp) = synthetic_pair()?;
            (left, right, geometry, ndisp, 0.05)
        }
    };
    let mut params = DepthParams::default();
    params.matching.num_disparities = disparities;
    // Confidence is scaled by the pair's extrinsic quality; a rectified pair is ideal (1).
    let result = depth_from_rectified(&left, &right, &geometry, 1.0, &params)?;
    let image = result.frame.image();
    let mut widths: Vec<f32> = image
        .near()
        .iter()
        .zip(image.far())
        .filter(|(n, f)| n.is_finite() && f.is_finite())
        .map(|(n, f)| f - n)
        .collect();
    widths.sort_by(f32::total_cmp);
    println!(
        "{}×{} pair, {} disparities: {} of {} pixels with an interval (density {:.1} %), \
         median interval width {:.3} m",
        left.width(),
        left.height(),
        disparities,
        image.valid_pixels(),
        image.depth().len(),
        100.0 * result.disparity.density(),
        widths.get(widths.len() / 2).copied().unwrap_or(f32::NAN)
    );

    let mut map = FuzzyMap::new(FuzzyConfig::new(resolution)?)?;
    let stats = map.integrate_depth(&result.frame, &IntegrationOptions::default())?;
    let counts = map.counts();
    let (touched, strongest) = map
        .cells()
        .filter(|(_, m)| m.occupied > 0.0)
        .fold((0, 0.0f32), |(n, best), (_, m)| {
            (n + 1, best.max(m.occupied))
        });
    println!(
        "fuzzy map at {resolution} m from {} pixels: {} occupied, {} free, {} ambiguous voxels; \
         {touched} voxels hold occupied evidence, the strongest μO = {strongest:.2}",
        stats.integrated, counts.occupied, counts.free, counts.ambiguous
    );
    // One pair spreads each pixel's occupied evidence over its whole interval, so a wide
    // interval commits little to any one voxel: surfaces become `Occupied` only as more views
    // agree (integrate more pairs into the same map), while free space in front of them is
    // already clear.
    let out = std::env::temp_dir().join("fuzzyvox-depth-from-two-images.png");
    let (w, h) = write_view_png(&map, View::Side, ViewColor::Occupied, 2, &out)?;
    println!(
        "side view ({w}×{h}, occupied membership): {}",
        out.display()
    );
    Ok(())
}
