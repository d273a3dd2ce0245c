//! Views of a map: from the top, from the side, or a horizontal slice, coloured by class, by
//! one measure or by height. [`rasterize`] draws one pixel per voxel column; [`view_figure`]
//! frames that raster as a figure (title, axes in metres, scale bar, legend) at least
//! [`MIN_LONG_SIDE`](super::MIN_LONG_SIDE) pixels on its plot's long side. This is the one map
//! renderer: `export --png`, the demo's report and the examples all use it.
//!
//! A projection (top or side) shows, per column of voxels along the view direction, what a
//! planner most needs to know about that column:
//! - by class, the most critical class in it: occupied before ambiguous before free;
//! - by `occupied`, `free` or `ambiguity`, the largest value in the column;
//! - by `safety`, the smallest value over the column's observed voxels;
//! - by height, the height of its highest occupied voxel (columns with nothing occupied show
//!   free space in its class colour when asked, else unknown).
//!
//! Unobserved columns and voxels are light grey (the unknown class colour), distinct from the
//! figure's white background.

use std::path::Path;

use fuzzyvox_core::error::{Error, Result, finite};
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::{Measures, VoxelClass};
use fuzzyvox_core::storage::VoxelKey;
use image::RgbImage;

use super::frame::{Legend, MapFigure, Overlay};
use super::palette::{UNKNOWN, class_color, viridis};

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
    /// Occupied membership μO on the viridis colour map from 0 to 1.
    Occupied,
    /// Free membership μE, likewise.
    Free,
    /// Ambiguity, likewise.
    Ambiguity,
    /// Safety, likewise.
    Safety,
    /// The height (z, metres) of the highest occupied voxel, viridis over the view's height
    /// range.
    Height,
}

impl ViewColor {
    /// The measure's name in legends and titles.
    pub fn name(self) -> &'static str {
        match self {
            Self::Class => "class",
            Self::Occupied => "occupied membership",
            Self::Free => "free membership",
            Self::Ambiguity => "ambiguity",
            Self::Safety => "safety",
            Self::Height => "height (m)",
        }
    }
}

/// What a view shows, beyond its direction and colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSpec {
    /// Where the view looks from.
    pub view: View,
    /// What colours it.
    pub color: ViewColor,
    /// The part of the map shown, in metres along the image axes (`[[left, right], [bottom,
    /// top]]`); `None` spans the observed voxels.
    pub window: Option<[[f64; 2]; 2]>,
    /// Voxels whose centre lies below this height (the ground) are left out.
    pub floor: Option<f64>,
    /// The heights at the two ends of the colour map with [`ViewColor::Height`]; `None` spans
    /// the occupied voxels shown.
    pub heights: Option<[f64; 2]>,
    /// With [`ViewColor::Height`], whether columns with free voxels and nothing occupied show
    /// the free colour.
    pub show_free: bool,
}

impl ViewSpec {
    /// A view of the whole observed map.
    pub fn new(view: View, color: ViewColor) -> Self {
        Self {
            view,
            color,
            window: None,
            floor: None,
            heights: None,
            show_free: false,
        }
    }
}

/// A view's raster: one pixel per voxel column, and where it lies.
#[derive(Clone, Debug, PartialEq)]
pub struct MapRaster {
    /// The pixels, row 0 at the top.
    pub image: RgbImage,
    /// Its extent in metres: `[[left, right], [bottom, top]]`.
    pub extent: [[f64; 2]; 2],
    /// The image axes' names with unit.
    pub axes: [&'static str; 2],
    /// The values at the ends of the colour map (`[0, 1]` for a measure, the heights for
    /// height); `None` for classes.
    pub range: Option<[f64; 2]>,
}

/// Largest raster side in pixels, a guard against absurd extents.
pub const MAX_VIEW_SIDE: u32 = 16_384;

/// Renders a view of `map` as a bare raster, `scale` pixels per voxel (1 to 16), spanning the
/// observed voxels. [`write_view_png`] frames it as a figure.
///
/// ```
/// use fuzzyvox_figure::{View, ViewColor, render_view};
/// use fuzzyvox_core::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelMap, VoxelMapMut};
/// use nalgebra::Point3;
///
/// let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
/// let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(1.05, 0.05, 0.05)])?;
/// map.integrate_cloud(&cloud, &IntegrationOptions::default())?;
/// let image = render_view(&map, View::Top, ViewColor::Class, 1)?;
/// // The observed voxels run from x = 0 to 1.1 m: 11 columns, one row.
/// assert_eq!(image.dimensions(), (11, 1));
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
pub fn render_view(
    map: &dyn VoxelMap,
    view: View,
    color: ViewColor,
    scale: u32,
) -> Result<RgbImage> {
    check_scale(scale)?;
    let raster = rasterize(map, &ViewSpec::new(view, color))?;
    let (w, h) = raster.image.dimensions();
    if u64::from(w.max(h)) * u64::from(scale) > u64::from(MAX_VIEW_SIDE) {
        return Err(too_large(w.max(h), scale));
    }
    Ok(image::imageops::resize(
        &raster.image,
        w * scale,
        h * scale,
        image::imageops::FilterType::Nearest,
    ))
}

fn check_scale(scale: u32) -> Result<()> {
    if !(1..=16).contains(&scale) {
        return Err(Error::InvalidParameter {
            name: "scale",
            value: f64::from(scale),
            expected: "1 to 16 pixels per voxel",
        });
    }
    Ok(())
}

fn too_large(side: u32, scale: u32) -> Error {
    Error::InvalidParameter {
        name: "view size in pixels",
        value: f64::from(side) * f64::from(scale),
        expected: "at most 16384 pixels per side: export a coarser map or a slice",
    }
}

/// Draws one pixel per voxel column of the view `spec` of `map`.
pub fn rasterize(map: &dyn VoxelMap, spec: &ViewSpec) -> Result<MapRaster> {
    let resolution = map.resolution();
    let size = resolution.size();
    let layer = match spec.view {
        View::Slice { z } => {
            finite("slice height", z)?;
            let key = resolution.key_of(&nalgebra::Point3::new(0.0, 0.0, z))?;
            Some(key.z)
        }
        _ => None,
    };
    if let Some(floor) = spec.floor {
        finite("floor height", floor)?;
    }
    // Horizontal and vertical image axes of a voxel key.
    let view = spec.view;
    let axes_of = |k: VoxelKey| -> (i32, i32) {
        match view {
            View::Side => (k.x, k.z),
            View::Top | View::Slice { .. } => (k.x, k.y),
        }
    };
    let floor = spec.floor;
    let config = map.measure_config();
    let cells = || {
        map.cells().filter(move |(k, _)| {
            layer.is_none_or(|z| k.z == z) && floor.is_none_or(|f| resolution.center(*k).z >= f)
        })
    };
    let (lo, hi) = match spec.window {
        Some(window) => {
            for v in window.iter().flatten() {
                finite("view window", *v)?;
            }
            let index = |v: f64| (v / size).floor().clamp(-2e9, 2e9) as i32;
            let (lo, hi) = (
                (index(window[0][0]), index(window[1][0])),
                (
                    index(window[0][1] - 1e-9 * size),
                    index(window[1][1] - 1e-9 * size),
                ),
            );
            if hi.0 < lo.0 || hi.1 < lo.1 {
                return Err(Error::Empty("view window"));
            }
            (lo, hi)
        }
        None => cells()
            .fold(None, |acc: Option<((i32, i32), (i32, i32))>, (k, _)| {
                let (a, b) = axes_of(k);
                Some(match acc {
                    None => ((a, b), (a, b)),
                    Some((lo, hi)) => ((lo.0.min(a), lo.1.min(b)), (hi.0.max(a), hi.1.max(b))),
                })
            })
            .ok_or(Error::Empty(match spec.view {
                View::Slice { .. } => "map slice at this height",
                _ => "map",
            }))?,
    };
    let columns = (i64::from(hi.0) - i64::from(lo.0) + 1) as u64;
    let rows = (i64::from(hi.1) - i64::from(lo.1) + 1) as u64;
    if columns.max(rows) > u64::from(MAX_VIEW_SIDE) {
        return Err(too_large(columns.max(rows) as u32, 1));
    }
    let (columns, rows) = (columns as usize, rows as usize);
    let index = |k: VoxelKey| -> Option<usize> {
        let (a, b) = axes_of(k);
        let (u, v) = (
            i64::from(a) - i64::from(lo.0),
            i64::from(b) - i64::from(lo.1),
        );
        (u >= 0 && v >= 0 && (u as usize) < columns && (v as usize) < rows)
            .then(|| v as usize * columns + u as usize)
    };
    let image;
    let mut range = None;
    if spec.color == ViewColor::Height {
        let mut top: Vec<Option<i32>> = vec![None; columns * rows];
        let mut free = vec![false; columns * rows];
        for (key, m) in cells() {
            let Some(i) = index(key) else { continue };
            match config.classify(m) {
                VoxelClass::Occupied => top[i] = Some(top[i].map_or(key.z, |z| z.max(key.z))),
                VoxelClass::Free => free[i] = true,
                _ => {}
            }
        }
        let height = |z: i32| resolution.center(VoxelKey::new(0, 0, z)).z;
        let heights = spec.heights.unwrap_or_else(|| {
            let (a, b) = top
                .iter()
                .flatten()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
                    (a.min(height(*z)), b.max(height(*z)))
                });
            if a.is_finite() {
                [a, b.max(a + size)]
            } else {
                [0.0, 1.0]
            }
        });
        let span = (heights[1] - heights[0]).max(1e-9);
        range = Some(heights);
        image = RgbImage::from_fn(columns as u32, rows as u32, |x, y| {
            let i = (rows - 1 - y as usize) * columns + x as usize;
            image::Rgb(match top[i] {
                Some(z) => viridis((height(z) - heights[0]) / span),
                None if spec.show_free && free[i] => class_color(VoxelClass::Free),
                None => UNKNOWN,
            })
        });
    } else {
        let mut pixels: Vec<Option<Measures>> = vec![None; columns * rows];
        for (key, m) in cells() {
            let Some(i) = index(key) else { continue };
            let m = config.measures(m);
            pixels[i] = Some(match pixels[i] {
                None => m,
                Some(old) => combine(old, m, spec.color),
            });
        }
        if spec.color != ViewColor::Class {
            range = Some([0.0, 1.0]);
        }
        image = RgbImage::from_fn(columns as u32, rows as u32, |x, y| {
            let i = (rows - 1 - y as usize) * columns + x as usize;
            image::Rgb(match pixels[i] {
                None => UNKNOWN,
                Some(m) => match spec.color {
                    ViewColor::Class | ViewColor::Height => class_color(m.class),
                    ViewColor::Occupied => viridis(f64::from(m.occupied)),
                    ViewColor::Free => viridis(f64::from(m.free)),
                    ViewColor::Ambiguity => viridis(f64::from(m.ambiguity)),
                    ViewColor::Safety => viridis(f64::from(m.safety)),
                },
            })
        });
    }
    let edge = |i: i32| f64::from(i) * size;
    Ok(MapRaster {
        image,
        extent: [[edge(lo.0), edge(hi.0 + 1)], [edge(lo.1), edge(hi.1 + 1)]],
        axes: match spec.view {
            View::Side => ["x (m)", "z (m)"],
            _ => ["x (m)", "y (m)"],
        },
        range,
    })
}

/// The legend of a raster coloured by `color`.
pub fn legend_for(color: ViewColor, range: Option<[f64; 2]>, show_free: bool) -> Legend {
    let class = |c: VoxelClass| (c.name().to_string(), class_color(c));
    match (color, range) {
        (ViewColor::Class, _) | (_, None) => Legend::Swatches {
            heading: "class".into(),
            entries: VoxelClass::ALL.iter().map(|c| class(*c)).collect(),
        },
        (ViewColor::Height, Some(range)) => Legend::ColorBar {
            label: "occupied, height (m)".into(),
            range,
            extra: if show_free {
                vec![class(VoxelClass::Free), class(VoxelClass::Unknown)]
            } else {
                vec![("no occupied voxel".into(), UNKNOWN)]
            },
        },
        (color, Some(range)) => Legend::ColorBar {
            label: color.name().into(),
            range,
            extra: vec![("unobserved".into(), UNKNOWN)],
        },
    }
}

/// Draws the view `spec` of `map` as a figure titled `title`, with `overlays` drawn over it
/// and at least `scale` pixels per voxel.
pub fn view_figure(
    map: &dyn VoxelMap,
    spec: &ViewSpec,
    title: &str,
    overlays: Vec<Overlay>,
    scale: u32,
) -> Result<RgbImage> {
    check_scale(scale)?;
    let raster = rasterize(map, spec)?;
    let (w, h) = raster.image.dimensions();
    if u64::from(w.max(h)) * u64::from(scale) > u64::from(MAX_VIEW_SIDE) {
        return Err(too_large(w.max(h), scale));
    }
    MapFigure {
        title: title.to_string(),
        raster: &raster.image,
        extent: raster.extent,
        axes: raster.axes.map(String::from),
        legend: legend_for(spec.color, raster.range, spec.show_free),
        overlays,
        pixels_per_cell: scale,
    }
    .render()
}

/// Draws a view as a figure (see [`view_figure`]: title, axes in metres, scale bar, legend)
/// and saves it as a PNG at `path`, atomically. Returns the figure's width and height.
pub fn write_view_png(
    map: &dyn VoxelMap,
    view: View,
    color: ViewColor,
    scale: u32,
    path: &Path,
) -> Result<(u32, u32)> {
    let name = match view {
        View::Top => "top view".to_string(),
        View::Side => "side view".to_string(),
        View::Slice { z } => format!("slice at z = {z} m"),
    };
    let title = format!(
        "{name}, {} ({} m voxels)",
        color.name(),
        map.resolution().size()
    );
    let figure = view_figure(map, &ViewSpec::new(view, color), &title, Vec::new(), scale)?;
    super::save_png(&figure, path)?;
    Ok(figure.dimensions())
}

/// Which of two voxels of a column the projection keeps.
fn combine(a: Measures, b: Measures, color: ViewColor) -> Measures {
    let keep_a = match color {
        ViewColor::Class | ViewColor::Height => rank(a.class) <= rank(b.class),
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

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::integrate::{IntegrationOptions, PointCloud};
    use fuzzyvox_core::map::VoxelMapMut;
    use fuzzyvox_core::map::{FuzzyConfig, FuzzyMap, VoxelMap};
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
        assert_eq!(wall_px, viridis(0.0));
        let open = map.measures_at(VoxelKey::new(10, 4, 2));
        assert!(open.safety > 0.2, "{open:?}");
        assert_eq!(open_px, viridis(f64::from(open.safety)));
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
