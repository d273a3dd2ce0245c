//! OctoMap's binary scan graph (`.graph`): scans with their sensor poses, and pose constraints.
//!
//! Layout, all little endian (OctoMap writes its C++ structs field by field):
//!
//! ```text
//! u32 node count, then per node:
//!     u32 point count, then per point: vector3
//!     pose6d                          sensor pose in the world
//!     u32 id
//! u32 edge count, then per edge:
//!     u32 first node id, u32 second node id, pose6d constraint, f64 weight
//!
//! vector3    = i32 3 (element count), f64 x, f64 y, f64 z
//! quaternion = i32 4 (element count), f64 w, f64 x, f64 y, f64 z
//! pose6d     = vector3 translation, quaternion rotation
//! ```
//!
//! OctoMap keeps these values as `f32` and widens them to `f64` on disk. Edges hold relative poses
//! for graph optimisation; they are validated and skipped, since mapping needs the node poses only.

use std::path::Path;

use fuzzyvox_core::error::{Error, FormatError, Result};
use fuzzyvox_core::geometry::validate_pose;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};

use super::cursor::Cursor;
use super::scan::ScanNode;

/// Bytes of a stored vector: the element-count tag and three doubles.
const VECTOR_BYTES: usize = 4 + 3 * 8;
/// Bytes of a stored quaternion: the element-count tag and four doubles.
const QUATERNION_BYTES: usize = 4 + 4 * 8;
/// Bytes of a stored pose.
const POSE_BYTES: usize = VECTOR_BYTES + QUATERNION_BYTES;
/// The smallest node: no points, a pose and an id.
const MIN_NODE_BYTES: usize = 4 + POSE_BYTES + 4;
/// One edge: two ids, a pose and a weight.
const EDGE_BYTES: usize = 4 + 4 + POSE_BYTES + 8;
/// How far a stored quaternion's norm may be from 1. OctoMap computes and keeps quaternions in
/// `f32`, so a norm off by ~1e-7 is normal; anything far off means damage, not rounding.
const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Reads an OctoMap binary scan graph (`.graph`, as written by `ScanGraph::writeBinary`).
///
/// Every count is checked against the bytes left before anything is allocated, and the file must
/// end exactly after the last edge; any damage is an [`Error::Format`].
pub fn read_scan_graph(path: &Path) -> Result<Vec<ScanNode>> {
    let bytes = crate::bounded::read_regular(path)?;
    decode_scan_graph(&bytes).map_err(|reason| Error::Format {
        path: path.to_path_buf(),
        reason,
    })
}

/// Decodes the bytes of a `.graph` file; see [`read_scan_graph`].
pub fn decode_scan_graph(bytes: &[u8]) -> Result<Vec<ScanNode>, FormatError> {
    let mut c = Cursor::new(bytes);
    let node_count = count(&mut c, "node count", MIN_NODE_BYTES)?;
    let mut nodes = Vec::with_capacity(node_count);
    for index in 0..node_count {
        let point_count = count(&mut c, "point count", VECTOR_BYTES)?;
        let mut points = Vec::with_capacity(point_count);
        for _ in 0..point_count {
            let [x, y, z] = vector(&mut c, "point")?;
            points.push(Point3::new(x, y, z));
        }
        let pose = pose(&mut c).map_err(|e| {
            FormatError::Invalid(format!("node {index} (byte {}): {e}", c.position()))
        })?;
        let id = c.u32("node id")?;
        nodes.push(ScanNode {
            world_from_sensor: pose,
            points_in_sensor: points,
            id,
        });
    }
    let edge_count = count(&mut c, "edge count", EDGE_BYTES)?;
    // Sorted ids: edge checks stay O(log n) on large graphs.
    let mut ids: Vec<u32> = nodes.iter().map(|n| n.id).collect();
    ids.sort_unstable();
    for index in 0..edge_count {
        for end in ["first", "second"] {
            let id = c.u32("edge node id")?;
            if ids.binary_search(&id).is_err() {
                return Err(FormatError::Invalid(format!(
                    "edge {index}: its {end} node id {id} names no node"
                )));
            }
        }
        // The constraint is only checked for shape: fuzzyvox maps with the node poses.
        vector(&mut c, "edge translation")?;
        quaternion(&mut c, "edge rotation")?;
        c.f64("edge weight")?;
    }
    if c.remaining() != 0 {
        return Err(FormatError::Invalid(format!(
            "{} bytes after the last edge: not a scan graph, or damaged",
            c.remaining()
        )));
    }
    Ok(nodes)
}

/// Reads a `u32` count of items that take at least `item_bytes` each, and rejects it when the
/// bytes left cannot hold that many, so that a damaged count never drives a huge allocation.
fn count(c: &mut Cursor<'_>, what: &str, item_bytes: usize) -> Result<usize, FormatError> {
    let at = c.position();
    let n = c.u32(what)?;
    let n = usize::try_from(n).unwrap_or(usize::MAX);
    if n > c.remaining() / item_bytes {
        return Err(FormatError::Invalid(format!(
            "{what} {n} at byte {at} cannot fit in the {} bytes left",
            c.remaining()
        )));
    }
    Ok(n)
}

/// Reads the element-count tag OctoMap writes before each vector and quaternion.
fn tag(c: &mut Cursor<'_>, what: &str, expected: i32) -> Result<(), FormatError> {
    let at = c.position();
    let found = c.i32(what)?;
    if found == expected {
        Ok(())
    } else {
        Err(FormatError::Invalid(format!(
            "{what} at byte {at} has element count {found}, expected {expected}"
        )))
    }
}

fn vector(c: &mut Cursor<'_>, what: &str) -> Result<[f64; 3], FormatError> {
    tag(c, what, 3)?;
    Ok([c.f64(what)?, c.f64(what)?, c.f64(what)?])
}

/// Reads a quaternion (stored w, x, y, z), checking it is finite and of unit norm.
fn quaternion(c: &mut Cursor<'_>, what: &str) -> Result<UnitQuaternion<f64>, FormatError> {
    tag(c, what, 4)?;
    let [w, x, y, z] = [c.f64(what)?, c.f64(what)?, c.f64(what)?, c.f64(what)?];
    let q = Quaternion::new(w, x, y, z);
    let norm = q.norm();
    if !norm.is_finite() || (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(FormatError::Invalid(format!(
            "{what} ({w}, {x}, {y}, {z}) is not a unit quaternion"
        )));
    }
    // Renormalise away the f32 rounding OctoMap stored.
    Ok(UnitQuaternion::from_quaternion(q))
}

/// Reads a node pose and validates it as a rigid transform.
fn pose(c: &mut Cursor<'_>) -> Result<Isometry3<f64>, FormatError> {
    let [x, y, z] = vector(c, "pose translation")?;
    let rotation = quaternion(c, "pose rotation")?;
    let pose = Isometry3::from_parts(Translation3::new(x, y, z), rotation);
    validate_pose(&pose).map_err(|e| FormatError::Invalid(e.to_string()))?;
    Ok(pose)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn put_vector(out: &mut Vec<u8>, v: [f64; 3]) {
        out.extend(3i32.to_le_bytes());
        v.iter().for_each(|x| out.extend(x.to_le_bytes()));
    }

    fn put_pose(out: &mut Vec<u8>, t: [f64; 3], q: [f64; 4]) {
        put_vector(out, t);
        out.extend(4i32.to_le_bytes());
        q.iter().for_each(|x| out.extend(x.to_le_bytes()));
    }

    /// Two nodes (ids 5 and 9) joined by one edge.
    fn sample() -> Vec<u8> {
        let mut out = Vec::new();
        out.extend(2u32.to_le_bytes());
        for (id, points) in [(5u32, 2u32), (9, 0)] {
            out.extend(points.to_le_bytes());
            for i in 0..points {
                put_vector(&mut out, [f64::from(i), 1.0, f64::NAN]);
            }
            put_pose(&mut out, [1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 1.0]);
            out.extend(id.to_le_bytes());
        }
        out.extend(1u32.to_le_bytes());
        out.extend(5u32.to_le_bytes());
        out.extend(9u32.to_le_bytes());
        put_pose(&mut out, [0.0; 3], [1.0, 0.0, 0.0, 0.0]);
        out.extend(1.0f64.to_le_bytes());
        out
    }

    #[test]
    fn decodes_nodes_and_skips_edges() {
        let nodes = decode_scan_graph(&sample()).unwrap();
        assert_eq!(nodes.len(), 2);
        assert_eq!((nodes[0].id, nodes[1].id), (5, 9));
        assert_eq!(nodes[0].points_in_sensor.len(), 2);
        assert!(nodes[0].points_in_sensor[1].z.is_nan());
        // (w, x, y, z) = (0, 0, 0, 1): half a turn about z.
        let p = nodes[1].world_from_sensor * Point3::new(1.0, 0.0, 0.0);
        assert!((p - Point3::new(0.0, 2.0, 3.0)).norm() < 1e-12, "{p}");
    }

    #[test]
    fn every_truncation_is_an_error() {
        let bytes = sample();
        for len in 0..bytes.len() {
            assert!(decode_scan_graph(&bytes[..len]).is_err(), "length {len}");
        }
    }

    #[test]
    fn rejects_bad_edges_tags_and_rotations() {
        let mut bytes = sample();
        let n = bytes.len();
        bytes[n - 80..n - 76].copy_from_slice(&7u32.to_le_bytes());
        assert!(decode_scan_graph(&bytes).is_err(), "edge to a missing node");

        let mut bytes = sample();
        bytes[8] = 2; // first point's tag
        assert!(decode_scan_graph(&bytes).is_err(), "bad tag");

        let mut bytes = sample();
        let q = 8 + 2 * VECTOR_BYTES + VECTOR_BYTES + 4;
        bytes[q..q + 8].copy_from_slice(&0.5f64.to_le_bytes());
        assert!(decode_scan_graph(&bytes).is_err(), "non-unit quaternion");

        let mut bytes = sample();
        bytes.push(0);
        assert!(decode_scan_graph(&bytes).is_err(), "trailing byte");
    }
}
