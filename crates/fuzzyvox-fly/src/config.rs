//! The closed loop's parameters.

use serde::Serialize;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_plan::{PlannerConfig, UnknownPolicy};

/// Every setting of a closed-loop flight, in one value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlyConfig {
    /// Voxel size of the maps, metres. Default 0.2.
    pub resolution: f64,
    /// Cruise speed, metres per second. Default 2.
    pub speed: f64,
    /// Time between frames, seconds: each cycle advances `speed × frame_interval` metres.
    /// Default 0.25 (0.5 m per frame).
    pub frame_interval: f64,
    /// A flight that has not reached its goal after this many seconds ends. Default: 60.
    pub time_limit: f64,
    /// A flight that has come no nearer to its goal (by a voxel edge) for this many seconds
    /// ends as stuck: a vehicle dithering in front of a goal its map will not let it enter
    /// reports so instead of hovering until the time limit. Default 15 (a detour round a
    /// building takes a few seconds of flying away from the goal).
    pub patience: f64,
    /// Camera views per depth image (2: the current and the previous frame). Default 2.
    pub views: usize,
    /// Nearest depth the depth stage looks for, metres. A plane sweep's planes, and so its
    /// time, grow with `1 / min_depth`; at the default speed a surface nearer than 1 m was
    /// in view from farther away two frames before. Default 1.
    pub min_depth: f64,
    /// Depth images are integrated up to this distance from the camera, metres (the scene's
    /// own range when that is shorter). With a baseline of one step, depth beyond it is too
    /// uncertain to matter, and the integration's time grows with the cube of the range.
    /// Default 20.
    pub map_range: f64,
    /// Planner settings; the vehicle radius is also the radius of the collision check against
    /// the true scene. Default: the planner's defaults with unknown space allowed at a cost of
    /// 2 per metre (goals lie in space nobody has seen yet).
    pub planner: PlannerConfig,
    /// Radius of the prior map around the start, metres: what the vehicle knows before it
    /// takes off (the true surfaces and free space within this distance, seen from the start
    /// in six directions). Default 2.
    pub prior_radius: f64,
    /// The camera looks at the point this far ahead along the current path (horizontally).
    /// Default 3 m.
    pub look_ahead: f64,
    /// The camera turns (yaws) at most this fast, degrees per second, so that consecutive
    /// frames overlap and the depth stage can match them even when the path turns sharply.
    /// Default 720 (180° per frame at the default frame interval: no limit).
    pub max_yaw_rate: f64,
    /// The camera pitches towards the point ahead when the path climbs or descends, at most
    /// this many degrees up or down (turning at the yaw rate's limit), so that it sees what a
    /// climb or descent flies into (a level camera does not see the top of a box the path
    /// crosses). 0 keeps the camera level. Default 30.
    pub max_pitch: f64,
    /// The vehicle weaves: each step leaves the direction of the path's next waypoint by this
    /// angle, degrees, to the left and then to the right, so that what lies straight ahead on
    /// the path is never at the epipole of the camera's motion (where depth from motion is
    /// undefined). 0 flies straight. Default 0.
    pub weave_angle: f64,
    /// The vehicle looks aside before it flies into what it has not seen: at take-off, and
    /// whenever the camera has turned by more than this angle, degrees, since it last did, its
    /// next step goes sideways instead of along the path, so that the view ahead gets a
    /// sideways baseline. 0 turns it off. Default 45.
    pub look_turn: f64,
    /// Frames between changes of the weaving side. Default 2.
    pub weave_frames: usize,
    /// The planner keeps its path while it stays valid, but replans at least every this many
    /// frames to use what the map has learnt. Default 8.
    pub replan_every: usize,
    /// That periodic replan only looks for a better path while the current one stays clear,
    /// so it gives up after expanding this many voxels and keeps the path (a path that is no
    /// longer clear is replanned without a limit). It keeps a frame from paying a long search
    /// for an improvement: 20,000 voxels is about 8 ms. Default 20,000.
    pub replan_budget: usize,
    /// A path that is no longer clear is first repaired: A* from the vehicle to the first
    /// voxel of the path past its last blocked one, expanding at most this many voxels, and
    /// the rest of the path as it was ([`repair_in_field`](fuzzyvox_plan::repair_in_field)).
    /// Only when that fails is it replanned without a limit. 0 turns repairs off. Default
    /// 5,000.
    pub repair_budget: usize,
    /// A repair's detour rejoins the old path this far past the last voxel that blocks it,
    /// metres (along the path; the path's end when that is nearer), so that it goes round
    /// the blocked stretch instead of hugging it back onto the old line. Default 1.5.
    pub repair_rejoin: f64,
    /// The unseen-surface guard collects, within this distance of the vehicle, metres, the
    /// unknown voxels next to surfaces the map has seen, and the planner neither enters them
    /// nor passes within the vehicle's radius of them, whatever the unknown-space policy: see
    /// [`UnknownGuard`](super::guard::UnknownGuard). 0 turns the guard off. Default 0 (off).
    pub unknown_guard: f64,
    /// The guard forbids only unknown voxels within this distance of an occupied or ambiguous
    /// voxel, metres: the unseen parts of surfaces the map has begun to see. Default 0.6.
    pub guard_surface_reach: f64,
    /// Within [`FlyConfig::look_ahead`] of the vehicle, unknown voxels whose occupied
    /// membership is at least this (and above their free membership) are forbidden, with every
    /// voxel within the vehicle's radius of them, whatever the guard's radius: the map has seen
    /// a surface there, though not confidently enough to call it occupied (see
    /// [`UnknownGuard`](super::guard::UnknownGuard)). Above 1 turns it off. Default 0.2.
    pub leaning_occupied: f64,
    /// Steps into unknown space may head outside the camera's last picture. By default
    /// (`false`) a step that would enter an unknown voxel must head at least
    /// [`VIEW_MARGIN`](super::flight::VIEW_MARGIN) inside the picture's edges; otherwise it
    /// turns towards the camera's axis, or the vehicle waits a frame for the camera to turn:
    /// unknown space is crossed only where the camera has just looked. `true` keeps the
    /// earlier behaviour, for comparison. Default false.
    pub blind_steps: bool,
    /// Horizontal margin of the planning region around start and goal, metres. Default 6.
    pub region_margin: f64,
}

impl Default for FlyConfig {
    fn default() -> Self {
        Self {
            resolution: 0.2,
            speed: 2.0,
            frame_interval: 0.25,
            time_limit: 60.0,
            patience: 15.0,
            views: 2,
            min_depth: 1.0,
            map_range: 20.0,
            planner: PlannerConfig {
                unknown: UnknownPolicy::Cost(2.0),
                ..PlannerConfig::default()
            },
            prior_radius: 2.0,
            look_ahead: 3.0,
            max_yaw_rate: 720.0,
            weave_angle: 0.0,
            max_pitch: 30.0,
            look_turn: 45.0,
            weave_frames: 2,
            replan_every: 8,
            replan_budget: 20_000,
            repair_budget: 5_000,
            repair_rejoin: 1.5,
            unknown_guard: 0.0,
            guard_surface_reach: 0.6,
            leaning_occupied: 0.2,
            blind_steps: false,
            region_margin: 6.0,
        }
    }
}

impl FlyConfig {
    /// Checks every value.
    pub fn validate(self) -> Result<Self> {
        let positive = |name: &'static str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name,
                    value,
                    expected: "a finite value > 0",
                })
            }
        };
        positive("resolution", self.resolution)?;
        positive("speed", self.speed)?;
        positive("frame interval", self.frame_interval)?;
        positive("time limit", self.time_limit)?;
        positive("patience", self.patience)?;
        positive("prior radius", self.prior_radius)?;
        positive("look-ahead", self.look_ahead)?;
        positive("maximum yaw rate", self.max_yaw_rate)?;
        positive("region margin", self.region_margin)?;
        positive("minimum depth", self.min_depth)?;
        positive("map range", self.map_range)?;
        for (name, value) in [
            ("unknown guard", self.unknown_guard),
            ("guard surface reach", self.guard_surface_reach),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    expected: "a finite distance >= 0 m",
                });
            }
        }
        if !(self.leaning_occupied.is_finite() && self.leaning_occupied > 0.0) {
            return Err(Error::InvalidParameter {
                name: "leaning occupied",
                value: self.leaning_occupied,
                expected: "a finite membership > 0 (above 1 turns it off)",
            });
        }
        for (name, value) in [
            ("maximum pitch", self.max_pitch),
            ("weave angle", self.weave_angle),
        ] {
            if !(0.0..=80.0).contains(&value) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    expected: "an angle from 0 to 80 degrees",
                });
            }
        }
        if !(0.0..=180.0).contains(&self.look_turn) {
            return Err(Error::InvalidParameter {
                name: "look turn",
                value: self.look_turn,
                expected: "an angle from 0 to 180 degrees",
            });
        }
        if self.weave_frames == 0 {
            return Err(Error::InvalidParameter {
                name: "weave frames",
                value: 0.0,
                expected: "at least 1 frame",
            });
        }
        if !(2..=17).contains(&self.views) {
            return Err(Error::InvalidParameter {
                name: "views",
                value: self.views as f64,
                expected: "2 to 17 camera views per depth image",
            });
        }
        if self.replan_every == 0 {
            return Err(Error::InvalidParameter {
                name: "replan every",
                value: 0.0,
                expected: "at least 1 frame",
            });
        }
        if self.replan_budget == 0 {
            return Err(Error::InvalidParameter {
                name: "replan budget",
                value: 0.0,
                expected: "at least 1 voxel",
            });
        }
        if !(self.repair_rejoin.is_finite() && self.repair_rejoin >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "repair rejoin",
                value: self.repair_rejoin,
                expected: "a finite distance of at least 0 m",
            });
        }
        self.planner.validate()?;
        Ok(self)
    }

    /// Metres flown per frame.
    pub fn step(&self) -> f64 {
        self.speed * self.frame_interval
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defaults are valid; a loop that never replans, or a replan that may expand no
    /// voxel, is refused with the setting's name.
    #[test]
    fn out_of_range_settings_are_named() {
        assert!(FlyConfig::default().validate().is_ok());
        let no_repairs = FlyConfig {
            repair_budget: 0,
            ..FlyConfig::default()
        };
        assert!(no_repairs.validate().is_ok());
        for (config, setting) in [
            (
                FlyConfig {
                    replan_every: 0,
                    ..FlyConfig::default()
                },
                "replan every",
            ),
            (
                FlyConfig {
                    replan_budget: 0,
                    ..FlyConfig::default()
                },
                "replan budget",
            ),
            (
                FlyConfig {
                    repair_rejoin: f64::NAN,
                    ..FlyConfig::default()
                },
                "repair rejoin",
            ),
            (
                FlyConfig {
                    repair_rejoin: -1.0,
                    ..FlyConfig::default()
                },
                "repair rejoin",
            ),
        ] {
            assert!(
                matches!(config.validate(), Err(Error::InvalidParameter { name, .. }) if name == setting),
                "{setting}"
            );
        }
    }
}
