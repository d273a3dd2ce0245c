//! ROS 1 recordings: any bytes, written to a file (the reader maps files), give a summary, scans
//! and frames, or a typed error.
#![no_main]

use fuzzyvox::bag::Bag;
use libfuzzer_sys::fuzz_target;

#[path = "../common/recording.rs"]
mod recording;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("fuzzyvox-fuzz-{}.bag", std::process::id()));
    std::fs::write(&path, data).expect("temporary file");
    if let Ok(bag) = Bag::open(&path) {
        recording::read_recording(&bag);
    }
});
