//! Middlebury `calib.txt`: any bytes give a calibration or a typed error, and a calibration
//! gives a stereo geometry or a typed error.
#![no_main]

use fuzzyvox::io::middlebury::parse_calib;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(calib) = parse_calib(data) {
        let _ = calib.geometry();
    }
});
