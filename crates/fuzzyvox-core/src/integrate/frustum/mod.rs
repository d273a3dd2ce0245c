//! Projective frustum integration of an interval depth image ([`depth_evidence`]), which also
//! schedules the work: the pixels' evidence ([`pixel`]), the tiles' reach ([`tiles`]), the
//! blocks that survive culling ([`cull`]), each block's evidence in parallel ([`camera`]), and
//! last the end points' hits ([`end_points`]).

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::integrate::depth_image::DepthFrame;
use crate::integrate::evidence::{
    Evidence, EvidenceKind, EvidenceModel, IntegrationOptions, IntegrationStats, ScanEvidence,
};
use crate::integrate::footprint::FootprintFill;
use crate::ops::TConorm;
use crate::storage::{Block, BlockKey, Resolution};

mod camera;
mod cull;
mod end_points;
mod pixel;
mod tiles;

use camera::{CameraView, block_evidence};
use cull::frustum_box;
use end_points::mark_end_points;
use pixel::{PixelEvidence, pixel_evidence};
use tiles::TileReach;

/// Largest frustum bounding box, in blocks, that one depth image may span (a guard against
/// absurd depths; ordinary frames span thousands).
const MAX_FRUSTUM_BLOCKS: u128 = 1 << 26;

/// Turns an interval depth image into one scan's evidence by projective frustum integration.
///
/// Every block that the camera frustum touches in front of the observed surfaces is visited;
/// each of its voxel centres is projected into the image and compared, by its depth `z` along
/// the optical axis, with that pixel's interval `(P-, P0, P+)` and confidence `c`; with `δ` half
/// a voxel diagonal:
/// - `z < P- - δ`: free evidence (the voxel lies in front of the surface);
/// - `P- - δ <= z <= P+ + δ`: occupied evidence `k_O · φ(z)`, weighted by `c`;
/// - `z > P+ + δ`: nothing (occluded).
///
/// `φ` is a tent that is flat within `δ` of `P0` and falls linearly to zero at `P- - δ` and
/// `P+ + δ`; its height `(2δ / (P+ - P- + 2δ))^f` (`f` = [`EvidenceModel::interval_falloff`])
/// makes wide (far, uncertain) intervals commit less per voxel: `f = 1` keeps the evidence
/// summed along the ray that of one sharp hit, `f = 0` gives every voxel of the interval the full
/// evidence. The voxel that holds the pixel's `P0` point also gets the full occupied evidence
/// of a hit (see `mark_end_points`). A pixel whose depth exceeds `max_range` clears free space
/// up to `max_range` and marks nothing occupied. Invalid pixels contribute nothing.
///
/// Blocks are found by culling the blocks of the frustum's bounding box against the largest far
/// depth over 8×8 pixel tiles (conservative, so no observed block is missed) and are processed in
/// parallel, each by one thread: the result is the same for any number of threads.
pub fn depth_evidence(
    frame: &DepthFrame,
    resolution: &Resolution,
    model: &EvidenceModel,
    operator: &TConorm,
    options: &IntegrationOptions,
) -> Result<(ScanEvidence, IntegrationStats)> {
    let options = options.validate()?;
    let max_range = options.max_range.unwrap_or(f64::INFINITY) as f32;
    let image = frame.image();
    let (width, height) = (image.width(), image.height());
    let half_diagonal = (0.5 * 3f64.sqrt() * resolution.size()) as f32;

    // Per pixel: its interval and the evidence that does not depend on the voxel.
    let pixels = pixel_evidence(image, model, operator, max_range, half_diagonal);
    let integrated = pixels.iter().filter(|p| p.is_valid()).count();
    let stats = IntegrationStats {
        integrated,
        skipped: pixels.len() - integrated,
        clipped: pixels
            .iter()
            .filter(|p| p.is_valid() && p.depth > max_range)
            .count(),
        voxels_updated: 0,
    };
    if integrated == 0 {
        return Ok((ScanEvidence::new(), stats));
    }

    let fill = (model.kind == EvidenceKind::Dual && model.fill_footprints).then(|| {
        let free_bound = |p: &PixelEvidence| {
            if p.is_valid() && p.free > 0.0 {
                p.free_until
            } else {
                f32::INFINITY
            }
        };
        let bound: Vec<f32> = pixels.iter().map(free_bound).collect();
        let weight: Vec<f32> = pixels
            .iter()
            .map(|p| {
                if free_bound(p).is_finite() {
                    p.free_weight
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        FootprintFill::new(&bound, &weight, width as usize, height as usize)
    });
    let tiles = TileReach::new(&pixels, fill.as_ref(), width, height);
    let camera = CameraView::new(frame, resolution);
    let frustum = frustum_box(frame, resolution, tiles.max_reach)?;
    if frustum.block_count() > MAX_FRUSTUM_BLOCKS {
        return Err(Error::InvalidParameter {
            name: "depth image reach",
            value: f64::from(tiles.max_reach),
            expected: "a frustum of at most 2^26 blocks at this resolution; set max_range",
        });
    }
    let candidates = camera.observed_blocks(&frustum, &tiles);

    let blocks: Vec<(BlockKey, Box<Block<Evidence>>)> = candidates
        .par_iter()
        .filter_map(|&key| {
            let fill = fill.as_ref();
            block_evidence(&camera, key, &pixels, fill, model, operator, half_diagonal)
                .map(|b| (key, b))
        })
        .collect();
    let mut evidence = ScanEvidence::new();
    for (key, block) in blocks {
        evidence.insert_block(key, block);
    }
    mark_end_points(&mut evidence, frame, &pixels, resolution, model, operator);
    Ok((evidence, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PinholeIntrinsics;
    use crate::integrate::IntervalDepthImage;
    use crate::storage::AccessorMut;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    /// Every block of the frustum's box that the culling drops receives no evidence: culling
    /// by groups and by the image's side planes only ever saves work.
    #[test]
    fn culling_drops_no_block_with_evidence() {
        let frames = [
            // An ordinary camera, tilted.
            (
                PinholeIntrinsics::new(24, 16, 20.0, 20.0, 11.5, 7.5).unwrap(),
                Isometry3::from_parts(
                    Translation3::new(0.3, -0.2, 1.0),
                    UnitQuaternion::from_euler_angles(0.3, -0.7, 2.0),
                ),
            ),
            // A principal point far off the image and unequal focal lengths.
            (
                PinholeIntrinsics::new(13, 9, 6.0, 25.0, 30.0, -4.0).unwrap(),
                Isometry3::from_parts(
                    Translation3::new(-1.0, 2.0, 0.5),
                    UnitQuaternion::from_euler_angles(-1.2, 0.4, 0.1),
                ),
            ),
            // A wide camera looking straight up.
            (
                PinholeIntrinsics::new(16, 16, 3.0, 3.0, 7.5, 7.5).unwrap(),
                Isometry3::from_parts(
                    Translation3::new(0.0, 0.0, -0.4),
                    UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0),
                ),
            ),
            // A tiny image whose principal point lies 1,000 px away (fuzzing found one 8,000 px
            // away): a needle of a frustum, tens of metres long and grazing the camera plane.
            (
                PinholeIntrinsics::new(2, 3, 64.125, 31.875, 819.875, 816.375).unwrap(),
                Isometry3::from_parts(
                    Translation3::new(0.0, -0.01, -241.59),
                    UnitQuaternion::from_euler_angles(-1e-3, -1e-3, -0.768),
                ),
            ),
        ];
        let resolution = Resolution::new(0.1).unwrap();
        let model = EvidenceModel::default();
        let operator = TConorm::default();
        let half_diagonal = (0.5 * 3f64.sqrt() * resolution.size()) as f32;
        for (index, (k, pose)) in frames.into_iter().enumerate() {
            let n = (k.width() * k.height()) as usize;
            let depth: Vec<f32> = (0..n).map(|i| 0.4 + (i % 11) as f32 * 0.35).collect();
            let image = IntervalDepthImage::from_depth(k.width(), k.height(), &depth, |z| {
                (0.9 * z, 1.2 * z, 0.8)
            })
            .unwrap();
            let frame = DepthFrame::new(k, pose, image).unwrap();
            let pixels = pixel_evidence(
                frame.image(),
                &model,
                &operator,
                f32::INFINITY,
                half_diagonal,
            );
            let tiles = TileReach::new(&pixels, None, k.width(), k.height());
            let camera = CameraView::new(&frame, &resolution);
            let frustum = frustum_box(&frame, &resolution, tiles.max_reach).unwrap();
            let kept = camera.observed_blocks(&frustum, &tiles);
            let all: Vec<BlockKey> = frustum.blocks().collect();
            assert!(kept.len() < all.len(), "frame {index}: nothing culled");
            let mut with_evidence = 0;
            for &key in &all {
                let evidence = block_evidence(
                    &camera,
                    key,
                    &pixels,
                    None,
                    &model,
                    &operator,
                    half_diagonal,
                );
                if evidence.is_some() {
                    with_evidence += 1;
                    assert!(
                        kept.binary_search_by_key(&(key.z, key.y, key.x), |k| (k.z, k.y, k.x))
                            .is_ok(),
                        "frame {index}: block {key:?} has evidence but was culled"
                    );
                }
            }
            assert!(with_evidence > 0, "frame {index} observes nothing");
            // The separating-axis test keeps the needle's blocks, not the sheet of blocks
            // around it that the side planes alone let through.
            if index == 3 {
                assert!(
                    kept.len() * 20 < all.len(),
                    "frame {index}: {} of {} blocks kept",
                    kept.len(),
                    all.len()
                );
            }
        }
    }

    /// The end-point hits, one weighted evidence per run of pixels in a voxel and rows in
    /// parallel, against the definition: every pixel's hit raised into its voxel one by one.
    /// Smooth depths put many neighbouring pixels in one voxel; confidences vary within runs.
    #[test]
    fn end_point_hits_equal_one_hit_per_pixel() {
        let k = PinholeIntrinsics::new(48, 36, 200.0, 200.0, 23.5, 17.5).unwrap();
        let pose = Isometry3::from_parts(
            Translation3::new(0.2, -0.1, 0.5),
            UnitQuaternion::from_euler_angles(0.2, -0.3, 0.4),
        );
        let n = (k.width() * k.height()) as usize;
        let depth: Vec<f32> = (0..n)
            .map(|i| {
                let (u, v) = ((i % 48) as f32, (i / 48) as f32);
                if i % 97 == 5 {
                    f32::NAN
                } else {
                    1.0 + 0.02 * u + 0.01 * v
                }
            })
            .collect();
        let image = IntervalDepthImage::from_depth(k.width(), k.height(), &depth, |z| {
            let c = 0.3 + 0.7 * ((z * 1000.0) as u32 % 13) as f32 / 13.0;
            (0.95 * z, 1.05 * z, c)
        })
        .unwrap();
        let frame = DepthFrame::new(k, pose, image).unwrap();
        let resolution = Resolution::new(0.05).unwrap();
        let operator = TConorm::default();
        let model = EvidenceModel::default();
        let half_diagonal = (0.5 * 3f64.sqrt() * resolution.size()) as f32;
        let pixels = pixel_evidence(
            frame.image(),
            &model,
            &operator,
            f32::INFINITY,
            half_diagonal,
        );
        let mut fast = ScanEvidence::new();
        mark_end_points(&mut fast, &frame, &pixels, &resolution, &model, &operator);
        let mut reference = ScanEvidence::new();
        let mut cells = AccessorMut::new(&mut reference);
        let mut runs_shared = 0;
        for (i, p) in pixels.iter().enumerate() {
            if !p.is_valid() {
                continue;
            }
            let (u, v) = ((i % 48) as f64, (i / 48) as f64);
            let point = pose * k.back_project(u, v, f64::from(p.depth));
            let key = resolution.key_of(&point).unwrap();
            let hit = model.occupied(&operator, p.confidence, 1.0);
            let cell = cells.get_or_insert(key);
            runs_shared += usize::from(cell.occupied > 0.0);
            cell.occupied = cell.occupied.max(hit);
        }
        assert!(runs_shared > n / 2, "pixels rarely share a voxel");
        let a: Vec<_> = fast
            .cells()
            .map(|(k, c)| (k, c.occupied.to_bits()))
            .collect();
        let b: Vec<_> = reference
            .cells()
            .map(|(k, c)| (k, c.occupied.to_bits()))
            .collect();
        assert_eq!(a, b);
    }
}
