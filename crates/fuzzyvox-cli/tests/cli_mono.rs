//! `fuzzyvox mono`: maps from posed colour images through the one-camera depth stage, on a
//! simulated posed folder (the wall scenario as `fuzzyvox simulate` writes it) and, with
//! `FUZZYVOX_DATA`, on real 7-Scenes frames.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use std::path::{Path, PathBuf};

use common::{data_dir, fuzzyvox, json};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_mono")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The wall scenario's 24 frames in the RGB-D layout, with true depth.
fn simulated(name: &str) -> PathBuf {
    let dir = scratch(name).join("frames");
    json(&fuzzyvox(&[
        "simulate",
        "--scenario",
        "wall",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]));
    dir
}

fn mono(dir: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "mono",
        "--dir",
        dir.to_str().unwrap(),
        "--res",
        "0.2",
        "--near",
        "1",
        "--far",
        "40",
        "--holdout",
        "4",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ];
    args.extend_from_slice(extra);
    json(&fuzzyvox(&args))
}

fn map_bytes(dir: &Path) -> Vec<Vec<u8>> {
    ["logodds", "alpha", "fuzzy"]
        .iter()
        .map(|m| std::fs::read(dir.join(format!("{m}.fvx"))).unwrap())
        .collect()
}

#[test]
fn mono_maps_simulated_frames_deterministically_without_sensor_depth() {
    let frames = simulated("deterministic");
    let root = frames.parent().unwrap().to_path_buf();
    let first = mono(&frames, &root.join("maps-1"), &[]);
    assert_eq!(first["frames"], 24);
    assert_eq!(first["build_frames"], 18);
    assert_eq!(first["held_out_checked"], 6);
    assert!(
        first["maps"][0].get("plan_queries").is_none(),
        "no flights without --plan"
    );
    let images = first["depth_images"].as_u64().unwrap();
    assert!(images >= 10, "{first}");
    assert!(first["rectified"].as_u64().unwrap() > 0);
    assert!(
        first["swept"].as_u64().unwrap() > 0,
        "the receding phase is swept"
    );
    let skipped: u64 = first["skipped"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(images + skipped, 18, "{first}");
    // The depth stage on clean rendered images: close to the truth, intervals that hold it.
    let stage = &first["depth_stage"];
    assert!(
        stage["median_rel_error_top50"].as_f64().unwrap() < 0.05,
        "{stage}"
    );
    assert!(
        stage["interval_coverage_top50"].as_f64().unwrap() > 0.9,
        "{stage}"
    );
    assert!(stage["share_of_mapping_time"].as_f64().unwrap() > 0.0);
    let models: Vec<&str> = first["maps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["model"].as_str().unwrap())
        .collect();
    assert_eq!(models, ["logodds", "alpha", "fuzzy"]);
    for m in first["maps"].as_array().unwrap() {
        assert!(m["within_2_voxels"].as_f64().unwrap() > 0.1, "{m}");
    }

    // The same run again gives the same maps, byte for byte, and the same figures.
    let second = mono(&frames, &root.join("maps-2"), &[]);
    assert_eq!(
        map_bytes(&root.join("maps-1")),
        map_bytes(&root.join("maps-2"))
    );
    for key in ["depth_images", "skipped", "maps"] {
        let strip = |v: &serde_json::Value| {
            let mut v = v.clone();
            if let Some(maps) = v.as_array_mut() {
                for m in maps {
                    m["build_seconds"] = 0.into();
                    m["predict_seconds"] = 0.into();
                }
            }
            v
        };
        assert_eq!(strip(&first[key]), strip(&second[key]), "{key}");
    }
    assert_eq!(
        first["depth_stage"]["median_rel_error"],
        second["depth_stage"]["median_rel_error"]
    );

    // Sensor depth never reaches the maps: without the depth files, the same maps.
    let bare = root.join("no-depth");
    std::fs::create_dir_all(&bare).unwrap();
    for entry in std::fs::read_dir(&frames).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        if !name.ends_with(".depth.png") {
            std::fs::copy(&path, bare.join(&name)).unwrap();
        }
    }
    let without = mono(&bare, &root.join("maps-3"), &[]);
    assert_eq!(
        map_bytes(&root.join("maps-1")),
        map_bytes(&root.join("maps-3"))
    );
    assert_eq!(without["held_out_checked"], 0);
    assert_eq!(without["depth_stage"]["pixels"], 0);

    // Poses from a TUM trajectory (the same poses as quaternions, k-th line for the k-th frame,
    // the same times) give the same pairs and nearly the same maps: rotations rounded through
    // quaternions move some matches by a disparity step.
    let mut names: Vec<String> = std::fs::read_dir(&bare)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_str().unwrap().to_string())
        .filter(|n| n.ends_with(".pose.txt"))
        .collect();
    names.sort();
    let mut tum = String::from("# timestamp tx ty tz qx qy qz qw\n");
    for (k, name) in names.iter().enumerate() {
        let pose = fuzzyvox::io::rgbd::read_pose_txt(&bare.join(name)).unwrap();
        let (t, q) = (pose.translation.vector, pose.rotation.quaternion());
        tum.push_str(&format!(
            "{} {} {} {} {} {} {} {}\n",
            k as f64 / 30.0,
            t.x,
            t.y,
            t.z,
            q.i,
            q.j,
            q.k,
            q.w
        ));
        std::fs::remove_file(bare.join(name)).unwrap();
    }
    let trajectory = root.join("poses.tum");
    std::fs::write(&trajectory, tum).unwrap();
    let from_tum = mono(
        &bare,
        &root.join("maps-4"),
        &["--trajectory", trajectory.to_str().unwrap()],
    );
    assert_eq!(from_tum["depth_images"], first["depth_images"]);
    assert_eq!(from_tum["skipped"], first["skipped"]);
    let fuzzy = |dir: &Path| {
        fuzzyvox::FuzzyMap::load(dir.join("fuzzy.fvx"))
            .unwrap()
            .counts()
    };
    let (a, b) = (fuzzy(&root.join("maps-4")), fuzzy(&root.join("maps-1")));
    for (x, y) in [(a.occupied, b.occupied), (a.free, b.free)] {
        assert!(x.abs_diff(y) * 10 <= y, "{a:?} against {b:?}");
    }
}

#[test]
fn mono_refuses_bad_folders_and_options_clearly() {
    let frames = simulated("refusals");
    let root = frames.parent().unwrap().to_path_buf();
    let fails = |args: &[&str], says: &str| {
        let out = fuzzyvox(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    };
    let dir = frames.to_str().unwrap();
    fails(
        &[
            "mono", "--dir", dir, "--res", "0.2", "--near", "5", "--far", "2",
        ],
        "0 < near < far",
    );
    fails(
        &["mono", "--dir", dir, "--res", "0.2", "--holdout", "1"],
        "--holdout 1",
    );
    let empty = root.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    fails(
        &["mono", "--dir", empty.to_str().unwrap(), "--res", "0.2"],
        "frame-N.color.png",
    );
    // A frame without its pose.
    let broken = root.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    for name in [
        "camera-intrinsics.txt",
        "frame-000000.color.png",
        "frame-000001.color.png",
    ] {
        std::fs::copy(frames.join(name), broken.join(name)).unwrap();
    }
    std::fs::copy(
        frames.join("frame-000000.pose.txt"),
        broken.join("frame-000000.pose.txt"),
    )
    .unwrap();
    fails(
        &["mono", "--dir", broken.to_str().unwrap(), "--res", "0.2"],
        "frame-000001.pose.txt",
    );
    // A trajectory of the wrong length, or with a bad line.
    let short = root.join("short.tum");
    std::fs::write(&short, "0 0 0 0 0 0 0 1\n").unwrap();
    let args = |t: &Path| {
        vec![
            "mono".to_string(),
            "--dir".into(),
            dir.into(),
            "--res".into(),
            "0.2".into(),
            "--trajectory".into(),
            t.to_str().unwrap().into(),
        ]
    };
    let run = |t: &Path, says: &str| {
        let owned = args(t);
        let refs: Vec<&str> = owned.iter().map(String::as_str).collect();
        fails(&refs, says);
    };
    run(&short, "trajectory poses");
    let bad = root.join("bad.tum");
    std::fs::write(&bad, "0 0 0 0 0 0 0 1\n1 0 0 nan 0 0 0 1\n").unwrap();
    run(&bad, "bad.tum:2");
    let unnormalised = root.join("unnormalised.tum");
    std::fs::write(&unnormalised, "0 0 0 0 0 0 0 2\n").unwrap();
    run(&unnormalised, "quaternion");
}

#[test]
fn mono_plans_flights_through_every_map_against_a_map_of_the_sensor_depth() {
    let frames = simulated("flights");
    let root = frames.parent().unwrap().to_path_buf();
    let report = mono(&frames, &root.join("maps"), &["--plan", "8", "--seed", "3"]);
    let maps = report["maps"].as_array().unwrap();
    assert_eq!(maps.len(), 3);
    for map in maps {
        assert_eq!(map["plan_queries"], 8, "{map}");
        // The queries lie in the reference's free space, clear of its occupied voxels: the
        // reference solves them.
        assert!(
            map["reference_plan_success"].as_f64().unwrap() >= 0.75,
            "{map}"
        );
        assert_eq!(
            map["reference_plan_success"],
            maps[0]["reference_plan_success"]
        );
        let success = map["plan_success"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&success), "{map}");
        let collisions = map["plan_collisions"].as_u64().unwrap();
        let details = map["plan_collision_details"].as_array().unwrap();
        assert_eq!(details.len() as u64, collisions);
        for detail in details {
            assert!(
                detail["distance_to_surface"].as_f64().unwrap() < 0.2,
                "{detail}"
            );
            assert!(detail["class"].is_string(), "{detail}");
        }
        let failures = &map["plan_failures"];
        let failed: u64 = [
            "start_unsafe",
            "goal_unsafe",
            "disconnected",
            "out_of_region",
            "error",
        ]
        .iter()
        .map(|k| failures[*k].as_u64().unwrap())
        .sum();
        assert!(
            (failed as f64 - 8.0 * (1.0 - success)).abs() < 1e-9,
            "{failures} against {success}"
        );
    }
    // --out writes each map, its top view and its viewer page with the camera's path.
    for model in ["logodds", "alpha", "fuzzy"] {
        let out = root.join("maps");
        assert!(out.join(format!("{model}.fvx")).is_file());
        let top = image::open(out.join(format!("{model}-top.png"))).unwrap();
        assert!(top.width() >= 200 && top.height() >= 200, "{model}");
        let page = std::fs::read_to_string(out.join(format!("{model}.html"))).unwrap();
        assert!(page.contains("camera"), "{model}");
    }
    // The same seed draws the same queries: the same figures again.
    let again = mono(
        &frames,
        &root.join("maps-again"),
        &["--plan", "8", "--seed", "3"],
    );
    for (a, b) in maps.iter().zip(again["maps"].as_array().unwrap()) {
        for key in [
            "plan_success",
            "plan_collisions",
            "reference_plan_success",
            "plan_failures",
        ] {
            assert_eq!(a[key], b[key], "{key}");
        }
    }
    let refused = fuzzyvox(&[
        "mono",
        "--dir",
        frames.to_str().unwrap(),
        "--res",
        "0.2",
        "--plan",
        "0",
    ]);
    assert!(!refused.status.success());
    assert!(
        String::from_utf8_lossy(&refused.stderr).contains("flights to plan"),
        "{}",
        String::from_utf8_lossy(&refused.stderr)
    );
}

#[test]
fn mono_on_real_frames_reports_the_depth_stage() {
    let Some(data) = data_dir("mono_on_real_frames_reports_the_depth_stage") else {
        return;
    };
    let dir = data.join("rgbd-7scenes-redkitchen");
    let out = scratch("real");
    // The log-odds map of every 4th pixel's check is enough for the depth stage's figures.
    let run = |extra: &[&str]| {
        let mut args = vec![
            "mono",
            "--dir",
            dir.to_str().unwrap(),
            "--res",
            "0.05",
            "--model",
            "logodds",
            "--pixel-step",
            "4",
            "--json",
        ];
        args.extend_from_slice(extra);
        json(&fuzzyvox(&args))
    };
    let report = run(&["--out", out.to_str().unwrap()]);
    assert_eq!(report["frames"], 50);
    assert_eq!(report["held_out_checked"], 10);
    // The colour camera's own K was read.
    assert!(
        report["color_intrinsics"]
            .as_str()
            .unwrap()
            .ends_with("color-intrinsics.txt")
    );
    let stage = &report["depth_stage"];
    assert!(stage["pixels"].as_u64().unwrap() > 50_000, "{stage}");
    // The consistency check kept part of the depth, and what it kept is more accurate than the
    // unchecked depth of the same frames.
    let check = &report["consistency"];
    assert_eq!(check["neighbours"], 4);
    let (kept, checked) = (
        check["pixels_kept"].as_u64().unwrap(),
        check["pixels_checked"].as_u64().unwrap(),
    );
    assert!(kept > 0 && kept < checked, "{check}");
    let unchecked = run(&["--consistency", "0", "--views", "2"]);
    let raw = &unchecked["depth_stage"];
    assert_eq!(unchecked["consistency"]["pixels_checked"], 0);
    assert!(
        stage["median_rel_error"].as_f64().unwrap() < raw["median_rel_error"].as_f64().unwrap(),
        "checked {stage}, unchecked {raw}"
    );
    // Unchecked pairs: the confidence ranks the depth, the confident half being more accurate
    // than all pixels.
    assert!(
        raw["median_rel_error_top50"].as_f64().unwrap() < raw["median_rel_error"].as_f64().unwrap(),
        "{raw}"
    );
    assert!(report["frames_per_second"].as_f64().unwrap() > 0.0);
}

#[test]
fn mono_reads_jpeg_and_16_bit_frames() {
    let frames = simulated("jpeg");
    let root = frames.parent().unwrap().to_path_buf();
    let png = mono(&frames, &root.join("maps-png"), &[]);
    // The same frames as JPEG (quality 95) for even frame numbers and 16-bit grey PNG for odd.
    let converted = root.join("converted");
    std::fs::create_dir_all(&converted).unwrap();
    for entry in std::fs::read_dir(&frames).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        let Some(stem) = name.strip_suffix(".color.png") else {
            std::fs::copy(&path, converted.join(&name)).unwrap();
            continue;
        };
        let gray = image::open(&path).unwrap().to_luma8();
        let number: u32 = stem.trim_start_matches("frame-").parse().unwrap();
        if number.is_multiple_of(2) {
            let file = std::fs::File::create(converted.join(format!("{stem}.color.jpg"))).unwrap();
            let mut encoder = image::codecs::jpeg::JpegEncoder::new_with_quality(
                std::io::BufWriter::new(file),
                95,
            );
            encoder.encode_image(&gray).unwrap();
        } else {
            let wide = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(
                gray.width(),
                gray.height(),
                |x, y| image::Luma([u16::from(gray.get_pixel(x, y)[0]) * 257]),
            );
            wide.save(converted.join(&name)).unwrap();
        }
    }
    let mixed = mono(&converted, &root.join("maps-mixed"), &[]);
    assert_eq!(mixed["frames"], 24);
    assert_eq!(mixed["skipped"], png["skipped"], "{mixed}");
    let stage = &mixed["depth_stage"];
    assert!(
        stage["median_rel_error_top50"].as_f64().unwrap() < 0.05,
        "{stage}"
    );
    // Anything else is refused, naming the file.
    let bad = root.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    for entry in std::fs::read_dir(&frames).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, bad.join(path.file_name().unwrap())).unwrap();
    }
    std::fs::write(bad.join("frame-000003.color.png"), b"GIF89a not really").unwrap();
    let out = fuzzyvox(&[
        "mono",
        "--dir",
        bad.to_str().unwrap(),
        "--res",
        "0.2",
        "--near",
        "1",
        "--far",
        "40",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("frame-000003.color.png"), "{stderr}");
    assert!(stderr.contains("not a readable image"), "{stderr}");
}
