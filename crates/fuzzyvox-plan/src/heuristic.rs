//! A* heuristics: lower bounds on the cost from a voxel to the goal through a cost field.
//!
//! The plain bound is the octile distance (the length of the shortest 26-connected route)
//! times the field's least rate. Where the goal lies in expensive space (unknown space that
//! costs more per metre than seen free space, as when a vehicle plans towards a goal it has
//! not seen yet) that bound is loose by the ratio of the rates, and A* expands every voxel
//! whose cost from the start is below the goal's: most of the region. [`GoalProfile`] is
//! tighter there and as cheap to evaluate: it charges each stretch of the remaining distance
//! the least rate of any voxel as near the goal as that stretch, so the last metres through
//! unknown space cost what unknown space costs.

use rayon::prelude::*;

use fuzzyvox_core::storage::VoxelKey;

use crate::cost_field::CostField;

/// Width of a distance bin, in voxel edges.
const BIN: f64 = 0.5;
/// Bins a step may span: every step is at most `√3` voxel edges long, under `SLACK × BIN`.
const SLACK: usize = 4;

/// The octile distance between two voxels in voxel edges: the length of the shortest
/// 26-connected route between them in open space.
#[inline]
pub(crate) fn octile(a: VoxelKey, b: VoxelKey) -> f64 {
    let d = [a.x - b.x, a.y - b.y, a.z - b.z].map(|c| f64::from(c.unsigned_abs()));
    let high = d[0].max(d[1]).max(d[2]);
    let low = d[0].min(d[1]).min(d[2]);
    let mid = d[0] + d[1] + d[2] - high - low;
    (high - mid) + std::f64::consts::SQRT_2 * (mid - low) + 3f64.sqrt() * low
}

/// [`octile`] of the offsets' magnitudes, in single precision (binning only: the bins have
/// [`SLACK`] to spare for its rounding).
#[inline]
fn octile_f32(a: f32, b: f32, c: f32) -> f32 {
    let high = a.max(b).max(c);
    let low = a.min(b).min(c);
    let mid = a + b + c - high - low;
    (high - mid) + std::f32::consts::SQRT_2 * (mid - low) + 1.732_050_8 * low
}

/// A consistent heuristic towards one goal from the field's rates by distance to the goal.
///
/// Let `m(t)` be the least rate of any voxel within octile distance `t + s` of the goal, with
/// `s` at least the longest step (`√3` edges). It never increases with `t`. The heuristic of a
/// voxel at octile distance `d` is `size × ∫₀ᵈ m(t) dt`. It is consistent: a step from `u` to
/// `v` with `d_v < d_u ≤ d_v + l` costs at least `l` times the lower of the two rates, and
/// both voxels lie within `d_v + s` of the goal, so both rates are at least `m(d_v)`, while
/// the heuristic drops by at most `(d_u − d_v) × m(d_v)`. Steps away from the goal raise it.
/// Since `m(t)` is at least the field's least rate, it is never below the plain octile bound.
///
/// Distances are binned (half a voxel edge) and `m` is taken over whole bins, which only
/// lowers it; building the profile reads the rate of every voxel within its reach once.
#[derive(Clone, Debug)]
pub(crate) struct GoalProfile {
    goal: VoxelKey,
    /// Metres per voxel edge.
    size: f64,
    /// Per bin `j`: the rate charged to distances in `[j, j + 1) × BIN`.
    rate: Vec<f64>,
    /// Per bin `j`: the heuristic at distance `j × BIN` in voxel edges times rate.
    start: Vec<f64>,
}

impl GoalProfile {
    /// The profile of `field` around `goal` (a voxel of the field's region), exact within
    /// `reach` voxel edges of the goal; beyond that, distances are charged the field's least
    /// rate (the plain bound), so that a search near the goal reads only the voxels near it.
    pub(crate) fn new(field: &CostField, goal: VoxelKey, reach: f64) -> Self {
        let region = field.region();
        let dims = region.dims();
        let min = region.min();
        // The box of voxels within `reach` of the goal along every axis: it holds every voxel
        // within octile distance `reach` (never less than the largest axis offset), so the
        // bins that end by then are complete.
        let r = reach.max(0.0).ceil() as i64;
        let g = [goal.x - min.x, goal.y - min.y, goal.z - min.z].map(i64::from);
        let lo: [usize; 3] = std::array::from_fn(|a| (g[a] - r).clamp(0, dims[a] as i64) as usize);
        let hi: [usize; 3] =
            std::array::from_fn(|a| (g[a] + r + 1).clamp(0, dims[a] as i64) as usize);
        let complete = (r as f64 / BIN) as usize;
        // Bin `complete` gathers the rest of the box.
        let last = complete as i32;
        let width = hi[0].saturating_sub(lo[0]);
        // Offsets along x, the same for every row.
        let dxs: Vec<f32> = (lo[0]..hi[0])
            .map(|x| (x as i64 - g[0]).abs() as f32)
            .collect();
        // The least rate per bin of distance, one slab of z per task, merged by minimum
        // (exact, so the thread count does not matter). Per row, the bins first (a loop that
        // vectorises), then the minima.
        let least = (lo[2]..hi[2].max(lo[2]))
            .into_par_iter()
            .fold(
                || (vec![f32::INFINITY; complete + 1], vec![0i32; width]),
                |(mut least, mut row_bins), z| {
                    let dz = (z as i64 - g[2]).abs() as f32;
                    for y in lo[1]..hi[1] {
                        let dy = (y as i64 - g[1]).abs() as f32;
                        for (bin, &dx) in row_bins.iter_mut().zip(&dxs) {
                            *bin = ((octile_f32(dx, dy, dz) * (1.0 / BIN as f32)) as i32).min(last);
                        }
                        let rates = field.rates_of_row((z * dims[1] + y) * dims[0] + lo[0], width);
                        for (&bin, rate) in row_bins.iter().zip(rates) {
                            let slot = &mut least[bin as usize];
                            if rate < *slot {
                                *slot = rate;
                            }
                        }
                    }
                    (least, row_bins)
                },
            )
            .map(|(least, _)| least)
            .reduce(
                || vec![f32::INFINITY; complete + 1],
                |a, b| a.iter().zip(&b).map(|(p, q)| p.min(*q)).collect(),
            );
        // m over bin j: the least rate of bins 0 ..= j + SLACK while those are complete, then
        // the field's least rate.
        let floor = field.min_rate();
        let mut rate = Vec::with_capacity(complete + 1);
        let mut running = f32::INFINITY;
        for (j, &l) in least.iter().enumerate() {
            running = running.min(l);
            if j >= SLACK {
                rate.push(f64::from(if running.is_finite() { running } else { floor }));
            }
        }
        rate.truncate(complete.saturating_sub(SLACK));
        rate.push(f64::from(floor));
        let mut start = Vec::with_capacity(rate.len());
        let mut sum = 0.0;
        for &r in &rate {
            start.push(sum);
            sum += BIN * r;
        }
        Self {
            goal,
            size: field.resolution().size(),
            rate,
            start,
        }
    }

    /// The heuristic of `key`: a lower bound on the cost of any route from it to the goal.
    #[inline]
    pub(crate) fn cost_to_goal(&self, key: VoxelKey) -> f32 {
        let d = octile(key, self.goal);
        let j = ((d / BIN) as usize).min(self.rate.len() - 1);
        (self.size * (self.start[j] + (d - j as f64 * BIN) * self.rate[j])) as f32
    }
}

#[cfg(test)]
mod tests {
    use fuzzyvox_core::map::FunctionMap;
    use fuzzyvox_core::measures::Memberships;
    use fuzzyvox_core::storage::Resolution;
    use petgraph::visit::EdgeRef;

    use super::*;
    use crate::config::{PlannerConfig, UnknownPolicy};
    use crate::graph::VoxelGraph;
    use crate::path::plan_in_field;
    use crate::region::PlanningRegion;

    /// A 6 × 4 × 2 m box at 0.1 m: seen free space of varying confidence for x < 2 m, a
    /// pillar, and unknown space (at a cost) beyond.
    fn mixed_field() -> CostField {
        let resolution = Resolution::new(0.1).unwrap();
        let map = FunctionMap::new(resolution, |key| {
            if (12..16).contains(&key.x) && (10..30).contains(&key.y) {
                Memberships {
                    occupied: 0.9,
                    free: 0.0,
                }
            } else if key.x < 20 {
                let wobble = ((key.x * 7 + key.y * 13 + key.z * 5).rem_euclid(11)) as f32;
                Memberships {
                    occupied: 0.0,
                    free: 0.6 + 0.035 * wobble,
                }
            } else {
                Memberships::default()
            }
        });
        let region =
            PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(59, 39, 19)).unwrap();
        let config = PlannerConfig {
            vehicle_radius: 0.1,
            unknown: UnknownPolicy::Cost(2.0),
            ..PlannerConfig::default()
        };
        CostField::build(&map, region, config).unwrap()
    }

    /// Every step between traversable voxels costs at least the drop of the heuristic along
    /// it, the goal's heuristic is 0, and no voxel's is below the plain octile bound: for
    /// goals in unknown space, in seen space and on the region's edge, and for a reach that
    /// covers the region and one that covers a little of it.
    #[test]
    fn the_profile_is_consistent_and_never_below_the_plain_bound() {
        let field = mixed_field();
        let region = *field.region();
        let graph = VoxelGraph::new(&field);
        let size = field.resolution().size() as f32;
        let goals = [
            VoxelKey::new(50, 20, 10),
            VoxelKey::new(5, 5, 5),
            VoxelKey::new(59, 39, 0),
        ];
        for goal in goals {
            for reach in [200.0, 6.0] {
                let profile = GoalProfile::new(&field, goal, reach);
                assert!(profile.cost_to_goal(goal).abs() < 1e-6);
                for index in 0..region.len() {
                    let key = region.key_at(index);
                    let h = profile.cost_to_goal(key);
                    let plain = size * field.min_rate() * octile(key, goal) as f32;
                    assert!(h >= plain * (1.0 - 1e-5), "{key:?}: {h} < {plain}");
                    for edge in graph.edges_from(index as u32) {
                        let next = profile.cost_to_goal(region.key_at(edge.target() as usize));
                        assert!(
                            h <= edge.weight() + next + 1e-4 * (1.0 + h),
                            "goal {goal:?} reach {reach}: {key:?} {h} > {} + {next}",
                            edge.weight()
                        );
                    }
                }
            }
        }
    }

    /// Towards a goal deep in unknown space the profile charges the unknown stretch what it
    /// costs, so A* expands far fewer voxels than with the plain bound, and still finds the
    /// cheapest route (Dijkstra's cost through petgraph).
    #[test]
    fn a_goal_in_unknown_space_is_found_cheaply_and_exactly() {
        let field = mixed_field();
        let (start, goal) = (VoxelKey::new(3, 20, 10), VoxelKey::new(55, 20, 10));
        let path = plan_in_field(&field, start, goal).unwrap();
        let graph = VoxelGraph::new(&field);
        let (s, g) = (graph.node(start).unwrap(), graph.node(goal).unwrap());
        let costs = petgraph::algo::dijkstra(&graph, s, Some(g), |e| *e.weight());
        let best = f64::from(costs[&g]);
        assert!(
            (path.cost - best).abs() < 1e-4 * best,
            "{} vs {best}",
            path.cost
        );
        let profile = GoalProfile::new(&field, goal, 200.0);
        let plain =
            field.resolution().size() as f32 * field.min_rate() * octile(start, goal) as f32;
        let h = profile.cost_to_goal(start);
        assert!(h > 1.5 * plain, "profile {h} vs plain {plain}");
        assert!(f64::from(h) <= best * (1.0 + 1e-5));
        // The plain bound lets A* expand far more on the way.
        let region = field.region();
        let index = |key| region.index_of(key).unwrap();
        let scale = field.resolution().size() as f32 * field.min_rate();
        let plain = crate::astar::astar(
            &field,
            index(start),
            index(goal),
            |key| scale * octile(key, goal) as f32,
            &|_| false,
            usize::MAX,
        )
        .unwrap();
        assert!((plain.cost - path.cost as f32).abs() < 1e-4 * plain.cost);
        assert!(
            path.expanded * 2 < plain.expanded,
            "A* expanded {} voxels with the profile, {} with the plain bound",
            path.expanded,
            plain.expanded
        );
    }
}
