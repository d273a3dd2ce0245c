//! One cycle of the closed loop at 320 × 240, and the cost field's incremental update beside a
//! full rebuild of the same field.
//!
//! A vehicle flies the first goal of the random scenario (seed 3) for a few frames; from that
//! state, each measured iteration is the vehicle's work on its next frame ([`Flight::see`]:
//! depth stage, integration, cost-field update, path check or replanning), on a fresh copy of
//! the state. Rendering the frame (the simulator's work) is outside the measured loop.
//! `field/update_after_one_frame` updates the planner's field after that frame;
//! `field/update_and_path_check_after_one_frame` updates it and checks that the path flown so
//! far is still clear (what a frame that keeps its path does; the bench prints whether the
//! measured frame does);
//! `field/update_and_astar_after_one_frame` updates it and plans from scratch (A*) from the
//! vehicle's position to its goal (what a frame whose path is blocked does);
//! `field/full_rebuild` builds the same field from scratch.
//!
//! Run: `cargo bench --bench fly`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use fuzzyvox::MapKind;
use fuzzyvox::eval::QueryConfig;
use fuzzyvox::eval::closed_loop::draw_goals;
use fuzzyvox::fly::{Flight, FlyConfig, integrate_prior};
use fuzzyvox::plan::CostField;
use fuzzyvox::sim::scenario;

/// Frames flown before the measured one: far enough that the map holds several depth images.
const WARM_UP_CYCLES: usize = 6;

fn cycle(c: &mut Criterion) {
    let scenario = scenario::random(10, 3).expect("scenario");
    let config = FlyConfig::default();
    let queries = QueryConfig::closed_loop(1, 3, config.planner);
    let goal = draw_goals(&scenario, &config, &queries).expect("goals")[0];
    for model in [MapKind::Fuzzy, MapKind::LogOdds] {
        let mut map = model.new_map(config.resolution).expect("map");
        integrate_prior(&scenario, &mut map, &goal.from, &config).expect("prior");
        let mut flight =
            Flight::new(&scenario, &goal.from, &goal.to, &map, &config, 3).expect("flight");
        for _ in 0..WARM_UP_CYCLES {
            flight.cycle(&mut map).expect("cycle");
        }
        assert!(flight.ending().is_none(), "the flight ended during warm-up");
        let frame = flight.clone().render().expect("frame");
        // The state after the measured frame, for the field benchmarks.
        let (mut after, mut seen) = (flight.clone(), map.clone());
        after.see(frame.clone(), &mut seen).expect("see");

        // The replan's endpoints: the vehicle's voxel and the goal's.
        let resolution = after.planner().field().resolution();
        let start = resolution.key_of(&after.position()).expect("start key");
        let target = resolution.key_of(&goal.to).expect("goal key");
        let path = flight
            .path()
            .expect("a path before the measured frame")
            .to_vec();
        {
            let mut planner = flight.planner().clone();
            planner.update(seen.as_map());
            let keeps = planner.is_clear(&path);
            eprintln!(
                "{}: the measured frame {} its path",
                model.name(),
                if keeps { "keeps" } else { "replans" }
            );
            planner
                .plan(start, target)
                .expect("the measured replan finds a path");
        }

        let mut group = c.benchmark_group(format!("fly_320x240_{}", model.name()));
        group.sample_size(20);
        group.bench_function("cycle", |b| {
            // `_ref`: the copies are dropped outside the measured time.
            b.iter_batched_ref(
                || (flight.clone(), map.clone(), Some(frame.clone())),
                |(flight, map, frame)| {
                    let frame = frame.take().expect("one frame per copy");
                    flight.see(frame, map).expect("see")
                },
                BatchSize::LargeInput,
            )
        });
        group.bench_function("field/update_after_one_frame", |b| {
            b.iter_batched_ref(
                || flight.planner().clone(),
                |planner| planner.update(seen.as_map()),
                BatchSize::LargeInput,
            )
        });
        group.bench_function("field/update_and_path_check_after_one_frame", |b| {
            b.iter_batched_ref(
                || flight.planner().clone(),
                |planner| {
                    planner.update(seen.as_map());
                    planner.is_clear(&path)
                },
                BatchSize::LargeInput,
            )
        });
        group.bench_function("field/update_and_astar_after_one_frame", |b| {
            b.iter_batched_ref(
                || flight.planner().clone(),
                |planner| {
                    planner.update(seen.as_map());
                    planner.plan(start, target)
                },
                BatchSize::LargeInput,
            )
        });
        let field = flight.planner().field();
        group.bench_function("field/full_rebuild", |b| {
            b.iter(|| CostField::build(seen.as_map(), *field.region(), *field.config()).unwrap())
        });
        group.finish();
    }
}

criterion_group!(benches, cycle);
criterion_main!(benches);
