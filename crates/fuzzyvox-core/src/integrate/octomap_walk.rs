use nalgebra::Point3;

use crate::storage::{Resolution, VoxelKey};

use crate::storage::BlockKey;

/// Where a ray walk reports the voxels it visits, block by block: [`CellSink::enter`] when the
/// walk enters a block (and before its first voxel), [`CellSink::mark`] for each voxel with its
/// index in the block (see [`VoxelKey::cell_index`]). Consecutive voxels of a ray mostly share a
/// block, so a sink that looks a block up once per `enter` does one lookup per block crossed
/// rather than one per voxel.
pub trait CellSink {
    /// The walk enters block `block`.
    fn enter(&mut self, block: BlockKey);
    /// The walk visits cell `cell` of the block last entered.
    fn mark(&mut self, cell: usize);
}

/// Visits the voxels that OctoMap 1.9's `computeRayKeys` reports as free for a ray from
/// `origin` to `end`, in order: the origin's voxel, then every voxel crossed before the end
/// voxel. Returns `false` when either end has no key (OctoMap skips such rays).
///
/// This is the standard method's traversal reproduced operation for operation, including its
/// single-precision points (`point3d` is `float`), its tie-breaking (strict `<`), and its stop
/// rule (the end key is reached, or the next border lies beyond the ray's length), so that the
/// log-odds baseline marks exactly the voxels OctoMap marks. The fuzzy map uses the cleaner
/// [`walk_ray`](super::walk_ray).
pub fn walk_ray_octomap(
    resolution: &Resolution,
    origin: [f32; 3],
    end: [f32; 3],
    visit: impl FnMut(VoxelKey),
) -> bool {
    struct Keys<F> {
        block: BlockKey,
        visit: F,
    }
    impl<F: FnMut(VoxelKey)> CellSink for Keys<F> {
        fn enter(&mut self, block: BlockKey) {
            self.block = block;
        }
        fn mark(&mut self, cell: usize) {
            (self.visit)(self.block.voxel(cell));
        }
    }
    walk_ray_octomap_cells(
        resolution,
        origin,
        end,
        &mut Keys {
            block: BlockKey::new(0, 0, 0),
            visit,
        },
    )
}

/// [`walk_ray_octomap`] reporting its voxels block by block to `sink`: the same voxels in the
/// same order. A step that stays in its block moves the cell index by ±1, ±8 or ±64 instead of
/// recomputing the block, which is most of what marking a voxel costs.
#[inline]
pub fn walk_ray_octomap_cells(
    resolution: &Resolution,
    origin: [f32; 3],
    end: [f32; 3],
    sink: &mut impl CellSink,
) -> bool {
    let key_of = |p: [f32; 3]| {
        resolution.try_key_of(&Point3::new(
            f64::from(p[0]),
            f64::from(p[1]),
            f64::from(p[2]),
        ))
    };
    let (Some(start), Some(stop)) = (key_of(origin), key_of(end)) else {
        return false;
    };
    if start == stop {
        return true;
    }
    sink.enter(start.block());
    let mut cell = start.cell_index();
    sink.mark(cell);

    // Direction and length in single precision, as OctoMap's Vector3 computes them.
    let mut direction = [end[0] - origin[0], end[1] - origin[1], end[2] - origin[2]];
    let norm_sq =
        direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2];
    let length = f64::from(norm_sq).sqrt() as f32;
    for d in &mut direction {
        *d /= length;
    }
    let size = resolution.size();
    // Per axis: step, ray parameter at the next border, parameter per voxel; f64::MAX where
    // the ray does not move along the axis, as in OctoMap.
    let axis = |key: i32, origin: f32, d: f32| -> (i32, f64, f64) {
        if d == 0.0 {
            return (0, f64::MAX, f64::MAX);
        }
        let step = if d > 0.0 { 1 } else { -1 };
        let half_step = (f64::from(step) * size * 0.5) as f32;
        let border = (f64::from(key) + 0.5) * size + f64::from(half_step);
        let d = f64::from(d);
        (step, (border - f64::from(origin)) / d, size / d.abs())
    };
    let (step_x, mut t_x, delta_x) = axis(start.x, origin[0], direction[0]);
    let (step_y, mut t_y, delta_y) = axis(start.y, origin[1], direction[1]);
    let (step_z, mut t_z, delta_z) = axis(start.z, origin[2], direction[2]);
    let (mut x, mut y, mut z) = (start.x, start.y, start.z);
    // The low three bits a coordinate has just after it stepped into a new block.
    let entry = |step: i32| if step > 0 { 0 } else { 7 };
    let (entry_x, entry_y, entry_z) = (entry(step_x), entry(step_y), entry(step_z));
    let length = f64::from(length);
    // Steps until the walk can first stand on the end key: every step moves one coordinate
    // towards it or past it, and a coordinate that passed it never comes back.
    let mut until_end = (i64::from(stop.x) - i64::from(x)).unsigned_abs()
        + (i64::from(stop.y) - i64::from(y)).unsigned_abs()
        + (i64::from(stop.z) - i64::from(z)).unsigned_abs();
    // OctoMap stops by its own rules; the cap only guards against a walk that would never end
    // and lies far above any real ray's step count.
    let cap = until_end + 64;
    // One step along an axis, then OctoMap's two stop rules, then the visit. Only the axis
    // that stepped changed, so its parameter is tested first against the length (OctoMap's
    // `min(min(tx, ty), tz) > length`; no parameter is NaN) and the end key is compared only
    // once enough steps were taken.
    macro_rules! step {
        ($c:ident, $t:ident, $step:expr, $delta:expr, $entry:expr, $moved:expr) => {{
            $c += $step;
            $t += $delta;
            until_end = until_end.wrapping_sub(1);
            if until_end == 0 && x == stop.x && y == stop.y && z == stop.z {
                break;
            }
            if $t > length && t_x > length && t_y > length && t_z > length {
                break;
            }
            if $c & 7 == $entry {
                let key = VoxelKey::new(x, y, z);
                sink.enter(key.block());
                cell = key.cell_index();
            } else {
                cell = cell.wrapping_add_signed($moved);
            }
            sink.mark(cell);
        }};
    }
    for _ in 0..cap {
        if t_x < t_y {
            if t_x < t_z {
                step!(x, t_x, step_x, delta_x, entry_x, step_x as isize);
            } else {
                step!(z, t_z, step_z, delta_z, entry_z, 64 * step_z as isize);
            }
        } else if t_y < t_z {
            step!(y, t_y, step_y, delta_y, entry_y, 8 * step_y as isize);
        } else {
            step!(z, t_z, step_z, delta_z, entry_z, 64 * step_z as isize);
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(res: f64, origin: [f32; 3], end: [f32; 3]) -> Vec<VoxelKey> {
        let mut out = Vec::new();
        assert!(walk_ray_octomap(
            &Resolution::new(res).unwrap(),
            origin,
            end,
            |k| out.push(k)
        ));
        out
    }

    #[test]
    fn includes_origin_excludes_end() {
        let k = keys(1.0, [0.5, 0.5, 0.5], [3.5, 0.5, 0.5]);
        assert_eq!(
            k,
            vec![
                VoxelKey::new(0, 0, 0),
                VoxelKey::new(1, 0, 0),
                VoxelKey::new(2, 0, 0)
            ]
        );
        assert!(keys(1.0, [0.1, 0.1, 0.1], [0.9, 0.9, 0.9]).is_empty());
    }

    #[test]
    fn agrees_with_the_exact_walk_on_generic_rays() {
        let r = Resolution::new(0.1).unwrap();
        let origin = [0.013f32, -0.027, 0.051];
        for i in 0..200 {
            let a = f64::from(i) * 0.37;
            // Generic end points: none on a voxel border, where the two walks legitimately
            // differ (OctoMap stops short of an end key it would only touch at the end point).
            let end = [
                (3.0 * a.cos() + 0.0123) as f32,
                (2.0 * a.sin() + 0.0171) as f32,
                (1.5 * (0.3 * a).sin() + 0.0137) as f32,
            ];
            let octo = keys(0.1, origin, end);
            let mut exact = Vec::new();
            let (o, e) = (
                Point3::new(
                    f64::from(origin[0]),
                    f64::from(origin[1]),
                    f64::from(origin[2]),
                ),
                Point3::new(f64::from(end[0]), f64::from(end[1]), f64::from(end[2])),
            );
            super::super::walk_ray(
                &r,
                &o,
                &e,
                r.key_of(&o).unwrap(),
                r.key_of(&e).unwrap(),
                |k| exact.push(k),
            );
            assert_eq!(octo, exact, "ray {i}");
        }
    }
}
