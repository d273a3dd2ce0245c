//! Reading and writing files: native map files, text point clouds, RGB-D frames and OctoMap's
//! formats.
//!
//! Readers take bytes from anywhere, so this module may not index or slice: every access to
//! file bytes is checked (`get`, `split_at_checked`, patterns), and a bad file is an error.
#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

mod atomic;
mod bounded;
mod cloud_text;
mod fuzzy_file;
mod gray;
mod load;
mod logodds_file;
mod mapfile;
pub mod middlebury;
pub mod octomap;
pub mod pfm;
pub mod ply;
pub mod posed;
pub mod rgbd;
pub mod rgbd_write;
mod stored_blocks;

pub use atomic::write_atomic;
pub use cloud_text::{parse_text_cloud, read_text_cloud};
pub use gray::{decode_gray_image, read_gray_image};
pub use load::{LoadedMap, MapFormat, load_map};
pub(crate) use mapfile::read_checked;
pub use mapfile::{MapHeader, MapKind, read_header};
