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

/// Free-space soundness of one group of pixels: how often the true surface lies in front of the
/// depth up to which the dual evidence model clears (`P- - δ`, and the profile's ends at half
/// and all of the way to `P0`).
#[derive(Default)]
struct Soundness {
    pixels: usize,
    without_far: usize,
    before_near: usize,
    before_half: usize,
    before_depth: usize,
}

impl Soundness {
    fn add(&mut self, near: f32, depth: f32, far: f32, truth: f32, delta: f32) {
        self.pixels += 1;
        self.without_far += usize::from(!far.is_finite());
        self.before_near += usize::from(truth < near - delta);
        self.before_half += usize::from(truth < near + 0.5 * (depth - near) - delta);
        self.before_depth += usize::from(truth < depth - delta);
    }

    fn row(&self, label: &str) {
        if self.pixels == 0 {
            return;
        }
        let share = |n: usize| 100.0 * n as f64 / self.pixels as f64;
        println!(
            "| {label} | {} | {:.1} % | {:.2} % | {:.2} % | {:.2} % |",
            self.pixels,
            share(self.without_far),
            share(self.before_near),
            share(self.before_half),
            share(self.before_depth)
        );
    }
}

/// Prints one soundness table: the first half of `groups` holds rectified pixels, the second
/// half plane-swept ones, each half by the bins `bins` (low, high).
fn soundness_table(by: &str, groups: &[Soundness], bins: &[(f64, f64)], digits: usize) {
    println!(
        "\n| matching, {by} | pixels with P- and P0 | without P+ | truth before P- - δ | before the half-way profile end | before P0 - δ |"
    );
    println!("|---|---|---|---|---|---|");
    for (group, s) in groups.iter().enumerate() {
        let (low, high) = bins[group % bins.len()];
        let method = if group < bins.len() {
            "rectified"
        } else {
            "plane sweep"
        };
        s.row(&format!(
            "{method}, {low:.digits$}–{:.digits$}",
            high.min(1.0)
        ));
    }
}

/// Bins `[0, e0), [e0, e1), …` from their upper ends.
fn from_ends(ends: &[f64]) -> Vec<(f64, f64)> {
    ends.iter()
        .enumerate()
        .map(|(i, &high)| (if i == 0 { 0.0 } else { ends[i - 1] }, high))
        .collect()
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
    // Pixels that see a surface within the range, and pixels the depth stage gave a depth.
    let (mut surface_pixels, mut matched_pixels) = (0usize, 0usize);
    // Per rectified pair: its Q_ABD and the median |disparity error| over its pixels.
    let mut by_quality: Vec<(f64, f32)> = Vec::new();
    // |P0 - truth| on the ground (world z below 0.1 m) and on everything else.
    let (mut ground, mut other_surfaces) = (Vec::new(), Vec::new());
    // Free-space soundness by how the pair was matched and its Q_ABD.
    const QUALITY_BINS: [(f64, f64); 4] = [(0.0, 0.3), (0.3, 0.6), (0.6, 0.9), (0.9, 1.01)];
    let mut soundness: Vec<Soundness> = (0..8).map(|_| Soundness::default()).collect();
    let delta = 0.5 * 3f32.sqrt() * voxel;
    // The same by each pixel's own parallax: the sine of the angle between its ray and the
    // baseline.
    const SINE_BINS: [f64; 6] = [0.05, 0.1, 0.2, 0.4, 0.7, 1.01];
    let mut by_sine: Vec<Soundness> = (0..12).map(|_| Soundness::default()).collect();
    // And by the best match's window cost (a fraction of the largest).
    const COST_BINS: [f32; 6] = [0.05, 0.1, 0.15, 0.2, 0.3, 1.01];
    let mut by_cost: Vec<Soundness> = (0..12).map(|_| Soundness::default()).collect();
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
        surface_pixels += truth
            .depth
            .iter()
            .filter(|z| **z <= scenario.max_range as f32)
            .count();
        matched_pixels += image.depth().iter().filter(|z| z.is_finite()).count();
        let rectified = result.method == MatchMethod::Rectified;
        let mut disparity_errors = Vec::new();
        let group = 4 * usize::from(!rectified)
            + QUALITY_BINS
                .iter()
                .position(|(low, high)| (*low..*high).contains(&result.quality))
                .unwrap_or(0);
        for (i, &z) in image.depth().iter().enumerate() {
            if !z.is_finite() {
                continue;
            }
            let true_z = truth.depth.get(i).copied().unwrap_or(f32::INFINITY);
            soundness[group].add(image.near()[i], z, image.far()[i], true_z, delta);
            {
                let (u, v) = (
                    (i % truth.width as usize) as f64,
                    (i / truth.width as usize) as f64,
                );
                let ray = out.world_from_camera().rotation
                    * out.intrinsics().back_project(u, v, 1.0).coords;
                let baseline = other.translation.vector - reference.translation.vector;
                let sine = ray.cross(&baseline).norm() / (ray.norm() * baseline.norm());
                let bin = SINE_BINS.iter().position(|&end| sine < end).unwrap_or(5);
                by_sine[6 * usize::from(!rectified) + bin].add(
                    image.near()[i],
                    z,
                    image.far()[i],
                    true_z,
                    delta,
                );
                let cost = result.disparity.cost[i];
                let bin = COST_BINS.iter().position(|&end| cost < end).unwrap_or(5);
                by_cost[6 * usize::from(!rectified) + bin].add(
                    image.near()[i],
                    z,
                    image.far()[i],
                    true_z,
                    delta,
                );
            }
            if !true_z.is_finite() {
                depth_in_sky += 1;
                continue;
            }
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
        "pixels seeing a surface within {} m: {surface_pixels}; pixels with a depth: {matched_pixels} ({:.1} %)",
        scenario.max_range,
        100.0 * matched_pixels as f64 / surface_pixels.max(1) as f64
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
    soundness_table("pair Q_ABD", &soundness, &QUALITY_BINS, 1);
    soundness_table("pixel parallax sine", &by_sine, &from_ends(&SINE_BINS), 2);
    let cost_ends: Vec<f64> = COST_BINS.iter().map(|&e| f64::from(e)).collect();
    soundness_table("best window cost", &by_cost, &from_ends(&cost_ends), 2);
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
