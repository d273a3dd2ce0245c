//! The true scene as a map, for planning the paths the truth allows.

use fuzzyvox_core::map::FunctionMap;
use fuzzyvox_core::measures::Memberships;
use fuzzyvox_core::storage::{Resolution, VoxelKey};
use fuzzyvox_sim::scenario::Scenario;

/// The true scene as a map: a voxel that meets any surface is occupied, every other voxel free.
pub fn truth_map(
    scenario: &Scenario,
    resolution: Resolution,
) -> FunctionMap<impl Fn(VoxelKey) -> Memberships + Send + Sync + '_> {
    FunctionMap::new(resolution, move |key: VoxelKey| {
        let half = nalgebra::Vector3::repeat(resolution.size() / 2.0);
        let center = resolution.center(key);
        let (min, max) = (center - half, center + half);
        if scenario.scene.intersects_box(&min, &max) {
            Memberships {
                occupied: 1.0,
                free: 0.0,
            }
        } else {
            Memberships {
                occupied: 0.0,
                free: 1.0,
            }
        }
    })
}
