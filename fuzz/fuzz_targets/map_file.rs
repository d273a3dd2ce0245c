//! Native map files: any bytes give a map or a typed error. Most mutations break the checksum,
//! so each input is also tried with its declared length and CRC repaired, to reach the body
//! decoder. A decoded map must re-encode to bytes that decode to the same map, and must accept a
//! small scan.
#![no_main]

use fuzzyvox::{AlphaCutMap, FuzzyMap, LogOddsMap, PointCloud, VoxelMapMut};
use libfuzzer_sys::fuzz_target;
use nalgebra::Point3;

const HEADER_LEN: usize = 40;

fuzz_target!(|data: &[u8]| {
    check(data);
    if data.len() >= HEADER_LEN && data.starts_with(b"FUZZYVOX") {
        let mut repaired = data.to_vec();
        let body_len = (repaired.len() - HEADER_LEN) as u64;
        repaired[28..36].copy_from_slice(&body_len.to_le_bytes());
        let mut crc = crc32fast::Hasher::new();
        crc.update(&repaired[..36]);
        crc.update(&repaired[HEADER_LEN..]);
        repaired[36..40].copy_from_slice(&crc.finalize().to_le_bytes());
        check(&repaired);
    }
});

fn check(bytes: &[u8]) {
    if let Ok(map) = FuzzyMap::from_bytes(bytes) {
        let again = map.to_bytes();
        let decoded = FuzzyMap::from_bytes(&again).expect("a saved map loads");
        assert_eq!(decoded.to_bytes(), again, "fuzzy map round trip");
        exercise(map);
    }
    if let Ok(map) = LogOddsMap::from_bytes(bytes) {
        let again = map.to_bytes();
        let decoded = LogOddsMap::from_bytes(&again).expect("a saved map loads");
        assert_eq!(decoded.to_bytes(), again, "log-odds map round trip");
        exercise(map);
    }
    if let Ok(map) = AlphaCutMap::from_bytes(bytes) {
        let again = map.to_bytes();
        let decoded = AlphaCutMap::from_bytes(&again).expect("a saved map loads");
        assert_eq!(decoded.to_bytes(), again, "alpha-cut map round trip");
        exercise(map);
    }
}

/// Queries the loaded map and integrates a three-voxel ray into it.
fn exercise(mut map: impl VoxelMapMut) {
    let counts = map.counts();
    let _ = counts;
    for (_, m) in map.cells().take(4096) {
        assert!((0.0..=1.0).contains(&m.occupied) && (0.0..=1.0).contains(&m.free));
    }
    let step = map.resolution().size();
    let cloud = PointCloud::new(
        Point3::origin(),
        vec![Point3::new(3.0 * step, 0.5 * step, 0.0)],
    )
    .expect("finite origin");
    let _ = map.integrate_cloud(&cloud, &Default::default());
}
