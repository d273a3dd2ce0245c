//! The report's figures, drawn with [`fuzzyvox_figure`]: top-down views of the occupied voxels
//! (with or without free space), planned flights over a map, and the depth stage's images of
//! one pair, each with its title, axes in metres, scale bar and legend.

use std::path::Path;

use nalgebra::Point3;

use super::experiment::DepthSample;
use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_figure::palette::{PATH_COLLIDES, PATH_OK};
use fuzzyvox_figure::{
    ImagePanel, Overlay, View, ViewColor, ViewSpec, image_figure, save_png, view_figure,
};

/// The part of the world a top-down view shows: the x/y box `[min, max]` (metres) and the
/// heights `[low, high]` that the colour map spans; voxels whose centre lies below `low` (the
/// ground) are left out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TopDownView {
    /// South-west corner (x, y), metres.
    pub min: [f64; 2],
    /// North-east corner (x, y), metres.
    pub max: [f64; 2],
    /// Heights at the two ends of the colour map, metres.
    pub heights: [f64; 2],
}

impl TopDownView {
    fn spec(&self, show_free: bool) -> ViewSpec {
        ViewSpec {
            view: View::Top,
            color: ViewColor::Height,
            window: Some([[self.min[0], self.max[0]], [self.min[1], self.max[1]]]),
            floor: Some(self.heights[0]),
            heights: Some(self.heights),
            show_free,
        }
    }
}

/// Writes a top-down figure of `map` titled `title`: occupied voxel columns coloured by the
/// height of their highest occupied voxel (viridis); with `show_free`, columns with free voxels
/// and nothing occupied in the free colour; the rest unknown grey.
pub fn top_down_png(
    map: &dyn VoxelMap,
    view: &TopDownView,
    show_free: bool,
    title: &str,
    path: &Path,
) -> Result<()> {
    save_png(
        &view_figure(map, &view.spec(show_free), title, Vec::new(), 1)?,
        path,
    )
}

/// Writes a top-down figure of `map` (occupied only) with flight paths drawn over it: each
/// path as its waypoint polyline, red when it meets the true geometry, blue otherwise, its
/// start marked by a dot.
pub fn flights_png(
    map: &dyn VoxelMap,
    view: &TopDownView,
    paths: &[(&[Point3<f64>], bool)],
    title: &str,
    path: &Path,
) -> Result<()> {
    let overlays = paths
        .iter()
        .map(|(waypoints, collides)| Overlay {
            points: waypoints.iter().map(|p| [p.x, p.y]).collect(),
            color: if *collides { PATH_COLLIDES } else { PATH_OK },
            mark_start: true,
        })
        .collect();
    save_png(
        &view_figure(map, &view.spec(false), title, overlays, 1)?,
        path,
    )
}

/// Writes the depth stage's images of one pair as a 4 × 2 grid of panels, each with a colour
/// bar in its units: top row the rendered image, the true depth, the error `|P0 - truth|` (0 to
/// 2 m) and the confidence (0 to 1); bottom row `P-`, `P0`, `P+` and the interval width
/// `P+ - P-` (0 to 10 m). Depths share one range, from 0 to the 98th percentile of the true
/// depth; pixels without a value are black.
pub fn depth_panels_png(sample: &DepthSample, title: &str, path: &Path) -> Result<()> {
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
    let top = ImagePanel::robust_range(&truth.depth)[1].max(1e-3);
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
    let panel = |title: &str, values, unit: &str, range: [f64; 2], grey| ImagePanel {
        title: title.into(),
        values,
        width: w,
        height: h,
        unit: unit.into(),
        range,
        grey,
    };
    let depth = [0.0, top];
    let panels = [
        panel("image", &truth.image[..], "intensity", [0.0, 1.0], true),
        panel("true depth", &truth.depth[..], "m", depth, false),
        panel("error |P0 - truth|", &error[..], "m", [0.0, 2.0], false),
        panel("confidence C(p)", image.confidence(), "", [0.0, 1.0], false),
        panel("near bound P-", image.near(), "m", depth, false),
        panel("depth P0", image.depth(), "m", depth, false),
        panel("far bound P+", image.far(), "m", depth, false),
        panel(
            "interval width P+ - P-",
            &width[..],
            "m",
            [0.0, 10.0],
            false,
        ),
    ];
    save_png(&image_figure(title, &panels, 4)?, path)
}
