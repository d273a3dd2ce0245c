//! End points: the voxel of each pixel's most likely surface point gets the full evidence of a
//! hit, as in the point integrator.

use rayon::prelude::*;

use super::pixel::PixelEvidence;
use crate::integrate::depth_image::DepthFrame;
use crate::integrate::evidence::{EvidenceModel, ScanEvidence};
use crate::ops::TConorm;
use crate::storage::{AccessorMut, Resolution, VoxelKey};

/// Gives the voxel that holds each pixel's most likely surface point (its `P0` back-projected)
/// the full occupied evidence of a hit, `k_O` weighted by the pixel's confidence, as the point
/// integrator does for its end voxel. The frustum's voxel-centre test alone misses surfaces
/// that cross a voxel away from its centre (ground seen at a grazing angle), and the interval's
/// kernel is deliberately weak when the interval is wide; the hit keeps the most likely point
/// as strong as the paper's confidence-weighted point insertion. Evidence only rises, so the
/// order of pixels does not matter.
///
/// Rows are back-projected in parallel. Neighbouring pixels of a row mostly land in the same
/// voxel, so each run of them keeps its highest confidence, and the weighted evidence (a
/// generator and its inverse, the costly part) is computed once per run: the weighting rises
/// with confidence, so that is the largest of the run's hits.
pub(super) fn mark_end_points(
    evidence: &mut ScanEvidence,
    frame: &DepthFrame,
    pixels: &[PixelEvidence],
    resolution: &Resolution,
    model: &EvidenceModel,
    operator: &TConorm,
) {
    let k = frame.intrinsics();
    let pose = frame.world_from_camera();
    let width = k.width() as usize;
    let rows: Vec<Vec<(VoxelKey, f32)>> = pixels
        .par_chunks(width.max(1))
        .enumerate()
        .map(|(v, row)| {
            let mut runs: Vec<(VoxelKey, f32)> = Vec::new();
            for (u, p) in row.iter().enumerate() {
                if !p.is_valid() || p.height <= 0.0 {
                    continue;
                }
                let point = pose * k.back_project(u as f64, v as f64, f64::from(p.depth));
                // A point outside the key range was already refused by the frustum box; skip it.
                let Ok(key) = resolution.key_of(&point) else {
                    continue;
                };
                match runs.last_mut() {
                    Some((last, confidence)) if *last == key => {
                        *confidence = confidence.max(p.confidence);
                    }
                    _ => runs.push((key, p.confidence)),
                }
            }
            // Each run's highest confidence becomes its hit.
            for (_, value) in &mut runs {
                *value = model.occupied(operator, *value, 1.0);
            }
            runs
        })
        .collect();
    let mut cells = AccessorMut::new(evidence);
    for (key, hit) in rows.iter().flatten() {
        let cell = cells.get_or_insert(*key);
        cell.occupied = cell.occupied.max(*hit);
    }
}
