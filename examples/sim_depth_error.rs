//! How far the depth stage's output lies from the simulator's true depth, by range and by pair
//! quality: the measurement behind the random-flight figures in `docs/experiments.md`.
//!
//! Run: `cargo run --release --example sim_depth_error -- [random|wall] [PAIRS] [VOXEL] [VIEWS]`,
//! e.g. `-- random 100 0.2 2` (the defaults). Every pair is rendered and matched as
//! `fuzzyvox eval --views VIEWS` does (receding pairs by plane sweep; more than two views by the
//! multiple-baseline sweep); each pixel with a depth is compared with the true depth seen from
//! the same (rectified) camera, by true depth and by surface (the ground or anything else).

use fuzzyvox::depth::{DepthParams, ForwardMotion, MatchMethod, ViewWindow};
use fuzzyvox::sim::{render, scenario};

/// Upper ends of the true-depth bins, metres.
const RANGE_BINS: [f32; 6] = [5.0, 10.0, 20.0, 40.0, 60.0, f32::INFINITY];

#[derive(Default)]
struct RangeBin {
    pixels: usize,
    beyond_voxel: usize,
    truth_outside: usize,
    width: f64,
    confidence: f64,
}

fn median(values: &mut [f32]) -> f32 {
    values.sort_by(f32::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f32::NAN)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "random".into());
    let pairs: usize = args.next().map_or(Ok(100), |s| s.parse())?;
    let voxel: f32 = args.next().map_or(Ok(0.2), |s| s.parse())?;
    let mut window = ViewWindow::new(args.next().map_or(Ok(2), |s| s.parse())?)?;
    let scenario = match name.as_str() {
        "wall" => scenario::wall()?,
        "random" => scenario::random(pairs, 1)?,
        other => return Err(format!("unknown scenario {other:?}: wall or random").into()),
    };
    let mut params = DepthParams {
        forward_motion: ForwardMotion::PlaneSweep,
        ..DepthParams::default()
    };
    params.depth_range = Some((1.0, scenario.max_range));
    // Beyond this the renderer saw sky.
    let sky = (scenario.max_range * 4.0) as f32;

    let mut bins: Vec<RangeBin> = RANGE_BINS.iter().map(|_| RangeBin::default()).collect();
    let mut depth_in_sky = 0usize;
    // Per rectified pair: its Q_ABD and the median |disparity error| over its pixels.
    let mut by_quality: Vec<(f64, f32)> = Vec::new();
    // |P0 - truth| on the ground (world z below 0.1 m) and on everything else.
    let (mut ground, mut other_surfaces) = (Vec::new(), Vec::new());
    for (index, (reference, other)) in scenario.pairs.iter().enumerate() {
        if scenario.phases.iter().any(|(_, r)| r.start == index) {
            window.clear();
        }
        let Some(views) = scenario.render_pair(index, 1) else {
            continue;
        };
        let time = index as f64;
        let (a, b) = (
            views[0].to_frame(scenario.intrinsics, *reference, time)?,
            views[1].to_frame(scenario.intrinsics, *other, time)?,
        );
        let Ok(result) = window.depth(a, b, &params) else {
            continue;
        };
        let out = &result.frame;
        let truth = render(
            &scenario.scene,
            out.intrinsics(),
            out.world_from_camera(),
            1,
            f64::from(sky),
        );
        let image = out.image();
        let rectified = result.method == MatchMethod::Rectified;
        let mut disparity_errors = Vec::new();
        for (i, &z) in image.depth().iter().enumerate() {
            if !z.is_finite() {
                continue;
            }
            let Some(&true_z) = truth.depth.get(i).filter(|t| t.is_finite()) else {
                depth_in_sky += 1;
                continue;
            };
            let Some(bin) = RANGE_BINS.iter().position(|&end| true_z < end) else {
                continue;
            };
            let b = &mut bins[bin];
            b.pixels += 1;
            b.beyond_voxel += usize::from((z - true_z).abs() > voxel);
            let (near, far) = (image.near()[i], image.far()[i]);
            b.truth_outside += usize::from(!(near <= true_z && true_z <= far));
            if far.is_finite() {
                b.width += f64::from(far - near);
            }
            b.confidence += f64::from(image.confidence()[i]);
            let (u, v) = (i % truth.width as usize, i / truth.width as usize);
            let seen = out
                .intrinsics()
                .back_project(u as f64, v as f64, f64::from(true_z));
            let error = (z - true_z).abs();
            if (out.world_from_camera() * seen).z < 0.1 {
                ground.push(error);
            } else {
                other_surfaces.push(error);
            }
            if rectified {
                let d = result.disparity.disparity[i];
                let true_d = result.geometry.disparity(f64::from(true_z)) as f32;
                disparity_errors.push((d - true_d).abs());
            }
        }
        if !disparity_errors.is_empty() {
            by_quality.push((result.quality, median(&mut disparity_errors)));
        }
    }

    println!(
        "{name}, {} pairs, {} views, voxel {voxel} m; pixels with a depth where the truth is sky: {depth_in_sky}",
        scenario.pairs.len(),
        window.views()
    );
    println!(
        "| true depth | pixels | |P0 - truth| > voxel | truth outside [P-, P+] | mean width | mean confidence |"
    );
    println!("|---|---|---|---|---|---|");
    let mut start = 0.0;
    for (end, b) in RANGE_BINS.iter().zip(&bins) {
        if b.pixels > 0 {
            let n = b.pixels as f64;
            println!(
                "| {start}–{end} m | {} | {:.1} % | {:.1} % | {:.2} m | {:.2} |",
                b.pixels,
                100.0 * b.beyond_voxel as f64 / n,
                100.0 * b.truth_outside as f64 / n,
                b.width / n,
                b.confidence / n
            );
        }
        start = *end;
    }
    println!("\n| surface | pixels | |P0 - truth| > voxel | median |P0 - truth| |");
    println!("|---|---|---|---|");
    for (surface, errors) in [("ground", &mut ground), ("other", &mut other_surfaces)] {
        if !errors.is_empty() {
            let beyond = errors.iter().filter(|e| **e > voxel).count();
            println!(
                "| {surface} | {} | {:.1} % | {:.3} m |",
                errors.len(),
                100.0 * beyond as f64 / errors.len() as f64,
                median(errors)
            );
        }
    }
    println!("\n| pair Q_ABD | rectified pairs | median of their median |disparity error| |");
    println!("|---|---|---|");
    for (low, high) in [(0.0, 0.6), (0.6, 0.8), (0.8, 0.95), (0.95, 1.01)] {
        let mut medians: Vec<f32> = by_quality
            .iter()
            .filter(|(q, _)| (low..high).contains(q))
            .map(|(_, m)| *m)
            .collect();
        if !medians.is_empty() {
            let count = medians.len();
            println!(
                "| {low:.2}–{:.2} | {count} | {:.3} px |",
                high.min(1.0),
                median(&mut medians)
            );
        }
    }
    Ok(())
}
