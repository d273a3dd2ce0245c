//! What the vehicle does with each picture: the camera renders it, the depth stage matches it
//! against the previous views, the depth image goes into the map, the planner updates its cost
//! field, and the path is kept while it stays clear or planned again.

use std::time::Instant;

use fuzzyvox_core::error::Result;
use fuzzyvox_core::map::AnyMap;
use fuzzyvox_depth::Frame;
use fuzzyvox_sim::render;
use fuzzyvox_sim::trajectory::look_at;
use nalgebra::Vector3;

use super::geometry::{level, point_ahead, turn_towards};
use super::log::CycleTimes;
use super::replan::{ReplanInputs, Replanned, repair, replan};
use super::{Flight, Sight};

impl Flight<'_> {
    /// The picture the camera takes now: towards the point ahead on the path, or along the
    /// step the vehicle held back last frame because it headed outside the picture (turning at
    /// most [`FlyConfig::max_yaw_rate`](crate::FlyConfig::max_yaw_rate), and pitching up or
    /// down as the path climbs or descends, up to
    /// [`FlyConfig::max_pitch`](crate::FlyConfig::max_pitch)), rendered from the true scene
    /// with the frame's noise.
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
                    let quality = result.quality;
                    let mut depth = result.frame;
                    depth.scale_confidence(weight)?;
                    let t = Instant::now();
                    map.as_map_mut().integrate_depth(&depth, &self.options)?;
                    times.integrate_ms = ms(t);
                    self.log.depth_images += 1;
                    self.sight = Some(Sight::new(
                        depth,
                        quality,
                        frame.image(),
                        &self.params.matching,
                    ));
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
        let clear = self
            .path
            .as_deref()
            .is_some_and(|p| p.len() >= 2 && self.planner.is_path_clear_avoiding(p, &avoid));
        let repaired = if clear || self.config.repair_budget == 0 {
            None
        } else {
            // A blocked path is first repaired round what blocks it, within a budget.
            self.path.as_deref().and_then(|old| {
                repair(
                    self.planner.field(),
                    self.position,
                    old,
                    &avoid,
                    self.config.repair_rejoin,
                    self.config.repair_budget,
                )
            })
        };
        if let Some(path) = repaired {
            self.path = Some(path);
            self.log.repairs += 1;
        } else if clear && self.since_plan < self.config.replan_every {
            self.since_plan += 1;
        } else {
            // A clear path is only looked at again for a better one, within the budget; a
            // blocked one is replanned whatever it costs. A path that goes nowhere (the
            // vehicle's own voxel is the nearest it can reach) is no path: the vehicle
            // side-steps to look, and gives up after `STALL_FRAMES`, instead of hovering on it
            // until the time runs out.
            let limit = if clear {
                self.config.replan_budget
            } else {
                usize::MAX
            };
            let inputs = ReplanInputs {
                generation: self.planner.generation(),
                forbidden: guard.forbidden_voxels().to_vec(),
                position: self.position,
                limit,
            };
            let (planner, position, goal) = (&self.planner, self.position, self.goal_key);
            let outcome = self.last_replan.outcome(inputs, || {
                replan(planner.field(), position, goal, &avoid, limit)
            });
            match outcome {
                Replanned::Path(path) => self.path = Some(path).filter(|p| p.len() >= 2),
                Replanned::Kept => {}
                Replanned::Failed => self.path = None,
            }
            self.log.replans += 1;
            self.since_plan = 0;
        }
        times.update_replan_ms = updated + ms(t);
        self.log.cycles.push(times);
        Ok(times)
    }
}

/// Milliseconds since `t`.
fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
