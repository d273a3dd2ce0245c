//! A small ray-cast world with exact ground truth, for experiments the real world cannot give:
//! a [`Scene`] of parry3d shapes found through a BVH, a [`render`]er that makes textured images
//! the depth stage can match (texture fixed to world coordinates, so views agree; a smooth,
//! texture-less sky, where matching fails as it does for real UAV footage) with their true
//! depth, and the camera [`trajectory`] patterns of the paper's scenarios.
//!
//! Everything is deterministic for a seed: the same scene, camera and seed give the same image
//! bit for bit, on any number of threads.

pub mod export;
mod render;
pub mod scenario;
mod scene;
mod texture;
pub mod trajectory;

pub use render::{RenderedFrame, render};
pub use scene::{Hit, Scene, SurfaceKind};
pub use texture::unit_hash;
