//! ROS messages in either wire format: the first byte picks ROS 1 or CDR, the rest is a
//! PointCloud2, a TF message or a CameraInfo; decoding gives the message or a typed error, and
//! a decoded cloud gives finite points or an error in words.
#![no_main]

use fuzzyvox::bag::messages::{CameraInfo, Message, PointCloud2, TfMessage};
use fuzzyvox::bag::{Connection, Encoding, RawMessage, TfTree, cloud_points};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&first, bytes)) = data.split_first() else {
        return;
    };
    let encoding = if first & 1 == 0 { Encoding::Ros1 } else { Encoding::Cdr };
    let connection = Connection {
        topic: "/fuzz".into(),
        msg_type: String::new(),
        encoding,
    };
    let message = RawMessage {
        connection: &connection,
        log_time: 0,
        data: bytes,
    };
    match (first >> 1) % 3 {
        0 => {
            if let Ok(cloud) = PointCloud2::decode(&message, 0)
                && let Ok(points) = cloud_points(&cloud)
            {
                assert!(points.points.iter().all(|p| p.iter().all(|v| v.is_finite())));
            }
        }
        1 => {
            if let Ok(tf) = TfMessage::decode(&message, 0) {
                let mut tree = TfTree::new();
                for t in &tf.transforms {
                    tree.add(t, false);
                }
                if let (Some(a), Some(b)) = (tf.transforms.first(), tf.transforms.last()) {
                    if let Ok(pose) = tree.lookup(&a.header.frame_id, &b.child_frame_id, b.header.stamp_ns) {
                        assert!(pose.translation.vector.iter().all(|v| v.is_finite()));
                    }
                }
            }
        }
        _ => {
            let _ = CameraInfo::decode(&message, 0);
        }
    }
});
