//! The four classes a voxel can fall in: plain data that storage counts and measures decide,
//! so that storage does not depend on how classes are computed; and each class's colour, the
//! same in every figure, PLY export and viewer page.

use serde::{Deserialize, Serialize};

/// The four classes a voxel can fall in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum VoxelClass {
    /// Evidence says occupied, and clearly more than free.
    Occupied,
    /// Evidence says free, and clearly more than occupied.
    Free,
    /// Both sets claim the voxel: conflicting evidence.
    Ambiguous,
    /// Neither set claims it strongly enough (including voxels never observed).
    Unknown,
}

impl VoxelClass {
    /// All classes, in index order.
    pub const ALL: [VoxelClass; 4] = [Self::Occupied, Self::Free, Self::Ambiguous, Self::Unknown];

    /// A dense index 0..4, for counting.
    #[inline]
    pub const fn index(self) -> usize {
        match self {
            Self::Occupied => 0,
            Self::Free => 1,
            Self::Ambiguous => 2,
            Self::Unknown => 3,
        }
    }

    /// Lower-case name (`occupied`, `free`, `ambiguous`, `unknown`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Occupied => "occupied",
            Self::Free => "free",
            Self::Ambiguous => "ambiguous",
            Self::Unknown => "unknown",
        }
    }
}

/// The colour of each class, everywhere (figures, PLY export, viewer page): occupied near black,
/// free light green, ambiguous orange, unknown light grey (the table in `fuzzyvox-figure`'s
/// `palette`).
pub const fn class_color(class: VoxelClass) -> [u8; 3] {
    match class {
        VoxelClass::Occupied => [40, 40, 40],
        VoxelClass::Free => [150, 210, 150],
        VoxelClass::Ambiguous => [235, 140, 30],
        VoxelClass::Unknown => [215, 215, 215],
    }
}
