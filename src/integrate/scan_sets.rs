use rayon::prelude::*;

use super::cloud::PointCloud;
use super::evidence::{IntegrationOptions, IntegrationStats};
use super::octomap_walk::walk_ray_octomap;
use crate::error::{Error, Result};
use crate::storage::{AccessorMut, BlockGrid, Resolution};

/// Flag: a ray of the scan passed through the voxel.
pub const PASSED: u8 = 1;
/// Flag: an end point of the scan lies in the voxel.
pub const HIT: u8 = 2;

/// One scan in the standard method's terms: per voxel, whether a ray passed through it and
/// whether an end point lies in it. A voxel with both counts as hit.
pub type ScanSets = BlockGrid<u8>;

/// Points per unit of parallel work.
const CHUNK: usize = 1024;

/// The free and hit sets of one scan exactly as OctoMap 1.9's `insertPointCloud` builds them
/// (`computeUpdate` without discretisation): points in single precision, OctoMap's ray
/// traversal, rays longer than `max_range` cut there and clearing only. `include` selects the
/// points that belong to the scan (all, or one confidence cut).
///
/// Errors (before any work): a finite point outside the key range.
pub fn scan_sets(
    cloud: &PointCloud,
    resolution: &Resolution,
    options: &IntegrationOptions,
    include: impl Fn(usize) -> bool + Sync,
) -> Result<(ScanSets, IntegrationStats)> {
    let options = options.validate()?;
    let origin = cloud.origin();
    resolution.key_of(&origin)?;
    if let Some(p) = cloud
        .points()
        .par_iter()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .find_first(|p| {
            resolution.try_key_of(p).is_none() || p.iter().any(|v| !(*v as f32).is_finite())
        })
    {
        return Err(Error::OutOfKeyRange {
            x: p.x,
            y: p.y,
            z: p.z,
            resolution: resolution.size(),
        });
    }
    let single = |p: &nalgebra::Point3<f64>| [p.x as f32, p.y as f32, p.z as f32];
    let origin32 = single(&origin);
    let max_range = options.max_range;
    let sets = cloud
        .points()
        .par_chunks(CHUNK)
        .enumerate()
        .fold(ScanSets::new, |mut sets, (chunk_index, chunk)| {
            let mut acc = AccessorMut::new(&mut sets);
            for (offset, point) in chunk.iter().enumerate() {
                if !point.iter().all(|v| v.is_finite()) || !include(chunk_index * CHUNK + offset) {
                    continue;
                }
                let p = single(point);
                let delta = [p[0] - origin32[0], p[1] - origin32[1], p[2] - origin32[2]];
                let norm_sq = delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2];
                let range = f64::from(norm_sq).sqrt();
                match max_range {
                    Some(max) if range > max => {
                        // OctoMap: origin + normalized direction × (float) max_range.
                        let length = range as f32;
                        let m = max as f32;
                        let end = [
                            origin32[0] + delta[0] / length * m,
                            origin32[1] + delta[1] / length * m,
                            origin32[2] + delta[2] / length * m,
                        ];
                        walk_ray_octomap(resolution, origin32, end, |key| {
                            *acc.get_or_insert(key) |= PASSED;
                        });
                    }
                    _ => {
                        walk_ray_octomap(resolution, origin32, p, |key| {
                            *acc.get_or_insert(key) |= PASSED;
                        });
                        let end = nalgebra::Point3::new(
                            f64::from(p[0]),
                            f64::from(p[1]),
                            f64::from(p[2]),
                        );
                        if let Some(key) = resolution.try_key_of(&end) {
                            *acc.get_or_insert(key) |= HIT;
                        }
                    }
                }
            }
            sets
        })
        .reduce(ScanSets::new, merge_or);
    let integrated = cloud
        .points()
        .iter()
        .enumerate()
        .filter(|(i, p)| p.iter().all(|v| v.is_finite()) && include(*i))
        .count();
    let clipped = match max_range {
        Some(max) => cloud
            .points()
            .iter()
            .enumerate()
            .filter(|(i, p)| include(*i) && (**p - origin).norm() > max)
            .count(),
        None => 0,
    };
    let finite = cloud
        .points()
        .iter()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .count();
    let stats = IntegrationStats {
        integrated,
        skipped: cloud.len() - finite,
        clipped,
        voxels_updated: 0,
    };
    Ok((sets, stats))
}

/// Unites two partial scans (bitwise or: exact, so the split does not matter).
fn merge_or(mut a: ScanSets, b: ScanSets) -> ScanSets {
    if a.block_count() < b.block_count() {
        return merge_or(b, a);
    }
    for (key, block) in b.blocks() {
        let position = a.ensure_block(key);
        for (t, s) in a
            .block_at_mut(position)
            .cells
            .iter_mut()
            .zip(block.cells.iter())
        {
            *t |= *s;
        }
    }
    a
}
