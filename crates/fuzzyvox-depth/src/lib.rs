//! The depth stage (EpiDepth-style motion stereo with one camera): pair selection, extrinsic
//! quality `Q_ABD`, rectification, census block matching, and per-pixel depth intervals
//! `P- <= P0 <= P+` with a confidence, output as a [`DepthFrame`](fuzzyvox_core::DepthFrame) for the
//! frustum integrator; and depth from several views at once ([`depth_from_views`],
//! [`ViewWindow`]). See `docs/depth.md`.

mod census;
mod consistency;
mod frame;
mod interval;
mod matching;
mod metrics;
mod params;
mod pipeline;
mod quality;
mod rectify;
mod scan;
mod stream;
mod sweep;
mod texture;
mod views;

pub use census::{
    CENSUS_BITS, CENSUS_HEIGHT, CENSUS_MAX_COST, CENSUS_WIDTH, CensusCode, CensusImage,
    census_transform,
};
pub use consistency::{
    ConsistencyCounts, ConsistencyFilter, ConsistencyParams, ConsistencyVotes, check_consistency,
};
pub use frame::{PairCriteria, PairSelector, SelectedPair};
pub use fuzzyvox_core::error::UnrectifiableReason;
pub use fuzzyvox_core::image::{Frame, GrayImage, MIN_BASELINE, StereoGeometry};
pub use interval::{
    IntervalMethod, IntervalParams, RELIABLE_COST, confidence, interval_image, match_reliability,
};
pub use matching::match_pair;
pub use metrics::{Accuracy, evaluate};
pub use params::{DEFAULT_MIN_CONTRAST, DisparityMap, MAX_DISPARITIES, MAX_WINDOW, MatchParams};
pub use pipeline::{
    DepthParams, DepthResult, ForwardMotion, MatchMethod, SWEEP_EPIPOLE_MARGIN,
    depth_by_plane_sweep, depth_from_pair, depth_from_rectified, depth_from_selected,
    depth_from_views,
};
pub use quality::{ExtrinsicQuality, extrinsic_quality, quality_from_vectors};
pub use rectify::{Rectification, Side};
pub use stream::{DepthStream, SkipReason, StreamCounts};
pub use sweep::{MAX_SWEEP_PIXELS, MAX_SWEEP_SIDE, MAX_SWEEP_VIEWS, PLANE_COUNT};
pub use texture::textureless;
pub use views::ViewWindow;
