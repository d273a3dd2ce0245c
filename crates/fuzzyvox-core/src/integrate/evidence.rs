use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, finite};
use crate::ops::TConorm;
use crate::storage::{AccessorMut, BlockGrid, VoxelKey};

/// The evidence one scan gives one voxel: how strongly it says occupied and how strongly free,
/// each in `[0, 1]`, already weighted by confidence.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Evidence {
    /// Occupied evidence `o`.
    pub occupied: f32,
    /// Free evidence `e`.
    pub free: f32,
}

/// One scan's evidence: per voxel, the strongest occupied and the strongest free evidence that
/// any ray or pixel of the scan gave it.
pub type ScanEvidence = BlockGrid<Evidence>;

/// Raises the evidence at `key` to at least `occupied` / `free`.
#[inline]
pub(crate) fn raise(acc: &mut AccessorMut<'_, Evidence>, key: VoxelKey, occupied: f32, free: f32) {
    let cell = acc.get_or_insert(key);
    cell.occupied = cell.occupied.max(occupied);
    cell.free = cell.free.max(free);
}

/// Combines two partial scans by taking the larger evidence per voxel (exact in floating point,
/// so the result does not depend on how work was split).
pub(crate) fn merge_max(mut a: ScanEvidence, b: ScanEvidence) -> ScanEvidence {
    if a.block_count() < b.block_count() {
        return merge_max(b, a);
    }
    for (key, block) in b.blocks() {
        let position = a.ensure_block(key);
        let target = a.block_at_mut(position);
        for (t, s) in target.cells.iter_mut().zip(block.cells.iter()) {
            t.occupied = t.occupied.max(s.occupied);
            t.free = t.free.max(s.free);
        }
    }
    a
}

/// Which claims of a measurement its free evidence rests on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum EvidenceKind {
    /// The paper's model: free evidence weighted by the same confidence `c` as occupied
    /// evidence, and only in front of the interval (a depth image's voxels up to `P- - δ`).
    /// A pixel without a far bound or a confidence gives nothing.
    Paper,
    /// Each set gets the evidence its claim supports (see `docs/concepts.md`): occupied
    /// evidence keeps the confidence `c`; free evidence is weighted by the measurement's
    /// *reliability* `r` (how likely the match is right, not how wide its interval is) and,
    /// for a depth interval, reaches into the interval with a profile `ψ(z)` that falls from 1
    /// at `P-` to 0 part of the way to `P0` ([`EvidenceModel::free_reach`]). A pixel whose
    /// `P+` is undefined still clears up to its `P-` when it is reliable. The default.
    #[default]
    Dual,
}

impl EvidenceKind {
    /// Lower-case name (`paper`, `dual`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Dual => "dual",
        }
    }
}

/// How measurements become evidence.
///
/// A measurement of confidence `c` gives occupied evidence `g⁻¹(c · g(occupied_gain · φ))`
/// around its end point, where `g` is the additive generator of the map's t-conorm (so
/// `c = 0.5` counts as half an observation) and `φ` in `[0, 1]` is the spatial kernel; for the
/// non-Archimedean maximum the weighting is `c · μ`. Free evidence to the voxels it sees
/// through is `g⁻¹(w · g(free_gain))` with `w = c` in the paper's model and `w = r · ψ(z)` in
/// the dual model ([`EvidenceKind`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvidenceModel {
    /// Which model: the paper's or the dual one.
    pub kind: EvidenceKind,
    /// Occupied evidence of one certain hit at the kernel's peak (`k_O`, default 0.7).
    pub occupied_gain: f32,
    /// Free evidence of one certain pass-through (`k_E`, default 0.6).
    pub free_gain: f32,
    /// Angular footprint of a beam in radians: the occupied kernel around a point at range `r`
    /// has lateral σ = `r × angular_resolution` and reaches out to 2σ (at most
    /// [`EvidenceModel::MAX_KERNEL_VOXELS`] voxels). 0 puts all occupied evidence in the end
    /// voxel. Default 0.002 rad (0.11°).
    pub angular_resolution: f64,
    /// How fast a depth interval's occupied evidence falls as the interval widens: the peak is
    /// `(2δ / (P+ - P- + 2δ))^interval_falloff`, δ half a voxel diagonal. 1 spreads one sharp
    /// hit's evidence over the interval (a 13-voxel interval gives each voxel a thirteenth);
    /// 0 ignores the width; in between, wide intervals commit less per voxel yet repeated views
    /// build up faster. Default 1.
    pub interval_falloff: f32,
    /// Dual model: how far into a depth interval free evidence reaches, as a fraction of
    /// `P0 - P-`: the profile `ψ` is 1 up to `P-` and falls linearly to 0 at
    /// `P- + free_reach · (P0 - P-)` (each less `δ`, half a voxel diagonal, so that a voxel
    /// whose centre is cleared lies wholly in front of the bound). 0 stops at `P-`, as the
    /// paper's model does. In `[0, 1]`; ignored by the paper's model.
    pub free_reach: f32,
    /// Dual model: a voxel whose centre falls on a depth-image pixel without a measurement
    /// reads the measured pixels of its footprint instead (free in front of the nearest of
    /// their near bounds, with the least of their free weights), as the rays of a point-cloud
    /// integrator would clear it. Default on; ignored by the paper's model.
    pub fill_footprints: bool,
    /// Depth images: how an end point's hit is weighed against the image's other rays through
    /// its voxel. With `s` the share of those rays that end in the voxel (rays that pass
    /// through it within [`EvidenceModel::PASS_VOXELS`] voxels of their own end count against
    /// it), the hit counts `min(1, s / end_point_share)`. Within one image the pixels whose
    /// depth came out a few percent short put end points in front of the surface that most of
    /// the image's rays pass through; weighed, they count for little, while a voxel where the
    /// rays end counts fully. 0 turns the weighing off: every end point counts as a full hit,
    /// as in the point integrator. In `[0, 1]`; default 0 ([`EvidenceModel::confirmed`]: 1/3).
    pub end_point_share: f32,
}

impl EvidenceModel {
    /// Largest kernel radius, in voxels, around a point's end voxel.
    pub const MAX_KERNEL_VOXELS: i32 = 4;

    /// How far in front of its end a ray counts as passing through a voxel when end points are
    /// weighed ([`EvidenceModel::end_point_share`]), in voxels.
    pub const PASS_VOXELS: f32 = 4.0;

    /// Checks that the gains lie in `(0, 1]` and the angular resolution in `[0, 0.1]` rad.
    pub fn validate(self) -> Result<Self> {
        for (name, value) in [
            ("occupied_gain", self.occupied_gain),
            ("free_gain", self.free_gain),
        ] {
            if !(value > 0.0 && value <= 1.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: f64::from(value),
                    expected: "an evidence gain in (0, 1]",
                });
            }
        }
        if !(0.0..=1.0).contains(&self.interval_falloff) {
            return Err(Error::InvalidParameter {
                name: "interval_falloff",
                value: f64::from(self.interval_falloff),
                expected: "an exponent in [0, 1]",
            });
        }
        if !(0.0..=1.0).contains(&self.free_reach) {
            return Err(Error::InvalidParameter {
                name: "free_reach",
                value: f64::from(self.free_reach),
                expected: "a fraction of the interval in [0, 1]",
            });
        }
        if !(0.0..=1.0).contains(&self.end_point_share) {
            return Err(Error::InvalidParameter {
                name: "end_point_share",
                value: f64::from(self.end_point_share),
                expected: "a share of an image's rays in [0, 1]",
            });
        }
        finite("angular_resolution", self.angular_resolution)?;
        if !(0.0..=0.1).contains(&self.angular_resolution) {
            return Err(Error::InvalidParameter {
                name: "angular_resolution",
                value: self.angular_resolution,
                expected: "a beam footprint between 0 and 0.1 rad",
            });
        }
        Ok(self)
    }

    /// The paper's model, as the first wave built it.
    pub fn paper() -> Self {
        Self {
            kind: EvidenceKind::Paper,
            occupied_gain: 0.7,
            free_gain: 0.6,
            angular_resolution: 0.002,
            interval_falloff: 1.0,
            free_reach: 0.0,
            fill_footprints: false,
            end_point_share: 0.0,
        }
    }

    /// The dual model (the default).
    pub fn dual() -> Self {
        Self {
            kind: EvidenceKind::Dual,
            free_reach: 0.5,
            fill_footprints: true,
            ..Self::paper()
        }
    }

    /// The dual model for depth images whose pixels other views have confirmed (the depth
    /// stage's consistency check, `fuzzyvox_depth::ConsistencyFilter`): a kept pixel's depth is
    /// right far more often than a lone match's, so its free claim is trusted up to the
    /// surface: free evidence reaches all the way to `P0` (less half a voxel diagonal) and one
    /// pass-through counts 0.9 instead of 0.6. On the shared real frames (HoloLens walk,
    /// 0.05 m, four windows) this lifts the fuzzy map's `within_2_voxels` by 0.03-0.08 over
    /// [`EvidenceModel::dual`] on the same checked images: the free evidence of many views
    /// clears the front of a surface that their scattered occupied evidence would thicken.
    ///
    /// End points are weighed by the share of the image's rays that end in their voxel, an end
    /// point counting fully from a third ([`EvidenceModel::end_point_share`]): on the same
    /// frames (four windows, at least one agreeing neighbour) this lifts `within_2_voxels` by
    /// 0.017-0.023 and cuts the held-out rays that stop too near by 17-30%.
    pub fn confirmed() -> Self {
        Self {
            free_reach: 1.0,
            free_gain: 0.9,
            end_point_share: 1.0 / 3.0,
            ..Self::dual()
        }
    }

    /// The model of `kind` with its default parameters.
    pub fn of_kind(kind: EvidenceKind) -> Self {
        match kind {
            EvidenceKind::Paper => Self::paper(),
            EvidenceKind::Dual => Self::dual(),
        }
    }

    /// The weight of a measurement's free evidence before any profile: its confidence in the
    /// paper's model, its reliability in the dual one.
    #[inline]
    pub fn free_weight(&self, confidence: f32, reliability: f32) -> f32 {
        match self.kind {
            EvidenceKind::Paper => confidence,
            EvidenceKind::Dual => reliability,
        }
    }

    /// Free evidence of a measurement of weight `w` (see [`EvidenceModel::free_weight`]).
    #[inline]
    pub fn free(&self, operator: &TConorm, w: f32) -> f32 {
        operator.weighted(self.free_gain, w)
    }

    /// Occupied evidence of a measurement with confidence `c` where the kernel is `phi`.
    #[inline]
    pub fn occupied(&self, operator: &TConorm, c: f32, phi: f32) -> f32 {
        operator.weighted(self.occupied_gain * phi, c)
    }
}

impl Default for EvidenceModel {
    fn default() -> Self {
        Self::dual()
    }
}

/// Per-call options of an integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IntegrationOptions {
    /// Rays longer than this (metres; for depth images, depth along the optical axis) are cut
    /// here and only clear free space. `None`: no limit.
    pub max_range: Option<f64>,
}

impl IntegrationOptions {
    /// The longest ray, in voxels, that a point-cloud integration walks: 65,536 voxels (6.5 km
    /// at 10 cm, 655 m at 1 cm), beyond any real sensor's range. A longer ray (a glitch at
    /// 10⁶ m, say) would allocate free space along all of its length, so it is an error
    /// ([`Error::InvalidParameter`]) before anything changes; set `max_range` to cut such rays.
    pub const MAX_RAY_VOXELS: f64 = 65_536.0;

    /// Checks that `max_range`, when set, is finite and positive.
    pub fn validate(self) -> Result<Self> {
        if let Some(range) = self.max_range {
            finite("max_range", range)?;
            if range <= 0.0 {
                return Err(Error::InvalidParameter {
                    name: "max_range",
                    value: range,
                    expected: "a positive range in metres",
                });
            }
        }
        Ok(self)
    }
}

/// What an integration did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct IntegrationStats {
    /// Points (or valid pixels) that contributed.
    pub integrated: usize,
    /// Points skipped because they were not finite (or pixels that were invalid).
    pub skipped: usize,
    /// Rays cut at `max_range`.
    pub clipped: usize,
    /// Voxels whose cells received evidence.
    pub voxels_updated: usize,
}

/// Refuses a ray longer than [`IntegrationOptions::MAX_RAY_VOXELS`] voxels of `resolution`
/// metres (`range` already cut at `max_range`).
pub(crate) fn check_ray_length(range: f64, resolution: f64) -> Result<()> {
    if range / resolution > IntegrationOptions::MAX_RAY_VOXELS {
        return Err(Error::InvalidParameter {
            name: "ray length",
            value: range,
            expected: "a ray of at most 65,536 voxels; set max_range to cut longer rays",
        });
    }
    Ok(())
}
