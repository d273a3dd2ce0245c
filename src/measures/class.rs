use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

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

/// Thresholds that turn measures into a [`VoxelClass`].
///
/// A voxel is classified in this order:
/// 1. **Ambiguous** when its ambiguity `A = T(μO, μE)` is at least `ambiguity`;
/// 2. **Occupied** when `μO >= occupied` and `μO > μE`;
/// 3. **Free** when `μE >= free` and `μE > μO`;
/// 4. **Unknown** otherwise (this includes every voxel that no evidence reached).
///
/// The defaults (0.5 each) make a log-odds cell occupied exactly when `p > 0.5`, as OctoMap does,
/// because such a cell has `μO = p` and `μE = 1 - p`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClassThresholds {
    /// Minimum occupied membership for `Occupied`.
    pub occupied: f32,
    /// Minimum free membership for `Free`.
    pub free: f32,
    /// Minimum ambiguity for `Ambiguous`.
    pub ambiguity: f32,
}

impl Default for ClassThresholds {
    fn default() -> Self {
        Self {
            occupied: 0.5,
            free: 0.5,
            ambiguity: 0.5,
        }
    }
}

impl ClassThresholds {
    /// Checks that every threshold lies in `(0, 1]`.
    pub fn validate(self) -> Result<Self> {
        for (name, value) in [
            ("occupied threshold", self.occupied),
            ("free threshold", self.free),
            ("ambiguity threshold", self.ambiguity),
        ] {
            if !(value > 0.0 && value <= 1.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: f64::from(value),
                    expected: "a threshold in (0, 1]",
                });
            }
        }
        Ok(self)
    }
}
