//! OctoMap trees as maps: `.bt` and `.ot` read into a read-only map that every query, the
//! planner and the exporters use, checked against OctoMap itself; opening any map file by
//! content; and OctoMap maps as priors of a fuzzy map.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use fuzzyvox::VoxelMapMut;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::octomap::{octomap_info, octomap_tool};
use common::{Rng, data_dir, fuzzyvox, json};
use fuzzyvox::io::octomap::{
    OcTreeMap, OctreeFormat, OctreeLeaf, encode_bt, encode_ot, read_bt, write_ot,
};
use fuzzyvox::io::{LoadedMap, load_map};
use fuzzyvox::plan::{PlannerConfig, plan_path};
use fuzzyvox::{
    Error, FormatError, FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelClass,
    VoxelKey, VoxelMap,
};
use nalgebra::Point3;

/// OctoMap 1.9.7's leaf census of `geb079.bt` (`scripts/octomap_check.cpp count`).
const GEB079_OCCUPIED: usize = 185_673;
const GEB079_FREE: usize = 950_759;
const GEB079_LEAVES: usize = 428_144;
const GEB079_NODES: usize = 532_566;

/// Two free points of the FR-079 building, 16.9 m apart: a room south of the corridor, and the
/// corridor's east half, joined through a door (the README's example).
const ROOM: [f64; 3] = [1.24, -3.4, 1.0];
const CORRIDOR: [f64; 3] = [18.0, -0.44, 0.92];

fn geb079(test: &str) -> Option<PathBuf> {
    data_dir(test).map(|d| d.join("octomap-samples/geb079.bt"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("octomap_maps");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn point(p: [f64; 3]) -> Point3<f64> {
    Point3::new(p[0], p[1], p[2])
}

/// A `.ot` file: OctoMap's header, then `nodes` as (log-odds, child byte) in pre-order.
fn ot_file(id: &str, size: usize, nodes: &[(f32, u8)]) -> Vec<u8> {
    let mut bytes =
        format!("# Octomap OcTree file\n# comment\nid {id}\nsize {size}\nres 0.1\ndata\n")
            .into_bytes();
    for (value, children) in nodes {
        bytes.extend_from_slice(&value.to_le_bytes());
        bytes.push(*children);
    }
    bytes
}

/// A chain from the root down child 0 to depth `depth`, whose last node has two leaf children
/// (0: free, 7: occupied), as a list of `.ot` nodes.
fn chain(depth: u8) -> Vec<(f32, u8)> {
    let mut nodes = vec![(2.0, 1u8); usize::from(depth)];
    nodes.push((2.0, 0b1000_0001));
    nodes.push((-2.0, 0));
    nodes.push((2.0, 0));
    nodes
}

#[test]
fn geb079_counts_and_queries_match_octomap() {
    let Some(path) = geb079("geb079_counts_and_queries_match_octomap") else {
        return;
    };
    let map = OcTreeMap::read(&path).unwrap();
    assert_eq!(map.format(), OctreeFormat::Binary);
    assert_eq!(map.resolution().size(), 0.08);
    let counts = map.counts();
    assert_eq!(
        (
            counts.occupied,
            counts.free,
            counts.ambiguous,
            counts.unknown
        ),
        (GEB079_OCCUPIED, GEB079_FREE, 0, 0)
    );
    assert_eq!(map.leaf_count(), GEB079_LEAVES);
    assert_eq!(map.node_count(), GEB079_NODES);
    // Every voxel of the file answers as its leaf says, pruned leaves included, and keys the
    // file does not list are unknown.
    let bt = read_bt(&path).unwrap();
    let voxels: HashMap<VoxelKey, bool> = bt.voxels().collect();
    assert_eq!(voxels.len(), GEB079_OCCUPIED + GEB079_FREE);
    for (key, occupied) in &voxels {
        let expected = if *occupied {
            VoxelClass::Occupied
        } else {
            VoxelClass::Free
        };
        assert_eq!(map.class_at(*key), expected, "{key:?}");
    }
    let mut rng = Rng::new(79);
    let mut unknown = 0;
    for _ in 0..200_000 {
        let key = VoxelKey::new(
            rng.uniform(-120.0, 420.0).floor() as i32,
            rng.uniform(-110.0, 110.0).floor() as i32,
            rng.uniform(-20.0, 50.0).floor() as i32,
        );
        if !voxels.contains_key(&key) {
            assert_eq!(map.class_at(key), VoxelClass::Unknown, "{key:?}");
            assert_eq!(map.memberships_at(key).occupied, 0.0);
            unknown += 1;
        }
    }
    assert!(unknown > 10_000, "the sample should reach unknown space");
    // Leaves come out as the file lists them, pruned cubes whole.
    let leaves: Vec<OctreeLeaf> = map.leaves().collect();
    assert_eq!(leaves.len(), bt.leaves.len());
    for (ours, theirs) in leaves.iter().zip(&bt.leaves) {
        assert_eq!((ours.key, ours.depth), (theirs.key, theirs.depth));
        assert_eq!(ours.memberships().occupied > 0.5, theirs.occupied);
    }
    assert_eq!(map.cells().count(), GEB079_OCCUPIED + GEB079_FREE);
    // OctoMap reads .bt leaves at its clamping probabilities.
    let occupied = leaves.iter().find(|l| l.log_odds > 0.0).unwrap();
    let free = leaves.iter().find(|l| l.log_odds < 0.0).unwrap();
    assert!((occupied.memberships().occupied - 0.971).abs() < 1e-6);
    assert!((free.memberships().occupied - 0.1192).abs() < 1e-6);
    // Five bytes per node: far below OctoMap's own 15.2 MB for this tree.
    assert!(
        map.memory_bytes() <= 5 * GEB079_NODES + 64,
        "{}",
        map.memory_bytes()
    );
}

#[test]
fn geb079_plans_a_path_octomap_confirms() {
    let Some(path) = geb079("geb079_plans_a_path_octomap_confirms") else {
        return;
    };
    let map = OcTreeMap::read(&path).unwrap();
    let config = PlannerConfig {
        vehicle_radius: 0.15,
        ..PlannerConfig::default()
    };
    let (from, to) = (point(ROOM), point(CORRIDOR));
    assert!((to - from).norm() >= 8.0);
    let plan = plan_path(&map, &from, &to, &config).unwrap();
    assert!(plan.length >= (to - from).norm());
    // Along the whole path, the vehicle keeps its radius from every occupied leaf's cube and
    // never enters unknown space (our own check, every centimetre)...
    for pair in plan.waypoints.windows(2) {
        let steps = ((pair[1] - pair[0]).norm() / 0.01).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let p = pair[0] + (pair[1] - pair[0]) * (s as f64 / steps as f64);
            assert_eq!(map.class_at_point(&p).unwrap(), VoxelClass::Free, "{p}");
        }
    }
    // ...and OctoMap itself confirms it.
    let Some(tool) = octomap_tool("geb079_plans_a_path_octomap_confirms") else {
        return;
    };
    let waypoints: Vec<[f64; 3]> = plan.waypoints.iter().map(|p| [p.x, p.y, p.z]).collect();
    let plan_file = scratch("geb079-plan.json");
    std::fs::write(
        &plan_file,
        serde_json::json!({ "waypoints": waypoints }).to_string(),
    )
    .unwrap();
    let output = Command::new(&tool)
        .arg("path")
        .arg(&path)
        .arg("0.15")
        .arg(&plan_file)
        .output()
        .unwrap();
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert!(output.status.success(), "{report}");
    assert_eq!(report["violations_cube"], 0, "{report}");
    assert_eq!(report["unknown_samples"], 0, "{report}");
    assert_eq!(report["occupied_samples"], 0, "{report}");
    assert!(report["min_distance_to_occupied_cube_m"].as_f64().unwrap() >= 0.15);
}

#[test]
fn ot_trees_read_pruned_leaves_and_log_odds() {
    // Root -> child 0 (depth 1) -> ... -> depth 15 node with two single-voxel leaves.
    let bytes = ot_file("OcTree", 18, &chain(15));
    let map = OcTreeMap::decode(&bytes).unwrap();
    assert_eq!(map.format(), OctreeFormat::Full);
    assert_eq!((map.leaf_count(), map.node_count()), (2, 18));
    let low = VoxelKey::new(-32768, -32768, -32768);
    let high = VoxelKey::new(-32767, -32767, -32767);
    assert_eq!(map.class_at(low), VoxelClass::Free);
    assert_eq!(map.class_at(high), VoxelClass::Occupied);
    let p = 1.0 / (1.0 + (-2.0f32).exp());
    assert!((map.memberships_at(high).occupied - p).abs() < 1e-6);
    assert!((map.memberships_at(high).free - (1.0 - p)).abs() < 1e-6);
    assert_eq!(
        map.class_at(VoxelKey::new(-32768, -32767, -32768)),
        VoxelClass::Unknown
    );
    assert_eq!(map.class_at(VoxelKey::new(0, 0, 0)), VoxelClass::Unknown);
    assert_eq!(
        map.class_at(VoxelKey::new(40_000, 0, 0)),
        VoxelClass::Unknown
    );

    // A pruned leaf at depth 3 covers 2^13 voxels per side without being expanded.
    let pruned = ot_file("OcTree", 4, &[(1.0, 1), (1.0, 1), (1.0, 0b100), (1.5, 0)]);
    let map = OcTreeMap::decode(&pruned).unwrap();
    let leaf = map.leaves().next().unwrap();
    assert_eq!((leaf.depth, leaf.side()), (3, 1 << 13));
    assert_eq!(leaf.key, VoxelKey::new(-32768, -32768 + (1 << 13), -32768));
    assert_eq!(map.counts().occupied, 1 << 39);
    assert!(map.memory_bytes() < 64);
    assert_eq!(
        map.class_at(VoxelKey::new(-32768 + 8191, -32768 + 16383, -32768 + 8191)),
        VoxelClass::Occupied
    );
    assert_eq!(
        map.class_at(VoxelKey::new(-32768 + 8192, -32768 + 16383, -32768)),
        VoxelClass::Unknown
    );
    // A root without children is one leaf covering everything, as OctoMap reads it.
    let all = OcTreeMap::decode(&ot_file("OcTree", 1, &[(-1.0, 0)])).unwrap();
    assert_eq!(all.class_at(VoxelKey::new(123, -456, 7)), VoxelClass::Free);
    assert_eq!(all.counts().free, 1 << 48);
    // An empty tree.
    let empty = OcTreeMap::decode(&ot_file("OcTree", 0, &[])).unwrap();
    assert_eq!(empty.leaf_count(), 0);
    assert_eq!(empty.class_at(VoxelKey::new(0, 0, 0)), VoxelClass::Unknown);
}

#[test]
fn damaged_ot_files_are_typed_errors() {
    let good = ot_file("OcTree", 18, &chain(15));
    OcTreeMap::decode(&good).unwrap();
    let invalid = |bytes: &[u8], what: &str| match OcTreeMap::decode(bytes) {
        Err(FormatError::Invalid(message)) => assert!(message.contains(what), "{message}"),
        other => panic!("expected an invalid-contents error with `{what}`, got {other:?}"),
    };
    // Truncated anywhere in the tree.
    for cut in 1..90 {
        assert!(OcTreeMap::decode(&good[..good.len() - cut]).is_err());
    }
    invalid(&ot_file("OcTree", 19, &chain(15)), "at most 18");
    invalid(&ot_file("OcTree", 17, &chain(15)), "more nodes");
    // Children below depth 16.
    invalid(&ot_file("OcTree", 19, &chain(16)), "16 levels");
    // A leaf value that is not a number.
    let mut nan = chain(15);
    nan[16].0 = f32::NAN;
    invalid(&ot_file("OcTree", 18, &nan), "log-odds NaN");
    // Other tree types carry more bytes per node.
    assert!(matches!(
        OcTreeMap::decode(&ot_file("ColorOcTree", 18, &chain(15))),
        Err(FormatError::WrongKind { found, .. }) if found == "ColorOcTree"
    ));
    invalid(
        b"# Octomap OcTree file\nid OcTree\nres 0.1\ndata\n",
        "no `size`",
    );
    invalid(b"not a tree at all", "first line");
    // Random damage never panics.
    let mut rng = Rng::new(3);
    for _ in 0..2000 {
        let mut bytes = good.clone();
        let at = (rng.next_u64() as usize) % bytes.len();
        bytes[at] = rng.next_u64() as u8;
        let _ = OcTreeMap::decode(&bytes);
    }
}

#[test]
fn ot_round_trips_and_matches_octomap_own_files() {
    // Our writer, read back.
    let voxels: Vec<(VoxelKey, bool)> = (0..4)
        .flat_map(|x| (0..4).map(move |y| (VoxelKey::new(x, y, 0), x < 2)))
        .chain([(VoxelKey::new(-9, 3, 2), true)])
        .collect();
    let bt = OcTreeMap::decode(&encode_bt(0.1, voxels.clone()).unwrap()).unwrap();
    let ot_bytes = encode_ot(&bt);
    let ot = OcTreeMap::decode(&ot_bytes).unwrap();
    assert_eq!(ot.format(), OctreeFormat::Full);
    assert_eq!(
        ot.leaves().collect::<Vec<_>>(),
        bt.leaves().collect::<Vec<_>>()
    );
    assert_eq!(ot.counts(), bt.counts());
    assert_eq!(encode_ot(&ot), ot_bytes);
    let path = scratch("small.ot");
    write_ot(&path, &ot).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), ot_bytes);

    // OctoMap's own map of a scan: its .ot and .bt read as OctoMap reads them, and the .ot
    // rewrites byte for byte.
    let Some(data) = data_dir("ot_round_trips_and_matches_octomap_own_files") else {
        return;
    };
    let Some(tool) = octomap_tool("ot_round_trips_and_matches_octomap_own_files") else {
        return;
    };
    let base = scratch("scan-10cm");
    let built = Command::new(&tool)
        .arg("build")
        .arg(data.join("octomap-samples/scan.dat"))
        .arg("0.1")
        .arg(&base)
        .output()
        .unwrap();
    assert!(
        built.status.success(),
        "{}",
        String::from_utf8_lossy(&built.stderr)
    );
    for extension in ["ot", "bt"] {
        let file = base.with_extension(extension);
        let map = OcTreeMap::read(&file).unwrap();
        let (nodes, leaves, occupied, free, resolution) = octomap_info(&tool, &file);
        assert_eq!(map.node_count(), nodes, "{extension}");
        assert_eq!(map.leaf_count(), leaves, "{extension}");
        assert_eq!(map.counts().occupied as u64, occupied, "{extension}");
        assert_eq!(map.counts().free as u64, free, "{extension}");
        assert_eq!(map.resolution().size(), resolution);
        if extension == "ot" {
            let original = std::fs::read(&file).unwrap();
            assert!(
                encode_ot(&map) == original,
                "the .ot does not rewrite as it was"
            );
        }
    }
}

#[test]
fn maps_open_by_content_whatever_their_name() {
    let dir = scratch("by-content");
    std::fs::create_dir_all(&dir).unwrap();
    let voxels = [
        (VoxelKey::new(0, 0, 0), true),
        (VoxelKey::new(1, 0, 0), false),
    ];
    let bt = encode_bt(0.1, voxels).unwrap();
    let ot = encode_ot(&OcTreeMap::decode(&bt).unwrap());
    let mut fuzzy = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(1.05, 0.05, 0.05)]).unwrap();
    fuzzy
        .integrate_cloud(&cloud, &IntegrationOptions::default())
        .unwrap();
    // Names that lie about the content.
    std::fs::write(dir.join("tree.fvx"), &bt).unwrap();
    std::fs::write(dir.join("tree.bt"), &ot).unwrap();
    std::fs::write(dir.join("map.ot"), fuzzy.to_bytes()).unwrap();
    let loaded = load_map(&dir.join("tree.fvx")).unwrap();
    assert_eq!(loaded.model_name(), "octomap-bt");
    assert_eq!(loaded.as_map().counts().occupied, 1);
    assert_eq!(
        load_map(&dir.join("tree.bt")).unwrap().model_name(),
        "octomap-ot"
    );
    let native = load_map(&dir.join("map.ot")).unwrap();
    assert!(matches!(native, LoadedMap::Native { .. }));
    assert_eq!(native.model_name(), "fuzzy");
    assert_eq!(native.as_map().counts(), fuzzy.counts());
    // Anything else is refused with the formats accepted.
    std::fs::write(dir.join("cloud.bt"), "1 2 3\n").unwrap();
    let error = load_map(&dir.join("cloud.bt")).unwrap_err();
    assert!(matches!(
        error,
        Error::Format {
            reason: FormatError::UnknownMapFormat,
            ..
        }
    ));
    let message = error.to_string();
    for format in [".fvx", ".bt", ".ot"] {
        assert!(message.contains(format), "{message}");
    }
    assert!(matches!(
        load_map(&dir.join("missing.bt")),
        Err(Error::Io { .. })
    ));
}

#[test]
fn an_octomap_prior_starts_a_fuzzy_map() {
    let voxels: Vec<(VoxelKey, bool)> = (0..8)
        .flat_map(|x| (0..8).map(move |y| (VoxelKey::new(x, y, 0), x == 7)))
        .collect();
    let prior = OcTreeMap::decode(&encode_bt(0.1, voxels).unwrap()).unwrap();
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    assert_eq!(map.add_prior(&prior, 0.6).unwrap(), 64);
    // 0.6 up to the fixed point of exact accumulation (`map::Accumulator`).
    let near = |a: f32, b: f32| (a - b).abs() < 1e-6;
    let free = map.memberships_at(VoxelKey::new(3, 3, 0));
    assert!(free.occupied == 0.0 && near(free.free, 0.6), "{free:?}");
    let wall = map.memberships_at(VoxelKey::new(7, 3, 0));
    assert!(near(wall.occupied, 0.6) && wall.free == 0.0, "{wall:?}");
    assert_eq!(map.counts().occupied, 8);
    assert_eq!(map.counts().free, 56);
    // New observations aggregate with it (product t-conorm: 1 - 0.4 · (1 - o)), and the order
    // does not matter.
    let cloud = PointCloud::new(
        Point3::new(0.05, 0.35, 0.05),
        vec![Point3::new(0.75, 0.35, 0.05)],
    )
    .unwrap();
    map.integrate_cloud(&cloud, &IntegrationOptions::default())
        .unwrap();
    let mut other = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    other
        .integrate_cloud(&cloud, &IntegrationOptions::default())
        .unwrap();
    let seen = other.memberships_at(VoxelKey::new(7, 3, 0)).occupied;
    other.add_prior(&prior, 0.6).unwrap();
    let both = map.memberships_at(VoxelKey::new(7, 3, 0)).occupied;
    assert!((both - (1.0 - 0.4 * (1.0 - seen))).abs() < 1e-6);
    for (key, m) in map.cells() {
        let o = other.memberships_at(key);
        assert!((m.occupied - o.occupied).abs() < 1e-6 && (m.free - o.free).abs() < 1e-6);
    }
    // Bad priors leave the map unchanged.
    let before: Vec<_> = map.cells().collect();
    for confidence in [0.0, -0.5, 1.5, f32::NAN] {
        assert!(map.add_prior(&prior, confidence).is_err(), "{confidence}");
    }
    let coarse =
        OcTreeMap::decode(&encode_bt(0.2, [(VoxelKey::new(0, 0, 0), true)]).unwrap()).unwrap();
    assert!(matches!(
        map.add_prior(&coarse, 0.5),
        Err(Error::Incompatible(_))
    ));
    let everything = OcTreeMap::decode(&ot_file("OcTree", 1, &[(-1.0, 0)])).unwrap();
    assert!(map.add_prior(&everything, 0.5).is_err());
    assert_eq!(map.cells().collect::<Vec<_>>(), before);
}

#[test]
fn cli_reads_octomap_maps() {
    let Some(path) = geb079("cli_reads_octomap_maps") else {
        return;
    };
    let map = path.to_str().unwrap();
    let info = json(&fuzzyvox(&["info", map, "--json"]));
    assert_eq!(info["model"], "octomap-bt");
    assert_eq!(info["occupied"], GEB079_OCCUPIED);
    assert_eq!(info["free"], GEB079_FREE);
    assert_eq!(info["octree"]["leaves"], GEB079_LEAVES);
    assert_eq!(info["resolution"], 0.08);

    let from = ROOM.map(|v| v.to_string()).join(",");
    let to = CORRIDOR.map(|v| v.to_string()).join(",");
    let plan = json(&fuzzyvox(&[
        "plan", "--map", map, "--radius", "0.15", "--from", &from, "--to", &to, "--json",
    ]));
    assert_eq!(plan["model"], "octomap-bt");
    assert!(plan["length_m"].as_f64().unwrap() >= 16.0, "{plan}");

    let ply = scratch("geb079.ply");
    let exported = json(&fuzzyvox(&[
        "export",
        map,
        "--ply",
        ply.to_str().unwrap(),
        "--classes",
        "occupied",
        "--json",
    ]));
    assert_eq!(exported["ply_vertices"], GEB079_OCCUPIED);
    // The .bt export of an OctoMap map is the same tree.
    let bt = scratch("geb079-again.bt");
    json(&fuzzyvox(&[
        "export",
        map,
        "--bt",
        bt.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(read_bt(&bt).unwrap(), read_bt(&path).unwrap());

    // A prior on the map-building commands.
    let cloud = scratch("few.xyz");
    std::fs::write(&cloud, "1.0 0.5 1.0\n2.0 0.5 1.0\n").unwrap();
    let built = json(&fuzzyvox(&[
        "insert",
        "--cloud",
        cloud.to_str().unwrap(),
        "--res",
        "0.08",
        "--prior",
        map,
        "--prior-confidence",
        "0.6",
        "--json",
    ]));
    assert_eq!(built["prior_voxels"], GEB079_OCCUPIED + GEB079_FREE);
    assert!(built["occupied"].as_u64().unwrap() > 100_000, "{built}");
    let refused = fuzzyvox(&[
        "insert",
        "--cloud",
        cloud.to_str().unwrap(),
        "--res",
        "0.08",
        "--model",
        "logodds",
        "--prior",
        map,
    ]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--model fuzzy"));
    // Not a map at all.
    let bad = fuzzyvox(&["info", cloud.to_str().unwrap()]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("OctoMap binary tree (.bt"));
}
