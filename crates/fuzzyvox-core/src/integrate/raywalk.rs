use std::ops::ControlFlow;

use nalgebra::Point3;

use crate::storage::{Resolution, VoxelKey};

/// Visits, in order, every voxel that the segment from `from` to `to` passes through, from the
/// voxel of `from` up to but excluding the voxel of `to` (the exact traversal of Amanatides and
/// Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing", 1987).
///
/// `start` and `end` must be the keys of `from` and `to`. The walk takes exactly as many steps
/// as the keys differ (the L1 distance), and an axis stops stepping once it has reached the end
/// key's coordinate, so rounding can never make it overshoot or loop.
#[inline]
pub fn walk_ray(
    resolution: &Resolution,
    from: &Point3<f64>,
    to: &Point3<f64>,
    start: VoxelKey,
    end: VoxelKey,
    mut visit: impl FnMut(VoxelKey),
) {
    let _: ControlFlow<()> = walk_ray_until(resolution, from, to, start, end, |key| {
        visit(key);
        ControlFlow::Continue(())
    });
}

/// The exact walk's set-up, shared by [`walk_ray_until`] and [`walk_ray_cells`]: per axis the
/// step (±1), the ray parameter t at the next voxel border and the t it takes to cross one
/// voxel (axes that need no step get infinite t and never win a comparison), and the number
/// of voxels to visit.
struct ExactSetup {
    step: [i32; 3],
    t: [f64; 3],
    delta: [f64; 3],
    remaining: u64,
}

impl ExactSetup {
    #[inline(always)]
    fn new(
        resolution: &Resolution,
        from: &Point3<f64>,
        to: &Point3<f64>,
        start: VoxelKey,
        end: VoxelKey,
    ) -> Self {
        let direction = to - from;
        let size = resolution.size();
        let axis = |current: i32, target: i32, from: f64, d: f64| -> (i32, f64, f64) {
            if current == target || d == 0.0 {
                (0, f64::INFINITY, f64::INFINITY)
            } else {
                let step = if d > 0.0 { 1 } else { -1 };
                let border = f64::from(current + i32::from(d > 0.0)) * size;
                (step, (border - from) / d, size / d.abs())
            }
        };
        let (step_x, t_x, delta_x) = axis(start.x, end.x, from.x, direction.x);
        let (step_y, t_y, delta_y) = axis(start.y, end.y, from.y, direction.y);
        let (step_z, t_z, delta_z) = axis(start.z, end.z, from.z, direction.z);
        let remaining = (i64::from(end.x) - i64::from(start.x)).unsigned_abs()
            + (i64::from(end.y) - i64::from(start.y)).unsigned_abs()
            + (i64::from(end.z) - i64::from(start.z)).unsigned_abs();
        Self {
            step: [step_x, step_y, step_z],
            t: [t_x, t_y, t_z],
            delta: [delta_x, delta_y, delta_z],
            remaining,
        }
    }
}

/// [`walk_ray`] that stops as soon as `visit` returns [`ControlFlow::Break`], and returns that
/// break value (for ray casts that look for the first voxel of some kind).
#[inline]
pub fn walk_ray_until<B>(
    resolution: &Resolution,
    from: &Point3<f64>,
    to: &Point3<f64>,
    start: VoxelKey,
    end: VoxelKey,
    mut visit: impl FnMut(VoxelKey) -> ControlFlow<B>,
) -> ControlFlow<B> {
    let ExactSetup {
        step: [step_x, step_y, step_z],
        t: [mut t_x, mut t_y, mut t_z],
        delta: [delta_x, delta_y, delta_z],
        mut remaining,
    } = ExactSetup::new(resolution, from, to, start, end);
    let (mut x, mut y, mut z) = (start.x, start.y, start.z);
    while remaining > 0 {
        visit(VoxelKey::new(x, y, z))?;
        remaining -= 1;
        if t_x <= t_y && t_x <= t_z {
            x += step_x;
            t_x = if x == end.x {
                f64::INFINITY
            } else {
                t_x + delta_x
            };
        } else if t_y <= t_z {
            y += step_y;
            t_y = if y == end.y {
                f64::INFINITY
            } else {
                t_y + delta_y
            };
        } else {
            z += step_z;
            t_z = if z == end.z {
                f64::INFINITY
            } else {
                t_z + delta_z
            };
        }
    }
    ControlFlow::Continue(())
}

/// [`walk_ray`] reporting its voxels block by block to `sink` (see
/// [`CellSink`](super::octomap_walk::CellSink)): the same voxels in the same order, with a step
/// that stays in its block moving the cell index instead of recomputing the block.
#[inline]
pub fn walk_ray_cells(
    resolution: &Resolution,
    from: &Point3<f64>,
    to: &Point3<f64>,
    start: VoxelKey,
    end: VoxelKey,
    sink: &mut impl super::octomap_walk::CellSink,
) {
    let ExactSetup {
        step: [step_x, step_y, step_z],
        t: [mut t_x, mut t_y, mut t_z],
        delta: [delta_x, delta_y, delta_z],
        mut remaining,
    } = ExactSetup::new(resolution, from, to, start, end);
    let (mut x, mut y, mut z) = (start.x, start.y, start.z);
    if remaining == 0 {
        return;
    }
    // The low three bits a coordinate has just after it stepped into a new block.
    let entry = |step: i32| if step > 0 { 0 } else { 7 };
    let (entry_x, entry_y, entry_z) = (entry(step_x), entry(step_y), entry(step_z));
    sink.enter(start.block());
    let mut cell = start.cell_index();
    loop {
        sink.mark(cell);
        remaining -= 1;
        if remaining == 0 {
            return;
        }
        let crossed = if t_x <= t_y && t_x <= t_z {
            x += step_x;
            t_x = if x == end.x {
                f64::INFINITY
            } else {
                t_x + delta_x
            };
            cell = cell.wrapping_add_signed(step_x as isize);
            x & 7 == entry_x
        } else if t_y <= t_z {
            y += step_y;
            t_y = if y == end.y {
                f64::INFINITY
            } else {
                t_y + delta_y
            };
            cell = cell.wrapping_add_signed(8 * step_y as isize);
            y & 7 == entry_y
        } else {
            z += step_z;
            t_z = if z == end.z {
                f64::INFINITY
            } else {
                t_z + delta_z
            };
            cell = cell.wrapping_add_signed(64 * step_z as isize);
            z & 7 == entry_z
        };
        if crossed {
            let key = VoxelKey::new(x, y, z);
            sink.enter(key.block());
            cell = key.cell_index();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walk(res: f64, from: [f64; 3], to: [f64; 3]) -> Vec<VoxelKey> {
        let r = Resolution::new(res).unwrap();
        let (a, b) = (Point3::from(from), Point3::from(to));
        let mut keys = Vec::new();
        walk_ray(
            &r,
            &a,
            &b,
            r.key_of(&a).unwrap(),
            r.key_of(&b).unwrap(),
            |k| keys.push(k),
        );
        keys
    }

    #[test]
    fn axis_aligned_ray() {
        let keys = walk(1.0, [0.5, 0.5, 0.5], [3.5, 0.5, 0.5]);
        assert_eq!(
            keys,
            vec![
                VoxelKey::new(0, 0, 0),
                VoxelKey::new(1, 0, 0),
                VoxelKey::new(2, 0, 0)
            ]
        );
    }

    #[test]
    fn same_voxel_visits_nothing() {
        assert!(walk(1.0, [0.1, 0.1, 0.1], [0.9, 0.9, 0.9]).is_empty());
    }

    #[test]
    fn diagonal_ray_is_connected_and_ends_before_target() {
        let keys = walk(0.1, [0.05, -0.33, 0.2], [-2.71, 1.9, -0.47]);
        let r = Resolution::new(0.1).unwrap();
        let end = r.key_of(&Point3::new(-2.71, 1.9, -0.47)).unwrap();
        assert!(!keys.contains(&end));
        for pair in keys.windows(2) {
            let d = (pair[0].x - pair[1].x).abs()
                + (pair[0].y - pair[1].y).abs()
                + (pair[0].z - pair[1].z).abs();
            assert_eq!(d, 1, "consecutive voxels must be face neighbours");
        }
        let last = keys.last().unwrap();
        let d = (last.x - end.x).abs() + (last.y - end.y).abs() + (last.z - end.z).abs();
        assert_eq!(d, 1);
        // Every visited voxel meets the segment: its distance to the line is at most half a
        // voxel diagonal.
        let a = Point3::new(0.05, -0.33, 0.2);
        let dir = (Point3::new(-2.71, 1.9, -0.47) - a).normalize();
        for k in &keys {
            let c = r.center(*k) - a;
            let dist = (c - dir * c.dot(&dir)).norm();
            assert!(dist <= 0.0867, "{k:?} is {dist} m from the ray");
        }
    }

    #[test]
    fn the_blockwise_walk_visits_the_same_voxels() {
        struct Keys(crate::storage::BlockKey, Vec<VoxelKey>);
        impl super::super::octomap_walk::CellSink for Keys {
            fn enter(&mut self, block: crate::storage::BlockKey) {
                self.0 = block;
            }
            fn mark(&mut self, cell: usize) {
                self.1.push(self.0.voxel(cell));
            }
        }
        let r = Resolution::new(0.05).unwrap();
        for i in 0..400 {
            let a = f64::from(i) * 0.61;
            let from = Point3::new(0.013 * a.sin() - 0.4, 0.021 * a.cos(), -0.017 * a);
            let to = Point3::new(
                4.0 * a.cos() + 0.0123,
                -3.0 * (0.7 * a).sin() - 0.0171,
                2.5 * (0.3 * a).sin() + 0.0137,
            );
            let (start, end) = (r.key_of(&from).unwrap(), r.key_of(&to).unwrap());
            let mut expected = Vec::new();
            walk_ray(&r, &from, &to, start, end, |k| expected.push(k));
            let mut blockwise = Keys(crate::storage::BlockKey::new(0, 0, 0), Vec::new());
            walk_ray_cells(&r, &from, &to, start, end, &mut blockwise);
            assert_eq!(blockwise.1, expected, "ray {i}");
        }
    }
}
