//! Starting a fuzzy map from an earlier map: a robot's old map (an OctoMap, a saved fuzzyvox
//! map) as evidence that new, uncertain observations then refine.

use super::{FuzzyMap, VoxelMap};
use crate::error::{Error, Result};
use crate::measures::{Memberships, VoxelClass};
use crate::storage::BlockGrid;

/// The most voxels a prior may hold (occupied and free together): a prior is expanded into the
/// fuzzy map's voxels, so a tree whose pruned leaves cover more space than this is refused
/// rather than filling memory.
pub const MAX_PRIOR_VOXELS: usize = 1 << 28;

impl FuzzyMap {
    /// Adds a prior map's knowledge as evidence of confidence `confidence`: each of its
    /// occupied voxels adds occupied evidence `confidence`, each free voxel free evidence
    /// `confidence`, aggregated with the map's t-conorm like any observation (so a prior may
    /// come before or after observations, with the same result). Ambiguous and unknown voxels
    /// of the prior add nothing. Returns the number of voxels that received evidence.
    ///
    /// The prior must have the map's resolution. Errors (the map unchanged): a confidence
    /// outside `(0, 1]`, another resolution, or a prior of more than [`MAX_PRIOR_VOXELS`]
    /// occupied and free voxels.
    ///
    /// ```
    /// use fuzzyvox_core::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelClass, VoxelMap, VoxelMapMut};
    /// use nalgebra::Point3;
    ///
    /// // Yesterday's map: one wall point seen from the origin.
    /// let mut old = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
    /// let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(2.05, 0.05, 0.05)])?;
    /// old.integrate_cloud(&cloud, &IntegrationOptions::default())?;
    ///
    /// // Today's map starts from it, trusting it at 0.6.
    /// let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
    /// map.add_prior(&old, 0.6)?;
    /// let free = map.memberships_at_point(&Point3::new(1.05, 0.05, 0.05))?;
    /// // (0.6 up to the fixed point of exact accumulation, see `map::Accumulator`.)
    /// assert!(free.occupied == 0.0 && (free.free - 0.6).abs() < 1e-6);
    /// assert_eq!(map.class_at_point(&Point3::new(2.05, 0.05, 0.05))?, VoxelClass::Occupied);
    /// # Ok::<(), fuzzyvox_core::Error>(())
    /// ```
    pub fn add_prior(&mut self, prior: &dyn VoxelMap, confidence: f32) -> Result<usize> {
        if !(confidence > 0.0 && confidence <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "prior confidence",
                value: f64::from(confidence),
                expected: "a confidence in (0, 1]",
            });
        }
        let (ours, theirs) = (self.config().resolution, prior.resolution());
        if ours != theirs {
            return Err(Error::Incompatible(format!(
                "the prior's resolution ({} m) differs from the map's ({} m)",
                theirs.size(),
                ours.size()
            )));
        }
        let counts = prior.counts();
        let known = counts.occupied.saturating_add(counts.free);
        if known > MAX_PRIOR_VOXELS {
            return Err(Error::InvalidParameter {
                name: "prior voxels",
                value: known as f64,
                expected: "at most 2^28 occupied and free voxels in a prior",
            });
        }
        let measures = prior.measure_config();
        let mut evidence = BlockGrid::<Memberships>::new();
        for (key, m) in prior.cells() {
            let cell = match measures.classify(m) {
                VoxelClass::Occupied => Memberships {
                    occupied: confidence,
                    free: 0.0,
                },
                VoxelClass::Free => Memberships {
                    occupied: 0.0,
                    free: confidence,
                },
                VoxelClass::Ambiguous | VoxelClass::Unknown => continue,
            };
            *evidence.cell_or_insert(key) = cell;
        }
        Ok(self.fold(&evidence, |m: &Memberships| (m.occupied, m.free)))
    }
}
