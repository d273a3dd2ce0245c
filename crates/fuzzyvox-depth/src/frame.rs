//! The choice of a stereo partner for each new posed frame ([`Frame`], from the core).

use std::collections::VecDeque;
use std::sync::Arc;

use fuzzyvox_core::image::Frame;

use super::quality::{ExtrinsicQuality, extrinsic_quality};
use fuzzyvox_core::error::{Error, Result};

/// What makes an earlier frame an acceptable partner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairCriteria {
    /// Largest time between the frames (s).
    pub time_window: f64,
    /// Smallest baseline (m).
    pub min_baseline: f64,
    /// Largest baseline (m).
    pub max_baseline: f64,
    /// Largest angle between the look directions (rad).
    pub max_look_angle: f64,
}

impl Default for PairCriteria {
    fn default() -> Self {
        Self {
            time_window: 2.0,
            min_baseline: 0.05,
            max_baseline: 2.0,
            max_look_angle: 20f64.to_radians(),
        }
    }
}

impl PairCriteria {
    /// Checks the criteria.
    pub fn validate(&self) -> Result<()> {
        let check = |name, value: f64, ok: bool, expected| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name,
                    value,
                    expected,
                })
            }
        };
        check(
            "time_window",
            self.time_window,
            self.time_window > 0.0,
            "a time > 0 s",
        )?;
        check(
            "min_baseline",
            self.min_baseline,
            self.min_baseline >= 0.0,
            "a baseline >= 0 m",
        )?;
        check(
            "max_baseline",
            self.max_baseline,
            self.max_baseline > self.min_baseline,
            "a baseline above min_baseline",
        )?;
        check(
            "max_look_angle",
            self.max_look_angle,
            (0.0..=std::f64::consts::PI).contains(&self.max_look_angle),
            "an angle in [0, π] rad",
        )
    }

    /// Whether `earlier` may pair with `current`.
    pub fn accepts(&self, current: &Frame, earlier: &Frame) -> bool {
        let dt = current.timestamp() - earlier.timestamp();
        let baseline = (current.world_from_camera().translation.vector
            - earlier.world_from_camera().translation.vector)
            .norm();
        let angle = current.look_direction().angle(&earlier.look_direction());
        dt >= 0.0
            && dt <= self.time_window
            && (self.min_baseline..=self.max_baseline).contains(&baseline)
            && angle <= self.max_look_angle
    }
}

/// A chosen pair: the new frame (reference) and its best earlier partner.
#[derive(Clone, Debug)]
pub struct SelectedPair {
    /// The new frame; the depth is computed in its (rectified) camera.
    pub reference: Arc<Frame>,
    /// The earlier frame.
    pub other: Arc<Frame>,
    /// The pair's `Q_ABD`.
    pub quality: ExtrinsicQuality,
}

/// Keeps the recent frames of a stream and picks, for each new frame, the earlier frame that
/// meets the [`PairCriteria`] with the highest `Q_ABD` (ties go to the most recent).
#[derive(Clone, Debug)]
pub struct PairSelector {
    criteria: PairCriteria,
    frames: VecDeque<Arc<Frame>>,
}

impl PairSelector {
    /// A selector with validated criteria.
    pub fn new(criteria: PairCriteria) -> Result<Self> {
        criteria.validate()?;
        Ok(Self {
            criteria,
            frames: VecDeque::new(),
        })
    }

    /// Frames currently kept.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether no frame is kept.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Adds a frame and returns its best partner, if any has `Q > 0`. Frames must arrive in
    /// time order; frames older than the time window are dropped.
    pub fn push(&mut self, frame: Frame) -> Result<Option<SelectedPair>> {
        if let Some(last) = self.frames.back()
            && frame.timestamp() < last.timestamp()
        {
            return Err(Error::InvalidParameter {
                name: "timestamp",
                value: frame.timestamp(),
                expected: "frames in non-decreasing time order",
            });
        }
        let current = Arc::new(frame);
        let horizon = current.timestamp() - self.criteria.time_window;
        while self.frames.front().is_some_and(|f| f.timestamp() < horizon) {
            self.frames.pop_front();
        }
        let mut best: Option<(Arc<Frame>, ExtrinsicQuality)> = None;
        for earlier in self.frames.iter().rev() {
            if !self.criteria.accepts(&current, earlier) {
                continue;
            }
            let quality =
                extrinsic_quality(current.world_from_camera(), earlier.world_from_camera())?;
            if quality.q > 0.0 && best.as_ref().is_none_or(|(_, b)| quality.q > b.q) {
                best = Some((Arc::clone(earlier), quality));
            }
        }
        self.frames.push_back(Arc::clone(&current));
        Ok(best.map(|(other, quality)| SelectedPair {
            reference: current,
            other,
            quality,
        }))
    }
}
