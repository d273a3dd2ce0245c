//! Exact squared Euclidean distance transform (Felzenszwalb and Huttenlocher, "Distance
//! Transforms of Sampled Functions", Theory of Computing 8, 2012): one pass of the 1D lower
//! envelope of parabolas along each axis.

use rayon::prelude::*;

/// Squared distance, in voxels, from every voxel of an `nx × ny × nz` grid (x fastest) to the
/// nearest voxel where `blocked` is true; `f32::INFINITY` everywhere when nothing is blocked.
/// Lines are processed in parallel; the result does not depend on the thread count.
pub fn squared_distance_transform(blocked: &[bool], dims: [usize; 3]) -> Vec<f32> {
    let [nx, ny, nz] = dims;
    if blocked.len() != nx * ny * nz || blocked.is_empty() {
        return blocked
            .iter()
            .map(|&b| if b { 0.0 } else { f32::INFINITY })
            .collect();
    }
    // Along x: rows are contiguous, and on a 0/∞ input the envelope is the distance to the
    // nearest blocked voxel of the row, found by two sweeps.
    let mut d = vec![0.0f32; blocked.len()];
    d.par_chunks_mut(nx)
        .zip(blocked.par_chunks(nx))
        .for_each(|(row, blocked)| nearest_in_row(row, blocked));
    // Along y: planes are independent; each column is gathered, transformed, scattered.
    d.par_chunks_mut(nx * ny)
        .for_each_init(Envelope::default, |envelope, plane| {
            let mut line = vec![0.0; ny];
            for x in 0..nx {
                for (y, v) in line.iter_mut().enumerate() {
                    *v = plane[x + nx * y];
                }
                envelope.transform(&mut line);
                for (y, v) in line.iter().enumerate() {
                    plane[x + nx * y] = *v;
                }
            }
        });
    // Along z: each y slab (all x and z for one y) is transformed into its own buffer, z
    // major, then copied back plane by plane.
    let plane = nx * ny;
    let slabs: Vec<Vec<f32>> = (0..ny)
        .into_par_iter()
        .map_init(Envelope::default, |envelope, y| {
            let mut slab = vec![0.0; nx * nz];
            let mut line = vec![0.0; nz];
            for x in 0..nx {
                for (z, v) in line.iter_mut().enumerate() {
                    *v = d[x + nx * y + plane * z];
                }
                envelope.transform(&mut line);
                for (z, v) in line.iter().enumerate() {
                    slab[x + nx * z] = *v;
                }
            }
            slab
        })
        .collect();
    d.par_chunks_mut(plane).enumerate().for_each(|(z, out)| {
        for (y, slab) in slabs.iter().enumerate() {
            out[nx * y..nx * (y + 1)].copy_from_slice(&slab[nx * z..nx * (z + 1)]);
        }
    });
    d
}

/// The squared distance along one row to its nearest blocked voxel (∞ when none is).
fn nearest_in_row(row: &mut [f32], blocked: &[bool]) {
    let mut last: Option<usize> = None;
    for (q, (out, &b)) in row.iter_mut().zip(blocked).enumerate() {
        if b {
            last = Some(q);
        }
        *out = last.map_or(f32::INFINITY, |p| ((q - p) * (q - p)) as f32);
    }
    let mut next: Option<usize> = None;
    for (q, (out, &b)) in row.iter_mut().zip(blocked).enumerate().rev() {
        if b {
            next = Some(q);
        }
        if let Some(p) = next {
            *out = out.min(((p - q) * (p - q)) as f32);
        }
    }
}

/// Working memory of the 1D transform, reused across lines.
#[derive(Default)]
struct Envelope {
    sampled: Vec<f64>,
    roots: Vec<usize>,
    bounds: Vec<f64>,
}

impl Envelope {
    /// In place: `f(q) ← min_p (q - p)² + f(p)` over one line.
    fn transform(&mut self, f: &mut [f32]) {
        self.sampled.clear();
        self.sampled.extend(f.iter().map(|&v| f64::from(v)));
        let sampled = &self.sampled;
        let (roots, bounds) = (&mut self.roots, &mut self.bounds);
        roots.clear();
        bounds.clear();
        let intersection = |p: usize, q: usize| {
            let (pf, qf) = (p as f64, q as f64);
            ((sampled[q] + qf * qf) - (sampled[p] + pf * pf)) / (2.0 * (qf - pf))
        };
        // Lower envelope of the parabolas rooted at the finite samples: parabola `roots[k]`
        // is the lowest between `bounds[k]` and `bounds[k + 1]`.
        bounds.push(f64::NEG_INFINITY);
        for q in (0..f.len()).filter(|&q| sampled[q].is_finite()) {
            if roots.is_empty() {
                roots.push(q);
                bounds.push(f64::INFINITY);
                continue;
            }
            let mut s = intersection(roots[roots.len() - 1], q);
            // bounds[0] is −∞, so the first parabola is never popped.
            while s <= bounds[roots.len() - 1] {
                roots.pop();
                bounds.pop();
                s = intersection(roots[roots.len() - 1], q);
            }
            let last = bounds.len() - 1;
            bounds[last] = s;
            bounds.push(f64::INFINITY);
            roots.push(q);
        }
        if roots.is_empty() {
            return;
        }
        let mut k = 0;
        for (q, out) in f.iter_mut().enumerate() {
            let x = q as f64;
            while bounds[k + 1] < x {
                k += 1;
            }
            let p = roots[k] as f64;
            *out = ((x - p) * (x - p) + sampled[roots[k]]) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_force(blocked: &[bool], dims: [usize; 3]) -> Vec<f32> {
        let [nx, ny, _] = dims;
        let at = |i: usize| (i % nx, (i / nx) % ny, i / (nx * ny));
        (0..blocked.len())
            .map(|i| {
                let (x, y, z) = at(i);
                (0..blocked.len())
                    .filter(|&j| blocked[j])
                    .map(|j| {
                        let (a, b, c) = at(j);
                        let d = |u: usize, v: usize| (u as f32 - v as f32).powi(2);
                        d(x, a) + d(y, b) + d(z, c)
                    })
                    .fold(f32::INFINITY, f32::min)
            })
            .collect()
    }

    #[test]
    fn matches_brute_force() {
        let dims = [9, 7, 5];
        let n = 9 * 7 * 5;
        for seed in 0..6u64 {
            let blocked: Vec<bool> = (0..n)
                .map(|i| (i as u64 * 2654435761 + seed * 97) % 23 < (seed % 3 + 1))
                .collect();
            assert_eq!(
                squared_distance_transform(&blocked, dims),
                brute_force(&blocked, dims)
            );
        }
        assert!(
            squared_distance_transform(&vec![false; n], dims)
                .iter()
                .all(|d| d.is_infinite())
        );
    }
}
