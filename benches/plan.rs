//! Planning speed: a cross-region query through a 200 × 200 × 40 voxel region with pillars,
//! fuzzyvox's planner beside the `pathfinding` crate's A* on the same graph and costs, with the
//! plain octile bound as its heuristic (fuzzyvox's goal profile is never below it).
//!
//! Run: `cargo bench --bench plan`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{Criterion, criterion_group, criterion_main};
use fuzzyvox::map::FunctionMap;
use fuzzyvox::plan::{CostField, PlannerConfig, PlanningRegion, VoxelGraph, plan_in_field};
use fuzzyvox::{Memberships, Resolution, VoxelKey};
use ordered_float::OrderedFloat;
use petgraph::visit::{EdgeRef, IntoEdges};

/// Whether a trunk of radius 0.3 m stands at `(x, y)` in a forest on a jittered grid of
/// `spacing` metres (about four in five grid points hold a trunk).
fn trunk_at(x: f64, y: f64, spacing: f64) -> bool {
    let g = spacing;
    let (cx, cy) = ((x / g).round(), (y / g).round());
    let hash = ((cx as i64 * 73_856_093) ^ (cy as i64 * 19_349_663)).rem_euclid(97) as f64;
    let jitter = 0.4 * g;
    let (px, py) = (
        cx * g + (hash / 97.0 - 0.5) * jitter,
        cy * g + ((hash * 7.0) % 97.0 / 97.0 - 0.5) * jitter,
    );
    hash > 20.0 && (x - px).hypot(y - py) < 0.3
}

fn cross_region(c: &mut Criterion) {
    for (name, spacing) in [("trees_3m", 3.0), ("dense_trees_1.5m", 1.5)] {
        bench_forest(c, name, spacing);
    }
}

fn bench_forest(c: &mut Criterion, name: &str, spacing: f64) {
    // A 20 × 20 × 4 m forest at 0.1 m: free space (μE = 0.9) between the trunks.
    let resolution = Resolution::new(0.1).unwrap();
    let forest = FunctionMap::new(resolution, move |key| {
        let c = resolution.center(key);
        if trunk_at(c.x, c.y, spacing) {
            Memberships {
                occupied: 0.9,
                free: 0.0,
            }
        } else {
            Memberships {
                occupied: 0.0,
                free: 0.9,
            }
        }
    });
    let region = PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(199, 199, 39)).unwrap();
    let config = PlannerConfig {
        vehicle_radius: 0.2,
        ..PlannerConfig::default()
    };
    let field = CostField::build(&forest, region, config).unwrap();
    // The traversable voxels nearest to two opposite corners (the pillars may stand there).
    let free_near = |x: i32, y: i32, step: i32| {
        (0..40)
            .flat_map(|d| {
                [
                    VoxelKey::new(x + step * d, y, 20),
                    VoxelKey::new(x, y + step * d, 20),
                ]
            })
            .find(|k| field.is_traversable(field.region().index_of(*k).unwrap()))
            .expect("free space near the corner")
    };
    let (start, goal) = (free_near(5, 5, 1), free_near(194, 194, -1));
    let ours = plan_in_field(&field, start, goal).expect("a path through the forest");
    eprintln!(
        "{name}: fuzzyvox: cost {:.3}, length {:.2} m, {} waypoints, {} voxels expanded",
        ours.cost,
        ours.length,
        ours.waypoints.len(),
        ours.expanded
    );
    let graph = VoxelGraph::new(&field);
    // The plain consistent heuristic: octile metres times the lowest rate.
    let size = field.resolution().size() as f32 * field.min_rate();
    let (s, g) = (graph.node(start).unwrap(), graph.node(goal).unwrap());
    let heuristic = move |n: &u32| {
        let k = graph.key(*n);
        let mut d = [
            (k.x - goal.x).unsigned_abs() as f32,
            (k.y - goal.y).unsigned_abs() as f32,
            (k.z - goal.z).unsigned_abs() as f32,
        ];
        d.sort_unstable_by(|a, b| b.total_cmp(a));
        OrderedFloat(
            size * ((d[0] - d[1]) + std::f32::consts::SQRT_2 * (d[1] - d[2]) + 1.732_050_8 * d[2]),
        )
    };
    let successors = move |n: &u32| {
        graph
            .edges(*n)
            .map(|e| (e.target(), OrderedFloat(*e.weight())))
            .collect::<Vec<_>>()
    };
    let (_, theirs) = pathfinding::prelude::astar(&s, successors, heuristic, |n| *n == g).unwrap();
    eprintln!("{name}: pathfinding: cost {:.3}", theirs.0);

    let mut group = c.benchmark_group(format!("plan_200x200x40_{name}"));
    group.sample_size(20);
    group.bench_function("fuzzyvox_astar_and_shortcut", |b| {
        b.iter(|| plan_in_field(&field, start, goal).unwrap())
    });
    group.bench_function("pathfinding_astar", |b| {
        b.iter(|| pathfinding::prelude::astar(&s, successors, heuristic, |n| *n == g).unwrap())
    });
    group.finish();
}

criterion_group!(benches, cross_region);
criterion_main!(benches);
