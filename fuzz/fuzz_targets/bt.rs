//! OctoMap trees, `.bt` and `.ot`: any bytes give a tree or a typed error. A decoded tree answers
//! every leaf's corner with that leaf and re-encodes as `.ot` to the same leaves; a small `.bt`
//! tree re-encodes to a file that decodes to the same voxels.
#![no_main]

use fuzzyvox::io::octomap::{OcTreeMap, decode_bt, encode_bt, encode_ot};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(tree) = OcTreeMap::decode(data) {
        let leaves: Vec<_> = tree.leaves().collect();
        assert_eq!(leaves.len(), tree.leaf_count());
        for leaf in leaves.iter().take(256) {
            assert_eq!(
                tree.leaf_at(leaf.key),
                Some(*leaf),
                "a leaf's corner finds it"
            );
        }
        if leaves.len() <= 4096 {
            let again = OcTreeMap::decode(&encode_ot(&tree)).expect("an encoded tree decodes");
            assert!(again.leaves().eq(leaves.iter().copied()), ".ot round trip");
        }
    }
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
