//! End points: the voxel of each pixel's most likely surface point gets the evidence of a hit,
//! in full as in the point integrator, or weighed by the share of the image's rays that end
//! there ([`EvidenceModel::end_point_share`]).

use nalgebra::Vector3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

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
    if model.end_point_share > 0.0 {
        mark_weighed_end_points(evidence, frame, pixels, resolution, model, operator);
        return;
    }
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

/// One image's rays at one voxel: how many end in it, how many pass through it on their last
/// [`EvidenceModel::PASS_VOXELS`] voxels, and the highest confidence of those that end.
#[derive(Clone, Copy, Default)]
struct RayTally {
    ends: u32,
    passes: u32,
    confidence: f32,
}

/// [`mark_end_points`] with each hit weighed by the share `s` of the image's rays through its
/// voxel that end there: the hit is `k_O · min(1, s / end_point_share)` weighted by the highest
/// confidence among them. A ray passes through the voxels it crosses within
/// [`EvidenceModel::PASS_VOXELS`] voxels in front of its own end point (sampled every third of
/// a voxel along the depth). Counts are sums and confidences maxima, so the order of pixels
/// and rows does not matter.
fn mark_weighed_end_points(
    evidence: &mut ScanEvidence,
    frame: &DepthFrame,
    pixels: &[PixelEvidence],
    resolution: &Resolution,
    model: &EvidenceModel,
    operator: &TConorm,
) {
    let k = frame.intrinsics();
    let pose = frame.world_from_camera();
    let origin = pose.translation.vector;
    let width = k.width() as usize;
    // Samples per voxel of depth in front of an end point.
    const PER_VOXEL: f32 = 3.0;
    let step = resolution.size() as f32 / PER_VOXEL;
    let samples = (EvidenceModel::PASS_VOXELS * PER_VOXEL) as u32;
    let rows: Vec<Vec<(VoxelKey, bool, f32)>> = pixels
        .par_chunks(width.max(1))
        .enumerate()
        .map(|(v, row)| {
            let mut rays = Vec::new();
            for (u, p) in row.iter().enumerate() {
                if !p.is_valid() || p.height <= 0.0 {
                    continue;
                }
                // The ray through the pixel, per metre of depth along the optical axis.
                let along = pose.rotation
                    * Vector3::new(
                        (u as f64 - k.cx()) / k.fx(),
                        (v as f64 - k.cy()) / k.fy(),
                        1.0,
                    );
                let at = |depth: f32| (origin + along * f64::from(depth)).into();
                // A point outside the key range was already refused by the frustum box; skip it.
                let Ok(end) = resolution.key_of(&at(p.depth)) else {
                    continue;
                };
                rays.push((end, true, p.confidence));
                let mut last = end;
                for j in 1..=samples {
                    let depth = p.depth - j as f32 * step;
                    if depth <= 0.0 {
                        break;
                    }
                    let Ok(key) = resolution.key_of(&at(depth)) else {
                        break;
                    };
                    if key != last && key != end {
                        rays.push((key, false, 0.0));
                        last = key;
                    }
                }
            }
            rays
        })
        .collect();
    let mut tally: FxHashMap<VoxelKey, RayTally> = FxHashMap::default();
    for &(key, ends, confidence) in rows.iter().flatten() {
        let t = tally.entry(key).or_default();
        if ends {
            t.ends += 1;
            t.confidence = t.confidence.max(confidence);
        } else {
            t.passes += 1;
        }
    }
    let mut cells = AccessorMut::new(evidence);
    for (key, t) in tally {
        if t.ends == 0 {
            continue;
        }
        let share = t.ends as f32 / (t.ends + t.passes) as f32;
        let weight = (share / model.end_point_share).min(1.0);
        let hit = model.occupied(operator, t.confidence, weight);
        let cell = cells.get_or_insert(key);
        cell.occupied = cell.occupied.max(hit);
    }
}
