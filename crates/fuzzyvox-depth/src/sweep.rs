//! Plane-sweep matching in the original reference camera: for pairs that cannot be rectified
//! usefully (motion along the look direction puts the epipole inside the image), and for
//! several other views at once (multi-baseline stereo).
//!
//! Fronto-parallel planes at inverse depths `w_k = w_far + k · Δw` (`k = 0 .. K`) play the part
//! of disparities: a reference pixel `x` on plane `k` maps into the other image at
//! `π(M x̃ + w_k K_o t)`, where `M = K_o R K_r⁻¹` and `(R, t)` is `other_from_reference`. `Δw` is
//! chosen so that no pixel moves more than one pixel between neighbouring planes. Each plane's
//! cost is the census Hamming distance to the other image's nearest pixel, aggregated over the
//! same window as the row matcher. With several other views (Okutomi and Kanade's
//! multiple-baseline stereo) a pixel's cost on a plane is the mean distance over the views it
//! lands in, and the view that moves fastest (the longest baseline) sets `Δw`: the short
//! baselines keep the cost curve free of repeated minima, the long one makes it sharp, and one
//! plane step is one pixel of the longest baseline. Then winner-takes-all with a parabola
//! refinement, the uniqueness test and the cost-curve range follow, exactly as for rectified
//! pairs. Because `w` is affine in the plane index, depth is `1 / (w_far + k Δw)`, which is a
//! [`StereoGeometry`] with `baseline · f = 1 / Δw` and `doffs = w_far / Δw`: the interval and
//! confidence code of rectified pairs applies unchanged.
//!
//! Near the epipole the planes barely move a pixel: one plane step is one pixel only where the
//! image moves fastest, so a pixel that moves `m` pixels over the whole sweep keeps the same
//! nearest pixel, and so the same cost, for about `planes / m` planes in a row. Its minimum is
//! then a run of equal costs: the match is the run's middle, and the uniqueness test looks for
//! rivals more than one pixel *of that pixel's motion* beyond the run (not one plane, which
//! would find the run itself and drop every slow pixel). Its cost-curve range spans the run, so
//! its interval is as wide as one pixel of motion makes it and its confidence follows. A pixel
//! that moves less than [`MIN_SWEEP_MOTION`] pixels over the whole depth range (the epipole
//! itself) cannot be measured and gets no depth: the honest answer for motion along the view.
//! There is no left-right check (the other image has no sweep of its own).
//!
//! Memory is bounded by a band of rows times the planes: the image is cut into bands of rows
//! that threads sweep independently (each band with a halo of half a window), keeping the
//! band's aggregated costs on every plane (at most 32 rows × width × 1024 planes × 2 bytes).

use fuzzyvox_core::image::{Frame, MIN_BASELINE, StereoGeometry};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use super::census::{CENSUS_BITS, CENSUS_MAX_COST, CensusImage, census_transform};
use super::params::{DisparityMap, MAX_DISPARITIES, MatchParams};
use super::texture::drop_textureless;
use crate::error::UnrectifiableReason;
use crate::error::{Error, Result};

/// Rows per band of the sweep (plus a halo of half a window above and below).
const BAND_ROWS: usize = 32;

/// Raw costs are the mean census distance over the views that see a pixel, in units of an
/// eighth of a bit, so that a mean over several views keeps three bits of its fraction. The
/// largest raw cost, `31 · 8 = 248`, still fits a byte and a 15 × 15 window sum a `u16`.
const COST_SCALE: u32 = 8;

/// The parameter an [`Error::InvalidParameter`] names when a sweep would need more than
/// [`MAX_DISPARITIES`] planes.
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

/// One other view of a sweep: where a reference pixel lands in it on each plane.
#[derive(Clone, Debug)]
struct SweepView {
    /// `K_o R K_r⁻¹`, in single precision.
    homography: [[f32; 3]; 3],
    /// `K_o t`.
    translation: [f32; 3],
}

/// The planes of a sweep and the geometry that turns a plane index into depth.
#[derive(Clone, Debug)]
pub(crate) struct Sweep {
    /// The other views, in the order given.
    views: Vec<SweepView>,
    /// Inverse depth of plane 0 (the farthest).
    inverse_far: f64,
    /// Inverse-depth step between planes.
    step: f64,
    /// Number of planes.
    planes: u32,
}

impl Sweep {
    /// The planes covering depths `near ..= far` for `reference` seen from every view of
    /// `others`: the step is set by the view whose image moves fastest (the longest baseline),
    /// so that no pixel of any view moves more than one pixel between neighbouring planes.
    pub(crate) fn new(reference: &Frame, others: &[&Frame], near: f64, far: f64) -> Result<Self> {
        if !(near.is_finite() && near > 0.0 && far > near) {
            return Err(Error::InvalidParameter {
                name: "depth range",
                value: near,
                expected: "0 < near < far",
            });
        }
        if others.is_empty() {
            return Err(Error::Empty("other views of the plane sweep"));
        }
        if others.len() > MAX_SWEEP_VIEWS {
            return Err(Error::InvalidParameter {
                name: "other views of the plane sweep",
                value: others.len() as f64,
                expected: "1 to 16 other views",
            });
        }
        let (inverse_near, inverse_far) =
            (1.0 / near, if far.is_finite() { 1.0 / far } else { 0.0 });
        let mut rate: f64 = 0.0;
        let mut views = Vec::with_capacity(others.len());
        for other in others {
            let (view, view_rate) = SweepView::new(reference, other, inverse_near, inverse_far)?;
            rate = rate.max(view_rate);
            views.push(view);
        }
        let planes = (rate * (inverse_near - inverse_far)).ceil() + 1.0;
        if !(planes.is_finite() && planes <= f64::from(MAX_DISPARITIES)) {
            return Err(Error::InvalidParameter {
                name: PLANE_COUNT,
                value: planes,
                expected: "1 to 1024 planes (narrow the depth range or the baselines)",
            });
        }
        let planes = planes.max(2.0) as u32;
        let step = (inverse_near - inverse_far) / f64::from(planes - 1);
        Ok(Self {
            views,
            inverse_far,
            step,
            planes,
        })
    }

    /// The geometry that maps a (fractional) plane index to depth in the reference camera.
    pub(crate) fn geometry(&self, reference: &Frame) -> Result<StereoGeometry> {
        let fx = reference.intrinsics().fx();
        StereoGeometry::new(
            *reference.intrinsics(),
            *reference.world_from_camera(),
            1.0 / (self.step * fx),
            self.inverse_far / self.step,
        )
    }

    /// Raw costs of reference row `y` on plane `k`, written into `out` (one per column): the
    /// mean census distance over the views in which the pixel lands on a valid pixel, scaled by
    /// [`COST_SCALE`], or the largest cost where it lands in none. `reference` holds the row's
    /// tagged codes (see [`tagged_codes`]).
    fn row_costs(
        &self,
        rays: RowRays<'_>,
        k: u32,
        reference: &[u32],
        others: &[TaggedImage],
        scratch: &mut RowScratch,
        out: &mut [u8],
    ) {
        let inverse = (self.inverse_far + self.step * f64::from(k)) as f32;
        let RowScratch {
            landing,
            gathered,
            sums,
            counts,
        } = scratch;
        sums.fill(0);
        counts.fill(0);
        for (v, (view, other)) in self.views.iter().zip(others).enumerate() {
            let (xs, ys, zs) = rays.view(v);
            let b = view.translation.map(|v| v * inverse);
            let (w, h) = (other.width as f32, other.height as f32);
            let stride = other.width as u32;
            // The nearest pixel of every column, branch-free so that it vectorises; -1 where
            // the pixel lands outside the image (or behind the camera). Truncation equals
            // floor for the non-negative values kept.
            for (((j, &ax), &ay), &az) in landing.iter_mut().zip(xs).zip(ys).zip(zs) {
                let qz = az + b[2];
                let inv = 1.0 / qz;
                let (u, v) = ((ax + b[0]) * inv + 0.5, (ay + b[1]) * inv + 0.5);
                let inside = qz > 1e-6 && u >= 0.0 && v >= 0.0 && u < w && v < h;
                let index = floor_small(v)
                    .wrapping_mul(stride)
                    .wrapping_add(floor_small(u));
                *j = if inside { index as i32 } else { -1 };
            }
            for (g, &j) in gathered.iter_mut().zip(landing.iter()) {
                *g = usize::try_from(j)
                    .ok()
                    .and_then(|j| other.codes.get(j))
                    .copied()
                    .unwrap_or(INVALID);
            }
            // Distances where both codes are valid, again branch-free.
            for (((sum, count), &g), &c) in sums
                .iter_mut()
                .zip(counts.iter_mut())
                .zip(gathered.iter())
                .zip(reference)
            {
                let both = ((g | c) >> 31) ^ 1;
                *sum += ((c ^ g).count_ones() * both) as u16;
                *count += both as u16;
            }
        }
        for ((cost, &sum), &count) in out.iter_mut().zip(sums.iter()).zip(counts.iter()) {
            *cost = mean_cost(sum, count);
        }
    }

    /// Each pixel's rival exclusion (see [`PixelState::exclusion`]) for one reference row:
    /// how far the pixel moves, in its fastest view, from the farthest to the nearest plane
    /// (summed over eight legs, so that motion that turns is not undercounted), turned into the
    /// number of planes per pixel of motion, rounded (a pixel that moves about a pixel per plane
    /// keeps the one-plane bound of rectified rows).
    fn exclusions(&self, rays: RowRays<'_>, row: &mut [PixelState]) {
        const LEGS: u32 = 8;
        let last = f64::from(self.planes - 1);
        for (x, s) in row.iter_mut().enumerate() {
            let mut motion = 0.0f32;
            for (v, view) in self.views.iter().enumerate() {
                let (xs, ys, zs) = rays.view(v);
                let ray = [xs[x], ys[x], zs[x]];
                let mut moved = 0.0f32;
                let mut previous: Option<(f32, f32)> = None;
                for leg in 0..=LEGS {
                    let k = last * f64::from(leg) / f64::from(LEGS);
                    let here = view.landing(ray, (self.inverse_far + self.step * k) as f32);
                    if let (Some(a), Some(b)) = (previous, here) {
                        moved += (b.0 - a.0).hypot(b.1 - a.1);
                    }
                    previous = here;
                }
                motion = motion.max(moved);
            }
            s.exclusion = if motion.is_finite() && motion >= MIN_SWEEP_MOTION {
                ((last as f32 / motion).round() as u32).max(1)
            } else {
                u32::MAX
            };
        }
    }
}

/// `2^23`: adding it to a float below `2^22` leaves its integer part in the mantissa.
const MAGIC: f32 = 8_388_608.0;

/// `floor(x)` for `0 <= x < 2^22`, anything for other `x`, without a branch: unlike `as`,
/// which must saturate, this vectorises. Views are at most [`MAX_SWEEP_SIDE`] pixels a side.
#[inline(always)]
fn floor_small(x: f32) -> u32 {
    let nearest = (x + MAGIC) - MAGIC;
    let floor = if nearest > x { nearest - 1.0 } else { nearest };
    (floor + MAGIC).to_bits().wrapping_sub(MAGIC.to_bits())
}

/// Bit 31 of a tagged census code: the pixel has no code and matches nothing. Census strings
/// use the bits below it.
const INVALID: u32 = 1 << 31;
const _: () = assert!(CENSUS_BITS <= 31);

/// A census image with each pixel's validity folded into its code (see [`INVALID`]).
struct TaggedImage {
    width: usize,
    height: usize,
    codes: Vec<u32>,
}

/// The codes of `census` with invalid pixels tagged [`INVALID`].
fn tagged_codes(census: &CensusImage) -> TaggedImage {
    TaggedImage {
        width: census.width,
        height: census.height,
        codes: census
            .codes
            .iter()
            .zip(&census.valid)
            .map(|(&code, &ok)| if ok { code } else { INVALID })
            .collect(),
    }
}

/// `ceil(2^18 / n)` for `n` = 0 ..= [`MAX_SWEEP_VIEWS`] (0 unused): dividing by a view count
/// as a multiplication and a shift, exact for the numerators [`mean_cost`] forms.
const RECIPROCALS: [u32; MAX_SWEEP_VIEWS + 1] = {
    let mut table = [0u32; MAX_SWEEP_VIEWS + 1];
    let mut n = 1;
    while n <= MAX_SWEEP_VIEWS {
        table[n] = (1u32 << 18).div_ceil(n as u32);
        n += 1;
    }
    table
};

/// `round(sum · COST_SCALE / count)`, or the largest cost when no view saw the pixel.
#[inline]
fn mean_cost(sum: u16, count: u16) -> u8 {
    match RECIPROCALS.get(usize::from(count)) {
        Some(&reciprocal) if count > 0 => {
            let count = u32::from(count);
            // At most 31 · 16 · 8 + 8 < 2^13, so the product stays below 2^31 and the
            // multiplication equals the division (numerator · count < 2^18).
            (((u32::from(sum) * COST_SCALE + count / 2) * reciprocal) >> 18) as u8
        }
        _ => (u32::from(CENSUS_MAX_COST) * COST_SCALE) as u8,
    }
}

/// One row's scratch space for [`Sweep::row_costs`].
struct RowScratch {
    landing: Vec<i32>,
    gathered: Vec<u32>,
    sums: Vec<u16>,
    counts: Vec<u16>,
}

impl RowScratch {
    fn new(width: usize) -> Self {
        Self {
            landing: vec![0; width],
            gathered: vec![0; width],
            sums: vec![0; width],
            counts: vec![0; width],
        }
    }
}

/// `M x̃` of the band's rows for every view, as three planes (x, y, z) so that the landing
/// loop vectorises: view `v`'s row `r` starts at `(v · rows + r) · width`.
struct BandRays {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    rows: usize,
    width: usize,
}

impl BandRays {
    fn new(sweep: &Sweep, first: usize, last: usize, width: usize) -> Self {
        let rows = last - first;
        let n = sweep.views.len() * rows * width;
        let mut rays = Self {
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            rows,
            width,
        };
        for view in &sweep.views {
            let [m0, m1, m2] = view.homography;
            for y in first..last {
                let yf = y as f32;
                for x in 0..width {
                    let xf = x as f32;
                    rays.x.push(m0[0] * xf + m0[1] * yf + m0[2]);
                    rays.y.push(m1[0] * xf + m1[1] * yf + m1[2]);
                    rays.z.push(m2[0] * xf + m2[1] * yf + m2[2]);
                }
            }
        }
        rays
    }

    /// Row `r` (counted from the band's first row) for every view.
    fn row(&self, r: usize) -> RowRays<'_> {
        RowRays { band: self, r }
    }
}

/// One row of [`BandRays`].
#[derive(Clone, Copy)]
struct RowRays<'a> {
    band: &'a BandRays,
    r: usize,
}

impl<'a> RowRays<'a> {
    /// View `v`'s x, y and z planes for the row's pixels.
    fn view(&self, v: usize) -> (&'a [f32], &'a [f32], &'a [f32]) {
        let start = (v * self.band.rows + self.r) * self.band.width;
        let range = start..start + self.band.width;
        (
            &self.band.x[range.clone()],
            &self.band.y[range.clone()],
            &self.band.z[range],
        )
    }
}

impl SweepView {
    /// Where a reference pixel whose ray is `ray` (`M x̃`) lands in this view on the plane of
    /// inverse depth `inverse`, unrounded; `None` behind the view's camera. (The sweep's cost
    /// loop does the same, branch-free and rounded to the nearest pixel.)
    fn landing(&self, ray: [f32; 3], inverse: f32) -> Option<(f32, f32)> {
        let b = self.translation.map(|t| t * inverse);
        let qz = ray[2] + b[2];
        (qz > 1e-6).then(|| ((ray[0] + b[0]) / qz, (ray[1] + b[1]) / qz))
    }

    /// The view of `other` from `reference` and the fastest image motion per unit of inverse
    /// depth over the swept range (sampled over a grid of pixels and depths).
    fn new(
        reference: &Frame,
        other: &Frame,
        inverse_near: f64,
        inverse_far: f64,
    ) -> Result<(Self, f64)> {
        let other_from_reference =
            other.world_from_camera().inverse() * reference.world_from_camera();
        let t = other_from_reference.translation.vector;
        if t.norm() <= MIN_BASELINE || !t.norm().is_finite() {
            return Err(Error::Unrectifiable {
                reason: UnrectifiableReason::ZeroBaseline { baseline: t.norm() },
            });
        }
        let kr = reference.intrinsics();
        let ko = other.intrinsics();
        if ko.width().max(ko.height()) > MAX_SWEEP_SIDE {
            return Err(Error::InvalidParameter {
                name: "image side of a plane-sweep view",
                value: f64::from(ko.width().max(ko.height())),
                expected: "at most 1,048,576 pixels",
            });
        }
        let pixels = u64::from(ko.width()) * u64::from(ko.height());
        if pixels > MAX_SWEEP_PIXELS {
            return Err(Error::InvalidParameter {
                name: "pixels of a plane-sweep view",
                value: pixels as f64,
                expected: "at most 2^31 - 1 pixels",
            });
        }
        let k_other = Matrix3::new(ko.fx(), 0.0, ko.cx(), 0.0, ko.fy(), ko.cy(), 0.0, 0.0, 1.0);
        let k_reference_inverse = Matrix3::new(
            1.0 / kr.fx(),
            0.0,
            -kr.cx() / kr.fx(),
            0.0,
            1.0 / kr.fy(),
            -kr.cy() / kr.fy(),
            0.0,
            0.0,
            1.0,
        );
        let m = k_other
            * other_from_reference.rotation.to_rotation_matrix().matrix()
            * k_reference_inverse;
        let b = k_other * t;
        let (w, h) = (f64::from(kr.width()), f64::from(kr.height()));
        // Where a pixel lands far outside the other image it costs nothing, and next to the
        // other camera's plane its motion grows without bound: only motion within the image
        // grown by its own size on every side counts.
        let (ow, oh) = (f64::from(ko.width()), f64::from(ko.height()));
        let near_image =
            |p: (f64, f64)| (-ow..2.0 * ow).contains(&p.0) && (-oh..2.0 * oh).contains(&p.1);
        let mut rate: f64 = 0.0;
        for (fx, fy) in
            (0..5).flat_map(|i| (0..5).map(move |j| (f64::from(i) / 4.0, f64::from(j) / 4.0)))
        {
            let a = m * Vector3::new(fx * (w - 1.0), fy * (h - 1.0), 1.0);
            let mut previous: Option<(f64, f64)> = None;
            const SAMPLES: u32 = 32;
            for s in 0..=SAMPLES {
                let inverse =
                    inverse_far + (inverse_near - inverse_far) * f64::from(s) / f64::from(SAMPLES);
                let q = a + b * inverse;
                if q.z <= 1e-12 {
                    previous = None;
                    continue;
                }
                let p = (q.x / q.z, q.y / q.z);
                if !near_image(p) {
                    previous = None;
                    continue;
                }
                if let Some(prev) = previous {
                    let moved = ((p.0 - prev.0).powi(2) + (p.1 - prev.1).powi(2)).sqrt();
                    rate = rate.max(moved * f64::from(SAMPLES) / (inverse_near - inverse_far));
                }
                previous = Some(p);
            }
        }
        let cast = |v: f64| v as f32;
        let view = Self {
            homography: std::array::from_fn(|r| std::array::from_fn(|c| cast(m[(r, c)]))),
            translation: [cast(b.x), cast(b.y), cast(b.z)],
        };
        Ok((view, rate))
    }
}

/// Per-pixel state of the two passes.
#[derive(Clone, Copy)]
struct PixelState {
    best: u16,
    /// First and last plane of the run of equal best costs (see the module's documentation).
    best_plane: u32,
    run_end: u32,
    /// Planes on either side of the run within which a cost is no rival: one pixel of this
    /// pixel's motion; `u32::MAX` when the pixel barely moves (no depth).
    exclusion: u32,
    left: u16,
    right: u16,
    runner_up: u16,
    low: u32,
    high: u32,
}

impl Default for PixelState {
    fn default() -> Self {
        Self {
            best: u16::MAX,
            best_plane: 0,
            run_end: 0,
            exclusion: 1,
            left: u16::MAX,
            right: u16::MAX,
            runner_up: u16::MAX,
            low: u32::MAX,
            high: 0,
        }
    }
}

/// Box sums of a band's raw costs: `raw` holds rows `first ..` of the image (the band and its
/// halo), `out` the aggregated rows `y0 .. y0 + out.len() / width`. Windows are clipped at the
/// image border, which keeps each pixel's window the same on every plane.
#[allow(clippy::too_many_arguments)]
fn aggregate(
    raw: &[u8],
    first: usize,
    width: usize,
    y0: usize,
    radius: (usize, usize),
    height: usize,
    horizontal: &mut [u16],
    out: &mut [u16],
) {
    let (rx, ry) = radius;
    let rows = raw.len() / width;
    for r in 0..rows {
        let src = &raw[r * width..(r + 1) * width];
        let dst = &mut horizontal[r * width..(r + 1) * width];
        let mut sum: u16 = src[..(rx + 1).min(width)]
            .iter()
            .map(|&c| u16::from(c))
            .sum();
        for x in 0..width {
            dst[x] = sum;
            if x + rx + 1 < width {
                sum += u16::from(src[x + rx + 1]);
            }
            if x >= rx {
                sum -= u16::from(src[x - rx]);
            }
        }
    }
    // Vertical running sums over the clipped windows, one output row at a time.
    let mut column = vec![0u16; width];
    let window = |y: usize| {
        (
            y.saturating_sub(ry).max(first) - first,
            (y + ry).min(height - 1) - first,
        )
    };
    let (mut top, mut bottom) = window(y0);
    for r in top..=bottom {
        for (c, &s) in column
            .iter_mut()
            .zip(&horizontal[r * width..(r + 1) * width])
        {
            *c += s;
        }
    }
    for (i, row) in out.chunks_exact_mut(width).enumerate() {
        let (t, b) = window(y0 + i);
        while bottom < b {
            bottom += 1;
            for (c, &s) in column
                .iter_mut()
                .zip(&horizontal[bottom * width..(bottom + 1) * width])
            {
                *c += s;
            }
        }
        while top < t {
            for (c, &s) in column
                .iter_mut()
                .zip(&horizontal[top * width..(top + 1) * width])
            {
                *c -= s;
            }
            top += 1;
        }
        row.copy_from_slice(&column);
    }
}

/// Sweeps one band of rows `y0 .. y1` through every plane, twice, and returns its pixels' state.
fn sweep_band(
    sweep: &Sweep,
    reference: &TaggedImage,
    others: &[TaggedImage],
    params: &MatchParams,
    y0: usize,
    y1: usize,
) -> Vec<PixelState> {
    let width = reference.width;
    let height = reference.height;
    let radius = (
        params.window_width as usize / 2,
        params.window_height as usize / 2,
    );
    let first = y0.saturating_sub(radius.1);
    let last = (y1 + radius.1).min(height);
    let rays = BandRays::new(sweep, first, last, width);
    let mut raw = vec![0u8; (last - first) * width];
    let mut horizontal = vec![0u16; raw.len()];
    let mut scratch = RowScratch::new(width);
    let n = (y1 - y0) * width;
    // The band's aggregated costs on every plane, plane after plane.
    let mut volume = vec![0u16; n * sweep.planes as usize];
    for (k, costs) in volume.chunks_exact_mut(n).enumerate() {
        for (r, row) in raw.chunks_exact_mut(width).enumerate() {
            let y = first + r;
            let codes = &reference.codes[y * width..(y + 1) * width];
            sweep.row_costs(rays.row(r), k as u32, codes, others, &mut scratch, row);
        }
        aggregate(
            &raw,
            first,
            width,
            y0,
            radius,
            height,
            &mut horizontal,
            costs,
        );
    }
    let mut previous = vec![u16::MAX; n];
    let mut state = vec![PixelState::default(); n];
    for (r, row) in state.chunks_exact_mut(width).enumerate() {
        sweep.exclusions(rays.row(y0 - first + r), row);
    }
    // Pass 1: the best run of planes and the costs on either side of it.
    for (k, costs) in (0..sweep.planes).zip(volume.chunks_exact(n)) {
        for ((s, &c), &p) in state.iter_mut().zip(costs).zip(&previous) {
            if c < s.best {
                (s.best, s.best_plane, s.run_end, s.left, s.right) = (c, k, k, p, u16::MAX);
            } else if k == s.run_end + 1 && s.best != u16::MAX {
                if c == s.best && s.right == u16::MAX && s.exclusion > 1 {
                    s.run_end = k;
                } else if s.right == u16::MAX {
                    s.right = c;
                }
            }
        }
        previous.copy_from_slice(costs);
    }
    // Pass 2: the best cost more than one pixel of motion beyond the run, and the cost-curve
    // range.
    let tolerance = 1.0 + f64::from(params.range_tolerance);
    let limits: Vec<u16> = state
        .iter()
        .map(|s| (f64::from(s.best) * tolerance).min(f64::from(u16::MAX - 1)) as u16)
        .collect();
    for (k, costs) in (0..sweep.planes).zip(volume.chunks_exact(n)) {
        for ((s, &c), &limit) in state.iter_mut().zip(costs).zip(&limits) {
            let before = s.best_plane.saturating_sub(k);
            let after = k.saturating_sub(s.run_end);
            if before.max(after) > s.exclusion {
                s.runner_up = s.runner_up.min(c);
            }
            if c <= limit {
                s.low = s.low.min(k);
                s.high = s.high.max(k);
            }
        }
    }
    state
}

/// Matches `reference` against the sweep's other views (`others`, in the order the sweep was
/// made with) by plane sweep in the reference camera; the result's "disparity" is the
/// fractional plane index. Pixels of texture-less windows of the reference are not matched
/// ([`MatchParams::min_contrast`]).
pub(crate) fn sweep_views(
    reference: &Frame,
    others: &[&Frame],
    sweep: &Sweep,
    params: &MatchParams,
) -> Result<DisparityMap> {
    params.validate()?;
    if others.len() != sweep.views.len() {
        return Err(Error::SizeMismatch {
            what: "views of the plane sweep",
            expected: sweep.views.len(),
            found: others.len(),
        });
    }
    let left = tagged_codes(&census_transform(reference.image()));
    let right: Vec<TaggedImage> = others
        .iter()
        .map(|o| tagged_codes(&census_transform(o.image())))
        .collect();
    let (width, height) = (left.width, left.height);
    if width == 0 || height == 0 {
        return Err(Error::Empty("reference image"));
    }
    let bands: Vec<(usize, usize)> = (0..height)
        .step_by(BAND_ROWS)
        .map(|y0| (y0, (y0 + BAND_ROWS).min(height)))
        .collect();
    let states: Vec<Vec<PixelState>> = bands
        .par_iter()
        .map(|&(y0, y1)| sweep_band(sweep, &left, &right, params, y0, y1))
        .collect();
    let n = width * height;
    let mut map = DisparityMap {
        width: width as u32,
        height: height as u32,
        disparity: vec![f32::NAN; n],
        range_low: vec![f32::NAN; n],
        range_high: vec![f32::NAN; n],
        cost: vec![f32::NAN; n],
    };
    let max_cost =
        u32::from(CENSUS_MAX_COST) * COST_SCALE * params.window_width * params.window_height;
    let ratio = params.uniqueness_ratio;
    for (i, s) in states.iter().flatten().enumerate() {
        if s.best == u16::MAX
            || u32::from(s.best) >= max_cost
            || s.low > s.high
            || s.exclusion == u32::MAX
        {
            continue;
        }
        if ratio > 0 && u32::from(s.runner_up) * (100 - ratio) < u32::from(s.best) * 100 {
            continue;
        }
        // A run's middle; a single best plane is refined by a parabola through its neighbours.
        let mut offset = (s.run_end - s.best_plane) as f32 / 2.0;
        if s.run_end == s.best_plane && s.left != u16::MAX && s.right != u16::MAX {
            let (l, b, r) = (f32::from(s.left), f32::from(s.best), f32::from(s.right));
            let curvature = l + r - 2.0 * b;
            if curvature > 0.0 {
                offset = ((l - r) / (2.0 * curvature)).clamp(-0.5, 0.5);
            }
        }
        map.disparity[i] = s.best_plane as f32 + offset;
        map.range_low[i] = s.low as f32;
        map.range_high[i] = s.high as f32;
        map.cost[i] = f32::from(s.best) / max_cost as f32;
    }
    drop_textureless(reference.image(), params, &mut map);
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GrayImage;
    use crate::geometry::PinholeIntrinsics;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    #[test]
    fn floor_small_is_floor_and_mean_cost_is_the_rounded_mean() {
        let mut x = 0.0f32;
        while x < 3000.0 {
            for y in [
                x,
                x.next_up(),
                (x + 0.5).next_down(),
                x + 0.5,
                (x + 1.0).next_down(),
            ] {
                assert_eq!(floor_small(y), y as u32, "{y}");
            }
            x += 0.999;
        }
        let edge = (MAX_SWEEP_SIDE as f32).next_down();
        assert_eq!(floor_small(edge), edge as u32);
        for count in 1..=MAX_SWEEP_VIEWS as u16 {
            for sum in 0..=u16::from(CENSUS_MAX_COST) * count {
                let exact = (u32::from(sum) * COST_SCALE + u32::from(count) / 2) / u32::from(count);
                assert_eq!(u32::from(mean_cost(sum, count)), exact, "{sum} / {count}");
            }
        }
        assert_eq!(
            u32::from(mean_cost(0, 0)),
            u32::from(CENSUS_MAX_COST) * COST_SCALE
        );
    }

    fn frame(image: GrayImage, k: PinholeIntrinsics, x: f64, z: f64) -> Frame {
        let pose = Isometry3::from_parts(Translation3::new(x, 0.0, z), UnitQuaternion::identity());
        Frame::new(image, k, pose, 0.0).unwrap()
    }

    #[test]
    fn plane_index_maps_to_the_swept_depths() {
        let k = PinholeIntrinsics::new(64, 48, 50.0, 50.0, 31.5, 23.5).unwrap();
        let image = GrayImage::new(64, 48, vec![0.5; 64 * 48]).unwrap();
        let a = frame(image.clone(), k, 0.0, 0.0);
        let b = frame(image, k, 0.0, -0.5);
        let sweep = Sweep::new(&a, &[&b], 2.0, 20.0).unwrap();
        let geometry = sweep.geometry(&a).unwrap();
        let near = geometry.depth(f64::from(sweep.planes - 1)).unwrap();
        let far = geometry.depth(0.0).unwrap();
        assert!((near - 2.0).abs() < 1e-9 && (far - 20.0).abs() < 1e-9);
        // Forward motion of 0.5 m: a corner pixel (about 40 px from the centre) moves
        // 40 · 0.5 · (1/2 - 1/20) ≈ 9 px over the range, so about ten planes.
        assert!((8..=14).contains(&sweep.planes), "{}", sweep.planes);
    }

    #[test]
    fn zero_baseline_and_bad_ranges_are_errors() {
        let k = PinholeIntrinsics::new(16, 16, 20.0, 20.0, 7.5, 7.5).unwrap();
        let image = GrayImage::new(16, 16, vec![0.5; 256]).unwrap();
        let a = frame(image.clone(), k, 0.0, 0.0);
        assert!(matches!(
            Sweep::new(&a, &[&a], 1.0, 10.0),
            Err(Error::Unrectifiable {
                reason: UnrectifiableReason::ZeroBaseline { .. }
            })
        ));
        let b = frame(image, k, 0.0, -1.0);
        assert!(Sweep::new(&a, &[&b], 10.0, 1.0).is_err());
        assert!(Sweep::new(&a, &[&b], f64::NAN, 1.0).is_err());
        // No views, too many, and a view wider than the sweep's pixel arithmetic allows.
        assert!(matches!(
            Sweep::new(&a, &[], 1.0, 10.0),
            Err(Error::Empty(_))
        ));
        let crowd = vec![&b; MAX_SWEEP_VIEWS + 1];
        assert!(Sweep::new(&a, &crowd, 1.0, 10.0).is_err());
        let side = MAX_SWEEP_SIDE + 1;
        let wide_k = PinholeIntrinsics::new(side, 1, 20.0, 20.0, 7.5, 0.0).unwrap();
        let wide = frame(
            GrayImage::new(side, 1, vec![0.5; side as usize]).unwrap(),
            wide_k,
            0.0,
            -1.0,
        );
        assert!(matches!(
            Sweep::new(&a, &[&wide], 1.0, 10.0),
            Err(Error::InvalidParameter { .. })
        ));
    }
}
