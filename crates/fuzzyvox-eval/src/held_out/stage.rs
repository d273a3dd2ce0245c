//! The stages a held-out run reports progress in.

use std::fmt;

/// A stage of a held-out run, as its progress callback names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HeldOutStage {
    /// Integrating sensor depth of the build frames into every map (`run_rgbd`).
    Integrating,
    /// The depth stage on the build frames and their integration (`run_mono`).
    DepthAndMapping,
    /// Ray casting every map into the held-out frames.
    RayCasting,
    /// Flights planned through every map and checked against the reference (`run_mono` with
    /// flights).
    Flights,
}

impl HeldOutStage {
    /// A short lower-case label: `integrating`, `depth and mapping`, `ray casting` or `flights`.
    pub fn label(self) -> &'static str {
        match self {
            Self::Integrating => "integrating",
            Self::DepthAndMapping => "depth and mapping",
            Self::RayCasting => "ray casting",
            Self::Flights => "flights",
        }
    }
}

impl fmt::Display for HeldOutStage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.label())
    }
}
