//! The rays of a band of reference rows: `M x̃` of every pixel for every other view, stored as
//! three planes so that the landing loop vectorises.

use super::planes::Sweep;

/// `M x̃` of the band's rows for every view, as three planes (x, y, z) so that the landing
/// loop vectorises: view `v`'s row `r` starts at `(v · rows + r) · width`.
pub(super) struct BandRays {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    rows: usize,
    width: usize,
}

impl BandRays {
    pub(super) fn new(sweep: &Sweep, first: usize, last: usize, width: usize) -> Self {
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
    pub(super) fn row(&self, r: usize) -> RowRays<'_> {
        RowRays { band: self, r }
    }
}

/// One row of [`BandRays`].
#[derive(Clone, Copy)]
pub(super) struct RowRays<'a> {
    band: &'a BandRays,
    r: usize,
}

impl<'a> RowRays<'a> {
    /// View `v`'s x, y and z planes for the row's pixels.
    pub(super) fn view(&self, v: usize) -> (&'a [f32], &'a [f32], &'a [f32]) {
        let start = (v * self.band.rows + self.r) * self.band.width;
        let range = start..start + self.band.width;
        (
            &self.band.x[range.clone()],
            &self.band.y[range.clone()],
            &self.band.z[range],
        )
    }
}
