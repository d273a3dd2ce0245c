//! What `rgbd` and `mono` share: the maps under test, built from the same depth images, and
//! their check against held-out frames of sensor depth (ray casting, `within_2_voxels`).

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::{Args, ValueEnum};
use fuzzyvox::eval::{DepthCheckConfig, DepthErrors};
use fuzzyvox::{AnyMap, DepthFrame, Family, IntegrationOptions};
use serde_json::{Value, json};
use tracing::{debug, info};

use super::maps::{Evidence, Model, PriorArgs, new_map};

/// Which maps a command builds (`--model`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Choice {
    Fuzzy,
    Logodds,
    Alpha,
    All,
}

/// The options of the maps under test and of their check against held-out frames.
#[derive(Args)]
pub struct MapCheckArgs {
    /// Voxel size in metres.
    #[arg(long, allow_negative_numbers = true)]
    pub res: f64,
    /// Which maps to build and check, comma-separated, or all three.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "all")]
    pub model: Vec<Choice>,
    /// Hold out every K-th frame (the K-th, 2K-th, ...); the others build the maps.
    #[arg(long, default_value_t = 5)]
    pub holdout: usize,
    /// Check every N-th pixel in both directions of the held-out frames (1: every pixel).
    #[arg(long, default_value_t = 1)]
    pub pixel_step: u32,
    /// Cast rays this far (metres); pixels measured farther are not checked.
    #[arg(long, default_value_t = 8.0, allow_negative_numbers = true)]
    pub cast_range: f64,
    /// Let ambiguous voxels stop rays too (by default only occupied voxels do; log-odds maps
    /// have no ambiguous voxels).
    #[arg(long)]
    pub stop_at_ambiguous: bool,
    /// Aggregation t-conorm of the fuzzy model as NAME[:PARAM] (see `insert --help`).
    #[arg(long, default_value = "product")]
    pub op: String,
    /// Number of confidence cuts of the alpha model.
    #[arg(long, default_value_t = 10)]
    pub cuts: u32,
    #[command(flatten)]
    pub prior: PriorArgs,
}

impl MapCheckArgs {
    /// The models asked for, in the order reports list them (log-odds, alpha, fuzzy).
    pub fn models(&self) -> Vec<Model> {
        Model::ALL
            .into_iter()
            .filter(|m| {
                self.model.iter().any(|c| match c {
                    Choice::Fuzzy => *m == Model::Fuzzy,
                    Choice::Logodds => *m == Model::Logodds,
                    Choice::Alpha => *m == Model::Alpha,
                    Choice::All => true,
                })
            })
            .collect()
    }

    /// The ray-casting check's settings.
    pub fn check(&self) -> anyhow::Result<DepthCheckConfig> {
        DepthCheckConfig {
            pixel_step: self.pixel_step,
            max_range: self.cast_range,
            stop_at_ambiguous: self.stop_at_ambiguous,
        }
        .validate()
        .context("--pixel-step / --cast-range")
    }

    /// The operator, checked against the models.
    pub fn family(&self) -> anyhow::Result<Family> {
        let family: Family = self.op.parse().context("--op")?;
        if !self.models().contains(&Model::Fuzzy) && self.op != "product" {
            anyhow::bail!("--op applies to the fuzzy model only");
        }
        self.prior.check_models(&self.models())?;
        Ok(family)
    }

    /// A new, empty map per model asked for (the fuzzy one with its prior, when given).
    pub fn maps(&self, family: Family) -> anyhow::Result<Vec<MapUnderTest>> {
        self.models()
            .into_iter()
            .map(|model| {
                let mut map = new_map(model, self.res, family, Evidence::Dual, self.cuts)?;
                self.prior.apply(&mut map)?;
                Ok(MapUnderTest {
                    model,
                    map,
                    build: Duration::ZERO,
                    predict: Duration::ZERO,
                    errors: DepthErrors::default(),
                })
            })
            .collect()
    }
}

/// One map under test, with its timings and its errors on held-out frames.
pub struct MapUnderTest {
    pub model: Model,
    pub map: AnyMap,
    pub build: Duration,
    pub predict: Duration,
    pub errors: DepthErrors,
}

/// Integrates one depth image into every map, timing each; `label` names it in errors.
pub fn integrate_all(
    maps: &mut [MapUnderTest],
    frame: &DepthFrame,
    options: &IntegrationOptions,
    label: &str,
) -> anyhow::Result<()> {
    for entry in maps {
        let started = Instant::now();
        let stats = entry
            .map
            .as_map_mut()
            .integrate_depth(frame, options)
            .with_context(|| format!("integrating {label}"))?;
        entry.build += started.elapsed();
        debug!(
            "{label} into the {} map: {} pixels, {} voxels updated",
            entry.map.kind().name(),
            stats.integrated,
            stats.voxels_updated
        );
    }
    Ok(())
}

/// Casts every map into one held-out frame of sensor depth and records the errors.
pub fn check_all(
    maps: &mut [MapUnderTest],
    frame: &DepthFrame,
    check: &DepthCheckConfig,
    label: &str,
) -> anyhow::Result<()> {
    for entry in maps {
        let started = Instant::now();
        entry
            .errors
            .add_frame(entry.map.as_map(), frame, check)
            .with_context(|| format!("checking {label}"))?;
        entry.predict += started.elapsed();
    }
    Ok(())
}

/// Saves every map as `DIR/MODEL.fvx`.
pub fn save_all(maps: &[MapUnderTest], dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for entry in maps {
        let path = dir.join(format!("{}.fvx", entry.map.kind().name()));
        entry
            .map
            .save(&path)
            .with_context(|| format!("saving {}", path.display()))?;
        info!("saved {}", path.display());
    }
    Ok(())
}

/// One JSON report per map.
pub fn reports(maps: &[MapUnderTest], family: Family, resolution: f64) -> Vec<Value> {
    maps.iter()
        .map(|entry| {
            let view = entry.map.as_map();
            let counts = view.counts();
            let summary = entry.errors.summary(resolution);
            json!({
                "model": entry.map.kind().name(),
                "operator": (entry.model == Model::Fuzzy).then(|| family.to_string()),
                "build_seconds": entry.build.as_secs_f64(),
                "predict_seconds": entry.predict.as_secs_f64(),
                "occupied": counts.occupied,
                "free": counts.free,
                "ambiguous": counts.ambiguous,
                "unknown": counts.unknown,
                "memory_bytes": view.memory_bytes(),
                "valid_pixels": summary.valid_pixels,
                "predicted_pixels": summary.predicted_pixels,
                "predicted": summary.predicted,
                "median_abs_depth_error_m": summary.median_abs_depth_error_m,
                "median_depth_error_m": summary.median_depth_error_m,
                "within_2_voxels": summary.within_2_voxels,
                "too_near": summary.too_near,
                "too_far": summary.too_far,
            })
        })
        .collect()
}

/// The reports as a table on standard output.
pub fn print_table(reports: &[Value]) {
    println!(
        "{:<8} {:>8} {:>10} {:>10} {:>15} {:>10} {:>9} {:>9} {:>9}",
        "model",
        "build s",
        "predict s",
        "predicted",
        "median error m",
        "within 2v",
        "too near",
        "too far",
        "occupied"
    );
    for r in reports {
        println!(
            "{:<8} {:>8.2} {:>10.2} {:>10.3} {:>15.4} {:>10.3} {:>9.3} {:>9.3} {:>9}",
            r["model"].as_str().unwrap_or("?"),
            r["build_seconds"].as_f64().unwrap_or(f64::NAN),
            r["predict_seconds"].as_f64().unwrap_or(f64::NAN),
            r["predicted"].as_f64().unwrap_or(f64::NAN),
            r["median_abs_depth_error_m"].as_f64().unwrap_or(f64::NAN),
            r["within_2_voxels"].as_f64().unwrap_or(f64::NAN),
            r["too_near"].as_f64().unwrap_or(f64::NAN),
            r["too_far"].as_f64().unwrap_or(f64::NAN),
            r["occupied"].as_u64().unwrap_or(0),
        );
    }
}
