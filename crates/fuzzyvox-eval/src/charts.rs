//! The report's charts: per map, holes, spurious voxels, F1 and flight success; the fuzzy
//! operators side by side; and the depth stage's accuracy against its confidence.

use super::depth_stage::DepthStageErrors;
use super::experiment::{DepthSample, ExperimentReport};
use fuzzyvox_core::map::MapKind;
use fuzzyvox_figure::chart::{BarPanel, Chart, LinePanel, Panel};

/// Holes, spurious voxels, occupied F1 and flight success of the three models (`logodds`,
/// `alpha`, `fuzzy`, in that order, those the experiment built).
pub fn maps_chart(report: &ExperimentReport) -> Chart {
    let maps: Vec<(&str, &super::MapReport)> = MapKind::ALL
        .into_iter()
        .filter_map(|kind| Some((kind.name(), report.maps.get(kind.name())?)))
        .collect();
    let names: Vec<String> = maps.iter().map(|(n, _)| n.to_string()).collect();
    let reports: Vec<&super::MapReport> = maps.iter().map(|(_, m)| *m).collect();
    let mut panels = vec![
        metric_bars(
            &reports,
            "holes (truly occupied, not occupied)",
            None,
            |m| m.holes as f64,
        ),
        metric_bars(
            &reports,
            "spurious (occupied in unknown space)",
            None,
            |m| m.spurious_unknown as f64,
        ),
        metric_bars(&reports, "occupied F1", Some([0.0, 1.0]), |m| m.occupied_f1),
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

/// A bar per map of one metric.
fn metric_bars(
    maps: &[&super::MapReport],
    title: &str,
    range: Option<[f64; 2]>,
    metric: impl Fn(&super::MapMetrics) -> f64,
) -> Panel {
    Panel::Bars(BarPanel {
        title: title.into(),
        values: maps.iter().map(|m| Some(metric(&m.metrics))).collect(),
        range,
    })
}

/// The fuzzy maps built with different t-conorms (`fuzzy`, the probabilistic sum, and each
/// `fuzzy:OP`), side by side, named by operator; `None` when the experiment built only one.
pub fn operators_chart(report: &ExperimentReport) -> Option<Chart> {
    let fuzzy: Vec<(&String, &super::MapReport)> = report
        .maps
        .iter()
        .filter(|(name, _)| operator_of(name).is_some())
        .collect();
    if fuzzy.len() < 2 {
        return None;
    }
    let reports: Vec<&super::MapReport> = fuzzy.iter().map(|(_, m)| *m).collect();
    Some(Chart {
        title: format!(
            "{} scenario: fuzzy maps by aggregation operator",
            report.scenario
        ),
        categories: fuzzy
            .iter()
            .map(|(n, _)| match operator_of(n).flatten() {
                Some(op) => op.replace('-', " "),
                None => "prob. sum".to_string(),
            })
            .collect(),
        panels: vec![
            metric_bars(&reports, "occupied precision", Some([0.0, 1.0]), |m| {
                m.occupied_precision
            }),
            metric_bars(&reports, "occupied recall", Some([0.0, 1.0]), |m| {
                m.occupied_recall
            }),
            metric_bars(&reports, "holes", None, |m| m.holes as f64),
            metric_bars(&reports, "spurious (unknown space)", None, |m| {
                m.spurious_unknown as f64
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

/// For a fuzzy map's name in an experiment (`fuzzy`, or `fuzzy:OP` for another operator), its
/// operator (`None` for the default one); `None` for every other map.
fn operator_of(name: &str) -> Option<Option<&str>> {
    let rest = name.strip_prefix(MapKind::Fuzzy.name())?;
    match rest.strip_prefix(':') {
        Some(op) => Some(Some(op)),
        None => rest.is_empty().then_some(None),
    }
}
