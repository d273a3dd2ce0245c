//! Culling: which blocks of the frustum's bounding box may receive evidence. Groups of blocks,
//! then blocks, are tested against the image's side planes and the tiles' reach
//! ([`CameraView::observed_blocks`]) and against the frustum as a convex solid ([`Pyramid`]).

use nalgebra::{Point3, Vector3};

use super::camera::CameraView;
use super::tiles::TileReach;
use crate::error::Result;
use crate::integrate::depth_image::DepthFrame;
use crate::storage::{BLOCK_SIDE, BlockKey, KeyBox, Resolution};

/// Blocks per side of the groups culled before their blocks.
const GROUP: i32 = 8;

/// The voxel box around the camera centre and the image corners pushed out to `reach`.
pub(super) fn frustum_box(
    frame: &DepthFrame,
    resolution: &Resolution,
    reach: f32,
) -> Result<KeyBox> {
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

impl CameraView {
    /// The blocks of `frustum` that may be observed, in the box's order (z slowest), culled
    /// first by groups of [`GROUP`]³ blocks: a frustum whose bounding box is mostly empty (a
    /// wide, skewed or far-reaching camera) costs one test per group, not one per block. The
    /// test is conservative for any cube, so a culled group holds no observable block and the
    /// result is the same as testing every block.
    pub(super) fn observed_blocks(&self, frustum: &KeyBox, tiles: &TileReach) -> Vec<BlockKey> {
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
}
