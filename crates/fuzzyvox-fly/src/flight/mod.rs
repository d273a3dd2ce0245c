//! One closed-loop flight: the vehicle plans through what its map knows, flies a little, takes
//! a picture, estimates depth from its own motion, updates the map and replans.
//!
//! - this module: the vehicle's state between cycles ([`Flight`]) and one whole flight
//!   ([`fly_goal`]);
//! - `see`: the camera's picture and the vehicle's own work on it (depth, integration, the
//!   cost field's update, keeping or replanning the path);
//! - `steer`: the step along the path (weaving, looking aside, the view rule) and its check
//!   against the true scene;
//! - `replan`: A* from the vehicle's position, or towards the reachable voxel nearest the goal,
//!   and the repair of a blocked path;
//! - `geometry`: polylines and headings;
//! - `prior`: what the vehicle knows before take-off;
//! - `log`: what a flight did.

mod geometry;
mod log;
mod prior;
mod replan;
mod see;
mod steer;

use fuzzyvox_core::error::Result;
use fuzzyvox_core::integrate::{DepthFrame, IntegrationOptions};
use fuzzyvox_core::map::AnyMap;
use fuzzyvox_core::storage::VoxelKey;
use fuzzyvox_depth::{
    DepthParams, ForwardMotion, Frame, GrayImage, MatchParams, ViewWindow, textureless,
};
use fuzzyvox_plan::Planner;
use fuzzyvox_sim::scenario::Scenario;
use nalgebra::{Isometry3, Point3, Vector3};

use crate::config::FlyConfig;
use crate::guard::UnknownGuard;
use crate::region::planning_region;
use geometry::level;
pub use log::{CycleTimes, Ending, FlightLog};
pub use prior::integrate_prior;
use replan::LastReplan;
pub use steer::{
    BLIND_QUALITY, BLIND_SHARE, DEPTH_SHARE, LOOK_FRAMES, NEAR_SHARE, REACHED_VOXELS, STALL_FRAMES,
    VIEW_MARGIN,
};

/// Flies from `start` to `goal` with `map` (which holds what the vehicle knew before;
/// [`integrate_prior`] gives it its surroundings), seeing the scene through the scenario's
/// camera. Deterministic for `seed`. Runs [`Flight::cycle`] until the flight ends.
pub fn fly_goal(
    scenario: &Scenario,
    start: &Point3<f64>,
    goal: &Point3<f64>,
    map: &mut AnyMap,
    config: &FlyConfig,
    seed: u64,
) -> Result<FlightLog> {
    let mut flight = Flight::new(scenario, start, goal, map, config, seed)?;
    while flight.ending().is_none() {
        flight.cycle(map)?;
    }
    Ok(flight.into_log())
}

/// A depth image the vehicle got, and whether it is blind ([`BLIND_SHARE`]).
#[derive(Clone)]
struct Sight {
    frame: DepthFrame,
    blind: bool,
}

impl Sight {
    /// The depth image `frame` matched from the picture `reference` by a pair of quality
    /// `quality` (`Q_ABD`): blind when the pair's quality is at least [`BLIND_QUALITY`] and
    /// fewer than [`BLIND_SHARE`] of the picture's textured pixels (the texture test of
    /// `matching`) got a depth. Shares of each image's own pixels are compared, since a
    /// rectified pair's depth image need not have the picture's size. The texture test runs
    /// only when the depth image holds a depth in fewer than [`BLIND_SHARE`] of all its
    /// pixels; no picture with more can be blind.
    fn new(frame: DepthFrame, quality: f64, reference: &GrayImage, matching: &MatchParams) -> Self {
        let image = frame.image();
        let pixels = image.depth().len();
        let measured = (0..pixels).filter(|&i| image.has_depth(i)).count();
        let coverage = measured as f64 / pixels.max(1) as f64;
        let blind = quality >= BLIND_QUALITY && coverage < BLIND_SHARE && {
            let flat = textureless(reference, matching);
            let textured = flat.iter().filter(|&&f| !f).count();
            coverage < BLIND_SHARE * textured as f64 / flat.len().max(1) as f64
        };
        Self { frame, blind }
    }
}

/// One closed-loop flight in progress: the vehicle's state between cycles.
///
/// Every [`cycle`](Flight::cycle): the camera looks [`FlyConfig::look_ahead`] metres ahead
/// along the current path (level; the yaw policy) and renders ([`Flight::render`]); then the
/// vehicle's own work ([`Flight::see`]): the depth stage matches this frame against the
/// previous ones (sideways pairs rectified, pairs along the view by plane sweep: the one
/// stereo decision of [`ViewWindow`]), the depth image goes into the map, the [`Planner`]
/// updates its cost field around the blocks the map changed, the current path is kept while
/// it stays clear and fewer than [`FlyConfig::replan_every`] frames have passed, otherwise A*
/// plans again from the current position; then the vehicle advances `speed × frame_interval`
/// along the path, and the true scene checks the step with the vehicle's swept ball.
#[derive(Clone)]
pub struct Flight<'a> {
    scenario: &'a Scenario,
    goal: Point3<f64>,
    goal_key: VoxelKey,
    config: FlyConfig,
    seed: u64,
    params: DepthParams,
    options: IntegrationOptions,
    planner: Planner,
    guard: UnknownGuard,
    window: ViewWindow,
    previous: Option<Frame>,
    path: Option<Vec<Point3<f64>>>,
    /// The last replan's inputs and what it gave, reused while the inputs stay the same.
    last_replan: LastReplan,
    position: Point3<f64>,
    heading: Vector3<f64>,
    pitch: f64,
    /// The camera's pose at the last picture: what the vehicle has just seen.
    camera: Option<Isometry3<f64>>,
    /// The last depth image: what the vehicle has measured most recently (a picture taken
    /// where the vehicle held has no baseline and gives none, so the one before still holds).
    sight: Option<Sight>,
    since_plan: usize,
    stalled: usize,
    /// The camera's heading when the vehicle last side-stepped to look ahead (`None` before
    /// the first look).
    looked: Option<Vector3<f64>>,
    /// The frame of the last look aside.
    looked_at: usize,
    /// A step the vehicle held back because it headed outside the last picture (or at
    /// something within reach): the next picture looks along it.
    aim: Option<Point3<f64>>,
    /// Whether the vehicle held its position last frame for want of a step it could take.
    held: bool,
    frame_index: usize,
    max_frames: usize,
    /// The nearest the vehicle has come to the goal, metres, and the frame it came there (by
    /// at least a voxel edge nearer than before).
    nearest: f64,
    nearer_at: usize,
    patience_frames: usize,
    ending: Option<Ending>,
    log: FlightLog,
}

impl<'a> Flight<'a> {
    /// A vehicle at `start` with `map` (its prior knowledge), about to take its first picture
    /// on its way to `goal`.
    pub fn new(
        scenario: &'a Scenario,
        start: &Point3<f64>,
        goal: &Point3<f64>,
        map: &AnyMap,
        config: &FlyConfig,
        seed: u64,
    ) -> Result<Self> {
        let config = config.validate()?;
        let resolution = map.as_map().resolution();
        let region = planning_region(&resolution, start, goal, &config)?;
        Ok(Self {
            scenario,
            goal: *goal,
            goal_key: resolution.key_of(goal)?,
            config,
            seed,
            params: DepthParams {
                depth_range: Some((config.min_depth, scenario.max_range)),
                forward_motion: ForwardMotion::PlaneSweep,
                ..DepthParams::default()
            },
            options: IntegrationOptions {
                max_range: Some(scenario.max_range.min(config.map_range)),
            },
            planner: Planner::new(map.as_map(), region, config.planner)?,
            guard: UnknownGuard::new(),
            window: ViewWindow::new(config.views)?,
            previous: None,
            path: None,
            last_replan: LastReplan::default(),
            position: *start,
            heading: level(goal - start).unwrap_or_else(Vector3::x),
            pitch: 0.0,
            camera: None,
            sight: None,
            since_plan: 0,
            stalled: 0,
            looked: None,
            looked_at: 0,
            aim: None,
            held: false,
            frame_index: 0,
            max_frames: (config.time_limit / config.frame_interval).ceil() as usize,
            nearest: (goal - start).norm(),
            nearer_at: 0,
            patience_frames: (config.patience / config.frame_interval).ceil() as usize,
            ending: None,
            log: FlightLog {
                ending: Ending::TimeLimit,
                trajectory: vec![*start],
                length: 0.0,
                seconds: 0.0,
                frames: 0,
                depth_images: 0,
                depth_refused: 0,
                replans: 0,
                repairs: 0,
                cycles: Vec::new(),
            },
        })
    }

    /// How the flight ended, or `None` while it goes on.
    pub fn ending(&self) -> Option<Ending> {
        self.ending
    }

    /// Where the vehicle is.
    pub fn position(&self) -> Point3<f64> {
        self.position
    }

    /// The path the vehicle follows (its first point is the vehicle), if it has one.
    pub fn path(&self) -> Option<&[Point3<f64>]> {
        self.path.as_deref()
    }

    /// The direction the camera looked in at the last frame (level).
    pub fn heading(&self) -> Vector3<f64> {
        self.heading
    }

    /// The planner and its current cost field.
    pub fn planner(&self) -> &Planner {
        &self.planner
    }

    /// The log so far.
    pub fn log(&self) -> &FlightLog {
        &self.log
    }

    /// The finished flight's log.
    pub fn into_log(self) -> FlightLog {
        self.log
    }

    /// One cycle: [`render`](Flight::render), [`see`](Flight::see) and
    /// a step along the path. Does nothing once the flight has ended.
    pub fn cycle(&mut self, map: &mut AnyMap) -> Result<()> {
        if self.ending.is_some() {
            return Ok(());
        }
        if self.frame_index >= self.max_frames {
            self.finish(Ending::TimeLimit);
            return Ok(());
        }
        if self.frame_index >= self.nearer_at + self.patience_frames {
            self.finish(Ending::Stuck);
            return Ok(());
        }
        let frame = self.render()?;
        self.see(frame, map)?;
        self.fly(map);
        self.frame_index += 1;
        Ok(())
    }

    /// Ends the flight.
    fn finish(&mut self, ending: Ending) {
        self.ending = Some(ending);
        self.log.ending = ending;
    }
}
