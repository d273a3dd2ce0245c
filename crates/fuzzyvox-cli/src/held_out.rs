//! What `rgbd` and `mono` share: the options of the maps under test and of their check against
//! held-out frames of sensor depth, the progress bars of a run and its table.
//! The runs themselves are the library's (`fuzzyvox::eval::run_rgbd`, `run_mono`).

use anyhow::Context;
use clap::Args;
use fuzzyvox::eval::{HeldOutConfig, HeldOutStage, MapCheckReport, PriorMap};
use fuzzyvox::map::MapKind;
use fuzzyvox::{Error, Family};
use indicatif::ProgressBar;

use super::maps::{ModelArg, PriorArgs};
use super::progress;

/// The options of the maps under test and of their check against held-out frames.
#[derive(Args)]
pub struct MapCheckArgs {
    /// Voxel size in metres.
    #[arg(long, allow_negative_numbers = true)]
    pub res: f64,
    /// Which maps to build and check, comma-separated, or all three.
    #[arg(long, value_parser = ModelArg::parser(), value_delimiter = ',', default_value = "all")]
    pub model: Vec<ModelArg>,
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
    pub fn kinds(&self) -> Vec<MapKind> {
        MapKind::ALL
            .into_iter()
            .filter(|kind| self.model.iter().any(|m| m.includes(*kind)))
            .collect()
    }

    /// The library's settings, checked (errors name the flags).
    pub fn config(&self) -> anyhow::Result<HeldOutConfig> {
        let operator: Family = self.op.parse().context("--op")?;
        let models = self.kinds();
        if !models.contains(&MapKind::Fuzzy) && self.op != "product" {
            anyhow::bail!("--op applies to the fuzzy model only");
        }
        self.prior.check_models(&models)?;
        let config = HeldOutConfig {
            resolution: self.res,
            models,
            holdout: self.holdout,
            pixel_step: self.pixel_step,
            cast_range: self.cast_range,
            stop_at_ambiguous: self.stop_at_ambiguous,
            operator,
            cuts: self.cuts,
            evidence: HeldOutConfig::new(self.res).evidence,
            prior: self.prior.prior.clone().map(|path| PriorMap {
                path,
                confidence: self.prior.prior_confidence,
            }),
        };
        config.validate().map_err(flag_error)?;
        Ok(config)
    }
}

/// A library error, with the flag of the value it refuses when it names one.
pub fn flag_error(error: Error) -> anyhow::Error {
    let named = match &error {
        Error::InvalidParameter { name, value, .. } => Some((*name, *value)),
        Error::NonFinite { what, value } => Some((*what, *value)),
        _ => None,
    };
    let flag = named.and_then(|(name, value)| {
        let flag = match name {
            "resolution" => "res",
            "holdout" => "holdout",
            "pixel_step" => "pixel-step",
            "max_range" | "cast_range" => "cast-range",
            "cuts" => "cuts",
            "prior_confidence" | "prior confidence" => "prior-confidence",
            "views" => "views",
            "near" => "near",
            "far" => "far",
            "min_baseline" => "min-baseline",
            "min_agreeing" => "min-agreeing",
            "flights to plan" => "plan",
            "vehicle_radius" => "radius",
            _ => return None,
        };
        Some(format!("--{flag} {value}"))
    });
    match flag {
        Some(flag) => anyhow::Error::new(error).context(flag),
        None => error.into(),
    }
}

/// One progress bar per stage of a run, driven by its progress callback.
pub struct StageBars {
    quiet: bool,
    current: Option<(HeldOutStage, ProgressBar)>,
}

impl StageBars {
    /// No bar yet; `quiet` hides them (as `--json` does).
    pub fn new(quiet: bool) -> Self {
        Self {
            quiet,
            current: None,
        }
    }

    /// The callback: `done` of `total` frames of `stage`.
    pub fn update(&mut self, stage: HeldOutStage, done: usize, total: usize) {
        if self.current.as_ref().map(|(s, _)| *s) != Some(stage) {
            self.finish();
            let bar = progress::bar(total as u64, stage.label(), self.quiet);
            self.current = Some((stage, bar));
        }
        if let Some((_, bar)) = &self.current {
            bar.set_position(done as u64);
        }
    }

    /// Clears the last bar.
    pub fn finish(&mut self) {
        if let Some((_, bar)) = self.current.take() {
            bar.finish_and_clear();
        }
    }
}

/// The reports as a table on standard output.
pub fn print_table(reports: &[MapCheckReport]) {
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
        let a = &r.agreement;
        println!(
            "{:<8} {:>8.2} {:>10.2} {:>10.3} {:>15.4} {:>10.3} {:>9.3} {:>9.3} {:>9}",
            r.model.name(),
            r.build_seconds,
            r.predict_seconds,
            a.predicted,
            a.median_abs_depth_error_m,
            a.within_2_voxels,
            a.too_near,
            a.too_far,
            r.counts.occupied,
        );
    }
}
