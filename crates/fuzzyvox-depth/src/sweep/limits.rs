//! The limits of a plane sweep: how many views, how large a view, how many planes, and how
//! little motion still measures depth.

/// The parameter an
/// [`Error::InvalidParameter`](fuzzyvox_core::error::Error::InvalidParameter) names when a
/// sweep would need more than [`MAX_DISPARITIES`](crate::MAX_DISPARITIES) planes.
pub const PLANE_COUNT: &str = "plane count for the depth range";

/// Longest image side, in pixels, of a view the sweep matches against (see `floor_small`).
pub const MAX_SWEEP_SIDE: u32 = 1 << 20;

/// Most pixels of a view the sweep matches against: a pixel's index in it must fit an `i32`
/// (the landing loop's `-1` marks "outside").
pub const MAX_SWEEP_PIXELS: u64 = (1 << 31) - 1;

/// A pixel that moves less than this many pixels, in its fastest view, between the nearest and
/// the farthest plane gets no depth: its cost curve cannot tell depths apart.
pub const MIN_SWEEP_MOTION: f32 = 2.0;

/// Most other views one sweep matches against (a pixel's cost sums and counts stay small).
pub const MAX_SWEEP_VIEWS: usize = 16;
