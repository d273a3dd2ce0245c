//! The box of voxels a planner works in, and the dense index (x fastest) of its voxels.

use nalgebra::Point3;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::storage::{Resolution, VoxelKey};

/// Largest planning region, in voxels (a guard against absurd requests: 64 Mi voxels use about
/// 1.5 GiB of working memory, 24 bytes a voxel with the map's stamps).
const MAX_REGION_VOXELS: usize = 1 << 26;

/// An axis-aligned box of voxels to plan in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlanningRegion {
    min: VoxelKey,
    dims: [usize; 3],
}

impl PlanningRegion {
    /// The voxels from `a` to `b` (inclusive, in any order); at most 2^26 voxels.
    pub fn new(a: VoxelKey, b: VoxelKey) -> Result<Self> {
        let min = VoxelKey::new(a.x.min(b.x), a.y.min(b.y), a.z.min(b.z));
        let span = |lo: i32, hi: i32| (i64::from(hi) - i64::from(lo) + 1) as usize;
        let dims = [
            span(min.x, a.x.max(b.x)),
            span(min.y, a.y.max(b.y)),
            span(min.z, a.z.max(b.z)),
        ];
        let voxels = dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]);
        if voxels > MAX_REGION_VOXELS {
            return Err(Error::InvalidParameter {
                name: "planning region voxels",
                value: voxels as f64,
                expected: "a region of at most 2^26 voxels; plan between nearer points or at a coarser resolution",
            });
        }
        Ok(Self { min, dims })
    }

    /// The box around two points grown by `margin` metres on every side.
    pub fn around(
        resolution: &Resolution,
        a: &Point3<f64>,
        b: &Point3<f64>,
        margin: f64,
    ) -> Result<Self> {
        let lo = a.inf(b) - nalgebra::Vector3::repeat(margin);
        let hi = a.sup(b) + nalgebra::Vector3::repeat(margin);
        Self::new(resolution.key_of(&lo)?, resolution.key_of(&hi)?)
    }

    /// Size in voxels along x, y, z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The lowest key.
    pub fn min(&self) -> VoxelKey {
        self.min
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Whether the region holds no voxel (never, for a constructed region).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The dense index of `key` (x fastest), if inside.
    #[inline]
    pub fn index_of(&self, key: VoxelKey) -> Option<usize> {
        let x = i64::from(key.x) - i64::from(self.min.x);
        let y = i64::from(key.y) - i64::from(self.min.y);
        let z = i64::from(key.z) - i64::from(self.min.z);
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        (x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz)
            .then(|| (x + nx * (y + ny * z)) as usize)
    }

    /// The dense index of the voxel at region coordinates `[x, y, z]` (each from 0 to its
    /// dimension, unchecked).
    #[inline]
    pub fn index_at(&self, [x, y, z]: [i64; 3]) -> usize {
        let [nx, ny, _] = self.dims.map(|d| d as i64);
        (x + nx * (y + ny * z)) as usize
    }

    /// The region coordinates `[x, y, z]` of a dense index.
    #[inline]
    pub fn coordinates_at(&self, index: usize) -> [i64; 3] {
        let [nx, ny, _] = self.dims;
        [index % nx, (index / nx) % ny, index / (nx * ny)].map(|c| c as i64)
    }

    /// The key at a dense index.
    #[inline]
    pub fn key_at(&self, index: usize) -> VoxelKey {
        let [nx, ny, _] = self.dims;
        VoxelKey::new(
            self.min.x + (index % nx) as i32,
            self.min.y + ((index / nx) % ny) as i32,
            self.min.z + (index / (nx * ny)) as i32,
        )
    }
}
