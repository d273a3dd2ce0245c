//! What the recording targets do with an opened recording: summarise it, read its clouds as
//! scans and its images as frames, under the topic names the seeds use.

use fuzzyvox::bag::{Bag, BagFrames, BagInfo, read_bag_scans};
use fuzzyvox::io::posed::PosedFrames;

/// Reads everything a user could ask of `bag`; results are whole or typed errors.
pub fn read_recording(bag: &Bag) {
    let Ok(info) = BagInfo::of(bag) else {
        return;
    };
    assert_eq!(info.message_count, info.topics.iter().map(|t| t.count).sum::<usize>());
    for frame in ["map", "lidar"] {
        if let Ok(scans) = read_bag_scans(bag, "/points", frame) {
            assert_eq!(scans.scans.len(), scans.stamps.len());
            for scan in &scans.scans {
                assert!(scan.points().iter().all(|p| p.iter().all(|v| v.is_finite())));
            }
        }
    }
    if let Ok(frames) = BagFrames::open(bag, "/image", None, "map") {
        for index in 0..frames.len().min(2) {
            let _ = frames.read_frame(index);
        }
    }
}
