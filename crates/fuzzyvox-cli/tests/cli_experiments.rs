//! The experiment commands (`eval`, `simulate`, `demo`), run as a user would.

mod common;

use std::path::PathBuf;

use common::browser::Browser;
use common::{fuzzyvox, json};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn fails_with(output: &std::process::Output, needle: &str) {
    assert!(!output.status.success(), "expected a failure");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains(needle), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
}

#[test]
fn eval_wall_reports_every_map_after_each_phase_with_flights_and_figures() {
    let out = scratch("eval");
    let report = json(&fuzzyvox(&[
        "eval",
        "--scenario",
        "wall",
        "--res",
        "0.25",
        "--plan",
        "4",
        "--ops",
        "max",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(report["scenario"], "wall");
    for name in ["logodds", "alpha", "fuzzy", "fuzzy:maximum"] {
        let map = &report["maps"][name];
        for key in [
            "occupied_precision",
            "occupied_recall",
            "occupied_f1",
            "holes",
            "spurious_unknown",
            "chamfer_m",
            "plan_queries",
            "plan_success",
            "plan_collisions",
            "path_length_ratio",
            "plan_collision_details",
        ] {
            assert!(map.get(key).is_some(), "{name} lacks {key}: {map}");
        }
        assert!(map["after_strafe"]["occupied_f1"].is_number(), "{name}");
        assert_eq!(map["plan_queries"], 4);
    }
    // The depth stage on the sampled pairs, against the true depth: the distribution rises.
    let stage = &report["depth_stage"];
    assert!(stage["pixels"].as_u64().unwrap() > 1000, "{stage}");
    let q = &stage["rel_error_quantiles"];
    let at = |k: &str| q[k].as_f64().unwrap();
    assert!(
        at("p10") <= at("p25") && at("p25") <= at("p50") && at("p50") <= at("p75"),
        "{q}"
    );
    assert!(at("p75") <= at("p90") && at("p50") < 0.2, "{q}");
    assert!((at("p50") - stage["median_rel_error"].as_f64().unwrap()).abs() < 1e-3);
    for file in [
        "metrics.json",
        "report.md",
        "wall-fuzzy.fvx",
        "wall-fuzzy.png",
        "wall-fuzzy-free.png",
        "wall-logodds-flights.png",
        "wall-pair0.png",
        "wall-pair6.png",
    ] {
        assert!(out.join(file).is_file(), "missing {file}");
    }
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("after strafe") && md.contains("![fuzzy](wall-fuzzy.png)"));
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn eval_with_several_views_reports_how_they_were_weighted() {
    let run = |extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--scenario",
            "wall",
            "--res",
            "0.25",
            "--views",
            "3",
        ];
        args.extend_from_slice(extra);
        args.push("--json");
        json(&fuzzyvox(&args))
    };
    let (weighted, unweighted) = (run(&[]), run(&["--unweighted-views"]));
    assert_eq!(weighted["views"], 3);
    assert_eq!(weighted["weigh_reused_views"], true);
    assert_eq!(unweighted["weigh_reused_views"], false);
    // Only the maps that weigh evidence by confidence change.
    assert_eq!(weighted["maps"]["logodds"], unweighted["maps"]["logodds"]);
    assert_ne!(weighted["maps"]["fuzzy"], unweighted["maps"]["fuzzy"]);
}

#[test]
fn eval_refuses_bad_arguments() {
    fails_with(
        &fuzzyvox(&["eval", "--scenario", "random", "--pairs", "0"]),
        "--pairs",
    );
    fails_with(
        &fuzzyvox(&["eval", "--scenario", "wall", "--ops", "frank:1"]),
        "--ops",
    );
    fails_with(
        &fuzzyvox(&["eval", "--scenario", "wall", "--res=-1"]),
        "resolution",
    );
    fails_with(&fuzzyvox(&["eval", "--scenario", "moon"]), "moon");
    fails_with(
        &fuzzyvox(&["eval", "--scenario", "wall", "--views", "18"]),
        "--views",
    );
}

#[test]
fn simulate_writes_frames_that_read_back_and_the_truth() {
    let out = scratch("simulate");
    let summary = json(&fuzzyvox(&[
        "simulate",
        "--scenario",
        "random",
        "--pairs",
        "2",
        "--seed",
        "5",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(summary["frames"], 4);
    assert!(summary["truth_occupied"].as_u64().unwrap() > 100);
    let depth = fuzzyvox::io::rgbd::read_depth_png_mm(&out.join("frame-000003.depth.png")).unwrap();
    assert_eq!((depth.width, depth.height), (320, 240));
    assert!(depth.depth.iter().any(|d| *d > 0.0));
    let pose = fuzzyvox::io::rgbd::read_pose_txt(&out.join("frame-000000.pose.txt")).unwrap();
    let scenario = fuzzyvox::sim::scenario::random(2, 5).unwrap();
    let expected = scenario.pairs[0].0.to_homogeneous();
    assert!((pose.to_homogeneous() - expected).abs().max() < 1e-8);
    let pairs = std::fs::read_to_string(out.join("pairs.txt")).unwrap();
    assert!(pairs.contains("0 1 flight") && pairs.contains("2 3 flight"));
    let info = fuzzyvox(&["info", out.join("gold.fvx").to_str().unwrap()]);
    assert!(info.status.success());
    let truth = std::fs::read_to_string(out.join("truth-occupied.xyz")).unwrap();
    assert_eq!(
        truth.lines().count() as u64,
        summary["truth_occupied"].as_u64().unwrap()
    );
    // Output under a file is an error with the path, not a panic.
    let blocker = out.join("pairs.txt");
    fails_with(
        &fuzzyvox(&[
            "simulate",
            "--scenario",
            "wall",
            "--out",
            blocker.join("inner").to_str().unwrap(),
        ]),
        "inner",
    );
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn demo_refuses_an_output_path_that_is_a_file() {
    let out = scratch("demo");
    std::fs::create_dir_all(&out).unwrap();
    let file = out.join("taken");
    std::fs::write(&file, b"not a folder").unwrap();
    fails_with(
        &fuzzyvox(&["demo", "--out", file.to_str().unwrap()]),
        "taken",
    );
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn demo_writes_the_report_maps_and_figures() {
    let out = scratch("demo-run");
    let run = fuzzyvox(&["demo", "--out", out.to_str().unwrap(), "--json"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // --json prints what metrics.json holds, with the folder and the time, and no progress.
    let printed = json(&run);
    assert!(
        run.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(printed["out"], out.to_str().unwrap());
    assert!(printed["seconds"].as_f64().unwrap() > 0.0);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for heading in ["## wall scenario", "## random scenario", "Planned flights"] {
        assert!(report.contains(heading), "report lacks {heading}");
    }
    let metrics: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("metrics.json")).unwrap()).unwrap();
    for scenario in ["wall", "random"] {
        assert_eq!(printed[scenario], metrics[scenario], "{scenario}");
        for map in ["logodds", "alpha", "fuzzy"] {
            let m = &metrics[scenario]["maps"][map];
            assert!(m["occupied_f1"].is_number(), "{scenario}/{map}");
            assert!(m["plan_queries"].as_u64().unwrap() > 0, "{scenario}/{map}");
            for ext in ["fvx", "bt", "ply", "png"] {
                let file = out.join(format!("{scenario}-{map}.{ext}"));
                assert!(file.is_file(), "missing {}", file.display());
            }
        }
    }
    // A short closed-loop flight per scenario, every map flying its own.
    for scenario in ["wall", "random"] {
        let closed = &metrics[scenario]["closed_loop"];
        assert_eq!(closed["goals"], 1, "{scenario}");
        for map in ["logodds", "alpha", "fuzzy"] {
            let m = &closed["maps"][map];
            assert!(m["reached"].as_f64().is_some(), "{scenario}/{map}");
            assert!(m["collisions"].as_u64().is_some(), "{scenario}/{map}");
            let figure = out.join(format!("{scenario}-fly-{map}-1.png"));
            assert!(figure.is_file(), "missing {}", figure.display());
        }
    }
    assert!(report.contains("### Closed-loop flights"));
    // Every figure, chart and viewer page the report links exists.
    for link in report.split("](").skip(1) {
        let name = &link[..link.find(')').unwrap()];
        if [".png", ".svg", ".html"]
            .iter()
            .any(|ext| name.ends_with(ext))
        {
            assert!(out.join(name).is_file(), "report links a missing {name}");
        }
    }
    // The wall scenario also compares aggregation operators.
    for (scenario, charts) in [
        ("wall", &["maps", "operators", "depth-confidence"][..]),
        ("random", &["maps", "depth-confidence"][..]),
    ] {
        for chart in charts {
            for ext in ["svg", "png"] {
                let file = out.join(format!("{scenario}-{chart}.{ext}"));
                assert!(file.is_file(), "missing {}", file.display());
            }
        }
    }
    // The report and every viewer page open in a browser without console errors, and each
    // page shows its map.
    if let Some(browser) = Browser::find("demo_writes_the_report_maps_and_figures (browser)") {
        let report_html = out.join("report.html");
        let run = browser.dump_dom(&report_html, "");
        assert!(run.console_errors().is_empty(), "{:#?}", run.console);
        assert!(run.dom.contains("<img"), "report.html shows no figures");
        for scenario in ["wall", "random"] {
            for map in ["logodds", "alpha", "fuzzy"] {
                let page = out.join(format!("{scenario}-{map}.html"));
                let shot = out.join(format!("{scenario}-{map}-shot.png"));
                let colors = browser.check_viewer_page(&page, "", &shot);
                assert!(
                    colors >= 20,
                    "{scenario}-{map}: the screenshot has only {colors} colours"
                );
                eprintln!("{scenario}-{map}.html: ready, {colors} colours");
            }
        }
    }
    std::fs::remove_dir_all(&out).unwrap();
}
