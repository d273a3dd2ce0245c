//! Every command of the built `fuzzyvox` binary given bad input: it exits with status 1 (a
//! reported error) or 2 (a usage error), never panics or dies of a signal, names the problem,
//! and leaves any existing output file as it was. Cases already in `cli.rs` are not repeated;
//! the table of every case is in `docs/robustness.md`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::fuzzyvox;

use std::path::{Path, PathBuf};

/// Runs a command that must fail with `status`, whose standard error must contain `expected`.
#[track_caller]
fn fails(args: &[&str], status: i32, expected: &str) {
    let out = fuzzyvox(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(status),
        "{args:?} exited with {:?}: {stderr}",
        out.status
    );
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    assert!(
        stderr.to_lowercase().contains(&expected.to_lowercase()),
        "{args:?}: expected `{expected}` in: {stderr}"
    );
    // Each cause once: no part of the message repeated.
    let parts: Vec<&str> = stderr.trim().split(": ").filter(|p| p.len() > 8).collect();
    for (i, part) in parts.iter().enumerate() {
        assert!(
            !parts[i + 1..].contains(part),
            "{args:?}: `{part}` repeated in: {stderr}"
        );
    }
    for path in args.iter().filter(|a| a.contains('/')) {
        assert!(
            stderr.matches(path).count() <= 1,
            "{args:?}: `{path}` named twice in: {stderr}"
        );
    }
}

/// A fresh folder for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-badcli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> String {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path.to_str().unwrap().to_string()
}

/// A small confident wall as a text cloud.
fn wall_cloud(dir: &Path) -> String {
    let mut text = String::new();
    for i in 0..60 {
        for j in 0..10 {
            let (y, z) = (-1.5 + 0.05 * f64::from(i), 0.1 * f64::from(j));
            text.push_str(&format!("3.0 {y} {z} 0.9\n"));
        }
    }
    write(dir, "wall.xyz", text)
}

/// Inserts the wall cloud and saves a fuzzy map; returns its path.
fn saved_map(dir: &Path) -> String {
    let cloud = wall_cloud(dir);
    let map = dir.join("map.fvx").to_str().unwrap().to_string();
    let out = fuzzyvox(&["insert", "--cloud", &cloud, "--res", "0.1", "--out", &map]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    map
}

// ---------------------------------------------------------------------------------------------
// insert
// ---------------------------------------------------------------------------------------------

#[test]
fn insert_refuses_absurd_resolutions() {
    let dir = scratch("res");
    let cloud = wall_cloud(&dir);
    for res in ["0", "nan", "inf", "1e9", "1e-9"] {
        fails(
            &["insert", "--cloud", &cloud, "--res", res],
            1,
            "resolution",
        );
    }
    fails(
        &["insert", "--cloud", &cloud, "--res", "ten"],
        2,
        "invalid value",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_of_an_empty_cloud_makes_an_empty_map() {
    // Documented: an empty file is a cloud of no points, and the map is empty.
    let dir = scratch("empty");
    let cloud = write(&dir, "empty.xyz", "");
    let out = fuzzyvox(&["insert", "--cloud", &cloud, "--res", "0.1", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["points"], 0);
    assert_eq!(report["occupied"], 0);
    assert_eq!(report["free"], 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_of_a_binary_file_names_the_line_and_writes_nothing() {
    let dir = scratch("binary");
    let cloud = write(&dir, "cloud.xyz", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\xff\xfe");
    let out = dir.join("out.fvx");
    fails(
        &[
            "insert",
            "--cloud",
            &cloud,
            "--res",
            "0.1",
            "--out",
            out.to_str().unwrap(),
        ],
        1,
        ":1: not UTF-8",
    );
    assert!(!out.exists(), "a failed insert wrote a map");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_of_a_damaged_scan_graph_leaves_the_old_map() {
    let dir = scratch("graph");
    let map = saved_map(&dir);
    let before = std::fs::read(&map).unwrap();
    // One node claiming 1000 points, with the bytes of two.
    let mut bytes = 1u32.to_le_bytes().to_vec();
    bytes.extend(1000u32.to_le_bytes());
    bytes.extend([0u8; 56]);
    let graph = write(&dir, "scan.graph", &bytes);
    fails(
        &["insert", "--cloud", &graph, "--res", "0.1", "--out", &map],
        1,
        "cannot fit",
    );
    let truncated = write(&dir, "short.graph", &bytes[..3]);
    fails(
        &[
            "insert", "--cloud", &truncated, "--res", "0.1", "--out", &map,
        ],
        1,
        "truncated",
    );
    assert_eq!(std::fs::read(&map).unwrap(), before, "the old map changed");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_of_a_log_with_a_nan_pose_names_the_line() {
    let dir = scratch("log");
    let log = write(
        &dir,
        "scan.log",
        "NODE 0 0 0 0 0 0\n1 0 0\nNODE 0 nan 0 0 0 0\n2 0 0\n",
    );
    fails(&["insert", "--cloud", &log, "--res", "0.1"], 1, ":3:");
    let empty = write(&dir, "empty.log", "# nothing\n");
    fails(&["insert", "--cloud", &empty, "--res", "0.1"], 1, "empty");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_refuses_a_point_a_thousand_kilometres_away_unless_cut() {
    let dir = scratch("far");
    let cloud = write(&dir, "far.xyz", "1 0 0\n1e6 0 0\n");
    for model in ["fuzzy", "logodds"] {
        fails(
            &[
                "insert", "--cloud", &cloud, "--res", "0.1", "--model", model,
            ],
            1,
            "ray length",
        );
    }
    let out = fuzzyvox(&[
        "insert",
        "--cloud",
        &cloud,
        "--res",
        "0.1",
        "--max-range",
        "20",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["clipped"], 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_refuses_bad_origins_ranges_cuts_and_operators() {
    let dir = scratch("options");
    let cloud = wall_cloud(&dir);
    let base = ["insert", "--cloud", cloud.as_str(), "--res", "0.1"];
    let with = |extra: &[&'static str]| -> Vec<String> {
        base.iter()
            .chain(extra)
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
    };
    let cases: [(&[&str], i32, &str); 10] = [
        (&["--origin", "nan,0,0"], 2, "finite"),
        (&["--origin", "1,2"], 2, "X,Y,Z"),
        (&["--max-range", "0"], 1, "max_range"),
        (&["--max-range", "-5"], 1, "max_range"),
        (&["--max-range", "nan"], 1, "max_range"),
        (&["--model", "alpha", "--cuts", "0"], 1, "cuts"),
        (&["--model", "alpha", "--cuts", "5000"], 1, "cuts"),
        (&["--op", "yager:0"], 1, "operator parameter p = 0"),
        (&["--op", "frank:1"], 1, "operator parameter s = 1"),
        (
            &["--model", "logodds", "--op", "max"],
            1,
            "fuzzy model only",
        ),
    ];
    for (extra, status, expected) in cases {
        let args = with(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails(&args, status, expected);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn insert_into_a_missing_folder_is_an_error() {
    let dir = scratch("out");
    let cloud = wall_cloud(&dir);
    let out = dir.join("no/such/folder/map.fvx");
    fails(
        &[
            "insert",
            "--cloud",
            &cloud,
            "--res",
            "0.1",
            "--out",
            out.to_str().unwrap(),
        ],
        1,
        "saving the map",
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// info and export
// ---------------------------------------------------------------------------------------------

#[test]
fn info_refuses_damaged_empty_and_foreign_files() {
    let dir = scratch("info");
    let map = saved_map(&dir);
    let bytes = std::fs::read(&map).unwrap();
    let truncated = write(&dir, "truncated.fvx", &bytes[..bytes.len() - 7]);
    let mut flipped = bytes.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 0x20;
    let flipped = write(&dir, "flipped.fvx", &flipped);
    let empty = write(&dir, "empty.fvx", b"");
    let bt = dir.join("map.bt");
    let out = fuzzyvox(&["export", &map, "--bt", bt.to_str().unwrap()]);
    assert!(out.status.success());
    if Path::new("/dev/zero").exists() {
        // An endless device: its first bytes are enough to refuse it.
        fails(&["info", "/dev/zero"], 1, "not a map file fuzzyvox reads");
        fails(
            &["insert", "--cloud", "/dev/zero", "--res", "0.1"],
            1,
            "line longer",
        );
    }
    for (path, expected) in [
        (truncated.as_str(), "length mismatch"),
        (flipped.as_str(), "checksum"),
        (empty.as_str(), "not a map file fuzzyvox reads"),
        (dir.to_str().unwrap(), "directory"),
        ("/nonexistent/map.fvx", "no such file"),
    ] {
        fails(&["info", path], 1, expected);
    }
    // OctoMap's own format is a map too.
    let info = fuzzyvox(&["info", bt.to_str().unwrap(), "--json"]);
    assert!(info.status.success());
    let damaged_bt = write(&dir, "damaged.bt", &std::fs::read(&bt).unwrap()[..60]);
    fails(&["info", &damaged_bt], 1, "damaged.bt");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_of_a_damaged_map_writes_no_tree() {
    let dir = scratch("export");
    let map = saved_map(&dir);
    let mut bytes = std::fs::read(&map).unwrap();
    bytes.truncate(100);
    let damaged = write(&dir, "damaged.fvx", &bytes);
    let bt = dir.join("out.bt");
    fails(
        &["export", &damaged, "--bt", bt.to_str().unwrap()],
        1,
        "length mismatch",
    );
    assert!(!bt.exists(), "a failed export wrote a tree");
    fails(&["export", &map], 2, "required arguments were not provided");
    let missing = dir.join("no/folder/out.bt");
    fails(
        &["export", &map, "--bt", missing.to_str().unwrap()],
        1,
        "writing",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// plan
// ---------------------------------------------------------------------------------------------

#[test]
fn plan_refuses_bad_maps_points_and_parameters() {
    let dir = scratch("plan");
    let map = saved_map(&dir);
    let damaged = write(&dir, "damaged.fvx", b"FUZZYVOX\x01\0\x01");
    let from = "0,0,0.5";
    let to = "2,0,0.5";
    fails(
        &["plan", "--map", &damaged, "--from", from, "--to", to],
        1,
        "length",
    );
    let cases: [(&[&str], i32, &str); 7] = [
        (&["--from", "nan,0,0", "--to", to], 2, "finite"),
        (&["--from", from, "--to", "0,inf,0"], 2, "finite"),
        (
            &["--from", from, "--to", "90000,0,0.5"],
            1,
            "planning region",
        ),
        (
            &["--from", from, "--to", to, "--radius", "-1"],
            1,
            "vehicle_radius",
        ),
        (
            &["--from", from, "--to", to, "--safety", "1.5"],
            1,
            "safety_threshold",
        ),
        (
            &[
                "--from",
                from,
                "--to",
                to,
                "--unknown",
                "cost",
                "--unknown-cost",
                "nan",
            ],
            1,
            "unknown cost",
        ),
        (&["--from", from, "--to", "3,0,0.5"], 1, "not safe"),
    ];
    for (extra, status, expected) in cases {
        let mut args = vec!["plan", "--map", map.as_str()];
        args.extend_from_slice(extra);
        fails(&args, status, expected);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unknown_cost_needs_unknown_cost_policy() {
    let dir = scratch("unknown-cost");
    let map = saved_map(&dir);
    let plan = [
        "plan",
        "--map",
        map.as_str(),
        "--from",
        "0,0,0.5",
        "--to",
        "2,0,0.5",
    ];
    let expected = "--unknown-cost only applies with `--unknown cost`";
    // Given alone or with unknown space forbidden, the cost would be ignored: a usage error.
    for extra in [
        &["--unknown-cost", "3"][..],
        &["--unknown", "forbid", "--unknown-cost", "3"],
    ] {
        let args: Vec<&str> = plan.iter().chain(extra).copied().collect();
        fails(&args, 2, expected);
    }
    // eval has the same pair of options and the same rule (checked before any work).
    fails(
        &[
            "eval",
            "--scenario",
            "wall",
            "--plan",
            "3",
            "--unknown-cost",
            "3",
        ],
        2,
        expected,
    );
    // With `--unknown cost` the cost is taken, with or without `--unknown-cost`.
    for extra in [
        &["--unknown", "cost"][..],
        &["--unknown", "cost", "--unknown-cost", "3"],
    ] {
        let args: Vec<&str> = plan.iter().chain(extra).copied().collect();
        let out = fuzzyvox(&args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// stereo
// ---------------------------------------------------------------------------------------------

const CALIB: &str = "cam0=[40 0 15.5; 0 40 11.5; 0 0 1]\ncam1=[40 0 15.5; 0 40 11.5; 0 0 1]\n\
                     doffs=0\nbaseline=100\nwidth=32\nheight=24\nndisp=16\n";

fn png(width: u32, height: u32, shift: u32) -> Vec<u8> {
    let image = image::GrayImage::from_fn(width, height, |x, y| {
        image::Luma([(((x + shift) * 53 % 251) ^ (y * 29 % 251)) as u8])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    image.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A Middlebury-style folder of 32 × 24 images whose right image is the left shifted by 4 px.
fn stereo_folder(dir: &Path) -> String {
    let folder = dir.join("pair");
    std::fs::create_dir_all(&folder).unwrap();
    write(&folder, "im0.png", png(32, 24, 4));
    write(&folder, "im1.png", png(32, 24, 0));
    write(&folder, "calib.txt", CALIB);
    folder.to_str().unwrap().to_string()
}

#[test]
fn stereo_on_a_small_valid_pair_succeeds() {
    // The control for the cases below: the same folder without damage matches.
    let dir = scratch("stereo-ok");
    let folder = stereo_folder(&dir);
    let out = fuzzyvox(&["stereo", "--middlebury", &folder, "--window", "5", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stereo_refuses_damaged_calibrations_and_images() {
    let dir = scratch("stereo-files");
    let folder = PathBuf::from(stereo_folder(&dir));
    let file = |name: &str| folder.join(name).to_str().unwrap().to_string();
    let (left, right, calib) = (file("im0.png"), file("im1.png"), file("calib.txt"));
    let stereo = |l: &str, r: &str, c: &str, extra: &[&str], expected: &str| {
        let mut args = vec!["stereo", "--left", l, "--right", r, "--calib", c];
        args.extend_from_slice(extra);
        fails(&args, 1, expected);
    };
    let no_baseline = write(
        &dir,
        "no-baseline.txt",
        CALIB.replacen("baseline=100\n", "", 1),
    );
    stereo(&left, &right, &no_baseline, &[], "baseline");
    let zero_focal = write(&dir, "zero.txt", CALIB.replacen("cam0=[40", "cam0=[0", 1));
    stereo(&left, &right, &zero_focal, &[], "fx");
    let binary = write(&dir, "binary.txt", png(4, 4, 0));
    stereo(&left, &right, &binary, &[], "not UTF-8");
    let pfm = write(&dir, "left.png", b"Pf\n32 24\n-1\n");
    stereo(&pfm, &right, &calib, &[], "not a readable image");
    let small = write(&dir, "small.png", png(16, 24, 0));
    stereo(&small, &right, &calib, &[], "the calibration says");
    stereo(&left, &small, &calib, &[], "size mismatch");
    let truncated_gt = write(&dir, "gt.pfm", b"Pf\n32 24\n-1\n\0\0\0\0");
    stereo(
        &left,
        &right,
        &calib,
        &["--gt", &truncated_gt],
        "length mismatch",
    );
    let mut small_gt = b"Pf\n2 2\n-1\n".to_vec();
    small_gt.extend([0u8; 16]);
    let small_gt = write(&dir, "small.pfm", small_gt);
    stereo(&left, &right, &calib, &["--gt", &small_gt], "comparing");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stereo_refuses_bad_matching_parameters_and_outputs() {
    let dir = scratch("stereo-params");
    let folder = stereo_folder(&dir);
    let a_file = write(&dir, "a-file", "not a folder");
    let cases: [(&[&str], i32, &str); 6] = [
        (&["--window", "8"], 1, "window"),
        (&["--window", "17"], 1, "window"),
        (&["--ndisp", "5000"], 1, "num_disparities"),
        (&["--delta", "nan"], 1, "delta"),
        (&["--delta=-1"], 1, "delta"),
        (&["--out", a_file.as_str()], 1, "error"),
    ];
    for (extra, status, expected) in cases {
        let mut args = vec!["stereo", "--middlebury", folder.as_str()];
        args.extend_from_slice(extra);
        fails(&args, status, expected);
    }
    assert_eq!(std::fs::read(&a_file).unwrap(), b"not a folder");
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// eval and demo
// ---------------------------------------------------------------------------------------------

#[test]
fn eval_refuses_bad_resolutions_and_operators_before_working() {
    for res in ["0", "-0.2", "nan", "5000"] {
        let res = format!("--res={res}");
        fails(&["eval", "--scenario", "wall", &res], 1, "resolution");
    }
    fails(
        &["eval", "--scenario", "wall", "--ops", "max,dombi:-1"],
        1,
        "dombi",
    );
    // `max` and `min` name one t-conorm: its map would be listed twice.
    fails(
        &["eval", "--scenario", "wall", "--ops", "max,min"],
        1,
        "the operator maximum is listed twice",
    );
    fails(&["eval", "--scenario", "moon"], 2, "invalid value");
}

#[test]
fn eval_of_no_pairs_is_refused() {
    // A random flight of zero pairs would observe nothing: a usage error, not an empty report.
    fails(
        &["eval", "--scenario", "random", "--pairs", "0", "--json"],
        1,
        "--pairs must be at least 1",
    );
}

#[test]
fn demo_refuses_an_output_path_that_is_a_file() {
    let dir = scratch("demo");
    let file = write(&dir, "report", "keep me");
    fails(&["demo", "--out", &file], 1, "creating");
    assert_eq!(std::fs::read(&file).unwrap(), b"keep me");
    std::fs::remove_dir_all(&dir).unwrap();
}
