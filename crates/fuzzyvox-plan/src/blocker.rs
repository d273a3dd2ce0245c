use std::fmt;

use nalgebra::Point3;
use serde::{Serialize, Serializer};

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_core::storage::{KeyBox, Resolution, VoxelKey};

/// Why the planner may not enter the voxel of a start or goal, with the numbers a user needs
/// to change the request: the class of the voxel, its safety, or its clearance and the blocked
/// voxel nearest to it.
///
/// `Display` gives one sentence that says what blocks the point and which setting would
/// change that (the unknown-space policy, the safety threshold, the vehicle radius, or none:
/// occupied and ambiguous voxels are never entered). Serialized (for JSON output) as an object
/// whose `kind` names the variant in snake case.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Blocker {
    /// The point lies outside the box of the map's observed voxels, where the map knows
    /// nothing, and unknown space is forbidden.
    OutsideObservedExtent {
        /// The point asked for.
        point: Point3<f64>,
        /// The box of the map's observed voxels.
        extent: ObservedExtent,
    },
    /// The voxel is unknown (inside the observed extent) and unknown space is forbidden.
    Unknown,
    /// The voxel is occupied: never entered.
    Occupied {
        /// The voxel's safety.
        safety: f32,
    },
    /// The voxel is ambiguous (its evidence conflicts): never entered.
    Ambiguous {
        /// The voxel's safety.
        safety: f32,
    },
    /// The voxel is free but its safety is below the threshold.
    LowSafety {
        /// The voxel's safety.
        safety: f32,
        /// The planner's safety threshold.
        threshold: f32,
    },
    /// The voxel itself may be entered, but a blocked voxel is closer than the vehicle needs.
    TooClose {
        /// Distance (metres) from the voxel's centre to the nearest blocked voxel centre.
        clearance: f64,
        /// The clearance the vehicle needs: its radius plus `√3 × resolution`.
        required: f64,
        /// The vehicle radius the planner was given.
        vehicle_radius: f64,
        /// The largest vehicle radius for which this voxel could be entered (negative when no
        /// radius would do).
        largest_radius: f64,
        /// The nearest blocked voxel, or `None` when the nearest blocked space is the edge of
        /// the planning region (only possible with a hand-made region).
        nearest: Option<NearestBlocked>,
    },
}

/// The blocked voxel nearest to a point the planner rejected for lack of clearance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NearestBlocked {
    /// Centre of the blocked voxel, in world coordinates.
    pub center: Point3<f64>,
    /// Its class (a free voxel here is blocked by its low safety).
    #[serde(serialize_with = "class_name")]
    pub class: VoxelClass,
    /// Its safety.
    pub safety: f32,
    /// Distance (metres) between the two voxel centres.
    pub distance: f64,
}

/// The box of a map's observed voxels (every voxel some evidence reached), in metres, from the
/// lowest corner of the lowest voxel to the highest corner of the highest one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ObservedExtent {
    /// The lowest corner.
    pub min: Point3<f64>,
    /// The highest corner.
    pub max: Point3<f64>,
    #[serde(skip)]
    keys: KeyBox,
}

impl ObservedExtent {
    /// The extent of `map`'s observed voxels, or `None` when the map lists none (an empty map,
    /// or one such as [`FunctionMap`](fuzzyvox_core::map::FunctionMap) that has no stored voxels).
    ///
    /// Visits every stored voxel, so it costs about as much as `fuzzyvox info`.
    pub fn of(map: &dyn VoxelMap) -> Option<Self> {
        let keys = map.cells().fold(None, |acc: Option<KeyBox>, (key, _)| {
            Some(match acc {
                None => KeyBox::new(key, key),
                Some(b) => KeyBox {
                    min: VoxelKey::new(b.min.x.min(key.x), b.min.y.min(key.y), b.min.z.min(key.z)),
                    max: VoxelKey::new(b.max.x.max(key.x), b.max.y.max(key.y), b.max.z.max(key.z)),
                },
            })
        })?;
        Some(Self::from_keys(&map.resolution(), keys))
    }

    /// The extent of a box of voxels.
    pub fn from_keys(resolution: &Resolution, keys: KeyBox) -> Self {
        let beyond = VoxelKey::new(
            keys.max.x.saturating_add(1),
            keys.max.y.saturating_add(1),
            keys.max.z.saturating_add(1),
        );
        Self {
            min: resolution.corner(keys.min),
            max: resolution.corner(beyond),
            keys,
        }
    }

    /// The observed voxels' keys.
    pub fn keys(&self) -> KeyBox {
        self.keys
    }

    /// Whether a voxel lies inside.
    pub fn contains(&self, key: VoxelKey) -> bool {
        self.keys.contains(key)
    }
}

impl fmt::Display for ObservedExtent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (a, b) = (self.min, self.max);
        write!(
            f,
            "[{:.2}, {:.2}, {:.2}] to [{:.2}, {:.2}, {:.2}] m",
            a.x, a.y, a.z, b.x, b.y, b.z
        )
    }
}

impl Blocker {
    /// The highest safety threshold, in hundredths, under which the planner would accept the
    /// blocked voxel: the voxel's own for [`Blocker::LowSafety`], the nearest blocked voxel's
    /// for [`Blocker::TooClose`] when that one is free but not safe enough.
    pub fn safety_to_accept(&self) -> Option<f32> {
        match self {
            Self::LowSafety { safety, .. } => Some(safety_to_accept(*safety)),
            Self::TooClose {
                nearest: Some(n), ..
            } if n.class == VoxelClass::Free => Some(safety_to_accept(n.safety)),
            _ => None,
        }
    }

    /// The largest vehicle radius, in whole centimetres, for which a [`Blocker::TooClose`]
    /// voxel has enough clearance; `None` for other blockers and when no radius would do.
    pub fn radius_to_fit(&self) -> Option<f64> {
        match self {
            // Rounded down, less a hair, so that the printed value fits when typed back.
            Self::TooClose { largest_radius, .. } if *largest_radius >= 0.0 => {
                Some(((largest_radius - 1e-6) * 100.0).floor().max(0.0) / 100.0)
            }
            _ => None,
        }
    }
}

/// The highest threshold in hundredths that a voxel of this safety passes (`safety >=
/// threshold`, compared in `f32` as the cost field does).
fn safety_to_accept(safety: f32) -> f32 {
    let mut cents = (f64::from(safety) * 100.0 + 1e-3).floor().max(0.0);
    while cents > 0.0 && (cents / 100.0) as f32 > safety {
        cents -= 1.0;
    }
    (cents / 100.0) as f32
}

impl NearestBlocked {
    /// What blocks this voxel, in a few words ("occupied", "free with safety 0.12").
    fn describe(&self) -> String {
        match self.class {
            VoxelClass::Free => format!("free but with safety {:.2}", self.safety),
            class => class.name().to_string(),
        }
    }
}

impl fmt::Display for Blocker {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::OutsideObservedExtent { extent, .. } => write!(
                f,
                "it lies outside the map's observed extent {extent}, where the map knows \
                 nothing and unknown space is forbidden; choose a point inside that extent or \
                 allow unknown space at a cost"
            ),
            Self::Unknown => write!(
                f,
                "its voxel is unknown (no evidence reached it) and unknown space is forbidden; \
                 allow unknown space at a cost or choose an observed point"
            ),
            Self::Occupied { safety } => write!(
                f,
                "its voxel is occupied (safety {safety:.2}), and occupied voxels are never \
                 entered; choose another point"
            ),
            Self::Ambiguous { safety } => write!(
                f,
                "its voxel is ambiguous (conflicting evidence, safety {safety:.2}), and \
                 ambiguous voxels are never entered; choose another point"
            ),
            Self::LowSafety { safety, threshold } => write!(
                f,
                "its voxel is free but its safety {safety:.2} is below the threshold \
                 {threshold:.2}; a threshold of at most {:.2} would accept it",
                safety_to_accept(*safety)
            ),
            Self::TooClose {
                clearance,
                required,
                vehicle_radius,
                largest_radius: _,
                nearest,
            } => {
                match nearest {
                    Some(n) => write!(
                        f,
                        "the nearest blocked voxel ({}, centre {:.2}, {:.2}, {:.2}) is {clearance:.2} m away",
                        n.describe(),
                        n.center.x,
                        n.center.y,
                        n.center.z
                    )?,
                    None => write!(
                        f,
                        "the edge of the planning region is {clearance:.2} m away"
                    )?,
                }
                write!(
                    f,
                    "; a vehicle of radius {vehicle_radius:.2} m needs {required:.2} m"
                )?;
                match self.radius_to_fit() {
                    Some(radius) => {
                        write!(f, "; a vehicle radius of at most {radius:.2} m would fit")
                    }
                    None => write!(f, "; no vehicle radius would fit: choose another point"),
                }
            }
        }
    }
}

fn class_name<S: Serializer>(class: &VoxelClass, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_str(class.name())
}

#[cfg(test)]
mod tests {
    use fuzzyvox_core::integrate::{IntegrationOptions, PointCloud};
    use fuzzyvox_core::map::VoxelMapMut;
    use fuzzyvox_core::map::{FunctionMap, FuzzyConfig, FuzzyMap};
    use fuzzyvox_core::measures::Memberships;

    use super::*;
    use crate::{PlanError, PlannerConfig, UnknownPolicy, plan_path};

    /// A 6 × 6 × 3 m box of confident free space (unknown outside) at 0.1 m with one voxel of
    /// each blocking kind: occupied at key (20, 20, 10), ambiguous at (40, 20, 10), free with
    /// safety 0.25 at (20, 40, 10), unknown at (40, 40, 10).
    fn features() -> impl VoxelMap {
        let resolution = Resolution::new(0.1).unwrap();
        FunctionMap::new(resolution, move |key| {
            let c = resolution.center(key);
            let inside =
                (0.0..6.0).contains(&c.x) && (0.0..6.0).contains(&c.y) && (0.0..3.0).contains(&c.z);
            let (occupied, free) = match (key.x, key.y, key.z) {
                _ if !inside => (0.0, 0.0),
                (20, 20, 10) => (0.9, 0.0),
                (40, 20, 10) => (0.8, 0.8),
                (20, 40, 10) => (0.0, 0.5),
                (40, 40, 10) => (0.0, 0.0),
                _ => (0.0, 0.95),
            };
            Memberships { occupied, free }
        })
    }

    fn config() -> PlannerConfig {
        PlannerConfig {
            vehicle_radius: 0.1,
            safety_threshold: 0.3,
            ..PlannerConfig::default()
        }
    }

    /// Centre of a voxel of the 0.1 m grid.
    fn at(x: i32, y: i32, z: i32) -> Point3<f64> {
        Resolution::new(0.1).unwrap().center(VoxelKey::new(x, y, z))
    }

    const GOAL: Point3<f64> = Point3::new(5.0, 5.0, 2.0);

    fn start_blocker(map: &dyn VoxelMap, from: Point3<f64>, config: &PlannerConfig) -> Blocker {
        match plan_path(map, &from, &GOAL, config) {
            Err(PlanError::StartUnsafe(why)) => why,
            other => panic!("expected an unsafe start, got {other:?}"),
        }
    }

    #[test]
    fn each_class_is_named_with_what_would_change_it() {
        let map = features();
        let cfg = config();
        let occupied = start_blocker(&map, at(20, 20, 10), &cfg);
        assert!(matches!(occupied, Blocker::Occupied { .. }), "{occupied:?}");
        assert!(occupied.to_string().contains("occupied"), "{occupied}");
        assert!(occupied.to_string().contains("choose another point"));
        let ambiguous = start_blocker(&map, at(40, 20, 10), &cfg);
        assert!(
            matches!(ambiguous, Blocker::Ambiguous { .. }),
            "{ambiguous:?}"
        );
        assert!(ambiguous.to_string().contains("ambiguous"), "{ambiguous}");
        let unknown = start_blocker(&map, at(40, 40, 10), &cfg);
        assert_eq!(unknown, Blocker::Unknown);
        assert!(unknown.to_string().contains("unknown space is forbidden"));
        // The goal is checked the same way.
        assert!(matches!(
            plan_path(&map, &GOAL, &at(20, 20, 10), &cfg),
            Err(PlanError::GoalUnsafe(Blocker::Occupied { .. }))
        ));
    }

    #[test]
    fn low_safety_gives_the_safety_and_the_threshold_that_accepts_it() {
        let map = features();
        let cfg = config();
        let low = start_blocker(&map, at(20, 40, 10), &cfg);
        let Blocker::LowSafety { safety, threshold } = low else {
            panic!("{low:?}");
        };
        assert!((safety - 0.25).abs() < 1e-6 && threshold == 0.3, "{low:?}");
        assert_eq!(low.safety_to_accept(), Some(0.25));
        assert!(low.to_string().contains("safety 0.25"), "{low}");
        // The suggested threshold really accepts the voxel, and the start with it.
        let lowered = PlannerConfig {
            safety_threshold: 0.25,
            ..cfg
        };
        plan_path(&map, &at(20, 40, 10), &GOAL, &lowered).unwrap();
        // A threshold a hair above the safety still refuses it: the value is not rounded up.
        assert_eq!(safety_to_accept(0.36), 0.36);
        assert_eq!(safety_to_accept(0.3649), 0.36);
        assert_eq!(safety_to_accept(0.0), 0.0);
    }

    #[test]
    fn too_close_names_the_nearest_blocked_voxel_and_a_radius_that_fits() {
        let map = features();
        let cfg = config();
        // Two voxels from the occupied one: 0.2 m, and 0.1 + √3 × 0.1 = 0.27 m is needed.
        let close = start_blocker(&map, at(22, 20, 10), &cfg);
        let Blocker::TooClose {
            clearance,
            required,
            nearest: Some(nearest),
            ..
        } = close
        else {
            panic!("{close:?}");
        };
        assert!((clearance - 0.2).abs() < 1e-6, "{close:?}");
        assert!((required - 0.273_205).abs() < 1e-5, "{close:?}");
        assert_eq!(nearest.class, VoxelClass::Occupied);
        assert!((nearest.distance - 0.2).abs() < 1e-9);
        assert!((nearest.center - at(20, 20, 10)).norm() < 1e-9);
        assert_eq!(close.radius_to_fit(), Some(0.02));
        let text = close.to_string();
        assert!(
            text.contains("occupied") && text.contains("0.20 m away"),
            "{text}"
        );
        assert!(text.contains("radius of at most 0.02 m"), "{text}");
        let smaller = PlannerConfig {
            vehicle_radius: 0.02,
            ..cfg
        };
        plan_path(&map, &at(22, 20, 10), &GOAL, &smaller).unwrap();
        // Next to the unknown voxel the nearest blocked voxel is unknown; right beside the
        // occupied one no radius fits.
        let by_hole = start_blocker(&map, at(40, 42, 10), &cfg);
        assert!(
            matches!(by_hole, Blocker::TooClose { nearest: Some(n), .. } if n.class == VoxelClass::Unknown),
            "{by_hole:?}"
        );
        let beside = start_blocker(&map, at(21, 20, 10), &cfg);
        assert_eq!(beside.radius_to_fit(), None);
        assert!(beside.to_string().contains("no vehicle radius would fit"));
        // Next to the low-safety voxel, its safety is the threshold that unblocks it.
        let by_low = start_blocker(&map, at(20, 42, 10), &cfg);
        assert_eq!(by_low.safety_to_accept(), Some(0.25), "{by_low:?}");
    }

    #[test]
    fn blockers_serialize_with_a_kind() {
        let map = features();
        let close = start_blocker(&map, at(22, 20, 10), &config());
        let json = serde_json::to_value(&close).unwrap();
        assert_eq!(json["kind"], "too_close");
        assert_eq!(json["nearest"]["class"], "occupied");
        assert_eq!(json["nearest"]["center"].as_array().unwrap().len(), 3);
        assert_eq!(
            serde_json::to_value(Blocker::Unknown).unwrap()["kind"],
            "unknown"
        );
    }

    /// A fuzzy map of one scan of a 4 × 2 m wall at x = 3 m from the origin.
    fn scanned_wall() -> FuzzyMap {
        let mut points = Vec::new();
        for i in 0..=80 {
            for j in 0..=40 {
                let (y, z) = (-2.0 + 0.05 * f64::from(i), -1.0 + 0.05 * f64::from(j));
                points.push(Point3::new(3.0, y, z));
            }
        }
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        let scan = PointCloud::new(Point3::origin(), points).unwrap();
        map.integrate_cloud(&scan, &IntegrationOptions::default())
            .unwrap();
        map
    }

    #[test]
    fn points_off_the_map_are_reported_with_the_observed_extent() {
        let map = scanned_wall();
        let extent = ObservedExtent::of(&map).unwrap();
        assert!(extent.min.x <= 0.0 && extent.max.x >= 3.0 && extent.max.x < 4.0);
        assert!(extent.min.y <= -2.0 && extent.max.y >= 2.0);
        let cfg = config();
        let (inside, beyond) = (Point3::new(1.5, 0.0, 0.0), Point3::new(10.0, 0.0, 0.0));
        match plan_path(&map, &inside, &beyond, &cfg) {
            Err(PlanError::GoalUnsafe(Blocker::OutsideObservedExtent { point, extent: e })) => {
                assert_eq!(point, beyond);
                assert_eq!(e, extent);
            }
            other => panic!("{other:?}"),
        }
        let above = Point3::new(1.5, 0.0, 5.0);
        let error = plan_path(&map, &above, &inside, &cfg).unwrap_err();
        assert!(
            matches!(
                error,
                PlanError::StartUnsafe(Blocker::OutsideObservedExtent { .. })
            ),
            "{error:?}"
        );
        let text = error.to_string();
        assert!(
            text.contains("outside the map's observed extent")
                && text.contains(&extent.to_string()),
            "{text}"
        );
        // Unknown but inside the extent: outside the scan's cone, beside the sensor.
        let beside = Point3::new(0.5, 1.8, 0.8);
        assert!(extent.contains(map.resolution().key_of(&beside).unwrap()));
        assert!(matches!(
            plan_path(&map, &inside, &beside, &cfg),
            Err(PlanError::GoalUnsafe(Blocker::Unknown))
        ));
        // With unknown space allowed, a goal off the map is a goal like any other.
        let exploring = PlannerConfig {
            unknown: UnknownPolicy::Cost(5.0),
            ..cfg
        };
        plan_path(&map, &inside, &beyond, &exploring).unwrap();
    }

    #[test]
    fn maps_without_stored_voxels_have_no_extent() {
        assert_eq!(ObservedExtent::of(&features()), None);
        let empty = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        assert_eq!(ObservedExtent::of(&empty), None);
    }
}
