//! PNG figures for reports, like the paper's: top-down views of the occupied voxels (with or
//! without free space), planned flights over a map, and the depth stage's images of one pair.

use std::path::Path;

use image::{Rgb, RgbImage};
use nalgebra::Point3;

use super::experiment::DepthSample;
use crate::error::{Error, Result};
use crate::map::VoxelMap;
use crate::measures::VoxelClass;
use crate::storage::VoxelKey;

/// The part of the world a top-down view shows: the x/y box `[min, max]` (metres) and the
/// heights `[low, high]` that the colour ramp spans; voxels whose centre lies below `low` (the
/// ground) are left out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TopDownView {
    /// South-west corner (x, y), metres.
    pub min: [f64; 2],
    /// North-east corner (x, y), metres.
    pub max: [f64; 2],
    /// Heights at the two ends of the colour ramp, metres.
    pub heights: [f64; 2],
}

/// Colour of free columns.
const FREE: Rgb<u8> = Rgb([190, 230, 190]);
/// Colour of columns with no occupied or free voxel.
const BLANK: Rgb<u8> = Rgb([255, 255, 255]);

/// Pixels per voxel column of a top-down view: enough for about 600 pixels across.
fn scale(columns: u32, rows: u32) -> u32 {
    (600 / columns.max(rows).max(1)).clamp(1, 8)
}

/// Draws a top-down view of `map`: each voxel column is a square of pixels (about 600 pixels
/// across in all); occupied columns are coloured by the height of their highest occupied voxel
/// (dark blue low, yellow high); with `show_free`, columns with free voxels and nothing
/// occupied are light green; the rest white.
pub fn top_down_image(map: &dyn VoxelMap, view: &TopDownView, show_free: bool) -> RgbImage {
    let resolution = map.resolution();
    let size = resolution.size();
    let columns = (((view.max[0] - view.min[0]) / size).ceil().max(1.0) as u32).min(4096);
    let rows = (((view.max[1] - view.min[1]) / size).ceil().max(1.0) as u32).min(4096);
    let x0 = (view.min[0] / size).floor() as i64;
    let y0 = (view.min[1] / size).floor() as i64;
    let mut top: Vec<Option<i32>> = vec![None; (columns * rows) as usize];
    let mut free = vec![false; (columns * rows) as usize];
    for (key, m) in map.cells() {
        let (u, v) = (i64::from(key.x) - x0, i64::from(key.y) - y0);
        if u < 0
            || v < 0
            || u >= i64::from(columns)
            || v >= i64::from(rows)
            || resolution.center(key).z < view.heights[0]
        {
            continue;
        }
        let i = (v as u32 * columns + u as u32) as usize;
        match map.measure_config().classify(m) {
            VoxelClass::Occupied => top[i] = Some(top[i].map_or(key.z, |z| z.max(key.z))),
            VoxelClass::Free => free[i] = true,
            _ => {}
        }
    }
    let span = (view.heights[1] - view.heights[0]).max(1e-9);
    let k = scale(columns, rows);
    RgbImage::from_fn(columns * k, rows * k, |u, v| {
        // Image rows run south to north upwards: flip so that +y is up.
        let (u, v) = (u / k, v / k);
        let i = ((rows - 1 - v) * columns + u) as usize;
        match top[i] {
            Some(z) => {
                let height = resolution.center(VoxelKey::new(0, 0, z)).z;
                Rgb(ramp(((height - view.heights[0]) / span).clamp(0.0, 1.0)))
            }
            None if show_free && free[i] => FREE,
            None => BLANK,
        }
    })
}

/// Writes [`top_down_image`] as a PNG.
pub fn top_down_png(
    map: &dyn VoxelMap,
    view: &TopDownView,
    show_free: bool,
    path: &Path,
) -> Result<()> {
    save(&top_down_image(map, view, show_free), path)
}

/// Writes a top-down view of `map` (occupied only) with flight paths drawn over it: each path
/// as its waypoint polyline, red when it meets the true geometry, black otherwise; starts are
/// marked by a small square.
pub fn flights_png(
    map: &dyn VoxelMap,
    view: &TopDownView,
    paths: &[(&[Point3<f64>], bool)],
    path: &Path,
) -> Result<()> {
    let mut image = top_down_image(map, view, false);
    // The view's first column starts at the voxel boundary below `view.min`; each column is
    // `k` pixels wide.
    let res = map.resolution().size();
    let columns = ((view.max[0] - view.min[0]) / res)
        .ceil()
        .clamp(1.0, 4096.0);
    let size = res * columns / f64::from(image.width());
    let (x0, y0) = (
        (view.min[0] / res).floor() * res,
        (view.min[1] / res).floor() * res,
    );
    let rows = f64::from(image.height());
    let to_pixel = |p: &Point3<f64>| ((p.x - x0) / size, rows - (p.y - y0) / size);
    for (waypoints, collides) in paths {
        let colour = if *collides {
            Rgb([220, 30, 30])
        } else {
            Rgb([20, 20, 20])
        };
        for w in waypoints.windows(2) {
            line(&mut image, to_pixel(&w[0]), to_pixel(&w[1]), colour);
        }
        if let Some(start) = waypoints.first() {
            let (u, v) = to_pixel(start);
            for du in -1..=1 {
                for dv in -1..=1 {
                    put(&mut image, u + f64::from(du), v + f64::from(dv), colour);
                }
            }
        }
    }
    save(&image, path)
}

/// Writes the depth stage's images of one pair as a 4 × 2 grid of panels, each the size of the
/// frame: top row the rendered image, the true depth, the error `|P0 - truth|` (0 to 2 m) and
/// the confidence (black 0, white 1); bottom row `P-`, `P0`, `P+` and the interval width
/// `P+ - P-` (0 to 10 m). Depths share one colour ramp from 0 to the 98th percentile of the
/// true depth; pixels without a value are black.
pub fn depth_panels_png(sample: &DepthSample, path: &Path) -> Result<()> {
    let image = sample.frame.image();
    let (w, h) = (image.width(), image.height());
    let truth = &sample.truth;
    if truth.width != w || truth.height != h {
        return Err(Error::SizeMismatch {
            what: "true depth pixels",
            expected: (w * h) as usize,
            found: truth.depth.len(),
        });
    }
    let mut finite: Vec<f32> = truth
        .depth
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .collect();
    finite.sort_by(f32::total_cmp);
    let top = finite
        .get(finite.len() * 98 / 100)
        .copied()
        .unwrap_or(1.0)
        .max(1e-3);
    let error: Vec<f32> = image
        .depth()
        .iter()
        .zip(&truth.depth)
        .map(|(p, t)| (p - t).abs())
        .collect();
    let width: Vec<f32> = image
        .far()
        .iter()
        .zip(image.near())
        .map(|(f, n)| f - n)
        .collect();
    let panels: [(&[f32], f32, bool); 8] = [
        (&truth.image, 1.0, false),
        (&truth.depth, top, true),
        (&error, 2.0, true),
        (image.confidence(), 1.0, false),
        (image.near(), top, true),
        (image.depth(), top, true),
        (image.far(), top, true),
        (&width, 10.0, true),
    ];
    let mut out = RgbImage::new(4 * w + 3, 2 * h + 1);
    for pixel in out.pixels_mut() {
        *pixel = BLANK;
    }
    for (p, (values, scale, coloured)) in panels.iter().enumerate() {
        let (ox, oy) = ((p as u32 % 4) * (w + 1), (p as u32 / 4) * (h + 1));
        for y in 0..h {
            for x in 0..w {
                let value = values
                    .get((y * w + x) as usize)
                    .copied()
                    .unwrap_or(f32::NAN);
                let colour = if !value.is_finite() {
                    Rgb([0, 0, 0])
                } else if *coloured {
                    Rgb(ramp(f64::from(value / scale).clamp(0.0, 1.0)))
                } else {
                    let g = (value / scale).clamp(0.0, 1.0) * 255.0;
                    Rgb([g as u8; 3])
                };
                out.put_pixel(ox + x, oy + y, colour);
            }
        }
    }
    save(&out, path)
}

fn save(image: &RgbImage, path: &Path) -> Result<()> {
    image.save(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })
}

fn put(image: &mut RgbImage, u: f64, v: f64, colour: Rgb<u8>) {
    if u >= 0.0 && v >= 0.0 && u < f64::from(image.width()) && v < f64::from(image.height()) {
        image.put_pixel(u as u32, v as u32, colour);
    }
}

/// A straight line from `a` to `b` (pixels), sampled at half-pixel steps.
fn line(image: &mut RgbImage, a: (f64, f64), b: (f64, f64), colour: Rgb<u8>) {
    let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) * 2.0)
        .ceil()
        .min(1e5) as u32;
    for s in 0..=steps {
        let t = if steps == 0 {
            0.0
        } else {
            f64::from(s) / f64::from(steps)
        };
        put(image, a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, colour);
    }
}

/// A dark-blue → teal → yellow colour ramp for `t` in `[0, 1]`.
fn ramp(t: f64) -> [u8; 3] {
    let stops = [
        [30.0, 30.0, 120.0],
        [30.0, 150.0, 140.0],
        [250.0, 220.0, 40.0],
    ];
    let s = t * 2.0;
    let (a, b, f) = if s < 1.0 {
        (stops[0], stops[1], s)
    } else {
        (stops[1], stops[2], s - 1.0)
    };
    [0, 1, 2].map(|c| (a[c] + (b[c] - a[c]) * f) as u8)
}
