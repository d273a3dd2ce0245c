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

impl Sweep {
    /// Each pixel's rival exclusion (see [`PixelState::exclusion`]) for one reference row:
    /// how far the pixel moves, in its fastest view, from the farthest to the nearest plane
    /// (summed over eight legs, so that motion that turns is not undercounted), turned into the
    /// number of planes per pixel of motion, rounded (a pixel that moves about a pixel per plane
    /// keeps the one-plane bound of rectified rows).
    fn exclusions(&self, rays: RowRays<'_>, row: &mut [u32]) {
        const LEGS: u32 = 8;
        let last = f64::from(self.planes - 1);
        for (x, exclusion) in row.iter_mut().enumerate() {
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
                        // Pixel distances are far from overflow, so the plain root serves
                        // (`hypot`, a library call, was a tenth of the sweep's time).
                        let (du, dv) = (b.0 - a.0, b.1 - a.1);
                        moved += (du * du + dv * dv).sqrt();
                    }
                    previous = here;
                }
                motion = motion.max(moved);
            }
            *exclusion = if motion.is_finite() && motion >= MIN_SWEEP_MOTION {
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
#[inline(always)]
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
    // Horizontal sums as the window's shifted rows added up (clipped at the row's ends): no
    // running sum, so no chain from one column to the next, and every addition vectorises.
    for (src, dst) in raw
        .chunks_exact(width)
        .zip(horizontal.chunks_exact_mut(width))
    {
        dst.fill(0);
        for offset in 0..=rx.min(width - 1) {
            // Column x adds src[x + offset] and src[x - offset].
            for (d, &c) in dst.iter_mut().zip(&src[offset..]) {
                *d += u16::from(c);
            }
            if offset > 0 {
                for (d, &c) in dst[offset..].iter_mut().zip(src) {
                    *d += u16::from(c);
                }
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

fuzzyvox_core::dispatched! {
    /// Sweeps one band of rows `y0 .. y1` through every plane, twice, and returns its pixels' state.
    /// Compiled for AVX-512 and AVX2 as well (with the raw costs and the box sums inlined), chosen
    /// at run time.
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
        // The passes run on one array per field, with selects instead of branches, so that
        // they vectorise; the pixels' states are assembled at the end.
        let mut exclusion = vec![1u32; n];
        for (r, row) in exclusion.chunks_exact_mut(width).enumerate() {
            sweep.exclusions(rays.row(y0 - first + r), row);
        }
        // Every lane is 32 bits wide, costs too (`NONE` for none yet), so that a vector holds
        // the same pixels in every array.
        const NONE: u32 = u16::MAX as u32;
        let (mut best, mut best_plane, mut run_end) = (vec![NONE; n], vec![0u32; n], vec![0u32; n]);
        let (mut left, mut right) = (vec![NONE; n], vec![NONE; n]);
        // Pass 1: the best run of planes and the costs on either side of it.
        let mut previous = vec![u16::MAX; n];
        for (k, costs) in (0..sweep.planes).zip(volume.chunks_exact(n)) {
            let lanes = best
                .iter_mut()
                .zip(best_plane.iter_mut())
                .zip(run_end.iter_mut())
                .zip(left.iter_mut())
                .zip(right.iter_mut())
                .zip(exclusion.iter())
                .zip(costs.iter().zip(previous.iter()));
            for ((((((best, best_plane), run_end), left), right), &exclusion), (&c, &p)) in lanes {
                // A new best starts a run; the plane right after the run either extends it (an
                // equal cost, when a plane is less than a pixel of motion) or gives its right-hand
                // cost.
                let (c, p) = (u32::from(c), u32::from(p));
                let new_best = c < *best;
                let next = !new_best
                    & (k == run_end.wrapping_add(1))
                    & (*best != NONE)
                    & (*right == NONE);
                let extend = next & (c == *best) & (exclusion > 1);
                *right = if new_best {
                    NONE
                } else if next & !extend {
                    c
                } else {
                    *right
                };
                *run_end = if new_best | extend { k } else { *run_end };
                *best_plane = if new_best { k } else { *best_plane };
                *left = if new_best { p } else { *left };
                *best = if new_best { c } else { *best };
            }
            previous.copy_from_slice(costs);
        }
        // Pass 2: the best cost more than one pixel of motion beyond the run, and the cost-curve
        // range.
        let tolerance = 1.0 + f64::from(params.range_tolerance);
        let limits: Vec<u32> = best
            .iter()
            .map(|&b| (f64::from(b) * tolerance).min(f64::from(u16::MAX - 1)) as u32)
            .collect();
        let (mut runner_up, mut low, mut high) = (vec![NONE; n], vec![u32::MAX; n], vec![0u32; n]);
        for (k, costs) in (0..sweep.planes).zip(volume.chunks_exact(n)) {
            let lanes = runner_up
                .iter_mut()
                .zip(low.iter_mut())
                .zip(high.iter_mut())
                .zip(best_plane.iter().zip(run_end.iter()))
                .zip(exclusion.iter().zip(limits.iter()))
                .zip(costs.iter());
            for (((((runner_up, low), high), (&best_plane, &run_end)), (&exclusion, &limit)), &c) in
                lanes
            {
                let c = u32::from(c);
                let beyond = best_plane.saturating_sub(k).max(k.saturating_sub(run_end)) > exclusion;
                *runner_up = if beyond {
                    (*runner_up).min(c)
                } else {
                    *runner_up
                };
                let in_range = c <= limit;
                *low = if in_range { (*low).min(k) } else { *low };
                *high = if in_range { (*high).max(k) } else { *high };
            }
        }
        (0..n)
            .map(|i| PixelState {
                best: best[i] as u16,
                best_plane: best_plane[i],
                run_end: run_end[i],
                exclusion: exclusion[i],
                left: left[i] as u16,
                right: right[i] as u16,
                runner_up: runner_up[i] as u16,
                low: low[i],
                high: high[i],
            })
            .collect()
}
}
