//! RGB-D text files: `frame-N.pose.txt` (4×4 pose) and `camera-intrinsics.txt` (3×3 K). Any
//! bytes give a value or a typed error; a parsed pose is a valid rigid transform.
#![no_main]

use fuzzyvox::io::rgbd::{parse_intrinsics_txt, parse_pose_txt};
use fuzzyvox::validate_pose;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(pose) = parse_pose_txt(data) {
        validate_pose(&pose).expect("a parsed pose is valid");
    }
    let _ = parse_intrinsics_txt(data, 640, 480);
});
