//! Figures people can read: the pixels of a framed map view and of an image figure hold a
//! title, a legend with the class colours or a viridis colour bar, a scale bar, and unknown
//! space distinct from the background.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::room_scan;
use fuzzyvox::figure::frame::LEGEND_WIDTH;
use fuzzyvox::figure::palette::{BACKGROUND, NO_VALUE, UNKNOWN};
use fuzzyvox::figure::{
    ImagePanel, MIN_LONG_SIDE, View, ViewColor, ViewSpec, class_color, image_figure, view_figure,
    viridis,
};
use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, VoxelClass, VoxelMapMut};
use image::RgbImage;
use nalgebra::Point3;

fn room() -> FuzzyMap {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
    map.integrate_cloud(
        &room_scan(Point3::new(0.5, -0.5, 1.0), 20_000, 3),
        &IntegrationOptions::default(),
    )
    .unwrap();
    map
}

/// Pixels of exactly `color` in columns `x0..x1`.
fn count(image: &RgbImage, color: [u8; 3], x0: u32, x1: u32) -> usize {
    image
        .enumerate_pixels()
        .filter(|(x, _, p)| (x0..x1).contains(x) && p.0 == color)
        .count()
}

/// Whether the image holds a solid black bar at least `min_len` pixels long and `rows` rows
/// thick (the scale bar; axis lines and the plot's frame are one pixel thick).
fn has_black_bar(image: &RgbImage, min_len: u32, rows: u32) -> bool {
    let (w, h) = image.dimensions();
    let black = |x: u32, y: u32| image.get_pixel(x, y).0 == [0, 0, 0];
    (0..h.saturating_sub(rows)).any(|y| {
        (0..w.saturating_sub(min_len))
            .any(|x| (0..rows).all(|dy| (0..min_len).all(|dx| black(x + dx, y + dy))))
    })
}

/// Dark (text) pixels in rows `y0..y1`.
fn dark_pixels(image: &RgbImage, y0: u32, y1: u32) -> usize {
    image
        .enumerate_pixels()
        .filter(|(_, y, p)| (y0..y1).contains(y) && p.0.iter().all(|c| *c < 110))
        .count()
}

#[test]
fn a_class_view_has_title_legend_scale_bar_and_grey_unknown() {
    let map = room();
    let mut spec = ViewSpec::new(View::Slice { z: 1.0 }, ViewColor::Class);
    spec.show_free = true;
    let figure = view_figure(&map, &spec, "room: slice at z = 1 m", Vec::new(), 1).unwrap();
    let (w, h) = figure.dimensions();
    assert!(w.max(h) >= MIN_LONG_SIDE, "{w} x {h}");
    let legend_x = w - LEGEND_WIDTH;
    // Every class has a swatch in the legend column, and the plot shows the classes it has.
    for class in VoxelClass::ALL {
        let swatch = count(&figure, class_color(class), legend_x, w);
        assert!(swatch >= 200, "{class:?}: {swatch} legend pixels");
    }
    for class in [VoxelClass::Occupied, VoxelClass::Free] {
        let plotted = count(&figure, class_color(class), 0, legend_x);
        assert!(plotted >= 1000, "{class:?}: {plotted} plot pixels");
    }
    assert_ne!(UNKNOWN, BACKGROUND, "unknown must not look like the page");
    assert!(has_black_bar(&figure, 40, 5), "no scale bar");
    assert!(dark_pixels(&figure, 0, 40) > 100, "no title");
    // Axis tick labels and names under the plot.
    assert!(dark_pixels(&figure, h - 50, h) > 100, "no x axis labels");
}

#[test]
fn a_measure_view_has_a_viridis_colour_bar() {
    let map = room();
    let spec = ViewSpec::new(View::Top, ViewColor::Height);
    let figure = view_figure(&map, &spec, "room: height", Vec::new(), 1).unwrap();
    let w = figure.width();
    let legend_x = w - LEGEND_WIDTH;
    for t in [0.0, 1.0] {
        let n = count(&figure, viridis(t), legend_x, w);
        assert!(n >= 10, "viridis({t}) appears {n} times in the colour bar");
    }
    let bar_colours: std::collections::BTreeSet<[u8; 3]> = figure
        .enumerate_pixels()
        .filter(|(x, _, _)| *x >= legend_x)
        .map(|(_, _, p)| p.0)
        .collect();
    assert!(
        bar_colours.len() > 100,
        "{} colours in the legend",
        bar_colours.len()
    );
    // The plot uses the colour map too.
    let plot_colours: std::collections::BTreeSet<[u8; 3]> = figure
        .enumerate_pixels()
        .filter(|(x, _, _)| *x < legend_x)
        .map(|(_, _, p)| p.0)
        .collect();
    assert!(plot_colours.len() > 50, "{} colours", plot_colours.len());
    assert!(has_black_bar(&figure, 40, 5), "no scale bar");
}

#[test]
fn image_figures_have_colour_bars_and_black_for_no_value() {
    let (width, height) = (64u32, 48u32);
    let depth: Vec<f32> = (0..width * height)
        .map(|i| {
            if i % 97 == 0 {
                f32::NAN
            } else {
                1.0 + (i % width) as f32 / 10.0
            }
        })
        .collect();
    let confidence: Vec<f32> = (0..width * height)
        .map(|i| (i / width) as f32 / height as f32)
        .collect();
    let panels = [
        ImagePanel {
            title: "depth".into(),
            values: &depth,
            width,
            height,
            unit: "depth (m)".into(),
            range: ImagePanel::robust_range(&depth),
            grey: false,
        },
        ImagePanel {
            title: "confidence".into(),
            values: &confidence,
            width,
            height,
            unit: "confidence".into(),
            range: [0.0, 1.0],
            grey: false,
        },
    ];
    let figure = image_figure("depth stage", &panels, 2).unwrap();
    assert!(figure.width() >= 800, "{}", figure.width());
    let all = figure.width();
    // Pixels without depth are black: the same figure without them has far fewer black pixels.
    let filled: Vec<f32> = depth
        .iter()
        .map(|d| if d.is_nan() { 1.0 } else { *d })
        .collect();
    let mut without = panels.clone();
    without[0].values = &filled;
    let without = image_figure("depth stage", &without, 2).unwrap();
    let extra = count(&figure, NO_VALUE, 0, all) - count(&without, NO_VALUE, 0, all);
    assert!(extra > 500, "{extra} more black pixels with missing depth");
    for t in [0.0, 1.0] {
        assert!(count(&figure, viridis(t), 0, all) > 50, "viridis({t})");
    }
    assert!(dark_pixels(&figure, 0, 40) > 100, "no title");
    // Panels of different sizes are refused.
    let small = [0.5f32; 4];
    let odd = ImagePanel {
        title: "odd".into(),
        values: &small,
        width: 2,
        height: 2,
        unit: "m".into(),
        range: [0.0, 1.0],
        grey: true,
    };
    assert!(image_figure("bad", &[panels[0].clone(), odd], 2).is_err());
}
