//! Robot recordings on the command line: `insert --bag`, `info --bag` and `mono --bag` on the
//! shared recordings (`FUZZYVOX_DATA/robot-logs`), and their errors.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use std::path::{Path, PathBuf};

use common::{data_dir, fuzzyvox, json};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_bags")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn logs(data: &Path, name: &str) -> String {
    data.join("robot-logs")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

fn stderr(output: &std::process::Output) -> String {
    assert!(!output.status.success(), "expected a failure");
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The HoloLens recording as a ROS 1 bag and as a ROS 2 folder gives one map file, byte for
/// byte, for every model; the log-odds map has OctoMap's counts for the same clouds and origins
/// (OctoMap on the scan list that `scripts/check-bags` writes from the bag with rosbags).
#[test]
fn both_recordings_give_the_same_map_file_with_octomaps_counts() {
    let Some(data) = data_dir("both_recordings_give_the_same_map_file_with_octomaps_counts") else {
        return;
    };
    let dir = scratch("same");
    for model in ["logodds", "fuzzy"] {
        let mut files = Vec::new();
        for bag in ["hololens-000.bag", "hololens-000-mcap"] {
            let out = dir.join(format!("{model}-{bag}.fvx"));
            let report = json(&fuzzyvox(&[
                "insert",
                "--bag",
                &logs(&data, bag),
                "--topic",
                "/camera/depth/points",
                "--res",
                "0.05",
                "--model",
                model,
                "--out",
                out.to_str().unwrap(),
                "--json",
            ]));
            assert_eq!(report["scans"], 80);
            assert_eq!(report["points"], 1_138_584);
            if model == "logodds" {
                assert_eq!(report["occupied"], 28_011, "OctoMap's occupied count");
                assert_eq!(report["free"], 351_202, "OctoMap's free count");
            }
            files.push(std::fs::read(&out).unwrap());
        }
        assert!(
            files[0] == files[1],
            "{model}: the two recordings' files differ"
        );
    }
}

#[test]
fn info_lists_topics_and_the_tf_tree() {
    let Some(data) = data_dir("info_lists_topics_and_the_tf_tree") else {
        return;
    };
    let info = json(&fuzzyvox(&[
        "info",
        "--bag",
        &logs(&data, "jsk-watercan.bag"),
        "--json",
    ]));
    assert_eq!(info["format"], "ros1");
    assert_eq!(info["message_count"], 3533);
    let topics = info["topics"].as_array().unwrap();
    assert_eq!(topics.len(), 3);
    assert_eq!(topics[1]["name"], "/tf");
    assert_eq!(topics[1]["type"], "tf/tfMessage");
    assert_eq!(topics[1]["count"], 333);
    assert!(info["tf"].as_array().unwrap().len() > 50);
    let text = fuzzyvox(&["info", "--bag", &logs(&data, "hololens-000-mcap")]);
    let text = String::from_utf8_lossy(&text.stdout).into_owned();
    assert!(text.contains("ros2 recording, 320 messages"), "{text}");
    assert!(text.contains("map -> camera_color_optical_frame"), "{text}");
}

/// Errors name what is missing, suggest the way out, and write nothing.
#[test]
fn bad_topics_and_missing_transforms_are_explained() {
    let Some(data) = data_dir("bad_topics_and_missing_transforms_are_explained") else {
        return;
    };
    let dir = scratch("errors");
    let out = dir.join("map.fvx");
    let lidar = logs(&data, "luminar-embag.bag");
    let insert = |topic: &str, extra: &[&str]| {
        let mut args = vec![
            "insert",
            "--bag",
            &lidar,
            "--topic",
            topic,
            "--res",
            "0.5",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        fuzzyvox(&args)
    };
    let unknown = stderr(&insert("/points", &[]));
    assert!(
        unknown.contains("no messages on topic `/points`"),
        "{unknown}"
    );
    assert!(
        unknown.contains("point cloud topics: /luminar_pointcloud"),
        "{unknown}"
    );
    let no_tf = stderr(&insert("/luminar_pointcloud", &[]));
    assert!(
        no_tf.contains("no transform from `luminar_lidar` to `map`"),
        "{no_tf}"
    );
    assert!(no_tf.contains("give --frame luminar_lidar"), "{no_tf}");
    let wrong = stderr(&insert("/base_scan", &[]));
    assert!(wrong.contains("sensor_msgs/LaserScan"), "{wrong}");
    assert!(!out.exists(), "a failed insert wrote a map");
    let report = json(&insert(
        "/luminar_pointcloud",
        &["--frame", "luminar_lidar", "--json"],
    ));
    assert_eq!(report["scans"], 5);
    assert!(out.exists());
    // A cloud stamped before its TF begins.
    let jsk = stderr(&fuzzyvox(&[
        "insert",
        "--bag",
        &logs(&data, "jsk-watercan.bag"),
        "--topic",
        "/euclidean_cluster_indices_decomposer/output00",
        "--res",
        "0.05",
    ]));
    assert!(
        jsk.contains("no transform from `ground` to `map` at 1527240251.98"),
        "{jsk}"
    );
    // A damaged copy.
    let bytes = std::fs::read(logs(&data, "hololens-000.bag")).unwrap();
    let cut = dir.join("cut.bag");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let damaged = stderr(&fuzzyvox(&[
        "insert",
        "--bag",
        cut.to_str().unwrap(),
        "--topic",
        "/camera/depth/points",
        "--res",
        "0.05",
    ]));
    assert!(damaged.contains("damaged recording"), "{damaged}");
    // Images on a topic that is not there, before any depth is computed.
    let images = stderr(&fuzzyvox(&[
        "mono",
        "--bag",
        &logs(&data, "hololens-000-mcap"),
        "--image-topic",
        "/camera/image",
        "--res",
        "0.05",
    ]));
    assert!(
        images.contains("image topics: /camera/color/image_raw/compressed"),
        "{images}"
    );
}

#[test]
fn input_flags_are_checked() {
    // One input, and the recording's flags only with a recording.
    let both = stderr(&fuzzyvox(&[
        "insert", "--cloud", "a.xyz", "--bag", "b.bag", "--topic", "/p", "--res", "0.1",
    ]));
    assert!(both.contains("cannot be used with"), "{both}");
    let topic = stderr(&fuzzyvox(&["insert", "--bag", "b.bag", "--res", "0.1"]));
    assert!(topic.contains("--topic"), "{topic}");
    let none = stderr(&fuzzyvox(&["insert", "--res", "0.1"]));
    assert!(none.contains("--cloud") && none.contains("--bag"), "{none}");
    let trajectory = stderr(&fuzzyvox(&[
        "mono",
        "--bag",
        "b.bag",
        "--image-topic",
        "/i",
        "--trajectory",
        "t.txt",
        "--res",
        "0.1",
    ]));
    assert!(trajectory.contains("cannot be used with"), "{trajectory}");
    let missing = stderr(&fuzzyvox(&["info", "--bag", "/nonexistent/recording.bag"]));
    assert!(missing.contains("/nonexistent/recording.bag"), "{missing}");
}
