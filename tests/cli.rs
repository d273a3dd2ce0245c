//! The command-line tool, run as a user would.

mod common;

use common::{data_dir, fuzzyvox, json};

#[test]
fn insert_logodds_reports_octomap_counts() {
    let Some(dir) = data_dir("insert_logodds_reports_octomap_counts") else {
        return;
    };
    let scan = dir.join("octomap-samples/scan.dat");
    let out = fuzzyvox(&[
        "insert",
        "--cloud",
        scan.to_str().unwrap(),
        "--res",
        "0.05",
        "--model",
        "logodds",
        "--json",
    ]);
    let report = json(&out);
    assert_eq!(report["model"], "logodds");
    assert_eq!(report["points"], 88_206);
    assert_eq!(report["occupied"], 40_568);
    assert_eq!(report["free"], 3_855_241);
    for key in [
        "resolution",
        "ambiguous",
        "unknown",
        "insert_seconds",
        "memory_bytes",
    ] {
        assert!(report.get(key).is_some(), "missing {key}");
    }
}

#[test]
fn insert_save_and_info_round_trip() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cloud = dir.join("cloud.xyz");
    let mut text = String::from("# x y z confidence\n");
    for i in 0..100 {
        text.push_str(&format!("3.0 {} 0.5 0.9\n", -1.0 + 0.02 * f64::from(i)));
    }
    std::fs::write(&cloud, text).unwrap();
    for model in ["fuzzy", "logodds", "alpha"] {
        let map = dir.join(format!("{model}.fvx"));
        let inserted = json(&fuzzyvox(&[
            "insert",
            "--cloud",
            cloud.to_str().unwrap(),
            "--res",
            "0.1",
            "--model",
            model,
            "--out",
            map.to_str().unwrap(),
            "--json",
        ]));
        assert_eq!(inserted["model"], model);
        assert!(
            inserted["occupied"].as_u64().unwrap() > 10,
            "{model}: {inserted}"
        );
        let info = json(&fuzzyvox(&["info", map.to_str().unwrap(), "--json"]));
        assert_eq!(info["model"], model);
        assert_eq!(info["occupied"], inserted["occupied"]);
        assert_eq!(info["free"], inserted["free"]);
        let text = fuzzyvox(&["info", map.to_str().unwrap()]);
        assert!(text.status.success());
        assert!(String::from_utf8_lossy(&text.stdout).contains("occupied"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_are_clear_and_exit_non_zero() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let plain = dir.join("plain.xyz");
    std::fs::write(&plain, "1 2 3\n4 5 6\n").unwrap();
    let bad = dir.join("bad.xyz");
    std::fs::write(&bad, "1 2 3\n4 five 6\n").unwrap();
    let not_a_map = dir.join("not-a-map.fvx");
    std::fs::write(&not_a_map, "hello").unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "insert",
                "--cloud",
                plain.to_str().unwrap(),
                "--res",
                "0.1",
                "--model",
                "alpha",
            ],
            "needs a confidence per point",
        ),
        (
            vec!["insert", "--cloud", bad.to_str().unwrap(), "--res", "0.1"],
            ":2:",
        ),
        (
            vec!["insert", "--cloud", plain.to_str().unwrap(), "--res", "-1"],
            "resolution",
        ),
        (
            vec![
                "insert",
                "--cloud",
                plain.to_str().unwrap(),
                "--res",
                "0.1",
                "--op",
                "dombi",
            ],
            "dombi",
        ),
        (
            vec!["insert", "--cloud", "/nonexistent.xyz", "--res", "0.1"],
            "nonexistent",
        ),
        (
            vec!["info", not_a_map.to_str().unwrap()],
            "not a fuzzyvox map",
        ),
    ];
    for (args, expected) in cases {
        let out = fuzzyvox(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_reads_octomap_scan_graphs_and_alpha_refuses_them() {
    let Some(dir) = data_dir("insert_reads_octomap_scan_graphs_and_alpha_refuses_them") else {
        return;
    };
    let graph = dir.join("octomap-samples/spherical_scan.graph");
    let report = json(&fuzzyvox(&[
        "insert",
        "--cloud",
        graph.to_str().unwrap(),
        "--res",
        "0.2",
        "--model",
        "logodds",
        "--json",
    ]));
    assert_eq!(report["scans"], 1);
    assert_eq!(report["points"], 10_201);
    // OctoMap 1.9.7 (ScanGraph::readBinary, then OcTree::insertPointCloud of each node at
    // 0.2 m) holds 425 occupied and 2,262 free voxels for this graph.
    assert_eq!(
        (report["occupied"].as_u64(), report["free"].as_u64()),
        (Some(425), Some(2262))
    );
    let alpha = fuzzyvox(&[
        "insert",
        "--cloud",
        graph.to_str().unwrap(),
        "--res",
        "0.2",
        "--model",
        "alpha",
    ]);
    assert!(!alpha.status.success());
    assert!(String::from_utf8_lossy(&alpha.stderr).contains("needs a confidence per point"));
}

#[test]
fn plan_through_a_saved_map() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-plan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A 6 × 4 m wall 3 m ahead of the sensor.
    let cloud = dir.join("wall.xyz");
    let mut text = String::new();
    for i in 0..=120 {
        for j in 0..=80 {
            let (y, z) = (-3.0 + 0.05 * f64::from(i), -1.5 + 0.05 * f64::from(j));
            text.push_str(&format!("3.0 {y} {z}\n"));
        }
    }
    std::fs::write(&cloud, text).unwrap();
    let map = dir.join("wall.fvx");
    json(&fuzzyvox(&[
        "insert",
        "--cloud",
        cloud.to_str().unwrap(),
        "--res",
        "0.1",
        "--origin",
        "0,0,0.5",
        "--out",
        map.to_str().unwrap(),
        "--json",
    ]));
    let plan = json(&fuzzyvox(&[
        "plan",
        "--map",
        map.to_str().unwrap(),
        "--from",
        "1.5,0,0.5",
        "--to",
        "2.5,0.3,0.6",
        "--radius",
        "0.1",
        "--json",
    ]));
    let waypoints = plan["waypoints"].as_array().unwrap();
    assert!(waypoints.len() >= 2);
    assert!(plan["length_m"].as_f64().unwrap() >= 1.0);
    assert!(plan["min_safety"].as_f64().unwrap() >= 0.2);
    // Behind the wall is unknown: no path, a clear error and a non-zero exit.
    let behind = fuzzyvox(&[
        "plan",
        "--map",
        map.to_str().unwrap(),
        "--from",
        "1.5,0,0.5",
        "--to",
        "4,0,0.5",
    ]);
    assert!(!behind.status.success());
    assert!(String::from_utf8_lossy(&behind.stderr).contains("goal is not safe"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stereo_reports_middlebury_accuracy_and_writes_maps() {
    let Some(dir) = data_dir("stereo_reports_middlebury_accuracy_and_writes_maps") else {
        return;
    };
    let folder = dir.join("middlebury-motorcycle");
    let out = std::env::temp_dir().join(format!("fuzzyvox-stereo-{}", std::process::id()));
    let report = json(&fuzzyvox(&[
        "stereo",
        "--middlebury",
        folder.to_str().unwrap(),
        "--ndisp",
        "80",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(report["width"], 741);
    assert_eq!(report["height"], 500);
    assert_eq!(report["disparities"], 80);
    assert!(report["seconds"].as_f64().unwrap() > 0.0);
    assert!(report["bad2_all"].as_f64().unwrap() <= 18.0, "{report}");
    assert!(
        report["bad2_top50_confidence"].as_f64().unwrap() < 2.0,
        "{report}"
    );
    assert!(report["density"].as_f64().unwrap() > 85.0, "{report}");
    for name in ["disparity", "depth", "near", "far", "confidence"] {
        let pfm = fuzzyvox::io::pfm::read_pfm(&out.join(format!("{name}.pfm"))).unwrap();
        assert_eq!((pfm.width, pfm.height), (741, 500));
        assert!(out.join(format!("{name}.png")).is_file());
    }
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn stereo_rejects_bad_inputs_without_panicking() {
    let missing = fuzzyvox(&["stereo", "--left", "a.png", "--right", "b.png"]);
    assert_eq!(missing.status.code(), Some(2), "clap usage error");
    let absent = fuzzyvox(&["stereo", "--middlebury", "/nonexistent/folder"]);
    assert_eq!(absent.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&absent.stderr).contains("error"));
    let Some(dir) = data_dir("stereo_rejects_bad_inputs_without_panicking") else {
        return;
    };
    let folder = dir.join("middlebury-motorcycle");
    let zero = fuzzyvox(&[
        "stereo",
        "--middlebury",
        folder.to_str().unwrap(),
        "--ndisp",
        "0",
    ]);
    assert_eq!(zero.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&zero.stderr).contains("num_disparities"));
    // Different image sizes: the right image is a depth PNG of another size.
    let other = dir.join("rgbd-7scenes-redkitchen/frame-000150.color.png");
    let sizes = fuzzyvox(&[
        "stereo",
        "--middlebury",
        folder.to_str().unwrap(),
        "--right",
        other.to_str().unwrap(),
    ]);
    assert_eq!(sizes.status.code(), Some(1));
    assert!(!String::from_utf8_lossy(&sizes.stderr).contains("panicked"));
}
