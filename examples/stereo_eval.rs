//! Matches the Middlebury motorcycle pair and prints accuracy and time (a development aid; the
//! CLI's `fuzzyvox stereo` does the same with more options).
//!
//! Run: `cargo run --release --example stereo_eval -- DIR [NDISP WINDOW LR UNIQUENESS RUNS]`,
//! e.g. `-- ../shared/data/middlebury-motorcycle 80 9 1 10 20` (the defaults; `LR` 0 turns the
//! left-right check off).

use std::path::PathBuf;

use fuzzyvox::depth::{DepthParams, depth_from_rectified, evaluate};
use fuzzyvox::io::middlebury::read_middlebury;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(
        args.next()
            .unwrap_or_else(|| "../shared/data/middlebury-motorcycle".into()),
    );
    let ndisp: u32 = args.next().map_or(Ok(80), |s| s.parse())?;
    let window: u32 = args.next().map_or(Ok(9), |s| s.parse())?;
    let lr: u32 = args.next().map_or(Ok(1), |s| s.parse())?;
    let uniqueness: u32 = args.next().map_or(Ok(10), |s| s.parse())?;
    let runs: usize = args.next().map_or(Ok(10), |s| s.parse())?;
    let pair = read_middlebury(&dir)?;
    let geometry = pair.calib.geometry()?;
    let mut params = DepthParams::default();
    params.matching.num_disparities = ndisp;
    params.matching.window_width = window;
    params.matching.window_height = window;
    params.matching.left_right_tolerance = (lr > 0).then_some(lr);
    params.matching.uniqueness_ratio = uniqueness;
    let mut best = f64::INFINITY;
    let mut result = None;
    for _ in 0..runs {
        let r = depth_from_rectified(&pair.left, &pair.right, &geometry, 1.0, &params)?;
        best = best.min(r.matching_seconds);
        result = Some(r);
    }
    let result = result.ok_or("no run")?;
    let truth = pair.ground_truth.ok_or("no ground truth")?;
    let accuracy = evaluate(
        &result.disparity.disparity,
        &truth.data,
        Some(result.frame.image().confidence()),
    )?;
    println!("best of {runs}: {:.2} ms", best * 1e3);
    println!("{accuracy:?}");
    Ok(())
}
