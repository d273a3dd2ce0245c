//! OctoMap's file formats, so that fuzzyvox can map OctoMap's data sets and exchange maps with it.
//!
//! - Scan input: the binary scan graph (`.graph`, [`read_scan_graph`]) and the text log
//!   ([`read_scan_log`]) both give [`ScanNode`]s: a validated sensor pose and points in the sensor
//!   frame; [`ScanNode::to_cloud`] turns one into a world-frame [`PointCloud`] to integrate.
//! - Maps: the binary max-likelihood octree (`.bt`), read into a [`BtMap`] of [`BtLeaf`]s
//!   ([`read_bt`]) and written from finest-level voxels ([`write_bt`]) as the pruned tree OctoMap
//!   itself would write, so that OctoMap (and its viewer, octovis) reads fuzzyvox maps.
//!
//! OctoMap keys are 16-bit: fuzzyvox key + 32768, so `.bt` files hold keys in `-32768..32768`
//! (±2.6 km at 8 cm). Every reader checks declared counts against the bytes present before
//! allocating and reports damaged, truncated or foreign files as typed errors. The layouts are in
//! `docs/formats.md` and in each reader's module.
//!
//! ```no_run
//! use fuzzyvox_io::octomap::{read_bt, read_scan_graph, write_bt};
//! use std::path::Path;
//!
//! for node in read_scan_graph(Path::new("spherical_scan.graph"))? {
//!     let cloud = node.to_cloud()?;
//!     println!("scan {}: {} points from {}", node.id, cloud.len(), cloud.origin());
//! }
//! let map = read_bt(Path::new("geb079.bt"))?;
//! println!("{} occupied voxels", map.voxel_count(true));
//! write_bt(Path::new("copy.bt"), map.resolution, map.voxels())?;
//! # Ok::<(), fuzzyvox_core::Error>(())
//! ```
//!
//! [`PointCloud`]: fuzzyvox_core::PointCloud

mod bt;
mod bt_write;
mod cursor;
mod graph;
mod header;
mod keys;
mod leaf;
mod log;
mod ot;
mod ot_write;
mod scan;
mod tree;
mod walk;

pub use bt::{BtLeaf, BtMap, decode_bt, read_bt};
pub use bt_write::{encode_bt, write_bt, write_bt_max_likelihood};
pub use graph::{decode_scan_graph, read_scan_graph};
pub use leaf::OctreeLeaf;
pub use log::{parse_scan_log, read_scan_log};
pub use ot_write::{encode_ot, write_ot};
pub use scan::ScanNode;
pub use tree::{OcTreeMap, OctreeFormat};
