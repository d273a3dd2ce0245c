//! The experiment layer: every experiment fuzzyvox runs, as library functions returning
//! serializable reports (the command prints them as they are, Python returns them as dicts).
//!
//! - Ground truth and metrics: [`GroundTruth`] holds, for a resolution, the voxels that meet
//!   the true scene geometry and the region the cameras could observe (from the "gold
//!   standard": true depth inserted with the standard method). [`evaluate`] compares any map
//!   with it: occupied precision, recall and F1; holes (truly occupied voxels the map calls
//!   free); spurious occupied voxels in the truly unknown region (behind walls, in the sky);
//!   and the Chamfer distance from occupied voxel centres to the true surface.
//! - Flights checked against the truth: one drawer of start/goal pairs ([`draw_queries`] with
//!   a [`QueryConfig`]), planning in a map ([`plan_queries`]) and one path check against the
//!   true world ([`Obstacles`], [`path_collides`]).
//! - The open-loop experiment: [`run_experiment`] feeds identical depth-stage output to every
//!   map, measures each after every phase and, optionally, plans flights in each map.
//! - Closed-loop flights ([`closed_loop`]): the vehicle of `fuzzyvox_fly` flown to goals drawn
//!   from the truth, with every map.
//! - Held-out runs on real frames: [`run_rgbd`] and [`run_mono`] build maps from an RGB-D folder
//!   or posed colour images and ray-cast them into frames they have not seen ([`HoldoutSplit`],
//!   [`DepthErrors`]).
//! - Reports: Markdown, HTML, figures and charts of each.

mod charts;
pub mod closed_loop;
mod depth_stage;
mod experiment;
mod figures;
mod flights;
mod held_out;
mod metrics;
mod report;
mod rgbd;
mod truth;

pub use charts::{depth_confidence_chart, maps_chart, operators_chart};
pub use depth_stage::{ConfidenceBin, DepthStageErrors, DepthStageSummary, ErrorQuantiles};
pub use experiment::{
    DepthSample, ExperimentConfig, ExperimentOutput, ExperimentReport, MapReport, run_experiment,
    run_experiment_with_progress,
};
pub use figures::{TopDownView, depth_panels_png, flights_png, top_down_png};
pub use flights::{
    BlockedByCounts, BlockingClass, Candidates, CollisionDetail, Connect, FailureCounts,
    FlightFailure, FlightOutcome, FlightQuery, FlightSummary, Obstacles, OccupiedVoxels,
    QueryConfig, draw_queries, path_collides, path_contact, plan_queries, summarize,
};
pub use held_out::{
    ConsistencyReport, DepthStageReport, FolderSplit, HeldOutConfig, HeldOutRun, HeldOutStage,
    MapCheckReport, MonoConfig, MonoReport, MonoRun, MonoSeconds, PriorMap, RealFlightConfig,
    RealFlights, RgbdReport, RgbdRun, run_mono, run_mono_on, run_rgbd, run_rgbd_on,
    save_held_out_maps, write_held_out_maps,
};
pub use metrics::{MapMetrics, evaluate};
pub use report::{file_stem, markdown, report_html, write_experiment};
pub use rgbd::{DepthAgreement, DepthCheckConfig, DepthErrors, HoldoutSplit};
pub use truth::{GroundTruth, gold_standard, meets_geometry};
