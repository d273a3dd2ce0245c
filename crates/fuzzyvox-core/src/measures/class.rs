use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Thresholds that turn measures into a [`VoxelClass`](crate::class::VoxelClass).
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
