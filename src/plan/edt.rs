//! Exact squared Euclidean distance transform (Felzenszwalb and Huttenlocher, "Distance
//! Transforms of Sampled Functions", Theory of Computing 8, 2012): one pass of the 1D lower
//! envelope of parabolas along each axis.

use rayon::prelude::*;

/// Squared distance, in voxels, from every voxel of an `nx × ny × nz` grid (x fastest) to the
/// nearest voxel where `blocked` is true; `f32::INFINITY` everywhere when nothing is blocked.
/// Lines are processed in parallel; the result does not depend on the thread count.
pub fn squared_distance_transform(blocked: &[bool], dims: [usize; 3]) -> Vec<f32> {
    let [nx, ny, nz] = dims;
    let mut d: Vec<f32> = blocked
        .iter()
        .map(|&b| if b { 0.0 } else { f32::INFINITY })
        .collect();
    if d.len() != nx * ny * nz || d.is_empty() {
        return d;
    }
    // Along x: rows are contiguous.
    d.par_chunks_mut(nx).for_each(transform_line);
    // Along y and z: gather each line, transform, scatter back. Planes are independent.
    d.par_chunks_mut(nx * ny).for_each(|plane| {
        let mut line = vec![0.0; ny];
        for x in 0..nx {
            for (y, v) in line.iter_mut().enumerate() {
                *v = plane[x + nx * y];
            }
            transform_line(&mut line);
            for (y, v) in line.iter().enumerate() {
                plane[x + nx * y] = *v;
            }
        }
    });
    let plane = nx * ny;
    let columns: Vec<Vec<f32>> = (0..plane)
        .into_par_iter()
        .map(|i| {
            let mut line: Vec<f32> = (0..nz).map(|z| d[i + plane * z]).collect();
            transform_line(&mut line);
            line
        })
        .collect();
    for (i, line) in columns.into_iter().enumerate() {
        for (z, v) in line.into_iter().enumerate() {
            d[i + plane * z] = v;
        }
    }
    d
}

/// In place: `f(q) ← min_p (q - p)² + f(p)` over one line.
fn transform_line(f: &mut [f32]) {
    let n = f.len();
    let sampled: Vec<f64> = f.iter().map(|&v| f64::from(v)).collect();
    let finite: Vec<usize> = (0..n).filter(|&q| sampled[q].is_finite()).collect();
    if finite.is_empty() {
        return;
    }
    let intersection = |p: usize, q: usize| {
        let (pf, qf) = (p as f64, q as f64);
        ((sampled[q] + qf * qf) - (sampled[p] + pf * pf)) / (2.0 * (qf - pf))
    };
    // Lower envelope of the parabolas rooted at the finite samples: parabola `roots[k]` is the
    // lowest between `bounds[k]` and `bounds[k + 1]`.
    let mut roots = vec![finite[0]];
    let mut bounds = vec![f64::NEG_INFINITY, f64::INFINITY];
    for &q in &finite[1..] {
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
