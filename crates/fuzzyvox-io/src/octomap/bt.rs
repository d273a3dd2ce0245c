//! OctoMap's binary tree files (`.bt`): a max-likelihood occupancy octree, two bits per node.
//!
//! A text header, then the tree depth first:
//!
//! ```text
//! # Octomap OcTree binary file          (the first line must start with this)
//! # ...comments...
//! id OcTree
//! size 532566                           number of nodes, the root included
//! res 0.08                              voxel edge length (m)
//! data                                  the tree follows the end of this line
//! ```
//!
//! Each inner node is two bytes: children 0–3 in the first, 4–7 in the second, two bits per child
//! at bits `2i` and `2i + 1` of its byte. `00`: no child (unknown space); bit `2i` alone: a free
//! leaf; bit `2i + 1` alone: an occupied leaf; both: an inner node, whose own two bytes follow
//! (after the bytes of every earlier sibling's subtree, that is in pre-order). Child `i` of a node
//! at depth `d` holds the keys whose bit `15 - d` is `i & 1` in x, `(i >> 1) & 1` in y and
//! `(i >> 2) & 1` in z. The tree is 16 levels deep, so OctoMap keys are 16-bit: fuzzyvox key
//! + 32768.

use std::path::Path;

use fuzzyvox_core::error::{Error, FormatError, Result};
use fuzzyvox_core::storage::VoxelKey;

use super::cursor::Cursor;
use super::keys::{TREE_DEPTH, voxel_key};
use super::walk::{TreeFormat, decode_tree_file, walk_children};

/// The start of the first line of every `.bt` file.
pub(super) const FILE_HEADER: &str = "# Octomap OcTree binary file";

/// A leaf of an OctoMap tree: a cube of `side()³` voxels, all free or all occupied.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BtLeaf {
    /// The fuzzyvox key (OctoMap key − 32768) of the cube's lowest-corner voxel.
    pub key: VoxelKey,
    /// Tree depth, 0..=16: the leaf covers `2^(16 - depth)` voxels per side (one at depth 16).
    pub depth: u8,
    /// Whether the cube is occupied (else free).
    pub occupied: bool,
}

impl BtLeaf {
    /// Voxels per side of the cube (depths beyond 16 count as 16).
    pub fn side(&self) -> u32 {
        1 << (TREE_DEPTH - self.depth.min(TREE_DEPTH))
    }

    /// Voxels in the cube.
    pub fn voxel_count(&self) -> u64 {
        u64::from(self.side()).pow(3)
    }

    /// Every voxel of the cube with the leaf's state, in Morton order (x fastest).
    pub fn voxels(&self) -> impl Iterator<Item = (VoxelKey, bool)> + use<> {
        let occupied = self.occupied;
        cube_keys(self.key, self.side()).map(move |k| (k, occupied))
    }
}

/// The keys of a cube of `side³` voxels (`side` a power of two) whose lowest corner is `key`, in
/// Morton order (x fastest).
pub(super) fn cube_keys(key: VoxelKey, side: u32) -> impl Iterator<Item = VoxelKey> + use<> {
    (0..u64::from(side).pow(3)).map(move |m| {
        let [dx, dy, dz] = deinterleave(m);
        // Wrapping: hand-built leaves may sit anywhere; decoded ones never come near i32's
        // limits.
        VoxelKey::new(
            key.x.wrapping_add(dx),
            key.y.wrapping_add(dy),
            key.z.wrapping_add(dz),
        )
    })
}

/// The contents of a `.bt` file: the leaves of OctoMap's max-likelihood tree.
#[derive(Clone, Debug, PartialEq)]
pub struct BtMap {
    /// Voxel edge length in metres.
    pub resolution: f64,
    /// Number of tree nodes, inner nodes and the root included (OctoMap's `size()`).
    pub node_count: usize,
    /// The leaves in file order, which is Morton order of their corners.
    pub leaves: Vec<BtLeaf>,
}

impl BtMap {
    /// Number of leaves (OctoMap's `getNumLeafNodes()`).
    pub fn leaf_count(&self) -> usize {
        self.leaves.len()
    }

    /// Number of finest-level voxels that are occupied (`true`) or free (`false`).
    pub fn voxel_count(&self, occupied: bool) -> u64 {
        self.leaves
            .iter()
            .filter(|l| l.occupied == occupied)
            .map(BtLeaf::voxel_count)
            // Saturating: hand-built maps could list more than 2^64 voxels.
            .fold(0, u64::saturating_add)
    }

    /// Every known voxel at the finest level with its state, leaves expanded, in Morton order.
    pub fn voxels(&self) -> impl Iterator<Item = (VoxelKey, bool)> + '_ {
        self.leaves.iter().flat_map(BtLeaf::voxels)
    }
}

/// Reads an OctoMap binary tree file (`.bt`); see [`decode_bt`] for what is checked.
pub fn read_bt(path: &Path) -> Result<BtMap> {
    let bytes = crate::bounded::read_regular(path)?;
    decode_bt(&bytes).map_err(|reason| Error::Format {
        path: path.to_path_buf(),
        reason,
    })
}

/// Decodes the bytes of a `.bt` file.
///
/// Checks, each a [`FormatError`]: the first line, an `id` of `OcTree` (or its deprecated form
/// `1`), a `size` and a finite positive `res` before `data`, the declared size against what the
/// data can hold (before decoding), the tree depth (never below 16 levels), truncation, inner
/// nodes without children, and the number of nodes read against `size`, as OctoMap does.
///
/// Like OctoMap, it ignores unknown header keywords and any bytes after the tree. A root without
/// children is, as OctoMap reads it, one occupied leaf covering all of space.
pub fn decode_bt(bytes: &[u8]) -> Result<BtMap, FormatError> {
    let format = TreeFormat {
        first_line: FILE_HEADER,
        name: "an OctoMap binary tree",
        aliases: &["1"],
        // Every node but the root is announced by two bits of its parent's two bytes.
        most_nodes: |data_len| data_len.saturating_mul(4).saturating_add(1),
    };
    let tree = decode_tree_file(bytes, &format, decode_tree)?;
    Ok(BtMap {
        resolution: tree.resolution,
        node_count: tree.node_count,
        leaves: tree.leaves,
    })
}

/// Reads the tree (see [`walk_children`]), appends its leaves and returns the number of nodes.
/// Stops with an error as soon as more than `declared` nodes are seen.
fn decode_tree(
    data: &[u8],
    declared: usize,
    leaves: &mut Vec<BtLeaf>,
) -> Result<usize, FormatError> {
    let mut c = Cursor::new(data);
    let root = children(&mut c)?;
    if root == 0 {
        // OctoMap gives a childless root the occupied clamping value: it is an occupied leaf.
        leaves.push(leaf([0; 3], 0, true));
        return Ok(1);
    }
    let code = |children: u16, i: u32| (children >> (2 * i)) & 3;
    walk_children(
        root,
        declared,
        |children, i| code(children, i) != 0,
        |child| {
            let (depth, corner) = (child.depth, child.corner);
            match code(child.siblings, child.index) {
                1 => leaves.push(leaf(corner, depth, false)),
                2 => leaves.push(leaf(corner, depth, true)),
                _ => return inner_node(&mut c, depth).map(Some),
            }
            Ok(None)
        },
    )
}

/// Reads the child bytes of an inner node at `depth`, which must be above the leaves' level and
/// have children.
fn inner_node(c: &mut Cursor<'_>, depth: u8) -> Result<u16, FormatError> {
    if depth >= TREE_DEPTH {
        return Err(FormatError::Invalid(format!(
            "inner node at depth {depth} (byte {}): OctoMap trees have 16 levels",
            c.position()
        )));
    }
    let at = c.position();
    let grandchildren = children(c)?;
    if grandchildren == 0 {
        // OctoMap never writes one: a node without children is written as a leaf.
        return Err(FormatError::Invalid(format!(
            "inner node at byte {at} has no children"
        )));
    }
    Ok(grandchildren)
}

/// Reads a node's two child bytes as one `u16`, child `i` at bits `2i, 2i + 1`.
fn children(c: &mut Cursor<'_>) -> Result<u16, FormatError> {
    let bytes = c.take(2, "tree node")?;
    let low = bytes.first().copied().unwrap_or_default();
    let high = bytes.get(1).copied().unwrap_or_default();
    Ok(u16::from_le_bytes([low, high]))
}

fn leaf(corner: [u32; 3], depth: u8, occupied: bool) -> BtLeaf {
    BtLeaf {
        key: voxel_key(corner),
        depth,
        occupied,
    }
}

/// Splits a Morton index into its x, y and z parts (x in bit 0 of each triple).
fn deinterleave(m: u64) -> [i32; 3] {
    let mut out = [0i32; 3];
    for bit in 0..u64::from(TREE_DEPTH) {
        for (axis, value) in out.iter_mut().enumerate() {
            *value |= (((m >> (3 * bit + axis as u64)) & 1) as i32) << bit;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::octomap::keys::KEY_OFFSET;

    fn file(header: &str, data: &[u8]) -> Vec<u8> {
        let mut bytes = format!("{FILE_HEADER}\n{header}data\n").into_bytes();
        bytes.extend_from_slice(data);
        bytes
    }

    /// Root: child 0 a free leaf (bits 01), child 1 an occupied leaf (10), child 7 inner (11)
    /// whose child 0 is an occupied leaf.
    const TREE: [u8; 4] = [0b0000_1001, 0b1100_0000, 0b0000_0010, 0];

    #[test]
    fn decodes_bits_keys_and_depths() {
        let map = decode_bt(&file("id OcTree\nsize 5\nres 0.5\n", &TREE)).unwrap();
        let m = -KEY_OFFSET;
        assert_eq!(map.resolution, 0.5);
        assert_eq!(map.node_count, 5);
        assert_eq!(
            map.leaves,
            [
                BtLeaf {
                    key: VoxelKey::new(m, m, m),
                    depth: 1,
                    occupied: false
                },
                BtLeaf {
                    key: VoxelKey::new(0, m, m),
                    depth: 1,
                    occupied: true
                },
                BtLeaf {
                    key: VoxelKey::new(0, 0, 0),
                    depth: 2,
                    occupied: true
                },
            ]
        );
        assert_eq!(map.voxel_count(false), 1 << 45);
        assert_eq!(map.voxel_count(true), (1 << 45) + (1 << 42));
        // Keywords may share a line, as OctoMap reads tokens.
        let same = decode_bt(&file("id OcTree size 5 res 0.5\n", &TREE)).unwrap();
        assert_eq!(same, map);
        // The declared size must match.
        assert!(decode_bt(&file("id OcTree\nsize 4\nres 0.5\n", &TREE)).is_err());
        assert!(decode_bt(&file("id OcTree\nsize 6\nres 0.5\n", &TREE)).is_err());
    }

    #[test]
    fn childless_root_is_one_occupied_leaf_and_childless_inner_nodes_are_errors() {
        let map = decode_bt(&file("id OcTree\nsize 1\nres 0.1\n", &[0, 0])).unwrap();
        let m = -KEY_OFFSET;
        let everything = BtLeaf {
            key: VoxelKey::new(m, m, m),
            depth: 0,
            occupied: true,
        };
        assert_eq!(map.leaves, [everything]);
        assert_eq!(map.voxel_count(true), 1 << 48);
        assert!(decode_bt(&file("id OcTree\nsize 2\nres 0.1\n", &[3, 0, 0, 0])).is_err());
    }

    #[test]
    fn leaf_voxels_come_in_morton_order() {
        let leaf = BtLeaf {
            key: VoxelKey::new(-4, 8, 0),
            depth: 14,
            occupied: false,
        };
        let keys: Vec<_> = leaf.voxels().map(|(k, _)| k).collect();
        assert_eq!(keys.len(), 64);
        assert_eq!(keys[1], VoxelKey::new(-3, 8, 0));
        assert_eq!(keys[2], VoxelKey::new(-4, 9, 0));
        assert_eq!(keys[4], VoxelKey::new(-4, 8, 1));
        assert_eq!(keys[63], VoxelKey::new(-1, 11, 3));
        let distinct: std::collections::BTreeSet<_> = keys.iter().collect();
        assert_eq!(distinct.len(), 64);
        // Depths past 16 (only possible in hand-built leaves) count as one voxel.
        let odd = BtLeaf { depth: 200, ..leaf };
        assert_eq!(odd.voxel_count(), 1);
    }
}
