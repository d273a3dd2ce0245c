//! The `fuzzyvox` command: argument parsing and output formatting over the library (the
//! `fuzzyvox` facade crate). Each command lives in its own file; the work is the library's.

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod demo;
mod eval;
mod export;
mod fly;
mod held_out;
mod info;
mod input;
mod insert;
mod maps;
mod merge;
mod mono;
mod plan;
mod progress;
mod rgbd;
mod simulate;
mod stereo;
mod view;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Confidence-aware 3D mapping: dual-set fuzzy voxel maps from uncertain depth.
#[derive(Parser)]
#[command(
    name = "fuzzyvox",
    version,
    about,
    long_about = None,
    after_help = "Examples:\n  \
        fuzzyvox demo\n  \
        fuzzyvox insert --cloud scan.dat --res 0.1 --out scan.fvx\n  \
        fuzzyvox info scan.fvx\n  \
        fuzzyvox merge part-1.fvx part-2.fvx --out whole.fvx\n  \
        fuzzyvox export scan.fvx --png top.png --ply scan.ply --bt scan.bt\n  \
        fuzzyvox view scan.fvx --out scan.html\n  \
        fuzzyvox plan --map scan.fvx --from 3,0,0.5 --to 7,-11,0.5\n  \
        fuzzyvox rgbd --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.02\n  \
        fuzzyvox mono --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.04\n  \
        fuzzyvox stereo --middlebury ../shared/data/middlebury-motorcycle --json\n\n\
        Every command has --help with its own examples; -v, -vv log more to standard error."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Log more to standard error: -v for steps, -vv for details, -vvv for everything.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
}

#[derive(Subcommand)]
enum Command {
    Insert(insert::InsertArgs),
    Info(info::InfoArgs),
    Merge(merge::MergeArgs),
    Export(export::ExportArgs),
    Eval(eval::EvalArgs),
    Demo(demo::DemoArgs),
    Plan(plan::PlanArgs),
    Stereo(stereo::StereoArgs),
    Simulate(simulate::SimulateArgs),
    Rgbd(rgbd::RgbdArgs),
    Mono(mono::MonoArgs),
    View(view::ViewArgs),
    Fly(fly::FlyArgs),
}

/// Parses the arguments, runs the command and reports errors with their causes.
fn main() -> ExitCode {
    let cli = Cli::parse();
    progress::init_logging(cli.verbose);
    let result = match cli.command {
        Command::Insert(args) => insert::run(args),
        Command::Info(args) => info::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Export(args) => export::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Demo(args) => demo::run(args),
        Command::Plan(args) => plan::run(args),
        Command::Stereo(args) => stereo::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Rgbd(args) => rgbd::run(args),
        Command::Mono(args) => mono::run(args),
        Command::Fly(args) => fly::run(args),
        Command::View(args) => view::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {}", describe(&error));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, each said once: library errors such as a failed
/// read already name their cause in their own message, and a cause that begins with the path
/// the context just named drops it (`writing a.bt` and `a.bt: No such file` give
/// `writing a.bt: No such file`; `reading c.xyz` and `c.xyz:3: bad number` give
/// `reading c.xyz:3: bad number`).
fn describe(error: &anyhow::Error) -> String {
    let mut message = error.to_string();
    for cause in error.chain().skip(1) {
        let text = cause.to_string();
        if message.contains(&text) {
            continue;
        }
        let rest = text
            .match_indices(':')
            .find(|&(at, _)| {
                text.get(..at)
                    .is_some_and(|head| !head.is_empty() && message.ends_with(head))
            })
            .and_then(|(at, _)| text.get(at..));
        match rest {
            Some(rest) => message.push_str(rest),
            None => {
                message.push_str(": ");
                message.push_str(&text);
            }
        }
    }
    message
}

/// Parses `X,Y,Z` into a point.
fn parse_point(text: &str) -> Result<nalgebra::Point3<f64>, String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("`{text}`: {e}"))?;
    match values.as_slice() {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok(nalgebra::Point3::new(*x, *y, *z)),
        [_, _, _] => Err(format!("`{text}`: coordinates must be finite")),
        _ => Err(format!("`{text}`: expected X,Y,Z")),
    }
}

/// Prints a value as one line of JSON.
fn print_json(value: &serde_json::Value) -> anyhow::Result<()> {
    println!("{}", serde_json::to_string(value)?);
    Ok(())
}
