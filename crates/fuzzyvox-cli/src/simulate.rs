use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use fuzzyvox::eval::{GroundTruth, gold_standard};
use fuzzyvox::sim::export::write_frames;

use super::eval::ScenarioName;

/// Render one of the paper's scenarios to disk: every stereo pair's two views as frames in the
/// RGB-D folder layout (grayscale image, true depth as 16-bit millimetres, pose), `pairs.txt`,
/// the camera, and the ground truth (the gold-standard map and the truly occupied voxels).
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox simulate --scenario wall --out sim-wall\n  \
    fuzzyvox simulate --scenario random --pairs 50 --seed 3 --out sim-random\n  \
    fuzzyvox rgbd --dir sim-wall --res 0.1      # map the true depth like a real RGB-D camera")]
pub struct SimulateArgs {
    /// Which scenario.
    #[arg(long, value_enum)]
    scenario: ScenarioName,
    /// Stereo pairs of the random flight (the wall scenario always has 12).
    #[arg(long, default_value_t = 100)]
    pairs: usize,
    /// Seed of the random flight and of the sensor noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Voxel size of the ground truth, metres.
    #[arg(long, default_value_t = 0.2)]
    res: f64,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Print a summary as one JSON object.
    #[arg(long)]
    json: bool,
}

pub fn run(args: SimulateArgs) -> anyhow::Result<()> {
    if args.pairs == 0 {
        anyhow::bail!("--pairs must be at least 1");
    }
    let started = Instant::now();
    let scenario = args.scenario.build(args.pairs, args.seed)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let bar = super::progress::bar(scenario.pairs.len() as u64, "rendering", args.json);
    let frames = write_frames(&args.out, &scenario, args.seed, &mut |done, _| {
        bar.set_position(done as u64);
    })
    .with_context(|| format!("writing frames to {}", args.out.display()))?;
    bar.finish_and_clear();
    let spinner = super::progress::spinner("ground truth", args.json);
    let references: Vec<_> = scenario.pairs.iter().map(|p| p.0).collect();
    let gold = gold_standard(
        &scenario.scene,
        &scenario.intrinsics,
        &references,
        args.res,
        scenario.max_range,
    )?;
    let truth = GroundTruth::from_scene(&scenario.scene, &gold);
    spinner.finish_and_clear();
    gold.save(args.out.join("gold.fvx"))?;
    let mut occupied: Vec<_> = truth.occupied().collect();
    occupied.sort_unstable();
    let mut xyz = String::new();
    for key in &occupied {
        let c = truth.resolution().center(*key);
        let _ = writeln!(xyz, "{:.4} {:.4} {:.4}", c.x, c.y, c.z);
    }
    fuzzyvox::io::write_atomic(&args.out.join("truth-occupied.xyz"), xyz.as_bytes())?;
    let summary = serde_json::json!({
        "scenario": scenario.name,
        "pairs": scenario.pairs.len(),
        "frames": frames,
        "seed": args.seed,
        "resolution": args.res,
        "max_range": scenario.max_range,
        "phases": scenario.phases.iter().map(|(name, r)| serde_json::json!({
            "name": name, "first_pair": r.start, "pairs": r.len()
        })).collect::<Vec<_>>(),
        "truth_occupied": occupied.len(),
        "observed_voxels": truth.observed_count(),
        "seconds": started.elapsed().as_secs_f64(),
    });
    fuzzyvox::io::write_atomic(
        &args.out.join("scenario.json"),
        serde_json::to_string_pretty(&summary)?.as_bytes(),
    )?;
    if args.json {
        return super::print_json(&summary);
    }
    println!(
        "{} scenario: wrote {frames} frames of {} pairs, gold.fvx and {} truly occupied voxels \
         (truth-occupied.xyz) to {} in {:.1} s",
        scenario.name,
        scenario.pairs.len(),
        occupied.len(),
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
