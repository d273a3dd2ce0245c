use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use fuzzyvox::figure::ViewColor;
use fuzzyvox::io::load_map;
use fuzzyvox::view::{DEFAULT_MAX_FREE, ViewerOptions, read_paths, write_viewer_page};
use serde_json::json;

use super::maps::ColorArg;
use super::progress;

/// Write a 3D viewer page for a map: one self-contained HTML file that opens offline by double
/// click (no server, no network, nothing to install).
///
/// The page draws the voxels with WebGL2: drag to orbit, right-drag (or shift-drag) to pan,
/// wheel to zoom, hover to read a voxel's memberships and class; a checkbox per class; a legend
/// with the colour map's range; axes and a scale in metres. Occupied and ambiguous voxels are
/// all written; free and unknown voxels are subsampled (at most `--max-free` free and half as
/// many unknown, the same voxels every time) and hidden until shown. `--flights` draws paths
/// over the map: the output of `fuzzyvox plan --json`, or a `{"paths": [...]}` file such as
/// the demo's `*-paths.json`.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox view scan.fvx\n  \
    fuzzyvox view scan.fvx --out scan.html --color safety\n  \
    fuzzyvox plan --map scan.fvx --from 3,0,0.5 --to 7,-11,0.5 --json > plan.json\n  \
    fuzzyvox view scan.fvx --flights plan.json\n  \
    fuzzyvox view geb079.bt --color height --show-free")]
pub struct ViewArgs {
    /// A map file: a fuzzyvox map, an OctoMap `.bt` or `.ot`.
    map: PathBuf,
    /// Where to write the page (default: the map's path with `.html`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// What colours the voxels when the page opens (the page can switch).
    #[arg(long, value_enum, default_value_t = ColorArg::Class)]
    color: ColorArg,
    /// Paths to draw: `fuzzyvox plan --json` output or a `{"paths": [...]}` file.
    #[arg(long)]
    flights: Option<PathBuf>,
    /// At most this many free voxels (and half as many unknown ones) in the page.
    #[arg(long, default_value_t = DEFAULT_MAX_FREE)]
    max_free: usize,
    /// Show free voxels when the page opens.
    #[arg(long)]
    show_free: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: ViewArgs) -> anyhow::Result<()> {
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| args.map.with_extension("html"));
    let paths = match &args.flights {
        Some(file) => read_paths(file).with_context(|| format!("reading {}", file.display()))?,
        None => Vec::new(),
    };
    let spinner = progress::spinner("loading the map", args.json);
    let map =
        load_map(&args.map).with_context(|| format!("loading the map {}", args.map.display()))?;
    spinner.set_message("writing the page");
    let name = args.map.file_name().unwrap_or_default().to_string_lossy();
    let mut options = ViewerOptions::new(
        format!("{name} ({} map)", map.model_name()),
        map.model_name(),
    );
    options.color = ViewColor::from(args.color);
    options.max_free = args.max_free;
    options.show_free = args.show_free;
    options.paths = paths;
    let summary = write_viewer_page(map.as_map(), &options, &out)
        .with_context(|| format!("writing {}", out.display()))?;
    spinner.finish_and_clear();
    let [occupied, free, ambiguous, unknown] = summary.drawn;
    if args.json {
        return super::print_json(&json!({
            "map": args.map,
            "model": map.model_name(),
            "out": out,
            "bytes": summary.bytes,
            "voxels": {
                "occupied": occupied, "free": free, "ambiguous": ambiguous, "unknown": unknown,
            },
            "totals": {
                "occupied": summary.total[0], "free": summary.total[1],
                "ambiguous": summary.total[2], "unknown": summary.total[3],
            },
            "paths": options.paths.len(),
        }));
    }
    println!(
        "wrote {} ({:.1} MB: {occupied} occupied, {ambiguous} ambiguous, {free} of {} free, \
         {unknown} of {} unknown voxels; {} paths); open it in a browser",
        out.display(),
        summary.bytes as f64 / 1e6,
        summary.total[1],
        summary.total[3],
        options.paths.len()
    );
    Ok(())
}
