use super::VoxelMap;
use super::counts::VoxelCounts;
use crate::error::Result;
use crate::measures::{MeasureConfig, Memberships};
use crate::storage::{Resolution, VoxelKey};

/// A read-only map whose memberships come from a function of the voxel key: ground truth from
/// a scene model, a synthetic world for tests and benchmarks, or a view computed from another
/// source. Planners and metrics run on it like on any map; it stores nothing, so it has no
/// cells to list or count, and it does not integrate observations (it is no
/// [`VoxelMapMut`](super::VoxelMapMut)).
///
/// ```
/// use fuzzyvox_core::map::FunctionMap;
/// use fuzzyvox_core::{Memberships, Resolution, VoxelClass, VoxelKey, VoxelMap};
///
/// // Free everywhere except a wall at x = 0.
/// let map = FunctionMap::new(Resolution::new(0.1)?, |k: VoxelKey| match k.x {
///     0 => Memberships { occupied: 1.0, free: 0.0 },
///     _ => Memberships { occupied: 0.0, free: 1.0 },
/// });
/// assert_eq!(map.class_at(VoxelKey::new(0, 5, 5)), VoxelClass::Occupied);
/// assert_eq!(map.class_at(VoxelKey::new(3, 5, 5)), VoxelClass::Free);
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
///
/// Writing into it does not compile: it implements [`VoxelMap`] only, not
/// [`VoxelMapMut`](super::VoxelMapMut) (the same `integrate` compiles for a
/// [`FuzzyMap`](super::FuzzyMap); `tests/map_traits.rs` checks that):
///
/// ```compile_fail,E0277
/// use fuzzyvox_core::map::FunctionMap;
/// use fuzzyvox_core::{IntegrationOptions, Memberships, PointCloud, Resolution, VoxelKey, VoxelMapMut};
///
/// fn integrate(map: &mut impl VoxelMapMut, cloud: &PointCloud) {
///     let _ = map.integrate_cloud(cloud, &IntegrationOptions::default());
/// }
/// let mut map = FunctionMap::new(Resolution::new(0.1)?, |_: VoxelKey| Memberships::default());
/// let cloud = PointCloud::new(nalgebra::Point3::origin(), vec![])?;
/// integrate(&mut map, &cloud);
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
pub struct FunctionMap<F> {
    resolution: Resolution,
    measures: MeasureConfig,
    memberships: F,
}

impl<F: Fn(VoxelKey) -> Memberships + Send + Sync> FunctionMap<F> {
    /// A map with the default measure configuration.
    pub fn new(resolution: Resolution, memberships: F) -> Self {
        Self {
            resolution,
            measures: MeasureConfig::default(),
            memberships,
        }
    }

    /// The same map with another measure configuration.
    pub fn with_measures(mut self, measures: MeasureConfig) -> Result<Self> {
        self.measures = measures.validate()?;
        Ok(self)
    }
}

impl<F: Fn(VoxelKey) -> Memberships + Send + Sync> VoxelMap for FunctionMap<F> {
    fn resolution(&self) -> Resolution {
        self.resolution
    }

    fn measure_config(&self) -> &MeasureConfig {
        &self.measures
    }

    fn memberships_at(&self, key: VoxelKey) -> Memberships {
        (self.memberships)(key)
    }

    fn counts(&self) -> VoxelCounts {
        VoxelCounts::default()
    }

    fn memory_bytes(&self) -> usize {
        0
    }

    fn cells(&self) -> Box<dyn Iterator<Item = (VoxelKey, Memberships)> + '_> {
        Box::new(std::iter::empty())
    }
}
