//! The report's charts: per map, holes, spurious voxels, F1 and flight success; the fuzzy
//! operators side by side; and the depth stage's accuracy against its confidence.

use super::depth_stage::DepthStageErrors;
use super::experiment::{DepthSample, ExperimentReport};
use crate::figure::chart::{BarPanel, Chart, LinePanel, Panel};

/// Holes, spurious voxels, occupied F1 and flight success of the three models (`logodds`,
/// `alpha`, `fuzzy`, in that order, those the experiment built).
pub fn maps_chart(report: &ExperimentReport) -> Chart {
    let maps: Vec<(&str, &super::MapReport)> = ["logodds", "alpha", "fuzzy"]
        .into_iter()
        .filter_map(|n| Some((n, report.maps.get(n)?)))
        .collect();
    let names: Vec<String> = maps.iter().map(|(n, _)| n.to_string()).collect();
    let metric = |f: &dyn Fn(&super::MapMetrics) -> f64| -> Vec<Option<f64>> {
        maps.iter().map(|(_, m)| Some(f(&m.metrics))).collect()
    };
    let mut panels = vec![
        Panel::Bars(BarPanel {
            title: "holes (truly occupied, not occupied)".into(),
            values: metric(&|m| m.holes as f64),
            range: None,
        }),
        Panel::Bars(BarPanel {
            title: "spurious (occupied in unknown space)".into(),
            values: metric(&|m| m.spurious_unknown as f64),
            range: None,
        }),
        Panel::Bars(BarPanel {
            title: "occupied F1".into(),
            values: metric(&|m| m.occupied_f1),
            range: Some([0.0, 1.0]),
        }),
    ];
    if maps.iter().any(|(_, m)| m.flights.is_some()) {
        panels.push(Panel::Bars(BarPanel {
            title: "flight success".into(),
            values: maps
                .iter()
                .map(|(_, m)| m.flights.as_ref().map(|f| f.plan_success))
                .collect(),
            range: Some([0.0, 1.0]),
        }));
    }
    Chart {
        title: format!(
            "{} scenario: every map against the true scene",
            report.scenario
        ),
        categories: names,
        panels,
        columns: 2,
    }
}

/// The fuzzy maps built with different t-conorms (`fuzzy`, the probabilistic sum, and each
/// `fuzzy:OP`), side by side, named by operator; `None` when the experiment built only one.
pub fn operators_chart(report: &ExperimentReport) -> Option<Chart> {
    let fuzzy: Vec<(&String, &super::MapReport)> = report
        .maps
        .iter()
        .filter(|(name, _)| name.as_str() == "fuzzy" || name.starts_with("fuzzy:"))
        .collect();
    if fuzzy.len() < 2 {
        return None;
    }
    let metric = |f: &dyn Fn(&super::MapMetrics) -> f64| -> Vec<Option<f64>> {
        fuzzy.iter().map(|(_, m)| Some(f(&m.metrics))).collect()
    };
    Some(Chart {
        title: format!(
            "{} scenario: fuzzy maps by aggregation operator",
            report.scenario
        ),
        categories: fuzzy
            .iter()
            .map(|(n, _)| match n.strip_prefix("fuzzy:") {
                Some(op) => op.replace('-', " "),
                None => "prob. sum".to_string(),
            })
            .collect(),
        panels: vec![
            Panel::Bars(BarPanel {
                title: "occupied precision".into(),
                values: metric(&|m| m.occupied_precision),
                range: Some([0.0, 1.0]),
            }),
            Panel::Bars(BarPanel {
                title: "occupied recall".into(),
                values: metric(&|m| m.occupied_recall),
                range: Some([0.0, 1.0]),
            }),
            Panel::Bars(BarPanel {
                title: "holes".into(),
                values: metric(&|m| m.holes as f64),
                range: None,
            }),
            Panel::Bars(BarPanel {
                title: "spurious (unknown space)".into(),
                values: metric(&|m| m.spurious_unknown as f64),
                range: None,
            }),
        ],
        columns: 2,
    })
}

/// The depth stage's accuracy against its confidence over the sampled pairs: the pixels cut
/// into ten groups of equal size by confidence, each group's median relative error and
/// interval coverage. `None` without samples or compared pixels.
pub fn depth_confidence_chart(scenario: &str, samples: &[DepthSample]) -> Option<Chart> {
    let mut errors = DepthStageErrors::default();
    for sample in samples {
        errors.add_aligned(sample.frame.image(), &sample.truth.depth);
    }
    let bins = errors.by_confidence(10);
    if bins.is_empty() {
        return None;
    }
    let top_error = bins
        .iter()
        .map(|b| b.median_rel_error)
        .filter(|e| e.is_finite())
        .fold(0.0f64, f64::max);
    Some(Chart {
        title: format!(
            "{scenario} scenario: depth stage accuracy against confidence ({} pixels of {} pairs)",
            bins.iter().map(|b| b.pixels).sum::<usize>(),
            samples.len()
        ),
        categories: Vec::new(),
        panels: vec![
            Panel::Lines(LinePanel {
                title: "median relative error of P0".into(),
                x_label: "confidence C(p), mean of each tenth of the pixels".into(),
                x_range: [0.0, 1.0],
                y_range: [0.0, (top_error * 1.15).max(0.05)],
                series: vec![(
                    "|P0 - z| / z".into(),
                    bins.iter()
                        .map(|b| (b.confidence, b.median_rel_error))
                        .collect(),
                )],
            }),
            Panel::Lines(LinePanel {
                title: "true depth inside [P-, P+]".into(),
                x_label: "confidence C(p), mean of each tenth of the pixels".into(),
                x_range: [0.0, 1.0],
                y_range: [0.0, 1.0],
                series: vec![(
                    "coverage".into(),
                    bins.iter()
                        .map(|b| (b.confidence, b.interval_coverage))
                        .collect(),
                )],
            }),
        ],
        columns: 2,
    })
}
