use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;
use fuzzyvox::AnyMap;
use fuzzyvox::io::octomap::write_bt_max_likelihood;
use serde_json::json;

/// Export a saved map to other tools' formats.
///
/// `--bt` writes an OctoMap binary octree (`.bt`, maximum likelihood) that OctoMap's tools and
/// octovis open: every observed voxel becomes occupied when its occupied membership is at least
/// its free membership (for a log-odds map: p ≥ 0.5, OctoMap's own rule) and free otherwise;
/// voxels nothing observed stay unknown.
#[derive(Args)]
#[command(
    after_help = "Examples:\n  fuzzyvox export scan.fvx --bt scan.bt\n  fuzzyvox export scan.fvx --bt scan.bt --json"
)]
pub struct ExportArgs {
    /// A map file written by `fuzzyvox insert --out`.
    map: PathBuf,
    /// Write an OctoMap `.bt` file here.
    #[arg(long)]
    bt: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: ExportArgs) -> anyhow::Result<()> {
    let Some(bt) = &args.bt else {
        bail!("nothing to export: give --bt OUT.bt");
    };
    let map = AnyMap::load(&args.map)?;
    let (occupied, free) = write_bt_max_likelihood(bt, map.as_map())
        .with_context(|| format!("writing {}", bt.display()))?;
    if args.json {
        return super::print_json(&json!({
            "map": args.map,
            "bt": bt,
            "occupied": occupied,
            "free": free,
        }));
    }
    println!(
        "wrote {} ({occupied} occupied and {free} free voxels, maximum likelihood)",
        bt.display()
    );
    Ok(())
}
