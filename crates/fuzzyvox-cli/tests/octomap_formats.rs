//! OctoMap's formats: the real sample files, `.bt` round trips, OctoMap reading fuzzyvox's
//! `.bt` files, and damaged input.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::octomap::{octomap_info, octomap_tool};
use common::{Rng, data_dir};
use fuzzyvox::io::octomap::{
    BtMap, decode_bt, encode_bt, read_bt, read_scan_graph, read_scan_log, write_bt,
};
use fuzzyvox::{Error, FormatError, VoxelKey, validate_pose};

/// What OctoMap 1.9.7 reports for `geb079.bt`: `scripts/octomap_check count geb079.bt` (built as
/// its header says) prints `"leaves":428144, "occupied_voxels":185673, "free_voxels":950759,
/// "nodes":532566`.
const GEB079_NODES: usize = 532_566;
const GEB079_LEAVES: usize = 428_144;
const GEB079_OCCUPIED: u64 = 185_673;
const GEB079_FREE: u64 = 950_759;

fn samples(test: &str) -> Option<PathBuf> {
    data_dir(test).map(|d| d.join("octomap-samples"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("octomap_formats");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The bytes after the header's `data` line.
fn tree_data(bytes: &[u8]) -> &[u8] {
    let at = bytes
        .windows(6)
        .position(|w| w == b"\ndata\n")
        .expect("a data line");
    &bytes[at + 6..]
}

/// `bytes` with the first `from` replaced by `to`, in the header only.
fn edit_header(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let start = bytes.len() - tree_data(bytes).len();
    let header = std::str::from_utf8(&bytes[..start]).unwrap();
    assert!(header.contains(from), "{from:?} not in the header");
    let mut out = header.replacen(from, to, 1).into_bytes();
    out.extend_from_slice(&bytes[start..]);
    out
}

fn voxel_set(map: &BtMap) -> BTreeMap<VoxelKey, bool> {
    map.voxels().collect()
}

/// Occupied 2×2×2 and 8×8×8 blocks (aligned, so both prune), a free 4×4×4 block, and scattered
/// free and occupied voxels with negative keys, out to both ends of OctoMap's key range.
fn synthetic() -> BTreeMap<VoxelKey, bool> {
    let mut voxels = BTreeMap::new();
    for i in 0..8 {
        voxels.insert(
            VoxelKey::new(10 + (i & 1), -4 + ((i >> 1) & 1), 6 + (i >> 2)),
            true,
        );
    }
    for x in -16..-8 {
        for y in -8..0 {
            for z in 24..32 {
                voxels.insert(VoxelKey::new(x, y, z), true);
            }
        }
    }
    for x in 0..4 {
        for y in 4..8 {
            for z in -4..0 {
                voxels.insert(VoxelKey::new(x, y, z), false);
            }
        }
    }
    let mut rng = Rng::new(7);
    let mut key = |range: f64| rng.uniform(-range, range).floor() as i32;
    for i in 0..3000 {
        let range = if i % 2 == 0 { 20.0 } else { 32768.0 };
        let k = VoxelKey::new(key(range), key(range), key(range));
        voxels.entry(k).or_insert(i % 5 == 0);
    }
    voxels.insert(VoxelKey::new(-32768, -32768, -32768), false);
    voxels.insert(VoxelKey::new(32767, 32767, 32767), true);
    voxels
}

#[test]
fn spherical_scan_graph_has_one_node() {
    let Some(dir) = samples("spherical_scan_graph_has_one_node") else {
        return;
    };
    let nodes = read_scan_graph(&dir.join("spherical_scan.graph")).unwrap();
    assert_eq!(nodes.len(), 1);
    let node = &nodes[0];
    assert_eq!(node.points_in_sensor.len(), 10_201);
    assert_eq!(node.id, 0);
    validate_pose(&node.world_from_sensor).unwrap();
    assert_eq!(
        node.world_from_sensor.translation.vector,
        nalgebra::Vector3::new(1.0, 0.0, -0.5)
    );
    let cloud = node.to_cloud().unwrap();
    assert_eq!(cloud.len(), 10_201);
    assert_eq!(cloud.origin(), nalgebra::Point3::new(1.0, 0.0, -0.5));
}

#[test]
fn geb079_reads_as_octomap_reads_it() {
    let Some(dir) = samples("geb079_reads_as_octomap_reads_it") else {
        return;
    };
    let map = read_bt(&dir.join("geb079.bt")).unwrap();
    assert_eq!(map.resolution, 0.08);
    assert_eq!(map.node_count, GEB079_NODES);
    assert_eq!(map.leaf_count(), GEB079_LEAVES);
    assert_eq!(map.voxel_count(true), GEB079_OCCUPIED);
    assert_eq!(map.voxel_count(false), GEB079_FREE);
    assert!(map.leaves.iter().all(|l| l.depth <= 16));
}

#[test]
fn geb079_rewrites_byte_identically() {
    let Some(dir) = samples("geb079_rewrites_byte_identically") else {
        return;
    };
    let original = std::fs::read(dir.join("geb079.bt")).unwrap();
    let map = decode_bt(&original).unwrap();
    let path = scratch("geb079-rewritten.bt");
    write_bt(&path, map.resolution, map.voxels()).unwrap();
    let written = std::fs::read(&path).unwrap();
    let again = read_bt(&path).unwrap();
    assert_eq!(again, map, "leaves, node count or resolution changed");
    // OctoMap wrote geb079.bt fully pruned, so the same voxels give the same tree bytes, and
    // fuzzyvox writes OctoMap's header text too.
    assert!(
        tree_data(&written) == tree_data(&original),
        "tree data differs"
    );
    assert!(written == original, "header differs");
}

#[test]
fn synthetic_voxels_round_trip_and_prune() {
    let voxels = synthetic();
    let bytes = encode_bt(0.05, voxels.iter().map(|(k, s)| (*k, *s))).unwrap();
    let map = decode_bt(&bytes).unwrap();
    assert_eq!(map.resolution, 0.05);
    assert_eq!(voxel_set(&map), voxels);
    let leaf_at = |key, depth| {
        map.leaves
            .iter()
            .find(|l| l.key == key && l.depth == depth)
            .map(|l| l.occupied)
    };
    assert_eq!(leaf_at(VoxelKey::new(10, -4, 6), 15), Some(true));
    assert_eq!(leaf_at(VoxelKey::new(-16, -8, 24), 13), Some(true));
    assert_eq!(leaf_at(VoxelKey::new(0, 4, -4), 14), Some(false));
    // Any input order, and re-encoding what was read, give the same bytes.
    let reversed: Vec<_> = voxels.iter().rev().map(|(k, s)| (*k, *s)).collect();
    assert_eq!(encode_bt(0.05, reversed).unwrap(), bytes);
    assert_eq!(encode_bt(0.05, map.voxels()).unwrap(), bytes);
    // The file path: atomic write, then read.
    let path = scratch("synthetic.bt");
    write_bt(&path, 0.05, map.voxels()).unwrap();
    assert_eq!(read_bt(&path).unwrap(), map);
}

#[test]
fn octomap_reads_fuzzyvox_bt_files() {
    let Some(tool) = octomap_tool("octomap_reads_fuzzyvox_bt_files") else {
        return;
    };
    let voxels = synthetic();
    let path = scratch("for-octomap.bt");
    write_bt(&path, 0.05, voxels.iter().map(|(k, s)| (*k, *s))).unwrap();
    let ours = read_bt(&path).unwrap();
    let occupied = voxels.values().filter(|s| **s).count() as u64;
    let free = voxels.len() as u64 - occupied;
    assert_eq!(
        octomap_info(&tool, &path),
        (ours.node_count, ours.leaf_count(), occupied, free, 0.05)
    );

    let empty = scratch("empty-for-octomap.bt");
    write_bt(&empty, 0.1, []).unwrap();
    assert_eq!(octomap_info(&tool, &empty), (0, 0, 0, 0, 0.1));

    if let Some(dir) = samples("octomap_reads_fuzzyvox_bt_files (geb079 part)") {
        let map = read_bt(&dir.join("geb079.bt")).unwrap();
        let path = scratch("geb079-for-octomap.bt");
        write_bt(&path, map.resolution, map.voxels()).unwrap();
        assert_eq!(
            octomap_info(&tool, &path),
            (
                GEB079_NODES,
                GEB079_LEAVES,
                GEB079_OCCUPIED,
                GEB079_FREE,
                0.08
            )
        );
    }
}

// ---- damaged and foreign input ------------------------------------------------------------

const PNG: &[u8] = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x10\0\0\0\x10\x08\x06\0\0\0";
const TEXT: &[u8] = b"Hello, this is a README.\nNothing to see here.\n";

/// A small valid graph: two nodes with a few points, one edge.
fn small_graph() -> Vec<u8> {
    let mut out = Vec::new();
    let vector = |out: &mut Vec<u8>, v: [f64; 3]| {
        out.extend(3i32.to_le_bytes());
        v.iter().for_each(|x| out.extend(x.to_le_bytes()));
    };
    let quaternion = |out: &mut Vec<u8>| {
        out.extend(4i32.to_le_bytes());
        [1.0f64, 0.0, 0.0, 0.0]
            .iter()
            .for_each(|x| out.extend(x.to_le_bytes()));
    };
    out.extend(2u32.to_le_bytes());
    for id in 0..2u32 {
        out.extend(3u32.to_le_bytes());
        for i in 0..3 {
            vector(&mut out, [f64::from(i), 0.5, -1.0]);
        }
        vector(&mut out, [0.0, 0.0, f64::from(id)]);
        quaternion(&mut out);
        out.extend(id.to_le_bytes());
    }
    out.extend(1u32.to_le_bytes());
    out.extend(0u32.to_le_bytes());
    out.extend(1u32.to_le_bytes());
    vector(&mut out, [0.0, 0.0, 1.0]);
    quaternion(&mut out);
    out.extend(1.0f64.to_le_bytes());
    out
}

fn graph_error(name: &str, bytes: &[u8]) -> FormatError {
    let path = scratch(name);
    std::fs::write(&path, bytes).unwrap();
    match read_scan_graph(&path) {
        Err(Error::Format { reason, .. }) => reason,
        other => panic!("{name}: expected a format error, got {other:?}"),
    }
}

fn bt_error(name: &str, bytes: &[u8]) -> FormatError {
    let path = scratch(name);
    std::fs::write(&path, bytes).unwrap();
    match read_bt(&path) {
        Err(Error::Format { reason, .. }) => reason,
        other => panic!("{name}: expected a format error, got {other:?}"),
    }
}

#[test]
fn bad_graph_files_are_typed_errors() {
    let good = small_graph();
    assert_eq!(decode_scan_graph_ok(&good), 2);
    for len in 0..good.len() {
        graph_error("truncated.graph", &good[..len]);
    }
    // Bits in counts, tags and the rotation: detectable, so errors.
    for (byte, bit) in [
        (0, 6),
        (3, 7),
        (4, 5),
        (7, 4),
        (8, 1),
        (4 + 4 + 3 * 28 + 28 + 4 + 7, 4),
    ] {
        let mut bytes = good.clone();
        bytes[byte] ^= 1 << bit;
        graph_error("flipped.graph", &bytes);
    }
    // Bits in coordinates are not detectable (the format has no checksum), but never panic.
    for byte in (0..good.len()).step_by(7) {
        let mut bytes = good.clone();
        bytes[byte] ^= 0x10;
        let _ = decode_scan_graph_ok_or_err(&bytes);
    }
    graph_error("png.graph", PNG);
    graph_error("text.graph", TEXT);
    // Oversized counts fail before allocating.
    for (at, value) in [(0, u32::MAX), (4, u32::MAX), (4, 1 << 28)] {
        let mut bytes = good.clone();
        bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
        let reason = graph_error("oversized.graph", &bytes);
        assert!(reason.to_string().contains("cannot fit"), "{reason}");
    }
    let mut bytes = good.clone();
    let edges = bytes.len() - 84;
    bytes[edges..edges + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    graph_error("oversized-edges.graph", &bytes);
}

fn decode_scan_graph_ok(bytes: &[u8]) -> usize {
    fuzzyvox::io::octomap::decode_scan_graph(bytes)
        .unwrap()
        .len()
}

fn decode_scan_graph_ok_or_err(bytes: &[u8]) -> Result<usize, FormatError> {
    fuzzyvox::io::octomap::decode_scan_graph(bytes).map(|n| n.len())
}

#[test]
fn bad_log_files_are_typed_errors() {
    let good = b"# pose then points\nNODE 0 0 1 0 0 0.5\n1 2 3\n4 5 6\n";
    let path = scratch("good.log");
    std::fs::write(&path, good).unwrap();
    assert_eq!(read_scan_log(&path).unwrap()[0].points_in_sensor.len(), 2);
    let read = |name: &str, bytes: &[u8]| {
        let path = scratch(name);
        std::fs::write(&path, bytes).unwrap();
        read_scan_log(&path)
    };
    assert!(matches!(read("empty.log", b""), Err(Error::Empty(_))));
    assert!(matches!(
        read("png.log", PNG),
        Err(Error::Parse { line: 1, .. })
    ));
    assert!(matches!(
        read("text.log", TEXT),
        Err(Error::Parse { line: 1, .. })
    ));
    for len in 0..good.len() {
        // A cut line is read as it stands: an error or fewer values, never a panic.
        let _ = read("truncated.log", &good[..len]);
    }
    for byte in 0..good.len() {
        let mut bytes = good.to_vec();
        bytes[byte] ^= 0x40;
        match read("flipped.log", &bytes) {
            Ok(_) | Err(Error::Parse { .. } | Error::Empty(_)) => {}
            Err(other) => panic!("byte {byte}: {other}"),
        }
    }
    assert!(matches!(
        read("nan-pose.log", b"NODE nan 0 0 0 0 0\n"),
        Err(Error::Parse { line: 1, .. })
    ));
}

#[test]
fn bad_bt_files_are_typed_errors() {
    let voxels = synthetic();
    let good = encode_bt(0.05, voxels.iter().map(|(k, s)| (*k, *s))).unwrap();
    let data_start = good.len() - tree_data(&good).len();
    assert!(data_start > 100);
    bt_error("truncated.bt", &good[..good.len() - 1]);
    for len in (0..data_start + 64).chain((data_start..good.len()).step_by(97)) {
        assert!(decode_bt(&good[..len]).is_err(), "truncated to {len} bytes");
    }
    bt_error("empty.bt", b"");
    bt_error("png.bt", PNG);
    bt_error("text.bt", TEXT);
    // Header damage: first line, id, size, res and data keywords, values; absurd sizes fail
    // before decoding.
    for (from, to) in [
        ("Octomap", "Octomaq"),
        ("id OcTree", "id OcTrea"),
        ("id OcTree", "ib OcTree"),
        ("size ", "sizf "),
        ("size ", "size 4294967295 "),
        ("size ", "size 99999999999999999999999 "),
        ("size ", "size -"),
        ("size ", "size x"),
        ("res 0.05", "res 0.0\u{5}"),
        ("res 0.05", "res -0.05"),
        ("res 0.05", "res 0"),
        ("res 0.05", "res nan"),
        ("res 0.05", "res inf"),
        ("\ndata\n", "\ndat` \n"),
    ] {
        bt_error("bad-header.bt", &edit_header(&good, from, to));
    }
    // Every bit of the first tree bytes: an error or a valid tree, never a panic; flips that
    // add, drop or deepen nodes break the node count.
    let mut caught = 0;
    for byte in data_start..(data_start + 64).min(good.len()) {
        for bit in 0..8 {
            let mut bytes = good.clone();
            bytes[byte] ^= 1 << bit;
            if decode_bt(&bytes).is_err() {
                caught += 1;
            }
        }
    }
    // All 512 are caught today; a flip that shifts the parse could in principle match the size.
    assert!(
        caught >= 512 * 9 / 10,
        "only {caught} of 512 flips detected"
    );
    // A tree deeper than 16 levels: every node has child 0 as an inner node.
    let mut deep = b"# Octomap OcTree binary file\nid OcTree\nsize 18\nres 0.1\ndata\n".to_vec();
    deep.extend([0x03, 0x00].repeat(18));
    let reason = bt_error("deep.bt", &deep);
    assert!(reason.to_string().contains("depth 16"), "{reason}");
    // Other tree types.
    assert!(matches!(
        decode_bt(&edit_header(&good, "id OcTree", "id ColorOcTree")),
        Err(FormatError::WrongKind { .. })
    ));
}

#[test]
fn bt_reader_accepts_what_octomap_accepts() {
    let voxels = synthetic();
    let good = encode_bt(0.05, voxels.iter().map(|(k, s)| (*k, *s))).unwrap();
    let map = decode_bt(&good).unwrap();
    // OctoMap ignores bytes after the tree (checked with scripts/octomap_check.cpp), and so do we.
    let mut trailing = good.clone();
    trailing.extend_from_slice(b"garbage\n");
    assert_eq!(decode_bt(&trailing).unwrap(), map);
    // Extra comments, unknown keywords, the deprecated id `1`, Windows line ends.
    let edited = edit_header(&good, "id OcTree\n", "# more\nauthor someone\nid 1\r\n");
    let edited = edit_header(&edited, "res 0.05\n", "res 0.05\r\n");
    assert_eq!(decode_bt(&edited).unwrap(), map);
}

#[test]
fn scan_mapped_by_fuzzyvox_and_exported_reads_in_octomap_with_the_same_voxels() {
    let test = "scan_mapped_by_fuzzyvox_and_exported_reads_in_octomap_with_the_same_voxels";
    let Some(tool) = octomap_tool(test) else {
        return;
    };
    let Some(dir) = samples(test) else {
        return;
    };
    let fuzzyvox = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_fuzzyvox"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let scan = dir.join("scan.dat");
    let map = scratch("scan-logodds.fvx");
    let bt = scratch("scan-logodds.bt");
    fuzzyvox(&[
        "insert",
        "--cloud",
        scan.to_str().unwrap(),
        "--res",
        "0.1",
        "--model",
        "logodds",
        "--out",
        map.to_str().unwrap(),
    ]);
    fuzzyvox(&[
        "export",
        map.to_str().unwrap(),
        "--bt",
        bt.to_str().unwrap(),
    ]);
    // OctoMap's own insertion of scan.dat at 0.1 m gives 23,537 occupied and 794,069 free
    // voxels (`../shared/REFERENCE.md`); the exported map must read back with exactly those.
    let (_, _, occupied, free, resolution) = octomap_info(&tool, &bt);
    assert_eq!((occupied, free, resolution), (23_537, 794_069, 0.1));
}
