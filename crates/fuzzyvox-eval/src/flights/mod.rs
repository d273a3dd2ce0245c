//! Planned flights checked against the truth: start/goal pairs drawn from the truth alone
//! ([`queries`]), a path planned in each map ([`plan`]), every path swept by a ball of the
//! vehicle's radius against the true world's obstacles ([`world`]), and what each map's paths
//! gave ([`outcome`]). The open-loop experiment (`eval`), the closed-loop flights (`fly`) and
//! the runs on real frames all draw, plan and check through these.

mod occupied;
mod outcome;
mod plan;
mod queries;
mod world;

pub use occupied::OccupiedVoxels;
pub use outcome::{
    BlockedByCounts, BlockingClass, CollisionDetail, FailureCounts, FlightFailure, FlightOutcome,
    FlightSummary, summarize,
};
pub use plan::plan_queries;
pub use queries::{Candidates, Connect, FlightQuery, QueryConfig, draw_queries};
pub use world::{Obstacles, path_collides, path_contact};

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::PointCloud;
    use fuzzyvox_core::map::{FuzzyConfig, FuzzyMap, VoxelMapMut};
    use fuzzyvox_core::measures::VoxelClass;
    use fuzzyvox_plan::{Blocker, NearestBlocked, PlannerConfig};
    use fuzzyvox_sim::{Scene, SurfaceKind};
    use nalgebra::{Point3, Vector3};

    /// A wall at x = 5 across the corridor, mapped from a sensor at the origin, so that the
    /// map knows the free space in front of the wall.
    fn wall_world() -> (Scene, FuzzyMap) {
        let mut scene = Scene::new();
        scene.add_box(
            Point3::new(5.3, 0.0, 3.0),
            Vector3::new(0.3, 6.0, 3.0),
            0.0,
            SurfaceKind::Wall,
        );
        let mut points = Vec::new();
        for i in -40..=40 {
            for j in 0..=40 {
                points.push(Point3::new(
                    5.0,
                    f64::from(i) * 0.1,
                    f64::from(j) * 0.1 + 1.0,
                ));
            }
        }
        let cloud = PointCloud::new(Point3::new(0.0, 0.0, 3.0), points).unwrap();
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
        for _ in 0..3 {
            map.integrate_cloud(&cloud, &Default::default()).unwrap();
        }
        (scene, map)
    }

    #[test]
    fn queries_lie_in_true_free_space_and_repeat_for_a_seed() {
        let (scene, map) = wall_world();
        let config = QueryConfig {
            queries: 10,
            distance: (1.0, 3.0),
            altitude: (1.5, 4.0),
            ..QueryConfig::default()
        };
        let a = draw_queries(&scene, Candidates::Reference(&map), &config).unwrap();
        assert_eq!(a.len(), 10);
        assert_eq!(
            a,
            draw_queries(&scene, Candidates::Reference(&map), &config).unwrap()
        );
        for q in &a {
            let d = (q.to - q.from).norm();
            assert!((1.0..=3.0).contains(&d));
            for p in [q.from, q.to] {
                assert!(scene.distance_to_surface(&p) >= 0.3);
                assert!(p.z >= 1.5 && p.z <= 4.0);
            }
        }
        let other = QueryConfig { seed: 2, ..config };
        assert_ne!(
            a,
            draw_queries(&scene, Candidates::Reference(&map), &other).unwrap()
        );
        // A truth that saw nothing leaves no candidates.
        let empty = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
        assert!(
            draw_queries(&scene, Candidates::Reference(&empty), &config)
                .unwrap()
                .is_empty()
        );
        // A map that knows nothing answers the same queries, and fails each at its start.
        let outcomes = plan_queries(&empty, &scene, &a, &config.planner);
        let summary = summarize(&outcomes, &plan_queries(&map, &scene, &a, &config.planner));
        assert_eq!(summary.plan_success, 0.0);
        assert_eq!(summary.plan_failures.start_unsafe, a.len());
        assert_eq!(summary.plan_failures.goal_unsafe, 0);
    }

    #[test]
    fn a_point_short_of_clearance_is_blocked_by_the_class_of_its_nearest_blocked_voxel() {
        let too_close = |nearest: Option<NearestBlocked>| Blocker::TooClose {
            clearance: 0.2,
            required: 0.47,
            vehicle_radius: 0.3,
            largest_radius: 0.03,
            nearest,
        };
        let near = |class| NearestBlocked {
            center: Point3::origin(),
            class,
            safety: 0.1,
            distance: 0.2,
        };
        for (class, expected) in [
            (VoxelClass::Unknown, BlockingClass::Unknown),
            (VoxelClass::Occupied, BlockingClass::Occupied),
            (VoxelClass::Ambiguous, BlockingClass::Ambiguous),
            (VoxelClass::Free, BlockingClass::LowSafety),
        ] {
            assert_eq!(
                BlockingClass::of(&too_close(Some(near(class)))),
                Some(expected)
            );
        }
        // The planning region's edge is no class.
        assert_eq!(BlockingClass::of(&too_close(None)), None);
        assert_eq!(
            BlockingClass::of(&Blocker::Unknown),
            Some(BlockingClass::Unknown)
        );
    }

    #[test]
    fn paths_are_checked_against_the_geometry() {
        let (scene, map) = wall_world();
        let planner = PlannerConfig::default();
        let safe = FlightQuery {
            from: Point3::new(2.5, -0.8, 3.0),
            to: Point3::new(4.0, 0.8, 3.0),
            reference_length: None,
        };
        let outcomes = plan_queries(&map, &scene, &[safe], &planner);
        assert!(outcomes[0].length.is_some());
        assert!(!outcomes[0].collides);
        // The same path judged against a scene with a pillar in its way collides.
        let mut blocked = scene.clone();
        blocked.add_box(
            Point3::new(3.25, 0.0, 3.0),
            Vector3::new(0.3, 0.3, 3.0),
            0.0,
            SurfaceKind::Building,
        );
        let judged = plan_queries(&map, &blocked, &[safe], &planner);
        assert!(judged[0].collides);
        // The collision is explained: where the ball first meets the pillar, and what the map
        // (which never saw the pillar) said there.
        let detail = judged[0].collision.unwrap();
        assert_eq!((detail.from, detail.to), (safe.from, safe.to));
        assert!(
            detail.distance_to_surface < planner.vehicle_radius,
            "{detail:?}"
        );
        assert!(blocked.distance_to_surface(&detail.point) < planner.vehicle_radius);
        assert_eq!(detail.class, "free");
        assert!(outcomes[0].collision.is_none());
        let summary = summarize(&judged, &outcomes);
        assert_eq!(summary.plan_queries, 1);
        assert_eq!(summary.plan_collisions, 1);
        assert_eq!(summary.plan_collision_details, vec![detail]);
        assert!((summary.plan_success - 1.0).abs() < 1e-12);
        assert!((summary.path_length_ratio.unwrap() - 1.0).abs() < 1e-12);
        // A goal inside the wall has no path.
        let into = FlightQuery {
            from: safe.from,
            to: Point3::new(5.3, 0.0, 3.0),
            reference_length: None,
        };
        let failed = plan_queries(&map, &scene, &[into], &planner);
        assert!(failed[0].length.is_none() && !failed[0].collides);
        assert_eq!(failed[0].failure, Some(FlightFailure::GoalUnsafe));
        assert_eq!(summarize(&failed, &failed).plan_failures.goal_unsafe, 1);
        assert_eq!(summarize(&failed, &failed).path_length_ratio, None);
        // A goal on the wall's face is blocked by the occupied voxels the sensor saw there.
        let onto = FlightQuery {
            from: safe.from,
            to: Point3::new(5.0, 0.0, 3.0),
            reference_length: None,
        };
        let failed = plan_queries(&map, &scene, &[onto], &planner);
        assert_eq!(failed[0].failure, Some(FlightFailure::GoalUnsafe));
        assert_eq!(failed[0].blocked_by, Some(BlockingClass::Occupied));
        let counts = summarize(&failed, &failed).plan_failures.blocked_by;
        assert_eq!(
            counts,
            BlockedByCounts {
                occupied: 1,
                ..BlockedByCounts::default()
            }
        );
    }

    #[test]
    fn queries_near_a_camera_path_lie_within_reach_of_it() {
        let (scene, map) = wall_world();
        let path = [Point3::new(2.0, -1.0, 3.0), Point3::new(2.0, 1.0, 3.0)];
        let config = QueryConfig {
            queries: 10,
            distance: (0.5, 3.0),
            altitude: (0.0, f64::MAX),
            ..QueryConfig::default()
        };
        let near = |reach| Candidates::NearPath {
            reference: &map,
            path: &path,
            reach,
        };
        let queries = draw_queries(&scene, near(1.0), &config).unwrap();
        assert_eq!(queries.len(), 10);
        for q in &queries {
            for p in [q.from, q.to] {
                assert!(path.iter().any(|c| (p - c).norm() <= 1.0), "{p}");
            }
        }
        assert!(draw_queries(&scene, near(0.0), &config).is_err());
        assert!(draw_queries(&scene, near(f64::NAN), &config).is_err());
    }
}
