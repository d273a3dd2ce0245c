//! OctoMap's full tree files (`.ot`): an occupancy octree with a log-odds value per node.
//!
//! The same text header as `.bt` (see `header.rs`), with the first line `# Octomap OcTree file`
//! and `id OcTree`. The tree follows in pre-order: each node is its log-odds (`f32`, little
//! endian) and one byte whose bit `i` says whether child `i` exists; the children follow, each
//! with its own subtree. A node without children is a leaf: at depth 16 a single voxel, above it
//! a pruned cube. Child `i` of a node at depth `d` holds the keys whose bit `15 - d` is `i & 1`
//! in x, `(i >> 1) & 1` in y and `(i >> 2) & 1` in z, as in `.bt`. Inner nodes hold the largest
//! log-odds of their children; readers take only the leaves' values.
//!
//! Only OctoMap's occupancy tree (`OcTree`) is read: other tree types (`ColorOcTree`,
//! `OcTreeStamped`, ...) store more bytes per node and are refused by name.

use fuzzyvox_core::error::{FormatError, Result};

use super::cursor::Cursor;
use super::keys::{TREE_DEPTH, voxel_key};
use super::leaf::OctreeLeaf;
use super::walk::{DecodedTree, TreeFormat, decode_tree_file, walk_children};

/// The start of the first line of every `.ot` file.
pub(super) const OT_HEADER: &str = "# Octomap OcTree file";

/// Bytes per node: a log-odds `f32` and the child byte.
pub(super) const NODE_BYTES: usize = 5;

/// Decodes the bytes of a `.ot` file.
///
/// Checks, each a [`FormatError`]: the first line, an `id` of `OcTree`, a `size` and a finite
/// positive `res`, the declared size against what the data can hold (before decoding), the tree
/// depth (16 levels), truncation, finite leaf values, and the number of nodes read against
/// `size`. Like OctoMap, it ignores unknown header keywords and any bytes after the tree.
pub(super) fn decode_ot(bytes: &[u8]) -> Result<DecodedTree<OctreeLeaf>, FormatError> {
    let format = TreeFormat {
        first_line: OT_HEADER,
        name: "an OctoMap tree (.ot)",
        aliases: &[],
        most_nodes: |data_len| data_len / NODE_BYTES,
    };
    decode_tree_file(bytes, &format, decode_tree)
}

/// Reads the tree (see [`walk_children`]), appends its leaves and returns the number of nodes;
/// stops as soon as more than `declared` nodes are seen.
fn decode_tree(
    data: &[u8],
    declared: usize,
    leaves: &mut Vec<OctreeLeaf>,
) -> Result<usize, FormatError> {
    let mut c = Cursor::new(data);
    let (value, children) = node(&mut c)?;
    if children == 0 {
        leaves.push(leaf([0; 3], 0, value)?);
        return Ok(1);
    }
    walk_children(
        children,
        declared,
        |children: u8, i| children & (1 << i) != 0,
        |child| {
            let (depth, corner) = (child.depth, child.corner);
            let at = c.position();
            let (value, children) = node(&mut c)?;
            if children == 0 {
                leaves.push(leaf(corner, depth, value)?);
                Ok(None)
            } else if depth >= TREE_DEPTH {
                Err(FormatError::Invalid(format!(
                    "node at byte {at} has children at depth {depth}: OctoMap trees have 16 levels"
                )))
            } else {
                Ok(Some(children))
            }
        },
    )
}

/// Reads one node: its log-odds and its child byte.
fn node(c: &mut Cursor<'_>) -> Result<(f32, u8), FormatError> {
    let value = f32::from_bits(c.u32("node value")?);
    let children = c
        .take(1, "child byte")?
        .first()
        .copied()
        .unwrap_or_default();
    Ok((value, children))
}

fn leaf(corner: [u32; 3], depth: u8, log_odds: f32) -> Result<OctreeLeaf, FormatError> {
    if !log_odds.is_finite() {
        return Err(FormatError::Invalid(format!(
            "a leaf at depth {depth} has log-odds {log_odds}"
        )));
    }
    Ok(OctreeLeaf {
        key: voxel_key(corner),
        depth,
        log_odds,
    })
}
