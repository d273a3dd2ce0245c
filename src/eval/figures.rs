//! PNG views of maps for reports: top-down occupied voxels coloured by height, with free space
//! shown faintly.

use std::path::Path;

use crate::error::{Error, Result};
use crate::map::VoxelMap;
use crate::measures::VoxelClass;
use crate::storage::VoxelKey;

/// Writes a top-down view of `map` over the x/y box `[min, max]` (metres): each pixel is one
/// voxel column; occupied columns are coloured by the height of their highest occupied voxel
/// (dark blue low, yellow high), columns with only free voxels light green, unknown ones white.
pub fn top_down_png(
    map: &dyn VoxelMap,
    min: [f64; 2],
    max: [f64; 2],
    height_range: [f64; 2],
    path: &Path,
) -> Result<()> {
    let resolution = map.resolution();
    let size = resolution.size();
    let columns = (((max[0] - min[0]) / size).ceil().max(1.0) as u32).min(4096);
    let rows = (((max[1] - min[1]) / size).ceil().max(1.0) as u32).min(4096);
    let x0 = (min[0] / size).floor() as i32;
    let y0 = (min[1] / size).floor() as i32;
    let mut top: Vec<Option<i32>> = vec![None; (columns * rows) as usize];
    let mut free = vec![false; (columns * rows) as usize];
    for (key, m) in map.cells() {
        let (u, v) = (key.x - x0, key.y - y0);
        if u < 0 || v < 0 || u >= columns as i32 || v >= rows as i32 {
            continue;
        }
        let i = (v as u32 * columns + u as u32) as usize;
        match map.measure_config().classify(m) {
            VoxelClass::Occupied => top[i] = Some(top[i].map_or(key.z, |z| z.max(key.z))),
            VoxelClass::Free => free[i] = true,
            _ => {}
        }
    }
    let image = image::RgbImage::from_fn(columns, rows, |u, v| {
        // Image rows run south to north upwards: flip so that +y is up.
        let i = ((rows - 1 - v) * columns + u) as usize;
        match top[i] {
            Some(z) => {
                let height = resolution.center(VoxelKey::new(0, 0, z)).z;
                let t = ((height - height_range[0]) / (height_range[1] - height_range[0]))
                    .clamp(0.0, 1.0);
                image::Rgb(ramp(t))
            }
            None if free[i] => image::Rgb([200, 235, 200]),
            None => image::Rgb([255, 255, 255]),
        }
    });
    image.save(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })
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
