//! Writing OctoMap's full tree files (`.ot`; the layout is in `ot.rs`).

use std::path::Path;

use fuzzyvox_core::error::Result;
use fuzzyvox_core::file::write_atomic;

use super::ot::{NODE_BYTES, OT_HEADER};
use super::tree::OcTreeMap;

/// Writes a tree as an OctoMap `.ot` file with [`encode_ot`], atomically.
pub fn write_ot(path: &Path, map: &OcTreeMap) -> Result<()> {
    write_atomic(path, &encode_ot(map))
}

/// Encodes a tree as the bytes of an OctoMap `.ot` file: OctoMap's header, then every node in
/// pre-order, inner nodes holding the largest log-odds of their children as OctoMap's
/// `updateInnerOccupancy` leaves them. A `.bt` tree is written with its leaves at the clamping
/// log-odds OctoMap gives them.
pub fn encode_ot(map: &OcTreeMap) -> Vec<u8> {
    use fuzzyvox_core::map::VoxelMap;
    let (masks, data) = map.nodes();
    let values = map.node_values();
    let resolution = map.resolution().size();
    let mut bytes = format!(
        "{OT_HEADER}\n# (feel free to add / change comments, but leave the first line as it \
         is!)\n#\nid OcTree\nsize {}\nres {resolution}\ndata\n",
        masks.len()
    )
    .into_bytes();
    bytes.reserve(masks.len() * NODE_BYTES);
    let mut stack = if masks.is_empty() {
        vec![]
    } else {
        vec![0usize]
    };
    while let Some(node) = stack.pop() {
        let mask = masks.get(node).copied().unwrap_or_default();
        let value = values.get(node).copied().unwrap_or_default();
        bytes.extend_from_slice(&value.to_le_bytes());
        bytes.push(mask);
        if mask != 0 {
            let first = data.get(node).copied().unwrap_or_default() as usize;
            // Last child first, so that the children pop in child order.
            stack.extend((first..first + mask.count_ones() as usize).rev());
        }
    }
    bytes
}
