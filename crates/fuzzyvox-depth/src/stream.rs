//! The depth stage over a stream of posed frames, as one camera delivers them: each new frame is
//! paired with its best earlier partner ([`PairSelector`]), matched with the earlier views the
//! window keeps ([`ViewWindow`]: sideways pairs rectified, pairs moving along the view by plane
//! sweep), and turned into an interval depth image; frames that give none are counted with the
//! reason.

use std::collections::BTreeMap;

use super::{
    DepthParams, DepthResult, ForwardMotion, Frame, MatchMethod, PairCriteria, PairSelector,
    ViewWindow,
};
use fuzzyvox_core::error::{Error, Result};

/// Why a frame of the stream gave no depth image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum SkipReason {
    /// No earlier frame within the time window has a baseline in range and a similar view.
    NoPartner,
    /// The pair's views are too far apart to match (opposite or non-overlapping views).
    Unmatchable,
    /// The pair moves along the view over so long a baseline that its plane sweep over the depth
    /// range would need more than 1024 planes.
    TooManyPlanes,
    /// The matching step failed for another reason.
    MatchFailed,
}

impl SkipReason {
    /// A short name for reports: `no_partner`, `unmatchable`, `too_many_planes`,
    /// `match_failed`.
    pub fn name(self) -> &'static str {
        match self {
            Self::NoPartner => "no_partner",
            Self::Unmatchable => "unmatchable",
            Self::TooManyPlanes => "too_many_planes",
            Self::MatchFailed => "match_failed",
        }
    }
}

/// What the stream did with its frames.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StreamCounts {
    /// Frames pushed.
    pub frames: usize,
    /// Depth images made, by how they were matched.
    pub rectified: usize,
    /// Depth images made by a two-view plane sweep (motion along the view).
    pub swept: usize,
    /// Depth images made from several views at once.
    pub multi_view: usize,
    /// Frames that gave no depth image, by reason.
    pub skipped: BTreeMap<SkipReason, usize>,
}

impl StreamCounts {
    /// Depth images made.
    pub fn depth_images(&self) -> usize {
        self.rectified + self.swept + self.multi_view
    }
}

/// The depth stage on a stream of frames.
///
/// ```
/// use fuzzyvox_depth::{DepthParams, DepthStream, PairCriteria};
///
/// let params = DepthParams { depth_range: Some((0.3, 8.0)), ..DepthParams::default() };
/// let stream = DepthStream::new(PairCriteria::default(), 2, params)?;
/// assert_eq!(stream.counts().frames, 0);
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct DepthStream {
    selector: PairSelector,
    window: ViewWindow,
    params: DepthParams,
    counts: StreamCounts,
}

impl DepthStream {
    /// A stream that pairs frames by `criteria` and matches each pair with up to `views - 2`
    /// earlier views (2: pairs alone). Pairs moving along the view are matched by plane sweep,
    /// so `params.depth_range` is required.
    pub fn new(criteria: PairCriteria, views: usize, params: DepthParams) -> Result<Self> {
        if params.depth_range.is_none() {
            return Err(Error::InvalidParameter {
                name: "depth_range",
                value: f64::NAN,
                expected: "a depth range (near, far) for the plane sweep",
            });
        }
        let params = DepthParams {
            forward_motion: ForwardMotion::PlaneSweep,
            ..params
        };
        Ok(Self {
            selector: PairSelector::new(criteria)?,
            window: ViewWindow::new(views)?,
            params,
            counts: StreamCounts::default(),
        })
    }

    /// What the stream has done so far.
    pub fn counts(&self) -> &StreamCounts {
        &self.counts
    }

    /// The earlier views the window left out because they needed too many planes.
    pub fn views_dropped(&self) -> usize {
        self.window.views_dropped()
    }

    /// Adds the next frame (frames must come in time order) and returns its depth image, or
    /// `Ok(None)` when it gives none (counted in [`counts`](Self::counts) with the reason).
    /// Errors: a frame out of time order, or invalid poses.
    pub fn push(&mut self, frame: Frame) -> Result<Option<DepthResult>> {
        let Some(pair) = self.selector.push(frame)? else {
            self.counts.frames += 1;
            self.skip(SkipReason::NoPartner);
            return Ok(None);
        };
        self.counts.frames += 1;
        let reference = Frame::clone(&pair.reference);
        let other = Frame::clone(&pair.other);
        match self.window.depth(reference, other, &self.params) {
            Ok(result) => {
                match result.method {
                    MatchMethod::Rectified => self.counts.rectified += 1,
                    MatchMethod::PlaneSweep => self.counts.swept += 1,
                    MatchMethod::MultiView => self.counts.multi_view += 1,
                }
                Ok(Some(result))
            }
            Err(Error::Unrectifiable { .. }) => {
                self.skip(SkipReason::Unmatchable);
                Ok(None)
            }
            Err(Error::InvalidParameter { name, .. }) if name == super::PLANE_COUNT => {
                self.skip(SkipReason::TooManyPlanes);
                Ok(None)
            }
            Err(_) => {
                self.skip(SkipReason::MatchFailed);
                Ok(None)
            }
        }
    }

    fn skip(&mut self, reason: SkipReason) {
        *self.counts.skipped.entry(reason).or_default() += 1;
    }
}
