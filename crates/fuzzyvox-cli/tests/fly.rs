//! Closed-loop flights: deterministic for a seed, stopped and counted at a collision, and the
//! `fly` command as a user runs it.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{fuzzyvox, json};
use fuzzyvox::MapKind;
use fuzzyvox::eval::FlightQuery;
use fuzzyvox::eval::closed_loop::fly_all;
use fuzzyvox::fly::{Ending, FlightLog, FlyConfig, fly_goal, integrate_prior};
use fuzzyvox::sim::scenario::{self, Scenario};
use fuzzyvox::sim::{Scene, SurfaceKind};
use nalgebra::{Point3, Vector3};

/// The flight logs without their timings, which differ from run to run.
fn strip_times(mut logs: Vec<fuzzyvox::fly::FlightLog>) -> Vec<fuzzyvox::fly::FlightLog> {
    for log in &mut logs {
        log.cycles.clear();
    }
    logs
}

#[test]
fn a_flight_is_the_same_for_the_same_seed() {
    let wall = scenario::wall().unwrap();
    let goal = FlightQuery {
        from: Point3::new(-5.9, -12.3, 2.7),
        to: Point3::new(3.7, -15.3, 4.7),
        reference_length: Some(10.25),
    };
    let config = FlyConfig::default();
    let run = || {
        let flights = fly_all(
            &wall,
            &[goal],
            &[MapKind::Fuzzy],
            &config,
            3,
            false,
            &mut |_, _| {},
        )
        .unwrap();
        strip_times(flights.into_iter().next().unwrap().flights)
    };
    let (a, b) = (run(), run());
    assert_eq!(a, b);
    let flight = &a[0];
    assert!(flight.frames > 5 && flight.depth_images > 0, "{flight:?}");
    assert_eq!(flight.trajectory[0], goal.from);
}

/// A 10 × 10 m plate 2.5 m under the start, which a level camera never sees (it lies below the
/// camera's view at every distance the plate reaches), over a goal beneath it.
fn hidden_plate() -> Scenario {
    one_box(
        "plate",
        Point3::new(0.0, 0.0, 3.0),
        Vector3::new(5.0, 5.0, 0.05),
    )
}

/// Flat ground with one building box (`centre`, half extents `half`), 20 m across.
fn one_box(name: &'static str, centre: Point3<f64>, half: Vector3<f64>) -> Scenario {
    let mut scene = Scene::new();
    scene
        .add_ground(0.013, 200.0)
        .add_box(centre, half, 0.0, SurfaceKind::Building);
    Scenario {
        name,
        scene,
        intrinsics: scenario::camera().unwrap(),
        pairs: Vec::new(),
        phases: Vec::new(),
        max_range: 40.0,
        extent: [[-10.0, -10.0], [10.0, 10.0]],
        heights: [0.3, 7.0],
        flight_altitude: (1.0, 6.0),
        flight_distance: (2.0, 12.0),
    }
}

/// A flight from above the hidden plate to a goal below it, with a level camera (no pitch
/// towards the descending path) flying straight; `blind_steps` lets it step into unknown space
/// below its view. Returns the plate, the start, the vehicle radius and the log.
fn fly_down_past_the_plate(blind_steps: bool) -> (Scenario, Point3<f64>, f64, FlightLog) {
    let plate = hidden_plate();
    let goal = FlightQuery {
        from: Point3::new(-0.9, 0.1, 5.5),
        to: Point3::new(1.1, 0.1, 1.1),
        reference_length: Some(12.0),
    };
    let config = FlyConfig {
        max_pitch: 0.0,
        weave_angle: 0.0,
        look_turn: 0.0,
        blind_steps,
        ..FlyConfig::default()
    };
    let mut map = MapKind::LogOdds.new_map(config.resolution).unwrap();
    integrate_prior(&plate, &mut map, &goal.from, &config).unwrap();
    let log = fly_goal(&plate, &goal.from, &goal.to, &mut map, &config, 1).unwrap();
    (plate, goal.from, config.planner.vehicle_radius, log)
}

#[test]
fn a_flight_into_an_unseen_obstacle_is_stopped_and_counted() {
    let (plate, _, radius, log) = fly_down_past_the_plate(true);
    assert_eq!(log.ending, Ending::Collided, "{:?}", log.trajectory);
    // Stopped before the step that meets the plate: every position flown is clear of it.
    let last = log.trajectory.last().unwrap();
    assert!(last.z > 3.0, "{last:?}");
    assert!(plate.scene.distance_to_surface(last) >= radius);
}

#[test]
fn a_vehicle_enters_unknown_space_only_where_its_camera_looks() {
    // The flight above, with the default rule: the steps into unknown space head into the
    // level camera's picture, so the vehicle descends no more steeply than the picture
    // reaches, sees the plate, and never touches it.
    let (_, start, _, log) = fly_down_past_the_plate(false);
    assert_ne!(log.ending, Ending::Collided, "{:?}", log.trajectory);
    // It did fly (down and out from under the start), not hover where it began.
    let last = log.trajectory.last().unwrap();
    assert!((last - start).norm() > 2.0, "{:?}", log.trajectory);
}

/// A building face 4 m ahead of the start, across the way to a goal behind it: beyond the prior
/// map, and straight ahead, where motion along the view measures almost nothing.
fn wall_ahead() -> (Scenario, FlightQuery) {
    let scenario = one_box(
        "wall ahead",
        Point3::new(4.5, 0.0, 3.0),
        Vector3::new(0.3, 2.0, 3.0),
    );
    let goal = FlightQuery {
        from: Point3::new(0.0, 0.3, 2.1),
        to: Point3::new(9.0, 0.3, 2.1),
        reference_length: Some(12.0),
    };
    (scenario, goal)
}

#[test]
fn looking_aside_at_take_off_sees_the_wall_that_forward_motion_misses() {
    let (scenario, goal) = wall_ahead();
    let fly = |look_turn: f64| {
        let config = FlyConfig {
            look_turn,
            ..FlyConfig::default()
        };
        let mut map = MapKind::Fuzzy.new_map(config.resolution).unwrap();
        integrate_prior(&scenario, &mut map, &goal.from, &config).unwrap();
        fly_goal(&scenario, &goal.from, &goal.to, &mut map, &config, 5).unwrap()
    };
    // Flying straight at it, the vehicle sees the face only from along its view: it flies
    // to within a metre and a half of it before it learns of it, and then either hits it or
    // dodges about it without reaching the goal.
    let straight = fly(0.0);
    assert_ne!(
        straight.ending,
        Ending::Reached,
        "{:?}",
        straight.trajectory
    );
    assert!(
        straight.trajectory.iter().any(|p| p.x > 2.9),
        "{:?}",
        straight.trajectory
    );
    // One sideways step at take-off gives the depth stage a sideways baseline: the face is
    // mapped and the vehicle goes round it, past the wall's far side, without touching it.
    let looked = fly(FlyConfig::default().look_turn);
    let first = looked.trajectory[1] - looked.trajectory[0];
    assert!(
        first.x.abs() < 1e-9 && first.y.abs() > 0.4,
        "first step {first:?}"
    );
    assert_eq!(looked.ending, Ending::Reached, "{:?}", looked.trajectory);
    assert!(
        looked.trajectory.iter().any(|p| p.x > 5.0),
        "{:?}",
        looked.trajectory
    );
}

#[test]
fn a_flight_that_comes_no_nearer_ends_as_stuck() {
    // The goal lies inside a building: once the vehicle has mapped the face in front of it, no
    // voxel nearer to the goal can be entered.
    let scenario = one_box(
        "goal inside",
        Point3::new(6.0, 0.0, 3.0),
        Vector3::new(1.5, 1.5, 3.0),
    );
    let goal = FlightQuery {
        from: Point3::new(0.0, 0.3, 2.1),
        to: Point3::new(6.0, 0.3, 2.1),
        reference_length: Some(6.0),
    };
    let config = FlyConfig::default();
    let mut map = MapKind::Fuzzy.new_map(config.resolution).unwrap();
    integrate_prior(&scenario, &mut map, &goal.from, &config).unwrap();
    let log = fly_goal(&scenario, &goal.from, &goal.to, &mut map, &config, 2).unwrap();
    assert_eq!(log.ending, Ending::Stuck, "{:?}", log.trajectory);
    // It gave the vehicle `patience` seconds, and ended long before the time limit.
    let frames = (config.patience / config.frame_interval) as usize;
    assert!(log.frames >= frames, "{} frames", log.frames);
    assert!(
        (log.frames as f64) * config.frame_interval < config.time_limit / 2.0,
        "{} frames",
        log.frames
    );
}

#[test]
fn fly_reports_every_map_as_json() {
    let out = std::env::temp_dir().join(format!("fuzzyvox-fly-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let report = json(&fuzzyvox(&[
        "fly",
        "--scenario",
        "wall",
        "--goals",
        "1",
        "--model",
        "fuzzy,logodds",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(report["goals"], 1);
    for model in ["fuzzy", "logodds"] {
        let m = &report["maps"][model];
        let reached = m["reached"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&reached), "{model}");
        assert!(m["collisions"].as_u64().is_some(), "{model}");
        assert!(m["update_replan_ms"].as_f64().unwrap() >= 0.0, "{model}");
        assert!(m["full_rebuild_ms"].as_f64().unwrap() > 0.0, "{model}");
        assert_eq!(m["flights"].as_array().unwrap().len(), 1);
        assert!(out.join(format!("fly-{model}-1.png")).is_file());
    }
    assert!(report["maps"]["alpha"].is_null());
    let written: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("fly.json")).unwrap()).unwrap();
    assert_eq!(
        written["maps"]["fuzzy"]["reached"],
        report["maps"]["fuzzy"]["reached"]
    );
    std::fs::remove_dir_all(&out).unwrap();

    // Bad arguments are refused with a reason.
    for (args, reason) in [
        (
            &["fly", "--scenario", "wall", "--goals", "0"][..],
            "--goals",
        ),
        (
            &[
                "fly",
                "--scenario",
                "wall",
                "--unknown",
                "forbid",
                "--unknown-cost",
                "3",
            ][..],
            "--unknown-cost",
        ),
        (&["fly", "--scenario", "nowhere"][..], "nowhere"),
        (
            &["fly", "--scenario", "wall", "--look-turn", "200"][..],
            "look turn",
        ),
        (&["fly", "--scenario", "wall", "--weave", "95"][..], "weave"),
        (
            &["fly", "--scenario", "wall", "--guard=-1"][..],
            "unknown guard",
        ),
        (
            &["fly", "--scenario", "wall", "--patience", "0"][..],
            "patience",
        ),
        (
            &["fly", "--scenario", "wall", "--leaning", "0"][..],
            "leaning occupied",
        ),
        (
            &["fly", "--scenario", "wall", "--leaning", "NaN"][..],
            "leaning occupied",
        ),
    ] {
        let run = fuzzyvox(args);
        assert!(!run.status.success(), "{args:?}");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(stderr.contains(reason), "{args:?}: {stderr}");
    }
}
