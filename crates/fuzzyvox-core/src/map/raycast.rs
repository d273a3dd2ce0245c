//! Ray casts through a map: the first voxel of a class along a ray, as a depth camera would see
//! the map.

use std::ops::ControlFlow;

use nalgebra::{Point3, Vector3};

use super::VoxelMap;
use crate::error::{Error, Result, finite};
use crate::integrate::walk_ray_until;
use crate::measures::VoxelClass;
use crate::storage::VoxelKey;

/// Where a ray met a voxel: the voxel and the stretch of the ray inside it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The voxel that stopped the ray.
    pub key: VoxelKey,
    /// Its class.
    pub class: VoxelClass,
    /// Distance from the origin (metres, along the unit direction) at which the ray enters the
    /// voxel; 0 when the origin lies inside it.
    pub entry: f64,
    /// Distance at which the ray leaves the voxel.
    pub exit: f64,
}

impl RayHit {
    /// The middle of the ray's chord through the voxel: the surface the voxel stands for lies
    /// somewhere in it, and the middle is the unbiased guess when nothing says where.
    pub fn distance(&self) -> f64 {
        0.5 * (self.entry + self.exit)
    }
}

/// Casts a ray from `origin` along `direction` (any length, not zero) up to `max_range` metres
/// and returns the first voxel whose class is in `stop_at`, visiting voxels in order with the
/// exact walk of [`walk_ray`](crate::integrate::walk_ray). The origin's own voxel counts.
///
/// Voxels of other classes (free, and unknown ones that nothing observed) let the ray through;
/// `None` means the ray reached `max_range` without stopping.
///
/// ```
/// use fuzzyvox_core::map::cast_ray;
/// use fuzzyvox_core::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelClass};
/// use nalgebra::{Point3, Vector3};
///
/// let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
/// let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(2.05, 0.05, 0.05)])?;
/// fuzzyvox_core::VoxelMapMut::integrate_cloud(&mut map, &cloud, &IntegrationOptions::default())?;
/// let hit = cast_ray(
///     &map,
///     &Point3::new(0.0, 0.05, 0.05),
///     &Vector3::x(),
///     10.0,
///     &[VoxelClass::Occupied],
/// )?
/// .expect("the ray meets the end point's voxel");
/// assert!((hit.entry - 2.0).abs() < 1e-9 && (hit.exit - 2.1).abs() < 1e-9);
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
pub fn cast_ray(
    map: &dyn VoxelMap,
    origin: &Point3<f64>,
    direction: &Vector3<f64>,
    max_range: f64,
    stop_at: &[VoxelClass],
) -> Result<Option<RayHit>> {
    for (what, value) in [
        ("ray origin x", origin.x),
        ("ray origin y", origin.y),
        ("ray origin z", origin.z),
        ("ray direction x", direction.x),
        ("ray direction y", direction.y),
        ("ray direction z", direction.z),
        ("max_range", max_range),
    ] {
        finite(what, value)?;
    }
    let length = direction.norm();
    if !(length.is_finite() && length > 0.0) {
        return Err(Error::InvalidParameter {
            name: "ray direction length",
            value: length,
            expected: "a non-zero finite direction",
        });
    }
    if max_range <= 0.0 {
        return Err(Error::InvalidParameter {
            name: "max_range",
            value: max_range,
            expected: "a positive range in metres",
        });
    }
    let unit = direction / length;
    let resolution = map.resolution();
    let end = origin + unit * max_range;
    let start_key = resolution.key_of(origin)?;
    let end_key = resolution.key_of(&end)?;
    let stops = |key: VoxelKey| -> Option<VoxelClass> {
        let class = map.class_at(key);
        stop_at.contains(&class).then_some(class)
    };
    let found = walk_ray_until(
        &resolution,
        origin,
        &end,
        start_key,
        end_key,
        |key| match stops(key) {
            Some(class) => ControlFlow::Break((key, class)),
            None => ControlFlow::Continue(()),
        },
    );
    // The walk stops short of the end voxel; it holds the last stretch of the ray.
    let (key, class) = match found {
        ControlFlow::Break(hit) => hit,
        ControlFlow::Continue(()) => match stops(end_key) {
            Some(class) => (end_key, class),
            None => return Ok(None),
        },
    };
    let (entry, exit) = chord(
        &resolution.corner(key),
        resolution.size(),
        origin,
        &unit,
        max_range,
    );
    Ok(Some(RayHit {
        key,
        class,
        entry,
        exit,
    }))
}

/// The part `[entry, exit]` of the ray `origin + t · unit`, `t` in `[0, max_range]`, inside the
/// cube with lowest corner `corner` and edge `size` (the slab method). The walk only hands over
/// voxels that the ray meets, so the interval is non-empty up to rounding; it is clamped so that
/// `0 <= entry <= exit <= max_range` holds regardless.
fn chord(
    corner: &Point3<f64>,
    size: f64,
    origin: &Point3<f64>,
    unit: &Vector3<f64>,
    max_range: f64,
) -> (f64, f64) {
    let (mut entry, mut exit) = (0.0_f64, max_range);
    for axis in 0..3 {
        let (lo, hi) = (corner[axis], corner[axis] + size);
        let d = unit[axis];
        if d == 0.0 {
            continue;
        }
        let (a, b) = ((lo - origin[axis]) / d, (hi - origin[axis]) / d);
        entry = entry.max(a.min(b));
        exit = exit.min(a.max(b));
    }
    let entry = entry.clamp(0.0, max_range);
    (entry, exit.clamp(entry, max_range))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{IntegrationOptions, PointCloud};
    use crate::map::{FuzzyConfig, FuzzyMap, LogOddsConfig, LogOddsMap, VoxelMapMut};

    const OCCUPIED: &[VoxelClass] = &[VoxelClass::Occupied];

    /// A wall at x = 3 m seen from the origin, in a map of `res` metres.
    fn wall_map(map: &mut dyn VoxelMapMut) {
        let points = (0..41)
            .flat_map(|i| (0..41).map(move |j| (i, j)))
            .map(|(i, j)| Point3::new(3.0, -1.0 + 0.05 * f64::from(i), -1.0 + 0.05 * f64::from(j)))
            .collect();
        let cloud = PointCloud::new(Point3::origin(), points).unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
    }

    #[test]
    fn finds_the_wall_at_its_depth_in_every_map() {
        let mut fuzzy = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        let mut logodds = LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap();
        wall_map(&mut fuzzy);
        wall_map(&mut logodds);
        for map in [&fuzzy as &dyn VoxelMap, &logodds] {
            for direction in [
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(1.0, 0.2, -0.1),
                Vector3::new(3.0, -0.5, 0.4),
            ] {
                let hit = cast_ray(map, &Point3::origin(), &direction, 10.0, OCCUPIED)
                    .unwrap()
                    .unwrap();
                assert_eq!(hit.class, VoxelClass::Occupied);
                // The wall's voxels span x in [3.0, 3.1); the hit is one of them.
                assert_eq!(hit.key.x, 30, "{direction:?}: {hit:?}");
                let along_x = hit.distance() * direction.normalize().x;
                assert!((2.95..3.15).contains(&along_x), "{direction:?}: {hit:?}");
                assert!(hit.entry <= hit.exit);
            }
        }
    }

    #[test]
    fn rays_that_miss_or_stop_short_find_nothing() {
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        wall_map(&mut map);
        let origin = Point3::origin();
        // Away from the wall, and towards it but not far enough.
        assert!(
            cast_ray(&map, &origin, &-Vector3::x(), 10.0, OCCUPIED)
                .unwrap()
                .is_none()
        );
        assert!(
            cast_ray(&map, &origin, &Vector3::x(), 2.5, OCCUPIED)
                .unwrap()
                .is_none()
        );
        // Stopping at free voxels instead finds the first voxel in front of the sensor.
        let free = cast_ray(&map, &origin, &Vector3::x(), 10.0, &[VoxelClass::Free])
            .unwrap()
            .unwrap();
        assert_eq!(free.key, VoxelKey::new(0, 0, 0));
        assert_eq!(free.entry, 0.0);
    }

    #[test]
    fn the_range_can_end_inside_the_hit_voxel() {
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        wall_map(&mut map);
        let hit = cast_ray(&map, &Point3::origin(), &Vector3::x(), 3.05, OCCUPIED)
            .unwrap()
            .unwrap();
        assert_eq!(hit.key.x, 30);
        assert!((hit.entry - 3.0).abs() < 1e-9 && (hit.exit - 3.05).abs() < 1e-9);
    }

    #[test]
    fn bad_rays_are_errors() {
        let map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        let o = Point3::origin();
        assert!(cast_ray(&map, &o, &Vector3::zeros(), 1.0, OCCUPIED).is_err());
        assert!(cast_ray(&map, &o, &Vector3::new(f64::NAN, 0.0, 0.0), 1.0, OCCUPIED).is_err());
        assert!(cast_ray(&map, &o, &Vector3::x(), -1.0, OCCUPIED).is_err());
        assert!(cast_ray(&map, &o, &Vector3::x(), f64::INFINITY, OCCUPIED).is_err());
        assert!(
            cast_ray(
                &map,
                &Point3::new(1e300, 0.0, 0.0),
                &Vector3::x(),
                1.0,
                OCCUPIED
            )
            .is_err()
        );
    }
}
