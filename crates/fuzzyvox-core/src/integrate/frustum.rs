use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::depth_image::{DepthFrame, IntervalDepthImage, PixelInterval};
use super::evidence::{
    Evidence, EvidenceKind, EvidenceModel, IntegrationOptions, IntegrationStats, ScanEvidence,
};
use super::footprint::FootprintFill;
use crate::error::{Error, Result};
use crate::ops::TConorm;
use crate::storage::{
    AccessorMut, BLOCK_CELLS, BLOCK_SIDE, Block, BlockKey, KeyBox, Resolution, VoxelKey,
};

/// Largest frustum bounding box, in blocks, that one depth image may span (a guard against
/// absurd depths; ordinary frames span thousands).
const MAX_FRUSTUM_BLOCKS: u128 = 1 << 26;

/// Side of the square pixel tiles whose largest far depth culls blocks.
const TILE: u32 = 8;

/// Blocks per side of the groups culled before their blocks.
const GROUP: i32 = 8;

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
            camera
                .block_evidence(key, &pixels, fill.as_ref(), model, operator, half_diagonal)
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
fn mark_end_points(
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

/// Every pixel's evidence that does not depend on the voxel, in parallel.
fn pixel_evidence(
    image: &IntervalDepthImage,
    model: &EvidenceModel,
    operator: &TConorm,
    max_range: f32,
    delta: f32,
) -> Vec<PixelEvidence> {
    (0..image.depth().len())
        .into_par_iter()
        .map(|i| PixelEvidence::of(image, i, model, operator, max_range, delta))
        .collect()
}

/// What one pixel contributes, packed into 32 aligned bytes: voxels look their pixel up at
/// random, and one record per half cache line keeps those reads to one line each. An invalid
/// pixel is [`PixelEvidence::NONE`], whose reach is below every depth.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct PixelEvidence {
    /// Voxels with `z` below this get the full free evidence (`ψ = 1`).
    free_until: f32,
    /// Voxels with `z` from `free_until` up to this get free evidence graded by the profile
    /// `ψ` (the dual model; equal to `free_until` in the paper's model).
    free_end: f32,
    /// Voxels with `z` up to this can get evidence.
    reach: f32,
    /// `P0`.
    depth: f32,
    /// Peak of the occupied kernel, `(2δ / (P+ - P- + 2δ))^falloff`; 0 for a pixel that only
    /// clears (beyond the maximum range, or without a confidence in the dual model).
    height: f32,
    /// Free evidence where `ψ = 1`.
    free: f32,
    /// Weight of the free evidence before the profile (confidence or reliability).
    free_weight: f32,
    /// The pixel's confidence (weight of its occupied evidence).
    confidence: f32,
}

impl PixelEvidence {
    const NONE: Self = Self {
        free_until: f32::NEG_INFINITY,
        free_end: f32::NEG_INFINITY,
        reach: f32::NEG_INFINITY,
        depth: 0.0,
        height: 0.0,
        free: 0.0,
        free_weight: 0.0,
        confidence: 0.0,
    };

    /// The pixel's evidence under `model`, or [`PixelEvidence::NONE`] when it gives none.
    fn of(
        image: &IntervalDepthImage,
        index: usize,
        model: &EvidenceModel,
        operator: &TConorm,
        max_range: f32,
        delta: f32,
    ) -> Self {
        let pixel = match model.kind {
            EvidenceKind::Paper => image.pixel(index),
            EvidenceKind::Dual => image.dual_pixel(index),
        };
        pixel.map_or(Self::NONE, |p| {
            Self::new(p, model, operator, max_range, delta)
        })
    }

    fn new(
        interval: PixelInterval,
        model: &EvidenceModel,
        operator: &TConorm,
        max_range: f32,
        delta: f32,
    ) -> Self {
        let beyond_range = interval.depth > max_range;
        let free_weight = model.free_weight(interval.confidence, interval.reliability);
        let free = model.free(operator, free_weight);
        if model.kind == EvidenceKind::Paper {
            let share = 2.0 * delta / (interval.far - interval.near + 2.0 * delta);
            let height = match model.interval_falloff {
                _ if beyond_range => 0.0,
                1.0 => share,
                0.0 => 1.0,
                falloff => share.powf(falloff),
            };
            let (free_until, reach) = if beyond_range {
                (max_range, max_range)
            } else {
                (interval.near - delta, interval.far + delta)
            };
            return Self {
                free_until,
                free_end: free_until,
                reach,
                depth: interval.depth,
                height,
                free,
                free_weight,
                confidence: interval.confidence,
            };
        }
        // Dual: ψ = 1 up to P- - δ, then falls linearly to 0 at the reach's end - δ; free
        // space never goes past the maximum range.
        let graded_end = interval.near + model.free_reach * (interval.depth - interval.near);
        let free_until = (interval.near - delta).min(max_range);
        let free_end = (graded_end - delta).min(max_range).max(free_until);
        let occupies = !beyond_range && interval.confidence > 0.0 && interval.far.is_finite();
        let height = if occupies {
            let share = 2.0 * delta / (interval.far - interval.near + 2.0 * delta);
            match model.interval_falloff {
                1.0 => share,
                0.0 => 1.0,
                falloff => share.powf(falloff),
            }
        } else {
            0.0
        };
        Self {
            free_until,
            free_end,
            reach: if occupies {
                (interval.far + delta).max(free_end)
            } else {
                free_end
            },
            depth: interval.depth,
            height,
            free,
            free_weight,
            confidence: interval.confidence,
        }
    }

    fn is_valid(&self) -> bool {
        self.reach > f32::NEG_INFINITY
    }

    /// Evidence for a voxel whose centre lies at depth `z` on this pixel.
    #[inline]
    fn at(
        &self,
        z: f32,
        model: &EvidenceModel,
        operator: &TConorm,
        delta: f32,
    ) -> Option<Evidence> {
        if z < self.free_until {
            return Some(Evidence {
                occupied: 0.0,
                free: self.free,
            });
        }
        if z > self.reach {
            return None;
        }
        let free = if z < self.free_end {
            let psi = (self.free_end - z) / (self.free_end - self.free_until);
            model.free(operator, self.free_weight * psi)
        } else {
            0.0
        };
        let occupied = if self.height > 0.0 {
            // The kernel spans `P- - δ` (where full free evidence ends) to the reach.
            let (low, high) = (self.free_until, self.reach);
            let shape = if (z - self.depth).abs() <= delta {
                1.0
            } else if z < self.depth {
                (z - low) / (self.depth - delta - low)
            } else {
                (high - z) / (high - (self.depth + delta))
            };
            let phi = (self.height * shape).clamp(0.0, 1.0);
            if phi > 0.0 {
                model.occupied(operator, self.confidence, phi)
            } else {
                0.0
            }
        } else {
            0.0
        };
        (occupied > 0.0 || free > 0.0).then_some(Evidence { occupied, free })
    }
}

/// The largest reach (far depth + δ, or max range) over square pixel tiles.
struct TileReach {
    columns: u32,
    rows: u32,
    reach: Vec<f32>,
    max_reach: f32,
}

impl TileReach {
    /// With `fill`, a pixel without evidence reaches as far as its footprint's fill can.
    fn new(
        pixels: &[PixelEvidence],
        fill: Option<&FootprintFill>,
        width: u32,
        height: u32,
    ) -> Self {
        let columns = width.div_ceil(TILE);
        let rows = height.div_ceil(TILE);
        let mut reach = vec![f32::NEG_INFINITY; (columns * rows) as usize];
        for (i, p) in pixels.iter().enumerate() {
            let (x, y) = (i as u32 % width, i as u32 / width);
            let t = ((y / TILE) * columns + x / TILE) as usize;
            let r = match fill {
                Some(fill) if !p.is_valid() => fill.reach(i),
                _ => p.reach,
            };
            reach[t] = reach[t].max(r);
        }
        let max_reach = reach.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        Self {
            columns,
            rows,
            reach,
            max_reach,
        }
    }

    /// Largest reach over the pixel rectangle `[u0, u1] × [v0, v1]` (inclusive).
    fn max_over(&self, u0: u32, u1: u32, v0: u32, v1: u32) -> f32 {
        let mut best = f32::NEG_INFINITY;
        for ty in (v0 / TILE)..=(v1 / TILE).min(self.rows - 1) {
            for tx in (u0 / TILE)..=(u1 / TILE).min(self.columns - 1) {
                best = best.max(self.reach[(ty * self.columns + tx) as usize]);
            }
        }
        best
    }
}

/// The frustum as a convex solid: the camera centre and the image's four corner rays cut at
/// the largest reach, in the camera frame. [`Pyramid::may_meet_cube`] is an exact
/// separating-axis test against a cube (face normals of both and the cross products of their
/// edges), so it drops only cubes that share no point with the frustum; every voxel that can
/// receive evidence lies inside it. It is what culls blocks beside a thin, grazing frustum
/// (a camera whose principal point lies far off its image), where the four side planes are
/// nearly one plane and the per-plane tests keep a whole sheet of blocks.
struct Pyramid {
    axes: Vec<SeparatingAxis>,
}

/// A candidate separating axis with the frustum's extent along it.
struct SeparatingAxis {
    /// Unit direction, in the camera frame.
    direction: Vector3<f64>,
    /// The frustum's lowest and highest projection on it.
    low: f64,
    high: f64,
    /// A cube's half extent along it per unit of its half side: the sum of `|direction · e|`
    /// over the cube's edge directions `e`.
    spread: f64,
}

impl Pyramid {
    fn new(view: &CameraView, reach: f64) -> Self {
        let (w, h) = (f64::from(view.width), f64::from(view.height));
        let corner = |u: f64, v: f64| {
            Vector3::new(
                (u - view.cx) / view.fx * reach,
                (v - view.cy) / view.fy * reach,
                reach,
            )
        };
        let far = [
            corner(-0.5, -0.5),
            corner(w - 0.5, -0.5),
            corner(w - 0.5, h - 0.5),
            corner(-0.5, h - 0.5),
        ];
        let vertices = [Vector3::zeros(), far[0], far[1], far[2], far[3]];
        let cube = [0, 1, 2].map(|k| view.camera_from_world.column(k).into_owned());
        let mut candidates: Vec<Vector3<f64>> = cube.to_vec();
        candidates.extend(view.sides);
        candidates.push(Vector3::z());
        let edges = [far[0], far[1], far[2], far[3], Vector3::x(), Vector3::y()];
        for edge in edges {
            for a in &cube {
                candidates.push(edge.cross(a));
            }
        }
        let axes = candidates
            .into_iter()
            .filter_map(|axis| {
                let norm = axis.norm();
                (norm.is_finite() && norm > 1e-12).then(|| axis / norm)
            })
            .filter_map(|axis| {
                let along = vertices.map(|v| axis.dot(&v));
                let low = along.iter().copied().fold(f64::INFINITY, f64::min);
                let high = along.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let spread: f64 = cube.iter().map(|a| axis.dot(a).abs()).sum();
                // An axis whose extent overflowed separates nothing reliably: leave it out, so
                // the test stays conservative.
                (low.is_finite() && high.is_finite() && spread.is_finite()).then_some(
                    SeparatingAxis {
                        direction: axis,
                        low,
                        high,
                        spread,
                    },
                )
            })
            .collect();
        Self { axes }
    }

    /// Whether the cube with lowest corner `corner` (world) and edge `side` may share a point
    /// with the frustum; `false` only when an axis separates them by more than a rounding
    /// margin.
    fn may_meet_cube(&self, view: &CameraView, corner: Point3<f64>, side: f64) -> bool {
        let center = view.to_camera(&(corner + Vector3::repeat(0.5 * side)));
        self.axes.iter().all(|axis| {
            let at = axis.direction.dot(&center);
            let half = 0.5 * side * axis.spread;
            let margin = 1e-9 * (at.abs() + half + axis.low.abs() + axis.high.abs()) + 1e-9;
            at - half <= axis.high + margin && at + half >= axis.low - margin
        })
    }
}

/// The camera as seen from the voxel grid: everything needed to project voxel centres.
struct CameraView {
    camera_from_world: Matrix3<f64>,
    camera_in_world: Vector3<f64>,
    /// Inward unit normals of the four planes through the camera centre that bound the image
    /// (`u >= -0.5`, `u <= w - 0.5`, `v >= -0.5`, `v <= h - 0.5`), in the camera frame.
    sides: [Vector3<f64>; 4],
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    width: u32,
    height: u32,
    resolution: Resolution,
}

impl CameraView {
    fn new(frame: &DepthFrame, resolution: &Resolution) -> Self {
        let pose = frame.world_from_camera();
        let k = frame.intrinsics();
        let (w, h) = (f64::from(k.width()), f64::from(k.height()));
        let sides = [
            Vector3::new(k.fx(), 0.0, k.cx() + 0.5),
            Vector3::new(-k.fx(), 0.0, w - 0.5 - k.cx()),
            Vector3::new(0.0, k.fy(), k.cy() + 0.5),
            Vector3::new(0.0, -k.fy(), h - 0.5 - k.cy()),
        ]
        .map(|n| n.normalize());
        Self {
            camera_from_world: pose.rotation.to_rotation_matrix().matrix().transpose(),
            camera_in_world: pose.translation.vector,
            sides,
            fx: k.fx(),
            fy: k.fy(),
            cx: k.cx(),
            cy: k.cy(),
            width: k.width(),
            height: k.height(),
            resolution: *resolution,
        }
    }

    fn to_camera(&self, p: &Point3<f64>) -> Vector3<f64> {
        self.camera_from_world * (p.coords - self.camera_in_world)
    }

    /// The blocks of `frustum` that may be observed, in the box's order (z slowest), culled
    /// first by groups of [`GROUP`]³ blocks: a frustum whose bounding box is mostly empty (a
    /// wide, skewed or far-reaching camera) costs one test per group, not one per block. The
    /// test is conservative for any cube, so a culled group holds no observable block and the
    /// result is the same as testing every block.
    fn observed_blocks(&self, frustum: &KeyBox, tiles: &TileReach) -> Vec<BlockKey> {
        let (lo, hi) = frustum.block_bounds();
        let group_side = f64::from(GROUP) * BLOCK_SIDE as f64 * self.resolution.size();
        let groups = |lo: i32, hi: i32| lo.div_euclid(GROUP)..=hi.div_euclid(GROUP);
        let within =
            |g: i32, lo: i32, hi: i32| (g * GROUP).max(lo)..=(g * GROUP + GROUP - 1).min(hi);
        let pyramid = Pyramid::new(self, f64::from(tiles.max_reach));
        let block_side = BLOCK_SIDE as f64 * self.resolution.size();
        let mut blocks = Vec::new();
        for gz in groups(lo.z, hi.z) {
            for gy in groups(lo.y, hi.y) {
                for gx in groups(lo.x, hi.x) {
                    let first = BlockKey::new(gx * GROUP, gy * GROUP, gz * GROUP);
                    let corner = self.resolution.corner(first.origin());
                    if !self.cube_may_be_observed(corner, group_side, tiles)
                        || !pyramid.may_meet_cube(self, corner, group_side)
                    {
                        continue;
                    }
                    for z in within(gz, lo.z, hi.z) {
                        for y in within(gy, lo.y, hi.y) {
                            for x in within(gx, lo.x, hi.x) {
                                let key = BlockKey::new(x, y, z);
                                let corner = self.resolution.corner(key.origin());
                                if self.block_may_be_observed(key, tiles)
                                    && pyramid.may_meet_cube(self, corner, block_side)
                                {
                                    blocks.push(key);
                                }
                            }
                        }
                    }
                }
            }
        }
        blocks.sort_unstable_by_key(|k| (k.z, k.y, k.x));
        blocks
    }

    /// Whether any voxel of the block could lie in front of some pixel's reach (conservative).
    fn block_may_be_observed(&self, key: BlockKey, tiles: &TileReach) -> bool {
        let side = BLOCK_SIDE as f64 * self.resolution.size();
        self.cube_may_be_observed(self.resolution.corner(key.origin()), side, tiles)
    }

    /// Whether any point of the cube with lowest corner `corner` (world) and edge `side` could
    /// lie in front of some pixel's reach (conservative: tests the cube's bounding sphere).
    fn cube_may_be_observed(&self, corner: Point3<f64>, side: f64, tiles: &TileReach) -> bool {
        let center = self.to_camera(&(corner + Vector3::repeat(0.5 * side)));
        let radius = 0.5 * 3f64.sqrt() * side;
        if center.z + radius <= 0.0 {
            return false;
        }
        // Wholly outside one of the planes that bound the image: no pixel sees it. This also
        // culls cubes that straddle the camera plane beside the frustum.
        let margin = radius * (1.0 + 1e-9) + 1e-9;
        if self.sides.iter().any(|n| n.dot(&center) < -margin) {
            return false;
        }
        let near = center.z - radius;
        if near >= f64::from(tiles.max_reach) {
            return false;
        }
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let (u0, u1, v0, v1) = if near <= 1e-6 {
            // The block straddles the camera plane: it may project anywhere.
            (0.0, w - 1.0, 0.0, h - 1.0)
        } else {
            let far = center.z + radius;
            let xs = [
                (center.x - radius) / near,
                (center.x - radius) / far,
                (center.x + radius) / near,
                (center.x + radius) / far,
            ];
            let ys = [
                (center.y - radius) / near,
                (center.y - radius) / far,
                (center.y + radius) / near,
                (center.y + radius) / far,
            ];
            let min = |v: [f64; 4]| v.into_iter().fold(f64::INFINITY, f64::min);
            let max = |v: [f64; 4]| v.into_iter().fold(f64::NEG_INFINITY, f64::max);
            (
                (self.fx * min(xs) + self.cx - 0.5).floor().max(0.0),
                (self.fx * max(xs) + self.cx + 0.5).ceil().min(w - 1.0),
                (self.fy * min(ys) + self.cy - 0.5).floor().max(0.0),
                (self.fy * max(ys) + self.cy + 0.5).ceil().min(h - 1.0),
            )
        };
        if u0 > u1 || v0 > v1 {
            return false;
        }
        let reach = tiles.max_over(u0 as u32, u1 as u32, v0 as u32, v1 as u32);
        near < f64::from(reach)
    }

    /// Evidence for one block's voxels, or `None` when no voxel received any.
    fn block_evidence(
        &self,
        key: BlockKey,
        pixels: &[PixelEvidence],
        fill: Option<&FootprintFill>,
        model: &EvidenceModel,
        operator: &TConorm,
        delta: f32,
    ) -> Option<Box<Block<Evidence>>> {
        // A voxel's footprint radius in pixels is `fx δ / z`.
        let footprint = (self.fx.max(self.fy) as f32) * delta;
        let size = self.resolution.size();
        let first = self.to_camera(&self.resolution.center(key.origin()));
        let step_x = self.camera_from_world.column(0) * size;
        let step_y = self.camera_from_world.column(1) * size;
        let step_z = self.camera_from_world.column(2) * size;
        let mut block: Option<Box<Block<Evidence>>> = None;
        for cell in 0..BLOCK_CELLS {
            let (i, j, l) = (cell % 8, (cell / 8) % 8, cell / 64);
            let p = first + step_x * i as f64 + step_y * j as f64 + step_z * l as f64;
            if p.z <= 0.0 {
                continue;
            }
            let u = (self.fx * p.x / p.z + self.cx + 0.5).floor();
            let v = (self.fy * p.y / p.z + self.cy + 0.5).floor();
            if !(u >= 0.0 && v >= 0.0 && u < f64::from(self.width) && v < f64::from(self.height)) {
                continue;
            }
            let index = v as usize * self.width as usize + u as usize;
            let z = p.z as f32;
            let pixel = &pixels[index];
            let evidence = match fill {
                Some(fill) if !pixel.is_valid() => fill
                    .lookup(index, footprint / z)
                    .filter(|&(bound, _)| z < bound)
                    .map(|(_, weight)| Evidence {
                        occupied: 0.0,
                        free: model.free(operator, weight),
                    }),
                _ => pixel.at(z, model, operator, delta),
            };
            if let Some(e) = evidence {
                block.get_or_insert_with(Box::default).cells[cell] = e;
            }
        }
        block
    }
}

/// The voxel box around the camera centre and the image corners pushed out to `reach`.
fn frustum_box(frame: &DepthFrame, resolution: &Resolution, reach: f32) -> Result<KeyBox> {
    let k = frame.intrinsics();
    let pose = frame.world_from_camera();
    let z = f64::from(reach);
    let (w, h) = (f64::from(k.width()), f64::from(k.height()));
    let mut lo = pose.translation.vector;
    let mut hi = lo;
    for (u, v) in [
        (-0.5, -0.5),
        (w - 0.5, -0.5),
        (-0.5, h - 0.5),
        (w - 0.5, h - 0.5),
    ] {
        let corner = pose * k.back_project(u, v, z);
        lo = lo.inf(&corner.coords);
        hi = hi.sup(&corner.coords);
    }
    KeyBox::from_points(resolution, &Point3::from(lo), &Point3::from(hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PinholeIntrinsics;
    use crate::integrate::IntervalDepthImage;
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
                let evidence =
                    camera.block_evidence(key, &pixels, None, &model, &operator, half_diagonal);
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
