//! Planning: cost field, A* through petgraph's traits, shortcutting, typed failures, queries.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::VoxelMapMut;
use fuzzyvox::map::FunctionMap;
use fuzzyvox::plan::{
    CostField, PlanError, PlannerConfig, PlanningRegion, SafetyQueries, UnknownPolicy, VoxelGraph,
    plan_in_field, plan_path,
};
use fuzzyvox::{
    IntegrationOptions, KeyBox, Memberships, PointCloud, Resolution, VoxelKey, VoxelMap,
};
use nalgebra::Point3;

/// A synthetic map: a 10 × 6 × 3 m room of free space (μE = 0.95) with a wall across it at
/// x = 5 m, optionally with a door; everything outside the room is unknown.
fn room(door: bool) -> impl VoxelMap {
    let resolution = Resolution::new(0.1).unwrap();
    FunctionMap::new(resolution, move |key| {
        let c = resolution.center(key);
        let inside =
            (0.0..10.0).contains(&c.x) && (0.0..6.0).contains(&c.y) && (0.0..3.0).contains(&c.z);
        if !inside {
            Memberships::default()
        } else if wall_at(&c, door) {
            Memberships {
                occupied: 0.9,
                free: 0.0,
            }
        } else {
            Memberships {
                occupied: 0.0,
                free: 0.95,
            }
        }
    })
}

fn wall_at(p: &Point3<f64>, door: bool) -> bool {
    let in_wall = (4.9..5.1).contains(&p.x);
    let in_door = (2.5..3.5).contains(&p.y) && p.z < 2.0;
    in_wall && !(door && in_door)
}

fn config() -> PlannerConfig {
    PlannerConfig {
        vehicle_radius: 0.2,
        ..PlannerConfig::default()
    }
}

/// Distance from a point to the nearest wall voxel's box.
fn distance_to_wall(room: &impl VoxelMap, p: &Point3<f64>) -> f64 {
    let r = room.resolution();
    let key = r.key_of(p).unwrap();
    let mut best = f64::INFINITY;
    for dz in -8..=8 {
        for dy in -8..=8 {
            for dx in -8..=8 {
                let k = VoxelKey::new(key.x + dx, key.y + dy, key.z + dz);
                let c = r.center(k);
                if room.memberships_at(k).occupied > 0.0 {
                    let gap = (p - c).map(|d| (d.abs() - 0.05).max(0.0));
                    best = best.min(gap.norm());
                }
            }
        }
    }
    best
}

#[test]
fn path_goes_through_the_door_and_keeps_the_vehicle_radius() {
    let room = room(true);
    let (from, to) = (Point3::new(2.0, 1.0, 1.0), Point3::new(8.0, 5.0, 1.5));
    let path = plan_path(&room, &from, &to, &config()).unwrap();
    assert!(
        path.waypoints.len() >= 3,
        "must bend through the door: {:?}",
        path.waypoints
    );
    assert!(path.length >= (to - from).norm());
    assert!(path.min_safety >= 0.2 && path.min_clearance >= 0.2);
    // Sample every segment: never closer than the vehicle radius to the wall.
    let mut through_door = false;
    for pair in path.waypoints.windows(2) {
        for s in 0..=100 {
            let p = pair[0] + (pair[1] - pair[0]) * (f64::from(s) / 100.0);
            assert!(
                distance_to_wall(&room, &p) >= 0.2 - 1e-9,
                "{p} too close to the wall"
            );
            through_door |= (4.9..5.1).contains(&p.x) && (2.5..3.5).contains(&p.y);
        }
    }
    assert!(through_door);
}

#[test]
fn petgraph_astar_runs_on_the_implicit_graph_and_agrees() {
    let room = room(true);
    let region = PlanningRegion::new(VoxelKey::new(0, 0, 5), VoxelKey::new(99, 59, 15)).unwrap();
    let field = CostField::build(&room, region, config()).unwrap();
    let (start, goal) = (VoxelKey::new(20, 10, 10), VoxelKey::new(80, 50, 10));
    let ours = plan_in_field(&field, start, goal).unwrap();
    let graph = VoxelGraph::new(&field);
    let (s, g) = (graph.node(start).unwrap(), graph.node(goal).unwrap());
    let (cost, nodes) = petgraph::algo::astar(
        &graph,
        s,
        |n| n == g,
        |e| *petgraph::visit::EdgeRef::weight(&e),
        |_| 0.0,
    )
    .unwrap();
    assert!(
        (f64::from(cost) - ours.cost).abs() < 1e-3 * ours.cost,
        "{cost} vs {}",
        ours.cost
    );
    assert_eq!(graph.key(nodes[0]), start);
    assert_eq!(graph.key(*nodes.last().unwrap()), goal);
}

#[test]
fn failures_are_typed() {
    let closed = room(false);
    let cfg = config();
    let result = plan_path(
        &closed,
        &Point3::new(2.0, 1.0, 1.0),
        &Point3::new(8.0, 5.0, 1.5),
        &cfg,
    );
    assert!(
        matches!(result, Err(PlanError::Disconnected { .. })),
        "{result:?}"
    );
    let open = room(true);
    let in_wall = plan_path(
        &open,
        &Point3::new(5.0, 1.0, 1.0),
        &Point3::new(8.0, 5.0, 1.5),
        &cfg,
    );
    assert!(
        matches!(in_wall, Err(PlanError::StartUnsafe(_))),
        "{in_wall:?}"
    );
    let near_wall = plan_path(
        &open,
        &Point3::new(2.0, 1.0, 1.0),
        &Point3::new(5.15, 1.0, 1.0),
        &cfg,
    );
    assert!(
        matches!(near_wall, Err(PlanError::GoalUnsafe(_))),
        "{near_wall:?}"
    );
    let outside = plan_path(
        &open,
        &Point3::new(2.0, 1.0, 1.0),
        &Point3::new(20.0, 1.0, 1.0),
        &cfg,
    );
    assert!(
        matches!(outside, Err(PlanError::GoalUnsafe(_))),
        "{outside:?}"
    );
    let region = PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(10, 10, 10)).unwrap();
    let field = CostField::build(&open, region, cfg).unwrap();
    let out = plan_in_field(&field, VoxelKey::new(5, 5, 5), VoxelKey::new(50, 5, 5));
    assert!(matches!(out, Err(PlanError::OutOfRegion("goal"))));
    let bad = PlannerConfig {
        vehicle_radius: f64::NAN,
        ..cfg
    };
    assert!(matches!(
        plan_path(
            &open,
            &Point3::new(2.0, 1.0, 1.0),
            &Point3::new(3.0, 1.0, 1.0),
            &bad
        ),
        Err(PlanError::Map(_))
    ));
    assert!(
        PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(100_000, 100_000, 10)).is_err()
    );
}

#[test]
fn unknown_space_is_forbidden_or_costed() {
    // Going from inside the room to a point outside it crosses unknown space.
    let room = room(false);
    let (from, to) = (Point3::new(2.0, 1.0, 1.0), Point3::new(8.0, 1.0, 1.0));
    let forbid = plan_path(&room, &from, &to, &config());
    assert!(
        matches!(forbid, Err(PlanError::Disconnected { .. })),
        "{forbid:?}"
    );
    let cost = PlannerConfig {
        unknown: UnknownPolicy::Cost(5.0),
        ..config()
    };
    let around = plan_path(&room, &from, &to, &cost).unwrap();
    // The only way round the closed wall is through unknown space above or beside the room.
    assert!(
        around
            .waypoints
            .iter()
            .any(|p| p.z > 3.0 || p.z < 0.0 || p.y < 0.0 || p.y > 6.0)
    );
}

#[test]
fn safety_queries() {
    let room = room(true);
    let cfg = config();
    assert!(
        room.is_safe(&Point3::new(2.0, 1.0, 1.0), 0.3, &cfg)
            .unwrap()
    );
    assert!(
        !room
            .is_safe(&Point3::new(4.8, 1.0, 1.0), 0.3, &cfg)
            .unwrap()
    );
    assert!(
        room.is_safe(&Point3::new(4.5, 1.0, 1.0), 0.3, &cfg)
            .unwrap()
    );
    let nearest = room
        .nearest_safe(&Point3::new(5.0, 1.0, 1.0), 1.0, &cfg)
        .unwrap()
        .unwrap();
    assert!(
        (nearest.x - 4.85).abs() < 1e-9 || (nearest.x - 5.15).abs() < 1e-9,
        "{nearest}"
    );
    assert!(
        room.nearest_safe(&Point3::new(50.0, 1.0, 1.0), 1.0, &cfg)
            .unwrap()
            .is_none()
    );
    let r = room.resolution();
    let region = KeyBox::from_points(
        &r,
        &Point3::new(4.55, 0.55, 0.55),
        &Point3::new(5.45, 0.95, 0.95),
    )
    .unwrap();
    let safe = room.safe_voxels_in_box(&region, &cfg);
    // Two wall voxels thick, 5 × 5 across.
    assert_eq!(safe.len(), region.voxel_count() as usize - 2 * 5 * 5);
    let m = room.measures_at_point(&Point3::new(2.0, 1.0, 1.0)).unwrap();
    assert!((m.safety - 0.9025).abs() < 1e-5);
}

#[test]
fn plans_in_a_real_fuzzy_map() {
    use fuzzyvox::{FuzzyConfig, FuzzyMap};
    // A wall seen three times from the left: the space before it is safe, behind it unknown.
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let mut wall = Vec::new();
    for i in 0..120 {
        for j in 0..30 {
            wall.push(Point3::new(
                4.0,
                -3.0 + 0.05 * f64::from(i),
                0.1 * f64::from(j),
            ));
        }
    }
    for origin in [
        Point3::new(0.0, -1.0, 1.0),
        Point3::new(0.0, 0.0, 1.5),
        Point3::new(0.0, 1.0, 1.0),
    ] {
        let cloud = PointCloud::new(origin, wall.clone()).unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
    }
    let cfg = config();
    let path = plan_path(
        &map,
        &Point3::new(1.5, 0.0, 1.5),
        &Point3::new(3.0, 0.5, 1.5),
        &cfg,
    )
    .unwrap();
    assert!(
        path.length >= 1.58 && path.min_safety >= cfg.safety_threshold,
        "{path:?}"
    );
    let behind = plan_path(
        &map,
        &Point3::new(1.5, 0.0, 1.5),
        &Point3::new(5.0, 0.0, 1.0),
        &cfg,
    );
    assert!(
        matches!(behind, Err(PlanError::GoalUnsafe(_))),
        "{behind:?}"
    );
}
