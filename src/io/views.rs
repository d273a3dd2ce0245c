//! PNG views of a map: from the top, from the side, or a horizontal slice, coloured by class or
//! by one measure. One pixel (or a `scale × scale` square) per voxel; the image spans the
//! observed voxels.
//!
//! A projection (top or side) shows, per column of voxels along the view direction, what a
//! planner most needs to know about that column:
//! - by class, the most critical class in it: occupied before ambiguous before free;
//! - by `occupied`, `free` or `ambiguity`, the largest value in the column;
//! - by `safety`, the smallest value over the column's observed voxels.
//!
//! Unobserved columns and voxels are white.

use std::path::Path;

use crate::error::{Error, Result, finite};
use crate::io::ply::class_color;
use crate::map::VoxelMap;
use crate::measures::{Measures, VoxelClass};
use crate::storage::VoxelKey;

/// Where the view looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// Down the z axis: x to the right, y up.
    Top,
    /// Along the y axis: x to the right, z up.
    Side,
    /// The layer of voxels that holds height `z` (metres): x to the right, y up.
    Slice {
        /// The height in metres.
        z: f64,
    },
}

/// What colours the pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewColor {
    /// The class colours of [`class_color`].
    Class,
    /// Occupied membership μO on a colour ramp from 0 (dark blue) to 1 (yellow).
    Occupied,
    /// Free membership μE on the same ramp.
    Free,
    /// Ambiguity on the same ramp.
    Ambiguity,
    /// Safety on the same ramp.
    Safety,
}

/// Largest image side in pixels, a guard against absurd extents.
pub const MAX_VIEW_SIDE: u32 = 16_384;

/// Renders a view of `map`, `scale` pixels per voxel (1 to 16).
///
/// ```
/// use fuzzyvox::io::views::{View, ViewColor, render_view};
/// use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelMap, VoxelMapMut};
/// use nalgebra::Point3;
///
/// let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
/// let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(1.05, 0.05, 0.05)])?;
/// map.integrate_cloud(&cloud, &IntegrationOptions::default())?;
/// let image = render_view(&map, View::Top, ViewColor::Class, 1)?;
/// // The observed voxels run from x = 0 to 1.1 m: 11 columns, one row.
/// assert_eq!(image.dimensions(), (11, 1));
/// # Ok::<(), fuzzyvox::Error>(())
/// ```
pub fn render_view(
    map: &dyn VoxelMap,
    view: View,
    color: ViewColor,
    scale: u32,
) -> Result<image::RgbImage> {
    if !(1..=16).contains(&scale) {
        return Err(Error::InvalidParameter {
            name: "scale",
            value: f64::from(scale),
            expected: "1 to 16 pixels per voxel",
        });
    }
    let resolution = map.resolution();
    let layer = match view {
        View::Slice { z } => {
            finite("slice height", z)?;
            let key = resolution.key_of(&nalgebra::Point3::new(0.0, 0.0, z))?;
            Some(key.z)
        }
        _ => None,
    };
    // Horizontal and vertical image axes of a voxel key.
    let axes = |k: VoxelKey| -> (i32, i32) {
        match view {
            View::Side => (k.x, k.z),
            View::Top | View::Slice { .. } => (k.x, k.y),
        }
    };
    let config = map.measure_config();
    let cells = || {
        map.cells()
            .filter(move |(k, _)| layer.is_none_or(|z| k.z == z))
    };
    let Some((lo, hi)) = cells().fold(None, |acc: Option<((i32, i32), (i32, i32))>, (k, _)| {
        let (a, b) = axes(k);
        Some(match acc {
            None => ((a, b), (a, b)),
            Some((lo, hi)) => ((lo.0.min(a), lo.1.min(b)), (hi.0.max(a), hi.1.max(b))),
        })
    }) else {
        return Err(Error::Empty(match view {
            View::Slice { .. } => "map slice at this height",
            _ => "map",
        }));
    };
    let columns = (i64::from(hi.0) - i64::from(lo.0) + 1) as u64;
    let rows = (i64::from(hi.1) - i64::from(lo.1) + 1) as u64;
    let side = columns.max(rows) * u64::from(scale);
    if side > u64::from(MAX_VIEW_SIDE) {
        return Err(Error::InvalidParameter {
            name: "view size in pixels",
            value: side as f64,
            expected: "at most 16384 pixels per side: export a coarser map or a slice",
        });
    }
    let (columns, rows) = (columns as usize, rows as usize);
    let mut pixels: Vec<Option<Measures>> = vec![None; columns * rows];
    for (key, m) in cells() {
        let (a, b) = axes(key);
        let i = (b - lo.1) as usize * columns + (a - lo.0) as usize;
        let m = config.measures(m);
        if let Some(pixel) = pixels.get_mut(i) {
            *pixel = Some(match *pixel {
                None => m,
                Some(old) => combine(old, m, color),
            });
        }
    }
    let image =
        image::RgbImage::from_fn((columns as u32) * scale, (rows as u32) * scale, |x, y| {
            let (a, b) = ((x / scale) as usize, rows - 1 - (y / scale) as usize);
            image::Rgb(match pixels.get(b * columns + a).copied().flatten() {
                None => [255, 255, 255],
                Some(m) => match color {
                    ViewColor::Class => class_color(m.class),
                    ViewColor::Occupied => ramp(m.occupied),
                    ViewColor::Free => ramp(m.free),
                    ViewColor::Ambiguity => ramp(m.ambiguity),
                    ViewColor::Safety => ramp(m.safety),
                },
            })
        });
    Ok(image)
}

/// Renders a view (see [`render_view`]) and saves it as a PNG at `path`, atomically. Returns
/// the image's width and height.
pub fn write_view_png(
    map: &dyn VoxelMap,
    view: View,
    color: ViewColor,
    scale: u32,
    path: &Path,
) -> Result<(u32, u32)> {
    let image = render_view(map, view, color, scale)?;
    let mut bytes = Vec::new();
    image::DynamicImage::ImageRgb8(image.clone())
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(e),
        })?;
    super::write_atomic(path, &bytes)?;
    Ok(image.dimensions())
}

/// Which of two voxels of a column the projection keeps.
fn combine(a: Measures, b: Measures, color: ViewColor) -> Measures {
    let keep_a = match color {
        ViewColor::Class => rank(a.class) <= rank(b.class),
        ViewColor::Occupied => a.occupied >= b.occupied,
        ViewColor::Free => a.free >= b.free,
        ViewColor::Ambiguity => a.ambiguity >= b.ambiguity,
        ViewColor::Safety => a.safety <= b.safety,
    };
    if keep_a { a } else { b }
}

/// How critical a class is in a projection (lower first).
fn rank(class: VoxelClass) -> u8 {
    match class {
        VoxelClass::Occupied => 0,
        VoxelClass::Ambiguous => 1,
        VoxelClass::Free => 2,
        VoxelClass::Unknown => 3,
    }
}

/// A dark blue → teal → yellow ramp for a value in `[0, 1]` (clamped).
fn ramp(value: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 3] = [
        [30.0, 30.0, 120.0],
        [30.0, 150.0, 140.0],
        [250.0, 220.0, 40.0],
    ];
    let s = 2.0 * value.clamp(0.0, 1.0);
    let [low, middle, high] = STOPS;
    let (a, b, f) = if s < 1.0 {
        (low, middle, s)
    } else {
        (middle, high, s - 1.0)
    };
    let mut out = [0u8; 3];
    for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
        *o = (a + (b - a) * f).round() as u8;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{IntegrationOptions, PointCloud};
    use crate::map::VoxelMapMut;
    use crate::map::{FuzzyConfig, FuzzyMap, VoxelMap};
    use nalgebra::Point3;

    /// A vertical wall at x = 2 m, y in [0, 1), z in [0, 0.5), seen from (0, 0.5, 0.25).
    fn wall() -> FuzzyMap {
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        let points = (0..10)
            .flat_map(|i| (0..5).map(move |j| (i, j)))
            .map(|(i, j)| Point3::new(2.05, 0.05 + 0.1 * f64::from(i), 0.05 + 0.1 * f64::from(j)))
            .collect();
        let cloud = PointCloud::new(Point3::new(0.05, 0.55, 0.25), points).unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        map
    }

    #[test]
    fn top_view_shows_the_wall_as_an_occupied_column_line() {
        let map = wall();
        let image = render_view(&map, View::Top, ViewColor::Class, 1).unwrap();
        // x from 0 to 2.1 m (21 columns), y from 0 to 1 m (10 rows).
        assert_eq!(image.dimensions(), (21, 10));
        let occupied = class_color(VoxelClass::Occupied);
        for y in 0..10 {
            assert_eq!(image.get_pixel(20, y).0, occupied, "wall column, row {y}");
            assert_ne!(image.get_pixel(10, y).0, occupied);
        }
        assert_eq!(image.get_pixel(5, 5).0, class_color(VoxelClass::Free));
    }

    #[test]
    fn side_view_and_slices_and_measures() {
        let map = wall();
        let side = render_view(&map, View::Side, ViewColor::Class, 2).unwrap();
        assert_eq!(side.dimensions(), (42, 10));
        // A slice at the wall's height holds the same line; one above the scene is empty.
        let slice = render_view(&map, View::Slice { z: 0.25 }, ViewColor::Class, 1).unwrap();
        assert_eq!(slice.get_pixel(20, 0).0, class_color(VoxelClass::Occupied));
        assert!(matches!(
            render_view(&map, View::Slice { z: 5.0 }, ViewColor::Class, 1),
            Err(Error::Empty(_))
        ));
        // Safety is high in front of the wall and low on it.
        let safety = render_view(&map, View::Slice { z: 0.25 }, ViewColor::Safety, 1).unwrap();
        let (wall_px, open_px) = (safety.get_pixel(20, 5).0, safety.get_pixel(10, 5).0);
        assert_eq!(wall_px, ramp(0.0));
        let open = map.measures_at(VoxelKey::new(10, 4, 2));
        assert!(open.safety > 0.2, "{open:?}");
        assert_eq!(open_px, ramp(open.safety));
    }

    #[test]
    fn bad_requests_are_errors() {
        let map = wall();
        assert!(render_view(&map, View::Top, ViewColor::Class, 0).is_err());
        assert!(render_view(&map, View::Slice { z: f64::NAN }, ViewColor::Class, 1).is_err());
        let empty = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        assert!(render_view(&empty, View::Top, ViewColor::Class, 1).is_err());
        let path = std::path::Path::new("/nonexistent-dir/view.png");
        assert!(write_view_png(&map, View::Top, ViewColor::Class, 1, path).is_err());
    }
}
