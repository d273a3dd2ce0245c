//! Accuracy of a disparity map against ground truth, with the definitions of the project's
//! reference table: errors count over pixels with ground truth; "matched" figures judge only
//! pixels that got a disparity, "all" figures count a pixel without one as an error.

use fuzzyvox_core::error::{Error, Result};

/// Accuracy figures, in percent.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Accuracy {
    /// Pixels with ground truth.
    pub ground_truth_pixels: usize,
    /// Share of ground-truth pixels that got a disparity (%).
    pub density: f64,
    /// Matched pixels off by more than 1 px (%).
    pub bad1_matched: f64,
    /// Matched pixels off by more than 2 px (%).
    pub bad2_matched: f64,
    /// Ground-truth pixels off by more than 2 px or without a disparity (%).
    pub bad2_all: f64,
    /// Bad-2 among the most confident half of the matched pixels (%); `NaN` without confidences.
    pub bad2_top50_confidence: f64,
}

/// Compares `disparity` (`NaN` = none) with `truth` (non-finite = no ground truth). `confidence`
/// ranks the matched pixels for the top-half figure (ties broken by pixel order).
pub fn evaluate(disparity: &[f32], truth: &[f32], confidence: Option<&[f32]>) -> Result<Accuracy> {
    if truth.len() != disparity.len() {
        return Err(Error::SizeMismatch {
            what: "ground truth pixels",
            expected: disparity.len(),
            found: truth.len(),
        });
    }
    if let Some(c) = confidence
        && c.len() != disparity.len()
    {
        return Err(Error::SizeMismatch {
            what: "confidence pixels",
            expected: disparity.len(),
            found: c.len(),
        });
    }
    let (mut total, mut matched, mut bad1, mut bad2) = (0usize, 0usize, 0usize, 0usize);
    let mut ranked: Vec<(f32, bool)> = Vec::new();
    for (i, (&d, &t)) in disparity.iter().zip(truth).enumerate() {
        if !t.is_finite() {
            continue;
        }
        total += 1;
        if d.is_nan() {
            continue;
        }
        matched += 1;
        let error = (d - t).abs();
        bad1 += usize::from(error > 1.0);
        bad2 += usize::from(error > 2.0);
        if let Some(c) = confidence {
            let c = if c[i].is_nan() { 0.0 } else { c[i] };
            ranked.push((c, error > 2.0));
        }
    }
    let percent = |n: usize, of: usize| 100.0 * n as f64 / of.max(1) as f64;
    let top50 = if confidence.is_some() && !ranked.is_empty() {
        // Stable sort: equal confidences keep pixel order, so the figure is deterministic.
        ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
        let half = ranked.len().div_ceil(2);
        percent(ranked[..half].iter().filter(|r| r.1).count(), half)
    } else {
        f64::NAN
    };
    Ok(Accuracy {
        ground_truth_pixels: total,
        density: percent(matched, total),
        bad1_matched: percent(bad1, matched),
        bad2_matched: percent(bad2, matched),
        bad2_all: percent(bad2 + (total - matched), total),
        bad2_top50_confidence: top50,
    })
}
