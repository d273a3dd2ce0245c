//! What a planned path is checked against: the obstacles of the true world, and the one path
//! check every experiment uses ([`path_collides`]).

use fuzzyvox_sim::Scene;
use nalgebra::Point3;

/// The true obstacles an experiment checks paths against and keeps starts and goals away from.
pub trait Obstacles: Sync {
    /// Distance from `point` to the nearest obstacle, metres (0 inside one).
    fn distance_to_surface(&self, point: &Point3<f64>) -> f64;
    /// Whether a ball of `radius` metres swept from `a` to `b` meets an obstacle.
    fn meets_swept_ball(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> bool;

    /// The first point from `a` towards `b`, in steps of a quarter of `radius`, whose ball of
    /// `radius` meets an obstacle (for a path that [`Obstacles::meets_swept_ball`] said meets
    /// one); `None` when no step does.
    fn first_contact(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> Option<Point3<f64>> {
        let length = (b - a).norm();
        let steps = (length / (radius / 4.0).max(1e-3)).ceil().max(1.0) as usize;
        (0..=steps)
            .map(|i| a + (b - a) * (i as f64 / steps as f64))
            .find(|p| self.distance_to_surface(p) < radius)
    }
}

/// A simulated scene's real geometry.
impl Obstacles for Scene {
    fn distance_to_surface(&self, point: &Point3<f64>) -> f64 {
        Scene::distance_to_surface(self, point)
    }

    fn meets_swept_ball(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> bool {
        self.intersects_swept_ball(a, b, radius)
    }
}

/// Where a ball of `radius` swept along the path `waypoints` first meets an obstacle of
/// `world`, as [`Obstacles::first_contact`] finds it on the first segment that meets one (the
/// segment's start when the steps find no nearer point); `None` when the path is clear. A
/// one-point path is checked as a ball at that point; an empty path meets nothing.
pub fn path_contact(
    world: &dyn Obstacles,
    waypoints: &[Point3<f64>],
    radius: f64,
) -> Option<Point3<f64>> {
    let single = match waypoints {
        [only] => Some((only, only)),
        _ => None,
    };
    single
        .into_iter()
        .chain(waypoints.windows(2).map(|w| (&w[0], &w[1])))
        .find(|(a, b)| world.meets_swept_ball(a, b, radius))
        .map(|(a, b)| world.first_contact(a, b, radius).unwrap_or(*a))
}

/// Whether a ball of `radius` swept along the path `waypoints` meets an obstacle of `world`
/// ([`path_contact`] finds where).
pub fn path_collides(world: &dyn Obstacles, waypoints: &[Point3<f64>], radius: f64) -> bool {
    path_contact(world, waypoints, radius).is_some()
}
