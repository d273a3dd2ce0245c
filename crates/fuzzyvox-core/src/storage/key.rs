use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, finite};

/// Largest absolute voxel key coordinate. A margin below `i32::MAX` leaves room for kernels and
/// neighbour offsets around any valid key without overflow.
pub const KEY_LIMIT: i32 = i32::MAX - 1024;

/// The integer coordinates of one voxel: `floor(p / resolution)` per axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct VoxelKey {
    /// Index along x.
    pub x: i32,
    /// Index along y.
    pub y: i32,
    /// Index along z.
    pub z: i32,
}

/// The coordinates of one 8×8×8 block: a voxel key shifted right by three.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BlockKey {
    /// Index along x.
    pub x: i32,
    /// Index along y.
    pub y: i32,
    /// Index along z.
    pub z: i32,
}

impl VoxelKey {
    /// A key from its three indices.
    pub const fn new(x: i32, y: i32, z: i32) -> Self {
        Self { x, y, z }
    }

    /// The block holding this voxel.
    #[inline]
    pub const fn block(self) -> BlockKey {
        BlockKey {
            x: self.x >> 3,
            y: self.y >> 3,
            z: self.z >> 3,
        }
    }

    /// The index of this voxel inside its block's cell array.
    #[inline]
    pub const fn cell_index(self) -> usize {
        ((self.x & 7) | ((self.y & 7) << 3) | ((self.z & 7) << 6)) as usize
    }

    /// Whether every coordinate lies within `±KEY_LIMIT`.
    pub fn is_valid(self) -> bool {
        [self.x, self.y, self.z]
            .iter()
            .all(|c| (-KEY_LIMIT..=KEY_LIMIT).contains(c))
    }
}

impl BlockKey {
    /// A block key from its three indices.
    pub const fn new(x: i32, y: i32, z: i32) -> Self {
        Self { x, y, z }
    }

    /// The key of the cell with index `cell` (0..512) in this block.
    #[inline]
    pub const fn voxel(self, cell: usize) -> VoxelKey {
        let c = cell as i32;
        VoxelKey {
            x: (self.x << 3) | (c & 7),
            y: (self.y << 3) | ((c >> 3) & 7),
            z: (self.z << 3) | ((c >> 6) & 7),
        }
    }

    /// The key of the block's lowest corner voxel.
    #[inline]
    pub const fn origin(self) -> VoxelKey {
        self.voxel(0)
    }
}

/// A validated voxel edge length with the conversions between points and keys.
///
/// Keys are `floor(p * (1 / resolution))`, which partitions space exactly as OctoMap does (it
/// multiplies by the same reciprocal and adds a constant offset) but without its ±2^15 key limit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Resolution {
    size: f64,
    inverse: f64,
}

impl Resolution {
    /// Smallest accepted voxel size (0.1 mm).
    pub const MIN: f64 = 1e-4;
    /// Largest accepted voxel size (1 km).
    pub const MAX: f64 = 1e3;

    /// A resolution of `size` metres, finite and within [`Self::MIN`], [`Self::MAX`].
    pub fn new(size: f64) -> Result<Self> {
        finite("resolution", size)?;
        if !(Self::MIN..=Self::MAX).contains(&size) {
            return Err(Error::InvalidParameter {
                name: "resolution",
                value: size,
                expected: "a voxel size between 0.0001 and 1000 m",
            });
        }
        Ok(Self {
            size,
            inverse: 1.0 / size,
        })
    }

    /// Voxel edge length in metres.
    #[inline]
    pub fn size(&self) -> f64 {
        self.size
    }

    /// `1 / size`.
    #[inline]
    pub fn inverse(&self) -> f64 {
        self.inverse
    }

    /// The key of the voxel containing `p`; an error when `p` is not finite or lies outside the
    /// key range, never a wrap.
    #[inline]
    pub fn key_of(&self, p: &Point3<f64>) -> Result<VoxelKey> {
        self.try_key_of(p).ok_or(Error::OutOfKeyRange {
            x: p.x,
            y: p.y,
            z: p.z,
            resolution: self.size,
        })
    }

    /// Like [`Self::key_of`], `None` instead of an error.
    #[inline]
    pub fn try_key_of(&self, p: &Point3<f64>) -> Option<VoxelKey> {
        let limit = f64::from(KEY_LIMIT);
        let mut k = [0i32; 3];
        for (axis, slot) in k.iter_mut().enumerate() {
            let q = (p[axis] * self.inverse).floor();
            // Also rejects NaN, for which every comparison is false.
            if !(q >= -limit && q <= limit) {
                return None;
            }
            *slot = q as i32;
        }
        Some(VoxelKey::new(k[0], k[1], k[2]))
    }

    /// The centre of a voxel: `(key + 0.5) * resolution`.
    #[inline]
    pub fn center(&self, key: VoxelKey) -> Point3<f64> {
        Point3::new(
            (f64::from(key.x) + 0.5) * self.size,
            (f64::from(key.y) + 0.5) * self.size,
            (f64::from(key.z) + 0.5) * self.size,
        )
    }

    /// The lowest corner of a voxel: `key * resolution`.
    #[inline]
    pub fn corner(&self, key: VoxelKey) -> Point3<f64> {
        Point3::from(Vector3::new(
            f64::from(key.x),
            f64::from(key.y),
            f64::from(key.z),
        )) * self.size
    }
}

impl TryFrom<f64> for Resolution {
    type Error = Error;
    fn try_from(size: f64) -> Result<Self> {
        Self::new(size)
    }
}

impl From<Resolution> for f64 {
    fn from(r: Resolution) -> f64 {
        r.size
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_floor_and_centres() {
        let r = Resolution::new(0.1).unwrap();
        assert_eq!(
            r.key_of(&Point3::new(0.05, -0.05, 1.0)).unwrap(),
            VoxelKey::new(0, -1, 10)
        );
        let c = r.center(VoxelKey::new(-1, 0, 3));
        assert!((c.x + 0.05).abs() < 1e-12 && (c.z - 0.35).abs() < 1e-12);
        assert_eq!(r.key_of(&c).unwrap(), VoxelKey::new(-1, 0, 3));
    }

    #[test]
    fn blocks_use_arithmetic_shift() {
        let k = VoxelKey::new(-1, 8, -9);
        assert_eq!(k.block(), BlockKey::new(-1, 1, -2));
        assert_eq!(k.block().voxel(k.cell_index()), k);
        for cell in 0..512 {
            let v = BlockKey::new(-3, 5, 0).voxel(cell);
            assert_eq!(v.cell_index(), cell);
            assert_eq!(v.block(), BlockKey::new(-3, 5, 0));
        }
    }

    #[test]
    fn out_of_range_is_an_error_not_a_wrap() {
        let r = Resolution::new(0.01).unwrap();
        assert!(r.key_of(&Point3::new(1e9, 0.0, 0.0)).is_err());
        assert!(r.key_of(&Point3::new(0.0, -1e9, 0.0)).is_err());
        assert!(r.key_of(&Point3::new(f64::NAN, 0.0, 0.0)).is_err());
        // 1e6 m at 1 cm is beyond OctoMap's 655 m limit but well inside ours.
        let far = r.key_of(&Point3::new(1e6, 0.0, 0.0)).unwrap();
        assert_eq!(far.x, 100_000_000);
    }

    #[test]
    fn invalid_resolutions() {
        for bad in [0.0, -0.1, f64::NAN, f64::INFINITY, 1e-9, 1e9] {
            assert!(Resolution::new(bad).is_err(), "{bad}");
        }
    }
}
