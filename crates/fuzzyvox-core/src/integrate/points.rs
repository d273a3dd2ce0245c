use nalgebra::Point3;
use rayon::prelude::*;

use super::cloud::PointCloud;
use super::evidence::{
    EvidenceModel, IntegrationOptions, IntegrationStats, ScanEvidence, check_ray_length, merge_max,
    raise,
};
use super::octomap_walk::CellSink;
use super::raywalk::walk_ray_cells;
use super::scan_sets::{CellMarks, Checked, ScanSets, key_box};
use crate::error::{Error, Result};
use crate::ops::TConorm;
use crate::storage::{AccessorMut, BlockKey, Resolution, VoxelKey};

/// Fewest points per unit of parallel work.
const CHUNK: usize = 1024;

/// Pieces of a cloud per thread.
const PIECES_PER_THREAD: usize = 2;

/// Turns a point cloud into one scan's evidence.
///
/// Each ray gives free evidence to every voxel it passes through before its end voxel (except
/// voxels inside its own occupied kernel) and occupied evidence to the end voxel and, with a
/// range-dependent Gaussian kernel, to its neighbours. Rays longer than `max_range` are cut
/// there and give free evidence only. Non-finite points are skipped and counted.
///
/// Errors (before any work): a finite point or cut end point outside the key range, or a ray
/// (cut at `max_range`) longer than [`IntegrationOptions::MAX_RAY_VOXELS`].
pub fn cloud_evidence(
    cloud: &PointCloud,
    resolution: &Resolution,
    model: &EvidenceModel,
    operator: &TConorm,
    options: &IntegrationOptions,
) -> Result<(ScanEvidence, IntegrationStats)> {
    cloud_evidence_checked(cloud, resolution, model, operator, options, Checked::No)
}

/// Checks everything that [`cloud_evidence`] rejects, before any work: the options, the
/// origin's key, every ray's end key and length (cut at `max_range`).
pub(crate) fn check_cloud(
    cloud: &PointCloud,
    resolution: &Resolution,
    options: &IntegrationOptions,
) -> Result<()> {
    let options = options.validate()?;
    let origin = cloud.origin();
    resolution.key_of(&origin)?;
    let ray_of = |p: &Point3<f64>| Ray::new(&origin, p, options.max_range);
    // Rays are made on the fly, here and in the walk, so memory does not grow with the cloud.
    let too_long = |ray: &Ray| check_ray_length(ray.range, resolution.size()).is_err();
    if let Some(ray) = cloud
        .points()
        .par_iter()
        .filter_map(ray_of)
        .find_first(|ray| resolution.try_key_of(&ray.end).is_none() || too_long(ray))
    {
        if resolution.try_key_of(&ray.end).is_none() {
            return Err(Error::OutOfKeyRange {
                x: ray.end.x,
                y: ray.end.y,
                z: ray.end.z,
                resolution: resolution.size(),
            });
        }
        check_ray_length(ray.range, resolution.size())?;
    }
    Ok(())
}

/// [`cloud_evidence`], skipping the checks when the caller made them ([`check_cloud`]).
pub(crate) fn cloud_evidence_checked(
    cloud: &PointCloud,
    resolution: &Resolution,
    model: &EvidenceModel,
    operator: &TConorm,
    options: &IntegrationOptions,
    checked: Checked,
) -> Result<(ScanEvidence, IntegrationStats)> {
    if checked == Checked::No {
        check_cloud(cloud, resolution, options)?;
    }
    let options = options.validate()?;
    let origin = cloud.origin();
    let origin_key = resolution.key_of(&origin)?;
    let ray_of = |p: &Point3<f64>| Ray::new(&origin, p, options.max_range);
    // Each piece of the cloud (a few per thread, so that rays of different lengths balance)
    // deposits into its own partial scan; `max` combines them exactly, so neither the split
    // nor the thread count changes the result. Few pieces keep the partial scans, and the
    // blocks they must merge, few.
    let pieces = (rayon::current_num_threads() * PIECES_PER_THREAD).max(1);
    let piece = cloud.points().len().div_ceil(pieces).max(CHUNK);
    let (evidence, stats) = cloud
        .points()
        .par_chunks(piece)
        .enumerate()
        .map(|(piece_index, chunk)| {
            let mut scan = ScanEvidence::new();
            let mut stats = IntegrationStats::default();
            let mut acc = AccessorMut::new(&mut scan);
            for (offset, point) in chunk.iter().enumerate() {
                let Some(ray) = ray_of(point) else {
                    stats.skipped += 1;
                    continue;
                };
                stats.integrated += 1;
                stats.clipped += usize::from(ray.clipped);
                let index = piece_index * piece + offset;
                let weight = PointWeight {
                    confidence: cloud.confidence_of(index),
                    reliability: cloud.reliability_of(index),
                };
                ray.deposit(&mut acc, resolution, origin_key, model, operator, weight);
            }
            (scan, stats)
        })
        .reduce(
            || (ScanEvidence::new(), IntegrationStats::default()),
            |(a, sa), (b, sb)| (merge_max(a, b), sum_stats(sa, sb)),
        );
    Ok((evidence, stats))
}

/// The counts of two pieces of one scan (voxels are counted when the scan is applied).
fn sum_stats(a: IntegrationStats, b: IntegrationStats) -> IntegrationStats {
    IntegrationStats {
        integrated: a.integrated + b.integrated,
        skipped: a.skipped + b.skipped,
        clipped: a.clipped + b.clipped,
        voxels_updated: 0,
    }
}

/// One scan of a cloud, in the form [`FuzzyMap`](crate::map::FuzzyMap) folds in.
pub(crate) enum CloudScan {
    /// Per voxel, the strongest occupied and free evidence of any ray.
    Evidence(ScanEvidence),
    /// Every ray carries the same free evidence `free` (a cloud without per-point weights, or
    /// with one weight for all): the occupied evidence as a scan's evidence (its free parts
    /// zero), and the voxels that some ray clears as bits. Folding both gives what
    /// [`CloudScan::Evidence`] of the same cloud would, with 2 bits per cleared voxel (the
    /// scan sets' blocks) instead of 64: most of a scan's time went into zeroing fresh
    /// evidence blocks.
    Uniform {
        occupied: ScanEvidence,
        passed: ScanSets,
        free: f32,
    },
}

/// The weight every point of `cloud` carries, when it is one for all.
fn uniform_weight(cloud: &PointCloud) -> Option<PointWeight> {
    let one = |values: Option<&[f32]>| match values {
        None => Some(1.0),
        Some(values) => {
            let first = *values.first()?;
            values
                .iter()
                .all(|v| v.to_bits() == first.to_bits())
                .then_some(first)
        }
    };
    Some(PointWeight {
        confidence: one(cloud.confidence())?,
        reliability: one(cloud.reliability())?,
    })
}

/// [`cloud_evidence_checked`] in the form the fuzzy map folds in: [`CloudScan::Uniform`] when
/// every point carries the same weight, else [`CloudScan::Evidence`].
pub(crate) fn cloud_scan_checked(
    cloud: &PointCloud,
    resolution: &Resolution,
    model: &EvidenceModel,
    operator: &TConorm,
    options: &IntegrationOptions,
    checked: Checked,
) -> Result<(CloudScan, IntegrationStats)> {
    let Some(weight) = uniform_weight(cloud) else {
        return cloud_evidence_checked(cloud, resolution, model, operator, options, checked)
            .map(|(evidence, stats)| (CloudScan::Evidence(evidence), stats));
    };
    if checked == Checked::No {
        check_cloud(cloud, resolution, options)?;
    }
    let options = options.validate()?;
    let origin = cloud.origin();
    let origin_key = resolution.key_of(&origin)?;
    let ray_of = |p: &Point3<f64>| Ray::new(&origin, p, options.max_range);
    // Every ray stays inside the box of the origin and the end points (cut ends lie on the
    // rays), so each piece's bits find their blocks in a flat index over it.
    let (lo, hi) = key_box(
        cloud,
        resolution,
        &[origin.x as f32, origin.y as f32, origin.z as f32],
    );
    let pieces = (rayon::current_num_threads() * PIECES_PER_THREAD).max(1);
    let piece = cloud.points().len().div_ceil(pieces).max(CHUNK);
    let (occupied, passed, stats) = cloud
        .points()
        .par_chunks(piece)
        .map(|chunk| {
            let mut occupied = ScanEvidence::new();
            let mut passed = ScanSets::for_box(lo, hi);
            let mut stats = IntegrationStats::default();
            let mut acc = AccessorMut::new(&mut occupied);
            let mut cells = PassedCells {
                sets: &mut passed,
                position: 0,
            };
            for point in chunk {
                let Some(ray) = ray_of(point) else {
                    stats.skipped += 1;
                    continue;
                };
                stats.integrated += 1;
                stats.clipped += usize::from(ray.clipped);
                if let Some(end_key) =
                    ray.deposit_free(&mut cells, resolution, origin_key, model, operator, weight)
                {
                    ray.deposit_occupied(&mut acc, resolution, end_key, model, operator, weight);
                }
            }
            (occupied, passed, stats)
        })
        .reduce(
            || {
                (
                    ScanEvidence::new(),
                    ScanSets::new(),
                    IntegrationStats::default(),
                )
            },
            |(a, pa, sa), (b, pb, sb)| (merge_max(a, b), pa.union(pb), sum_stats(sa, sb)),
        );
    let free = model.free(
        operator,
        model.free_weight(weight.confidence, weight.reliability),
    );
    Ok((
        CloudScan::Uniform {
            occupied,
            passed,
            free,
        },
        stats,
    ))
}

/// Where a ray's free evidence goes: a scan's evidence ([`EvidenceCells`]) or, when every ray
/// of the scan carries the same free evidence, one bit per voxel ([`PassedCells`]).
trait FreeTarget {
    /// The walk enters block `block`.
    fn enter(&mut self, block: BlockKey);
    /// Cell `cell` of the block entered last receives free evidence `free`.
    fn set(&mut self, cell: usize, free: f32);
}

/// Free evidence raised in a scan's evidence.
struct EvidenceCells<'a, 'g> {
    acc: &'a mut AccessorMut<'g, super::Evidence>,
    position: usize,
}

impl FreeTarget for EvidenceCells<'_, '_> {
    #[inline(always)]
    fn enter(&mut self, block: BlockKey) {
        self.position = self.acc.enter(block);
    }

    #[inline(always)]
    fn set(&mut self, cell: usize, free: f32) {
        // Occupied evidence is never negative, so raising it to 0 (as `raise` would) changes
        // nothing.
        let evidence = self.acc.cell_at(self.position, cell);
        evidence.free = evidence.free.max(free);
    }
}

/// Free evidence as a bit per voxel: every ray of the scan gives the same, so "some ray passed
/// here" says all (the scan sets' blocks: a quarter of a byte per voxel, with the unused hit
/// bit, against the eight bytes of [`Evidence`]).
///
/// [`Evidence`]: super::Evidence
struct PassedCells<'a> {
    sets: &'a mut ScanSets,
    position: usize,
}

impl FreeTarget for PassedCells<'_> {
    #[inline(always)]
    fn enter(&mut self, block: BlockKey) {
        self.position = self.sets.position(block);
    }

    #[inline(always)]
    fn set(&mut self, cell: usize, _free: f32) {
        if let Some(flags) = self.sets.block_at_mut(self.position) {
            flags.pass(cell, 1);
        }
    }
}

/// Free evidence along one ray, taken block by block from its walk: every voxel before the end
/// voxel receives the ray's free evidence, except voxels inside the ray's own occupied kernel.
struct FreeAlongRay<'a, T> {
    target: &'a mut T,
    /// The block the walk is in.
    block: BlockKey,
    /// Key steps from the voxel about to be visited to the end voxel (the walk takes exactly
    /// as many steps as the keys differ).
    steps_to_end: i32,
    /// Voxels at most this many key steps from the end are checked against the kernel.
    near_end: i32,
    reach: f64,
    end: Point3<f64>,
    resolution: &'a Resolution,
    free: f32,
}

impl<T: FreeTarget> CellSink for FreeAlongRay<'_, T> {
    #[inline(always)]
    fn enter(&mut self, block: BlockKey) {
        self.block = block;
        self.target.enter(block);
    }

    #[inline(always)]
    fn mark(&mut self, cell: usize) {
        let close = self.steps_to_end <= self.near_end;
        self.steps_to_end -= 1;
        if close {
            let key = self.block.voxel(cell);
            if (self.resolution.center(key) - self.end).norm() <= self.reach {
                return;
            }
        }
        self.target.set(cell, self.free);
    }
}

/// A point's confidence (its end point's occupied evidence) and reliability (its ray's free
/// evidence in the dual model).
#[derive(Clone, Copy)]
struct PointWeight {
    confidence: f32,
    reliability: f32,
}

/// One measurement ray, already cut at `max_range`.
struct Ray {
    origin: Point3<f64>,
    end: Point3<f64>,
    range: f64,
    clipped: bool,
}

impl Ray {
    fn new(origin: &Point3<f64>, point: &Point3<f64>, max_range: Option<f64>) -> Option<Ray> {
        if !point.iter().all(|v| v.is_finite()) {
            return None;
        }
        let delta = point - origin;
        let range = delta.norm();
        match max_range {
            Some(max) if range > max => Some(Ray {
                origin: *origin,
                end: origin + delta * (max / range),
                range: max,
                clipped: true,
            }),
            _ => Some(Ray {
                origin: *origin,
                end: *point,
                range,
                clipped: false,
            }),
        }
    }

    /// The ray's free and occupied evidence into one scan's evidence.
    fn deposit(
        &self,
        acc: &mut AccessorMut<'_, super::Evidence>,
        resolution: &Resolution,
        origin_key: VoxelKey,
        model: &EvidenceModel,
        operator: &TConorm,
        weight: PointWeight,
    ) {
        let mut cells = EvidenceCells { acc, position: 0 };
        if let Some(end_key) =
            self.deposit_free(&mut cells, resolution, origin_key, model, operator, weight)
        {
            self.deposit_occupied(cells.acc, resolution, end_key, model, operator, weight);
        }
    }

    /// The ray's free evidence into `target`; the end voxel's key when the ray gives any
    /// evidence at all.
    fn deposit_free<T: FreeTarget>(
        &self,
        target: &mut T,
        resolution: &Resolution,
        origin_key: VoxelKey,
        model: &EvidenceModel,
        operator: &TConorm,
        weight: PointWeight,
    ) -> Option<VoxelKey> {
        let free_weight = model.free_weight(weight.confidence, weight.reliability);
        if weight.confidence <= 0.0 && free_weight <= 0.0 {
            return None;
        }
        // Validated by the caller.
        let end_key = resolution.try_key_of(&self.end)?;
        let free = model.free(operator, free_weight);
        // A ray of no free weight (dual model, reliability 0) still marks its end point.
        if free <= 0.0 {
            return Some(end_key);
        }
        let (kernel, sigma) = self.kernel(resolution, model);
        let reach = 2.0 * sigma;
        // Voxels inside this ray's own occupied kernel get no free evidence from it. Only voxels
        // within a few key steps of the end voxel can be that close, so the distance is only
        // computed for those.
        let near_end = if kernel {
            3 * (EvidenceModel::MAX_KERNEL_VOXELS + 1)
        } else {
            -1
        };
        // The walk takes exactly as many steps as the keys differ, so a countdown tells how far
        // (in key steps) each visited voxel is from the end voxel.
        let steps_to_end = (origin_key.x - end_key.x).abs()
            + (origin_key.y - end_key.y).abs()
            + (origin_key.z - end_key.z).abs();
        let mut sink = FreeAlongRay {
            target,
            block: origin_key.block(),
            steps_to_end,
            near_end,
            reach,
            end: self.end,
            resolution,
            free,
        };
        walk_ray_cells(
            resolution,
            &self.origin,
            &self.end,
            origin_key,
            end_key,
            &mut sink,
        );
        Some(end_key)
    }

    /// Whether the ray's occupied evidence spreads over a kernel, and the kernel's σ.
    fn kernel(&self, resolution: &Resolution, model: &EvidenceModel) -> (bool, f64) {
        let sigma = self.range * model.angular_resolution;
        (
            !self.clipped && 2.0 * sigma > 0.5 * resolution.size(),
            sigma,
        )
    }

    /// The ray's occupied evidence: its end voxel and, with a range-dependent Gaussian kernel,
    /// the voxels around it (nothing for a ray cut at the maximum range or of confidence 0).
    fn deposit_occupied(
        &self,
        acc: &mut AccessorMut<'_, super::Evidence>,
        resolution: &Resolution,
        end_key: VoxelKey,
        model: &EvidenceModel,
        operator: &TConorm,
        weight: PointWeight,
    ) {
        let confidence = weight.confidence;
        if self.clipped || confidence <= 0.0 {
            return;
        }
        raise(acc, end_key, model.occupied(operator, confidence, 1.0), 0.0);
        let (kernel, sigma) = self.kernel(resolution, model);
        if kernel {
            let reach = 2.0 * sigma;
            let n =
                ((reach / resolution.size()).ceil() as i32).min(EvidenceModel::MAX_KERNEL_VOXELS);
            let inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
            for dz in -n..=n {
                for dy in -n..=n {
                    for dx in -n..=n {
                        if dx == 0 && dy == 0 && dz == 0 {
                            continue;
                        }
                        let key = VoxelKey::new(end_key.x + dx, end_key.y + dy, end_key.z + dz);
                        let d2 = (resolution.center(key) - self.end).norm_squared();
                        if d2 <= reach * reach {
                            let phi = (-d2 * inv_two_sigma2).exp() as f32;
                            raise(acc, key, model.occupied(operator, confidence, phi), 0.0);
                        }
                    }
                }
            }
        }
    }
}
