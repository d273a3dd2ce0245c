//! Sweeping one band of rows: raw costs on every plane, box sums over the window, then two
//! passes per pixel for the best run of planes, its rivals and the cost-curve range.

use super::costs::{RowScratch, TaggedImage};
use super::limits::MIN_SWEEP_MOTION;
use super::planes::Sweep;
use super::rays::{BandRays, RowRays};
use crate::params::MatchParams;

/// Per-pixel state of the two passes.
#[derive(Clone, Copy)]
pub(super) struct PixelState {
    pub(super) best: u16,
    /// First and last plane of the run of equal best costs (see the module's documentation).
    pub(super) best_plane: u32,
    pub(super) run_end: u32,
    /// Planes on either side of the run within which a cost is no rival: one pixel of this
    /// pixel's motion; `u32::MAX` when the pixel barely moves (no depth).
    pub(super) exclusion: u32,
    pub(super) left: u16,
    pub(super) right: u16,
    pub(super) runner_up: u16,
    pub(super) low: u32,
    pub(super) high: u32,
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

impl Sweep {
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
pub(super) fn sweep_band(
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
