//! The shared robot recordings (`FUZZYVOX_DATA/robot-logs`): what `info` finds in each, the
//! HoloLens frames read from the ROS 1 bag, the ROS 2 folder and its bare `.mcap` alike, the
//! recordings' frames equal to the folder they were written from, TF gaps as clear errors, and
//! damaged copies that fail cleanly.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use std::path::{Path, PathBuf};

use fuzzyvox_bag::{Bag, BagError, BagFrames, BagInfo, read_bag_scans};
use fuzzyvox_io::posed::{PosedFolder, PosedFrames};

/// The shared data folder; `None` (with a note) when `FUZZYVOX_DATA` is unset, a failure when
/// it is set but missing.
fn data_dir(test: &str) -> Option<PathBuf> {
    match std::env::var_os("FUZZYVOX_DATA") {
        None => {
            eprintln!("SKIPPED {test}: FUZZYVOX_DATA is not set (see README, Tests)");
            None
        }
        Some(dir) => {
            let dir = PathBuf::from(dir);
            assert!(
                dir.join("robot-logs").is_dir(),
                "no robot-logs in FUZZYVOX_DATA={}",
                dir.display()
            );
            Some(dir)
        }
    }
}

const POINTS: &str = "/camera/depth/points";
const IMAGES: &str = "/camera/color/image_raw/compressed";

fn open(dir: &Path, name: &str) -> Bag {
    Bag::open(&dir.join("robot-logs").join(name)).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("recordings")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A topic, its type and its message count.
type Topic = (&'static str, &'static str, usize);

/// Topics, types and counts as the rosbags library (0.11.9) lists them for each recording
/// (`scripts/check-bags` compares the two on every run; ROS 1 types as the bag spells them).
#[test]
fn info_lists_what_the_rosbags_library_lists() {
    let Some(data) = data_dir("info_lists_what_the_rosbags_library_lists") else {
        return;
    };
    let expected: [(&str, &str, &[Topic]); 4] = [
        (
            "hololens-000-mcap",
            "ros2",
            &[
                (
                    "/camera/color/camera_info",
                    "sensor_msgs/msg/CameraInfo",
                    80,
                ),
                (IMAGES, "sensor_msgs/msg/CompressedImage", 80),
                (POINTS, "sensor_msgs/msg/PointCloud2", 80),
                ("/tf", "tf2_msgs/msg/TFMessage", 80),
            ],
        ),
        (
            "hololens-000.bag",
            "ros1",
            &[
                (POINTS, "sensor_msgs/PointCloud2", 80),
                ("/tf", "tf2_msgs/TFMessage", 80),
            ],
        ),
        (
            "luminar-embag.bag",
            "ros1",
            &[
                ("/base_pose_ground_truth", "nav_msgs/Odometry", 5),
                ("/base_scan", "sensor_msgs/LaserScan", 5),
                ("/luminar_pointcloud", "sensor_msgs/PointCloud2", 5),
            ],
        ),
        (
            "jsk-watercan.bag",
            "ros1",
            &[
                (
                    "/euclidean_cluster_indices_decomposer/output00",
                    "sensor_msgs/PointCloud2",
                    1,
                ),
                ("/tf", "tf/tfMessage", 333),
                ("/tf", "tf2_msgs/TFMessage", 3199),
            ],
        ),
    ];
    for (name, format, topics) in expected {
        let info = BagInfo::of(&open(&data, name)).unwrap();
        assert_eq!(info.format, format, "{name}");
        let got: Vec<(&str, &str, usize)> = info
            .topics
            .iter()
            .map(|t| (t.name.as_str(), t.msg_type.as_str(), t.count))
            .collect();
        assert_eq!(got, topics, "{name}");
        assert_eq!(
            info.message_count,
            topics.iter().map(|t| t.2).sum::<usize>()
        );
    }
    let hololens = BagInfo::of(&open(&data, "hololens-000.bag")).unwrap();
    assert_eq!(
        (hololens.start_ns, hololens.end_ns),
        (1_000_000_000, 3_633_333_333)
    );
    assert_eq!(hololens.tf.len(), 1);
    assert_eq!(hololens.tf[0].samples, 80);
    // The humanoid's tree: both TF message types, leading slashes dropped.
    let jsk = BagInfo::of(&open(&data, "jsk-watercan.bag")).unwrap();
    assert!(
        jsk.tf
            .iter()
            .any(|e| e.parent == "map" && e.child == "biped_odom_particle")
    );
    assert!(
        jsk.tf
            .iter()
            .any(|e| e.parent == "BODY" && e.child == "ground")
    );
    assert!(
        jsk.tf
            .iter()
            .all(|e| !e.parent.starts_with('/') && !e.child.starts_with('/'))
    );
}

#[test]
fn the_ros1_bag_the_ros2_folder_and_its_mcap_give_the_same_scans() {
    let Some(data) = data_dir("the_ros1_bag_the_ros2_folder_and_its_mcap_give_the_same_scans")
    else {
        return;
    };
    let ros1 = read_bag_scans(&open(&data, "hololens-000.bag"), POINTS, "map").unwrap();
    let ros2 = read_bag_scans(&open(&data, "hololens-000-mcap"), POINTS, "map").unwrap();
    let file = open(&data, "hololens-000-mcap/hololens-000-mcap.mcap");
    let mcap = read_bag_scans(&file, POINTS, "map").unwrap();
    assert_eq!(ros1.scans.len(), 80);
    assert_eq!(ros1.scans.iter().map(|s| s.len()).sum::<usize>(), 1_138_584);
    assert_eq!(ros1.sensor_frame, "camera_color_optical_frame");
    for other in [&ros2, &mcap] {
        assert_eq!(ros1.scans, other.scans);
        assert_eq!(ros1.stamps, other.stamps);
    }
    // Each scan's origin is its frame's camera centre in the folder the bags were written from.
    let folder = PosedFolder::open(&data.join("rgbd-hololens-000"), None, None).unwrap();
    for (scan, pose) in ros1.scans.iter().zip(&folder.poses) {
        assert_eq!(scan.origin().coords, pose.translation.vector);
    }
}

/// The MCAP bag's images, camera info and TF give the folder's frames: the same pixels,
/// intrinsics and poses bit for bit (so `mono --bag` writes `mono --dir`'s maps).
#[test]
fn a_recordings_frames_are_the_folders_frames() {
    let Some(data) = data_dir("a_recordings_frames_are_the_folders_frames") else {
        return;
    };
    let frames = BagFrames::open(&open(&data, "hololens-000-mcap"), IMAGES, None, "map").unwrap();
    let folder = PosedFolder::open(&data.join("rgbd-hololens-000"), None, None).unwrap();
    assert_eq!(frames.len(), folder.len());
    assert_eq!(frames.poses(), folder.poses());
    for index in [0, 1, 41, 79] {
        let (a, b) = (
            frames.read_frame(index).unwrap(),
            folder.read_frame(index).unwrap(),
        );
        assert_eq!(a.image(), b.image(), "frame {index}");
        assert_eq!(a.intrinsics(), b.intrinsics());
        assert_eq!(a.world_from_camera(), b.world_from_camera());
        assert!((a.timestamp() - b.timestamp()).abs() < 1e-6);
        assert_eq!(frames.read_sensor_depth(index).unwrap(), None);
    }
    assert!(frames.read_frame(80).is_err());
    // An image topic that is not there lists the image topics; so does a cloud topic.
    let bag = open(&data, "hololens-000-mcap");
    match BagFrames::open(&bag, "/camera/image", None, "map") {
        Err(BagError::UnknownTopic {
            kind: "image",
            available,
            ..
        }) => {
            assert_eq!(available, [IMAGES]);
        }
        other => panic!("{other:?}"),
    }
    match BagFrames::open(&bag, IMAGES, Some("/info"), "map") {
        Err(BagError::UnknownTopic {
            kind: "camera info",
            available,
            ..
        }) => {
            assert_eq!(available, ["/camera/color/camera_info"]);
        }
        other => panic!("{other:?}"),
    }
    match BagFrames::open(&bag, POINTS, None, "map") {
        Err(BagError::WrongType { found, .. }) => assert_eq!(found, "sensor_msgs/msg/PointCloud2"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn lidar_clouds_without_tf_stay_in_their_own_frame() {
    let Some(data) = data_dir("lidar_clouds_without_tf_stay_in_their_own_frame") else {
        return;
    };
    let bag = open(&data, "luminar-embag.bag");
    let scans = read_bag_scans(&bag, "/luminar_pointcloud", "luminar_lidar").unwrap();
    assert_eq!(scans.scans.len(), 5);
    assert_eq!(scans.scans.iter().map(|s| s.len()).sum::<usize>(), 180_822);
    assert!(
        scans
            .scans
            .iter()
            .all(|s| s.origin() == nalgebra::Point3::origin())
    );
    match read_bag_scans(&bag, "/luminar_pointcloud", "map") {
        Err(BagError::NoTransform {
            source_frame,
            target_frame,
            detail,
            ..
        }) => {
            assert_eq!(
                (source_frame.as_str(), target_frame.as_str()),
                ("luminar_lidar", "map")
            );
            assert!(detail.contains("no transforms"), "{detail}");
        }
        other => panic!("{other:?}"),
    }
    match read_bag_scans(&bag, "/points", "map") {
        Err(BagError::UnknownTopic { available, .. }) => {
            assert_eq!(available, ["/luminar_pointcloud"]);
        }
        other => panic!("{other:?}"),
    }
    match read_bag_scans(&bag, "/base_scan", "map") {
        Err(BagError::WrongType { found, .. }) => assert_eq!(found, "sensor_msgs/LaserScan"),
        other => panic!("{other:?}"),
    }
}

/// The humanoid's cloud is stamped 5.6 s before its TF begins: an error naming the frames, the
/// stamp and the edge's times; in its own frame it reads whole.
#[test]
fn a_cloud_stamped_before_its_tf_is_a_clear_error() {
    let Some(data) = data_dir("a_cloud_stamped_before_its_tf_is_a_clear_error") else {
        return;
    };
    let bag = open(&data, "jsk-watercan.bag");
    let topic = "/euclidean_cluster_indices_decomposer/output00";
    match read_bag_scans(&bag, topic, "map") {
        Err(error @ BagError::NoTransform { .. }) => {
            let text = error.to_string();
            assert!(
                text.contains("from `ground` to `map` at 1527240251.98"),
                "{text}"
            );
            assert!(text.contains("never extrapolates"), "{text}");
        }
        other => panic!("{other:?}"),
    }
    let own = read_bag_scans(&bag, topic, "/ground").unwrap();
    assert_eq!(own.scans.len(), 1);
    assert_eq!(own.scans[0].len() + own.dropped_points, 13_966);
}

/// Truncated and corrupted copies of the recordings: typed errors, never a panic, and never a
/// partial result.
#[test]
fn damaged_recordings_are_errors() {
    let Some(data) = data_dir("damaged_recordings_are_errors") else {
        return;
    };
    let dir = scratch("damaged");
    let ros1 = std::fs::read(data.join("robot-logs/hololens-000.bag")).unwrap();
    let mcap =
        std::fs::read(data.join("robot-logs/hololens-000-mcap/hololens-000-mcap.mcap")).unwrap();
    for fraction in [0.0, 0.001, 0.3, 0.9, 0.9999] {
        let cut = (ros1.len() as f64 * fraction) as usize;
        let path = dir.join(format!("cut-{cut}.bag"));
        std::fs::write(&path, &ros1[..cut]).unwrap();
        let read = Bag::open(&path).and_then(|bag| read_bag_scans(&bag, POINTS, "map"));
        assert!(
            read.is_err(),
            "a ROS 1 bag cut at {cut} of {} bytes",
            ros1.len()
        );
        let cut = (mcap.len() as f64 * fraction) as usize;
        let read = Bag::from_mcap_bytes(Path::new("cut.mcap"), mcap[..cut].to_vec())
            .and_then(|bag| read_bag_scans(&bag, POINTS, "map"));
        assert!(
            read.is_err(),
            "an MCAP file cut at {cut} of {} bytes",
            mcap.len()
        );
    }
    // Bytes overwritten in the middle of the records: an error or a smaller honest result,
    // never a panic.
    for at in [20_000, 1_000_000, 7_000_000] {
        let mut bytes = ros1.clone();
        bytes[at..at + 64].fill(0xFF);
        let path = dir.join(format!("flipped-{at}.bag"));
        std::fs::write(&path, &bytes).unwrap();
        let _ = Bag::open(&path).and_then(|bag| BagInfo::of(&bag));
        let mut bytes = mcap.clone();
        bytes[at..at + 64].fill(0xFF);
        let _ = Bag::from_mcap_bytes(Path::new("flipped.mcap"), bytes)
            .and_then(|bag| read_bag_scans(&bag, POINTS, "map"));
    }
    let text = dir.join("not-a-bag.bag");
    std::fs::write(&text, "1 2 3\n").unwrap();
    assert!(matches!(Bag::open(&text), Err(BagError::NotABag { .. })));
    assert!(matches!(
        Bag::open(&dir.join("missing.bag")),
        Err(BagError::Io { .. })
    ));
    assert!(matches!(Bag::open(&dir), Err(BagError::NotABag { .. })));
    // A ROS 2 folder whose metadata names another storage, or a missing file.
    let folder = dir.join("sqlite");
    std::fs::create_dir_all(&folder).unwrap();
    let metadata = "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths:\n  - a.db3\n";
    std::fs::write(folder.join("metadata.yaml"), metadata).unwrap();
    assert!(matches!(
        Bag::open(&folder),
        Err(BagError::Unsupported { .. })
    ));
    let metadata = metadata
        .replace("sqlite3", "mcap")
        .replace("a.db3", "a.mcap");
    std::fs::write(folder.join("metadata.yaml"), metadata).unwrap();
    assert!(matches!(Bag::open(&folder), Err(BagError::Io { .. })));
    std::fs::write(
        folder.join("metadata.yaml"),
        "rosbag2_bagfile_information: [",
    )
    .unwrap();
    assert!(matches!(Bag::open(&folder), Err(BagError::Damaged { .. })));
}

/// The HoloLens recording rewritten with zstd and with lz4 chunks (the shared file's chunks
/// are uncompressed) reads as the original; a damaged compressed chunk is an error.
#[test]
fn compressed_chunks_read_as_plain_ones() {
    let Some(data) = data_dir("compressed_chunks_read_as_plain_ones") else {
        return;
    };
    let original = open(&data, "hololens-000-mcap");
    let expected = read_bag_scans(&original, POINTS, "map").unwrap();
    let mut messages = Vec::new();
    original
        .for_each_message(&mut |m| {
            let c = m.connection;
            messages.push((
                c.topic.clone(),
                c.msg_type.clone(),
                m.log_time,
                m.data.to_vec(),
            ));
            Ok(())
        })
        .unwrap();
    for compression in [mcap::Compression::Zstd, mcap::Compression::Lz4] {
        let options = mcap::WriteOptions::new()
            .compression(Some(compression))
            .chunk_size(Some(1 << 20));
        let mut writer = options.create(std::io::Cursor::new(Vec::new())).unwrap();
        let mut channels = std::collections::BTreeMap::new();
        for (sequence, (topic, msg_type, log_time, bytes)) in messages.iter().enumerate() {
            let channel_id = match channels.get(topic) {
                Some(&id) => id,
                None => {
                    let schema = writer.add_schema(msg_type, "ros2msg", b"").unwrap();
                    let id = writer
                        .add_channel(schema, topic, "cdr", &Default::default())
                        .unwrap();
                    channels.insert(topic.clone(), id);
                    id
                }
            };
            let header = mcap::records::MessageHeader {
                channel_id,
                sequence: sequence as u32,
                log_time: *log_time,
                publish_time: *log_time,
            };
            writer.write_to_known_channel(&header, bytes).unwrap();
        }
        writer.finish().unwrap();
        let bytes = writer.into_inner().into_inner();
        let plain =
            std::fs::metadata(data.join("robot-logs/hololens-000-mcap/hololens-000-mcap.mcap"))
                .unwrap()
                .len();
        assert!(
            (bytes.len() as u64) < plain,
            "{compression:?} did not compress"
        );
        let bag = Bag::from_mcap_bytes(Path::new("compressed.mcap"), bytes.clone()).unwrap();
        let scans = read_bag_scans(&bag, POINTS, "map").unwrap();
        assert_eq!(scans.scans, expected.scans, "{compression:?}");
        let mut damaged = bytes;
        let middle = damaged.len() / 2;
        damaged[middle..middle + 16].fill(0);
        let read = Bag::from_mcap_bytes(Path::new("damaged.mcap"), damaged)
            .and_then(|bag| read_bag_scans(&bag, POINTS, "map"));
        assert!(
            matches!(read, Err(BagError::Damaged { .. })),
            "{compression:?}: {read:?}"
        );
    }
}
