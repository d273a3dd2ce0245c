//! Text point clouds (`x y z [confidence]`): any bytes give a cloud or a typed error, and a
//! parsed cloud's confidences lie in [0, 1].
#![no_main]

use fuzzyvox::io::parse_text_cloud;
use libfuzzer_sys::fuzz_target;
use nalgebra::Point3;

fuzz_target!(|data: &[u8]| {
    if let Ok(cloud) = parse_text_cloud(data, Point3::origin())
        && let Some(confidence) = cloud.confidence()
    {
        assert_eq!(confidence.len(), cloud.len());
        assert!(confidence.iter().all(|c| (0.0..=1.0).contains(c)));
    }
});
