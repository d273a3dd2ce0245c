//! Pixel evidence: what one pixel of an interval depth image contributes to any voxel on its
//! ray, computed once per pixel ([`PixelEvidence`]) and read per voxel by its depth.

use rayon::prelude::*;

use crate::integrate::depth_image::{IntervalDepthImage, PixelInterval};
use crate::integrate::evidence::{Evidence, EvidenceKind, EvidenceModel};
use crate::ops::TConorm;

/// Every pixel's evidence that does not depend on the voxel, in parallel.
pub(super) fn pixel_evidence(
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
pub(super) struct PixelEvidence {
    /// Voxels with `z` below this get the full free evidence (`ψ = 1`).
    pub(super) free_until: f32,
    /// Voxels with `z` from `free_until` up to this get free evidence graded by the profile
    /// `ψ` (the dual model; equal to `free_until` in the paper's model).
    pub(super) free_end: f32,
    /// Voxels with `z` up to this can get evidence.
    pub(super) reach: f32,
    /// `P0`.
    pub(super) depth: f32,
    /// Peak of the occupied kernel, `(2δ / (P+ - P- + 2δ))^falloff`; 0 for a pixel that only
    /// clears (beyond the maximum range, or without a confidence in the dual model).
    pub(super) height: f32,
    /// Free evidence where `ψ = 1`.
    pub(super) free: f32,
    /// Weight of the free evidence before the profile (confidence or reliability).
    pub(super) free_weight: f32,
    /// The pixel's confidence (weight of its occupied evidence).
    pub(super) confidence: f32,
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

    pub(super) fn is_valid(&self) -> bool {
        self.reach > f32::NEG_INFINITY
    }

    /// Evidence for a voxel whose centre lies at depth `z` on this pixel.
    #[inline]
    pub(super) fn at(
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
