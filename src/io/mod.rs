//! Reading and writing files: native map files, text point clouds, RGB-D frames and OctoMap's
//! formats.

mod atomic;
mod cloud_text;
mod fuzzy_file;
mod logodds_file;
mod mapfile;
pub mod middlebury;
pub mod octomap;
pub mod pfm;
pub mod ply;
pub mod rgbd;
pub mod rgbd_write;
mod stored_blocks;
pub mod views;

pub use atomic::write_atomic;
pub use cloud_text::read_text_cloud;
pub use mapfile::{MapHeader, MapKind, read_header};
