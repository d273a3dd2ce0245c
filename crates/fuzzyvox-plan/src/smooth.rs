//! Path smoothing by line of sight: the voxels a straight segment crosses
//! ([`segment_voxels`]), greedy shortcutting of an A* path, and merging of collinear waypoints.

use fuzzyvox_core::integrate::walk_ray;
use fuzzyvox_core::storage::VoxelKey;
use nalgebra::Point3;

use crate::cost_field::CostField;

/// Calls `visit` with the dense index of every voxel the straight segment between two voxel
/// centres passes through (both ends included), stopping early when `visit` returns false;
/// returns false when stopped or when the segment leaves the region.
pub(crate) fn segment_voxels(
    field: &CostField,
    from: VoxelKey,
    to: VoxelKey,
    mut visit: impl FnMut(usize) -> bool,
) -> bool {
    let resolution = field.resolution();
    let region = field.region();
    let mut ok = true;
    walk_ray(
        &resolution,
        &resolution.center(from),
        &resolution.center(to),
        from,
        to,
        |key| {
            if ok {
                ok = region.index_of(key).is_some_and(&mut visit);
            }
        },
    );
    ok && region.index_of(to).is_some_and(visit)
}

/// Calls `visit` with the dense index of every voxel the straight segment between two voxel
/// centres passes through over a stretch of positive length, in order from `from` to `to`
/// (both included), stopping early when `visit` returns false; returns false when stopped or
/// when the segment leaves the region.
///
/// Where the segment crosses a voxel edge or corner exactly, the voxels that only touch it
/// there are not visited ([`segment_voxels`] visits one of them, as a ray walk breaks the
/// tie). So this is the exact test of the paths the planner gives: an A* step between
/// diagonal neighbours crosses only its two voxels, a leg [`segment_voxels`] passed crosses a
/// subset of what it visited, and a leg merged from collinear legs crosses what they crossed.
/// Exact: the crossings are compared as fractions of integers.
pub(crate) fn interior_voxels(
    field: &CostField,
    from: VoxelKey,
    to: VoxelKey,
    mut visit: impl FnMut(usize) -> bool,
) -> bool {
    let region = field.region();
    let d = [to.x - from.x, to.y - from.y, to.z - from.z].map(i64::from);
    let n = d.map(i64::abs);
    let mut key = [from.x, from.y, from.z];
    // Voxel faces crossed so far along each axis. The segment crosses the `k`-th face of axis
    // `a` at the fraction `(2k + 1) / (2 n[a])` of its length.
    let mut crossed = [0i64; 3];
    // Whether axis `a`'s next crossing comes before (`Less`) or with axis `b`'s.
    let order = |crossed: &[i64; 3], a: usize, b: usize| {
        ((2 * crossed[a] + 1) * n[b]).cmp(&((2 * crossed[b] + 1) * n[a]))
    };
    loop {
        let Some(index) = region.index_of(VoxelKey::new(key[0], key[1], key[2])) else {
            return false;
        };
        if !visit(index) {
            return false;
        }
        let mut first: Option<usize> = None;
        for a in (0..3).filter(|&a| crossed[a] < n[a]) {
            if first.is_none_or(|f| order(&crossed, a, f).is_lt()) {
                first = Some(a);
            }
        }
        let Some(first) = first else {
            return true;
        };
        let together: [bool; 3] =
            std::array::from_fn(|a| crossed[a] < n[a] && order(&crossed, a, first).is_eq());
        for a in (0..3).filter(|&a| together[a]) {
            crossed[a] += 1;
            key[a] += d[a].signum() as i32;
        }
    }
}

/// Which voxels a straight leg between two voxel centres counts as crossing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LegVoxels {
    /// Every voxel the ray walk visits ([`segment_voxels`]): the test of a step about to be
    /// taken and of the planner's own shortcuts.
    Ray,
    /// The voxels the leg passes through over a positive length ([`interior_voxels`]): the
    /// test of a path the planner gave.
    Interior,
}

impl LegVoxels {
    /// Visits the voxels the leg from `from` to `to` crosses, as [`segment_voxels`] and
    /// [`interior_voxels`] do.
    pub(crate) fn walk(
        self,
        field: &CostField,
        from: VoxelKey,
        to: VoxelKey,
        visit: impl FnMut(usize) -> bool,
    ) -> bool {
        match self {
            Self::Ray => segment_voxels(field, from, to, visit),
            Self::Interior => interior_voxels(field, from, to, visit),
        }
    }
}

/// Whether every leg of `waypoints` crosses, as `legs` counts it, only traversable voxels of
/// `field` that `avoid` allows, the first waypoint's voxel excepted (the vehicle is there
/// already); false when a waypoint lies outside the key range or the first outside the region.
pub(crate) fn legs_clear(
    field: &CostField,
    waypoints: &[Point3<f64>],
    avoid: &dyn Fn(usize) -> bool,
    legs: LegVoxels,
) -> bool {
    let resolution = field.resolution();
    let keys: Option<Vec<VoxelKey>> = waypoints
        .iter()
        .map(|p| resolution.key_of(p).ok())
        .collect();
    let Some(keys) = keys else {
        return false;
    };
    let Some(first) = keys.first().and_then(|k| field.region().index_of(*k)) else {
        return false;
    };
    let mut enter = |i: usize| field.is_traversable(i) && (i == first || !avoid(i));
    match keys.as_slice() {
        [_] => enter(first),
        _ => keys
            .windows(2)
            .all(|leg| legs.walk(field, leg[0], leg[1], &mut enter)),
    }
}

/// Greedy line-of-sight shortcutting: from each kept waypoint, jump to the farthest later
/// voxel of the path whose straight segment crosses only traversable voxels.
pub(crate) fn shortcut(
    field: &CostField,
    enter: &dyn Fn(usize) -> bool,
    voxels: &[VoxelKey],
) -> Vec<VoxelKey> {
    let mut kept = vec![voxels[0]];
    let mut anchor = 0;
    while anchor + 1 < voxels.len() {
        let mut next = anchor + 1;
        for candidate in (anchor + 2..voxels.len()).rev() {
            if segment_voxels(field, voxels[anchor], voxels[candidate], enter) {
                next = candidate;
                break;
            }
        }
        kept.push(voxels[next]);
        anchor = next;
    }
    kept
}

/// Drops every interior waypoint that lies on the segment between its neighbours, so that a
/// path has no redundant corners. Shortcutting leaves such points when the voxel walk of the
/// longer segment breaks a tie at a voxel edge differently from the two shorter ones.
///
/// A waypoint exactly on the segment is always dropped: the path is the same curve, so it keeps
/// the field's clearance guarantee. One within a thousandth of a voxel of it (possible only on
/// segments over a thousand voxels long) is dropped when the merged segment crosses
/// traversable voxels alone.
pub(crate) fn merge_collinear(
    field: &CostField,
    enter: &dyn Fn(usize) -> bool,
    corners: &[VoxelKey],
) -> Vec<VoxelKey> {
    let mut kept: Vec<VoxelKey> = Vec::with_capacity(corners.len());
    for (i, &key) in corners.iter().enumerate() {
        let redundant = match (kept.last(), corners.get(i + 1)) {
            (Some(&before), Some(&after)) => match offset_from_segment(before, key, after) {
                Some(0.0) => true,
                Some(offset) if offset <= 1e-3 => segment_voxels(field, before, after, enter),
                _ => false,
            },
            _ => false,
        };
        if !redundant {
            kept.push(key);
        }
    }
    kept
}

/// Distance in voxels from `middle` to the line through `a` and `b`, or `None` when `middle`
/// does not lie between the two ends (a reversal, whose removal would cut a corner) or the
/// ends coincide. Exact (0.0) for a point on the segment: the cross product of integer keys
/// is computed in integers.
fn offset_from_segment(a: VoxelKey, middle: VoxelKey, b: VoxelKey) -> Option<f64> {
    let vector = |from: VoxelKey, to: VoxelKey| {
        [
            i128::from(to.x) - i128::from(from.x),
            i128::from(to.y) - i128::from(from.y),
            i128::from(to.z) - i128::from(from.z),
        ]
    };
    let (u, v) = (vector(a, b), vector(a, middle));
    let dot = |p: [i128; 3], q: [i128; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let (length2, along) = (dot(u, u), dot(u, v));
    if length2 == 0 || along < 0 || along > length2 {
        return None;
    }
    // Squared in floating point: the cross product's components fit i128, their squares may
    // not, and a zero product stays exactly zero.
    let off = cross.map(|c| c as f64);
    Some(((off[0] * off[0] + off[1] * off[1] + off[2] * off[2]) / (length2 as f64)).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::plan_in_field;
    use crate::path::tests::open_field;

    fn traversable(field: &CostField) -> impl Fn(usize) -> bool + '_ {
        |index| field.is_traversable(index)
    }

    fn keys(points: &[[i32; 3]]) -> Vec<VoxelKey> {
        points
            .iter()
            .map(|&[x, y, z]| VoxelKey::new(x, y, z))
            .collect()
    }
    #[test]
    fn collinear_waypoints_are_merged() {
        let field = open_field(false);
        // Two points on the first leg, one on the second, then a turn into z.
        let corners = keys(&[
            [5, 5, 5],
            [7, 7, 5],
            [10, 10, 5],
            [10, 20, 5],
            [10, 30, 5],
            [10, 30, 10],
        ]);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &corners),
            keys(&[[5, 5, 5], [10, 10, 5], [10, 30, 5], [10, 30, 10]])
        );
        // A repeated point is redundant too.
        assert_eq!(
            merge_collinear(
                &field,
                &traversable(&field),
                &keys(&[[5, 5, 5], [5, 5, 5], [9, 5, 5]])
            ),
            keys(&[[5, 5, 5], [9, 5, 5]])
        );
    }

    #[test]
    fn corners_and_reversals_are_kept() {
        let field = open_field(false);
        // Off the line by one voxel: a real corner.
        let corner = keys(&[[5, 5, 5], [10, 6, 5], [15, 5, 5]]);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &corner),
            corner
        );
        // On the line but beyond its end: dropping it would cut the path short.
        let reversal = keys(&[[5, 5, 5], [15, 5, 5], [10, 5, 5]]);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &reversal),
            reversal
        );
        // Ends alone, and a single point, are left as they are.
        let two = keys(&[[5, 5, 5], [15, 5, 5]]);
        assert_eq!(merge_collinear(&field, &traversable(&field), &two), two);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &two[..1]),
            two[..1]
        );
    }

    #[test]
    fn offsets_from_a_segment_are_exact_on_it_and_none_beyond_its_ends() {
        let key = VoxelKey::new;
        let (a, b) = (key(0, 0, 0), key(10_000, 1, 0));
        assert_eq!(
            offset_from_segment(a, key(20_000, 2, 0), key(40_000, 4, 0)),
            Some(0.0)
        );
        // (5, 0, 0) is 0.0005 voxel off the line from a to b; (5000, 0, 0) is 0.5 off.
        let near = offset_from_segment(a, key(5, 0, 0), b).unwrap();
        assert!((near - 5e-4).abs() < 1e-9, "{near}");
        let far = offset_from_segment(a, key(5000, 0, 0), b).unwrap();
        assert!((far - 0.5).abs() < 1e-6, "{far}");
        assert_eq!(offset_from_segment(a, key(-1, 0, 0), b), None);
        assert_eq!(offset_from_segment(a, key(10_001, 1, 0), b), None);
        assert_eq!(offset_from_segment(a, a, a), None);
        // Keys at the ends of the key range do not overflow.
        let (lo, hi) = (key(i32::MIN, i32::MIN, 0), key(i32::MAX, i32::MAX, 0));
        assert_eq!(
            offset_from_segment(lo, key(0, 0, 0), hi).map(|d| d < 1.0),
            Some(true)
        );
    }

    #[test]
    fn planned_paths_have_no_collinear_interior_waypoints() {
        let field = open_field(true);
        let region = *field.region();
        let resolution = field.resolution();
        for (start, goal) in [
            ([5, 20, 10], [35, 20, 10]),
            ([5, 5, 5], [35, 35, 15]),
            ([20, 5, 10], [20, 35, 10]),
            ([8, 19, 4], [33, 21, 16]),
        ] {
            let (start, goal) = (
                VoxelKey::new(start[0], start[1], start[2]),
                VoxelKey::new(goal[0], goal[1], goal[2]),
            );
            let path = plan_in_field(&field, start, goal).unwrap();
            assert_eq!(resolution.key_of(&path.waypoints[0]).unwrap(), start);
            for w in path.waypoints.windows(3) {
                let k: Vec<VoxelKey> = w.iter().map(|p| resolution.key_of(p).unwrap()).collect();
                assert_ne!(
                    offset_from_segment(k[0], k[1], k[2]),
                    Some(0.0),
                    "redundant waypoint in {:?}",
                    path.waypoints
                );
                assert!(k.iter().all(|key| region.index_of(*key).is_some()));
            }
        }
    }

    fn visited(field: &CostField, from: VoxelKey, to: VoxelKey, legs: LegVoxels) -> Vec<usize> {
        let mut seen = Vec::new();
        assert!(legs.walk(field, from, to, |i| {
            seen.push(i);
            true
        }));
        seen
    }

    /// A step to any of the 26 neighbours crosses its two voxels alone; a longer segment
    /// crosses, in order, a chain of 26-neighbours from one end to the other, every one of
    /// them a voxel the ray walk visits too, and all of them along an axis.
    #[test]
    fn interior_voxels_skip_touched_edges_and_corners_only() {
        let field = open_field(false);
        let region = *field.region();
        let at = |x, y, z| region.index_of(VoxelKey::new(x, y, z)).unwrap();
        let centre = VoxelKey::new(20, 20, 10);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let to = VoxelKey::new(20 + dx, 20 + dy, 10 + dz);
                    let expected = if to == centre {
                        vec![at(20, 20, 10)]
                    } else {
                        vec![at(20, 20, 10), at(20 + dx, 20 + dy, 10 + dz)]
                    };
                    assert_eq!(visited(&field, centre, to, LegVoxels::Interior), expected);
                }
            }
        }
        let along = visited(
            &field,
            VoxelKey::new(3, 7, 2),
            VoxelKey::new(30, 7, 2),
            LegVoxels::Interior,
        );
        assert_eq!(
            along,
            visited(
                &field,
                VoxelKey::new(3, 7, 2),
                VoxelKey::new(30, 7, 2),
                LegVoxels::Ray
            )
        );
        for (from, to) in [
            ([2, 3, 4], [37, 29, 11]),
            ([30, 2, 18], [1, 39, 0]),
            ([5, 5, 5], [25, 15, 5]),
            ([10, 10, 10], [16, 13, 19]),
            ([0, 40, 20], [40, 0, 0]),
        ] {
            let (from, to) = (
                VoxelKey::new(from[0], from[1], from[2]),
                VoxelKey::new(to[0], to[1], to[2]),
            );
            let inner = visited(&field, from, to, LegVoxels::Interior);
            let ray = visited(&field, from, to, LegVoxels::Ray);
            assert_eq!(inner.first(), Some(&region.index_of(from).unwrap()));
            assert_eq!(inner.last(), Some(&region.index_of(to).unwrap()));
            assert!(inner.iter().all(|i| ray.contains(i)), "{from:?} to {to:?}");
            for pair in inner.windows(2) {
                let (a, b) = (region.key_at(pair[0]), region.key_at(pair[1]));
                let d = [b.x - a.x, b.y - a.y, b.z - a.z];
                assert!(d.iter().all(|c| c.abs() <= 1) && d != [0, 0, 0]);
            }
        }
    }

    /// Every leg of a planned path crosses only traversable voxels by the interior test (the
    /// test a closed loop keeps its path by), also where A* steps diagonally past a corner of
    /// the blocked space round the pillar.
    #[test]
    fn planned_paths_cross_only_traversable_voxels() {
        let field = open_field(true);
        let resolution = field.resolution();
        let mut diagonal_corners = 0;
        for (start, goal) in [
            ([5, 20, 10], [35, 20, 10]),
            ([5, 5, 5], [35, 35, 15]),
            ([20, 5, 10], [20, 35, 10]),
            ([8, 19, 4], [33, 21, 16]),
            ([10, 12, 3], [30, 28, 3]),
            ([30, 12, 17], [10, 27, 2]),
        ] {
            let (start, goal) = (
                VoxelKey::new(start[0], start[1], start[2]),
                VoxelKey::new(goal[0], goal[1], goal[2]),
            );
            let path = plan_in_field(&field, start, goal).unwrap();
            let keys: Vec<VoxelKey> = path
                .waypoints
                .iter()
                .map(|p| resolution.key_of(p).unwrap())
                .collect();
            for leg in keys.windows(2) {
                assert!(interior_voxels(&field, leg[0], leg[1], traversable(&field)));
                if !segment_voxels(&field, leg[0], leg[1], traversable(&field)) {
                    diagonal_corners += 1;
                }
            }
        }
        // The ray walk refuses some of these legs: the interior test is what keeps them.
        assert!(diagonal_corners > 0);
    }
}
