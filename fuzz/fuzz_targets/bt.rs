//! OctoMap `.bt` files: any bytes give a tree or a typed error; a small decoded tree re-encodes
//! to a file that decodes to the same voxels.
#![no_main]

use fuzzyvox::io::octomap::{decode_bt, encode_bt};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(map) = decode_bt(data) else {
        return;
    };
    assert_eq!(map.leaf_count(), map.leaves.len());
    let total = map.voxel_count(true).saturating_add(map.voxel_count(false));
    if total <= 1 << 16 {
        let voxels: Vec<_> = map.voxels().collect();
        let bytes = encode_bt(map.resolution, voxels.iter().copied()).expect("decoded keys fit");
        let again = decode_bt(&bytes).expect("an encoded tree decodes");
        let mut before = voxels;
        let mut after: Vec<_> = again.voxels().collect();
        before.sort_unstable_by_key(|(k, _)| (k.x, k.y, k.z));
        after.sort_unstable_by_key(|(k, _)| (k.x, k.y, k.z));
        assert_eq!(before, after, ".bt round trip");
    }
});
