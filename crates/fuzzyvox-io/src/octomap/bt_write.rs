//! Writing OctoMap binary tree files (`.bt`) from finest-level voxels.

use std::path::Path;

use fuzzyvox_core::error::{Error, Result, finite};
use fuzzyvox_core::file::write_atomic;
use fuzzyvox_core::storage::VoxelKey;

use super::bt::FILE_HEADER;
use super::keys::{KEY_OFFSET, TREE_DEPTH};

/// Two bits per child, every child a free leaf / every child an occupied leaf.
const ALL_FREE: u16 = 0x5555;
const ALL_OCCUPIED: u16 = 0xAAAA;

/// Writes `voxels` (key, occupied) as an OctoMap `.bt` file with [`encode_bt`], atomically (see
/// [`write_atomic`]).
pub fn write_bt(
    path: &Path,
    resolution: f64,
    voxels: impl IntoIterator<Item = (VoxelKey, bool)>,
) -> Result<()> {
    write_atomic(path, &encode_bt(resolution, voxels)?)
}

/// Encodes finest-level voxels (key, occupied) as the bytes of an OctoMap `.bt` file.
///
/// The tree is the one OctoMap writes for these voxels: max-likelihood, pruned bottom-up (a node
/// whose eight children are leaves in the same state becomes a leaf; the root never does), voxels
/// not listed are unknown, and the header's `size` is the resulting node count. Voxels may come in
/// any order; when a key repeats, the last state wins.
///
/// Errors: a resolution that is not finite and positive, or a key outside OctoMap's 16-bit range
/// (each coordinate must lie in `-32768..32768`).
pub fn encode_bt(
    resolution: f64,
    voxels: impl IntoIterator<Item = (VoxelKey, bool)>,
) -> Result<Vec<u8>> {
    if finite("resolution", resolution)? <= 0.0 {
        return Err(Error::InvalidParameter {
            name: "resolution",
            value: resolution,
            expected: "a positive voxel size in metres",
        });
    }
    // Morton code shifted left by one, the state in bit 0: 8 bytes per voxel, and sorting by
    // code puts the voxels in exactly the order the tree is written.
    let mut codes = Vec::new();
    for (key, occupied) in voxels {
        codes.push((morton(key)? << 1) | u64::from(occupied));
    }
    // BtMap::voxels() already yields Morton order; sort only when needed. The sort is stable,
    // so among equal keys the last given stays last.
    if !codes.is_sorted_by_key(|c| c >> 1) {
        codes.sort_by_key(|c| c >> 1);
    }
    codes.dedup_by(|later, kept| {
        let same = *later >> 1 == *kept >> 1;
        if same {
            *kept = *later;
        }
        same
    });
    let mut data = Vec::new();
    let mut nodes = 0usize;
    if !codes.is_empty() {
        build(&codes, 0, &mut data, &mut nodes);
        nodes += 1; // the root
    }
    // The header OctoMap writes, so that a fuzzyvox file is byte-identical to OctoMap's own.
    // Rust prints the shortest decimal that reads back as the same f64.
    let mut bytes = format!(
        "{FILE_HEADER}\n# (feel free to add / change comments, but leave the first line as it \
         is!)\n#\nid OcTree\nsize {nodes}\nres {resolution}\ndata\n"
    )
    .into_bytes();
    bytes.extend_from_slice(&data);
    Ok(bytes)
}

/// The OctoMap Morton code of a fuzzyvox key: bit `b` of the x, y and z OctoMap keys at bits
/// `3b`, `3b + 1` and `3b + 2`, so that three bits at a time, from the top, name the child to
/// descend into.
fn morton(key: VoxelKey) -> Result<u64> {
    let mut code = 0u64;
    for (axis, value) in [key.x, key.y, key.z].into_iter().enumerate() {
        let octomap = value
            .checked_add(KEY_OFFSET)
            .filter(|k| (0..1 << TREE_DEPTH).contains(k))
            .ok_or(Error::InvalidParameter {
                name: "voxel key coordinate",
                value: f64::from(value),
                expected: "-32768..32768, the range of OctoMap's 16-bit keys",
            })?;
        for bit in 0..u32::from(TREE_DEPTH) {
            code |= u64::from((octomap as u32 >> bit) & 1) << (3 * bit + axis as u32);
        }
    }
    Ok(code)
}

/// A built subtree as its parent records it.
enum Built {
    Leaf { occupied: bool },
    Inner,
}

/// Writes the subtree of the node at `depth` that holds `codes` (sorted, unique, non-empty,
/// sharing the node's key prefix) into `out` in pre-order, and adds its nodes below the node
/// itself to `nodes`. Recursion is at most 16 deep.
///
/// The node's two bytes are reserved before its children are built and filled in after, and
/// taken back when the node turns out to be a prunable leaf (its children, being leaves, wrote
/// nothing).
fn build(codes: &[u64], depth: u8, out: &mut Vec<u8>, nodes: &mut usize) -> Built {
    if depth >= TREE_DEPTH {
        let occupied = codes.last().is_some_and(|c| c & 1 == 1);
        return Built::Leaf { occupied };
    }
    let start = out.len();
    out.extend_from_slice(&[0, 0]);
    // The child index of this level, above the state bit.
    let shift = 1 + 3 * u32::from(TREE_DEPTH - 1 - depth);
    let mut children = 0u16;
    let mut count = 0;
    let mut rest = codes;
    while let Some(&first) = rest.first() {
        let child = (first >> shift) & 7;
        // Sorted codes with a common prefix group by child index, in ascending order.
        let len = rest.partition_point(|c| (c >> shift) & 7 == child);
        let (group, tail) = rest.split_at(len);
        rest = tail;
        let bits: u16 = match build(group, depth + 1, out, nodes) {
            Built::Leaf { occupied: false } => 0b01,
            Built::Leaf { occupied: true } => 0b10,
            Built::Inner => 0b11,
        };
        children |= bits << (2 * child);
        count += 1;
    }
    // OctoMap's prune() stops above depth 1: the root stays an inner node.
    if depth > 0 && (children == ALL_FREE || children == ALL_OCCUPIED) {
        out.truncate(start);
        return Built::Leaf {
            occupied: children == ALL_OCCUPIED,
        };
    }
    if let Some(slot) = out.get_mut(start..start + 2) {
        slot.copy_from_slice(&children.to_le_bytes());
    }
    *nodes += count;
    Built::Inner
}

/// Writes any map as an OctoMap `.bt` maximum-likelihood tree: every observed voxel is occupied
/// when its occupied membership is at least its free membership (for a log-odds map `p ≥ 0.5`,
/// OctoMap's own rule) and free otherwise; voxels nothing observed stay unknown. Returns the
/// numbers of occupied and free voxels written.
pub fn write_bt_max_likelihood(
    path: &std::path::Path,
    map: &dyn fuzzyvox_core::map::VoxelMap,
) -> Result<(usize, usize)> {
    let voxels: Vec<_> = map
        .cells()
        .map(|(key, m)| (key, m.occupied >= m.free))
        .collect();
    let occupied = voxels.iter().filter(|(_, o)| *o).count();
    let free = voxels.len() - occupied;
    write_bt(path, map.resolution().size(), voxels)?;
    Ok((occupied, free))
}

#[cfg(test)]
mod tests {
    use super::super::bt::decode_bt;
    use super::*;

    #[test]
    fn prunes_full_octants_but_not_the_root() {
        // The 2×2×2 cube at the origin: one occupied leaf at depth 15.
        let cube: Vec<_> = (0..8)
            .map(|i| (VoxelKey::new(i & 1, (i >> 1) & 1, (i >> 2) & 1), true))
            .collect();
        let map = decode_bt(&encode_bt(0.1, cube.clone()).unwrap()).unwrap();
        assert_eq!(map.leaves.len(), 1);
        assert_eq!(
            (map.leaves[0].depth, map.leaves[0].key),
            (15, VoxelKey::new(0, 0, 0))
        );
        // Root, 14 inner nodes on the way down, the leaf.
        assert_eq!(map.node_count, 16);

        // One voxel less, or one free: no pruning at depth 15.
        let map = decode_bt(&encode_bt(0.1, cube[1..].to_vec()).unwrap()).unwrap();
        assert_eq!((map.leaves.len(), map.node_count), (7, 16 + 7));
        let mut mixed = cube.clone();
        mixed[3].1 = false;
        let map = decode_bt(&encode_bt(0.1, mixed).unwrap()).unwrap();
        assert_eq!(map.leaves.len(), 8);
    }

    #[test]
    fn repeated_keys_keep_the_last_state_and_order_does_not_matter() {
        let k = |x| VoxelKey::new(x, -3, 7);
        let a = encode_bt(0.2, [(k(1), true), (k(-5), false), (k(1), false)]).unwrap();
        let b = encode_bt(0.2, [(k(-5), false), (k(1), false)]).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn rejects_keys_and_resolutions_octomap_cannot_hold() {
        for key in [VoxelKey::new(32768, 0, 0), VoxelKey::new(0, -32769, 0)] {
            assert!(matches!(
                encode_bt(0.1, [(key, true)]),
                Err(Error::InvalidParameter { .. })
            ));
        }
        assert!(encode_bt(0.1, [(VoxelKey::new(32767, -32768, 0), true)]).is_ok());
        for res in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(encode_bt(res, []).is_err(), "{res}");
        }
    }

    #[test]
    fn empty_tree_has_no_data() {
        let bytes = encode_bt(0.05, []).unwrap();
        assert!(bytes.ends_with(b"size 0\nres 0.05\ndata\n"));
        let map = decode_bt(&bytes).unwrap();
        assert_eq!((map.node_count, map.leaves.len()), (0, 0));
    }
}
