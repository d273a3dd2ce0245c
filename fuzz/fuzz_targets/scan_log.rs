//! OctoMap text scan logs: any bytes give scans or a typed error; every parsed scan turns into
//! a cloud.
#![no_main]

use fuzzyvox::io::octomap::parse_scan_log;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(nodes) = parse_scan_log(data) {
        assert!(!nodes.is_empty());
        for node in nodes {
            let cloud = node.to_cloud().expect("parsed poses are valid");
            assert_eq!(cloud.len(), node.points_in_sensor.len());
        }
    }
});
