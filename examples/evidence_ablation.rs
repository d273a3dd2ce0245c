//! The evidence model's ablation: one scenario's depth images fed to the standard maps and to
//! fuzzy maps that differ in one setting of the evidence model, each measured against the truth
//! and flown through with the same planned flights.
//!
//! ```sh
//! cargo run --release --example evidence_ablation -- wall 12 1 100
//! cargo run --release --example evidence_ablation -- random 300 7 100
//! # Variants of your own: NAME=KIND[,reach=R][,falloff=F] (KIND paper or dual).
//! cargo run --release --example evidence_ablation -- random 100 3 100 "wide=dual,reach=1"
//! ```
//! Arguments: scenario (`wall` or `random`), pairs (the random flight's), seed, planned
//! flights, then variants (default: the paper's model and the dual model's parts one by one).

use fuzzyvox::eval::{ExperimentConfig, QueryConfig, run_experiment};
use fuzzyvox::plan::PlannerConfig;
use fuzzyvox::sim::scenario;
use fuzzyvox::{EvidenceKind, EvidenceModel, FuzzyConfig};

fn parse_variant(spec: &str) -> Result<(String, EvidenceModel), String> {
    let (name, rest) = spec
        .split_once('=')
        .ok_or_else(|| format!("variant {spec:?}: expected NAME=KIND[,key=value...]"))?;
    let mut parts = rest.split(',');
    let mut model = match parts.next() {
        Some("paper") => EvidenceModel::paper(),
        Some("dual") => EvidenceModel::dual(),
        other => return Err(format!("variant {name}: unknown kind {other:?}")),
    };
    for part in parts {
        let (key, value) = part
            .split_once('=')
            .ok_or_else(|| format!("variant {name}: expected key=value, got {part:?}"))?;
        let value: f32 = value
            .parse()
            .map_err(|e| format!("variant {name}: {key}: {e}"))?;
        match key {
            "reach" => model.free_reach = value,
            "falloff" => model.interval_falloff = value,
            "free_gain" => model.free_gain = value,
            "occupied_gain" => model.occupied_gain = value,
            "fill" => model.fill_footprints = value != 0.0,
            _ => return Err(format!("variant {name}: unknown setting {key}")),
        }
    }
    Ok((name.to_string(), model))
}

fn default_variants() -> Vec<(String, EvidenceModel)> {
    let dual = EvidenceModel::dual();
    // Each step adds one part of the dual model to the one before.
    let reliability = EvidenceModel {
        kind: EvidenceKind::Dual,
        free_reach: 0.0,
        fill_footprints: false,
        ..dual
    };
    vec![
        ("paper".into(), EvidenceModel::paper()),
        ("+reliability".into(), reliability),
        (
            "+footprints".into(),
            EvidenceModel {
                fill_footprints: true,
                ..reliability
            },
        ),
        ("+profile (dual)".into(), dual),
        (
            "+wider kernel".into(),
            EvidenceModel {
                interval_falloff: 0.5,
                ..dual
            },
        ),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or(default.into());
    let name = arg(0, "wall");
    let pairs: usize = arg(1, "100").parse()?;
    let seed: u64 = arg(2, "1").parse()?;
    let flights: usize = arg(3, "100").parse()?;
    let variants = if args.len() > 4 {
        args[4..]
            .iter()
            .map(|s| parse_variant(s))
            .collect::<Result<Vec<_>, _>>()?
    } else {
        default_variants()
    };
    let scenario = match name.as_str() {
        "wall" => scenario::wall()?,
        "random" => scenario::random(pairs, seed)?,
        other => return Err(format!("unknown scenario {other:?}").into()),
    };
    let config = ExperimentConfig {
        seed,
        variants: variants
            .iter()
            .map(|(n, m)| Ok((n.clone(), FuzzyConfig::new(0.2)?.with_evidence(*m))))
            .collect::<fuzzyvox::Result<_>>()?,
        flights: (flights > 0).then(|| QueryConfig {
            queries: flights,
            seed,
            altitude: scenario.flight_altitude,
            distance: scenario.flight_distance,
            planner: PlannerConfig::default(),
            ..QueryConfig::default()
        }),
        ..ExperimentConfig::default()
    };
    let output = run_experiment(&scenario, &config)?;
    let report = &output.report;
    println!(
        "{} scenario, {} pairs, seed {seed}, {} flights (truth success {:.2})",
        report.scenario,
        report.pairs,
        output.flight_queries.len(),
        report
            .truth_flights
            .as_ref()
            .map_or(0.0, |f| f.plan_success)
    );
    println!(
        "| map | free voxels | flight success | collisions | start/goal unsafe, disconnected | holes | spurious | precision | recall | F1 |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (name, map) in &report.maps {
        let m = &map.metrics;
        let (success, collisions, failures) =
            map.flights
                .as_ref()
                .map_or(("-".to_string(), "-".to_string(), "-".to_string()), |f| {
                    let p = f.plan_failures;
                    (
                        format!("{:.2}", f.plan_success),
                        f.plan_collisions.to_string(),
                        format!(
                            "{}/{}, {} (unknown {}, occupied {}, ambiguous {}, low safety {})",
                            p.start_unsafe,
                            p.goal_unsafe,
                            p.disconnected,
                            p.blocked_by.unknown + p.blocked_by.outside_extent,
                            p.blocked_by.occupied,
                            p.blocked_by.ambiguous,
                            p.blocked_by.low_safety
                        ),
                    )
                });
        println!(
            "| {name} | {} | {success} | {collisions} | {failures} | {} | {} | {:.3} | {:.3} | {:.3} |",
            m.free,
            m.holes,
            m.spurious_unknown,
            m.occupied_precision,
            m.occupied_recall,
            m.occupied_f1
        );
    }
    Ok(())
}
