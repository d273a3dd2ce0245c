use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use fuzzyvox::VoxelClass;
use fuzzyvox::figure::{View, ViewColor, ViewSpec, save_png, view_figure};
use fuzzyvox::io::load_map;
use fuzzyvox::io::octomap::write_bt_max_likelihood;
use fuzzyvox::io::ply::{PlyEncoding, write_ply};
use serde_json::{Value, json};
use tracing::info;

use super::maps::ColorArg;
use super::progress;

/// Export a saved map to other tools' formats: OctoMap `.bt`, PLY points, PNG views.
///
/// `--bt` writes an OctoMap binary octree (`.bt`, maximum likelihood) that OctoMap's tools and
/// octovis open: every observed voxel becomes occupied when its occupied membership is at least
/// its free membership (for a log-odds map: p ≥ 0.5, OctoMap's own rule) and free otherwise;
/// voxels nothing observed stay unknown.
///
/// `--ply` writes one vertex per observed voxel centre (of the `--classes` chosen) with its
/// occupied and free memberships, ambiguity, safety, class (0 occupied, 1 free, 2 ambiguous,
/// 3 unknown) and a class colour; binary little-endian unless `--ascii`.
///
/// `--png` draws the map from the top (x right, y up), from the side (x right, z up) or as the
/// horizontal slice at `--height`, coloured by class, by one measure (viridis, 0 to 1) or by the
/// height of the highest occupied voxel, as a figure: a title, axes in metres, a scale bar and a
/// legend; the plot is at least 800 pixels on its long side and at least `--scale` pixels per
/// voxel. Projections show per column the most critical class, the largest membership or
/// ambiguity, or the smallest safety. Unobserved space is light grey.
///
/// Several outputs can be written in one call.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox export scan.fvx --bt scan.bt\n  \
    fuzzyvox export scan.fvx --ply scan.ply --classes occupied,ambiguous\n  \
    fuzzyvox export scan.fvx --ply scan.ply --ascii --json\n  \
    fuzzyvox export scan.fvx --png top.png\n  \
    fuzzyvox export scan.fvx --png side.png --view side --color occupied --scale 4\n  \
    fuzzyvox export scan.fvx --png slice.png --view slice --height 1.2 --color safety")]
#[command(group(clap::ArgGroup::new("output").required(true).multiple(true).args(["bt", "ply", "png"])))]
pub struct ExportArgs {
    /// A map file: a fuzzyvox map (`insert --out`, `rgbd --save`), an OctoMap `.bt` or `.ot`.
    map: PathBuf,
    /// Write an OctoMap `.bt` file here.
    #[arg(long)]
    bt: Option<PathBuf>,
    /// Write a PLY point file of voxel centres here.
    #[arg(long)]
    ply: Option<PathBuf>,
    /// Write the PLY as text instead of binary little-endian.
    #[arg(long, requires = "ply")]
    ascii: bool,
    /// Classes of the voxels in the PLY file, comma-separated (default: every observed voxel).
    #[arg(long, value_enum, value_delimiter = ',', requires = "ply")]
    classes: Vec<ClassArg>,
    /// Write a PNG view here.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Which view the PNG shows.
    #[arg(long, value_enum, default_value_t = ViewArg::Top, requires = "png")]
    view: ViewArg,
    /// Height of the slice in metres (with `--view slice`).
    #[arg(long, allow_negative_numbers = true, requires = "png")]
    height: Option<f64>,
    /// What colours the PNG.
    #[arg(long, value_enum, default_value_t = ColorArg::Class, requires = "png")]
    color: ColorArg,
    /// Pixels per voxel in the PNG at least (1 to 16; more when needed to reach 800 pixels).
    #[arg(long, default_value_t = 1, requires = "png")]
    scale: u32,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ClassArg {
    Occupied,
    Free,
    Ambiguous,
    Unknown,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ViewArg {
    Top,
    Side,
    Slice,
}

pub fn run(args: ExportArgs) -> anyhow::Result<()> {
    let view = match (args.view, args.height) {
        (ViewArg::Slice, Some(z)) => View::Slice { z },
        (ViewArg::Slice, None) => bail!("--view slice needs --height Z (metres)"),
        (_, Some(_)) => bail!("--height applies to --view slice only"),
        (ViewArg::Top, None) => View::Top,
        (ViewArg::Side, None) => View::Side,
    };
    let spinner = progress::spinner("loading the map", args.json);
    let map =
        load_map(&args.map).with_context(|| format!("loading the map {}", args.map.display()))?;
    let mut report = json!({ "map": args.map, "model": map.model_name() });
    let mut lines = Vec::new();

    if let Some(bt) = &args.bt {
        spinner.set_message("writing the .bt file");
        let (occupied, free) = write_bt_max_likelihood(bt, map.as_map())
            .with_context(|| format!("writing {}", bt.display()))?;
        info!("wrote {}", bt.display());
        report["bt"] = json!(bt);
        report["occupied"] = json!(occupied);
        report["free"] = json!(free);
        lines.push(format!(
            "wrote {} ({occupied} occupied and {free} free voxels, maximum likelihood)",
            bt.display()
        ));
    }
    if let Some(ply) = &args.ply {
        spinner.set_message("writing the PLY file");
        let classes: Vec<VoxelClass> = if args.classes.is_empty() {
            VoxelClass::ALL.to_vec()
        } else {
            args.classes
                .iter()
                .map(|c| match c {
                    ClassArg::Occupied => VoxelClass::Occupied,
                    ClassArg::Free => VoxelClass::Free,
                    ClassArg::Ambiguous => VoxelClass::Ambiguous,
                    ClassArg::Unknown => VoxelClass::Unknown,
                })
                .collect()
        };
        let encoding = if args.ascii {
            PlyEncoding::Ascii
        } else {
            PlyEncoding::BinaryLittleEndian
        };
        let vertices = write_ply(map.as_map(), &classes, encoding, ply)
            .with_context(|| format!("writing {}", ply.display()))?;
        info!("wrote {}", ply.display());
        report["ply"] = json!(ply);
        report["ply_vertices"] = json!(vertices);
        report["ply_format"] = json!(if args.ascii {
            "ascii"
        } else {
            "binary_little_endian"
        });
        let names: Vec<&str> = classes.iter().map(|c| c.name()).collect();
        lines.push(format!(
            "wrote {} ({vertices} voxels: {})",
            ply.display(),
            names.join(", ")
        ));
    }
    if let Some(png) = &args.png {
        spinner.set_message("drawing the PNG view");
        let color = ViewColor::from(args.color);
        let title = format!(
            "{}: {} view by {}, {} m voxels",
            args.map.file_name().unwrap_or_default().to_string_lossy(),
            match view {
                View::Top => "top".to_string(),
                View::Side => "side".to_string(),
                View::Slice { z } => format!("slice at z = {z} m"),
            },
            color.name(),
            map.as_map().resolution().size()
        );
        let figure = view_figure(
            map.as_map(),
            &ViewSpec::new(view, color),
            &title,
            Vec::new(),
            args.scale,
        )
        .with_context(|| format!("drawing {}", png.display()))?;
        save_png(&figure, png).with_context(|| format!("writing {}", png.display()))?;
        let (width, height) = figure.dimensions();
        info!("wrote {}", png.display());
        let view_name = match view {
            View::Top => "top",
            View::Side => "side",
            View::Slice { .. } => "slice",
        };
        let color_name = args
            .color
            .to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default();
        report["png"] = json!(png);
        report["png_width"] = json!(width);
        report["png_height"] = json!(height);
        report["view"] = json!(view_name);
        report["color"] = json!(color_name);
        report["slice_height"] = match view {
            View::Slice { z } => json!(z),
            _ => Value::Null,
        };
        lines.push(format!(
            "wrote {} ({width} × {height} pixels, {view_name} view by {color_name})",
            png.display()
        ));
    }
    spinner.finish_and_clear();
    if args.json {
        return super::print_json(&report);
    }
    for line in lines {
        println!("{line}");
    }
    Ok(())
}
