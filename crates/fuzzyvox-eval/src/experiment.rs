//! The experiment runner: one scenario, identical depth-stage output fed to every map, metrics
//! after every phase.

use fuzzyvox_core::map::VoxelMapMut;
use std::collections::BTreeMap;
use std::time::Instant;

use nalgebra::Isometry3;

use serde::Serialize;

use super::depth_stage::{DepthStageErrors, DepthStageSummary};
use super::flights::{
    Candidates, FlightOutcome, FlightQuery, FlightSummary, QueryConfig, draw_queries, plan_queries,
    summarize,
};
use super::metrics::{MapMetrics, evaluate};
use super::truth::{GroundTruth, gold_standard};
use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::{DepthFrame, EvidenceModel, IntegrationOptions, IntervalDepthImage};
use fuzzyvox_core::map::{
    AnyMap, FuzzyConfig, FuzzyMap, LogOddsConfig, LogOddsMap, MapKind, MapOptions,
};
use fuzzyvox_core::ops::{Family, TConorm};
use fuzzyvox_depth::{DepthParams, ForwardMotion, MatchMethod, ViewWindow};
use fuzzyvox_sim::scenario::Scenario;
use fuzzyvox_sim::{RenderedFrame, render};

/// Settings of an experiment.
#[derive(Clone, Debug)]
pub struct ExperimentConfig {
    /// Voxel size of every map, metres.
    pub resolution: f64,
    /// Extra fuzzy maps, one per operator (the default fuzzy map uses the probabilistic sum),
    /// each named `fuzzy:` and its t-conorm's name ([`TConorm`]'s `Display`: `fuzzy:maximum`,
    /// `fuzzy:dombi:2`). Listing one operator twice is an error.
    pub operators: Vec<Family>,
    /// How the fuzzy maps turn depth into evidence (default: the dual model).
    pub evidence: EvidenceModel,
    /// Further fuzzy maps with settings of their own, by name (for ablations: the same depth
    /// into maps that differ in one setting). A name used twice is an error.
    pub variants: Vec<(String, FuzzyConfig)>,
    /// The depth stage's settings (its depth range defaults to 1 m .. the scenario's range;
    /// forward-motion pairs go through the plane sweep by default, as the paper feeds every
    /// pair to the maps).
    pub depth: DepthParams,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// Planned flights checked against the true scene after the last phase; `None`: none.
    pub flights: Option<QueryConfig>,
    /// Pairs (by index) whose depth-stage output is kept for figures.
    pub sample_pairs: Vec<usize>,
    /// Camera views behind each depth image. 2 (the default, the paper's depth stage): each
    /// pair on its own. `N > 2`: each pair's two views and the `N - 2` most recent earlier
    /// camera positions of the same phase, matched at once by a multiple-baseline plane sweep
    /// ([`depth_from_views`](fuzzyvox_depth::depth_from_views)); a phase's first pair, with no
    /// earlier views, is matched on its own. At most 17.
    pub views: usize,
    /// Whether each depth image's confidence is scaled by its
    /// [`reuse_weight`](fuzzyvox_depth::DepthResult::reuse_weight) (`2 / views`) before it goes to
    /// the maps, so that images sharing views are not counted as independent evidence. Changes
    /// nothing for pairs; default `true`. The log-odds map ignores confidence either way.
    pub weigh_reused_views: bool,
}

impl Default for ExperimentConfig {
    fn default() -> Self {
        Self {
            resolution: 0.2,
            operators: Vec::new(),
            evidence: EvidenceModel::default(),
            variants: Vec::new(),
            depth: DepthParams {
                forward_motion: ForwardMotion::PlaneSweep,
                ..DepthParams::default()
            },
            seed: 1,
            flights: None,
            sample_pairs: Vec::new(),
            views: 2,
            weigh_reused_views: true,
        }
    }
}

/// Metrics of one map: at the end, and after each named phase.
#[derive(Clone, Debug, Serialize)]
pub struct MapReport {
    /// At the end of the flight.
    #[serde(flatten)]
    pub metrics: MapMetrics,
    /// After each phase but the last, as `after_PHASE` (the wall scenario's `after_strafe`).
    #[serde(flatten)]
    pub after: BTreeMap<String, MapMetrics>,
    /// Planned flights, when the experiment flew any.
    #[serde(flatten)]
    pub flights: Option<FlightSummary>,
}

/// One pair's depth-stage output kept for figures, with the truth seen from the same camera.
#[derive(Clone, Debug)]
pub struct DepthSample {
    /// Index of the pair in the scenario.
    pub pair: usize,
    /// The depth stage's interval depth and confidence.
    pub frame: DepthFrame,
    /// The scene rendered from the frame's (rectified) camera: image and true depth.
    pub truth: RenderedFrame,
}

/// Everything an experiment produced.
pub struct ExperimentOutput {
    /// The figures.
    pub report: ExperimentReport,
    /// Every map, by name, in report order.
    pub maps: Vec<(String, AnyMap)>,
    /// The gold-standard map (true depth inserted with the standard method).
    pub gold: AnyMap,
    /// The ground truth of the planned flights (what the depth images' cameras could see),
    /// when flights were planned.
    pub flight_truth: Option<AnyMap>,
    /// The kept depth-stage outputs.
    pub samples: Vec<DepthSample>,
    /// The flights' start/goal pairs.
    pub flight_queries: Vec<FlightQuery>,
    /// Each map's flight outcomes by name (the ground-truth map as `truth`).
    pub flights: Vec<(String, Vec<FlightOutcome>)>,
}

/// What an experiment measured.
#[derive(Clone, Debug, Serialize)]
pub struct ExperimentReport {
    /// Scenario name.
    pub scenario: String,
    /// Pairs flown.
    pub pairs: usize,
    /// Pairs the depth stage could not use.
    pub rejected_pairs: usize,
    /// Camera views behind each depth image (see [`ExperimentConfig::views`]).
    pub views: usize,
    /// Whether images from several views were weighted by how many views they share (see
    /// [`ExperimentConfig::weigh_reused_views`]).
    pub weigh_reused_views: bool,
    /// Earlier views left out, summed over the pairs, because with them the plane sweep would
    /// need more than 1024 planes (the longest baseline too long for the depth range).
    pub views_dropped: usize,
    /// Pairs matched by plane sweep (motion along the view, or several views) rather than
    /// rectified.
    pub swept_pairs: usize,
    /// Every map's metrics by name: `logodds`, `alpha`, `fuzzy`, and `fuzzy:OP` with `OP` the
    /// extra operator's t-conorm (`fuzzy:maximum`).
    pub maps: BTreeMap<String, MapReport>,
    /// Flights planned in the flights' ground-truth map (the true depth of every depth image's
    /// camera wherever it sees a surface within range), the reference for path lengths.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub truth_flights: Option<FlightSummary>,
    /// Truly occupied voxels in the observed region.
    pub truth_occupied: usize,
    /// The depth stage's accuracy on the sampled pairs ([`ExperimentConfig::sample_pairs`])
    /// against the scene's true depth from the same camera; absent without samples.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_stage: Option<DepthStageSummary>,
    /// Seconds spent rendering, in the depth stage, and integrating.
    pub seconds: BTreeMap<String, f64>,
}

impl ExperimentReport {
    /// For depth from several views, how they were used: "up to N views per depth image, D
    /// earlier views left out for the plane limit, each image weighted 2 / views"; `None` for
    /// pairs.
    pub fn views_summary(&self) -> Option<String> {
        (self.views > 2).then(|| {
            format!(
                "up to {} views per depth image, {} earlier views left out for the plane \
                 limit, {}",
                self.views,
                self.views_dropped,
                if self.weigh_reused_views {
                    "each image weighted 2 / views"
                } else {
                    "images unweighted"
                }
            )
        })
    }
}

/// The true depth that a stereo pair could measure, in its depth image's own camera (the
/// rectified reference camera of a rectified pair): every pixel that sees a surface within the
/// scenario's range, at a point that the pair's other view sees too, inside the matching
/// window's margin of its image. A pixel that sees the sky, a surface beyond the range the depth
/// stage searches, or a point the other view does not see, has no stereo depth for any matcher.
/// Inserted into a log-odds map, these frames are the planned flights' ground truth: the space
/// the cameras saw free.
fn seen_from(
    scenario: &Scenario,
    frame: &DepthFrame,
    other: &Isometry3<f64>,
    margin: f64,
) -> Result<DepthFrame> {
    let k = frame.intrinsics();
    let pose = frame.world_from_camera();
    let truth = render(&scenario.scene, k, pose, 0, scenario.max_range * 4.0);
    let range = scenario.max_range as f32;
    let seen_by_other = |u: f64, v: f64, z: f64| {
        let point = pose * k.back_project(u, v, z);
        let in_other = other.inverse_transform_point(&point);
        let o = &scenario.intrinsics;
        in_other.z > 0.0 && {
            let (x, y) = (
                o.fx() * in_other.x / in_other.z + o.cx(),
                o.fy() * in_other.y / in_other.z + o.cy(),
            );
            x >= margin
                && y >= margin
                && x <= f64::from(o.width()) - 1.0 - margin
                && y <= f64::from(o.height()) - 1.0 - margin
        }
    };
    let width = truth.width as usize;
    let depth: Vec<f32> = truth
        .depth
        .iter()
        .enumerate()
        .map(|(i, &z)| {
            let (u, v) = ((i % width) as f64, (i / width) as f64);
            if z <= range && seen_by_other(u, v, f64::from(z)) {
                z
            } else {
                f32::NAN
            }
        })
        .collect();
    let image = IntervalDepthImage::from_depth(truth.width, truth.height, &depth, |z| (z, z, 1.0))?;
    DepthFrame::new(*k, *pose, image)
}

/// Runs a scenario: renders every pair, runs the depth stage once per pair, feeds the same
/// depth frames to every map, and evaluates every map after each phase against the ground
/// truth (the scene's geometry inside the region the gold standard observed).
pub fn run_experiment(scenario: &Scenario, config: &ExperimentConfig) -> Result<ExperimentOutput> {
    run_experiment_with_progress(scenario, config, &mut |_, _| {})
}

/// [`run_experiment`], calling `progress(done, total)` after each pair.
pub fn run_experiment_with_progress(
    scenario: &Scenario,
    config: &ExperimentConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<ExperimentOutput> {
    let mut window = ViewWindow::new(config.views)?;
    // One map of every kind, the fuzzy one with the experiment's evidence model.
    let options = MapOptions {
        evidence: config.evidence,
        ..MapOptions::default()
    };
    let mut maps: Vec<(String, AnyMap)> = MapKind::ALL
        .into_iter()
        .map(|kind| {
            Ok((
                kind.name().to_string(),
                kind.new_map_with(config.resolution, &options)?,
            ))
        })
        .collect::<Result<_>>()?;
    for family in &config.operators {
        let operator = TConorm::new(*family)?;
        let name = format!("{}:{operator}", MapKind::Fuzzy.name());
        if maps.iter().any(|(existing, _)| *existing == name) {
            return Err(Error::Duplicate(format!("the operator {operator}")));
        }
        let fuzzy = FuzzyConfig::new(config.resolution)?
            .with_operator(operator)
            .with_evidence(config.evidence);
        maps.push((name, AnyMap::Fuzzy(FuzzyMap::new(fuzzy)?)));
    }
    for (name, fuzzy) in &config.variants {
        if maps.iter().any(|(existing, _)| existing == name) {
            return Err(Error::Duplicate(format!("the map name {name}")));
        }
        maps.push((name.clone(), AnyMap::Fuzzy(FuzzyMap::new(*fuzzy)?)));
    }
    let mut seconds = BTreeMap::new();
    let started = Instant::now();
    let references: Vec<_> = scenario.pairs.iter().map(|p| p.0).collect();
    let gold = gold_standard(
        &scenario.scene,
        &scenario.intrinsics,
        &references,
        config.resolution,
        scenario.max_range,
    )?;
    // The flights' ground truth: what the depth images' own cameras could see (filled pair by
    // pair below).
    let mut camera_truth = match config.flights {
        Some(_) => Some(LogOddsMap::new(LogOddsConfig::new(config.resolution)?)?),
        None => None,
    };
    let truth = GroundTruth::from_scene(&scenario.scene, &gold);
    seconds.insert("ground_truth".into(), started.elapsed().as_secs_f64());

    let mut depth = config.depth.clone();
    depth.depth_range.get_or_insert((1.0, scenario.max_range));
    let options = IntegrationOptions {
        max_range: Some(scenario.max_range),
    };
    // Pixels this close to an image's border have no full matching window.
    let match_margin = f64::from(
        depth
            .matching
            .window_width
            .max(depth.matching.window_height)
            / 2,
    );
    let mut phase_metrics: BTreeMap<String, BTreeMap<String, MapMetrics>> = BTreeMap::new();
    let (mut render_s, mut depth_s, mut integrate_s) = (0.0, 0.0, 0.0);
    let (mut rejected, mut swept) = (0, 0);
    let mut samples = Vec::new();
    let mut done = 0;
    let last_phase = scenario.phases.len().saturating_sub(1);
    for (phase_index, (phase, range)) in scenario.phases.iter().enumerate() {
        // Multi-view depth uses earlier views of the same phase only.
        window.clear();
        for index in range.clone() {
            let Some((reference, other)) = scenario.pairs.get(index) else {
                continue;
            };
            done += 1;
            progress(done, scenario.pairs.len());
            let t = Instant::now();
            let Some(views) = scenario.render_pair(index, config.seed) else {
                continue;
            };
            render_s += t.elapsed().as_secs_f64();
            let [a, b] = &views;
            let time = index as f64;
            let (a, b) = (
                a.to_frame(scenario.intrinsics, *reference, time)?,
                b.to_frame(scenario.intrinsics, *other, time)?,
            );
            let t = Instant::now();
            let result = window.depth(a, b, &depth);
            depth_s += t.elapsed().as_secs_f64();
            let depth_frame: DepthFrame = match result {
                Ok(result) => {
                    swept += usize::from(result.method != MatchMethod::Rectified);
                    if config.sample_pairs.contains(&index) {
                        samples.push(DepthSample {
                            pair: index,
                            truth: render(
                                &scenario.scene,
                                result.frame.intrinsics(),
                                result.frame.world_from_camera(),
                                config.seed,
                                scenario.max_range * 4.0,
                            ),
                            frame: result.frame.clone(),
                        });
                    }
                    let weight = result.reuse_weight();
                    let mut frame = result.frame;
                    if config.weigh_reused_views {
                        frame.scale_confidence(weight)?;
                    }
                    frame
                }
                Err(_) => {
                    rejected += 1;
                    continue;
                }
            };
            if let Some(truth_map) = &mut camera_truth {
                let seen = seen_from(scenario, &depth_frame, other, match_margin)?;
                truth_map.integrate_depth(&seen, &options)?;
            }
            let t = Instant::now();
            for (_, map) in maps.iter_mut() {
                map.as_map_mut().integrate_depth(&depth_frame, &options)?;
            }
            integrate_s += t.elapsed().as_secs_f64();
        }
        if phase_index == last_phase {
            continue;
        }
        for (name, map) in &maps {
            phase_metrics.entry(name.clone()).or_default().insert(
                format!("after_{phase}"),
                evaluate(map.as_map(), &truth, &scenario.scene),
            );
        }
    }
    seconds.insert("render".into(), render_s);
    seconds.insert("depth_stage".into(), depth_s);
    seconds.insert("integration".into(), integrate_s);
    let (flight_queries_list, flights) = match &config.flights {
        Some(flight_config) => {
            let t = Instant::now();
            // Flights are drawn from, and planned in, what the cameras could know of the truth.
            let truth_map = camera_truth.as_ref().unwrap_or(&gold);
            let queries = draw_queries(
                &scenario.scene,
                Candidates::Reference(truth_map),
                flight_config,
            )?;
            let mut flights = vec![(
                "truth".to_string(),
                plan_queries(truth_map, &scenario.scene, &queries, &flight_config.planner),
            )];
            for (name, map) in &maps {
                flights.push((
                    name.clone(),
                    plan_queries(
                        map.as_map(),
                        &scenario.scene,
                        &queries,
                        &flight_config.planner,
                    ),
                ));
            }
            seconds.insert("flights".into(), t.elapsed().as_secs_f64());
            (queries, flights)
        }
        None => (Vec::new(), Vec::new()),
    };
    let summary_of = |name: &str| {
        let reference = &flights.first()?.1;
        let (_, outcomes) = flights.iter().find(|(n, _)| n == name)?;
        Some(summarize(outcomes, reference))
    };
    let maps_report = maps
        .iter()
        .map(|(name, map)| {
            let after = phase_metrics.remove(name).unwrap_or_default();
            let metrics = evaluate(map.as_map(), &truth, &scenario.scene);
            let flights = summary_of(name);
            (
                name.clone(),
                MapReport {
                    metrics,
                    after,
                    flights,
                },
            )
        })
        .collect();
    let report = ExperimentReport {
        scenario: scenario.name.to_string(),
        pairs: scenario.pairs.len(),
        rejected_pairs: rejected,
        views: config.views,
        weigh_reused_views: config.weigh_reused_views,
        views_dropped: window.views_dropped(),
        swept_pairs: swept,
        maps: maps_report,
        truth_flights: summary_of("truth"),
        truth_occupied: truth.occupied_count(),
        depth_stage: (!samples.is_empty()).then(|| {
            let mut errors = DepthStageErrors::default();
            for sample in &samples {
                errors.add_aligned(sample.frame.image(), &sample.truth.depth);
            }
            errors.summary()
        }),
        seconds,
    };
    Ok(ExperimentOutput {
        report,
        maps,
        gold: AnyMap::LogOdds(gold),
        flight_truth: camera_truth.map(AnyMap::LogOdds),
        samples,
        flight_queries: flight_queries_list,
        flights,
    })
}
