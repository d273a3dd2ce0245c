//! Sparse voxel storage shared by every map: `i32` voxel keys, 8×8×8 dense blocks in a hash map,
//! cached accessors and per-block class counts.
//!
//! The layout is that of OpenVDB, Bonxai and Voxblox reduced to one level: a block key is the
//! voxel key shifted right by three (arithmetic, so negative keys work), and a block stores its
//! 512 cells as a plain array. Blocks live in a `Vec` with a hash index beside it, so parallel
//! updates can hand each block to exactly one thread without locks, and a cached accessor skips
//! the hash lookup while consecutive cells fall in the same block.

mod accessor;
mod block;
mod grid;
mod key;
mod packed;
mod region;

pub use accessor::{Accessor, AccessorMut};
pub use block::{BLOCK_CELLS, BLOCK_SIDE, Block, ClassCounts};
pub use grid::BlockGrid;
pub use key::{BlockKey, KEY_LIMIT, Resolution, VoxelKey};
pub use packed::{CellBits, PackedBlock, PackedGrid};
pub use region::KeyBox;
