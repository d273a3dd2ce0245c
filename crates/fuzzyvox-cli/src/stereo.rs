use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use fuzzyvox::depth::{
    Accuracy, DepthParams, GrayImage, IntervalMethod, depth_from_rectified, evaluate,
};
use fuzzyvox::figure::{ImagePanel, image_figure, save_png};
use fuzzyvox::io::middlebury::read_calib;
use fuzzyvox::io::pfm::{read_pfm, write_pfm};
use fuzzyvox::io::read_gray_image;
use serde_json::json;

/// Match a rectified stereo pair into disparity, interval depth and confidence.
///
/// `left(y, x)` must match `right(y, x - d)`; depth is `Z = baseline · f / (d + doffs)` from a
/// Middlebury `calib.txt`. With ground truth (`--gt`, or `disp0GT.pfm` in a `--middlebury`
/// folder) it reports accuracy: density and bad-1 / bad-2 over pixels with ground truth.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox stereo --middlebury ../shared/data/middlebury-motorcycle --ndisp 80 --repeat 20 --json\n  \
    fuzzyvox stereo --left im0.png --right im1.png --calib calib.txt --out depth/\n  \
    fuzzyvox stereo --middlebury DIR --interval fixed --delta 1 --out depth/ --json")]
#[command(group(clap::ArgGroup::new("calibration").required(true).args(["calib", "middlebury"])))]
pub struct StereoArgs {
    /// Left (reference) image; default `im0.png` of `--middlebury`.
    #[arg(long)]
    left: Option<PathBuf>,
    /// Right image; default `im1.png` of `--middlebury`.
    #[arg(long)]
    right: Option<PathBuf>,
    /// Calibration in Middlebury's `calib.txt` format.
    #[arg(long)]
    calib: Option<PathBuf>,
    /// A Middlebury folder (`im0.png`, `im1.png`, `calib.txt`, optional `disp0GT.pfm`).
    #[arg(long)]
    middlebury: Option<PathBuf>,
    /// Number of disparities searched (default: the calibration's `ndisp`).
    #[arg(long)]
    ndisp: Option<u32>,
    /// Smallest disparity searched.
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    min_disparity: i32,
    /// Aggregation window side (odd, up to 15).
    #[arg(long, default_value_t = 9)]
    window: u32,
    /// How P- and P+ are formed: the paper's fixed ±δ, or the cost-curve range widened by δ.
    #[arg(long, value_enum, default_value_t = Interval::Curve)]
    interval: Interval,
    /// δ in pixels.
    #[arg(long, default_value_t = 1.0)]
    delta: f32,
    /// Ground-truth disparity (PFM, non-finite = unknown).
    #[arg(long)]
    gt: Option<PathBuf>,
    /// Write disparity, depth, near, far and confidence as PFM and colour PNG here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Match this many times and report the fastest matching time (the first run also pays for
    /// starting threads and touching fresh memory).
    #[arg(long, default_value_t = 1)]
    repeat: u32,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Interval {
    Fixed,
    Curve,
}

pub fn run(args: StereoArgs) -> anyhow::Result<()> {
    let folder = args.middlebury.as_deref();
    let pick = |given: &Option<PathBuf>, name: &str| -> anyhow::Result<PathBuf> {
        match (given, folder) {
            (Some(path), _) => Ok(path.clone()),
            (None, Some(dir)) => Ok(dir.join(name)),
            (None, None) => bail!(
                "--{} is required without --middlebury",
                name.trim_end_matches(".png")
            ),
        }
    };
    let left_path = pick(&args.left, "im0.png")?;
    let right_path = pick(&args.right, "im1.png")?;
    let calib_path = pick(&args.calib, "calib.txt")?;
    let calib = read_calib(&calib_path)?;
    let left = read_gray_image(&left_path)?;
    let right = read_gray_image(&right_path)?;
    let geometry = calib.geometry()?;
    if left.width() != calib.width || left.height() != calib.height {
        bail!(
            "{} is {}×{}, the calibration says {}×{}",
            left_path.display(),
            left.width(),
            left.height(),
            calib.width,
            calib.height
        );
    }
    let gt_path = args
        .gt
        .clone()
        .or_else(|| folder.map(|d| d.join("disp0GT.pfm")).filter(|p| p.exists()));
    let mut params = DepthParams::default();
    params.matching.num_disparities = args.ndisp.unwrap_or(calib.ndisp);
    params.matching.min_disparity = args.min_disparity;
    params.matching.window_width = args.window;
    params.matching.window_height = args.window;
    params.interval.method = match args.interval {
        Interval::Fixed => IntervalMethod::FixedDelta { delta: args.delta },
        Interval::Curve => IntervalMethod::CostCurve { delta: args.delta },
    };
    let runs = args.repeat.max(1);
    let bar = super::progress::bar(u64::from(runs), "matching", args.json);
    let mut result = depth_from_rectified(&left, &right, &geometry, 1.0, &params)?;
    let mut seconds = result.matching_seconds;
    bar.inc(1);
    for _ in 1..runs {
        result = depth_from_rectified(&left, &right, &geometry, 1.0, &params)?;
        seconds = seconds.min(result.matching_seconds);
        bar.inc(1);
    }
    bar.finish_and_clear();
    tracing::info!(
        "matched {}×{} in {:.1} ms (best of {runs})",
        left.width(),
        left.height(),
        seconds * 1e3
    );
    let disparity = &result.disparity;
    let image = result.frame.image();
    let accuracy: Option<Accuracy> = match &gt_path {
        Some(path) => {
            let truth = read_pfm(path)?;
            Some(
                evaluate(&disparity.disparity, &truth.data, Some(image.confidence()))
                    .with_context(|| format!("comparing with {}", path.display()))?,
            )
        }
        None => None,
    };
    if let Some(dir) = &args.out {
        write_outputs(dir, &left, disparity.disparity.as_slice(), image)?;
    }
    let density = accuracy.map_or(100.0 * disparity.density(), |a| a.density);
    if args.json {
        let a = accuracy.as_ref();
        return super::print_json(&json!({
            "width": disparity.width,
            "height": disparity.height,
            "disparities": params.matching.num_disparities,
            "min_disparity": params.matching.min_disparity,
            "seconds": seconds,
            "repeat": args.repeat.max(1),
            "threads": rayon::current_num_threads(),
            "density": density,
            "bad1_matched": a.map(|a| a.bad1_matched),
            "bad2_matched": a.map(|a| a.bad2_matched),
            "bad2_all": a.map(|a| a.bad2_all),
            "bad2_top50_confidence": a.map(|a| a.bad2_top50_confidence),
            "ground_truth": gt_path,
            "out": args.out,
        }));
    }
    println!(
        "matched {}×{} over {} disparities in {:.1} ms ({} threads, best of {}): density {density:.1}%",
        disparity.width,
        disparity.height,
        params.matching.num_disparities,
        seconds * 1e3,
        rayon::current_num_threads(),
        args.repeat.max(1),
    );
    if let Some(a) = accuracy {
        println!(
            "bad-1 (matched) {:.1}%, bad-2 (matched) {:.1}%, bad-2 (all) {:.1}%, bad-2 (top 50% confidence) {:.1}%",
            a.bad1_matched, a.bad2_matched, a.bad2_all, a.bad2_top50_confidence
        );
    }
    if let Some(dir) = &args.out {
        println!(
            "wrote disparity, depth, near, far and confidence (.pfm, .png) to {}",
            dir.display()
        );
    }
    Ok(())
}

fn write_outputs(
    dir: &Path,
    left: &GrayImage,
    disparity: &[f32],
    image: &fuzzyvox::IntervalDepthImage,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let (w, h) = (left.width(), left.height());
    let planes: [(&str, &[f32]); 5] = [
        ("disparity", disparity),
        ("depth", image.depth()),
        ("near", image.near()),
        ("far", image.far()),
        ("confidence", image.confidence()),
    ];
    for (name, plane) in planes {
        write_pfm(&dir.join(format!("{name}.pfm")), w, h, plane)?;
        let png = dir.join(format!("{name}.png"));
        let (unit, range) = match name {
            "confidence" => ("confidence", [0.0, 1.0]),
            "disparity" => ("px", ImagePanel::robust_range(plane)),
            _ => ("m", ImagePanel::robust_range(image.depth())),
        };
        let panel = ImagePanel {
            title: format!("{name} ({w} × {h} pixels)"),
            values: plane,
            width: w,
            height: h,
            unit: unit.into(),
            range,
            grey: false,
        };
        let figure = image_figure(&format!("fuzzyvox stereo: {name}"), &[panel], 1)
            .with_context(|| format!("drawing {}", png.display()))?;
        save_png(&figure, &png).with_context(|| format!("writing {}", png.display()))?;
    }
    Ok(())
}
