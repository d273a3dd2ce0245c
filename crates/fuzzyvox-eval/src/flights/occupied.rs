//! The obstacles of real footage: the occupied voxels of a reference map (a map built from the
//! sensor's own depth, as the truth of the runs on real frames).

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_core::storage::{Resolution, VoxelKey};
use nalgebra::{Point3, Vector3};
use rustc_hash::FxHashSet;

use super::world::Obstacles;

/// The occupied voxels of a reference map as obstacles: a point meets one when it lies within
/// the radius of the voxel's cube.
#[derive(Clone, Debug)]
pub struct OccupiedVoxels {
    resolution: Resolution,
    occupied: FxHashSet<VoxelKey>,
    reach: f64,
}

impl OccupiedVoxels {
    /// The voxels `reference` calls occupied. Distances are searched up to `reach` metres;
    /// [`Obstacles::distance_to_surface`] answers `reach` for a point with no occupied voxel
    /// nearer.
    pub fn new(reference: &dyn VoxelMap, reach: f64) -> Self {
        let measures = reference.measure_config();
        Self {
            resolution: reference.resolution(),
            occupied: reference
                .cells()
                .filter(|(_, m)| measures.classify(*m) == VoxelClass::Occupied)
                .map(|(key, _)| key)
                .collect(),
            reach: reach.max(0.0),
        }
    }

    /// How many voxels are obstacles.
    pub fn len(&self) -> usize {
        self.occupied.len()
    }

    /// Whether no voxel is an obstacle.
    pub fn is_empty(&self) -> bool {
        self.occupied.is_empty()
    }

    /// Distance from `point` to the cube of `key`.
    fn distance_to_voxel(&self, point: &Point3<f64>, key: VoxelKey) -> f64 {
        let half = self.resolution.size() / 2.0;
        let offset = point - self.resolution.center(key);
        Vector3::new(
            (offset.x.abs() - half).max(0.0),
            (offset.y.abs() - half).max(0.0),
            (offset.z.abs() - half).max(0.0),
        )
        .norm()
    }

    /// The nearest occupied voxel's distance from `point`, searched within `within` metres;
    /// `None` when there is none that near (or the point is off the grid).
    fn nearest_within(&self, point: &Point3<f64>, within: f64) -> Option<f64> {
        let center = self.resolution.key_of(point).ok()?;
        let reach = (within / self.resolution.size()).ceil() as i32 + 1;
        let mut nearest: Option<f64> = None;
        for dz in -reach..=reach {
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let key = VoxelKey::new(center.x + dx, center.y + dy, center.z + dz);
                    if self.occupied.contains(&key) {
                        let d = self.distance_to_voxel(point, key);
                        if d <= within && nearest.is_none_or(|n| d < n) {
                            nearest = Some(d);
                        }
                    }
                }
            }
        }
        nearest
    }
}

impl Obstacles for OccupiedVoxels {
    fn distance_to_surface(&self, point: &Point3<f64>) -> f64 {
        self.nearest_within(point, self.reach).unwrap_or(self.reach)
    }

    fn meets_swept_ball(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> bool {
        // Points a quarter voxel apart: a ball of `radius` around each covers the capsule but
        // for slivers thinner than the step, which a voxel's cube cannot slip through.
        let step = self.resolution.size() / 4.0;
        let steps = ((b - a).norm() / step).ceil().max(1.0) as usize;
        (0..=steps).any(|i| {
            let p = a + (b - a) * (i as f64 / steps as f64);
            self.nearest_within(&p, radius).is_some_and(|d| d < radius)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::PointCloud;
    use fuzzyvox_core::map::{LogOddsConfig, LogOddsMap, VoxelMapMut};

    /// A log-odds map of a wall at x = 2 m, seen from the origin, at 0.1 m.
    fn wall() -> LogOddsMap {
        let mut points = Vec::new();
        for i in -10..=10 {
            for j in -10..=10 {
                points.push(Point3::new(2.0, f64::from(i) * 0.05, f64::from(j) * 0.05));
            }
        }
        let cloud = PointCloud::new(Point3::origin(), points).unwrap();
        let mut map = LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap();
        for _ in 0..3 {
            map.integrate_cloud(&cloud, &Default::default()).unwrap();
        }
        map
    }

    #[test]
    fn distances_and_swept_balls_follow_the_occupied_voxels() {
        let obstacles = OccupiedVoxels::new(&wall(), 1.0);
        assert!(!obstacles.is_empty());
        // The wall's voxels span x in [2.0, 2.1).
        let d = obstacles.distance_to_surface(&Point3::new(1.5, 0.0, 0.0));
        assert!((d - 0.5).abs() < 1e-9, "{d}");
        assert_eq!(
            obstacles.distance_to_surface(&Point3::new(2.05, 0.0, 0.0)),
            0.0
        );
        // Farther than the search reach: the reach.
        assert_eq!(
            obstacles.distance_to_surface(&Point3::new(-1.0, 0.0, 0.0)),
            1.0
        );
        let radius = 0.2;
        assert!(obstacles.meets_swept_ball(
            &Point3::new(1.0, 0.0, 0.0),
            &Point3::new(3.0, 0.0, 0.0),
            radius
        ));
        assert!(!obstacles.meets_swept_ball(
            &Point3::new(1.0, -0.5, 0.0),
            &Point3::new(1.7, 0.5, 0.0),
            radius
        ));
        // The first contact of a path through the wall lies within the radius of its face.
        let contact = obstacles
            .first_contact(
                &Point3::new(1.0, 0.0, 0.0),
                &Point3::new(3.0, 0.0, 0.0),
                radius,
            )
            .unwrap();
        assert!(
            contact.x >= 2.0 - radius - 1e-9 && contact.x < 2.0,
            "{contact}"
        );
    }
}
