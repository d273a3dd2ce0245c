//! The simulator and the evaluation together: the gold standard (true depth, standard method)
//! of a wall seen from strafing cameras agrees with the geometric truth.

use fuzzyvox::eval::{GroundTruth, evaluate, gold_standard};
use fuzzyvox::sim::trajectory::strafe;
use fuzzyvox::sim::{Scene, SurfaceKind};
use fuzzyvox::{PinholeIntrinsics, VoxelMap};
use nalgebra::{Point3, Vector3};

fn wall_scene() -> Scene {
    let mut scene = Scene::new();
    scene.add_ground(0.0, 200.0).add_box(
        Point3::new(10.0, 0.0, 3.0),
        Vector3::new(0.25, 8.0, 3.0),
        0.0,
        SurfaceKind::Wall,
    );
    scene
}

#[test]
fn gold_standard_matches_the_geometric_truth() {
    let scene = wall_scene();
    let k = PinholeIntrinsics::new(160, 120, 120.0, 120.0, 79.5, 59.5).unwrap();
    let poses = strafe(
        Point3::new(0.0, -2.0, 2.0),
        Vector3::y(),
        Vector3::new(1.0, 0.0, -0.05),
        0.5,
        6,
    );
    let gold = gold_standard(&scene, &k, &poses, 0.2, 30.0).unwrap();
    let truth = GroundTruth::from_scene(&scene, &gold);
    assert!(truth.occupied_count() > 500, "{}", truth.occupied_count());
    let metrics = evaluate(&gold, &truth, &scene);
    eprintln!("gold standard against the geometric truth: {metrics:?}");
    // The gold standard marks the voxels its rays end in; they meet the geometry.
    assert!(metrics.occupied_precision > 0.95, "{metrics:?}");
    assert!(metrics.occupied_recall > 0.5, "{metrics:?}");
    assert_eq!(metrics.spurious_unknown, 0);
    assert!(metrics.chamfer_m < 0.2, "{metrics:?}");
    // Nothing is known behind the wall.
    assert!(
        !truth.is_observed(
            gold.resolution()
                .key_of(&Point3::new(12.0, 0.0, 2.0))
                .unwrap()
        )
    );
}

#[test]
fn the_wall_experiment_is_reproducible_and_reports_every_map() {
    use fuzzyvox::eval::{ExperimentConfig, run_experiment};
    use fuzzyvox::sim::scenario;
    let scenario = scenario::wall().unwrap();
    let config = ExperimentConfig {
        resolution: 0.25,
        operators: vec!["max".parse().unwrap()],
        ..ExperimentConfig::default()
    };
    let output = run_experiment(&scenario, &config).unwrap();
    let (first, maps) = (output.report, output.maps);
    let second = run_experiment(&scenario, &config).unwrap().report;
    let names: Vec<_> = first.maps.keys().cloned().collect();
    assert_eq!(names, ["alpha", "fuzzy", "fuzzy:maximum", "logodds"]);
    for name in &names {
        assert_eq!(
            first.maps[name].metrics, second.maps[name].metrics,
            "{name}"
        );
        assert_eq!(
            first.maps[name].after.keys().collect::<Vec<_>>(),
            ["after_strafe"]
        );
    }
    assert_eq!(maps.len(), 4);
    // The standard map built from the strafing pairs finds the wall.
    assert!(first.maps["logodds"].metrics.occupied > 1000);
    assert!(first.maps["logodds"].metrics.occupied_recall > 0.2);
    // The receding pairs (matched by plane sweep) erode the standard map's wall and put voxels
    // behind it; the confidence-aware maps barely change.
    assert_eq!(first.swept_pairs, 6);
    let standard = &first.maps["logodds"];
    let strafed = &standard.after["after_strafe"];
    assert!(standard.metrics.holes > 2 * strafed.holes);
    assert!(standard.metrics.spurious_unknown > 2 * strafed.spurious_unknown);
    let fuzzy = &first.maps["fuzzy"].metrics;
    assert!(
        5 * fuzzy.holes <= standard.metrics.holes,
        "fuzzy holes {}, log-odds {}",
        fuzzy.holes,
        standard.metrics.holes
    );
    assert!(5 * fuzzy.spurious_unknown <= standard.metrics.spurious_unknown);
}

#[test]
fn the_wall_experiment_with_several_views_per_depth_image() {
    use fuzzyvox::eval::{ExperimentConfig, run_experiment};
    use fuzzyvox::sim::scenario;
    let scenario = scenario::wall().unwrap();
    let run = |views: usize| {
        let config = ExperimentConfig {
            resolution: 0.25,
            views,
            ..ExperimentConfig::default()
        };
        run_experiment(&scenario, &config).unwrap().report
    };
    let (pairs, several) = (run(2), run(4));
    assert_eq!((pairs.views, several.views), (2, 4));
    // Every pair but the first strafing one goes through the plane sweep (the first of each
    // phase has no earlier view; the first receding pair is swept anyway), nothing refused.
    assert_eq!(several.swept_pairs, 11);
    assert_eq!(several.rejected_pairs, 0);
    // The receding pairs' earlier positions lie ahead along the view, 1.0 and 1.4 m: depths
    // from 1 m would sweep points through those cameras' own planes (more than 1024 planes),
    // so both are left out of each of the five later receding pairs.
    assert_eq!(several.views_dropped, 10);
    // Baselines up to 1.4 m instead of 0.4 m: the standard map puts fewer voxels behind the
    // wall and in the sky after the strafe phase.
    let spurious = |report: &fuzzyvox::eval::ExperimentReport| {
        report.maps["logodds"].after["after_strafe"].spurious_unknown
    };
    assert!(
        2 * spurious(&several) < spurious(&pairs),
        "{} with four views, {} with pairs",
        spurious(&several),
        spurious(&pairs)
    );
    // Weighting each image by 2 / views (the default) against counting each as a full
    // observation: the standard map ignores confidence and is the same; the fuzzy map, which
    // no longer counts the images' shared views several times, puts fewer voxels behind the
    // wall and in the sky.
    assert!(several.weigh_reused_views);
    assert_eq!(pairs.views_summary(), None);
    assert!(
        several
            .views_summary()
            .is_some_and(|s| s.starts_with("up to 4 views") && s.ends_with("weighted 2 / views")),
        "{:?}",
        several.views_summary()
    );
    let unweighted = run_experiment(
        &scenario,
        &ExperimentConfig {
            resolution: 0.25,
            views: 4,
            weigh_reused_views: false,
            ..ExperimentConfig::default()
        },
    )
    .unwrap()
    .report;
    assert!(
        unweighted
            .views_summary()
            .is_some_and(|s| s.ends_with("images unweighted"))
    );
    assert_eq!(
        unweighted.maps["logodds"].metrics,
        several.maps["logodds"].metrics
    );
    let fuzzy = |report: &fuzzyvox::eval::ExperimentReport| report.maps["fuzzy"].metrics;
    let (weighted, unweighted) = (fuzzy(&several), fuzzy(&unweighted));
    assert!(
        weighted.occupied_precision > unweighted.occupied_precision + 0.05
            && weighted.spurious_unknown <= unweighted.spurious_unknown,
        "{weighted:?} weighted, {unweighted:?} unweighted"
    );
    let config = ExperimentConfig {
        views: 1,
        ..ExperimentConfig::default()
    };
    assert!(matches!(
        run_experiment(&scenario, &config),
        Err(fuzzyvox::Error::InvalidParameter { name: "views", .. })
    ));
}
