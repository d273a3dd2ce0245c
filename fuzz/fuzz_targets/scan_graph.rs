//! OctoMap `.graph` scan graphs: any bytes give scans or a typed error; every decoded scan
//! turns into a cloud.
#![no_main]

use fuzzyvox::io::octomap::decode_scan_graph;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(nodes) = decode_scan_graph(data) {
        for node in nodes {
            let cloud = node.to_cloud().expect("decoded poses are valid");
            assert_eq!(cloud.len(), node.points_in_sensor.len());
        }
    }
});
