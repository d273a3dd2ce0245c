use rayon::prelude::*;
use serde::Serialize;

use super::truth::{GroundTruth, meets_geometry};
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_sim::Scene;

/// How one map compares with the ground truth.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MapMetrics {
    /// Of the map's occupied voxels, the fraction that truly meet the geometry (seen or not:
    /// a voxel inside a solid wall is rightly occupied).
    pub occupied_precision: f64,
    /// Of the truly occupied voxels, the fraction the map calls occupied.
    pub occupied_recall: f64,
    /// Harmonic mean of precision and recall.
    pub occupied_f1: f64,
    /// Truly occupied voxels that the map calls free.
    pub holes: usize,
    /// Voxels the map calls occupied in the truly unknown region: outside the observed region
    /// and not meeting the geometry (the empty space behind walls, the sky).
    pub spurious_unknown: usize,
    /// Mean distance (metres) from the map's occupied voxel centres to the true surface.
    pub chamfer_m: f64,
    /// The map's occupied voxels.
    pub occupied: usize,
    /// The map's free voxels.
    pub free: usize,
}

/// Compares a map with the ground truth (and, for the Chamfer distance, the scene).
pub fn evaluate(map: &dyn VoxelMap, truth: &GroundTruth, scene: &Scene) -> MapMetrics {
    let resolution = map.resolution();
    let occupied: Vec<_> = map
        .cells()
        .filter(|(_, m)| map.measure_config().classify(*m) == VoxelClass::Occupied)
        .map(|(key, _)| key)
        .collect();
    let free = map
        .cells()
        .filter(|(_, m)| map.measure_config().classify(*m) == VoxelClass::Free)
        .count();
    let meets: Vec<bool> = occupied
        .par_iter()
        .map(|&k| truth.is_occupied(k) || meets_geometry(scene, resolution, k))
        .collect();
    let correct = meets.iter().filter(|&&m| m).count();
    let found = occupied.iter().filter(|k| truth.is_occupied(**k)).count();
    let spurious_unknown = occupied
        .iter()
        .zip(&meets)
        .filter(|(k, m)| !**m && !truth.is_observed(**k))
        .count();
    let holes = truth
        .occupied()
        .filter(|k| map.class_at(*k) == VoxelClass::Free)
        .count();
    let precision = ratio(correct, occupied.len());
    let recall = ratio(found, truth.occupied_count());
    let f1 = if precision + recall > 0.0 {
        2.0 * precision * recall / (precision + recall)
    } else {
        0.0
    };
    let chamfer_sum: f64 = occupied
        .par_iter()
        .map(|k| scene.distance_to_surface(&resolution.center(*k)))
        .sum();
    MapMetrics {
        occupied_precision: precision,
        occupied_recall: recall,
        occupied_f1: f1,
        holes,
        spurious_unknown,
        chamfer_m: if occupied.is_empty() {
            0.0
        } else {
            chamfer_sum / occupied.len() as f64
        },
        occupied: occupied.len(),
        free,
    }
}

fn ratio(part: usize, whole: usize) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 / whole as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::integrate::{Evidence, ScanEvidence};
    use fuzzyvox_core::map::{FuzzyConfig, FuzzyMap};
    use fuzzyvox_core::storage::{Resolution, VoxelKey};
    use fuzzyvox_sim::SurfaceKind;
    use nalgebra::{Point3, Vector3};

    #[test]
    fn metrics_on_a_hand_made_map() {
        let r = Resolution::new(1.0).unwrap();
        // Truth: voxels x = 5 (y, z in 0..2) are occupied; x in 0..=5 observed.
        let wall: Vec<_> = (0..2)
            .flat_map(|y| (0..2).map(move |z| VoxelKey::new(5, y, z)))
            .collect();
        let observed: Vec<_> = (0..=5)
            .flat_map(|x| (0..2).flat_map(move |y| (0..2).map(move |z| VoxelKey::new(x, y, z))))
            .collect();
        let truth = GroundTruth::new(r, wall.clone(), observed);
        let mut scene = Scene::new();
        scene.add_box(
            Point3::new(5.5, 1.0, 1.0),
            Vector3::new(0.5, 1.0, 1.0),
            0.0,
            SurfaceKind::Wall,
        );
        // The map: three of the four wall voxels occupied, one free (a hole), and one
        // occupied voxel behind the wall (x = 7: unknown region, 1.5 m from the surface).
        let mut evidence = ScanEvidence::new();
        for key in &wall[1..] {
            *evidence.cell_or_insert(*key) = Evidence {
                occupied: 0.9,
                free: 0.0,
            };
        }
        *evidence.cell_or_insert(wall[0]) = Evidence {
            occupied: 0.0,
            free: 0.9,
        };
        *evidence.cell_or_insert(VoxelKey::new(7, 0, 0)) = Evidence {
            occupied: 0.9,
            free: 0.0,
        };
        // Unobserved but touching the wall's back face: rightly occupied, not spurious.
        *evidence.cell_or_insert(VoxelKey::new(6, 1, 1)) = Evidence {
            occupied: 0.9,
            free: 0.0,
        };
        let mut stored = FuzzyMap::new(FuzzyConfig::new(1.0).unwrap()).unwrap();
        stored.apply_evidence(&evidence);
        let m = evaluate(&stored, &truth, &scene);
        assert_eq!(m.occupied, 5);
        assert_eq!(m.holes, 1);
        assert_eq!(m.spurious_unknown, 1);
        assert!((m.occupied_precision - 0.8).abs() < 1e-12);
        assert!((m.occupied_recall - 0.75).abs() < 1e-12);
        let f1 = 2.0 * 0.8 * 0.75 / (0.8 + 0.75);
        assert!((m.occupied_f1 - f1).abs() < 1e-12);
        // Wall voxel centres lie inside the box (distance 0); the stray one is 1.5 m away, the
        // one behind the wall 0.5 m.
        assert!((m.chamfer_m - 2.0 / 5.0).abs() < 1e-4, "{}", m.chamfer_m);
    }
}
