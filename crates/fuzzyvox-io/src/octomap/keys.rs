//! OctoMap's tree keys: the tree's depth, the offset between its keys and fuzzyvox's, and the
//! corners of a node's children.

use fuzzyvox_core::storage::VoxelKey;

/// Depth of OctoMap's tree: leaves at this depth are single voxels.
pub(super) const TREE_DEPTH: u8 = 16;
/// OctoMap key of the voxel fuzzyvox calls key 0 (OctoMap keys are `floor(p / res) + 2^15`).
pub(super) const KEY_OFFSET: i32 = 1 << 15;
/// The OctoMap key of the lowest corner of child `child` (x in bit 0, y in 1, z in 2) of the node
/// at `depth` whose lowest corner is `parent`.
pub(super) fn child_corner(parent: [u32; 3], depth: u8, child: u32) -> [u32; 3] {
    let half = 1u32 << (TREE_DEPTH - 1 - depth.min(TREE_DEPTH - 1));
    let offset = |axis: u32| ((child >> axis) & 1) * half;
    [
        parent[0] + offset(0),
        parent[1] + offset(1),
        parent[2] + offset(2),
    ]
}

/// The fuzzyvox key of an OctoMap key (corners are below 2^16, so the conversion is exact).
pub(super) fn voxel_key(octomap: [u32; 3]) -> VoxelKey {
    let ours = |k: u32| k as i32 - KEY_OFFSET;
    VoxelKey::new(ours(octomap[0]), ours(octomap[1]), ours(octomap[2]))
}
