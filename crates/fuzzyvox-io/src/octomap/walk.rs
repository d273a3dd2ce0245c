//! What the `.bt` and `.ot` readers share: the checks around the tree (header, tree type,
//! declared node count) and the depth-first walk of its nodes. Each format reads its own nodes;
//! the walk keeps the stack, the corners and depths, and the count of nodes against the header.

use fuzzyvox_core::error::FormatError;

use super::header::{decode_declared, parse_header};
use super::keys::{TREE_DEPTH, child_corner};

/// The tree type both readers accept (`.bt` readers also accept its deprecated form `1`).
const OCTREE_ID: &str = "OcTree";

/// A decoded tree file: its leaves in file order (pre-order).
pub(super) struct DecodedTree<L> {
    /// Voxel edge length in metres.
    pub(super) resolution: f64,
    /// Number of tree nodes, the root included.
    pub(super) node_count: usize,
    /// The leaves in file order.
    pub(super) leaves: Vec<L>,
}

/// How a tree file is laid out, for [`decode_tree_file`].
pub(super) struct TreeFormat<'a> {
    /// The start the file's first line must have.
    pub(super) first_line: &'a str,
    /// The format's name in the error when the first line is another.
    pub(super) name: &'a str,
    /// Tree types accepted besides `OcTree`.
    pub(super) aliases: &'a [&'a str],
    /// The most nodes `n` bytes of tree data can hold.
    pub(super) most_nodes: fn(usize) -> usize,
}

/// Decodes a tree file: parses its header, checks the tree type and, unless the header declares
/// an empty tree (OctoMap then reads no data at all), runs `decode` on the tree data with the
/// declared node count as its limit (see [`decode_declared`] for the checks around it). `decode`
/// appends the leaves and returns the number of nodes it read.
pub(super) fn decode_tree_file<L>(
    bytes: &[u8],
    format: &TreeFormat<'_>,
    decode: impl FnOnce(&[u8], usize, &mut Vec<L>) -> Result<usize, FormatError>,
) -> Result<DecodedTree<L>, FormatError> {
    let header = parse_header(bytes, format.first_line, format.name)?;
    if header.id != OCTREE_ID && !format.aliases.contains(&header.id.as_str()) {
        return Err(FormatError::WrongKind {
            expected: OCTREE_ID,
            found: header.id,
        });
    }
    let data = bytes.get(header.data_start..).unwrap_or_default();
    let mut tree = DecodedTree {
        resolution: header.resolution,
        node_count: 0,
        leaves: Vec::new(),
    };
    if header.size == 0 {
        return Ok(tree);
    }
    let most = (format.most_nodes)(data.len());
    tree.node_count = decode_declared(header.size, data.len(), most, |declared| {
        decode(data, declared, &mut tree.leaves)
    })?;
    Ok(tree)
}

/// One inner node whose children are being visited.
struct Frame<C> {
    depth: u8,
    /// OctoMap key of the node's lowest corner.
    corner: [u32; 3],
    /// The node's children, as the format stores them.
    children: C,
    /// The next child to visit, 0..=8.
    next: u8,
}

/// A child of an inner node, as [`walk_children`] hands it to the format's reader.
pub(super) struct Child<C> {
    /// The parent's children, as the format stores them.
    pub(super) siblings: C,
    /// Which child of its parent it is, 0..8 (x in bit 0, y in 1, z in 2).
    pub(super) index: u32,
    /// Its depth, 1..=16.
    pub(super) depth: u8,
    /// OctoMap key of its lowest corner.
    pub(super) corner: [u32; 3],
}

/// Walks the tree below a root that has children (`root`, as the format stores them), depth
/// first with an explicit stack of at most 16 frames, so that damaged data cannot recurse
/// deeply. `exists(children, i)` tells whether child `i` is present; `read` reads each present
/// child in pre-order and returns its own children when it is an inner node to descend into,
/// `None` for a leaf. Returns the number of nodes, the root included, and stops with an error as
/// soon as more than `declared` nodes are seen (before reading the extra node).
pub(super) fn walk_children<C: Copy>(
    root: C,
    declared: usize,
    exists: impl Fn(C, u32) -> bool,
    mut read: impl FnMut(Child<C>) -> Result<Option<C>, FormatError>,
) -> Result<usize, FormatError> {
    let mut nodes = 1usize;
    let mut stack = Vec::with_capacity(usize::from(TREE_DEPTH));
    stack.push(Frame {
        depth: 0,
        corner: [0; 3],
        children: root,
        next: 0,
    });
    while let Some(frame) = stack.last_mut() {
        if frame.next == 8 {
            stack.pop();
            continue;
        }
        let index = u32::from(frame.next);
        frame.next += 1;
        if !exists(frame.children, index) {
            continue;
        }
        nodes += 1;
        if nodes > declared {
            return Err(FormatError::Invalid(format!(
                "the tree data holds more nodes than the {declared} the header declares"
            )));
        }
        let child = Child {
            siblings: frame.children,
            index,
            depth: frame.depth + 1,
            corner: child_corner(frame.corner, frame.depth, index),
        };
        let (depth, corner) = (child.depth, child.corner);
        if let Some(children) = read(child)? {
            stack.push(Frame {
                depth,
                corner,
                children,
                next: 0,
            });
        }
    }
    Ok(nodes)
}
