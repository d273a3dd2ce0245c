//! A* over a cost field's 26-connected voxels, with dense per-voxel arrays and the caller's
//! heuristic. It walks the same graph as [`VoxelGraph`](crate::VoxelGraph) (whose edges
//! petgraph's algorithms see, and `tests/plan.rs` checks that both agree), but steps to the 26
//! neighbours by fixed index offsets from the expanded voxel's coordinates (one division per
//! expansion, none per neighbour, and no bounds test away from the region's faces).

use dary_heap::QuaternaryHeap;
use std::cmp::Reverse;

use fuzzyvox_core::storage::VoxelKey;

use crate::cost_field::CostField;
use crate::graph::NEIGHBOURS;

/// A route A* found.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Route {
    /// The nodes from start to goal, both included.
    pub(crate) nodes: Vec<usize>,
    /// The summed edge weights from start to goal.
    pub(crate) cost: f32,
    /// Nodes expanded.
    pub(crate) expanded: usize,
}

/// A* from `start` to `goal` (dense indices) through the traversable voxels of `field`, never
/// entering a voxel for which `avoid` is true (the start is never tested). A step of length
/// `l` costs `l × (r₁ + r₂) / 2` ([`VoxelGraph`](crate::VoxelGraph)'s edge weight).
/// `heuristic` must be consistent: the first time a voxel is expanded its cost is final. Ties
/// in the open set are broken by index, so the result is deterministic.
///
/// Expands at most `limit` voxels. Returns the route, or why there is none.
pub(crate) fn astar<H, A>(
    field: &CostField,
    start: usize,
    goal: usize,
    heuristic: H,
    avoid: &A,
    limit: usize,
) -> Result<Route, Unreached>
where
    H: Fn(VoxelKey) -> f32,
    A: Fn(usize) -> bool + ?Sized,
{
    let region = field.region();
    let n = region.len();
    let [nx, ny, nz] = region.dims();
    let min = region.min();
    let size = field.resolution().size() as f32;
    // Per neighbour: index offset, coordinate offset, and half the step's length in metres.
    let steps: [(isize, [i32; 3], f32); 26] = NEIGHBOURS.map(|([dx, dy, dz], length)| {
        let offset = dx as isize + nx as isize * (dy as isize + ny as isize * dz as isize);
        (offset, [dx, dy, dz], length * size * 0.5)
    });
    // Per voxel: its state (bit 7 closed, bit 6 reached, bits 0-4 the step from its parent)
    // and its cost from the start once reached. Both start zeroed: the pages are the system's
    // zeroed ones, and only those the search touches are ever written, so a short search
    // costs little however large the region.
    let mut state = vec![0u8; n];
    let mut cost = vec![0.0f32; n];
    let key_at =
        |[x, y, z]: [i64; 3]| VoxelKey::new(min.x + x as i32, min.y + y as i32, min.z + z as i32);
    let mut open = QuaternaryHeap::new();
    state[start] = REACHED;
    open.push(Reverse(open_key(
        heuristic(region.key_at(start)),
        start as u32,
    )));
    let mut expanded = 0;
    while let Some(Reverse(key)) = open.pop() {
        let node = key as u32 as usize;
        if state[node] & CLOSED != 0 {
            continue;
        }
        if expanded == limit {
            return Err(Unreached::Limit);
        }
        state[node] |= CLOSED;
        expanded += 1;
        if node == goal {
            break;
        }
        let rate = field.rate(node);
        if !rate.is_finite() {
            // Not traversable (only the start can be): no edges leave it.
            continue;
        }
        let g = cost[node];
        let (x, y, z) = (node % nx, (node / nx) % ny, node / (nx * ny));
        let inside = x > 0 && y > 0 && z > 0 && x + 1 < nx && y + 1 < ny && z + 1 < nz;
        for (direction, &(offset, [dx, dy, dz], half)) in steps.iter().enumerate() {
            let to = [
                x as i64 + i64::from(dx),
                y as i64 + i64::from(dy),
                z as i64 + i64::from(dz),
            ];
            if !inside && (0..3).any(|a| to[a] < 0 || to[a] >= [nx, ny, nz][a] as i64) {
                continue;
            }
            let target = node.wrapping_add_signed(offset);
            let seen = state[target];
            if seen & CLOSED != 0 {
                continue;
            }
            let next = field.rate(target);
            if !next.is_finite() || avoid(target) {
                continue;
            }
            let candidate = g + half * (rate + next);
            if seen & REACHED == 0 || candidate < cost[target] {
                state[target] = REACHED | direction as u8;
                cost[target] = candidate;
                let f = candidate + heuristic(key_at(to));
                open.push(Reverse(open_key(f, target as u32)));
            }
        }
    }
    if state[goal] & CLOSED == 0 {
        return Err(Unreached::Disconnected { expanded });
    }
    let mut route = vec![goal];
    let mut node = goal;
    while node != start {
        let (offset, _, _) = steps[usize::from(state[node] & STEP)];
        node = node.wrapping_add_signed(-offset);
        route.push(node);
    }
    route.reverse();
    Ok(Route {
        nodes: route,
        cost: cost[goal],
        expanded,
    })
}

/// Why A* found no route.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Unreached {
    /// Every voxel reachable from the start was expanded (this many).
    Disconnected {
        /// Voxels expanded.
        expanded: usize,
    },
    /// The search stopped at its limit of expanded voxels.
    Limit,
}

/// A voxel's search state: expanded, reached, and (low bits) the step that reached it.
const CLOSED: u8 = 0x80;
const REACHED: u8 = 0x40;
const STEP: u8 = 0x1f;

/// The open set's key of a voxel with estimated total cost `f` (never negative): `f`'s bits
/// above the index, so that one integer comparison orders by `f`, then by index (the bits of
/// non-negative floats order as the floats do).
#[inline]
fn open_key(f: f32, node: u32) -> u64 {
    (u64::from(f.to_bits()) << 32) | u64::from(node)
}
