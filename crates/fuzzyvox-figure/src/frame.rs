//! A map figure people can read: a title, the map drawn to scale in a plot with axes in metres,
//! a scale bar, paths drawn over it, and a legend (the class colours, or a colour bar with the
//! measure's range).

use fuzzyvox_core::error::{Error, Result};
use image::RgbImage;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::font::{self, FAMILY};
use super::palette;

/// The long side of a figure's plot, at least (pixels).
pub const MIN_LONG_SIDE: u32 = 800;
/// The long side of a figure's plot, at most (pixels).
pub const MAX_PLOT_SIDE: u32 = 16_384;

const TITLE_HEIGHT: u32 = 44;
const Y_LABEL_WIDTH: u32 = 78;
const X_LABEL_HEIGHT: u32 = 52;
const MARGIN: u32 = 16;
/// Width of the legend column on the right of the plot.
pub const LEGEND_WIDTH: u32 = 210;
const LEGEND_MIN_HEIGHT: u32 = 300;

/// What the legend shows.
#[derive(Clone, Debug, PartialEq)]
pub enum Legend {
    /// One swatch per entry: a name and its colour.
    Swatches {
        /// The legend's heading.
        heading: String,
        /// Name and colour of each entry, top to bottom.
        entries: Vec<(String, [u8; 3])>,
    },
    /// A vertical viridis colour bar from `range[0]` (bottom) to `range[1]` (top), labelled in
    /// the measure's units.
    ColorBar {
        /// The measure and its unit, e.g. `height (m)` or `safety`.
        label: String,
        /// The values at the two ends of the colour map.
        range: [f64; 2],
        /// Extra entries under the bar (for example unknown space, or a path colour).
        extra: Vec<(String, [u8; 3])>,
    },
}

/// A polyline drawn over the map, in the plot's coordinates (metres).
#[derive(Clone, Debug, PartialEq)]
pub struct Overlay {
    /// Points of the line.
    pub points: Vec<[f64; 2]>,
    /// Its colour.
    pub color: [u8; 3],
    /// Whether its first point gets a dot (a flight's start).
    pub mark_start: bool,
}

/// A map raster framed as a figure.
#[derive(Clone, Debug)]
pub struct MapFigure<'a> {
    /// Title, drawn above the plot.
    pub title: String,
    /// One pixel per map cell, row 0 at the top (the largest vertical coordinate).
    pub raster: &'a RgbImage,
    /// The raster's extent in metres: `[[left, right], [bottom, top]]`.
    pub extent: [[f64; 2]; 2],
    /// The axis names with their unit, e.g. `["x (m)", "y (m)"]`.
    pub axes: [String; 2],
    /// The legend.
    pub legend: Legend,
    /// Lines drawn over the map.
    pub overlays: Vec<Overlay>,
    /// Pixels per cell at least; the figure enlarges it until the plot's long side reaches
    /// [`MIN_LONG_SIDE`].
    pub pixels_per_cell: u32,
}

impl MapFigure<'_> {
    /// Draws the figure.
    pub fn render(&self) -> Result<RgbImage> {
        let (columns, rows) = self.raster.dimensions();
        if columns == 0 || rows == 0 {
            return Err(Error::Empty("figure raster"));
        }
        let [[u0, u1], [v0, v1]] = self.extent;
        if ![u0, u1, v0, v1].iter().all(|v| v.is_finite()) || u1 <= u0 || v1 <= v0 {
            return Err(Error::Figure(format!(
                "the extent [{u0}, {u1}] x [{v0}, {v1}] is not a finite, non-empty box"
            )));
        }
        let long = columns.max(rows);
        let k = self
            .pixels_per_cell
            .max(MIN_LONG_SIDE.div_ceil(long))
            .min((MAX_PLOT_SIDE / long).max(1));
        let (plot_w, plot_h) = (columns * k, rows * k);
        let width = Y_LABEL_WIDTH + plot_w + MARGIN + LEGEND_WIDTH;
        let height = TITLE_HEIGHT + (plot_h + MARGIN + X_LABEL_HEIGHT).max(LEGEND_MIN_HEIGHT);
        font::ensure();
        let mut buffer = vec![255u8; width as usize * height as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
            let (top, body) = root.split_vertically(TITLE_HEIGHT);
            draw_title(&top, &self.title)?;
            let (left, legend) = body.split_horizontally(Y_LABEL_WIDTH + plot_w + MARGIN);
            let (chart_area, _) = left.split_vertically(plot_h + MARGIN + X_LABEL_HEIGHT);
            let mut chart = ChartBuilder::on(&chart_area)
                .margin_top(MARGIN)
                .margin_right(MARGIN)
                .x_label_area_size(X_LABEL_HEIGHT)
                .y_label_area_size(Y_LABEL_WIDTH)
                .build_cartesian_2d(u0..u1, v0..v1)
                .map_err(figure_error)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(self.axes[0].as_str())
                .y_desc(self.axes[1].as_str())
                .x_labels(8)
                .y_labels(8)
                .x_label_formatter(&|v| metres(*v))
                .y_label_formatter(&|v| metres(*v))
                .label_style((FAMILY, 14))
                .axis_desc_style((FAMILY, 15))
                .draw()
                .map_err(figure_error)?;
            let (w, h) = chart.plotting_area().dim_in_pixel();
            let pixels = resample(self.raster, w, h);
            let bitmap = BitMapElement::with_owned_buffer((u0, v1), (w, h), pixels)
                .ok_or_else(|| Error::Figure("the plot's pixels do not fit".into()))?;
            chart
                .draw_series(std::iter::once(bitmap))
                .map_err(figure_error)?;
            for overlay in &self.overlays {
                let color = rgb(overlay.color);
                chart
                    .draw_series(LineSeries::new(
                        overlay.points.iter().map(|p| (p[0], p[1])),
                        color.stroke_width(2),
                    ))
                    .map_err(figure_error)?;
                if let Some(p) = overlay.points.first().filter(|_| overlay.mark_start) {
                    chart
                        .draw_series(std::iter::once(Circle::new(
                            (p[0], p[1]),
                            4,
                            color.filled(),
                        )))
                        .map_err(figure_error)?;
                }
            }
            draw_scale_bar(&chart.plotting_area().strip_coord_spec(), u1 - u0, w)?;
            chart
                .plotting_area()
                .draw(&Rectangle::new([(u0, v0), (u1, v1)], BLACK.stroke_width(1)))
                .map_err(figure_error)?;
            draw_legend(&legend, &self.legend)?;
            root.present().map_err(figure_error)?;
        }
        RgbImage::from_raw(width, height, buffer)
            .ok_or_else(|| Error::Figure("the figure's buffer has the wrong size".into()))
    }
}

/// The title, left-aligned above the plot.
pub(crate) fn draw_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<()> {
    area.draw(&Text::new(
        title.to_string(),
        (16, 12),
        (FAMILY, 22).into_font().color(&BLACK),
    ))
    .map_err(figure_error)
}

/// A scale bar in the plot's bottom-left corner: the longest 1, 2 or 5 × 10ⁿ metres that
/// fits in a quarter of the plot, labelled.
fn draw_scale_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    width_m: f64,
    width_px: u32,
) -> Result<()> {
    let length = nice_length(width_m / 4.0);
    let px = ((length / width_m) * f64::from(width_px)).round().max(1.0) as i32;
    let (_, h) = area.dim_in_pixel();
    let (x, y) = (14, h as i32 - 16);
    let label = format!("{} m", metres(length));
    area.draw(&Rectangle::new(
        [(x - 8, y - 30), (x + px.max(60) + 8, y + 8)],
        WHITE.mix(0.85).filled(),
    ))
    .map_err(figure_error)?;
    area.draw(&Rectangle::new([(x, y - 6), (x + px, y)], BLACK.filled()))
        .map_err(figure_error)?;
    area.draw(&Text::new(label, (x, y - 26), (FAMILY, 15).into_font()))
        .map_err(figure_error)
}

/// The longest `1, 2 or 5 × 10ⁿ` not above `at_most` (positive).
pub fn nice_length(at_most: f64) -> f64 {
    let at_most = at_most.max(1e-9);
    let power = 10f64.powf(at_most.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * power)
        .find(|l| *l <= at_most * (1.0 + 1e-9))
        .unwrap_or(power)
}

/// The legend column: a heading, then swatches or a colour bar.
pub(crate) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    legend: &Legend,
) -> Result<()> {
    let heading_style = (FAMILY, 17).into_font();
    let style = (FAMILY, 15).into_font();
    let (x, mut y) = (8, MARGIN as i32);
    let swatches = |area: &DrawingArea<DB, Shift>, entries: &[(String, [u8; 3])], mut y: i32| {
        for (name, colour) in entries {
            area.draw(&Rectangle::new(
                [(x, y), (x + 20, y + 18)],
                rgb(*colour).filled(),
            ))
            .map_err(figure_error)?;
            area.draw(&Rectangle::new(
                [(x, y), (x + 20, y + 18)],
                BLACK.stroke_width(1),
            ))
            .map_err(figure_error)?;
            area.draw(&Text::new(name.clone(), (x + 30, y + 1), style.clone()))
                .map_err(figure_error)?;
            y += 28;
        }
        Ok::<i32, Error>(y)
    };
    match legend {
        Legend::Swatches { heading, entries } => {
            area.draw(&Text::new(heading.clone(), (x, y), heading_style.clone()))
                .map_err(figure_error)?;
            swatches(area, entries, y + 32)?;
        }
        Legend::ColorBar {
            label,
            range,
            extra,
        } => {
            area.draw(&Text::new(label.clone(), (x, y), heading_style.clone()))
                .map_err(figure_error)?;
            y += 34;
            let bar = 180;
            for row in 0..bar {
                let t = 1.0 - f64::from(row) / f64::from(bar - 1);
                area.draw(&Rectangle::new(
                    [(x, y + row), (x + 24, y + row + 1)],
                    rgb(palette::viridis(t)).filled(),
                ))
                .map_err(figure_error)?;
            }
            // The frame lies just outside the bar, so that both ends of the colour map show.
            area.draw(&Rectangle::new(
                [(x - 1, y - 1), (x + 25, y + bar)],
                BLACK.stroke_width(1),
            ))
            .map_err(figure_error)?;
            for value in bar_ticks(*range) {
                let t = (value - range[0]) / (range[1] - range[0]);
                let ty = y + ((1.0 - t) * f64::from(bar - 1)) as i32;
                area.draw(&PathElement::new(vec![(x + 24, ty), (x + 30, ty)], BLACK))
                    .map_err(figure_error)?;
                area.draw(&Text::new(tick(value), (x + 34, ty - 8), style.clone()))
                    .map_err(figure_error)?;
            }
            swatches(area, extra, y + bar + 20)?;
        }
    }
    Ok(())
}

/// The values labelled on a colour bar over `range`: its two ends, and the round values
/// (multiples of 1, 2 or 5 × 10ⁿ, about three of them) between them that are not too close to
/// an end.
pub fn bar_ticks(range: [f64; 2]) -> Vec<f64> {
    let [lo, hi] = range;
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return vec![lo];
    }
    let step = nice_length((hi - lo) / 3.0);
    let mut ticks = vec![lo];
    let mut k = (lo / step).ceil();
    while k * step < hi {
        let value = k * step;
        if value - lo > 0.4 * step && hi - value > 0.4 * step {
            ticks.push(value);
        }
        k += 1.0;
    }
    ticks.push(hi);
    ticks
}

/// A tick label: at most three decimals, no trailing zeros.
pub fn tick(value: f64) -> String {
    let text = format!("{value:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// Metres for axis labels and the scale bar (same rule as [`tick`]).
fn metres(value: f64) -> String {
    tick(value)
}

/// Nearest-neighbour resampling of `image` to `w × h`, as raw RGB bytes.
fn resample(image: &RgbImage, w: u32, h: u32) -> Vec<u8> {
    let (iw, ih) = image.dimensions();
    let mut out = Vec::with_capacity(w as usize * h as usize * 3);
    for y in 0..h {
        let sy = (u64::from(y) * u64::from(ih) / u64::from(h.max(1))) as u32;
        for x in 0..w {
            let sx = (u64::from(x) * u64::from(iw) / u64::from(w.max(1))) as u32;
            out.extend_from_slice(&image.get_pixel(sx.min(iw - 1), sy.min(ih - 1)).0);
        }
    }
    out
}

pub(crate) fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

pub(crate) fn figure_error<E: std::error::Error + Send + Sync>(e: E) -> Error {
    Error::Figure(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_bars_label_their_ends_and_round_values() {
        let close = |range: [f64; 2], expected: &[f64]| {
            let ticks = bar_ticks(range);
            assert_eq!(ticks.len(), expected.len(), "{ticks:?}");
            for (t, e) in ticks.iter().zip(expected) {
                assert!((t - e).abs() < 1e-12, "{ticks:?}");
            }
        };
        close([0.3, 8.0], &[0.3, 2.0, 4.0, 6.0, 8.0]);
        close([0.0, 1.0], &[0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        close([-1.07, 10.18], &[-1.07, 0.0, 2.0, 4.0, 6.0, 8.0, 10.18]);
        close([1.0, 1.0], &[1.0]);
    }

    #[test]
    fn scale_bars_have_round_lengths() {
        assert_eq!(nice_length(2.6), 2.0);
        assert_eq!(nice_length(0.74), 0.5);
        assert_eq!(nice_length(10.0), 10.0);
        assert_eq!(nice_length(0.019), 0.01);
        assert_eq!(tick(0.5), "0.5");
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(-0.0001), "0");
    }
}
