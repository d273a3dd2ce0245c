//! Evaluation of maps against ground truth: the quantitative metrics the paper could not give.
//!
//! [`GroundTruth`] holds, for a resolution, the voxels that meet the true scene geometry and
//! the region the cameras could observe (from the "gold standard": true depth inserted with the
//! standard method). [`evaluate`] compares any map with it: occupied precision, recall and F1;
//! holes (truly occupied voxels the map calls free); spurious occupied voxels in the truly
//! unknown region (behind walls, in the sky); and the Chamfer distance from occupied voxel
//! centres to the true surface.
//!
//! [`run_experiment`] feeds identical depth-stage output to every map, measures each after
//! every phase and, optionally, plans flights in each map and checks them against the true
//! scene ([`fly`]). [`HoldoutSplit`] and [`DepthErrors`] evaluate maps of real RGB-D data by
//! ray-casting them into held-out frames; [`run_rgbd`] and [`run_mono`] run the held-out
//! experiments on real RGB-D folders and posed colour images.

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
pub use depth_stage::{ConfidenceBin, DepthStageErrors, DepthStageSummary};
pub use experiment::{
    DepthSample, ExperimentConfig, ExperimentOutput, ExperimentReport, MapReport, run_experiment,
    run_experiment_with_progress,
};
pub use figures::{TopDownView, depth_panels_png, flights_png, top_down_png};
pub use flights::{
    BlockedByCounts, BlockingClass, Candidates, Connect, FailureCounts, FlightFailure,
    FlightOutcome, FlightQuery, FlightSummary, Obstacles, QueryConfig, draw_queries, path_collides,
    plan_queries, summarize,
};
pub use held_out::{
    DepthStageReport, FolderSplit, HeldOutConfig, HeldOutRun, HeldOutStage, MapCheckReport,
    MonoConfig, MonoReport, MonoRun, MonoSeconds, PriorMap, RgbdReport, RgbdRun, run_mono,
    run_mono_on, run_rgbd, run_rgbd_on,
};
pub use metrics::{MapMetrics, evaluate};
pub use report::{file_stem, markdown, report_html, write_experiment};
pub use rgbd::{DepthAgreement, DepthCheckConfig, DepthErrors, HoldoutSplit};
pub use truth::{GroundTruth, gold_standard, meets_geometry};
