use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::Ray;
use parry3d::shape::{Ball, Capsule, Cuboid, Cylinder, SharedShape};

/// What a surface is, for texturing and for evaluation (sky has none).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SurfaceKind {
    /// The ground.
    Ground,
    /// A wall.
    Wall,
    /// A building.
    Building,
    /// A tree trunk.
    Trunk,
    /// A tree crown.
    Crown,
}

/// One shape of the scene.
#[derive(Clone)]
struct Object {
    shape: SharedShape,
    pose: Isometry3<f32>,
    kind: SurfaceKind,
}

/// A ray's first hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction, metres.
    pub distance: f64,
    /// The hit point in the world.
    pub point: Point3<f64>,
    /// The surface normal at the hit, unit length.
    pub normal: Vector3<f64>,
    /// What was hit.
    pub kind: SurfaceKind,
    /// Index of the object hit.
    pub object: usize,
}

/// A static scene of parry3d shapes with a bounding-volume hierarchy over their boxes.
///
/// Coordinates are metres in the world frame (z up). parry3d works in single precision; the
/// scene converts at its boundary, which is far finer than any voxel or pixel.
#[derive(Clone)]
pub struct Scene {
    objects: Vec<Object>,
    bvh: Bvh,
}

impl Default for Scene {
    fn default() -> Self {
        Self::new()
    }
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Self {
        Self {
            objects: Vec::new(),
            bvh: Bvh::new(),
        }
    }

    fn push(&mut self, shape: SharedShape, pose: Isometry3<f32>, kind: SurfaceKind) -> &mut Self {
        self.objects.push(Object { shape, pose, kind });
        let boxes: Vec<Aabb> = self
            .objects
            .iter()
            .map(|o| o.shape.compute_aabb(&o.pose))
            .collect();
        self.bvh = Bvh::from_leaves(BvhBuildStrategy::default(), &boxes);
        self
    }

    /// Adds a box with its centre at `center`, half extents `half`, turned by `yaw` radians
    /// about the vertical axis.
    pub fn add_box(
        &mut self,
        center: Point3<f64>,
        half: Vector3<f64>,
        yaw: f64,
        kind: SurfaceKind,
    ) -> &mut Self {
        let pose = Isometry3::from_parts(
            Translation3::from(center.coords.cast::<f32>()),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw as f32),
        );
        self.push(
            SharedShape::new(Cuboid::new(half.cast::<f32>())),
            pose,
            kind,
        )
    }

    /// Adds flat ground: a slab `size` metres square whose top is at height `z`.
    pub fn add_ground(&mut self, z: f64, size: f64) -> &mut Self {
        self.add_box(
            Point3::new(0.0, 0.0, z - 0.5),
            Vector3::new(0.5 * size, 0.5 * size, 0.5),
            0.0,
            SurfaceKind::Ground,
        )
    }

    /// Adds a tree: a cylindrical trunk standing on `base` and a ball crown on top.
    pub fn add_tree(
        &mut self,
        base: Point3<f64>,
        trunk_radius: f64,
        trunk_height: f64,
        crown_radius: f64,
    ) -> &mut Self {
        // parry's cylinder is along its local y axis; turn it upright.
        let upright =
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f32::consts::FRAC_PI_2);
        let trunk_center = base + Vector3::new(0.0, 0.0, 0.5 * trunk_height);
        self.push(
            SharedShape::new(Cylinder::new(
                0.5 * trunk_height as f32,
                trunk_radius as f32,
            )),
            Isometry3::from_parts(
                Translation3::from(trunk_center.coords.cast::<f32>()),
                upright,
            ),
            SurfaceKind::Trunk,
        );
        let crown = base + Vector3::new(0.0, 0.0, trunk_height + 0.6 * crown_radius);
        self.push(
            SharedShape::new(Ball::new(crown_radius as f32)),
            Isometry3::translation(crown.x as f32, crown.y as f32, crown.z as f32),
            SurfaceKind::Crown,
        )
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether the scene has no object.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// The first hit of the ray from `origin` along `direction` (any length; normalised here)
    /// within `max_distance`, found through the BVH.
    pub fn cast_ray(
        &self,
        origin: &Point3<f64>,
        direction: &Vector3<f64>,
        max_distance: f64,
    ) -> Option<Hit> {
        let ray = single_precision_ray(origin, direction)?;
        let (index, _) = self.bvh.cast_ray(&ray, max_distance as f32, |leaf, best| {
            let object = self.objects.get(leaf as usize)?;
            object.shape.cast_ray(&object.pose, &ray, best, true)
        })?;
        self.hit_of(index as usize, &ray, max_distance)
    }

    /// The first hit found by testing every object (no BVH): the independent reference that
    /// tests compare [`Scene::cast_ray`] with.
    pub fn cast_ray_brute_force(
        &self,
        origin: &Point3<f64>,
        direction: &Vector3<f64>,
        max_distance: f64,
    ) -> Option<Hit> {
        let ray = single_precision_ray(origin, direction)?;
        let mut best: Option<(usize, f32)> = None;
        for (i, object) in self.objects.iter().enumerate() {
            let limit = best.map_or(max_distance as f32, |b| b.1);
            if let Some(t) = object.shape.cast_ray(&object.pose, &ray, limit, true)
                && best.is_none_or(|b| t < b.1)
            {
                best = Some((i, t));
            }
        }
        self.hit_of(best?.0, &ray, max_distance)
    }

    fn hit_of(&self, index: usize, ray: &Ray, max_distance: f64) -> Option<Hit> {
        let object = self.objects.get(index)?;
        let hit =
            object
                .shape
                .cast_ray_and_get_normal(&object.pose, ray, max_distance as f32, true)?;
        let distance = f64::from(hit.time_of_impact);
        let point = ray.point_at(hit.time_of_impact).cast::<f64>();
        Some(Hit {
            distance,
            point,
            normal: hit.normal.cast::<f64>(),
            kind: object.kind,
            object: index,
        })
    }

    /// Whether any object meets the axis-aligned box from `min` to `max` (for geometric ground
    /// truth: a voxel is occupied when it meets the scene).
    pub fn intersects_box(&self, min: &Point3<f64>, max: &Point3<f64>) -> bool {
        let aabb = Aabb::new(min.cast::<f32>(), max.cast::<f32>());
        let half = (aabb.maxs - aabb.mins) * 0.5;
        let cuboid = Cuboid::new(half);
        let pose = Isometry3::translation(aabb.center().x, aabb.center().y, aabb.center().z);
        self.bvh.intersect_aabb(&aabb).any(|leaf| {
            self.objects.get(leaf as usize).is_some_and(|o| {
                parry3d::query::intersection_test(&pose, &cuboid, &o.pose, &*o.shape)
                    .unwrap_or(true)
            })
        })
    }

    /// Whether a ball of `radius` metres swept along the segment from `a` to `b` (a capsule)
    /// meets any object: the check of a planned flight against the true geometry.
    pub fn intersects_swept_ball(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> bool {
        let capsule = Capsule::new(a.cast::<f32>(), b.cast::<f32>(), radius.max(0.0) as f32);
        let identity = Isometry3::identity();
        let aabb = capsule.aabb(&identity);
        self.bvh.intersect_aabb(&aabb).any(|leaf| {
            self.objects.get(leaf as usize).is_some_and(|o| {
                parry3d::query::intersection_test(&identity, &capsule, &o.pose, &*o.shape)
                    .unwrap_or(true)
            })
        })
    }

    /// Distance from `point` to the nearest surface (0 inside a solid).
    pub fn distance_to_surface(&self, point: &Point3<f64>) -> f64 {
        let p = point.cast::<f32>();
        self.objects
            .iter()
            .map(|o| f64::from(o.shape.distance_to_point(&o.pose, &p, true)))
            .fold(f64::INFINITY, f64::min)
    }
}

/// parry's ray (single precision, unit direction); `None` for a zero direction.
fn single_precision_ray(origin: &Point3<f64>, direction: &Vector3<f64>) -> Option<Ray> {
    let dir = direction.try_normalize(1e-12)?;
    Some(Ray::new(origin.cast::<f32>(), dir.cast::<f32>()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        let mut s = Scene::new();
        s.add_ground(0.0, 100.0)
            .add_box(
                Point3::new(10.0, 0.0, 2.0),
                Vector3::new(0.2, 5.0, 2.0),
                0.0,
                SurfaceKind::Wall,
            )
            .add_tree(Point3::new(5.0, 3.0, 0.0), 0.2, 3.0, 1.0);
        s
    }

    #[test]
    fn rays_hit_what_they_should() {
        let s = scene();
        let hit = s
            .cast_ray(&Point3::new(0.0, 0.0, 1.0), &Vector3::x(), 100.0)
            .unwrap();
        assert!((hit.distance - 9.8).abs() < 1e-4, "{hit:?}");
        assert_eq!(hit.kind, SurfaceKind::Wall);
        assert!((hit.normal - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-5);
        let down = s
            .cast_ray(&Point3::new(0.0, 0.0, 1.0), &-Vector3::z(), 100.0)
            .unwrap();
        assert_eq!(down.kind, SurfaceKind::Ground);
        assert!((down.distance - 1.0).abs() < 1e-5);
        assert!(
            s.cast_ray(&Point3::new(0.0, 0.0, 1.0), &Vector3::z(), 100.0)
                .is_none()
        );
        let trunk = s
            .cast_ray(&Point3::new(5.0, 0.0, 1.0), &Vector3::y(), 100.0)
            .unwrap();
        assert_eq!(trunk.kind, SurfaceKind::Trunk);
        assert!((trunk.distance - 2.8).abs() < 1e-4);
    }

    #[test]
    fn boxes_and_distances() {
        let s = scene();
        assert!(s.intersects_box(&Point3::new(9.7, -0.1, 1.0), &Point3::new(9.85, 0.1, 1.1)));
        assert!(!s.intersects_box(&Point3::new(9.0, -0.1, 1.0), &Point3::new(9.7, 0.1, 1.1)));
        assert!((s.distance_to_surface(&Point3::new(9.0, 0.0, 2.0)) - 0.8).abs() < 1e-4);
    }

    #[test]
    fn swept_balls_meet_what_they_pass() {
        let s = scene();
        // Along the wall face (x = 9.8) at 0.5 m: clear with a 0.3 m ball, not with 0.6 m.
        let (a, b) = (Point3::new(9.3, -3.0, 2.0), Point3::new(9.3, 3.0, 2.0));
        assert!(!s.intersects_swept_ball(&a, &b, 0.3));
        assert!(s.intersects_swept_ball(&a, &b, 0.6));
        // Through the wall: always a collision; the trunk (radius 0.2 at (5, 3)) too.
        assert!(s.intersects_swept_ball(
            &Point3::new(9.0, 0.0, 2.0),
            &Point3::new(11.0, 0.0, 2.0),
            0.01
        ));
        assert!(s.intersects_swept_ball(
            &Point3::new(5.0, 1.0, 1.0),
            &Point3::new(5.0, 5.0, 1.0),
            0.1
        ));
        assert!(!s.intersects_swept_ball(
            &Point3::new(4.0, 1.0, 1.0),
            &Point3::new(4.0, 5.0, 1.0),
            0.5
        ));
        // Down into the ground.
        assert!(s.intersects_swept_ball(
            &Point3::new(0.0, 0.0, 1.0),
            &Point3::new(0.0, 0.0, 0.2),
            0.3
        ));
    }
}
