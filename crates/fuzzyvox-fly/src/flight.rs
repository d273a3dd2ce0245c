//! One closed-loop flight: the vehicle plans through what its map knows, flies a little, takes
//! a picture, estimates depth from its own motion, updates the map and replans.

use std::time::Instant;

use nalgebra::{Isometry3, Point3, Vector3};
use serde::Serialize;

use super::config::FlyConfig;
use super::goals::{Goal, planning_region};
use super::guard::UnknownGuard;
use crate::depth::{DepthParams, ForwardMotion, Frame, ViewWindow};
use crate::error::Result;
use crate::integrate::{DepthFrame, IntegrationOptions, IntervalDepthImage};
use crate::map::AnyMap;
use crate::measures::VoxelClass;
use crate::plan::{CostField, PlanError, Planner, plan_in_field_avoiding};
use crate::sim::render;
use crate::sim::scenario::Scenario;
use crate::sim::trajectory::look_at;
use crate::storage::VoxelKey;

/// How a flight ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Ending {
    /// Within [`REACHED_VOXELS`] voxel edges of the goal.
    Reached,
    /// The vehicle's swept ball met the true scene; the flight stopped there.
    Collided,
    /// The time limit passed.
    TimeLimit,
    /// The map offered no path (not even towards the goal) for [`STALL_FRAMES`] frames in a
    /// row.
    NoPath,
    /// The vehicle came no nearer to the goal for [`FlyConfig::patience`] seconds.
    Stuck,
}

/// A flight has reached its goal within this many voxel edges of it (`√3`: in the goal's
/// voxel or one that touches it).
pub const REACHED_VOXELS: f64 = 1.732_050_807_568_877_2;

/// Frames after a look aside before the next one: a path that swings from side to side
/// (around an obstacle, or while the map fills in) would otherwise send the vehicle sideways
/// every frame.
pub const LOOK_FRAMES: usize = 4;

/// Frames in a row without a path after which a flight gives up.
pub const STALL_FRAMES: usize = 12;

/// How far inside the last picture's edges (a fraction of its width and height) a step into
/// unknown space must head: the vehicle enters unknown space only where its camera has just
/// looked.
pub const VIEW_MARGIN: f64 = 0.1;

/// Milliseconds each part of one cycle took.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CycleTimes {
    /// The depth stage on the latest views.
    pub depth_ms: f64,
    /// Integrating the depth image into the map.
    pub integrate_ms: f64,
    /// Updating the cost field from the blocks the integration changed, checking the current
    /// path against it and, when the path is no longer clear (or every
    /// [`FlyConfig::replan_every`] frames), planning again.
    pub update_replan_ms: f64,
    /// Updating the [`UnknownGuard`] (not part of `update_replan_ms`).
    pub guard_ms: f64,
    /// A full rebuild of the cost field over the planning region, timed on every tenth cycle
    /// only (for comparison); `None` on the others.
    pub full_rebuild_ms: Option<f64>,
}

/// What one flight did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FlightLog {
    /// How it ended.
    pub ending: Ending,
    /// Positions of the vehicle, the start first, one per frame it moved.
    pub trajectory: Vec<Point3<f64>>,
    /// Length flown, metres.
    pub length: f64,
    /// Flight time, seconds (frames × frame interval).
    pub seconds: f64,
    /// Camera frames taken.
    pub frames: usize,
    /// Depth images integrated.
    pub depth_images: usize,
    /// Pairs the depth stage refused (too short a baseline, no overlap, ...).
    pub depth_refused: usize,
    /// Times the cost field was built and a path planned.
    pub replans: usize,
    /// Per-cycle times.
    pub cycles: Vec<CycleTimes>,
}

/// The prior map: what the vehicle knows of its surroundings before take-off. Six true depth
/// images from the start (four level directions, up and down), cut at the prior radius: the
/// surfaces within it and the free space in front of them, with full confidence.
pub fn integrate_prior(
    scenario: &Scenario,
    map: &mut AnyMap,
    start: &Point3<f64>,
    config: &FlyConfig,
) -> Result<()> {
    let directions = [
        Vector3::x(),
        Vector3::y(),
        -Vector3::x(),
        -Vector3::y(),
        Vector3::new(0.01, 0.0, 1.0),
        Vector3::new(0.01, 0.0, -1.0),
    ];
    let options = IntegrationOptions {
        max_range: Some(config.prior_radius),
    };
    for direction in directions {
        let pose = look_at(*start, direction);
        let k = scenario.intrinsics;
        let view = render(&scenario.scene, &k, &pose, 0, scenario.max_range * 4.0);
        // Sky: far away, so that the ray clears free space up to the prior radius.
        let far = (scenario.max_range * 4.0) as f32;
        let depth: Vec<f32> = view
            .depth
            .iter()
            .map(|z| if z.is_finite() { *z } else { far })
            .collect();
        let image =
            IntervalDepthImage::from_depth(view.width, view.height, &depth, |z| (z, z, 1.0))?;
        map.as_map_mut()
            .integrate_depth(&DepthFrame::new(k, pose, image)?, &options)?;
    }
    Ok(())
}

/// Flies from `goal.start` to `goal.goal` with `map` (which holds what the vehicle knew before;
/// [`integrate_prior`] gives it its surroundings), seeing the scene through the scenario's
/// camera. Deterministic for `seed`. Runs [`Flight::cycle`] until the flight ends.
pub fn fly_goal(
    scenario: &Scenario,
    goal: &Goal,
    map: &mut AnyMap,
    config: &FlyConfig,
    seed: u64,
) -> Result<FlightLog> {
    let mut flight = Flight::new(scenario, goal, map, config, seed)?;
    while flight.ending().is_none() {
        flight.cycle(map)?;
    }
    Ok(flight.into_log())
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
    goal: Goal,
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
    position: Point3<f64>,
    heading: Vector3<f64>,
    pitch: f64,
    /// The camera's pose at the last picture: what the vehicle has just seen.
    camera: Option<Isometry3<f64>>,
    since_plan: usize,
    stalled: usize,
    /// The camera's heading when the vehicle last side-stepped to look ahead (`None` before
    /// the first look).
    looked: Option<Vector3<f64>>,
    /// The frame of the last look aside.
    looked_at: usize,
    /// A step the vehicle held back because it headed outside the last picture: the next
    /// picture looks along it.
    aim: Option<Point3<f64>>,
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
    /// A vehicle at `goal.start` with `map` (its prior knowledge), about to take its first
    /// picture.
    pub fn new(
        scenario: &'a Scenario,
        goal: &Goal,
        map: &AnyMap,
        config: &FlyConfig,
        seed: u64,
    ) -> Result<Self> {
        let config = config.validate()?;
        let resolution = map.as_map().resolution();
        let region = planning_region(&resolution, &goal.start, &goal.goal, &config)?;
        Ok(Self {
            scenario,
            goal: *goal,
            goal_key: resolution.key_of(&goal.goal)?,
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
            position: goal.start,
            heading: level(goal.goal - goal.start).unwrap_or_else(Vector3::x),
            pitch: 0.0,
            camera: None,
            since_plan: 0,
            stalled: 0,
            looked: None,
            looked_at: 0,
            aim: None,
            frame_index: 0,
            max_frames: (config.time_limit / config.frame_interval).ceil() as usize,
            nearest: (goal.goal - goal.start).norm(),
            nearer_at: 0,
            patience_frames: (config.patience / config.frame_interval).ceil() as usize,
            ending: None,
            log: FlightLog {
                ending: Ending::TimeLimit,
                trajectory: vec![goal.start],
                length: 0.0,
                seconds: 0.0,
                frames: 0,
                depth_images: 0,
                depth_refused: 0,
                replans: 0,
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
        if self.frame_index.is_multiple_of(10) {
            let t = Instant::now();
            CostField::build(
                map.as_map(),
                *self.planner.field().region(),
                self.config.planner,
            )?;
            let rebuild = ms(t);
            if let Some(last) = self.log.cycles.last_mut() {
                last.full_rebuild_ms = Some(rebuild);
            }
        }
        self.fly(map);
        self.frame_index += 1;
        Ok(())
    }

    /// The picture the camera takes now: towards the point ahead on the path, or along the
    /// step the vehicle held back last frame because it headed outside the picture (turning at
    /// most [`FlyConfig::max_yaw_rate`], and pitching up or down as the path climbs or
    /// descends, up to [`FlyConfig::max_pitch`]), rendered from the true scene with the frame's
    /// noise.
    pub fn render(&mut self) -> Result<Frame> {
        let turn = self.config.max_yaw_rate.to_radians() * self.config.frame_interval;
        if let Some(ahead) = self.aim.take().or_else(|| {
            self.path
                .as_deref()
                .map(|p| point_ahead(p, self.config.look_ahead))
        }) {
            let to = ahead - self.position;
            if let Some(direction) = level(to) {
                self.heading = turn_towards(self.heading, direction, turn);
            }
            let horizontal = to.x.hypot(to.y);
            let wanted = if horizontal > 1e-6 || to.z.abs() > 1e-6 {
                to.z.atan2(horizontal)
            } else {
                0.0
            };
            let limit = self.config.max_pitch.to_radians();
            let wanted = wanted.clamp(-limit, limit);
            self.pitch += (wanted - self.pitch).clamp(-turn, turn);
        }
        let (sin, cos) = self.pitch.sin_cos();
        let pose = look_at(self.position, self.heading * cos + Vector3::z() * sin);
        self.camera = Some(pose);
        let noise = self
            .seed
            .wrapping_mul(1_000_003)
            .wrapping_add(self.frame_index as u64);
        let scenario = self.scenario;
        let view = render(
            &scenario.scene,
            &scenario.intrinsics,
            &pose,
            noise,
            scenario.max_range * 4.0,
        );
        let time = self.frame_index as f64 * self.config.frame_interval;
        view.to_frame(scenario.intrinsics, pose, time)
    }

    /// The vehicle's own work on a new frame: depth from it and the previous frame(s) into the
    /// map, the cost field updated from the blocks that changed, the path kept or planned
    /// again. Returns (and logs) what each part took.
    pub fn see(&mut self, frame: Frame, map: &mut AnyMap) -> Result<CycleTimes> {
        let mut times = CycleTimes::default();
        self.log.frames += 1;
        if let Some(other) = self.previous.take() {
            let t = Instant::now();
            let result = self.window.depth(frame.clone(), other, &self.params);
            times.depth_ms = ms(t);
            match result {
                Ok(result) => {
                    let weight = result.reuse_weight();
                    let mut depth = result.frame;
                    depth.scale_confidence(weight)?;
                    let t = Instant::now();
                    map.as_map_mut().integrate_depth(&depth, &self.options)?;
                    times.integrate_ms = ms(t);
                    self.log.depth_images += 1;
                }
                Err(_) => self.log.depth_refused += 1,
            }
        }
        self.previous = Some(frame);

        // Update the field from what the frame changed; keep the path while it is clear,
        // otherwise plan again.
        let t = Instant::now();
        self.planner.update(map.as_map());
        let updated = ms(t);
        let t = Instant::now();
        self.guard.add_leaning(
            map.as_map(),
            self.planner.field(),
            &self.position,
            self.config.look_ahead,
            self.config.leaning_occupied as f32,
        );
        self.guard.update(
            self.planner.field(),
            &self.position,
            self.config.unknown_guard,
            self.config.guard_surface_reach,
        );
        times.guard_ms = ms(t);
        let t = Instant::now();
        let guard = &self.guard;
        let avoid = |index: usize| guard.forbids(index);
        let keep = self.since_plan < self.config.replan_every
            && self
                .path
                .as_deref()
                .is_some_and(|p| p.len() >= 2 && self.planner.is_clear_avoiding(p, &avoid));
        if keep {
            self.since_plan += 1;
        } else {
            // A path that goes nowhere (the vehicle's own voxel is the nearest it can reach) is
            // no path: the vehicle side-steps to look, and gives up after `STALL_FRAMES`, instead
            // of hovering on it until the time runs out.
            self.path = replan(self.planner.field(), self.position, self.goal_key, &avoid)
                .ok()
                .filter(|p| p.len() >= 2);
            self.log.replans += 1;
            self.since_plan = 0;
        }
        times.update_replan_ms = updated + ms(t);
        self.log.cycles.push(times);
        Ok(times)
    }

    /// Advances along the path (or side-steps when there is none), checks the step against the
    /// true scene, and ends the flight at a collision, at the goal or after too many frames
    /// without a path.
    fn fly(&mut self, map: &AnyMap) {
        let step = self.config.step();
        let position = self.position;
        let weave = self.path.as_deref().and_then(|p| self.weave(p, step));
        let look = if self.path.as_ref().is_some_and(|p| !p.is_empty()) {
            self.look_aside(step)
        } else {
            None
        };
        let next = match self.path.clone() {
            Some(mut ahead) if !ahead.is_empty() => {
                self.stalled = 0;
                let along = advance(&mut ahead, step);
                let next = match look.or(weave) {
                    Some(next) => next,
                    None if self.sees(along) => {
                        self.path = Some(ahead);
                        along
                    }
                    // The path heads into unknown space the camera has not seen: turn the step
                    // towards the view, or hold and look along the step in the next picture.
                    None => match self.toward_view(along) {
                        Some(next) => next,
                        None => {
                            self.aim = Some(along);
                            return;
                        }
                    },
                };
                if let Some(current) = self.path.as_mut() {
                    current[0] = next;
                }
                next
            }
            _ => {
                // No path: look at the goal and side-step left and right (when the map and
                // the guard hold the step clear), so that the next frames see what blocks the
                // way with a sideways baseline, stereo's best geometry.
                self.stalled += 1;
                if self.stalled >= STALL_FRAMES {
                    self.finish(Ending::NoPath);
                    return;
                }
                self.heading = level(self.goal.goal - position).unwrap_or(self.heading);
                // These side-steps look at the goal with a sideways baseline: the next look
                // aside is due when the camera turns away from this heading.
                self.looked = Some(self.heading);
                let sign = if self.stalled % 2 == 1 { 1.0 } else { -1.0 };
                let next = position + self.heading.cross(&Vector3::z()) * sign * (0.6 * step);
                if !self
                    .planner
                    .is_clear_avoiding(&[position, next], &|i| self.guard.forbids(i))
                    || !self.sees(next)
                {
                    return;
                }
                next
            }
        };
        let radius = self.config.planner.vehicle_radius;
        if self
            .scenario
            .scene
            .intersects_swept_ball(&position, &next, radius)
        {
            self.finish(Ending::Collided);
            return;
        }
        self.log.length += (next - position).norm();
        self.position = next;
        self.log.trajectory.push(next);
        self.log.seconds = (self.frame_index + 1) as f64 * self.config.frame_interval;
        let edge = map.as_map().resolution().size();
        let distance = (next - self.goal.goal).norm();
        if distance <= self.nearest - edge {
            self.nearest = distance;
            self.nearer_at = self.frame_index + 1;
        }
        if distance <= REACHED_VOXELS * edge {
            self.finish(Ending::Reached);
        }
    }

    /// The weaving step: `step` metres in the direction of the path's next waypoint turned by
    /// [`FlyConfig::weave_angle`] to the left or right (the side changes every
    /// [`FlyConfig::weave_frames`] frames), so that the point ahead never lies at the
    /// epipole of the motion, where a moving camera measures no depth. `None` (fly straight)
    /// when weaving is off, the path's next waypoint is within two steps, or the map does not
    /// hold the weaving step and the leg from it to that waypoint clear.
    fn weave(&self, path: &[Point3<f64>], step: f64) -> Option<Point3<f64>> {
        let angle = self.config.weave_angle.to_radians();
        let next_waypoint = *path.get(1)?;
        let towards = next_waypoint - self.position;
        if angle <= 0.0 || towards.norm() < 2.0 * step {
            return None;
        }
        let direction = towards.normalize();
        let side = if (self.frame_index / self.config.weave_frames).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        let axis = nalgebra::Unit::new_normalize(Vector3::z());
        let turned = nalgebra::Rotation3::from_axis_angle(&axis, side * angle) * direction;
        let next = self.position + turned * step;
        (self
            .planner
            .is_clear_avoiding(&[self.position, next, next_waypoint], &|i| {
                self.guard.forbids(i)
            })
            && self.sees(next))
        .then_some(next)
    }

    /// The look-aside step: at take-off, and whenever the camera has turned by more than
    /// [`FlyConfig::look_turn`] since the last look (and at least [`LOOK_FRAMES`] frames after
    /// it; the side-steps of a vehicle without a path, which look at the goal, set the heading
    /// a look compares with), the vehicle steps `step` metres sideways (left, or right when
    /// the map does not hold the left step clear) instead of along its path, so that the next depth image of what lies ahead comes from a sideways baseline
    /// (rectified stereo, the best geometry) rather than from motion along the view, which
    /// measures nothing at the epipole, exactly where the vehicle is going. `None` when the
    /// look is off or not due, or neither side is clear.
    fn look_aside(&mut self, step: f64) -> Option<Point3<f64>> {
        let turn = self.config.look_turn;
        if turn <= 0.0 {
            return None;
        }
        let due = self.looked.is_none_or(|h| {
            h.angle(&self.heading) > turn.to_radians()
                && self.frame_index >= self.looked_at + LOOK_FRAMES
        });
        if !due {
            return None;
        }
        let aside = self.heading.cross(&Vector3::z()) * step;
        let clear = |next: Point3<f64>| {
            self.planner
                .is_clear_avoiding(&[self.position, next], &|i| self.guard.forbids(i))
                && self.sees(next)
        };
        let next = [self.position + aside, self.position - aside]
            .into_iter()
            .find(|&next| clear(next))?;
        self.looked = Some(self.heading);
        self.looked_at = self.frame_index;
        Some(next)
    }

    /// Whether the straight step from the vehicle to `next` keeps out of unknown voxels, or
    /// heads into the picture the camera has just taken ([`VIEW_MARGIN`] inside its edges);
    /// always with [`FlyConfig::blind_steps`].
    /// Unknown space is crossed at a cost, but only where the camera looks: a path that
    /// descends more steeply than the camera pitches (or a step to the side) otherwise flies
    /// the vehicle into space no frame has shown it, such as the inside of a tree crown whose
    /// top it saw from above.
    fn sees(&self, next: Point3<f64>) -> bool {
        self.config.blind_steps || !self.enters_unknown(next) || self.in_view(next)
    }

    /// Whether the direction from the vehicle to `next` lies inside the last picture, at least
    /// [`VIEW_MARGIN`] of its width and height from its edges.
    fn in_view(&self, next: Point3<f64>) -> bool {
        let Some(camera) = self.camera else {
            return false;
        };
        let k = &self.scenario.intrinsics;
        let direction = camera.rotation.inverse() * (next - self.position);
        let Some(pixel) = k.project(&Point3::from(direction)) else {
            return false;
        };
        let (w, h) = (f64::from(k.width()), f64::from(k.height()));
        let (mx, my) = (VIEW_MARGIN * w, VIEW_MARGIN * h);
        (mx..=w - mx).contains(&pixel.x) && (my..=h - my).contains(&pixel.y)
    }

    /// Whether the straight step from the vehicle to `next` passes through an unknown voxel of
    /// the field (or leaves the planning region), sampled every half voxel beyond the
    /// vehicle's own position.
    fn enters_unknown(&self, next: Point3<f64>) -> bool {
        let field = self.planner.field();
        let resolution = field.resolution();
        let region = field.region();
        let step = next - self.position;
        let samples = (step.norm() / (0.5 * resolution.size())).ceil().max(1.0) as usize;
        (1..=samples).any(|i| {
            let p = self.position + step * (i as f64 / samples as f64);
            resolution
                .key_of(&p)
                .ok()
                .and_then(|key| region.index_of(key))
                .is_none_or(|index| field.class(index) == VoxelClass::Unknown)
        })
    }

    /// A step as long as the one to `along`, turned towards the camera's axis (a quarter,
    /// half, three quarters or all the way) until [`Flight::sees`] accepts it and the field
    /// and the guard hold it clear; `None` when no turn does.
    fn toward_view(&self, along: Point3<f64>) -> Option<Point3<f64>> {
        let axis = self.camera?.rotation * Vector3::z();
        let step = along - self.position;
        let (direction, length) = (step.try_normalize(1e-9)?, step.norm());
        [0.25, 0.5, 0.75, 1.0]
            .into_iter()
            .filter_map(|t| (direction * (1.0 - t) + axis * t).try_normalize(1e-9))
            .map(|turned| self.position + turned * length)
            .find(|&next| {
                self.sees(next)
                    && self
                        .planner
                        .is_clear_avoiding(&[self.position, next], &|i| self.guard.forbids(i))
            })
    }

    fn finish(&mut self, ending: Ending) {
        self.ending = Some(ending);
        self.log.ending = ending;
    }
}

/// Plans through `field` from `position` to the goal. When the voxel the vehicle is in cannot
/// be entered (the map learnt that something is near), plans from the nearest traversable
/// voxel within half a metre instead. Never enters a voxel `avoid` names (the start
/// excepted).
fn replan(
    field: &CostField,
    position: Point3<f64>,
    goal: VoxelKey,
    avoid: &dyn Fn(usize) -> bool,
) -> std::result::Result<Vec<Point3<f64>>, PlanError> {
    let resolution = field.resolution();
    let region = *field.region();
    let here = resolution.key_of(&position)?;
    let start = match region.index_of(here) {
        Some(index) if !field.is_traversable(index) => {
            let reach = (0.5 / resolution.size()).ceil() as i32;
            let mut best: Option<(i32, VoxelKey)> = None;
            for dz in -reach..=reach {
                for dy in -reach..=reach {
                    for dx in -reach..=reach {
                        let key = VoxelKey::new(here.x + dx, here.y + dy, here.z + dz);
                        let d2 = dx * dx + dy * dy + dz * dz;
                        if best.is_none_or(|(b, _)| d2 < b)
                            && region
                                .index_of(key)
                                .is_some_and(|i| field.is_traversable(i) && !avoid(i))
                        {
                            best = Some((d2, key));
                        }
                    }
                }
            }
            best.map_or(here, |(_, key)| key)
        }
        _ => here,
    };
    let mut path = match plan_in_field_avoiding(field, start, goal, avoid) {
        // The goal cannot be entered or reached yet: fly to the reachable voxel nearest to
        // it (the known-safe frontier towards the goal), see more, and plan again there.
        Err(PlanError::GoalUnsafe(_) | PlanError::GoalAvoided | PlanError::Disconnected { .. }) => {
            let target = nearest_reachable(field, start, goal, avoid)
                .ok_or(PlanError::Disconnected { expanded: 0 })?;
            if resolution.center(target) == resolution.center(start) {
                return Err(PlanError::Disconnected { expanded: 0 });
            }
            plan_in_field_avoiding(field, start, target, avoid)?
        }
        other => other?,
    };
    // The path starts where the vehicle is, not at its voxel's centre.
    if let Some(first) = path.waypoints.first_mut() {
        *first = position;
    }
    Ok(path.waypoints)
}

/// The traversable voxel connected to `start` (through the field's 26-neighbourhood) nearest
/// to `goal` without entering a voxel `avoid` names, ties to the lowest index; `None` when
/// `start` is not traversable.
fn nearest_reachable(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
    avoid: &dyn Fn(usize) -> bool,
) -> Option<VoxelKey> {
    let region = field.region();
    let first = region
        .index_of(start)
        .filter(|&i| field.is_traversable(i))?;
    let mut seen = vec![false; region.len()];
    let mut queue = std::collections::VecDeque::from([first]);
    seen[first] = true;
    let distance = |key: VoxelKey| {
        let d = [key.x - goal.x, key.y - goal.y, key.z - goal.z].map(i64::from);
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    };
    let mut best = (distance(start), first);
    while let Some(index) = queue.pop_front() {
        let key = region.key_at(index);
        let d = distance(key);
        if d < best.0 || (d == best.0 && index < best.1) {
            best = (d, index);
        }
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let next = VoxelKey::new(key.x + dx, key.y + dy, key.z + dz);
                    if let Some(n) = region.index_of(next)
                        && !seen[n]
                        && field.is_traversable(n)
                        && !avoid(n)
                    {
                        seen[n] = true;
                        queue.push_back(n);
                    }
                }
            }
        }
    }
    Some(region.key_at(best.1))
}

/// Moves `step` metres along `path` (its first point is the vehicle) and returns the new
/// position; the path loses the waypoints passed and starts at the new position.
fn advance(path: &mut Vec<Point3<f64>>, step: f64) -> Point3<f64> {
    let mut left = step;
    while path.len() >= 2 {
        let (a, b) = (path[0], path[1]);
        let leg = (b - a).norm();
        if leg > left {
            let p = a + (b - a) * (left / leg);
            path[0] = p;
            return p;
        }
        left -= leg;
        path.remove(0);
    }
    path.first().copied().unwrap_or(Point3::origin())
}

/// The point `distance` metres along `path` (its end when the path is shorter; paths from the
/// planner are never empty).
fn point_ahead(path: &[Point3<f64>], distance: f64) -> Point3<f64> {
    let mut left = distance;
    for pair in path.windows(2) {
        let leg = (pair[1] - pair[0]).norm();
        if leg >= left {
            return pair[0] + (pair[1] - pair[0]) * (left / leg.max(1e-12));
        }
        left -= leg;
    }
    path.last().copied().unwrap_or(Point3::origin())
}

/// `from` turned about the vertical towards `to` (both level unit vectors) by at most `max`
/// radians (`to` itself when it is that near).
fn turn_towards(from: Vector3<f64>, to: Vector3<f64>, max: f64) -> Vector3<f64> {
    let angle = from.x.mul_add(to.y, -(from.y * to.x)).atan2(from.dot(&to));
    if angle.abs() <= max {
        return to;
    }
    let turn = angle.clamp(-max, max);
    let (sin, cos) = turn.sin_cos();
    Vector3::new(
        from.x * cos - from.y * sin,
        from.x * sin + from.y * cos,
        0.0,
    )
}

/// The horizontal part of `v`, normalised; `None` when it is (nearly) vertical.
fn level(v: Vector3<f64>) -> Option<Vector3<f64>> {
    Vector3::new(v.x, v.y, 0.0).try_normalize(1e-6)
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advancing_follows_the_polyline() {
        let mut path = vec![
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(1.0, 0.0, 1.0),
            Point3::new(1.0, 2.0, 1.0),
        ];
        let p = advance(&mut path, 0.5);
        assert_eq!(p, Point3::new(0.5, 0.0, 1.0));
        let p = advance(&mut path, 1.0);
        assert!((p - Point3::new(1.0, 0.5, 1.0)).norm() < 1e-12);
        assert_eq!(path.len(), 2);
        let p = advance(&mut path, 5.0);
        assert_eq!(p, Point3::new(1.0, 2.0, 1.0));
        assert_eq!(point_ahead(&[Point3::origin()], 3.0), Point3::origin());
    }

    #[test]
    fn the_camera_turns_at_most_its_rate() {
        let (x, y) = (Vector3::x(), Vector3::y());
        let max = 22.5f64.to_radians();
        // A quarter turn to the left takes four frames, the first one 22.5° of it.
        let first = turn_towards(x, y, max);
        assert!((first.y.atan2(first.x) - max).abs() < 1e-12, "{first:?}");
        // To the right as well; a small turn is made at once.
        let right = turn_towards(x, -y, max);
        assert!((right.y.atan2(right.x) + max).abs() < 1e-12, "{right:?}");
        let small = Vector3::new(1.0, 0.1, 0.0).normalize();
        assert!((turn_towards(x, small, max) - small).norm() < 1e-12);
        assert!((turn_towards(x, x, max) - x).norm() < 1e-15);
    }
}
