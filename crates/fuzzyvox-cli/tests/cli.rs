//! The command-line tool, run as a user would.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{data_dir, fuzzyvox, insert_wall, json};

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
            "not a map file fuzzyvox reads",
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

/// A fuzzy map of a 6 × 4 m wall 3 m ahead of a sensor at (0, 0, 0.5), saved in `dir`; its
/// observed extent is [0, -3, -1.5] to [3.1, 3.1, 2.6] m.
fn wall_map(dir: &std::path::Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut text = String::new();
    for i in 0..=120 {
        for j in 0..=80 {
            let (y, z) = (-3.0 + 0.05 * f64::from(i), -1.5 + 0.05 * f64::from(j));
            text.push_str(&format!("3.0 {y} {z}\n"));
        }
    }
    insert_wall(dir, &text)
}

#[test]
fn plan_through_a_saved_map() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-plan-{}", std::process::id()));
    let map = wall_map(&dir);
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

/// Runs `fuzzyvox plan` on `map` from 1.5, 0, 0.5 with `extra` arguments; expects a failure
/// with exit status 1 and returns standard error.
fn plan_failure(map: &std::path::Path, extra: &[&str]) -> String {
    let mut args = vec![
        "plan",
        "--map",
        map.to_str().unwrap(),
        "--from",
        "1.5,0,0.5",
    ];
    args.extend_from_slice(extra);
    let out = fuzzyvox(&args);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    stderr
}

#[test]
fn plan_failures_say_what_blocks_and_which_option_helps() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-why-{}", std::process::id()));
    let map = wall_map(&dir);
    let cases: [(&[&str], &[&str]); 6] = [
        // Behind the wall: outside everything the scan observed.
        (
            &["--to", "4,0,0.5"],
            &[
                "goal is not safe",
                "outside the map's observed extent [0.00, -3.00, -1.50] to [3.10, 3.10, 2.60] m",
                "hint: try a --to inside that extent, or `--unknown cost`",
            ],
        ),
        // Beside the sensor, outside the scan's cone but inside the extent.
        (
            &["--to", "0.5,2.5,0.5"],
            &["its voxel is unknown", "hint: try `--unknown cost`"],
        ),
        (
            &["--to", "3.05,0,0.5"],
            &["its voxel is occupied", "hint: try another --to"],
        ),
        // One free observation gives safety 0.36 (0.6², a hair under it after the fixed point of
        // exact accumulation, so the largest threshold that accepts it is 0.35).
        (
            &["--to", "2.5,0.3,0.6", "--safety", "0.9"],
            &[
                "start is not safe",
                "safety 0.36 is below the threshold 0.90",
                "a threshold of at most 0.35 would accept it",
                "hint: try `--safety 0.35` or lower",
            ],
        ),
        // 0.3 m from the wall; a 0.3 m vehicle needs 0.3 + √3 × 0.1 m.
        (
            &["--to", "2.75,0,0.5"],
            &[
                "nearest blocked voxel (occupied, centre 3.05, 0.05, 0.55) is 0.30 m away",
                "needs 0.47 m",
                "hint: try `--radius 0.12` or smaller",
            ],
        ),
        // Right against the wall no radius fits.
        (
            &["--to", "2.95,0,0.5"],
            &[
                "no vehicle radius would fit",
                "a --to farther from the blocked voxel",
            ],
        ),
    ];
    for (extra, expected) in cases {
        let stderr = plan_failure(&map, extra);
        for text in expected {
            assert!(stderr.contains(text), "{extra:?}: `{text}` not in {stderr}");
        }
    }
    // The suggested radius and threshold work when typed back.
    for extra in [
        &["--to", "2.75,0,0.5", "--radius", "0.12"][..],
        &["--to", "2.5,0.3,0.6", "--safety", "0.35"],
    ] {
        let mut args = vec![
            "plan",
            "--map",
            map.to_str().unwrap(),
            "--from",
            "1.5,0,0.5",
        ];
        args.extend_from_slice(extra);
        args.push("--json");
        assert!(
            !json(&fuzzyvox(&args))["waypoints"]
                .as_array()
                .unwrap()
                .is_empty()
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_json_failure_prints_the_reason() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-whyjson-{}", std::process::id()));
    let map = wall_map(&dir);
    for (to, failure, kind) in [
        ("4,0,0.5", "goal_unsafe", "outside_observed_extent"),
        ("2.75,0,0.5", "goal_unsafe", "too_close"),
    ] {
        let out = fuzzyvox(&[
            "plan",
            "--map",
            map.to_str().unwrap(),
            "--from",
            "1.5,0,0.5",
            "--to",
            to,
            "--json",
        ]);
        assert_eq!(out.status.code(), Some(1));
        let report: serde_json::Value =
            serde_json::from_slice(&out.stdout).expect("one JSON object on stdout");
        assert_eq!(report["failure"], failure);
        assert_eq!(report["reason"]["kind"], kind);
        assert_eq!(report["model"], "fuzzy");
        assert!(report["map"].as_str().unwrap().ends_with("wall.fvx"));
        assert!(
            report["error"]
                .as_str()
                .unwrap()
                .contains("goal is not safe")
        );
        assert!(report["hint"].is_string());
        assert!(report.get("waypoints").is_none());
        // The message goes to standard error too, as for every failure.
        assert!(String::from_utf8_lossy(&out.stderr).contains("goal is not safe"));
    }
    let out = fuzzyvox(&[
        "plan",
        "--map",
        map.to_str().unwrap(),
        "--from",
        "1.5,0,0.5",
        "--to",
        "4,0,0.5",
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let extent = &report["reason"]["extent"];
    assert_eq!(extent["min"].as_array().unwrap().len(), 3);
    assert!((extent["max"][0].as_f64().unwrap() - 3.1).abs() < 1e-9);
    let close = fuzzyvox(&[
        "plan",
        "--map",
        map.to_str().unwrap(),
        "--from",
        "1.5,0,0.5",
        "--to",
        "2.75,0,0.5",
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&close.stdout).unwrap();
    let reason = &report["reason"];
    assert_eq!(reason["nearest"]["class"], "occupied");
    assert!((reason["clearance"].as_f64().unwrap() - 0.3).abs() < 1e-6);
    assert!((reason["vehicle_radius"].as_f64().unwrap() - 0.3).abs() < 1e-9);
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
fn stereo_reads_a_jpeg_pair() {
    let Some(dir) = data_dir("stereo_reads_a_jpeg_pair") else {
        return;
    };
    let folder = dir.join("middlebury-motorcycle");
    let out = std::env::temp_dir().join(format!("fuzzyvox-stereo-jpeg-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    // The Middlebury pair as colour JPEG at quality 95, the most common camera format.
    for name in ["im0", "im1"] {
        let image = image::open(folder.join(format!("{name}.png")))
            .unwrap()
            .to_rgb8();
        let file = std::fs::File::create(out.join(format!("{name}.jpg"))).unwrap();
        image::codecs::jpeg::JpegEncoder::new_with_quality(std::io::BufWriter::new(file), 95)
            .encode_image(&image)
            .unwrap();
    }
    let path = |p: std::path::PathBuf| p.to_str().unwrap().to_string();
    let report = json(&fuzzyvox(&[
        "stereo",
        "--left",
        &path(out.join("im0.jpg")),
        "--right",
        &path(out.join("im1.jpg")),
        "--calib",
        &path(folder.join("calib.txt")),
        "--gt",
        &path(folder.join("disp0GT.pfm")),
        "--ndisp",
        "80",
        "--json",
    ]));
    assert_eq!(report["width"], 741);
    // JPEG's block noise costs some density, little accuracy: measured bad-2 of the matched
    // pixels 4.1% (PNG 3.8%), bad-2 of all 20.3% (16.8%), density 83.1% (86.5%).
    assert!(report["bad2_matched"].as_f64().unwrap() <= 5.0, "{report}");
    assert!(report["bad2_all"].as_f64().unwrap() <= 22.0, "{report}");
    assert!(report["density"].as_f64().unwrap() > 80.0, "{report}");
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

/// The `fuzzyvox plan` examples in a text: lines of the form `fuzzyvox plan ...` or
/// `cargo run --release -- plan ...` (after an optional `$ ` prompt, without a trailing
/// `# comment` or `> file`), skipping synopses (`X,Y,Z`). An example followed by a line that starts with
/// `error:` is expected to fail with that line's first words.
fn plan_examples(text: &str) -> Vec<(String, Option<String>)> {
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let mut examples = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let line = line.strip_prefix("$ ").unwrap_or(line);
        let line = line.replace("cargo run --release -- plan ", "fuzzyvox plan ");
        if !line.starts_with("fuzzyvox plan ") || line.contains("X,Y,Z") {
            continue;
        }
        // A trailing comment or redirection of the output is the shell's, not the command's.
        let command = line.split(" #").next().unwrap_or(&line);
        let command = command
            .split(" > ")
            .next()
            .unwrap_or(command)
            .trim()
            .to_string();
        let error = lines
            .get(i + 1)
            .filter(|next| next.starts_with("error:"))
            .map(|next| next.chars().take(40).collect());
        examples.push((command, error));
    }
    examples
}

#[test]
fn printed_plan_examples_work() {
    let Some(data) = data_dir("printed_plan_examples_work") else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-examples-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The map the examples use, made as the README says.
    let map = dir.join("scan.fvx");
    json(&fuzzyvox(&[
        "insert",
        "--cloud",
        data.join("octomap-samples/scan.dat").to_str().unwrap(),
        "--res",
        "0.1",
        "--out",
        map.to_str().unwrap(),
        "--json",
    ]));
    // The README's map of a robot recording, made as it says.
    let room = dir.join("room.fvx");
    json(&fuzzyvox(&[
        "insert",
        "--bag",
        data.join("robot-logs/hololens-000.bag").to_str().unwrap(),
        "--topic",
        "/camera/depth/points",
        "--res",
        "0.05",
        "--out",
        room.to_str().unwrap(),
        "--json",
    ]));
    let root = common::repo_root();
    let mut examples = Vec::new();
    for doc in ["README.md", "docs/planning.md", "docs/cli.md"] {
        let found = plan_examples(&std::fs::read_to_string(root.join(doc)).unwrap());
        assert!(!found.is_empty(), "{doc} has no plan example");
        examples.extend(found);
    }
    for help in [&["--help"][..], &["plan", "--help"]] {
        let out = fuzzyvox(help);
        let found = plan_examples(&String::from_utf8_lossy(&out.stdout));
        assert!(!found.is_empty(), "{help:?} shows no plan example");
        examples.extend(found);
    }
    for (command, error) in examples {
        let args: Vec<String> = command
            .split_whitespace()
            .skip(1)
            .map(|a| match a {
                "scan.fvx" => map.to_str().unwrap().to_string(),
                "room.fvx" => room.to_str().unwrap().to_string(),
                // OctoMap's own map, wherever the data folder is.
                other if other.ends_with("octomap-samples/geb079.bt") => data
                    .join("octomap-samples/geb079.bt")
                    .to_str()
                    .unwrap()
                    .to_string(),
                other => other.to_string(),
            })
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = fuzzyvox(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        match error {
            None => {
                assert!(out.status.success(), "`{command}` failed: {stderr}");
                if args.contains(&"--json") {
                    let plan: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
                    assert!(
                        plan["waypoints"].as_array().unwrap().len() >= 2,
                        "{command}"
                    );
                } else {
                    assert!(
                        String::from_utf8_lossy(&out.stdout).starts_with("path of"),
                        "{command}"
                    );
                }
            }
            Some(error) => {
                assert_eq!(out.status.code(), Some(1), "`{command}`: {stderr}");
                assert!(stderr.starts_with(&error), "`{command}`: {stderr}");
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A map of `cloud` (text `x y z` lines) from `origin`, saved as `dir/name.fvx`.
fn insert_map(
    dir: &std::path::Path,
    name: &str,
    points: &str,
    extra: &[&str],
) -> std::path::PathBuf {
    let cloud = dir.join(format!("{name}.xyz"));
    std::fs::write(&cloud, points).unwrap();
    let map = dir.join(format!("{name}.fvx"));
    let mut args = vec![
        "insert",
        "--cloud",
        cloud.to_str().unwrap(),
        "--origin",
        "0,0,0.5",
        "--out",
        map.to_str().unwrap(),
        "--json",
    ];
    args.extend_from_slice(extra);
    json(&fuzzyvox(&args));
    map
}

#[test]
fn merge_combines_fuzzy_maps_and_refuses_the_rest() {
    use fuzzyvox::AnyMap;
    let dir = std::env::temp_dir().join(format!("fuzzyvox-cli-merge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Two halves of a wall seen from the same place, and the wall seen through a gap.
    let mut left = String::new();
    let mut right = String::new();
    for i in 0..=60 {
        for j in 0..=40 {
            let (y, z) = (-3.0 + 0.05 * f64::from(i), -1.0 + 0.05 * f64::from(j));
            left.push_str(&format!("3.0 {y} {z}\n"));
            right.push_str(&format!("3.0 {} {z}\n", -y));
        }
    }
    let a = insert_map(&dir, "left", &left, &["--res", "0.1"]);
    let b = insert_map(&dir, "right", &right, &["--res", "0.1"]);
    let out = dir.join("merged.fvx");
    let report = json(&fuzzyvox(&[
        "merge",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(report["maps"], 2);
    // The command's map is the library's merge of the two files, byte for byte.
    let (AnyMap::Fuzzy(mut expected), AnyMap::Fuzzy(other)) =
        (AnyMap::load(&a).unwrap(), AnyMap::load(&b).unwrap())
    else {
        panic!("fuzzy maps expected");
    };
    let (left_occupied, right_occupied) = (expected.counts().occupied, other.counts().occupied);
    expected.merge(&other).unwrap();
    assert_eq!(std::fs::read(&out).unwrap(), expected.to_bytes());
    let merged = AnyMap::load(&out).unwrap();
    let occupied = merged.as_map().counts().occupied;
    assert_eq!(report["occupied"], occupied);
    assert!(
        occupied > left_occupied.max(right_occupied),
        "{occupied} occupied"
    );
    assert_eq!(
        merged
            .as_map()
            .class_at_point(&nalgebra::Point3::new(3.0, -2.0, 0.0))
            .unwrap(),
        fuzzyvox::VoxelClass::Occupied
    );

    // Refused, and nothing written: another resolution, a log-odds map, an OctoMap tree.
    let coarse = insert_map(&dir, "coarse", &left, &["--res", "0.2"]);
    let logodds = insert_map(
        &dir,
        "logodds",
        &left,
        &["--res", "0.1", "--model", "logodds"],
    );
    let refused = dir.join("refused.fvx");
    for (other, message) in [
        (&coarse, "resolutions differ"),
        (&logodds, "only fuzzy maps merge"),
    ] {
        let run = fuzzyvox(&[
            "merge",
            a.to_str().unwrap(),
            other.to_str().unwrap(),
            "--out",
            refused.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success() && stderr.contains(message),
            "{stderr}"
        );
        assert!(!refused.exists());
    }
    let missing = fuzzyvox(&[
        "merge",
        "/nonexistent.fvx",
        "--out",
        refused.to_str().unwrap(),
    ]);
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("/nonexistent.fvx"));
    std::fs::remove_dir_all(&dir).unwrap();
}
