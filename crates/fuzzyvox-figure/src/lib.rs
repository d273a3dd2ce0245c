//! Figures people can read without opening the code: every PNG has a title, a legend and, for
//! maps, axes in metres and a scale bar; measures use the viridis colour map and classes the
//! same colours everywhere ([`palette`]); text uses a font bundled in the binary ([`font`]).
//!
//! - [`view`]: the map renderer (top, side, slice; by class, measure or height) and its framed
//!   figure;
//! - [`frame`]: the frame itself (title, axes, scale bar, legend, paths over the map);
//! - [`image`]: depth, disparity and confidence images with a colour bar in their units;
//! - [`chart`]: bar and line charts as SVG and PNG (map metrics, operators, depth accuracy
//!   against confidence).

pub mod chart;
pub mod font;
pub mod frame;
pub mod image;
pub mod palette;
pub mod view;

use std::path::Path;

pub use chart::{BarPanel, Chart, LinePanel, Panel};
pub use frame::{Legend, MIN_LONG_SIDE, MapFigure, Overlay};
use fuzzyvox_core::error::{Error, Result};
pub use image::{ImagePanel, image_figure};
pub use palette::{class_color, viridis};
pub use view::{
    MapRaster, View, ViewColor, ViewSpec, legend_for, rasterize, render_view, view_figure,
    write_view_png,
};

/// Encodes `figure` as PNG and writes it to `path` atomically (a failed write leaves no half
/// file).
pub fn save_png(figure: &::image::RgbImage, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    ::image::DynamicImage::ImageRgb8(figure.clone())
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            ::image::ImageFormat::Png,
        )
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(e),
        })?;
    fuzzyvox_core::file::write_atomic(path, &bytes)
}
