//! Free space for voxels whose centre falls on a pixel without a measurement.
//!
//! Near the camera a voxel covers many pixels: at 0.2 m and a focal length of 277 px, a voxel
//! 3 m away spans about 16 px. Frustum integration reads the one pixel under the voxel's
//! centre, so in a sparse depth image (a stereo matcher leaves textureless, occluded and
//! ambiguous pixels without depth) a voxel that dozens of measured rays pass through gets no
//! evidence when its centre pixel happens to be empty, and the free set is riddled with unknown
//! voxels where a ray-casting map has none. The dual model then reads the measured pixels of the
//! voxel's footprint instead: the voxel is free when it lies in front of the nearest of their
//! near bounds (`min P- - δ`), with the least of their free weights. Taking the minimum never
//! clears a voxel that holds a surface seen by any pixel of its footprint.
//!
//! Footprints are approximated by square windows of radius 1, 2, 4, …, 64 px around the centre
//! pixel (the smallest that covers the footprint's radius `f δ / z`), each a separable minimum
//! filter built by doubling: a window of radius `2r` is the minimum of two of radius `r`.

/// Window radii in pixels, smallest first.
pub(crate) const RADII: [u32; 7] = [1, 2, 4, 8, 16, 32, 64];

/// Per window radius, the least near bound (`P- - δ`) and the least free weight over the
/// measured pixels of the window around each pixel; `+∞` where the window has none.
pub(crate) struct FootprintFill {
    bound: Vec<Vec<f32>>,
    weight: Vec<Vec<f32>>,
}

impl FootprintFill {
    /// From each pixel's free bound and free weight (`+∞` for a pixel without a measurement),
    /// row-major, `width × height`.
    pub(crate) fn new(bound: &[f32], weight: &[f32], width: usize, height: usize) -> Self {
        Self {
            bound: windowed_minima(bound, width, height),
            weight: windowed_minima(weight, width, height),
        }
    }

    /// The bound and weight of the smallest window whose radius is at least `radius` pixels
    /// (the largest window beyond 64 px), when the window holds a measured pixel.
    #[inline]
    pub(crate) fn lookup(&self, index: usize, radius: f32) -> Option<(f32, f32)> {
        let level = RADII
            .iter()
            .position(|&r| r as f32 >= radius)
            .unwrap_or(RADII.len() - 1);
        let (bound, weight) = (self.bound[level][index], self.weight[level][index]);
        (bound.is_finite() && weight.is_finite() && weight > 0.0).then_some((bound, weight))
    }

    /// The farthest bound any window gives pixel `index` (the smallest window with a measured
    /// pixel: larger windows only lower the minimum); `-∞` when none has one.
    pub(crate) fn reach(&self, index: usize) -> f32 {
        self.bound
            .iter()
            .map(|level| level[index])
            .find(|b| b.is_finite())
            .unwrap_or(f32::NEG_INFINITY)
    }
}

/// Minimum filters of every radius in [`RADII`] over square windows, clamped at the borders:
/// along rows (radius 1, then by doubling), then each level along columns the same way.
fn windowed_minima(values: &[f32], width: usize, height: usize) -> Vec<Vec<f32>> {
    let mut rows = vec![shift_min(values, width, height, 1, Axis::Row, true)];
    for level in 1..RADII.len() {
        let shift = RADII[level - 1] as usize;
        rows.push(shift_min(
            &rows[level - 1],
            width,
            height,
            shift,
            Axis::Row,
            false,
        ));
    }
    rows.iter()
        .enumerate()
        .map(|(level, row_minima)| {
            let mut column = shift_min(row_minima, width, height, 1, Axis::Column, true);
            for &shift in &RADII[..level] {
                column = shift_min(&column, width, height, shift as usize, Axis::Column, false);
            }
            column
        })
        .collect()
}

#[derive(Clone, Copy)]
enum Axis {
    Row,
    Column,
}

/// `out[x] = min(v[x - s], v[x + s])` along `axis` (and `v[x]` too when `centre`), clamped at
/// the borders: from windows of radius `s` this gives radius `2s`; with `centre` and `s = 1`
/// from single pixels, radius 1.
fn shift_min(
    values: &[f32],
    width: usize,
    height: usize,
    shift: usize,
    axis: Axis,
    centre: bool,
) -> Vec<f32> {
    let mut out = vec![f32::INFINITY; values.len()];
    if width == 0 || height == 0 {
        return out;
    }
    // `min(low, high)`, then with the centre: the same operations in the same order for every
    // pixel, on whole rows so that they vectorise.
    let combine = |out: &mut [f32], low: &[f32], high: &[f32], middle: &[f32]| {
        for (((o, &l), &h), &m) in out.iter_mut().zip(low).zip(high).zip(middle) {
            let low_high = l.min(h);
            *o = if centre { low_high.min(m) } else { low_high };
        }
    };
    let rows = values.chunks_exact(width).zip(out.chunks_exact_mut(width));
    match axis {
        Axis::Row => {
            for (row, out) in rows {
                // Columns whose both neighbours lie inside the row, then the clamped ones.
                let inner = width.saturating_sub(2 * shift);
                if inner > 0 {
                    combine(
                        &mut out[shift..shift + inner],
                        &row[..inner],
                        &row[2 * shift..],
                        &row[shift..],
                    );
                }
                let clamped = if inner > 0 {
                    (0..shift).chain(shift + inner..width)
                } else {
                    (0..width).chain(width..width)
                };
                for x in clamped {
                    let (low, high) = (x.saturating_sub(shift), (x + shift).min(width - 1));
                    combine(
                        &mut out[x..=x],
                        &row[low..=low],
                        &row[high..=high],
                        &row[x..=x],
                    );
                }
            }
        }
        Axis::Column => {
            let row = |y: usize| &values[y * width..(y + 1) * width];
            for (y, (middle, out)) in rows.enumerate() {
                let (low, high) = (
                    row(y.saturating_sub(shift)),
                    row((y + shift).min(height - 1)),
                );
                combine(out, low, high, middle);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every level equals a brute-force minimum over its square window.
    #[test]
    fn windows_equal_brute_force_minima() {
        let (w, h) = (37, 23);
        let values: Vec<f32> = (0..w * h)
            .map(|i| {
                if i % 7 == 3 || i % 11 == 0 {
                    f32::INFINITY
                } else {
                    ((i * 7919) % 1000) as f32
                }
            })
            .collect();
        let levels = windowed_minima(&values, w, h);
        for (level, &r) in RADII.iter().enumerate() {
            let r = r as isize;
            for y in 0..h as isize {
                for x in 0..w as isize {
                    let mut m = f32::INFINITY;
                    for yy in (y - r).max(0)..=(y + r).min(h as isize - 1) {
                        for xx in (x - r).max(0)..=(x + r).min(w as isize - 1) {
                            m = m.min(values[(yy * w as isize + xx) as usize]);
                        }
                    }
                    assert_eq!(
                        levels[level][(y * w as isize + x) as usize],
                        m,
                        "radius {r} at ({x}, {y})"
                    );
                }
            }
        }
    }

    #[test]
    fn lookups_pick_the_covering_window_and_need_a_measured_pixel() {
        let (w, h) = (9, 1);
        let mut bound = vec![f32::INFINITY; 9];
        let mut weight = vec![f32::INFINITY; 9];
        bound[6] = 4.0;
        weight[6] = 0.5;
        let fill = FootprintFill::new(&bound, &weight, w, h);
        assert_eq!(fill.lookup(4, 0.5), None);
        assert_eq!(fill.lookup(4, 1.5), Some((4.0, 0.5)));
        assert_eq!(fill.lookup(0, 3.0), None);
        assert_eq!(fill.lookup(0, 5.0), Some((4.0, 0.5)));
        assert_eq!(fill.reach(4), 4.0);
        assert_eq!(fill.reach(6), 4.0);
        let empty = FootprintFill::new(&[f32::INFINITY; 3], &[f32::INFINITY; 3], 3, 1);
        assert_eq!(empty.reach(1), f32::NEG_INFINITY);
    }
}
