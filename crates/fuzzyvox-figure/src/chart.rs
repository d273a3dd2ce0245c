//! Charts as SVG (for pages and papers) and PNG: a grid of panels, each a bar chart with one
//! bar per category (per map, per operator) or a line chart (accuracy against confidence).

use std::path::{Path, PathBuf};

use ::image::RgbImage;
use fuzzyvox_core::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::font::{self, FAMILY};
use super::frame::{draw_title, figure_error, rgb, tick};

/// Colours of categories, in order (a qualitative palette readable by most colour-blind
/// readers).
pub const CATEGORY_COLORS: [[u8; 3]; 8] = [
    [0, 114, 178],
    [230, 159, 0],
    [0, 158, 115],
    [204, 121, 167],
    [86, 180, 233],
    [213, 94, 0],
    [240, 228, 66],
    [100, 100, 100],
];

/// A bar chart panel: one bar per category of the chart.
#[derive(Clone, Debug, PartialEq)]
pub struct BarPanel {
    /// What the bars measure.
    pub title: String,
    /// One value per category; `None` draws no bar ("n/a").
    pub values: Vec<Option<f64>>,
    /// The value axis; `None` runs from 0 to a little above the largest value.
    pub range: Option<[f64; 2]>,
}

/// A line chart panel.
#[derive(Clone, Debug, PartialEq)]
pub struct LinePanel {
    /// What the lines show.
    pub title: String,
    /// Horizontal axis name with unit.
    pub x_label: String,
    /// The horizontal axis range.
    pub x_range: [f64; 2],
    /// The vertical axis range.
    pub y_range: [f64; 2],
    /// Each line: name, points.
    pub series: Vec<(String, Vec<(f64, f64)>)>,
}

/// One panel of a chart.
#[derive(Clone, Debug, PartialEq)]
pub enum Panel {
    /// Bars, one per category.
    Bars(BarPanel),
    /// Lines.
    Lines(LinePanel),
}

/// A chart: a title and a grid of panels.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// The chart's title.
    pub title: String,
    /// The bars' categories (map or operator names), in order; their colours follow
    /// [`CATEGORY_COLORS`].
    pub categories: Vec<String>,
    /// The panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
}

const PANEL_W: u32 = 440;
const PANEL_H: u32 = 330;
const TITLE_HEIGHT: u32 = 44;

impl Chart {
    /// The chart's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        let columns = self.columns.clamp(1, self.panels.len().max(1)) as u32;
        let rows = (self.panels.len().max(1) as u32).div_ceil(columns);
        (columns * PANEL_W, TITLE_HEIGHT + rows * PANEL_H)
    }

    /// The chart as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, self.size()).into_drawing_area();
            self.draw(&root)?;
            root.present().map_err(figure_error)?;
        }
        Ok(svg)
    }

    /// The chart as an image.
    pub fn to_png(&self) -> Result<RgbImage> {
        let (w, h) = self.size();
        let mut buffer = vec![255u8; w as usize * h as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut buffer, (w, h)).into_drawing_area();
            self.draw(&root)?;
            root.present().map_err(figure_error)?;
        }
        RgbImage::from_raw(w, h, buffer)
            .ok_or_else(|| Error::Figure("the chart's buffer has the wrong size".into()))
    }

    /// Writes `STEM.svg` and `STEM.png` (atomically) and returns their paths.
    pub fn save(&self, stem: &Path) -> Result<[PathBuf; 2]> {
        let svg = stem.with_extension("svg");
        let png = stem.with_extension("png");
        fuzzyvox_core::file::write_atomic(&svg, self.to_svg()?.as_bytes())?;
        super::save_png(&self.to_png()?, &png)?;
        Ok([svg, png])
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        font::ensure();
        if self.panels.is_empty() {
            return Err(Error::Empty("chart panels"));
        }
        root.fill(&WHITE).map_err(figure_error)?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        draw_title(&top, &self.title)?;
        let columns = self.columns.clamp(1, self.panels.len());
        let rows = self.panels.len().div_ceil(columns);
        let areas = body.split_evenly((rows, columns));
        for (panel, area) in self.panels.iter().zip(&areas) {
            match panel {
                Panel::Bars(bars) => self.draw_bars(area, bars)?,
                Panel::Lines(lines) => draw_lines(area, lines)?,
            }
        }
        Ok(())
    }

    fn draw_bars<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        panel: &BarPanel,
    ) -> Result<()> {
        let n = self.categories.len().max(1);
        if panel.values.len() != self.categories.len() {
            return Err(Error::SizeMismatch {
                what: "bar values",
                expected: self.categories.len(),
                found: panel.values.len(),
            });
        }
        let largest = panel
            .values
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        let [lo, hi] = panel
            .range
            .unwrap_or([0.0, if largest > 0.0 { largest * 1.15 } else { 1.0 }]);
        let categories = &self.categories;
        let mut chart = ChartBuilder::on(area)
            .caption(panel.title.as_str(), (FAMILY, 17))
            .margin(12)
            .x_label_area_size(46)
            .y_label_area_size(62)
            .build_cartesian_2d(-0.5f64..(n as f64 - 0.5), lo..hi)
            .map_err(figure_error)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .light_line_style(WHITE)
            .x_labels(n)
            .x_label_formatter(&|x| {
                let i = x.round();
                if (x - i).abs() < 1e-6 && i >= 0.0 {
                    categories.get(i as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .y_label_formatter(&|y| tick(*y))
            .label_style((FAMILY, 13))
            .draw()
            .map_err(figure_error)?;
        for (i, value) in panel.values.iter().enumerate() {
            let x = i as f64;
            let colour = rgb(CATEGORY_COLORS[i % CATEGORY_COLORS.len()]);
            match value.filter(|v| v.is_finite()) {
                Some(v) => {
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(x - 0.35, lo), (x + 0.35, v.clamp(lo, hi))],
                            colour.filled(),
                        )))
                        .map_err(figure_error)?;
                    chart
                        .draw_series(std::iter::once(Text::new(
                            value_label(v),
                            (x - 0.3, v.clamp(lo, hi) + (hi - lo) * 0.07),
                            (FAMILY, 13).into_font(),
                        )))
                        .map_err(figure_error)?;
                }
                None => {
                    chart
                        .draw_series(std::iter::once(Text::new(
                            "n/a".to_string(),
                            (x - 0.15, lo + (hi - lo) * 0.08),
                            (FAMILY, 13).into_font(),
                        )))
                        .map_err(figure_error)?;
                }
            }
        }
        Ok(())
    }
}

fn draw_lines<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, panel: &LinePanel) -> Result<()> {
    let [x0, x1] = panel.x_range;
    let [y0, y1] = panel.y_range;
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title.as_str(), (FAMILY, 17))
        .margin(12)
        .x_label_area_size(46)
        .y_label_area_size(62)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(figure_error)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .x_desc(panel.x_label.as_str())
        .x_label_formatter(&|x| tick(*x))
        .y_label_formatter(&|y| tick(*y))
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 14))
        .draw()
        .map_err(figure_error)?;
    for (i, (name, points)) in panel.series.iter().enumerate() {
        let colour = rgb(CATEGORY_COLORS[i % CATEGORY_COLORS.len()]);
        chart
            .draw_series(LineSeries::new(
                points.iter().copied(),
                colour.stroke_width(2),
            ))
            .map_err(figure_error)?
            .label(name.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(points.iter().map(|p| Circle::new(*p, 3, colour.filled())))
            .map_err(figure_error)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 13))
        .draw()
        .map_err(figure_error)?;
    Ok(())
}

/// A bar's value: whole numbers as they are, fractions with three decimals.
fn value_label(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v:.3}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> Chart {
        Chart {
            title: "maps".into(),
            categories: vec!["logodds".into(), "fuzzy".into()],
            panels: vec![
                Panel::Bars(BarPanel {
                    title: "holes".into(),
                    values: vec![Some(120.0), Some(3.0)],
                    range: None,
                }),
                Panel::Bars(BarPanel {
                    title: "flight success".into(),
                    values: vec![Some(0.8), None],
                    range: Some([0.0, 1.0]),
                }),
                Panel::Lines(LinePanel {
                    title: "error".into(),
                    x_label: "confidence".into(),
                    x_range: [0.0, 1.0],
                    y_range: [0.0, 0.5],
                    series: vec![("median".into(), vec![(0.1, 0.4), (0.9, 0.05)])],
                }),
            ],
            columns: 2,
        }
    }

    #[test]
    fn charts_draw_bars_in_their_category_colours_as_png_and_svg() {
        let c = chart();
        let png = c.to_png().unwrap();
        assert_eq!(png.dimensions(), c.size());
        let has = |colour: [u8; 3]| png.pixels().filter(|p| p.0 == colour).count();
        assert!(has(CATEGORY_COLORS[0]) > 500, "the first category's bars");
        assert!(has(CATEGORY_COLORS[1]) > 50, "the second category's bar");
        let svg = c.to_svg().unwrap();
        assert!(svg.starts_with("<svg"));
        for text in [
            "maps",
            "holes",
            "flight success",
            "logodds",
            "fuzzy",
            "n/a",
            "confidence",
        ] {
            assert!(svg.contains(text), "{text} in the SVG");
        }
    }

    #[test]
    fn mismatched_bars_are_an_error() {
        let mut c = chart();
        c.panels[0] = Panel::Bars(BarPanel {
            title: "holes".into(),
            values: vec![Some(1.0)],
            range: None,
        });
        assert!(matches!(c.to_png(), Err(Error::SizeMismatch { .. })));
        c.panels.clear();
        assert!(c.to_svg().is_err());
    }
}
