//! ROS 2 recordings (MCAP): any bytes give a summary, scans and frames, or a typed error; scans
//! come back only whole, with finite points.
#![no_main]

use std::path::Path;

use fuzzyvox::bag::Bag;
use libfuzzer_sys::fuzz_target;

#[path = "../common/recording.rs"]
mod recording;

fuzz_target!(|data: &[u8]| {
    let Ok(bag) = Bag::from_mcap_bytes(Path::new("fuzz.mcap"), data.to_vec()) else {
        return;
    };
    recording::read_recording(&bag);
});
