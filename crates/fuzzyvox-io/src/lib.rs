//! Reading and writing the formats around fuzzyvox: text point clouds, RGB-D and posed-image
//! folders, Middlebury stereo, PFM, PLY, OctoMap's `.bt`, `.ot` and scan graphs, and a loader
//! that opens any map file. The native map files live in the core
//! ([`fuzzyvox_core::file`]) and are re-exported here.
//!
//! Readers take bytes from anywhere, so this crate may not index or slice: every access to
//! file bytes is checked (`get`, `split_at_checked`, patterns), and a bad file is an error.

#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

mod bounded;
mod cloud_text;
mod gray;
mod image_source;
mod load;
pub mod middlebury;
pub mod octomap;
pub mod pfm;
pub mod ply;
pub mod posed;
pub mod rgbd;
pub mod rgbd_write;
mod scan_list;

pub use cloud_text::{parse_text_cloud, read_text_cloud};
pub use fuzzyvox_core::file::{MapHeader, read_header, write_atomic};
pub use fuzzyvox_core::map::MapKind;
pub use gray::{decode_gray_image, read_gray_image};
pub use load::{LoadedMap, MapFormat, load_map};
pub use scan_list::{ScanListEntry, read_scan_list, read_scan_list_entries};
