//! The held-out experiments on real data, as library functions: maps built from some frames of
//! a real sequence and checked against the sensor depth of frames they have not seen.
//!
//! [`run_rgbd`] builds the maps from the sensor depth of an RGB-D folder (what `fuzzyvox rgbd`
//! runs); [`run_mono`] builds them from the one-camera depth stage on the colour images (what
//! `fuzzyvox mono` runs). Both return a report whose JSON is the command's `--json` output, and
//! the built maps.

mod config;
mod flights;
mod maps;
mod mono;
mod mono_config;
mod rgbd;
mod run;
mod stage;
mod write;

pub use config::{HeldOutConfig, PriorMap};
pub use flights::{RealFlightConfig, RealFlights};
pub use maps::MapCheckReport;
pub use mono::{
    ConsistencyReport, DepthStageReport, MonoReport, MonoRun, MonoSeconds, run_mono, run_mono_on,
};
pub use mono_config::MonoConfig;
pub use rgbd::{RgbdReport, RgbdRun, run_rgbd, run_rgbd_on};
pub use run::{FolderSplit, HeldOutRun};
pub use stage::HeldOutStage;
pub use write::{save_held_out_maps, write_held_out_maps};
