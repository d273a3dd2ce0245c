//! The step along the path: weaving, looking aside before flying into what the camera has not
//! seen, the view rule for steps into unknown space, and the true scene's check of the step.

use fuzzyvox_core::map::AnyMap;
use fuzzyvox_core::measures::VoxelClass;
use nalgebra::{Point3, Vector3};

use super::Flight;
use super::geometry::{advance, level};
use super::log::Ending;

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

impl Flight<'_> {
    /// Advances along the path (or side-steps when there is none), checks the step against the
    /// true scene, and ends the flight at a collision, at the goal or after too many frames
    /// without a path.
    pub(super) fn fly(&mut self, map: &AnyMap) {
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
                self.heading = level(self.goal - position).unwrap_or(self.heading);
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
        let distance = (next - self.goal).norm();
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
}
