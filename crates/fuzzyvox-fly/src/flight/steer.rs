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

/// A step into unknown space must not head at something the last depth image shows within
/// reach: it is refused when at least this share of the image's pixels around the step's
/// direction (within the vehicle's outline) that hold a depth, of any confidence, hold one
/// nearer than [`FlyConfig::min_depth`](crate::FlyConfig::min_depth) beyond the step's end.
/// Once the vehicle is that near, the depth stage no longer looks there.
pub const NEAR_SHARE: f64 = 0.1;

/// A depth image that holds a depth in fewer than this share of its picture's textured pixels
/// is blind: the picture shows something, but the camera is too near it for the depth stage to
/// match it. Every step into unknown space counts as heading at something within reach until a
/// better picture comes. Texture-less pixels (the sky, a view that runs out of the scene) get
/// no depth whatever their distance, so they do not count: a camera that looks at the sky is
/// not blind.
pub const BLIND_SHARE: f64 = 0.05;

/// The least quality (`Q_ABD`, `fuzzyvox_depth::quality`) of the pair behind a depth image for
/// [`BLIND_SHARE`] to apply. A pair whose baseline runs along the view (a step straight ahead
/// or straight back) measures nothing around the epipole, the middle of its picture, whatever
/// lies there: its lack of depth says nothing of what is near.
pub const BLIND_QUALITY: f64 = 0.1;

/// The share of those pixels that must hold a depth at all for [`NEAR_SHARE`] to apply (the
/// sky holds none).
pub const DEPTH_SHARE: f64 = 0.01;

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
                    // The path heads into unknown space the camera has not seen, or at
                    // something within reach: turn the step towards the view, or step aside so
                    // that the next picture has a baseline across the view, or hold and look
                    // along the step in the next picture. A picture taken where the vehicle
                    // held has no baseline and gives no depth, so after one hold the vehicle
                    // steps back to where it was before instead.
                    None => match self
                        .toward_view(along)
                        .or_else(|| self.side_step(step, self.frame_index % 2 == 1))
                        .or_else(|| self.held.then(|| self.step_back()).flatten())
                    {
                        Some(next) => next,
                        None => {
                            self.aim = Some(along);
                            self.held = true;
                            return;
                        }
                    },
                };
                if let Some(current) = self.path.as_mut() {
                    current[0] = next;
                }
                self.held = false;
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
        let next = self.side_step(step, false)?;
        self.looked = Some(self.heading);
        self.looked_at = self.frame_index;
        Some(next)
    }

    /// The step back to the last position the vehicle flew from: the space the vehicle has
    /// just flown through is free whatever its map says, and the step gives the next picture a
    /// baseline.
    fn step_back(&self) -> Option<Point3<f64>> {
        self.log
            .trajectory
            .iter()
            .rev()
            .find(|p| (*p - self.position).norm() > 1e-6)
            .copied()
    }

    /// A step of `step` metres square to the camera's heading, to the left (to the right first
    /// when `right_first`), or the other way when the map and the guard do not hold the first
    /// clear or [`Flight::sees`] refuses it; `None` when neither side will do.
    fn side_step(&self, step: f64, right_first: bool) -> Option<Point3<f64>> {
        let aside = self.heading.cross(&Vector3::z()) * step;
        let sides = if right_first {
            [self.position - aside, self.position + aside]
        } else {
            [self.position + aside, self.position - aside]
        };
        sides.into_iter().find(|&next| {
            self.planner
                .is_clear_avoiding(&[self.position, next], &|i| self.guard.forbids(i))
                && self.sees(next)
        })
    }

    /// Whether the straight step from the vehicle to `next` keeps out of unknown voxels, or
    /// heads into the picture the camera has just taken ([`VIEW_MARGIN`] inside its edges) and
    /// not at something its depth image shows within reach ([`Flight::near_ahead`]); always with
    /// [`FlyConfig::blind_steps`].
    /// Unknown space is crossed at a cost, but only where the camera looks: a path that
    /// descends more steeply than the camera pitches (or a step to the side) otherwise flies
    /// the vehicle into space no frame has shown it, such as the inside of a tree crown whose
    /// top it saw from above.
    fn sees(&self, next: Point3<f64>) -> bool {
        self.config.blind_steps
            || !self.enters_unknown(next)
            || (self.in_view(next) && !self.near_ahead(next))
    }

    /// Whether the last depth image shows something within reach ahead of the step to `next`:
    /// of its pixels within the vehicle's outline around the direction of the step, seen at
    /// [`FlyConfig::min_depth`] beyond the step's end, at least [`NEAR_SHARE`] of those that
    /// hold a depth (when at least [`DEPTH_SHARE`] of them do) hold one nearer than that. Depth
    /// of any confidence counts: a camera flying straight at a surface puts it at the epipole
    /// of its motion, where the depth stage finds it but trusts it too little for the map, and
    /// once the vehicle is nearer than the least depth the stage looks for, no picture will
    /// show it again. A blind image ([`BLIND_SHARE`]) counts as showing something everywhere.
    /// Reads the last depth image the vehicle got (a picture taken where it held gives none);
    /// `false` before the first one and when the direction lies outside it.
    fn near_ahead(&self, next: Point3<f64>) -> bool {
        let (Some(sight), Some(direction)) =
            (&self.sight, (next - self.position).try_normalize(1e-9))
        else {
            return false;
        };
        if sight.blind {
            return true;
        }
        let reach = self.config.min_depth + (next - self.position).norm();
        let sight = &sight.frame;
        let k = sight.intrinsics();
        let local = sight
            .world_from_camera()
            .inverse_transform_point(&(self.position + direction * reach));
        let Some(pixel) = k.project(&local) else {
            return false;
        };
        let image = sight.image();
        let (w, h) = (i64::from(image.width()), i64::from(image.height()));
        let r = (k.fx() * self.config.planner.vehicle_radius / local.z)
            .ceil()
            .clamp(0.0, (w + h) as f64) as i64;
        let (u, v) = (pixel.x.floor() as i64, pixel.y.floor() as i64);
        let depth = image.depth();
        let reach = reach as f32;
        let (mut pixels, mut measured, mut near) = (0usize, 0usize, 0usize);
        for y in (v - r).max(0)..=(v + r).min(h - 1) {
            for x in (u - r).max(0)..=(u + r).min(w - 1) {
                if (x - u).pow(2) + (y - v).pow(2) > r * r {
                    continue;
                }
                pixels += 1;
                let index = (y * w + x) as usize;
                if image.has_depth(index) {
                    measured += 1;
                    near += usize::from(depth[index] < reach);
                }
            }
        }
        measured as f64 >= DEPTH_SHARE * pixels as f64
            && measured > 0
            && near as f64 >= NEAR_SHARE * measured as f64
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use fuzzyvox_core::image::GrayImage;
    use fuzzyvox_core::integrate::{DepthFrame, IntervalDepthImage};
    use fuzzyvox_core::map::MapKind;
    use fuzzyvox_depth::MatchParams;
    use fuzzyvox_sim::scenario;
    use fuzzyvox_sim::trajectory::look_at;

    use super::*;
    use crate::FlyConfig;
    use crate::flight::Sight;

    /// Whether a flight at `start`, looking along +x with a depth image whose pixels hold
    /// `depth(column, row)`, matched from a textured picture, finds something within reach of
    /// a step of 0.5 m along +x.
    fn near_ahead_with(depth: impl Fn(u32, u32) -> f32) -> bool {
        near_ahead_seeing(depth, true, 1.0)
    }

    /// [`near_ahead_with`] from a picture that is textured everywhere, or blank (one grey
    /// level, as the sky) when `textured` is false, matched by a pair of quality `quality`.
    fn near_ahead_seeing(depth: impl Fn(u32, u32) -> f32, textured: bool, quality: f64) -> bool {
        let scenario = scenario::wall().unwrap();
        let config = FlyConfig::default();
        let start = Point3::new(0.0, 0.0, 3.0);
        let goal = Point3::new(8.0, 0.0, 3.0);
        let map = MapKind::Fuzzy.new_map(config.resolution).unwrap();
        let mut flight = Flight::new(&scenario, &start, &goal, &map, &config, 1).unwrap();
        let k = scenario.intrinsics;
        let (w, h) = (k.width(), k.height());
        let plane: Vec<f32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| depth(x, y))
            .collect();
        let near: Vec<f32> = plane.iter().map(|z| z * 0.9).collect();
        let far: Vec<f32> = plane.iter().map(|z| z * 1.1).collect();
        let confidence = vec![0.01; plane.len()];
        let image = IntervalDepthImage::new(w, h, near, plane, far, confidence).unwrap();
        let pose = look_at(start, Vector3::x());
        let grey = (0..w * h)
            .map(|i| {
                if textured {
                    0.2 + 0.6 * ((i.wrapping_mul(2_654_435_761) >> 7) % 101) as f32 / 100.0
                } else {
                    0.5
                }
            })
            .collect();
        let picture = GrayImage::new(w, h, grey).unwrap();
        let depth = DepthFrame::new(k, pose, image).unwrap();
        flight.sight = Some(Sight::new(
            depth,
            quality,
            &picture,
            &MatchParams::default(),
        ));
        flight.near_ahead(start + Vector3::x() * 0.5)
    }

    #[test]
    fn a_step_at_depth_within_reach_is_refused_whatever_its_confidence() {
        // A surface 1.2 m ahead, nearer than the least depth (1 m) beyond the step's end:
        // refused, though every pixel's confidence is 0.01.
        assert!(near_ahead_with(|_, _| 1.2));
        // Far depth lets the step go on.
        assert!(!near_ahead_with(|_, _| 12.0));
        // A textured picture with (almost) no depth anywhere is blind: refused.
        assert!(near_ahead_with(|_, _| f32::NAN));
        assert!(near_ahead_with(|x, y| if x == 0 && y == 0 {
            12.0
        } else {
            f32::NAN
        }));
        // A blank one (the sky) is not: texture-less pixels get no depth at any distance.
        assert!(!near_ahead_seeing(|_, _| f32::NAN, false, 1.0));
        // Nor is one from a pair whose baseline runs along the view, which measures nothing
        // around the middle of its picture whatever lies there.
        assert!(!near_ahead_seeing(|_, _| f32::NAN, true, 0.05));
        // No depth straight ahead in a picture that has some elsewhere (the sky above the
        // ground) lets the step go on.
        let k = scenario::camera().unwrap();
        let ground = k.height() * 3 / 4;
        assert!(!near_ahead_with(|_, y| if y > ground {
            12.0
        } else {
            f32::NAN
        }));
        // A few stray near matches among far ones do not stop it; a tenth of them does.
        let scattered = |every: u32| {
            move |x: u32, y: u32| {
                if (x + y).is_multiple_of(every) {
                    1.2
                } else {
                    12.0
                }
            }
        };
        assert!(!near_ahead_with(scattered(20)));
        assert!(near_ahead_with(scattered(5)));
        // Near depth off to the side of the step's direction does not count.
        let left_edge = (k.width() / 8) as f32;
        assert!(!near_ahead_with(|x, _| if (x as f32) < left_edge {
            1.2
        } else {
            12.0
        }));
    }
}
