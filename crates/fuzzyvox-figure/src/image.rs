//! Images of per-pixel values (depth, disparity, confidence, errors) as figures: each panel has
//! its title and a colour bar with the value range in its units; pixels without a value are
//! black and the legend says so.

use ::image::RgbImage;
use fuzzyvox_core::error::{Error, Result};
use plotters::prelude::*;

use super::font::{self, FAMILY};
use super::frame::{draw_title, figure_error, rgb, tick};
use super::palette::{NO_VALUE, viridis};

/// One panel: a plane of values and how to colour it.
#[derive(Clone, Debug)]
pub struct ImagePanel<'a> {
    /// The panel's title.
    pub title: String,
    /// Row-major values, `width × height`; non-finite values are drawn black ("no value").
    pub values: &'a [f32],
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// What the colour bar measures, with its unit (`depth (m)`, `disparity (px)`,
    /// `confidence`).
    pub unit: String,
    /// The values at the two ends of the colour map; values outside are clamped.
    pub range: [f64; 2],
    /// Grey levels instead of viridis (for camera images).
    pub grey: bool,
}

impl ImagePanel<'_> {
    /// A range over the finite values: from the smallest to the 98th percentile (a wide
    /// default when there is none).
    pub fn robust_range(values: &[f32]) -> [f64; 2] {
        let mut finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if finite.is_empty() {
            return [0.0, 1.0];
        }
        finite.sort_by(f32::total_cmp);
        let lo = f64::from(finite[0]);
        let hi = f64::from(finite[(finite.len() - 1) * 98 / 100]);
        if hi > lo { [lo, hi] } else { [lo, lo + 1.0] }
    }

    fn colour(&self, value: f32) -> [u8; 3] {
        if !value.is_finite() {
            return NO_VALUE;
        }
        let span = (self.range[1] - self.range[0]).max(1e-12);
        let t = ((f64::from(value) - self.range[0]) / span).clamp(0.0, 1.0);
        if self.grey {
            [(t * 255.0).round() as u8; 3]
        } else {
            viridis(t)
        }
    }
}

const TITLE_HEIGHT: u32 = 44;
const PANEL_TITLE: u32 = 26;
const BAR_HEIGHT: u32 = 54;
const GAP: u32 = 16;

/// Draws `panels` in a grid of `columns`, under `title`. Each panel is scaled by a whole factor
/// so that the figure is at least 800 pixels wide; all panels must have the same size.
pub fn image_figure(title: &str, panels: &[ImagePanel], columns: usize) -> Result<RgbImage> {
    let Some(first) = panels.first() else {
        return Err(Error::Empty("figure panels"));
    };
    let (w, h) = (first.width, first.height);
    for p in panels {
        if p.width != w || p.height != h || p.values.len() != (w as usize) * (h as usize) {
            return Err(Error::SizeMismatch {
                what: "figure panel pixels",
                expected: (w as usize) * (h as usize),
                found: p.values.len(),
            });
        }
        if !p.range.iter().all(|v| v.is_finite()) {
            return Err(Error::Figure(format!(
                "panel {} has no finite range",
                p.title
            )));
        }
    }
    if w == 0 || h == 0 {
        return Err(Error::Empty("figure panel"));
    }
    let columns = columns.clamp(1, panels.len()) as u32;
    let rows = (panels.len() as u32).div_ceil(columns);
    let k = (super::MIN_LONG_SIDE / columns).div_ceil(w).clamp(1, 8);
    let cell_w = (w * k).max(240);
    let cell_h = PANEL_TITLE + h * k + BAR_HEIGHT;
    let width = GAP + columns * (cell_w + GAP);
    let height = TITLE_HEIGHT + rows * (cell_h + GAP) + 24;
    font::ensure();
    let mut buffer = vec![255u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        draw_title(&top, title)?;
        let style = (FAMILY, 15).into_font();
        for (i, panel) in panels.iter().enumerate() {
            let (cx, cy) = (
                (GAP + (i as u32 % columns) * (cell_w + GAP)) as i32,
                ((i as u32 / columns) * (cell_h + GAP)) as i32,
            );
            body.draw(&Text::new(panel.title.clone(), (cx, cy + 2), style.clone()))
                .map_err(figure_error)?;
            let mut pixels = Vec::with_capacity((w * k * h * k * 3) as usize);
            for y in 0..h * k {
                for x in 0..w * k {
                    let v = panel.values[((y / k) * w + x / k) as usize];
                    pixels.extend_from_slice(&panel.colour(v));
                }
            }
            let image_y = cy + PANEL_TITLE as i32;
            let bitmap = BitMapElement::with_owned_buffer((cx, image_y), (w * k, h * k), pixels)
                .ok_or_else(|| Error::Figure("panel pixels do not fit".into()))?;
            body.draw(&bitmap).map_err(figure_error)?;
            // The colour bar under the image, its range in the panel's units.
            let bar_y = image_y + (h * k) as i32 + 8;
            let bar_w = (cell_w.min(w * k).max(200) - 10) as i32;
            for x in 0..bar_w {
                let t = f64::from(x) / f64::from(bar_w - 1);
                let c = if panel.grey {
                    [(t * 255.0).round() as u8; 3]
                } else {
                    viridis(t)
                };
                body.draw(&Rectangle::new(
                    [(cx + x, bar_y), (cx + x + 1, bar_y + 12)],
                    rgb(c).filled(),
                ))
                .map_err(figure_error)?;
            }
            body.draw(&Rectangle::new(
                [(cx - 1, bar_y - 1), (cx + bar_w, bar_y + 13)],
                BLACK.stroke_width(1),
            ))
            .map_err(figure_error)?;
            let labels = format!(
                "{} … {}  {}",
                tick(panel.range[0]),
                tick(panel.range[1]),
                panel.unit
            );
            body.draw(&Text::new(
                labels,
                (cx, bar_y + 16),
                (FAMILY, 14).into_font(),
            ))
            .map_err(figure_error)?;
        }
        body.draw(&Rectangle::new(
            [
                (GAP as i32, (height - TITLE_HEIGHT - 22) as i32),
                (GAP as i32 + 14, (height - TITLE_HEIGHT - 8) as i32),
            ],
            rgb(NO_VALUE).filled(),
        ))
        .map_err(figure_error)?;
        body.draw(&Text::new(
            "no value".to_string(),
            (GAP as i32 + 22, (height - TITLE_HEIGHT - 23) as i32),
            (FAMILY, 14).into_font(),
        ))
        .map_err(figure_error)?;
        root.present().map_err(figure_error)?;
    }
    RgbImage::from_raw(width, height, buffer)
        .ok_or_else(|| Error::Figure("the figure's buffer has the wrong size".into()))
}
